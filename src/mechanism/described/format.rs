//! The TOML form of a walker's description (docs/model.md section 13), as serde reads it: every table refuses
//! an unknown key, and every value keeps its place in the file (`toml::Spanned`) so that the checks of
//! `check.rs` can name the line of what they refuse.

use std::fmt;

use serde::de::{self, Deserializer, MapAccess, Visitor};
use serde::Deserialize;
use toml::Spanned;

/// A numeric field: a number, or an expression over the parameters (`"leg_length - leg_mass_offset"`).
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// A number.
    Number(f64),
    /// An expression's text.
    Expr(String),
}

impl<'de> Deserialize<'de> for Value {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Value, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Value;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number or an expression over the parameters (a string)")
            }
            fn visit_f64<E: de::Error>(self, x: f64) -> Result<Value, E> {
                Ok(Value::Number(x))
            }
            fn visit_i64<E: de::Error>(self, x: i64) -> Result<Value, E> {
                Ok(Value::Number(x as f64))
            }
            fn visit_u64<E: de::Error>(self, x: u64) -> Result<Value, E> {
                Ok(Value::Number(x as f64))
            }
            fn visit_str<E: de::Error>(self, s: &str) -> Result<Value, E> {
                Ok(Value::Expr(s.to_string()))
            }
        }
        d.deserialize_any(V)
    }
}

/// A field of the file with its place.
pub type Field = Spanned<Value>;

/// A point or a direction in a frame: `[x, z]`.
pub type Vector = [Field; 2];

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct File {
    /// The walker's name, as outputs name it.
    pub name: Spanned<String>,
    /// The parameters, in the order of the file.
    pub parameters: Spanned<Parameters>,
    /// The bodies.
    #[serde(default)]
    pub bodies: Vec<Spanned<Body>>,
    /// The joints.
    #[serde(default)]
    pub joints: Vec<Spanned<Joint>>,
    /// The contact points.
    #[serde(default)]
    pub contacts: Vec<Spanned<Contact>>,
    /// How the walker takes its steps (a biped with rigid legs); absent: the walker has no walk yet.
    pub gait: Option<Spanned<Gait>>,
}

/// A table read in the order of the file: each key (with its place) and its value.
#[derive(Debug)]
pub struct Pairs<V>(pub Vec<(Spanned<String>, V)>);

/// The `[parameters]` table.
pub type Parameters = Pairs<Spanned<Parameter>>;

impl<'de, V: Deserialize<'de>> Deserialize<'de> for Pairs<V> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Pairs<V>, D::Error> {
        struct Visit<V>(std::marker::PhantomData<V>);
        impl<'de, V: Deserialize<'de>> Visitor<'de> for Visit<V> {
            type Value = Pairs<V>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a table")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Pairs<V>, A::Error> {
                let mut out = Vec::new();
                while let Some(entry) = map.next_entry()? {
                    out.push(entry);
                }
                Ok(Pairs(out))
            }
        }
        d.deserialize_map(Visit(std::marker::PhantomData))
    }
}

/// One parameter: its default value, or a table with its domain.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// The default value.
    pub value: f64,
    /// The least value allowed.
    pub min: Option<f64>,
    /// The largest value allowed.
    pub max: Option<f64>,
    /// Whether it must be above 0.
    pub positive: bool,
}

/// A parameter's table form.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ParameterTable {
    value: f64,
    min: Option<f64>,
    max: Option<f64>,
    #[serde(default)]
    positive: bool,
}

impl<'de> Deserialize<'de> for Parameter {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Parameter, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Parameter;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number, or a table { value, min, max, positive }")
            }
            fn visit_f64<E: de::Error>(self, value: f64) -> Result<Parameter, E> {
                Ok(Parameter {
                    value,
                    min: None,
                    max: None,
                    positive: false,
                })
            }
            fn visit_i64<E: de::Error>(self, x: i64) -> Result<Parameter, E> {
                self.visit_f64(x as f64)
            }
            fn visit_u64<E: de::Error>(self, x: u64) -> Result<Parameter, E> {
                self.visit_f64(x as f64)
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Parameter, A::Error> {
                let t = ParameterTable::deserialize(de::value::MapAccessDeserializer::new(map))?;
                Ok(Parameter {
                    value: t.value,
                    min: t.min,
                    max: t.max,
                    positive: t.positive,
                })
            }
        }
        d.deserialize_any(V)
    }
}

/// A body: a point mass, or a rigid body with an inertia.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Body {
    /// Its name.
    pub name: Spanned<String>,
    /// Its mass \[kg\]; default 0 (a massless link).
    pub mass: Option<Field>,
    /// Its centre of mass in its frame; default the frame's origin.
    pub centre: Option<Vector>,
    /// Its rotational inertia about its centre \[kg m^2\]; default 0 (a point mass).
    pub inertia: Option<Field>,
}

/// The kind of a joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum JointKind {
    /// A hinge: the child turns about the joint's position.
    Revolute,
    /// A slider: the child moves along the joint's direction.
    Prismatic,
}

/// What a revolute joint's angle is measured from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AngleFrom {
    /// From the parent's frame.
    #[default]
    Relative,
    /// From the slope's downward normal (the ground's frame).
    Absolute,
}

/// A linear spring on a free joint.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Spring {
    /// Its stiffness \[N/m or N m/rad\].
    pub stiffness: Field,
    /// The joint's value where it is relaxed.
    pub rest: Field,
}

/// A linear damper on a free joint.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Damper {
    /// Its coefficient \[N s/m or N m s/rad\].
    pub coefficient: Field,
}

/// A free joint's stoppers.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stoppers {
    /// The least value of the joint.
    pub lower: Option<Field>,
    /// The largest value of the joint.
    pub upper: Option<Field>,
}

/// A joint between a parent (`ground` or a body) and a child body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Joint {
    /// Its name: the coordinate's, if it is free.
    pub name: Spanned<String>,
    /// `revolute` or `prismatic`.
    pub kind: Spanned<JointKind>,
    /// `ground` or a body.
    pub parent: Spanned<String>,
    /// A body.
    pub child: Spanned<String>,
    /// Where it is in the parent's frame; default its origin.
    pub at: Option<Vector>,
    /// A prismatic joint's direction in the parent's frame (a unit vector).
    pub direction: Option<Spanned<Vector>>,
    /// A revolute joint's angle: `relative` to the parent (default) or `absolute`.
    pub angle: Option<Spanned<AngleFrom>>,
    /// A revolute joint's angle grows clockwise (default: counterclockwise, toward `+x` from below).
    pub clockwise: Option<Spanned<bool>>,
    /// The value at which the joint is held; absent: the joint is free, a coordinate.
    pub fixed: Option<Field>,
    /// A free joint's spring.
    pub spring: Option<Spanned<Spring>>,
    /// A free joint's damper.
    pub damper: Option<Spanned<Damper>>,
    /// A free joint's stoppers.
    pub stoppers: Option<Spanned<Stoppers>>,
}

/// A contact point.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Contact {
    /// Its name.
    pub name: Spanned<String>,
    /// The body it is on.
    pub body: Spanned<String>,
    /// Where it is in the body's frame; default the frame's origin.
    pub at: Option<Vector>,
}

/// The fore (stance) and the rear (landing) leg's strokes: each a free prismatic joint, the leg's length, with
/// an upper stopper.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Strokes {
    /// The stance leg's length.
    pub fore: Spanned<String>,
    /// The landing leg's length.
    pub rear: Spanned<String>,
}

/// How a biped walks: single support on `stance`, heel strike of `lands`, the legs' exchange; with `strokes`,
/// its legs are telescopic and it walks by the compliant walk.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Gait {
    /// The contact on the ground in single support.
    pub stance: Spanned<String>,
    /// The contact that strikes the ground ahead.
    pub lands: Spanned<String>,
    /// The relabeling at heel strike: each coordinate named here takes the value the named one had (a
    /// permutation); the others keep theirs.
    pub relabel: Spanned<Pairs<Spanned<String>>>,
    /// The telescopic legs' strokes: present, the walker walks by the compliant walk (docs/model.md section
    /// 13); absent, its legs are rigid.
    pub strokes: Option<Spanned<Strokes>>,
    /// The coordinate moved so that the new stance contact is at `x = 0` (a floating base's slide along the
    /// slope).
    pub shift: Option<Spanned<String>>,
    /// The body whose frame's height is the hip's: the walker has fallen when it reaches the ground.
    pub hip: Spanned<String>,
    /// The section's coordinates: names of coordinates (`theta1`) and of velocities (`theta1_dot`).
    pub section: Spanned<Vec<Spanned<String>>>,
    /// Guesses of the other coordinates on the section, as expressions over the parameters and the section's
    /// coordinates, from which Newton's method solves the contact conditions; the others start at 0.
    pub guess: Option<Pairs<Field>>,
    /// Where a gait search starts on the section.
    pub start: Spanned<Vec<f64>>,
}
