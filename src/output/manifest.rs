//! `manifest.json`: which files of an output directory belong to the run that wrote it, and whether that run
//! finished.
//!
//! Every job first checks that it may write the directory ([`check_out_dir`]: it creates it and writes and
//! removes a probe file; a directory of files vrw did not write is refused, and so is another command's run
//! unless the job is asked to replace it), then ([`RunDir::start`]) removes the earlier run it replaces (the
//! files its manifest lists and those its command writes, [`COMMAND_FILES`], with temporary files of a killed
//! run; never a file vrw does not write), and writes the manifest with the status `running`. At the end it
//! writes the manifest again with the files that belong to the run and the status `completed`, `interrupted`
//! (Ctrl-C: the files hold the complete part) or `failed` (with the reason). `vrw plot` and `vrw animate` add
//! the figures they write. The content is deterministic (no timestamps), so a repeated run writes the same
//! bytes. A second Ctrl-C quits through [`quit_interrupted`], which leaves the run `interrupted`, never
//! `running`.
//!
//! The tables that stream rows while a walk runs (`steps.csv`, `trajectory.csv`) are written in place, not
//! under a temporary name: they are listed in the `running` manifest as soon as they are created, so after a
//! kill the directory says the run did not finish, and their complete rows can still be read.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::{ensure_dir, write_json, OutputError, TEMP_MARK};

/// The manifest's file name.
pub const MANIFEST: &str = "manifest.json";

/// The files each command writes into its output directory (with the figures `plot` and `animate` add to a run
/// of `simulate` or `gait`). A run of a command replaces an earlier run of the same command in its directory:
/// it removes the files the earlier manifest lists and these (a killed run may not have listed them).
pub const COMMAND_FILES: [(&str, &[&str]); 7] = [
    ("simulate", &RUN_FIGURES_OF_WALKS),
    ("gait", &RUN_FIGURES_OF_WALKS),
    (
        "sweep",
        &["sweep.csv", "thresholds.json", "fig2.svg", "fig2.png"],
    ),
    (
        "map",
        &[
            "map.csv",
            "curves.json",
            "map.svg",
            "map.png",
            "signatures.svg",
            "signatures.png",
        ],
    ),
    (
        "orbit",
        &["orbit.csv", "branch.csv", "orbit.json", "orbit.png"],
    ),
    ("basin", &["basin.csv", "basin.json", "basin.png"]),
    (
        "continue",
        &[
            "branch.csv",
            "special_points.json",
            "bifurcation.svg",
            "bifurcation.png",
            "curves.csv",
            "curves.svg",
            "curves.png",
        ],
    ),
];

/// The files of a run of `simulate` or `gait` (`gait.json` only for `gait`), with the figures of `plot` and
/// `animate`.
const RUN_FIGURES_OF_WALKS: [&str; 10] = [
    "steps.csv",
    "trajectory.csv",
    "summary.json",
    "gait.json",
    "run.png",
    "run.svg",
    "steps.png",
    "steps.svg",
    "walk.gif",
    "walk-frame.png",
];

/// The files `command` writes ([`COMMAND_FILES`]; none for a command vrw does not know).
pub fn command_files(command: &str) -> &'static [&'static str] {
    COMMAND_FILES
        .iter()
        .find(|(c, _)| *c == command)
        .map_or(&[], |(_, files)| *files)
}

/// The earlier run a new one replaces in its directory: its command and the files removed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Replaced {
    /// The earlier run's command.
    pub command: String,
    /// The files removed (the manifest itself not counted), in the directory's order.
    pub files: Vec<String>,
}

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
    /// The walker the job ran on, for a walker other than the wheel (`--model`: `simplest`, `compass`,
    /// `telescopic`, or a described walker's name); absent for the wheel, whose manifests are as before.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
    /// How the run ended.
    pub status: RunStatus,
    /// Why it was interrupted or failed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// The files of the run (and the figures `plot`/`animate` made of it), in the order written.
    pub files: Vec<String>,
    /// The earlier run of another command this one replaced (`--overwrite`), with the files removed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replaced: Option<Replaced>,
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
    /// Start a run of `command` in `dir`: check it ([`check_out_dir`]), remove the earlier run it replaces (the
    /// files its manifest lists, the files its command writes, and temporary files of a killed run; never a
    /// file vrw does not write), and write the manifest with the status `running`.
    ///
    /// # Errors
    /// [`OutputError`] naming the directory (or the stale file) when it cannot be created, written or cleared,
    /// or when it holds files vrw did not write, or another command's run without `overwrite`.
    pub fn start(dir: &Path, command: &str, overwrite: bool) -> Result<RunDir, OutputError> {
        RunDir::start_on(dir, command, None, overwrite)
    }

    /// [`RunDir::start`] of a job on the walker `model` (`None`: the wheel), which the manifest names.
    ///
    /// # Errors
    /// As [`RunDir::start`].
    pub fn start_on(
        dir: &Path,
        command: &str,
        model: Option<&str>,
        overwrite: bool,
    ) -> Result<RunDir, OutputError> {
        let replaced = check_out_dir(dir, command, overwrite)?;
        clear(dir, replaced.as_ref())?;
        let run = RunDir {
            dir: dir.to_path_buf(),
            manifest: Manifest {
                vrw_version: env!("CARGO_PKG_VERSION").to_string(),
                command: command.to_string(),
                model: model.map(str::to_string),
                status: RunStatus::Running,
                reason: None,
                files: Vec::new(),
                replaced: replaced.filter(|r| r.command != command),
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

    /// Rewrite the manifest as it stands (after [`RunDir::add`] on a reopened run). A run under way is
    /// recorded for [`quit_interrupted`], which waits for this write to end.
    pub fn write(&self) -> Result<(), OutputError> {
        let mut active = ACTIVE.lock();
        *active = (self.manifest.status == RunStatus::Running)
            .then(|| (self.dir.clone(), self.manifest.clone()));
        write_json(&self.dir.join(MANIFEST), &self.manifest)
    }

    /// The earlier run of another command this one replaced (with `overwrite`), if any.
    pub fn replaced(&self) -> Option<&Replaced> {
        self.manifest.replaced.as_ref()
    }
}

/// The run under way in this process (its directory and manifest as last written), for
/// [`quit_interrupted`]; its lock is held while the manifest is written, so that a quitting process never
/// leaves one half written or overwrites the last word.
struct ActiveRun(std::sync::Mutex<Option<(PathBuf, Manifest)>>);

type ActiveGuard<'a> = std::sync::MutexGuard<'a, Option<(PathBuf, Manifest)>>;

impl ActiveRun {
    /// The record, locked (a panic elsewhere does not make it unusable).
    fn lock(&self) -> ActiveGuard<'_> {
        self.0
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

static ACTIVE: ActiveRun = ActiveRun(std::sync::Mutex::new(None));

/// Quit the process at once with exit `code` (a second Ctrl-C): the manifest of the run under way, if any, is
/// rewritten with the status `interrupted` and `reason`, listing the files complete so far (and the streamed
/// tables, whose rows are complete), and every temporary file being written is removed
/// (`output::remove_temporaries`). The process exits holding the locks, so no other thread writes a
/// manifest after it.
pub fn quit_interrupted(reason: &str, code: i32) -> ! {
    let _held = abandon(&ACTIVE, reason);
    super::remove_temporaries();
    std::process::exit(code)
}

/// Rewrite the run recorded in `active` as `interrupted` (see [`quit_interrupted`]) and remove its temporary
/// files; the record stays locked while the guard lives.
fn abandon<'a>(active: &'a ActiveRun, reason: &str) -> ActiveGuard<'a> {
    let mut guard = active.lock();
    if let Some((dir, mut manifest)) = guard.take() {
        manifest.status = RunStatus::Interrupted;
        manifest.reason = Some(reason.to_string());
        let _ = write_json(&dir.join(MANIFEST), &manifest);
        if let Ok(entries) = std::fs::read_dir(&dir) {
            for entry in entries.flatten() {
                if is_temporary(&entry.file_name().to_string_lossy()) {
                    let _ = std::fs::remove_file(entry.path());
                }
            }
        }
    }
    guard
}

/// Is `name` a temporary file of a vrw job (written there, then renamed into place)?
fn is_temporary(name: &str) -> bool {
    name.starts_with('.') && name.contains(TEMP_MARK)
}

/// The most file names an error or a message lists before it says how many more there are.
const LISTED_FILES: usize = 10;

/// `files` in words: the first ten names and how many more.
pub fn file_list(files: &[String]) -> String {
    crate::fmt::first_of(files, LISTED_FILES, "")
}

/// Check that a job of `command` may write into `dir` before it computes anything: the directory can be
/// created and written (a probe file is written and removed), and it holds nothing that the run would remove
/// without being asked:
///
/// - no `manifest.json` and no files (subdirectories and temporary files of vrw aside): fine;
/// - files but no manifest (or one that cannot be read): refused, naming the files (vrw did not write them,
///   or cannot tell);
/// - the manifest of a run of `command`: fine, the new run replaces it;
/// - the manifest of another command's run: refused unless `overwrite`, naming the files that would be
///   removed.
///
/// Returns the earlier run the new one replaces, with the files it would remove.
///
/// # Errors
/// [`OutputError::Io`] when the directory cannot be created or written, [`OutputError::NotVrwDir`] and
/// [`OutputError::OtherRun`] for the refusals.
pub fn check_out_dir(
    dir: &Path,
    command: &str,
    overwrite: bool,
) -> Result<Option<Replaced>, OutputError> {
    ensure_dir(dir)?;
    probe(dir)?;
    let files = plain_files(dir)?;
    let manifest = match Manifest::read(dir) {
        Ok(m) => m,
        Err(ManifestError::Missing { .. }) if files.is_empty() => return Ok(None),
        Err(e) => {
            return Err(OutputError::NotVrwDir {
                dir: dir.to_path_buf(),
                files: file_list(&files),
                why: match e {
                    ManifestError::Missing { .. } => "it has no manifest.json".to_string(),
                    other => other.to_string(),
                },
            })
        }
    };
    let removed = files_of_run(&manifest, &files);
    let replaced = Replaced {
        command: manifest.command.clone(),
        files: removed,
    };
    if manifest.command != command && !overwrite {
        return Err(OutputError::OtherRun {
            dir: dir.to_path_buf(),
            command: manifest.command,
            files: file_list(&replaced.files),
        });
    }
    Ok(Some(replaced))
}

/// The regular files in `dir` (not its subdirectories, nor vrw's temporary files), by name.
fn plain_files(dir: &Path) -> Result<Vec<String>, OutputError> {
    let io = |source| OutputError::Io {
        path: dir.to_path_buf(),
        source,
    };
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(io)? {
        let entry = entry.map_err(io)?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if !entry.file_type().map_err(io)?.is_dir() && !is_temporary(&name) {
            files.push(name);
        }
    }
    files.sort();
    Ok(files)
}

/// Of the `files` in a directory whose manifest is `manifest`, those of its run: listed in it, or written by
/// its command (a killed run may not have listed them); the manifest itself not counted.
fn files_of_run(manifest: &Manifest, files: &[String]) -> Vec<String> {
    let ours = command_files(&manifest.command);
    files
        .iter()
        .filter(|f| *f != MANIFEST && (manifest.lists(f) || ours.contains(&f.as_str())))
        .cloned()
        .collect()
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

/// Remove the earlier run `replaced` in `dir` ([`check_out_dir`]'s answer: the files of its run, and its
/// manifest) and vrw's temporary files.
fn clear(dir: &Path, replaced: Option<&Replaced>) -> Result<(), OutputError> {
    if let Some(replaced) = replaced {
        for name in replaced.files.iter().map(String::as_str).chain([MANIFEST]) {
            let path = dir.join(name);
            match std::fs::remove_file(&path) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    return Err(OutputError::Io { path, source: e })
                }
                _ => {}
            }
        }
    }
    remove_temporary(dir)
}

/// Remove vrw's temporary files from `dir` (a killed run's).
fn remove_temporary(dir: &Path) -> Result<(), OutputError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| OutputError::Io { path, source }
    };
    for entry in std::fs::read_dir(dir).map_err(io(dir))? {
        let entry = entry.map_err(io(dir))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if is_temporary(&name) && entry.file_type().map_err(io(dir))?.is_file() {
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

    fn names(dir: &Path) -> Vec<String> {
        let mut left: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        left
    }

    fn write(dir: &Path, files: &[&str]) {
        for f in files {
            std::fs::write(dir.join(f), "x").unwrap();
        }
    }

    /// A run of `command` in `dir` that wrote `files` and finished.
    fn finished_run(dir: &Path, command: &str, files: &[&str]) {
        let mut run = RunDir::start(dir, command, false).unwrap();
        write(dir, files);
        for f in files {
            run.add(f);
        }
        run.finish(RunStatus::Completed, None).unwrap();
    }

    /// A directory of files vrw did not write (no manifest) is refused, naming them, and nothing is removed
    /// (a user's `fig2.png`, `map.csv`, `basin.png` and `run.svg` were deleted by `vrw gait --out mydir`).
    #[test]
    fn files_without_a_manifest_are_refused_and_kept() {
        let dir = tempfile::tempdir().unwrap();
        let mine = ["basin.png", "fig2.png", "map.csv", "run.svg"];
        write(dir.path(), &mine);
        for command in ["gait", "sweep"] {
            for overwrite in [false, true] {
                let e = RunDir::start(dir.path(), command, overwrite).unwrap_err();
                assert!(matches!(e, OutputError::NotVrwDir { .. }), "{e}");
                assert!(
                    e.to_string()
                        .contains("basin.png, fig2.png, map.csv, run.svg"),
                    "{e}"
                );
            }
        }
        assert_eq!(names(dir.path()), mine);
        // Subdirectories and vrw's own temporary files are no reason to refuse.
        let empty = tempfile::tempdir().unwrap();
        std::fs::create_dir(empty.path().join("sub")).unwrap();
        write(empty.path(), &[".run.vrw-tmp.png"]);
        RunDir::start(empty.path(), "gait", false).unwrap();
        assert_eq!(names(empty.path()), ["manifest.json", "sub"]);
    }

    /// A run replaces the same command's earlier run (the files its manifest lists and the files the command
    /// writes, which a killed run may not have listed), and leaves every other file.
    #[test]
    fn a_run_replaces_its_own_commands_run_only() {
        let dir = tempfile::tempdir().unwrap();
        finished_run(
            dir.path(),
            "sweep",
            &["sweep.csv", "thresholds.json", "fig2.png"],
        );
        write(dir.path(), &["notes.txt", "fig2.svg", ".fig2.vrw-tmp.svg"]);
        let run = RunDir::start(dir.path(), "sweep", false).unwrap();
        assert_eq!(run.replaced(), None);
        assert_eq!(names(dir.path()), ["manifest.json", "notes.txt"]);
        assert_eq!(
            Manifest::read(dir.path()).unwrap().status,
            RunStatus::Running
        );
    }

    /// Another command's run is refused without `overwrite` (`vrw sweep --out s; vrw gait --out s` removed
    /// the sweep without a word); with it, its files are removed and listed in the new manifest.
    #[test]
    fn another_commands_run_needs_overwrite() {
        let dir = tempfile::tempdir().unwrap();
        finished_run(dir.path(), "sweep", &["sweep.csv", "thresholds.json"]);
        write(dir.path(), &["notes.txt"]);
        let e = RunDir::start(dir.path(), "gait", false).unwrap_err();
        assert!(matches!(e, OutputError::OtherRun { .. }), "{e}");
        assert!(e.to_string().contains("sweep.csv, thresholds.json"), "{e}");
        assert_eq!(
            names(dir.path()),
            ["manifest.json", "notes.txt", "sweep.csv", "thresholds.json"]
        );
        let checked = check_out_dir(dir.path(), "gait", true).unwrap().unwrap();
        let mut run = RunDir::start(dir.path(), "gait", true).unwrap();
        let replaced = Replaced {
            command: "sweep".to_string(),
            files: vec!["sweep.csv".to_string(), "thresholds.json".to_string()],
        };
        assert_eq!(
            (checked, run.replaced()),
            (replaced.clone(), Some(&replaced))
        );
        assert_eq!(names(dir.path()), ["manifest.json", "notes.txt"]);
        run.finish(RunStatus::Completed, None).unwrap();
        assert_eq!(Manifest::read(dir.path()).unwrap().replaced, Some(replaced));
    }

    /// A manifest that cannot be read does not say which files are vrw's: refused.
    #[test]
    fn an_unreadable_manifest_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join(MANIFEST), "{ not json").unwrap();
        write(dir.path(), &["sweep.csv"]);
        let e = RunDir::start(dir.path(), "sweep", true).unwrap_err();
        assert!(matches!(e, OutputError::NotVrwDir { .. }), "{e}");
        assert_eq!(names(dir.path()), ["manifest.json", "sweep.csv"]);
    }

    /// A second Ctrl-C leaves the run under way `interrupted`, never `running`, and no temporary file.
    #[test]
    fn an_abandoned_run_says_interrupted() {
        let dir = tempfile::tempdir().unwrap();
        let mut run = RunDir::start(dir.path(), "simulate", false).unwrap();
        run.add_streaming(&["steps.csv"]).unwrap();
        write(dir.path(), &["steps.csv", ".summary.vrw-tmp.json"]);
        // The process's record is shared by the tests running beside this one: a record of its own.
        let active = ActiveRun(std::sync::Mutex::new(None));
        *active.lock() = Some((run.dir.clone(), run.manifest.clone()));
        drop(abandon(&active, "quit at once"));
        let m = Manifest::read(dir.path()).unwrap();
        assert_eq!(
            (m.status, m.reason.as_deref(), m.files),
            (
                RunStatus::Interrupted,
                Some("quit at once"),
                vec!["steps.csv".to_string()]
            )
        );
        assert_eq!(names(dir.path()), ["manifest.json", "steps.csv"]);
    }
}
