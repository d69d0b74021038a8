//! The scene file: its TOML schema, and its validation into a [`Scene`] ready to solve.
//!
//! The schema is described in `docs/scenes.md`. Every table rejects unknown keys, every value
//! keeps its place in the file, and every mistake is reported at that place.
//!
//! | file | holds |
//! |---|---|
//! | `schema.rs` | the file as written: serde structures, every value with its span |
//! | `spec.rs` | the scene as validated: [`Scene`], [`SolveSpec`], [`EventSpec`], [`OutputSpec`], ... |
//! | `validate.rs` | from one to the other, every mistake located |
//! | `parameters.rs` | `[parameters]` resolved in dependency order, in linear time |

mod parameters;
mod schema;
mod spec;
mod validate;

use std::ops::Range;
use std::path::Path;
use std::sync::Arc;

use chetaev::prelude::Record;

use crate::error::{Error, SourceFile};

pub use spec::{
    EventSpec, GridEnd, MethodSpec, OutputSpec, Picture, Scene, SolveSpec, Table, Times,
};

/// The most times an output grid may have.
pub const MAX_OUTPUT_TIMES: i64 = 10_000_000;

impl Scene {
    /// Reads and validates the scene file at `path`.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, Error> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| Error::Read {
            path: path.display().to_string(),
            source,
        })?;
        Self::parse(&text, &path.display().to_string())
    }

    /// Validates a scene given as text; `path` names it in messages and gives the default output
    /// directory `out/<file stem>`.
    pub fn parse(text: &str, path: &str) -> Result<Self, Error> {
        let file = SourceFile {
            path: path.to_string(),
            text: Arc::from(text),
        };
        let raw: schema::RawScene = toml::from_str(text).map_err(|e| {
            let span = e.span().unwrap_or(0..0);
            file.error(span, validate::toml_message(e.message()))
        })?;
        validate::Builder { file }.build(raw)
    }

    /// `N`, the number of coordinates.
    pub fn n(&self) -> usize {
        self.coordinates.len()
    }

    /// `K`, the number of constraints.
    pub fn k(&self) -> usize {
        self.constraints.len()
    }

    /// What has to be recorded along the motion for the tables and pictures asked for.
    pub fn record(&self) -> Record {
        let tables = self.output.tables.iter().map(|t| t.record());
        let pictures = self.output.pictures.iter().map(|p| p.record());
        tables.chain(pictures).max().unwrap_or(Record::State)
    }

    /// Whether anything is sampled along the motion (a table or a picture other than the events
    /// table). When nothing is, only the start, the end and the events are recorded.
    pub fn samples_motion(&self) -> bool {
        !self.output.pictures.is_empty() || self.output.tables.iter().any(|t| *t != Table::Events)
    }

    pub(crate) fn error_at(&self, range: Range<usize>, message: impl Into<String>) -> Error {
        self.file.error(range, message)
    }
}
