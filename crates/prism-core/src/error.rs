//! Errors that reach the user: one message, the place in the input it concerns, and what to do.
//!
//! Every error Prism reports for bad input carries a [`SourceLocation`] (file, line and column) when
//! there is one, so that a user can go straight to the offending element. Input errors make the
//! program exit with status 2 ([`ErrorKind::exit_code`]); internal failures such as an unwritable
//! output file exit with 1.

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A place in an input file: 1-based line and column; or, for a scene given as a dictionary,
/// the key path of the entry (`scene.sphere.bsdf.reflectance`) as the file, with line and
/// column 0.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct SourceLocation {
    pub file: Arc<Path>,
    pub line: u32,
    pub column: u32,
}

impl SourceLocation {
    pub fn new(file: impl Into<PathBuf>, line: u32, column: u32) -> Self {
        SourceLocation {
            file: Arc::from(file.into().into_boxed_path()),
            line,
            column,
        }
    }

    /// The entry of a dictionary at `key_path` (keys joined by dots).
    pub fn key_path(key_path: &str) -> Self {
        SourceLocation::new(key_path, 0, 0)
    }

    /// Whether this is a dictionary's key path rather than a place in a file.
    pub fn is_key_path(&self) -> bool {
        self.line == 0
    }
}

impl fmt::Display for SourceLocation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_key_path() {
            write!(f, "{}", self.file.display())
        } else {
            write!(f, "{}:{}:{}", self.file.display(), self.line, self.column)
        }
    }
}

/// What went wrong, broadly: it decides the exit status.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorKind {
    /// The scene, a file it references, or a command-line argument is invalid.
    Input,
    /// Reading or writing a file failed for reasons outside the input's content.
    Io,
}

impl ErrorKind {
    /// Exit status of the command line program for this kind of error.
    pub fn exit_code(self) -> i32 {
        match self {
            ErrorKind::Input => 2,
            ErrorKind::Io => 1,
        }
    }
}

/// An error with a location, a message and an optional hint on how to fix it.
#[derive(Clone, Debug)]
pub struct Error {
    pub kind: ErrorKind,
    pub location: Option<SourceLocation>,
    pub message: String,
    pub help: Option<String>,
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// Invalid input at a known place.
    pub fn input(location: &SourceLocation, message: impl Into<String>) -> Self {
        Error {
            kind: ErrorKind::Input,
            location: Some(location.clone()),
            message: message.into(),
            help: None,
        }
    }

    /// Invalid input with no place in a file (a command-line argument, say).
    pub fn usage(message: impl Into<String>) -> Self {
        Error {
            kind: ErrorKind::Input,
            location: None,
            message: message.into(),
            help: None,
        }
    }

    /// A failure to read or write a file.
    pub fn io(path: &Path, err: &std::io::Error, doing: &str) -> Self {
        Error {
            kind: ErrorKind::Io,
            location: None,
            message: format!("could not {doing} \"{}\": {err}", path.display()),
            help: None,
        }
    }

    /// Adds a sentence telling the user what to do.
    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    /// Turns into an input error (for files that the scene references, whose absence is the
    /// scene's fault) and gives it the location of the referencing element.
    pub fn at(mut self, location: &SourceLocation) -> Self {
        self.kind = ErrorKind::Input;
        if self.location.is_none() {
            self.location = Some(location.clone());
        }
        self
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(location) = &self.location {
            write!(f, "{location}: ")?;
        }
        write!(f, "{}", self.message)?;
        if let Some(help) = &self.help {
            write!(f, "\n  help: {help}")?;
        }
        Ok(())
    }
}

impl std::error::Error for Error {}
