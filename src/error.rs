//! One error type for everything the user can get wrong. Every variant maps to exit code 2
//! and prints as a single line naming the file (or parameter) and the problem.

use std::fmt;
use std::path::Path;

#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Error {
    /// What the problem is about: a file path, or a parameter such as `--n`.
    pub subject: String,
    pub message: String,
}

impl Error {
    pub fn new(subject: impl Into<String>, message: impl Into<String>) -> Self {
        Error { subject: subject.into(), message: message.into() }
    }
    pub fn file(path: &Path, message: impl Into<String>) -> Self {
        Error::new(path.display().to_string(), message)
    }
    /// A problem on one line of a file: prints as `path:line: message`, the position
    /// compilers and HDL tools give, which editors and terminals jump to.
    pub fn file_line(path: &Path, line: usize, message: impl Into<String>) -> Self {
        Error::new(format!("{}:{line}", path.display()), message)
    }
    pub fn param(name: &str, message: impl Into<String>) -> Self {
        Error::new(format!("--{name}"), message)
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // One line, no matter what the message contains.
        let msg = self.message.replace('\n', " ");
        write!(f, "{}: {}", self.subject, msg)
    }
}

impl std::error::Error for Error {}

pub type Result<T> = std::result::Result<T, Error>;
