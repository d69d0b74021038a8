//! The scene file: its TOML schema, and its validation into a [`Scene`] ready to solve.
//!
//! The schema is described in `docs/scenes.md`. Every table rejects unknown keys, every value
//! keeps its place in the file, and every mistake is reported at that place.
//!
//! | file | holds |
//! |---|---|
//! | `schema.rs` | the file as written: serde structures, every value with its span |
//! | `spec.rs` | the scene as validated: [`Scene`], [`SolveSpec`], [`EventSpec`], [`OutputSpec`], [`Units`], ... |
//! | `validate.rs` | from one to the other, every mistake located |
//! | `parameters.rs` | `[parameters]` resolved in dependency order, in linear time, with the rates of those computed from parameters asked for |
//! | `sensitivities.rs` | `[sensitivities]`: one seed per parameter asked for, with the rates of the initial values |

mod parameters;
mod schema;
mod sensitivities;
mod spec;
mod validate;
pub(crate) use schema::{Number, RawScene, RawSweep};
pub(crate) use validate::adaptive_methods;

use std::io::Read as _;
use std::ops::Range;
use std::path::Path;
use std::sync::Arc;

use chetaev::prelude::Record;

use crate::error::{Error, SourceFile};

pub use spec::{
    EventSpec, GridEnd, LoadSpec, OutputSpec, Picture, Scene, SensitivitySpec, SolveSpec, Table,
    Times, Units,
};

/// The most times an output grid may have.
pub const MAX_OUTPUT_TIMES: i64 = 10_000_000;

/// The largest scene file read, 16 MiB: far more than any scene needs (20 000 parameters take
/// about 400 KiB), and a bound on what a wrong path can make the command read.
pub const MAX_SCENE_BYTES: u64 = 16 * 1024 * 1024;

impl Scene {
    /// Reads and validates the scene file at `path`. At most [`MAX_SCENE_BYTES`] are read, so a
    /// path to an endless stream (`/dev/zero`, a pipe) is refused instead of filling the memory.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, Error> {
        let path = path.as_ref();
        let text = read_text(path)?;
        Self::parse(&text, &path.display().to_string())
    }

    /// Validates a scene given as text; `path` names it in messages and gives the default output
    /// directory `out/<file stem>`. A text longer than [`MAX_SCENE_BYTES`] is refused.
    pub fn parse(text: &str, path: &str) -> Result<Self, Error> {
        let (file, raw) = Self::read_raw(text, path)?;
        Self::build(file, raw)
    }

    /// The scene as written: its TOML read into the raw structures, unchecked but for its size
    /// (at most [`MAX_SCENE_BYTES`]).
    pub(crate) fn read_raw(text: &str, path: &str) -> Result<(SourceFile, RawScene), Error> {
        if text.len() as u64 > MAX_SCENE_BYTES {
            return Err(Error::TooLarge {
                path: path.to_string(),
                limit: MAX_SCENE_BYTES,
            });
        }
        let file = SourceFile {
            path: path.to_string(),
            text: Arc::from(text),
        };
        let raw: RawScene = toml::from_str(text).map_err(|e| {
            let span = e.span().unwrap_or(0..0);
            file.error(span, validate::toml_message(e.message()))
        })?;
        Ok((file, raw))
    }

    /// The scene as written, validated.
    pub(crate) fn build(file: SourceFile, raw: RawScene) -> Result<Self, Error> {
        validate::Builder {
            file,
            warnings: Default::default(),
        }
        .build(raw)
    }

    /// `N`, the number of coordinates.
    pub fn n(&self) -> usize {
        self.coordinates.len()
    }

    /// `K`, the number of constraints: the velocity constraints, then the holonomic ones (whose
    /// multipliers follow in `μ`).
    pub fn k(&self) -> usize {
        self.constraints.len() + self.holonomic.len()
    }

    /// What has to be recorded along the motion for the tables and pictures asked for.
    pub fn record(&self) -> Record {
        let tables = self.output.tables.iter().map(|t| t.record());
        let pictures = self.output.pictures.iter().map(|p| p.record());
        // Output quantities that read `μ` or `Φ`, and the sensitivities of `μ` and `Φ` (with
        // constraints), need them recorded.
        let quantities = self.output.tables.contains(&Table::Quantities)
            || self.output.pictures.contains(&Picture::Quantities);
        let reads = quantities
            && self
                .output
                .quantities
                .iter()
                .any(|(_, e)| e.reads_recorded());
        let sensitivities = self.output.tables.contains(&Table::Sensitivities) && self.k() > 0;
        let dynamics = (reads || sensitivities).then_some(Record::Dynamics);
        tables
            .chain(pictures)
            .chain(dynamics)
            .max()
            .unwrap_or(Record::State)
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

/// The text of the scene file at `path`: at most [`MAX_SCENE_BYTES`], UTF-8.
pub(crate) fn read_text(path: &Path) -> Result<String, Error> {
    let name = path.display().to_string();
    let read_error = |source| Error::Read {
        path: name.clone(),
        source,
    };
    let file = std::fs::File::open(path).map_err(read_error)?;
    let mut bytes = Vec::new();
    file.take(MAX_SCENE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(read_error)?;
    if bytes.len() as u64 > MAX_SCENE_BYTES {
        return Err(Error::TooLarge {
            path: name,
            limit: MAX_SCENE_BYTES,
        });
    }
    let text = String::from_utf8(bytes).map_err(|e| {
        // Located in the text read so far, as a scene error is.
        let at = e.utf8_error().valid_up_to();
        let shown = String::from_utf8_lossy(e.as_bytes());
        let file = SourceFile {
            path: name.clone(),
            text: Arc::from(shown.as_ref()),
        };
        file.error(
            at..at + 1,
            "this byte is not UTF-8 text; a scene file is TOML, which is UTF-8: save it as \
             UTF-8 (most editors offer it under the file's encoding)",
        )
    })?;
    Ok(text)
}
