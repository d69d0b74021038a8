//! The one error type of the crate.
//!
//! Everything wrong with a scene file is an [`Error::Scene`] that points at a line and column of
//! the file, says what was expected and carries the quoted line with a caret under the place.
//! A failure during the integration is not an error: it is the status of the
//! [`Outcome`](crate::Outcome), which keeps the motion computed up to the failure.

use std::ops::Range;
use std::sync::Arc;

use crate::source::{position, snippet};

/// Everything that can go wrong before or after the integration.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The scene file could not be read.
    #[error("cannot read the scene file {path}: {source}; check the path")]
    Read {
        /// The file.
        path: String,
        /// What the operating system said.
        source: std::io::Error,
    },

    /// The scene file is not valid: TOML syntax, a missing or unknown key, a wrong value, an
    /// expression that does not parse or names something unknown, more constraints than
    /// coordinates, or an initial state the model refuses.
    #[error("{path}:{line}:{column}: {message}")]
    Scene {
        /// The file, as given.
        path: String,
        /// Line, from 1.
        line: usize,
        /// Column, from 1, in characters.
        column: usize,
        /// What was wrong and what to write instead.
        message: String,
        /// The line quoted, with a caret under the place (several lines).
        snippet: String,
    },

    /// The scene file is larger than [`MAX_SCENE_BYTES`](crate::scene::MAX_SCENE_BYTES).
    #[error("the scene file {path} is larger than {limit} bytes; a scene is a short text file (is this the right file?)")]
    TooLarge {
        /// The file, as given.
        path: String,
        /// The largest size read.
        limit: u64,
    },

    /// An output file could not be written.
    #[error("cannot write {path}: {reason}; check that the output directory can be created and written (or choose another with --out)")]
    Write {
        /// The file.
        path: String,
        /// What went wrong.
        reason: String,
    },

    /// A sweep that cannot be run as asked (`chetaev sweep`): a variable or quantity given on the
    /// command line that is unknown or malformed, a range that is empty or runs through zero on
    /// a logarithmic scale, more runs than allowed without `--yes`. A mistake in the scene file's
    /// `[sweep]` table is an [`Error::Scene`] at its place.
    #[error("sweep: {message}")]
    Sweep {
        /// What was wrong and what to write instead.
        message: String,
    },

    /// The part files of a sharded sweep cannot be joined ([`chetaev_parts::merge`]).
    #[error("{0}")]
    Parts(String),

    /// The output directory cannot be used: it cannot be created or written, it is a file, or it
    /// holds files this run would leave beside its own or overwrite without having written them.
    #[error("output directory {path}: {reason}")]
    OutputDirectory {
        /// The directory, as resolved.
        path: String,
        /// What is wrong, and what to do.
        reason: String,
    },
}

impl Error {
    /// The quoted line with a caret, for a located error.
    pub fn snippet(&self) -> Option<&str> {
        match self {
            Error::Scene { snippet, .. } => Some(snippet),
            _ => None,
        }
    }

    /// The line and column of a located error.
    pub fn position(&self) -> Option<(usize, usize)> {
        match self {
            Error::Scene { line, column, .. } => Some((*line, *column)),
            _ => None,
        }
    }

    /// The message of a located error, without the position.
    pub fn message(&self) -> String {
        match self {
            Error::Scene { message, .. } => message.clone(),
            other => other.to_string(),
        }
    }
}

/// Something in a scene that is valid but may not be what was meant (an `e` read as Euler's
/// number), located in the file as an [`Error::Scene`] is. The command prints it to standard
/// error and goes on.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{path}:{line}:{column}: {message}")]
pub struct Warning {
    /// The file, as given.
    pub path: String,
    /// Line, from 1.
    pub line: usize,
    /// Column, from 1, in characters.
    pub column: usize,
    /// What may be wrong, and what to write if it is.
    pub message: String,
    /// The line quoted, with a caret under the place (several lines).
    pub snippet: String,
}

/// A scene file's name and text, for locating errors.
#[derive(Clone, Debug)]
pub struct SourceFile {
    /// The path, as given.
    pub path: String,
    /// The whole text.
    pub text: Arc<str>,
}

impl SourceFile {
    /// An [`Error::Scene`] at the byte range `range` of the file.
    pub fn error(&self, range: Range<usize>, message: impl Into<String>) -> Error {
        let p = position(&self.text, range.start);
        Error::Scene {
            path: self.path.clone(),
            line: p.line,
            column: p.column,
            message: message.into(),
            snippet: snippet(&self.text, range),
        }
    }

    /// A [`Warning`] at the byte range `range` of the file.
    pub fn warning(&self, range: Range<usize>, message: impl Into<String>) -> Warning {
        let p = position(&self.text, range.start);
        Warning {
            path: self.path.clone(),
            line: p.line,
            column: p.column,
            message: message.into(),
            snippet: snippet(&self.text, range),
        }
    }
}
