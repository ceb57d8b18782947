//! The one code writer both printers write through: lines, indentation, comments.

/// Text built a line at a time, each line indented by two spaces per level.
pub struct CodeWriter {
    text: String,
    level: usize,
    /// The comment leader of the language ("--" or "//").
    leader: &'static str,
}

impl CodeWriter {
    pub fn new(leader: &'static str) -> CodeWriter {
        CodeWriter { text: String::new(), level: 0, leader }
    }

    /// One line at the current indentation (an empty `s` gives an empty line).
    pub fn line(&mut self, s: impl AsRef<str>) {
        let s = s.as_ref();
        if !s.is_empty() {
            (0..self.level).for_each(|_| self.text.push_str("  "));
            self.text.push_str(s);
        }
        self.text.push('\n');
    }

    /// An empty line (never two in a row, never at the start).
    pub fn blank(&mut self) {
        if !self.text.is_empty() && !self.text.ends_with("\n\n") {
            self.text.push('\n');
        }
    }

    /// A comment line.
    pub fn comment(&mut self, s: impl AsRef<str>) {
        self.line(format!("{} {}", self.leader, s.as_ref()));
    }

    /// `s` followed by a trailing comment (`s` alone without one).
    pub fn commented(&mut self, s: impl AsRef<str>, comment: Option<&str>) {
        match comment {
            Some(c) => self.line(format!("{}  {} {c}", s.as_ref(), self.leader)),
            None => self.line(s),
        }
    }

    /// A line that opens a construct: the lines after it are one level deeper (an empty `s`
    /// only indents).
    pub fn open(&mut self, s: impl AsRef<str>) {
        if !s.as_ref().is_empty() {
            self.line(s);
        }
        self.level += 1;
    }

    /// A line that closes the construct `open` began (an empty `s` only unindents).
    pub fn close(&mut self, s: impl AsRef<str>) {
        self.level -= 1;
        if !s.as_ref().is_empty() {
            self.line(s);
        }
    }

    /// `open`, then what `body` writes one level deeper, then `close` (either may be empty).
    pub fn nest(&mut self, open: impl AsRef<str>, close: impl AsRef<str>, body: impl FnOnce(&mut CodeWriter)) {
        self.open(open);
        body(self);
        self.close(close);
    }

    /// What `body` writes, one level deeper.
    pub fn indented(&mut self, body: impl FnOnce(&mut CodeWriter)) {
        self.level += 1;
        body(self);
        self.level -= 1;
    }

    pub fn finish(self) -> String {
        self.text
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indents_nests_and_comments() {
        let mut w = CodeWriter::new("--");
        w.blank();
        w.comment("top");
        w.nest("begin", "end", |w| {
            w.line("a;");
            w.commented("b;", Some("why"));
            w.blank();
            w.blank();
            w.indented(|w| w.line("c;"));
            w.open("if");
            w.line("d;");
            w.close("end if;");
        });
        assert_eq!(w.finish(), "-- top\nbegin\n  a;\n  b;  -- why\n\n    c;\n  if\n    d;\n  end if;\nend\n");
    }
}
