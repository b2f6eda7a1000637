//! Errors on user input: one message naming the file, the line and the key.

/// A problem in an input file.
#[derive(Clone, Debug, PartialEq)]
pub struct InputError {
    pub file: String,
    /// 1-based line, when it could be found.
    pub line: Option<usize>,
    /// Dotted key path, e.g. `bodies[3].radius` (empty for syntax errors).
    pub key: String,
    pub message: String,
}

impl std::fmt::Display for InputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(l) = self.line {
            write!(f, ":{l}")?;
        }
        if !self.key.is_empty() {
            write!(f, ": key `{}`", self.key)?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for InputError {}

/// 1-based line of a byte offset.
pub fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())].iter().filter(|&&c| c == b'\n').count() + 1
}
