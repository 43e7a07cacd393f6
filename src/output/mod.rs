//! Output: tables a script can read (CSV, JSON) and figures a person can look at (STYLE.md point 12).
//!
//! This file holds the shared CSV and JSON writing; each table's columns and writer are declared once in
//! `tables`, each figure has its own file.
//!
//! Every file is written atomically ([`write_atomic`]: under a temporary name in the same directory, then
//! renamed), so a reader never sees half a file under its real name; the tables that stream rows as a walk runs
//! (`steps.csv`, `trajectory.csv`) are the exception, written in place, and the run's `manifest.json`
//! ([`manifest`]) says whether they are complete.
//!
//! Numbers are written with Rust's shortest round-trip formatting, so a value read back is bit-identical;
//! undefined values (e.g. `lambda_2+` after an (A3) exchange) are written as `NaN` in CSV and `null` in JSON.

pub mod animate;
pub(crate) mod basin_plot;
pub(crate) mod bifurcation_plot;
pub(crate) mod chart;
pub mod manifest;
pub mod map_plot;
pub(crate) mod orbit_plot;
pub(crate) mod plot;
pub mod read;
pub mod run_plot;
pub(crate) mod signature_plot;
pub mod steps_plot;
pub mod style;
pub(crate) mod tables;
pub(crate) mod walker_map_plot;
pub mod walker_plot;
pub mod walker_run;

pub use tables::attractors::{
    basin_header, basin_row, branch_header, branch_rows, orbit_header, orbit_rows,
};
pub(crate) use tables::attractors::{write_basin_csv, write_branch_csv, write_orbit_csv};
pub use tables::family::{curve_header, curve_row, family_header, family_row, CurveRow, FamilyRow};
pub(crate) use tables::family::{write_curves_csv, write_family_csv};
pub(crate) use tables::map::write_map_csv;
pub use tables::map::{map_header, map_rows};
pub use tables::steps::{
    step_row, steps_header, steps_row, write_steps_csv, StepsColumns, StepsCsv, STEPS_HEADER,
};
pub use tables::sweep::{
    friction_columns, sweep_header, sweep_row, write_sweep_csv, SWEEP_COLUMNS,
};
pub use tables::trajectory::{
    trajectory_header, trajectory_row, trajectory_row_under, write_trajectory_csv, TrajectoryCsv,
    TRAJECTORY_HEADER,
};
pub use tables::Cell;

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use serde::Serialize;

/// Writing a result file failed.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The file or directory could not be created or written.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The path.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// CSV encoding failed.
    #[error("cannot write CSV {path}: {source}")]
    Csv {
        /// The path.
        path: PathBuf,
        /// Why.
        source: csv::Error,
    },
    /// The output directory names an existing file.
    #[error("output directory {path} is an existing file, not a directory: choose another `out`")]
    NotADirectory {
        /// The path.
        path: PathBuf,
    },
    /// JSON encoding failed.
    #[error("cannot write JSON {path}: {source}")]
    Json {
        /// The path.
        path: PathBuf,
        /// Why.
        source: serde_json::Error,
    },
    /// The output directory holds files and no readable manifest: vrw did not write them (or cannot tell), and
    /// removes nothing it did not write.
    #[error(
        "output directory {dir} holds files vrw did not write ({why}): {files}; choose another `out` (vrw \
         never removes a file it did not write)"
    )]
    NotVrwDir {
        /// The directory.
        dir: PathBuf,
        /// Its files, in words.
        files: String,
        /// Why they are not vrw's (no manifest, or an unreadable one).
        why: String,
    },
    /// The output directory holds a run of another command.
    #[error(
        "output directory {dir} holds a run of `vrw {command}` ({files}): give `overwrite` to replace it, or \
         choose another `out`"
    )]
    OtherRun {
        /// The directory.
        dir: PathBuf,
        /// The other run's command.
        command: String,
        /// The files that would be removed, in words.
        files: String,
    },
}

/// A number as written in CSV: the shortest text that reads back to the same `f64`, in scientific notation
/// when very small or very large; `NaN` for undefined values.
pub(crate) fn num(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 {
        "0".to_string()
    } else if (1e-4..1e15).contains(&a) {
        v.to_string()
    } else {
        format!("{v:e}")
    }
}

/// Create `dir` (and its parents) if needed; a `dir` that is an existing file is refused.
pub(crate) fn ensure_dir(dir: &Path) -> Result<(), OutputError> {
    if dir.exists() && !dir.is_dir() {
        return Err(OutputError::NotADirectory {
            path: dir.to_path_buf(),
        });
    }
    std::fs::create_dir_all(dir).map_err(|source| OutputError::Io {
        path: dir.to_path_buf(),
        source,
    })
}

/// Open a CSV writer on `path`.
pub(crate) fn csv_writer(path: &Path) -> Result<csv::Writer<File>, OutputError> {
    csv::Writer::from_path(path).map_err(|source| OutputError::Csv {
        path: path.to_path_buf(),
        source,
    })
}

/// Write one CSV record, mapping errors to [`OutputError`].
pub(crate) fn write_record<I, T>(
    w: &mut csv::Writer<File>,
    path: &Path,
    record: I,
) -> Result<(), OutputError>
where
    I: IntoIterator<Item = T>,
    T: AsRef<[u8]>,
{
    w.write_record(record).map_err(|source| OutputError::Csv {
        path: path.to_path_buf(),
        source,
    })
}

/// Flush a CSV writer.
pub(crate) fn finish_csv(mut w: csv::Writer<File>, path: &Path) -> Result<(), OutputError> {
    w.flush().map_err(|source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// The temporary name under which `path` is written before it is renamed: `.NAME.vrw-tmp.EXT` in the same
/// directory (the extension is kept, since figure writers choose the format by it).
pub fn temp_path(path: &Path) -> PathBuf {
    let stem = path
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let name = match path.extension() {
        Some(ext) => format!(".{stem}{TEMP_MARK}.{}", ext.to_string_lossy()),
        None => format!(".{stem}{TEMP_MARK}"),
    };
    path.with_file_name(name)
}

/// What marks a temporary file name ([`temp_path`]); a job removes such files left by a killed run.
pub const TEMP_MARK: &str = ".vrw-tmp";

/// Write `path` atomically: `write` writes the temporary file [`temp_path`]`(path)`, which is renamed to
/// `path` when `write` succeeds and removed when it fails. A reader sees the old file or the whole new one,
/// never a part.
pub fn write_atomic<T, E: From<OutputError>>(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<T, E>,
) -> Result<T, E> {
    let temp = temp_path(path);
    let _registered = Temporary::register(&temp);
    match write(&temp) {
        Ok(value) => {
            std::fs::rename(&temp, path).map_err(|source| {
                let _ = std::fs::remove_file(&temp);
                OutputError::Io {
                    path: path.to_path_buf(),
                    source,
                }
            })?;
            Ok(value)
        }
        Err(e) => {
            let _ = std::fs::remove_file(&temp);
            Err(e)
        }
    }
}

/// The temporary files being written in this process ([`write_atomic`]), for [`remove_temporaries`].
static TEMPORARIES: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Set once [`remove_temporaries`] runs: the process is about to exit, and no new temporary file is started.
static QUITTING: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// A temporary file registered in [`TEMPORARIES`] while it exists; unregistered when dropped.
struct Temporary(PathBuf);

impl Temporary {
    /// Register `path` before it is written. Once the process quits ([`remove_temporaries`]), the writer waits
    /// here for the exit instead: a file it would start could be left behind.
    fn register(path: &Path) -> Temporary {
        if let Ok(mut all) = TEMPORARIES.lock() {
            if QUITTING.load(std::sync::atomic::Ordering::SeqCst) {
                drop(all);
                loop {
                    std::thread::park();
                }
            }
            all.push(path.to_path_buf());
        }
        Temporary(path.to_path_buf())
    }
}

impl Drop for Temporary {
    fn drop(&mut self) {
        if let Ok(mut all) = TEMPORARIES.lock() {
            if let Some(i) = all.iter().position(|p| *p == self.0) {
                all.swap_remove(i);
            }
        }
    }
}

/// How long [`remove_temporaries`] waits for the writers of temporary files to give up.
const QUIT_WAIT: std::time::Duration = std::time::Duration::from_secs(1);

/// Remove every temporary file this process is writing (a second Ctrl-C, just before the process exits, so
/// that no half-written file is left behind). No temporary file is started after it; a writer already under
/// way may create its file after a removal (it was registered, then preempted before creating it), so the
/// removal is repeated every millisecond until every writer has given up (its file removed, its rename then
/// failing) or finished (the whole file in place), for at most [`QUIT_WAIT`].
pub(crate) fn remove_temporaries() {
    QUITTING.store(true, std::sync::atomic::Ordering::SeqCst);
    let deadline = std::time::Instant::now() + QUIT_WAIT;
    loop {
        let all = TEMPORARIES
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        for path in all.iter() {
            let _ = std::fs::remove_file(path);
        }
        if all.is_empty() || std::time::Instant::now() >= deadline {
            return;
        }
        drop(all);
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
}

/// Write `value` as pretty JSON to `path` (atomically).
pub fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<(), OutputError> {
    write_atomic(path, |temp| write_json_in_place(temp, value))
        .map_err(|e| e.renamed(temp_path(path).as_path(), path))
}

fn write_json_in_place<T: Serialize>(path: &Path, value: &T) -> Result<(), OutputError> {
    let io = |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut w = BufWriter::new(File::create(path).map_err(io)?);
    serde_json::to_writer_pretty(&mut w, value).map_err(|source| OutputError::Json {
        path: path.to_path_buf(),
        source,
    })?;
    writeln!(w).map_err(io)?;
    w.flush().map_err(io)?;
    w.get_ref().sync_all().map_err(io)
}

impl OutputError {
    /// The same error, naming `to` where it named the temporary file `from`.
    fn renamed(self, from: &Path, to: &Path) -> OutputError {
        let fix = |p: PathBuf| if p == from { to.to_path_buf() } else { p };
        match self {
            OutputError::Io { path, source } => OutputError::Io {
                path: fix(path),
                source,
            },
            OutputError::Csv { path, source } => OutputError::Csv {
                path: fix(path),
                source,
            },
            OutputError::Json { path, source } => OutputError::Json {
                path: fix(path),
                source,
            },
            other => other,
        }
    }
}

/// Write a CSV table atomically: the header, then one record per row.
pub fn write_table<H, R>(path: &Path, header: &[H], rows: R) -> Result<(), OutputError>
where
    H: AsRef<[u8]>,
    R: IntoIterator<Item = Vec<Cell>>,
{
    write_atomic(path, |temp| {
        let mut w = csv_writer(temp)?;
        write_record(&mut w, temp, header)?;
        for row in rows {
            write_record(&mut w, temp, row.iter().map(Cell::to_csv))?;
        }
        finish_csv(w, temp)
    })
    .map_err(|e| e.renamed(temp_path(path).as_path(), path))
}

/// A CSV file written row by row: each row is flushed to the file as soon as it is written, so an
/// interrupted or crashed run keeps every row it produced and memory does not grow with the rows.
pub(crate) struct CsvStream {
    w: csv::Writer<File>,
    path: PathBuf,
}

impl CsvStream {
    /// Create (truncate) `path` and write `header`.
    pub(crate) fn create<I, T>(path: &Path, header: I) -> Result<CsvStream, OutputError>
    where
        I: IntoIterator<Item = T>,
        T: AsRef<[u8]>,
    {
        let mut w = csv_writer(path)?;
        write_record(&mut w, path, header)?;
        Ok(CsvStream {
            w,
            path: path.to_path_buf(),
        })
    }

    /// Write one row, without flushing.
    fn row<I, T>(&mut self, record: I) -> Result<(), csv::Error>
    where
        I: IntoIterator<Item = T>,
        T: AsRef<[u8]>,
    {
        self.w.write_record(record)
    }

    /// Write one row and flush it to the file.
    pub(crate) fn write<I, T>(&mut self, record: I) -> Result<(), OutputError>
    where
        I: IntoIterator<Item = T>,
        T: AsRef<[u8]>,
    {
        write_record(&mut self.w, &self.path, record)?;
        self.flush()
    }

    /// Flush the rows written so far to the file.
    pub(crate) fn flush(&mut self) -> Result<(), OutputError> {
        self.w.flush().map_err(|source| OutputError::Io {
            path: self.path.clone(),
            source,
        })
    }

    /// The file written.
    pub(crate) fn path(&self) -> &Path {
        &self.path
    }
}
