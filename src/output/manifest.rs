//! `manifest.json`: which files of an output directory belong to the run that wrote it, and whether that run
//! finished.
//!
//! Every job ([`RunDir::start`]) first checks that it can write the directory (it creates it and writes and
//! removes a probe file), removes what an earlier run of any job left there ([`RUN_FILES`], temporary files of
//! a killed run; never a file vrw does not write), and writes the manifest with the status `running`. At the
//! end it writes the manifest again with the files that belong to the run and the status `completed`,
//! `interrupted` (Ctrl-C: the files hold the complete part) or `failed` (with the reason). `vrw plot` and
//! `vrw animate` add the figures they write. The content is deterministic (no timestamps), so a repeated run
//! writes the same bytes.
//!
//! The tables that stream rows while a walk runs (`steps.csv`, `trajectory.csv`) are written in place, not
//! under a temporary name: they are listed in the `running` manifest as soon as they are created, so after a
//! kill the directory says the run did not finish, and their complete rows can still be read.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::{ensure_dir, write_json, OutputError, TEMP_MARK};

/// The manifest's file name.
pub const MANIFEST: &str = "manifest.json";

/// Every file a vrw job writes into an output directory; a job removes them all before it starts.
pub const RUN_FILES: [&str; 28] = [
    MANIFEST,
    // simulate, gait
    "steps.csv",
    "trajectory.csv",
    "summary.json",
    "gait.json",
    // sweep
    "sweep.csv",
    "thresholds.json",
    "fig2.svg",
    "fig2.png",
    // map
    "map.csv",
    "curves.json",
    "map.svg",
    "map.png",
    "signatures.svg",
    "signatures.png",
    // orbit
    "orbit.csv",
    "branch.csv",
    "orbit.json",
    "orbit.png",
    // basin
    "basin.csv",
    "basin.json",
    "basin.png",
    // plot, animate
    "run.png",
    "run.svg",
    "steps.png",
    "steps.svg",
    "walk.gif",
    "walk-frame.png",
];

/// How the run that wrote a directory ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RunStatus {
    /// Still running, or killed (the manifest was never rewritten).
    Running,
    /// Every file is complete.
    Completed,
    /// Stopped by Ctrl-C: the files hold what was complete.
    Interrupted,
    /// Stopped by an error (`reason`); the files listed are complete.
    Failed,
}

/// The content of `manifest.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// Version of vrw that wrote the directory.
    pub vrw_version: String,
    /// The job: `simulate`, `gait`, `sweep`, `map`, `orbit` or `basin`.
    pub command: String,
    /// How the run ended.
    pub status: RunStatus,
    /// Why it was interrupted or failed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// The files of the run (and the figures `plot`/`animate` made of it), in the order written.
    pub files: Vec<String>,
}

/// Reading `manifest.json` failed.
#[derive(Debug, thiserror::Error)]
pub enum ManifestError {
    /// There is none.
    #[error(
        "{dir} has no {MANIFEST}: its files are not known to belong to one run (written by hand, by an older \
         vrw, or by a run killed before it started); run the job again"
    )]
    Missing {
        /// The directory.
        dir: PathBuf,
    },
    /// It cannot be read or parsed.
    #[error("cannot read {path}: {message}")]
    Unreadable {
        /// The manifest's path.
        path: PathBuf,
        /// Why.
        message: String,
    },
}

impl Manifest {
    /// Read `dir/manifest.json`.
    pub fn read(dir: &Path) -> Result<Manifest, ManifestError> {
        let path = dir.join(MANIFEST);
        let text = match std::fs::read_to_string(&path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(ManifestError::Missing {
                    dir: dir.to_path_buf(),
                })
            }
            other => other.map_err(|e| ManifestError::Unreadable {
                path: path.clone(),
                message: e.to_string(),
            })?,
        };
        serde_json::from_str(&text).map_err(|e| ManifestError::Unreadable {
            path,
            message: e.to_string(),
        })
    }

    /// Does the run list `file`?
    pub fn lists(&self, file: &str) -> bool {
        self.files.iter().any(|f| f == file)
    }
}

/// An output directory a job is writing, with its manifest.
#[derive(Debug)]
pub struct RunDir {
    dir: PathBuf,
    manifest: Manifest,
}

impl RunDir {
    /// Start a run of `command` in `dir`: create the directory, check that a file can be written there, remove
    /// every file an earlier run left ([`RUN_FILES`] and temporary files), and write the manifest with the
    /// status `running`.
    ///
    /// # Errors
    /// [`OutputError`] naming the directory (or the stale file) when it cannot be created, written or cleared.
    pub fn start(dir: &Path, command: &str) -> Result<RunDir, OutputError> {
        ensure_dir(dir)?;
        probe(dir)?;
        clear(dir)?;
        let run = RunDir {
            dir: dir.to_path_buf(),
            manifest: Manifest {
                vrw_version: env!("CARGO_PKG_VERSION").to_string(),
                command: command.to_string(),
                status: RunStatus::Running,
                reason: None,
                files: Vec::new(),
            },
        };
        run.write()?;
        Ok(run)
    }

    /// Reopen the finished run in `dir` to add figures made of it (`plot`, `animate`).
    pub fn reopen(dir: &Path, manifest: Manifest) -> RunDir {
        RunDir {
            dir: dir.to_path_buf(),
            manifest,
        }
    }

    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Path of `name` in the directory.
    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    /// Record `name` as a file of the run (once).
    pub fn add(&mut self, name: &str) {
        if !self.manifest.lists(name) {
            self.manifest.files.push(name.to_string());
        }
    }

    /// Record files written in place while the run goes on (streamed tables) and rewrite the `running`
    /// manifest at once, so that a kill leaves them listed.
    pub fn add_streaming(&mut self, names: &[&str]) -> Result<(), OutputError> {
        for name in names {
            self.add(name);
        }
        self.write()
    }

    /// Write the manifest with its final `status` (and `reason`).
    pub fn finish(&mut self, status: RunStatus, reason: Option<String>) -> Result<(), OutputError> {
        self.manifest.status = status;
        self.manifest.reason = reason;
        self.write()
    }

    /// Rewrite the manifest as it stands (after [`RunDir::add`] on a reopened run).
    pub fn write(&self) -> Result<(), OutputError> {
        write_json(&self.dir.join(MANIFEST), &self.manifest)
    }
}

/// Write and remove a probe file in `dir`: a read-only directory or a full disk is found before the work.
fn probe(dir: &Path) -> Result<(), OutputError> {
    let path = dir.join(format!(".probe{TEMP_MARK}"));
    let io = |source| OutputError::Io {
        path: dir.to_path_buf(),
        source,
    };
    std::fs::write(&path, b"vrw checks that it can write here\n").map_err(io)?;
    std::fs::remove_file(&path).map_err(io)
}

/// Remove every file of an earlier run from `dir`.
fn clear(dir: &Path) -> Result<(), OutputError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| OutputError::Io { path, source }
    };
    let entries = std::fs::read_dir(dir).map_err(io(dir))?;
    for entry in entries {
        let entry = entry.map_err(io(dir))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let ours = RUN_FILES.contains(&name.as_str())
            || (name.starts_with('.') && name.contains(TEMP_MARK));
        if ours && entry.file_type().map_err(io(dir))?.is_file() {
            let path = entry.path();
            match std::fs::remove_file(&path) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(io(&path)(e)),
                _ => {}
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A new run removes what any earlier job wrote, and nothing else.
    #[test]
    fn start_clears_earlier_runs_only() {
        let dir = tempfile::tempdir().unwrap();
        for f in ["gait.json", "run.png", ".run.vrw-tmp.png", "notes.txt"] {
            std::fs::write(dir.path().join(f), "x").unwrap();
        }
        let mut run = RunDir::start(dir.path(), "sweep").unwrap();
        let left: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        let mut left = left;
        left.sort();
        assert_eq!(left, ["manifest.json", "notes.txt"]);
        assert_eq!(
            Manifest::read(dir.path()).unwrap().status,
            RunStatus::Running
        );
        run.add("sweep.csv");
        run.finish(RunStatus::Completed, None).unwrap();
        let m = Manifest::read(dir.path()).unwrap();
        assert_eq!(
            (m.status, m.files),
            (RunStatus::Completed, vec!["sweep.csv".to_string()])
        );
    }
}
