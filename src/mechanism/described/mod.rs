//! Walkers described in a TOML file (docs/model.md section 13, "Described walkers"): parameters, bodies (point
//! masses and rigid bodies) in a tree of revolute and prismatic joints rooted at the ground, free or fixed joints
//! with springs, dampers and stoppers, contact points, and for a biped how its legs take turns.
//!
//! The file is read by serde (`format.rs`) and checked (`check.rs`, `checker.rs`, `tree.rs`, `check_gait.rs`,
//! `values.rs`)
//! into a [`Description`] whose numeric fields are expressions over the parameters (`expr.rs`), evaluated over
//! any [`Real`] by the kinematics (`kinematics.rs`), so that a described walker is a [`Mechanism`] like the
//! built-in ones, with exact derivatives through dual numbers. Its number of coordinates `N` is known only once
//! the file is read, while the interface is `Mechanism<N>` with `N` a constant: [`load`] dispatches once over
//! `1..=MAX_COORDINATES` into [`AnyDescribed`]. A described biped with rigid legs walks as the built-in compass
//! gait does (`walk.rs`, through [`super::turns`]), one with two telescopic legs by the compliant walk of
//! [`super::legged`] as the built-in telescopic walker does (`compliant.rs`).

mod check;
mod check_gait;
mod checker;
mod compliant;
mod drawing;
mod error;
pub mod expr;
mod format;
mod kinematics;
pub mod model;
mod tree;
mod values;
mod walk;

#[cfg(test)]
mod compliant_tests;
#[cfg(test)]
mod refusal_tests;
#[cfg(test)]
mod tests;

use std::collections::HashSet;
use std::path::Path;
use std::sync::{Arc, Mutex};

use nalgebra::SVector;

use super::{Equations, Mechanism, PointKinematics, Real};
use crate::params::ConfigError;

pub use drawing::Drawing;
pub use error::{DescriptionError, Problem};
pub use expr::{Expr, ExprError};
pub use kinematics::Values;
pub use model::{Description, MAX_COORDINATES, MAX_PARAMETERS};
pub use walk::{walk, walkable, NotWalkable, SectionError, Walk};

/// Most bytes a description file may have.
pub const MAX_DESCRIPTION_BYTES: u64 = 1 << 20;

/// `name` as a `&'static str`, the form the interface names things in ([`Mechanism::name`],
/// [`Mechanism::coordinates`]). A description's names are known only at run time, so each distinct name is
/// leaked once and kept in this set: reading the same file again (a continuation, the Python binding) reuses
/// them, and the memory is bounded by the distinct names ever read.
pub fn intern(name: &str) -> &'static str {
    static NAMES: Mutex<Option<HashSet<&'static str>>> = Mutex::new(None);
    let mut guard = NAMES.lock().unwrap_or_else(|e| e.into_inner());
    let set = guard.get_or_insert_with(HashSet::new);
    if let Some(known) = set.get(name) {
        return known;
    }
    let leaked: &'static str = Box::leak(name.to_string().into_boxed_str());
    set.insert(leaked);
    leaked
}

/// A described walker with `N` coordinates at one parameter point.
#[derive(Debug, Clone, PartialEq)]
pub struct Described<const N: usize> {
    /// The checked description (shared by every parameter point of it).
    pub description: Arc<Description>,
    /// The parameters' values, in their order.
    pub values: Vec<f64>,
}

impl<const N: usize> Described<N> {
    /// The value of parameter `key`.
    pub fn value(&self, key: &str) -> Option<f64> {
        let i = self
            .description
            .parameters
            .iter()
            .position(|p| p.name == key)?;
        Some(self.values[i])
    }

    /// The parameters' keys and values.
    pub fn parameters(&self) -> Vec<(&'static str, f64)> {
        let names = self.description.parameters.iter().map(|p| p.name);
        names.zip(self.values.iter().copied()).collect()
    }

    /// The same walker with parameter `key` at `value`, checked ([`Described::with_values`]).
    pub fn with_value(&self, key: &str, value: f64) -> Result<Described<N>, ConfigError> {
        let d = &self.description;
        let Some(i) = d.parameters.iter().position(|p| p.name == key) else {
            return Err(ConfigError::UnknownKey {
                key: key.to_string(),
                known: d
                    .parameters
                    .iter()
                    .map(|p| p.name)
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        };
        let mut values = self.values.clone();
        values[i] = value;
        self.with_values(values)
    }

    /// The same walker with the parameters at `values` (in their order), checked: each in its domain, and
    /// every rule of the description at the new point (no negative mass, unit directions, ...), each broken
    /// rule named with its parameter and the line of the file it is about.
    pub fn with_values(&self, values: Vec<f64>) -> Result<Described<N>, ConfigError> {
        let d = &self.description;
        let changed: Vec<usize> = (0..values.len())
            .filter(|i| values[*i] != self.values[*i])
            .collect();
        let invalid = |i: usize, reason: String| ConfigError::InvalidValue {
            key: d.parameters[i].name.to_string(),
            value: crate::fmt::short(values[i]),
            reason,
        };
        let mut errors = Vec::new();
        for (i, p) in d.parameters.iter().enumerate() {
            if let Some(rule) = values::outside_domain(p, values[i]) {
                errors.push(invalid(i, format!("it must be {rule}")));
            }
        }
        // The description's rules at the new point, once every parameter is in its domain.
        let problems = if errors.is_empty() {
            values::problems(d, &values)
        } else {
            Vec::new()
        };
        for (line, problem) in problems {
            // The rule is about the changed parameters together; it is reported with the first of them.
            let i = changed.first().copied().unwrap_or(0);
            errors.push(invalid(
                i,
                format!("then {} line {line}: {problem}", d.file),
            ));
        }
        ConfigError::all(errors)?;
        Ok(Described {
            description: Arc::clone(d),
            values,
        })
    }
}

impl<const N: usize> Mechanism<N> for Described<N> {
    type Constants<T: Real> = Values<T>;

    fn name(&self) -> &'static str {
        self.description.name
    }

    fn coordinates(&self) -> [&'static str; N] {
        std::array::from_fn(|i| self.description.coordinates[i])
    }

    fn constants<T: Real>(&self, value: &dyn Fn(&'static str, f64) -> T) -> Values<T> {
        let mut values = [T::zero(); MAX_PARAMETERS];
        for (slot, (p, v)) in values
            .iter_mut()
            .zip(self.description.parameters.iter().zip(&self.values))
        {
            *slot = value(p.name, *v);
        }
        Values {
            values,
            len: self.values.len(),
        }
    }

    fn equations<T: Real>(
        &self,
        c: &Values<T>,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
    ) -> Equations<T, N> {
        kinematics::equations(&self.description, c, q, qd)
    }

    fn contact_points(&self) -> usize {
        self.description.contacts.len()
    }

    fn contact<T: Real>(
        &self,
        c: &Values<T>,
        q: &SVector<T, N>,
        qd: &SVector<T, N>,
        i: usize,
    ) -> PointKinematics<T, N> {
        kinematics::contact(&self.description, c, q, qd, i)
    }

    fn potential_energy(&self, q: &SVector<f64, N>) -> f64 {
        kinematics::potential_energy(&self.description, &self.constants_f64(), q)
    }

    fn damper_power(&self, _q: &SVector<f64, N>, qd: &SVector<f64, N>) -> f64 {
        kinematics::damper_power(&self.description, &self.constants_f64(), qd)
    }
}

impl<const N: usize> super::rigid_family::Parametrized for Described<N> {
    fn parameter_keys(&self) -> Vec<&'static str> {
        self.description.parameters.iter().map(|p| p.name).collect()
    }

    fn with_parameter(&self, key: &str, value: f64) -> Result<Described<N>, ConfigError> {
        self.with_value(key, value)
    }
}

/// Calls `$body` with `$w` bound to the [`Described`] inside an [`AnyDescribed`], whatever its `N`.
#[macro_export]
macro_rules! with_described {
    ($any:expr, $w:ident => $body:expr) => {{
        use $crate::mechanism::described::AnyDescribed as A;
        match $any {
            A::N1($w) => $body,
            A::N2($w) => $body,
            A::N3($w) => $body,
            A::N4($w) => $body,
            A::N5($w) => $body,
            A::N6($w) => $body,
            A::N7($w) => $body,
            A::N8($w) => $body,
        }
    }};
}

/// A described walker of any supported number of coordinates (`1..=MAX_COORDINATES`), dispatched once.
#[derive(Debug, Clone, PartialEq)]
#[allow(missing_docs)]
pub enum AnyDescribed {
    N1(Described<1>),
    N2(Described<2>),
    N3(Described<3>),
    N4(Described<4>),
    N5(Described<5>),
    N6(Described<6>),
    N7(Described<7>),
    N8(Described<8>),
}

impl AnyDescribed {
    /// The walker of `description` at its defaults.
    pub fn new(description: Description) -> AnyDescribed {
        let values = description.parameters.iter().map(|p| p.default).collect();
        let description = Arc::new(description);
        macro_rules! of {
            ($v:ident, $n:literal) => {
                AnyDescribed::$v(Described::<$n> {
                    description,
                    values,
                })
            };
        }
        match description.coordinates.len() {
            1 => of!(N1, 1),
            2 => of!(N2, 2),
            3 => of!(N3, 3),
            4 => of!(N4, 4),
            5 => of!(N5, 5),
            6 => of!(N6, 6),
            7 => of!(N7, 7),
            // The check refuses more than MAX_COORDINATES and fewer than 1.
            _ => of!(N8, 8),
        }
    }

    /// The description.
    pub fn description(&self) -> &Description {
        with_described!(self, w => &w.description)
    }

    /// The parameters' keys and values.
    pub fn parameters(&self) -> Vec<(&'static str, f64)> {
        with_described!(self, w => w.parameters())
    }

    /// The same walker with its parameters read as a walker's are: from the flat TOML `file` of `key = value`
    /// lines, then the `--set key=value` `overrides` ([`crate::params::read_named_parameters`]), checked
    /// ([`Described::with_values`]).
    pub fn with_parameters<S: AsRef<str>>(
        &self,
        file: Option<&Path>,
        overrides: &[S],
    ) -> Result<AnyDescribed, ConfigError> {
        let values = crate::params::read_named_parameters(&self.parameters(), file, overrides)?;
        Ok(match self {
            AnyDescribed::N1(w) => AnyDescribed::N1(w.with_values(values)?),
            AnyDescribed::N2(w) => AnyDescribed::N2(w.with_values(values)?),
            AnyDescribed::N3(w) => AnyDescribed::N3(w.with_values(values)?),
            AnyDescribed::N4(w) => AnyDescribed::N4(w.with_values(values)?),
            AnyDescribed::N5(w) => AnyDescribed::N5(w.with_values(values)?),
            AnyDescribed::N6(w) => AnyDescribed::N6(w.with_values(values)?),
            AnyDescribed::N7(w) => AnyDescribed::N7(w.with_values(values)?),
            AnyDescribed::N8(w) => AnyDescribed::N8(w.with_values(values)?),
        })
    }

    /// The same walker with parameter `key` at `value`, checked ([`Described::with_value`]).
    pub fn with_value(&self, key: &str, value: f64) -> Result<AnyDescribed, ConfigError> {
        Ok(match self {
            AnyDescribed::N1(w) => AnyDescribed::N1(w.with_value(key, value)?),
            AnyDescribed::N2(w) => AnyDescribed::N2(w.with_value(key, value)?),
            AnyDescribed::N3(w) => AnyDescribed::N3(w.with_value(key, value)?),
            AnyDescribed::N4(w) => AnyDescribed::N4(w.with_value(key, value)?),
            AnyDescribed::N5(w) => AnyDescribed::N5(w.with_value(key, value)?),
            AnyDescribed::N6(w) => AnyDescribed::N6(w.with_value(key, value)?),
            AnyDescribed::N7(w) => AnyDescribed::N7(w.with_value(key, value)?),
            AnyDescribed::N8(w) => AnyDescribed::N8(w.with_value(key, value)?),
        })
    }
}

impl serde::Serialize for AnyDescribed {
    /// The parameters, by key.
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let parameters = self.parameters();
        let mut map = serializer.serialize_map(Some(parameters.len()))?;
        for (k, v) in parameters {
            map.serialize_entry(k, &v)?;
        }
        map.end()
    }
}

/// The description in `text`, as read from `file` (a name for its errors).
pub fn parse(file: &str, text: &str) -> Result<AnyDescribed, DescriptionError> {
    Ok(AnyDescribed::new(check::description(file, text)?))
}

/// The description in the file `path`: a regular UTF-8 file of at most [`MAX_DESCRIPTION_BYTES`].
pub fn load(path: &Path) -> Result<AnyDescribed, DescriptionError> {
    use std::io::Read;
    let file = path.display().to_string();
    let unreadable = |reason: String| DescriptionError::Unreadable {
        file: file.clone(),
        reason,
    };
    // The kind is read before the file is opened: opening a FIFO waits for a writer, for ever.
    let kind = std::fs::metadata(path)
        .map_err(|e| unreadable(e.to_string()))?
        .file_type();
    if !kind.is_file() {
        return Err(unreadable("it is not a regular file".to_string()));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_DESCRIPTION_BYTES + 1).read_to_end(&mut bytes))
        .map_err(|e| unreadable(e.to_string()))?;
    if bytes.len() as u64 > MAX_DESCRIPTION_BYTES {
        return Err(unreadable(format!(
            "it is larger than {MAX_DESCRIPTION_BYTES} bytes"
        )));
    }
    let text =
        String::from_utf8(bytes).map_err(|e| unreadable(format!("it is not UTF-8 text ({e})")))?;
    parse(&file, &text)
}
