//! The text of a description being checked (docs/model.md section 13): the line of each place in it, and the
//! reading of its fields (expressions, vectors, names) with errors at their lines.

use std::collections::HashMap;

use toml::Spanned;

use super::error::{line_of, DescriptionError, Problem};
use super::expr::Expr;
use super::format::{self, Field, Value};
use super::model::Vector;

/// The name of the tree's root.
pub const GROUND: &str = "ground";

/// The text being checked, for the lines of its errors.
pub struct Checker<'a> {
    /// The file, as given.
    pub file: &'a str,
    /// Its text.
    pub text: &'a str,
}

impl Checker<'_> {
    /// The error `problem` at byte `offset`.
    pub fn at(&self, offset: usize, problem: Problem) -> DescriptionError {
        DescriptionError::At {
            file: self.file.to_string(),
            line: line_of(self.text, offset),
            problem,
        }
    }

    /// The line of byte `offset`.
    pub fn line(&self, offset: usize) -> usize {
        line_of(self.text, offset)
    }

    /// The field `f` as an expression over `names`.
    pub fn expr(&self, f: &Field, names: &[&str]) -> Result<Expr, DescriptionError> {
        match f.get_ref() {
            Value::Number(x) => Ok(Expr::Number(*x)),
            Value::Expr(text) => {
                Expr::parse(text, names).map_err(|e| self.at(f.span().start, e.into()))
            }
        }
    }

    /// An optional vector, default the origin.
    pub fn vector(
        &self,
        v: &Option<format::Vector>,
        names: &[&str],
    ) -> Result<Vector, DescriptionError> {
        match v {
            None => Ok([Expr::Number(0.0), Expr::Number(0.0)]),
            Some([x, z]) => Ok([self.expr(x, names)?, self.expr(z, names)?]),
        }
    }

    /// The index of `name` among `known` (things of kind `what`), or an error at its place.
    pub fn find(
        &self,
        name: &Spanned<String>,
        known: &[&str],
        what: &'static str,
    ) -> Result<usize, DescriptionError> {
        known
            .iter()
            .position(|k| k == name.get_ref())
            .ok_or_else(|| {
                self.at(
                    name.span().start,
                    Problem::Unknown {
                        what,
                        name: name.get_ref().clone(),
                        known: known.join(", "),
                    },
                )
            })
    }

    /// Refuse a second use of a name among `names` (with their lines).
    pub fn unique<'n>(
        &self,
        what: &'static str,
        names: impl Iterator<Item = &'n Spanned<String>>,
    ) -> Result<(), DescriptionError> {
        let mut seen: HashMap<&str, usize> = HashMap::new();
        for n in names {
            let line = self.line(n.span().start);
            if let Some(first) = seen.insert(n.get_ref(), line) {
                return Err(self.at(
                    n.span().start,
                    Problem::Duplicate {
                        what,
                        name: n.get_ref().clone(),
                        first,
                    },
                ));
            }
        }
        Ok(())
    }
}
