//! A walker's description once checked (docs/model.md section 13): names resolved to indices, expressions
//! parsed, the joints ordered from the ground outward. `check.rs` makes it from the file; the kinematics
//! (`kinematics.rs`) and the walk read it.

use super::expr::Expr;

/// Most parameters a description may have (its constants are a fixed-size array, so that they are `Copy` as
/// the interface asks).
pub const MAX_PARAMETERS: usize = 32;

/// Most generalized coordinates: the interface is `Mechanism<N>` with `N` a constant, and a description is
/// dispatched once, at load time, over `1..=MAX_COORDINATES`.
pub const MAX_COORDINATES: usize = 8;

/// A point or a direction in a frame, `[x, z]`.
pub type Vector = [Expr; 2];

/// A parameter of the walker.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// Its key (`--set KEY=VALUE`, `--param KEY`).
    pub name: &'static str,
    /// Its default.
    pub default: f64,
    /// The least value allowed.
    pub min: Option<f64>,
    /// The largest value allowed.
    pub max: Option<f64>,
    /// Whether it must be above 0.
    pub positive: bool,
}

/// A body.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// Its name.
    pub name: String,
    /// Its mass \[kg\].
    pub mass: Expr,
    /// Its centre of mass in its frame \[m\].
    pub centre: Vector,
    /// Its rotational inertia about its centre \[kg m^2\].
    pub inertia: Expr,
    /// The lines of its mass and its inertia in the file.
    pub lines: [usize; 2],
}

/// How a joint moves its child.
#[derive(Debug, Clone, PartialEq)]
pub enum Motion {
    /// A hinge: the child's frame turns by the joint's value `sign * value` (`sign` -1 for a clockwise angle),
    /// from the parent's angle or, `absolute`, from the ground's.
    Revolute {
        /// The angle measured from the ground's frame rather than the parent's.
        absolute: bool,
        /// 1, or -1 for a clockwise angle.
        sign: f64,
    },
    /// A slider: the child's frame moves by the joint's value along `direction` (a unit vector in the
    /// parent's frame).
    Prismatic {
        /// The direction.
        direction: Vector,
    },
}

/// A free joint's coordinate and what acts on it.
#[derive(Debug, Clone, PartialEq)]
pub struct Free {
    /// Its index in `q`.
    pub coordinate: usize,
    /// A linear spring: stiffness and rest value.
    pub spring: Option<(Expr, Expr)>,
    /// A linear damper's coefficient.
    pub damper: Option<Expr>,
    /// The stoppers: the least and the largest value.
    pub stoppers: [Option<Expr>; 2],
}

/// A joint's value: a coordinate, or held.
#[derive(Debug, Clone, PartialEq)]
pub enum State {
    /// A generalized coordinate.
    Free(Free),
    /// Held at this value.
    Fixed(Expr),
}

/// A joint.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Its name (the coordinate's if it is free).
    pub name: String,
    /// How it moves its child.
    pub motion: Motion,
    /// The parent body (`None`: the ground).
    pub parent: Option<usize>,
    /// The child body.
    pub child: usize,
    /// Where it is in the parent's frame.
    pub at: Vector,
    /// Its value.
    pub state: State,
    /// Its line in the file.
    pub line: usize,
    /// The lines of its direction, spring, damper and stoppers (its own line where it has none).
    pub field_lines: [usize; 4],
}

/// The index in [`Joint::field_lines`] of the direction's line.
pub const DIRECTION_LINE: usize = 0;
/// ... of the spring's.
pub const SPRING_LINE: usize = 1;
/// ... of the damper's.
pub const DAMPER_LINE: usize = 2;
/// ... of the stoppers'.
pub const STOPPERS_LINE: usize = 3;

/// A contact point.
#[derive(Debug, Clone, PartialEq)]
pub struct Contact {
    /// Its name.
    pub name: String,
    /// Its body.
    pub body: usize,
    /// Where it is in the body's frame.
    pub at: Vector,
}

/// A telescopic leg's stroke: the coordinate that is its length and its upper stopper (the compliant walk's
/// `Stroke`, with the stopper an expression over the parameters).
#[derive(Debug, Clone, PartialEq)]
pub struct LegStroke {
    /// The length's index in `q`.
    pub coordinate: usize,
    /// The stopper: the leg is at most this long.
    pub stopper: Expr,
}

/// How a biped takes its steps.
#[derive(Debug, Clone, PartialEq)]
pub struct Gait {
    /// The stance contact.
    pub stance: usize,
    /// The contact that lands.
    pub lands: usize,
    /// The relabeling: after a heel strike, coordinate `i` takes the value coordinate `relabel[i]` had.
    pub relabel: Vec<usize>,
    /// The fore (stance) and rear (landing) legs' strokes, for a walker with telescopic legs that walks by the
    /// compliant walk; `None`: rigid legs.
    pub strokes: Option<[LegStroke; 2]>,
    /// The coordinate that slides the whole walker along the slope, moved so that the new stance contact is
    /// at `x = 0` (a free prismatic joint from the ground along the slope).
    pub shift: Option<usize>,
    /// The hip's body.
    pub hip: usize,
    /// The section's names, in order.
    pub section_names: Vec<&'static str>,
    /// For each section value: the coordinate it is, and whether it is its velocity.
    pub section: Vec<(usize, bool)>,
    /// Guesses of the other coordinates: expressions over the parameters then the section's coordinates (the
    /// positions among them, in the section's order).
    pub guess: Vec<(usize, Expr)>,
    /// Where a gait search starts.
    pub start: Vec<f64>,
}

/// A checked description.
#[derive(Debug, Clone, PartialEq)]
pub struct Description {
    /// The walker's name.
    pub name: &'static str,
    /// The file it was read from, as given.
    pub file: String,
    /// The parameters.
    pub parameters: Vec<Parameter>,
    /// Indices of `slope` and `gravity` among them.
    pub slope_gravity: [usize; 2],
    /// The bodies.
    pub bodies: Vec<Body>,
    /// The joints, each after the joint that makes its parent.
    pub joints: Vec<Joint>,
    /// The contact points.
    pub contacts: Vec<Contact>,
    /// The names of the coordinates, in the order of `q` (the free joints in the file's order).
    pub coordinates: Vec<&'static str>,
    /// How it walks (a rigid biped), if it does.
    pub gait: Option<Gait>,
}

impl Description {
    /// The free joints.
    pub fn free_joints(&self) -> impl Iterator<Item = (&Joint, &Free)> {
        self.joints.iter().filter_map(|j| match &j.state {
            State::Free(f) => Some((j, f)),
            State::Fixed(_) => None,
        })
    }

    /// Whether any joint has a spring, a damper or a stopper: such a walker needs the compliant walk.
    pub fn compliant_joints(&self) -> Vec<&str> {
        self.free_joints()
            .filter(|(_, f)| {
                f.spring.is_some() || f.damper.is_some() || f.stoppers.iter().any(Option::is_some)
            })
            .map(|(j, _)| j.name.as_str())
            .collect()
    }
}
