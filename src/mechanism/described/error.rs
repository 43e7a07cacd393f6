//! What is wrong with a walker's description, by the line of the file it is on (docs/model.md section 13).

use super::expr::ExprError;
use super::model::MAX_COORDINATES;

/// A description that cannot be read or is not a walker.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DescriptionError {
    /// The file cannot be read at all.
    #[error("{file}: {reason}")]
    Unreadable {
        /// The file, as given.
        file: String,
        /// Why.
        reason: String,
    },
    /// A problem at a line of the file.
    #[error("{file} line {line}: {problem}")]
    At {
        /// The file, as given.
        file: String,
        /// The line (from 1).
        line: usize,
        /// What is wrong.
        problem: Problem,
    },
}

/// What is wrong at a line of a description.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Problem {
    /// The TOML parser's refusal: a syntax error, an unknown key, an unknown joint kind, a value of the wrong
    /// type, a missing field.
    #[error("{message}")]
    Toml {
        /// The parser's message.
        message: String,
    },
    /// A malformed expression or one naming no parameter.
    #[error("{0}")]
    Expression(#[from] ExprError),
    /// Two things of one kind share a name.
    #[error("the {what} name `{name}` is used twice (also at line {first})")]
    Duplicate {
        /// `body`, `joint`, `contact` or `parameter`.
        what: &'static str,
        /// The name.
        name: String,
        /// The line of the first.
        first: usize,
    },
    /// A name that names none of the things it should.
    #[error("unknown {what} `{name}` (the {what}s: {known})")]
    Unknown {
        /// What was looked for (`body`, `contact`, `coordinate`).
        what: &'static str,
        /// The name.
        name: String,
        /// What there is.
        known: String,
    },
    /// A body made the child of two joints.
    #[error(
        "body `{body}` has two parents: it is already the child of joint `{first}` (line {line})"
    )]
    TwoParents {
        /// The body.
        body: String,
        /// The first joint.
        first: String,
        /// Its line.
        line: usize,
    },
    /// Joints that form a loop.
    #[error("the joints form a cycle ({cycle}): joints must form a tree rooted at the ground")]
    Cycle {
        /// The bodies around it.
        cycle: String,
    },
    /// A body no joint attaches.
    #[error(
        "body `{body}` is the child of no joint: every body hangs from the ground through joints"
    )]
    Unattached {
        /// The body.
        body: String,
    },
    /// A quantity that must not be negative (or must be positive) is.
    #[error("{what} is {value}: it must be {rule}")]
    OutOfRange {
        /// What (`the mass of body leg1`).
        what: String,
        /// Its value.
        value: f64,
        /// The rule (`at least 0`).
        rule: String,
    },
    /// A field that does not belong where it is, or a missing one.
    #[error("{field}: {reason}")]
    Field {
        /// The field.
        field: &'static str,
        /// Why.
        reason: String,
    },
    /// A relabeling that is not a permutation of the coordinates.
    #[error("the relabeling is not a permutation of the coordinates: {reason}")]
    NotAPermutation {
        /// Why.
        reason: String,
    },
    /// More free joints than the dispatch supports.
    #[error("{count} coordinates (free joints): at most {MAX_COORDINATES} are supported")]
    TooManyCoordinates {
        /// How many.
        count: usize,
    },
}

/// The line (from 1) of byte `offset` of `text`.
pub fn line_of(text: &str, offset: usize) -> usize {
    1 + text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|b| **b == b'\n')
        .count()
}
