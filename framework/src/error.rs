//! The library's errors: [`Error`], and what it is made of: bad input
//! ([`InputError`]: one message naming the file, the line and the key; a
//! plugin's [`ParamError`] before the loader locates it), a diverging run
//! ([`Diverged`]: step and body), outputs that cannot be written, and a
//! multi-process run that cannot start. Every fallible function of the library
//! returns one of these, and each converts into [`Error`] with `?`:
//!
//! ```no_run
//! fn simulate(reg: &nscdd::registry::Registry) -> Result<(), nscdd::Error> {
//!     let mut scene = nscdd::scene::load("scene.toml".as_ref(), reg)?; // InputError
//!     scene.world.step()?; // Diverged
//!     Ok(())
//! }
//! ```

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

/// A plugin's key that failed, with the reason (located in the scene file by the
/// loader, which turns it into an [`InputError`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ParamError {
    pub key: String,
    pub msg: String,
}

impl ParamError {
    pub fn new(key: impl Into<String>, msg: impl Into<String>) -> Self {
        ParamError {
            key: key.into(),
            msg: msg.into(),
        }
    }
}

impl std::fmt::Display for ParamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "key `{}`: {}", self.key, self.msg)
    }
}

impl std::error::Error for ParamError {}

/// A step produced a non-finite state.
#[derive(Clone, Debug, PartialEq)]
pub struct Diverged {
    pub step: u64,
    pub body: u32,
    pub message: String,
}

impl std::fmt::Display for Diverged {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "the run diverged at step {}: {}", self.step, self.message)
    }
}

impl std::error::Error for Diverged {}

/// The library's error: whatever stopped a load or a run.
#[derive(Debug)]
pub enum Error {
    /// Bad input (exit 2): file, line, key.
    Input(InputError),
    /// A plugin's parameter outside a scene file (exit 2).
    Param(ParamError),
    /// A non-finite state; what was written so far is kept (exit 1).
    Diverged(Diverged),
    /// An output could not be written (exit 1).
    Io(String),
    /// A multi-process run that cannot start: ranks against the decomposition
    /// (exit 2).
    Ranks(String),
    /// Stopped on request (SIGINT/SIGTERM, [`crate::run::request_stop`]) at the end
    /// of this step, a checkpoint written (exit 130).
    Interrupted(u64),
}

impl Error {
    /// The program's exit status for this error: 2 for bad input, 1 otherwise.
    pub fn exit_code(&self) -> u8 {
        match self {
            Error::Input(_) | Error::Param(_) | Error::Ranks(_) => 2,
            Error::Diverged(_) | Error::Io(_) => 1,
            Error::Interrupted(_) => 130,
        }
    }
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Error::Input(e) => write!(f, "{e}"),
            Error::Param(e) => write!(f, "{e}"),
            Error::Diverged(d) => write!(f, "{d}"),
            Error::Io(m) | Error::Ranks(m) => write!(f, "{m}"),
            Error::Interrupted(step) => write!(
                f,
                "stopped on request at the end of step {step}; checkpoint.json holds that state (continue with --restart)"
            ),
        }
    }
}

impl std::error::Error for Error {}

impl From<InputError> for Error {
    fn from(e: InputError) -> Self {
        Error::Input(e)
    }
}
impl From<ParamError> for Error {
    fn from(e: ParamError) -> Self {
        Error::Param(e)
    }
}
impl From<Diverged> for Error {
    fn from(e: Diverged) -> Self {
        Error::Diverged(e)
    }
}
impl From<std::io::Error> for Error {
    fn from(e: std::io::Error) -> Self {
        Error::Io(e.to_string())
    }
}
