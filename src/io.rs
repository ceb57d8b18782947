//! Output files are written all or nothing. A command's files form an `OutputSet`: each file is
//! staged as a temporary file beside its target (so on the target's file system, where a
//! rename is atomic) as soon as it is added, and only `commit` renames them into place, all of
//! them, once every one is complete. A set dropped without a commit (the command failed) removes
//! what it staged and the folders it created. A rename failing halfway through a commit undoes
//! the renames before it: a file that was replaced gets its old contents back (a hard link to it
//! was taken before the rename), a new one is removed.
//!
//! Every error names the target, never a temporary name.
//!
//! Also where the project's Python tools are (`venv_bins`), for the flows that run them.

use crate::error::{Error, Result};
use std::collections::HashSet;
use std::io::Write;
use std::path::{Path, PathBuf};
use tempfile::TempPath;

/// Modes of output files; temporary files are created private (0600).
const FILE_MODE: u32 = 0o644;
const EXECUTABLE_MODE: u32 = 0o755;
/// Temporary names: hidden, and recognisably fxrt's if a killed process leaves one behind.
const TEMP_PREFIX: &str = ".fxrt-";

/// The files of one command, committed together or not at all (module documentation).
#[must_use = "an output set writes nothing until it is committed"]
#[derive(Debug, Default)]
pub struct OutputSet {
    staged: Vec<Staged>,
    /// The staged targets with their folders resolved: two names of one file are one target.
    targets: HashSet<PathBuf>,
    /// Folders this set created, parents first: removed again (when empty) unless it commits.
    created: Vec<PathBuf>,
}

#[derive(Debug)]
struct Staged {
    tmp: TempPath,
    target: PathBuf,
}

/// A file renamed into place, with the hard link to the file it replaced (if any).
struct Placed {
    target: PathBuf,
    old: Option<TempPath>,
}

impl OutputSet {
    pub fn new() -> OutputSet {
        OutputSet::default()
    }

    /// Files staged so far.
    pub fn len(&self) -> usize {
        self.staged.len()
    }

    pub fn is_empty(&self) -> bool {
        self.staged.is_empty()
    }

    /// Stages `bytes` for `path` (mode 0644), creating its folders.
    pub fn add(&mut self, path: &Path, bytes: &[u8]) -> Result<()> {
        self.stage(path, bytes, FILE_MODE)
    }

    /// Stages a script for `path`, executable (mode 0755).
    pub fn add_executable(&mut self, path: &Path, bytes: &[u8]) -> Result<()> {
        self.stage(path, bytes, EXECUTABLE_MODE)
    }

    /// Stages each (path, contents).
    pub fn extend<P: AsRef<Path>, B: AsRef<[u8]>>(&mut self, files: impl IntoIterator<Item = (P, B)>) -> Result<()> {
        files.into_iter().try_for_each(|(p, b)| self.add(p.as_ref(), b.as_ref()))
    }

    fn stage(&mut self, path: &Path, bytes: &[u8], mode: u32) -> Result<()> {
        check_writable(path)?;
        let name = path.file_name().ok_or_else(|| Error::file(path, "cannot write: not a file name"))?;
        let dir = parent(path);
        self.create_folders(path, dir)?;
        let cannot = |e: std::io::Error| Error::file(path, format!("cannot write: {e}"));
        let key = dir.canonicalize().map_err(cannot)?.join(name);
        if !self.targets.insert(key) {
            return Err(Error::file(path, "is named twice among this command's outputs"));
        }
        // `make_in` with a plain `File`: tempfile's own writers would put the temporary name
        // into the error messages.
        let mut tmp = tempfile::Builder::new()
            .prefix(TEMP_PREFIX)
            .suffix(".tmp")
            .make_in(dir, |p| std::fs::File::options().write(true).create_new(true).open(p))
            .map_err(cannot)?;
        tmp.as_file_mut().write_all(bytes).map_err(cannot)?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            tmp.as_file().set_permissions(std::fs::Permissions::from_mode(mode)).map_err(cannot)?;
        }
        #[cfg(not(unix))]
        let _ = mode;
        // Closed: a sweep stages thousands of files.
        self.staged.push(Staged { tmp: tmp.into_temp_path(), target: path.to_path_buf() });
        Ok(())
    }

    /// Creates the folders of `dir` that do not exist, one by one, remembering each.
    fn create_folders(&mut self, path: &Path, dir: &Path) -> Result<()> {
        let missing: Vec<&Path> = dir.ancestors().take_while(|a| !a.as_os_str().is_empty() && !a.exists()).collect();
        for d in missing.into_iter().rev() {
            match std::fs::create_dir(d) {
                Ok(()) => self.created.push(d.to_path_buf()),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && d.is_dir() => {}
                Err(e) => return Err(Error::file(path, format!("cannot create the folder {}: {e}", d.display()))),
            }
        }
        Ok(())
    }

    /// Renames every staged file into place; on a failure undoes the renames before it.
    pub fn commit(mut self) -> Result<()> {
        let mut placed: Vec<Placed> = Vec::with_capacity(self.staged.len());
        for s in std::mem::take(&mut self.staged) {
            match place(s) {
                Ok(p) => placed.push(p),
                Err(e) => {
                    undo(placed);
                    // The files not yet placed and the folders go when `self` drops.
                    return Err(e);
                }
            }
        }
        // Committed: the folders stay; dropping `placed` removes the links to replaced files.
        self.created.clear();
        Ok(())
    }
}

impl Drop for OutputSet {
    /// Not committed: the staged files go, then the folders made for them (if still empty).
    fn drop(&mut self) {
        self.staged.clear();
        for d in self.created.iter().rev() {
            let _ = std::fs::remove_dir(d);
        }
    }
}

/// Renames `s` over its target, first linking an existing target to a temporary name so it
/// can be restored.
fn place(s: Staged) -> Result<Placed> {
    let old = match std::fs::symlink_metadata(&s.target) {
        Ok(_) => Some(keep_old(&s.target)?),
        Err(_) => None,
    };
    s.tmp.persist(&s.target).map_err(|e| Error::file(&s.target, format!("cannot write: {}", e.error)))?;
    Ok(Placed { target: s.target, old })
}

/// A second name for the file at `target`: a hard link (the target stays in place throughout),
/// or a copy where the file system has no hard links.
fn keep_old(target: &Path) -> Result<TempPath> {
    let link = |p: &Path| match std::fs::hard_link(target, p) {
        Err(e) if e.kind() != std::io::ErrorKind::AlreadyExists => std::fs::copy(target, p).map(|_| ()),
        r => r,
    };
    let kept = tempfile::Builder::new().prefix(TEMP_PREFIX).suffix(".old").make_in(parent(target), link);
    let kept =
        kept.map_err(|e| Error::file(target, format!("cannot replace it (keeping the old file failed): {e}")))?;
    Ok(kept.into_temp_path())
}

/// Puts back what `placed` replaced, last first (so a target placed twice ends as it began).
fn undo(placed: Vec<Placed>) {
    for p in placed.into_iter().rev() {
        match p.old {
            // Renaming within one folder, just done the other way; if even that fails, the
            // old contents stay under their temporary name rather than being deleted.
            Some(old) => {
                if let Err(e) = old.persist(&p.target) {
                    let _ = e.path.keep();
                }
            }
            None => {
                let _ = std::fs::remove_file(&p.target);
            }
        }
    }
}

/// The folder of `path` ("." for a bare file name).
fn parent(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// The nearest existing ancestor of `dir` (itself included) when it is not a folder: what
/// stops `dir` from being created.
fn blocking_file(dir: &Path) -> Option<&Path> {
    let existing = dir.ancestors().find(|a| !a.as_os_str().is_empty() && a.symlink_metadata().is_ok())?;
    (!existing.is_dir()).then_some(existing)
}

/// Refuses a file path that can never be written: a folder, or below a regular file. Only
/// looks (no file is created), so a command can refuse it before it runs.
pub fn check_writable(path: &Path) -> Result<()> {
    if path.is_dir() {
        return Err(Error::file(path, "cannot write: it is a folder"));
    }
    match blocking_file(parent(path)) {
        Some(f) => Err(Error::file(path, format!("cannot write: {} is a file, not a folder", f.display()))),
        None => Ok(()),
    }
}

/// Refuses an output folder that is a file or cannot be created below one. Only looks.
pub fn check_folder(dir: &Path) -> Result<()> {
    match blocking_file(dir) {
        Some(f) if f == dir => Err(Error::file(dir, "is a file, not a folder")),
        Some(f) => Err(Error::file(dir, format!("cannot create the folder: {} is a file, not a folder", f.display()))),
        None => Ok(()),
    }
}

/// Where scripts/install-deps.sh puts the Python tools: `./.venv/bin`, then the source tree's.
pub fn venv_bins() -> [PathBuf; 2] {
    [PathBuf::from(".venv/bin"), Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv/bin")]
}

#[cfg(test)]
mod tests;
