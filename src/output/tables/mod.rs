//! The result tables, each declared once (STYLE.md point 18): a table is a list of [`Column`]s, each with its
//! name, its unit and meaning, and the accessor that reads its cell from a row. The CSV header, the row
//! writer, the Python binding's column names and the checks of the readers in [`super::read`] all follow
//! from that list.
//!
//! One file per table (or per job's tables): `steps.csv` and `trajectory.csv` of a walk, `sweep.csv`,
//! `map.csv`, the attractor tables `orbit.csv`, `branch.csv` and `basin.csv`, and the families of
//! `vrw continue` (`branch.csv` too: its own directory). Each file holds the
//! declaration and the writer of its tables.

pub(crate) mod attractors;
pub(crate) mod family;
pub(crate) mod map;
pub(crate) mod steps;
pub(crate) mod sweep;
pub(crate) mod trajectory;

use super::num;

/// One cell of a result table, typed so that a table can be written as CSV or handed to another front (the
/// Python binding turns each column into an array of its type).
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    /// A real number, written with `num`.
    Real(f64),
    /// A count or an index (also the `0`/`1` flags of `trajectory.csv`).
    Count(usize),
    /// A flag, written `true` or `false`.
    Flag(bool),
    /// A word (a branch, a status, a message).
    Text(String),
    /// No value (e.g. the gait columns of a sweep point without a gait), written as an empty field.
    Empty,
}

impl Cell {
    /// The cell as a CSV field.
    pub fn to_csv(&self) -> String {
        match self {
            Cell::Real(v) => num(*v),
            Cell::Count(n) => n.to_string(),
            Cell::Flag(b) => b.to_string(),
            Cell::Text(t) => t.clone(),
            Cell::Empty => String::new(),
        }
    }
}

/// The name of a column: fixed, or the name of a swept parameter known only at run time (the leading
/// columns of `sweep.csv`, `map.csv`, `orbit.csv` and `branch.csv`, named after the parameter's config key).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Name {
    /// A fixed name.
    Fixed(&'static str),
    /// The name of the `k`-th swept parameter (from 0), given when the table is written.
    Param(usize),
}

/// One column of a table whose rows are `T`s.
pub(crate) struct Column<T> {
    /// The header name.
    pub(crate) name: Name,
    /// Unit and meaning (read by the tables' tests, which require every column to have one).
    #[cfg_attr(not(test), allow(dead_code))]
    pub(crate) doc: &'static str,
    /// The cell of a row.
    pub(crate) get: fn(&T) -> Cell,
}

impl<T> Column<T> {
    /// A column with a fixed name.
    pub(crate) const fn new(
        name: &'static str,
        doc: &'static str,
        get: fn(&T) -> Cell,
    ) -> Column<T> {
        Column {
            name: Name::Fixed(name),
            doc,
            get,
        }
    }

    /// A column named after the `k`-th swept parameter.
    pub(crate) const fn param(k: usize, doc: &'static str, get: fn(&T) -> Cell) -> Column<T> {
        Column {
            name: Name::Param(k),
            doc,
            get,
        }
    }

    /// The header name, with `params` the names of the swept parameters.
    ///
    /// # Panics
    /// If the column names a parameter beyond `params` (a table written with too few parameter names).
    pub(crate) fn header_name<'a>(&self, params: &[&'a str]) -> &'a str {
        match self.name {
            Name::Fixed(name) => name,
            Name::Param(k) => params[k],
        }
    }
}

/// The header of a table, with `params` the names of its swept parameters.
pub(crate) fn header<'a, T>(columns: &[Column<T>], params: &[&'a str]) -> Vec<&'a str> {
    columns.iter().map(|c| c.header_name(params)).collect()
}

/// One row of a table: the cell of every column, in order.
pub(crate) fn row<T>(columns: &[Column<T>], item: &T) -> Vec<Cell> {
    columns.iter().map(|c| (c.get)(item)).collect()
}

/// The columns a table has with Coulomb friction only (`slip`, ...), after its own: those of `extra` where `on`,
/// none otherwise (so that every file without friction is as it was before the option existed).
pub(crate) fn optional<T>(extra: &[Column<T>], on: bool) -> &[Column<T>] {
    if on {
        extra
    } else {
        &[]
    }
}

/// [`header`] of `columns` followed by the [`optional`] `extra` columns where `on`.
pub(crate) fn header_with<'a, T>(
    columns: &[Column<T>],
    params: &[&'a str],
    (extra, on): (&[Column<T>], bool),
) -> Vec<&'a str> {
    let mut names = header(columns, params);
    names.extend(header(optional(extra, on), params));
    names
}

/// [`row`] of `columns` followed by the [`optional`] `extra` columns where `on`.
pub(crate) fn row_with<T>(
    columns: &[Column<T>],
    (extra, on): (&[Column<T>], bool),
    item: &T,
) -> Vec<Cell> {
    let mut cells = row(columns, item);
    cells.extend(row(optional(extra, on), item));
    cells
}

/// The fixed names of `columns[skip..]`, for a `const` header.
///
/// # Panics
/// At compile time, if one of them names a swept parameter or `M != N - skip`.
pub(crate) const fn fixed_names<T, const N: usize, const M: usize>(
    columns: &[Column<T>; N],
    skip: usize,
) -> [&'static str; M] {
    assert!(
        M + skip == N,
        "the header's length is not the number of columns"
    );
    let mut names = [""; M];
    let mut k = 0;
    while k < M {
        names[k] = match columns[k + skip].name {
            Name::Fixed(name) => name,
            Name::Param(_) => panic!("a column named after a swept parameter has no fixed name"),
        };
        k += 1;
    }
    names
}

#[cfg(test)]
mod tests;
