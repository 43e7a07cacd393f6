//! What a walker's job computes, as the Python binding takes it ([`WalkerOutput`]: its JSON file's fields and
//! its CSV files' rows in memory) and as the command line writes it ([`write_rows`]).

use std::path::Path;

use super::AppError;
use crate::output;

/// What a walker's job computes, without its files (the Python binding): its JSON file's fields and the rows
/// of its CSV files (each its header first), by file name, in the order the job writes them.
#[derive(Debug, Clone)]
pub struct WalkerOutput<S> {
    /// The JSON file's fields.
    pub summary: S,
    /// The CSV files' names and rows.
    pub tables: Vec<(&'static str, Vec<Vec<String>>)>,
}

/// Write the table `rows` (its header first) as the CSV file `path`, atomically.
pub(super) fn write_rows(path: &Path, rows: &[Vec<String>]) -> Result<(), AppError> {
    output::write_atomic(path, |path| -> Result<(), AppError> {
        let mut w = output::csv_writer(path)?;
        for row in rows {
            output::write_record(&mut w, path, row)?;
        }
        w.flush().map_err(|source| crate::output::OutputError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Ok(())
    })
}
