//! Where a run writes, and the manifest that says which files are its own.
//!
//! A run writes its tables and pictures into one directory, and beside them [`MANIFEST`], which
//! lists them. Before integrating, [`Plan::new`] looks at the directory: a file of an earlier run
//! (listed in its manifest) that this run would not write again would be left beside the new ones,
//! and a file this run would write but no manifest lists would be overwritten without having been
//! written by a run. Either is refused unless the run is forced, and then the earlier run's files
//! are removed (only those its manifest lists) and the others overwritten. [`Plan::check_writable`]
//! tries the directory without leaving anything behind, so a run that cannot write its results
//! fails before integrating, not after.

use std::fs;
use std::io::{self, BufWriter, Write};
use std::path::{Component, Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::picture::figure;
use super::table::write_table;
use crate::error::Error;
use crate::run::Outcome;
use crate::scene::Scene;

/// The name of the file listing what a run wrote, in the output directory.
pub const MANIFEST: &str = "manifest.toml";

const WRITTEN_BY: &str = concat!("chetaev ", env!("CARGO_PKG_VERSION"));

/// The manifest: which files a run wrote, for which scene, and how the run ended.
#[derive(Debug, Default, Serialize, Deserialize)]
struct Manifest {
    /// `chetaev` and its version.
    written_by: String,
    /// The scene file, as given to the command.
    scene: String,
    /// How the integration ended.
    status: String,
    /// `false` while the files are being written: a manifest left so was interrupted.
    complete: bool,
    /// The files of the run, in the directory.
    files: Vec<String>,
}

/// What a run will write, where, and what is already there.
#[derive(Clone, Debug)]
pub struct Plan {
    /// The directory, as given (a relative path is relative to the working directory).
    pub dir: PathBuf,
    /// The directory as an absolute path, `.` and `..` resolved, for messages.
    pub resolved: PathBuf,
    /// The files this run writes, tables then pictures, without the manifest.
    pub files: Vec<String>,
    /// Files an earlier run wrote here (its manifest lists them) that this run would not write.
    pub stale: Vec<String>,
    /// Files this run would overwrite that no manifest here lists.
    pub foreign: Vec<String>,
    /// Whether stale files are removed and foreign ones overwritten.
    pub force: bool,
}

/// What [`Plan::write`] did.
#[derive(Clone, Debug)]
pub struct Written {
    /// The directory, as an absolute path.
    pub dir: PathBuf,
    /// The tables and pictures written, in the directory.
    pub files: Vec<PathBuf>,
    /// The manifest listing them.
    pub manifest: PathBuf,
    /// Files of an earlier run removed (only with `force`).
    pub removed: Vec<String>,
}

fn dir_error(path: &Path, reason: impl Into<String>) -> Error {
    Error::OutputDirectory {
        path: path.display().to_string(),
        reason: reason.into(),
    }
}

/// `path` made absolute against the working directory, with `.` and `..` resolved as written.
pub fn resolve(path: &Path) -> PathBuf {
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut out = PathBuf::new();
    for c in absolute.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// A file name a manifest may list: one plain component, so that removing it stays inside the
/// directory.
fn plain_name(name: &str) -> bool {
    let mut c = Path::new(name).components();
    matches!((c.next(), c.next()), (Some(Component::Normal(_)), None))
}

impl Plan {
    /// Looks at `dir` for the files `scene` asks for. Changes nothing. An error if `dir` exists but
    /// is not a directory or cannot be listed, or (unless `force`) if it holds files this run
    /// would leave beside its own or overwrite without a manifest listing them.
    pub fn new(scene: &Scene, dir: &Path, force: bool) -> Result<Self, Error> {
        let files: Vec<String> = scene
            .output
            .tables
            .iter()
            .map(|t| format!("{}.csv", t.name()))
            .chain(
                scene
                    .output
                    .pictures
                    .iter()
                    .map(|p| format!("{}.svg", p.name())),
            )
            .collect();
        let mut plan = Plan {
            dir: dir.to_path_buf(),
            resolved: resolve(dir),
            files,
            stale: Vec::new(),
            foreign: Vec::new(),
            force,
        };
        if plan.is_empty() {
            return Ok(plan);
        }
        match fs::metadata(dir) {
            Ok(m) if m.is_dir() => {}
            Ok(_) => {
                return Err(dir_error(
                    &plan.resolved,
                    "it is a file, not a directory; choose another with --out or output.directory",
                ))
            }
            // Missing, or under a file: `check_writable` says which.
            Err(e)
                if matches!(
                    e.kind(),
                    io::ErrorKind::NotFound | io::ErrorKind::NotADirectory
                ) =>
            {
                return Ok(plan)
            }
            Err(e) => return Err(dir_error(&plan.resolved, e.to_string())),
        }
        let manifest_path = dir.join(MANIFEST);
        let earlier: Option<Manifest> = match fs::read_to_string(&manifest_path) {
            Ok(text) => toml::from_str::<Manifest>(&text)
                .ok()
                .filter(|m| m.written_by.starts_with("chetaev")),
            Err(e) if e.kind() == io::ErrorKind::NotFound => None,
            Err(e) => {
                return Err(dir_error(
                    &plan.resolved,
                    format!("cannot read its {MANIFEST}: {e}"),
                ))
            }
        };
        let listed = |name: &str| {
            earlier
                .as_ref()
                .is_some_and(|m| m.files.iter().any(|f| f == name))
        };
        let exists = |name: &str| dir.join(name).symlink_metadata().is_ok();
        for f in &plan.files {
            if exists(f) && !listed(f) {
                plan.foreign.push(f.clone());
            }
        }
        if earlier.is_none() && exists(MANIFEST) {
            plan.foreign.push(MANIFEST.to_string());
        }
        if let Some(m) = &earlier {
            for f in &m.files {
                if plain_name(f) && !plan.files.contains(f) && exists(f) {
                    plan.stale.push(f.clone());
                }
            }
        }
        let clean = plan.stale.is_empty() && plan.foreign.is_empty();
        if !force && !clean {
            let mut reasons = Vec::new();
            if !plan.stale.is_empty() {
                reasons.push(format!(
                    "it holds {} of an earlier run that this run would not write, and would leave beside \
                     its own ({})",
                    files_word(plan.stale.len()),
                    plan.stale.join(", ")
                ));
            }
            if !plan.foreign.is_empty() {
                reasons.push(format!(
                    "this run would overwrite {} that no {MANIFEST} of an earlier run lists ({})",
                    files_word(plan.foreign.len()),
                    plan.foreign.join(", ")
                ));
            }
            let them = if plan.stale.len() + plan.foreign.len() == 1 {
                "it"
            } else {
                "them"
            };
            let replace = match (plan.stale.is_empty(), plan.foreign.is_empty()) {
                (true, _) => format!("overwrite {them}"),
                (false, true) => format!("remove {them}"),
                (false, false) => "remove the earlier run's files and overwrite the others".into(),
            };
            return Err(dir_error(
                &plan.resolved,
                format!(
                    "{}; choose another directory with --out, remove {them}, or pass --force to \
                     {replace}",
                    reasons.join("; and ")
                ),
            ));
        }
        Ok(plan)
    }

    /// Whether the scene asks for no file (then nothing is written, not even the manifest).
    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }

    /// Tries whether the directory can be created and written, leaving nothing behind: a probe
    /// file in it if it exists, else a probe directory in its nearest existing ancestor.
    pub fn check_writable(&self) -> Result<(), Error> {
        if self.is_empty() {
            return Ok(());
        }
        let probe_name = format!(".chetaev-probe-{}", std::process::id());
        if self.dir.is_dir() {
            let probe = self.dir.join(&probe_name);
            fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&probe)
                .and_then(|_| fs::remove_file(&probe))
                .map_err(|e| dir_error(&self.resolved, format!("it cannot be written: {e}")))?;
            return Ok(());
        }
        let ancestor = self
            .dir
            .ancestors()
            .skip(1)
            .map(|a| {
                if a.as_os_str().is_empty() {
                    Path::new(".")
                } else {
                    a
                }
            })
            .find(|a| a.symlink_metadata().is_ok())
            .unwrap_or(Path::new("."));
        if !ancestor.is_dir() {
            return Err(dir_error(
                &self.resolved,
                format!(
                    "it cannot be created: {} is a file, not a directory",
                    resolve(ancestor).display()
                ),
            ));
        }
        let probe = ancestor.join(&probe_name);
        fs::create_dir(&probe)
            .and_then(|()| fs::remove_dir(&probe))
            .map_err(|e| {
                dir_error(
                    &self.resolved,
                    format!(
                        "it cannot be created in {}: {e}",
                        resolve(ancestor).display()
                    ),
                )
            })
    }

    /// Writes the tables and pictures, and the manifest listing them. The directory is looked at
    /// again first (the integration may have taken long). With `force`, the files of an earlier
    /// run that this one does not write are removed.
    pub fn write(&self, scene: &Scene, out: &Outcome) -> Result<Written, Error> {
        let plan = Plan::new(scene, &self.dir, self.force)?;
        let mut written = Written {
            dir: plan.resolved.clone(),
            files: Vec::new(),
            manifest: plan.dir.join(MANIFEST),
            removed: Vec::new(),
        };
        if plan.is_empty() {
            return Ok(written);
        }
        fs::create_dir_all(&plan.dir)
            .map_err(|e| dir_error(&plan.resolved, format!("it cannot be created: {e}")))?;
        written.dir = fs::canonicalize(&plan.dir).unwrap_or(plan.resolved.clone());
        let write_error = |path: &Path, e: io::Error| Error::Write {
            path: path.display().to_string(),
            reason: e.to_string(),
        };
        for f in &plan.stale {
            let path = plan.dir.join(f);
            fs::remove_file(&path).map_err(|e| write_error(&path, e))?;
            written.removed.push(f.clone());
        }
        let mut manifest = Manifest {
            written_by: WRITTEN_BY.to_string(),
            scene: scene.file.path.clone(),
            status: super::summary::status_text(scene, out),
            complete: false,
            files: plan.files.clone(),
        };
        let manifest_path = written.manifest.clone();
        let save_manifest = |m: &Manifest| -> Result<(), Error> {
            let text = toml::to_string(m).map_err(|e| Error::Write {
                path: manifest_path.display().to_string(),
                reason: e.to_string(),
            })?;
            let text = format!(
                "# The files `chetaev run` wrote here, for the scene below. A later run into this directory\n\
                 # replaces them; it refuses to leave any of them beside its own files unless given --force.\n\
                 {text}"
            );
            fs::write(&manifest_path, text).map_err(|e| write_error(&manifest_path, e))
        };
        // Listed before they are written, so an interrupted run leaves no file unlisted.
        save_manifest(&manifest)?;
        for &t in &scene.output.tables {
            let path = plan.dir.join(format!("{}.csv", t.name()));
            let file = fs::File::create(&path).map_err(|e| write_error(&path, e))?;
            let mut w = BufWriter::new(file);
            write_table(&mut w, scene, out, t)
                .and_then(|()| w.flush())
                .map_err(|e| write_error(&path, e))?;
            written.files.push(path);
        }
        for &p in &scene.output.pictures {
            let path = plan.dir.join(format!("{}.svg", p.name()));
            figure(scene, out, p)
                .save(&path)
                .map_err(|e| Error::Write {
                    path: path.display().to_string(),
                    reason: e.to_string(),
                })?;
            written.files.push(path);
        }
        manifest.complete = true;
        save_manifest(&manifest)?;
        Ok(written)
    }
}

/// "1 file", "2 files".
fn files_word(n: usize) -> String {
    super::summary::count(n, "file", "files")
}
