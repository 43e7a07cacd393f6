//! From the TOML text of a description to a checked [`Description`] (docs/model.md section 13): names resolved,
//! expressions parsed, the joints' tree verified and ordered from the ground outward, every refusal naming the
//! line it is about. The gait's table is checked in `check_gait.rs`, the values at the parameters' defaults in
//! `values.rs`.

use toml::Spanned;

use super::checker::{Checker, GROUND};
use super::error::{DescriptionError, Problem};
use super::expr::Expr;
use super::format::{self, AngleFrom, Field, JointKind};
use super::intern;
use super::model::{
    Body, Contact, Description, Free, Joint, Motion, Parameter, State, MAX_COORDINATES,
    MAX_PARAMETERS,
};

/// The description in `text`, read from `file` (see the module documentation).
pub fn description(file: &str, text: &str) -> Result<Description, DescriptionError> {
    let cx = Checker { file, text };
    let raw: format::File = toml::from_str(text).map_err(|e: toml::de::Error| {
        let offset = e.span().map_or(0, |s| s.start);
        cx.at(
            offset,
            Problem::Toml {
                message: e.message().trim_end().to_string(),
            },
        )
    })?;
    let parameters = parameters(&cx, &raw.parameters)?;
    let names: Vec<&str> = parameters.iter().map(|p| p.name).collect();
    let slope_gravity = ["slope", "gravity"].map(|k| names.iter().position(|n| *n == k));
    let [Some(slope), Some(gravity)] = slope_gravity else {
        return Err(cx.at(
            raw.parameters.span().start,
            Problem::Field {
                field: "parameters",
                reason: "`slope` and `gravity` must be among them".to_string(),
            },
        ));
    };
    let bodies = bodies(&cx, &raw.bodies, &names)?;
    let (joints, coordinates) = joints(&cx, &raw.joints, &bodies, &names)?;
    let body_names: Vec<&str> = bodies.iter().map(|b| b.name.as_str()).collect();
    let contacts = contacts(&cx, &raw.contacts, &body_names, &names)?;
    let mut d = Description {
        name: intern(raw.name.get_ref()),
        file: file.to_string(),
        parameters,
        slope_gravity: [slope, gravity],
        bodies,
        joints,
        contacts,
        coordinates,
        gait: None,
    };
    if let Some(gait) = &raw.gait {
        d.gait = Some(super::check_gait::gait(&cx, gait, &d)?);
        super::check_gait::legs_first(&mut d);
    }
    super::values::check_defaults(&cx, &d)?;
    Ok(d)
}

/// The `[parameters]` table: names that are no function or constant, at most [`MAX_PARAMETERS`], defaults in
/// their domains.
fn parameters(
    cx: &Checker,
    table: &Spanned<format::Parameters>,
) -> Result<Vec<Parameter>, DescriptionError> {
    let entries = &table.get_ref().0;
    cx.unique("parameter", entries.iter().map(|(n, _)| n))?;
    if entries.len() > MAX_PARAMETERS {
        return Err(cx.at(
            table.span().start,
            Problem::Field {
                field: "parameters",
                reason: format!("{} parameters: at most {MAX_PARAMETERS}", entries.len()),
            },
        ));
    }
    let mut out = Vec::new();
    for (name, spec) in entries {
        let n = name.get_ref();
        let identifier = n.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
            && n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        if !identifier || ["pi", "sin", "cos"].contains(&n.as_str()) {
            return Err(cx.at(
                name.span().start,
                Problem::Field {
                    field: "parameters",
                    reason: format!(
                        "`{n}` cannot name a parameter (a name is letters, digits and `_`, not pi, sin or cos)"
                    ),
                },
            ));
        }
        let s = spec.get_ref();
        let p = Parameter {
            name: intern(n),
            default: s.value,
            min: s.min,
            max: s.max,
            positive: s.positive,
        };
        if let Some(reason) = super::values::outside_domain(&p, p.default) {
            return Err(cx.at(
                spec.span().start,
                Problem::OutOfRange {
                    what: format!("the default of `{n}`"),
                    value: p.default,
                    rule: reason,
                },
            ));
        }
        out.push(p);
    }
    Ok(out)
}

/// The bodies, with unique names.
fn bodies(
    cx: &Checker,
    raw: &[Spanned<format::Body>],
    names: &[&str],
) -> Result<Vec<Body>, DescriptionError> {
    cx.unique("body", raw.iter().map(|b| &b.get_ref().name))?;
    raw.iter()
        .map(|b| {
            let b = b.get_ref();
            let start = b.name.span().start;
            if b.name.get_ref() == GROUND {
                return Err(cx.at(
                    b.name.span().start,
                    Problem::Field {
                        field: "name",
                        reason: "`ground` is the root of the tree, not a body".to_string(),
                    },
                ));
            }
            let line_of = |f: &Option<Field>| cx.line(f.as_ref().map_or(start, |f| f.span().start));
            let zero = |f: &Option<Field>| match f {
                Some(f) => cx.expr(f, names),
                None => Ok(Expr::Number(0.0)),
            };
            Ok(Body {
                name: b.name.get_ref().clone(),
                mass: zero(&b.mass)?,
                centre: cx.vector(&b.centre, names)?,
                inertia: zero(&b.inertia)?,
                lines: [line_of(&b.mass), line_of(&b.inertia)],
            })
        })
        .collect()
}

/// The contact points, each on a body.
fn contacts(
    cx: &Checker,
    raw: &[Spanned<format::Contact>],
    bodies: &[&str],
    names: &[&str],
) -> Result<Vec<Contact>, DescriptionError> {
    cx.unique("contact", raw.iter().map(|c| &c.get_ref().name))?;
    raw.iter()
        .map(|c| {
            let c = c.get_ref();
            Ok(Contact {
                name: c.name.get_ref().clone(),
                body: cx.find(&c.body, bodies, "body")?,
                at: cx.vector(&c.at, names)?,
            })
        })
        .collect()
}

/// The joints, ordered from the ground outward, and the coordinates' names (the free joints in the file's
/// order).
fn joints(
    cx: &Checker,
    raw: &[Spanned<format::Joint>],
    bodies: &[Body],
    names: &[&str],
) -> Result<(Vec<Joint>, Vec<&'static str>), DescriptionError> {
    cx.unique("joint", raw.iter().map(|j| &j.get_ref().name))?;
    let body_names: Vec<&str> = bodies.iter().map(|b| b.name.as_str()).collect();
    let mut coordinates = Vec::new();
    let mut joints = Vec::new();
    for j in raw {
        let joint = joint(cx, j, &body_names, names, coordinates.len())?;
        if matches!(joint.state, State::Free(_)) {
            if coordinates.len() == MAX_COORDINATES {
                return Err(cx.at(
                    j.span().start,
                    Problem::TooManyCoordinates {
                        count: raw.iter().filter(|j| j.get_ref().fixed.is_none()).count(),
                    },
                ));
            }
            coordinates.push(intern(&joint.name));
        }
        joints.push(joint);
    }
    if coordinates.is_empty() {
        return Err(cx.at(
            0,
            Problem::Field {
                field: "joints",
                reason: "no free joint: a walker needs at least one coordinate".to_string(),
            },
        ));
    }
    let ordered = super::tree::ordered(cx, joints, bodies, raw)?;
    Ok((ordered, coordinates))
}

/// One joint, its coordinate (if free) numbered `next`.
fn joint(
    cx: &Checker,
    spanned: &Spanned<format::Joint>,
    bodies: &[&str],
    names: &[&str],
    next: usize,
) -> Result<Joint, DescriptionError> {
    let j = spanned.get_ref();
    let parent = match j.parent.get_ref().as_str() {
        GROUND => None,
        _ => Some(cx.find(&j.parent, bodies, "body")?),
    };
    if j.child.get_ref() == GROUND {
        return Err(misplaced(
            cx,
            j.child.span().start,
            "child",
            "the ground cannot be a child",
        ));
    }
    Ok(Joint {
        name: j.name.get_ref().clone(),
        motion: motion(cx, spanned, names)?,
        parent,
        child: cx.find(&j.child, bodies, "body")?,
        at: cx.vector(&j.at, names)?,
        state: state(cx, j, names, next)?,
        line: cx.line(spanned.span().start),
        field_lines: [
            j.direction.as_ref().map(Spanned::span),
            j.spring.as_ref().map(Spanned::span),
            j.damper.as_ref().map(Spanned::span),
            j.stoppers.as_ref().map(Spanned::span),
        ]
        .map(|s| cx.line(s.unwrap_or(spanned.span()).start)),
    })
}

/// The error of a field that does not belong where it is (or is missing), at byte `offset`.
fn misplaced(cx: &Checker, offset: usize, field: &'static str, reason: &str) -> DescriptionError {
    cx.at(
        offset,
        Problem::Field {
            field,
            reason: reason.to_string(),
        },
    )
}

/// How a joint moves its child: a revolute joint's angle (relative or absolute, its sense), a prismatic joint's
/// direction; each refusing the other's fields.
fn motion(
    cx: &Checker,
    spanned: &Spanned<format::Joint>,
    names: &[&str],
) -> Result<Motion, DescriptionError> {
    let j = spanned.get_ref();
    match *j.kind.get_ref() {
        JointKind::Revolute => {
            if let Some(d) = &j.direction {
                return Err(misplaced(
                    cx,
                    d.span().start,
                    "direction",
                    "only a prismatic joint has a direction",
                ));
            }
            let absolute = j.angle.as_ref().map(|a| *a.get_ref()) == Some(AngleFrom::Absolute);
            let clockwise = j.clockwise.as_ref().is_some_and(|c| *c.get_ref());
            Ok(Motion::Revolute {
                absolute,
                sign: if clockwise { -1.0 } else { 1.0 },
            })
        }
        JointKind::Prismatic => {
            if let Some(a) = &j.angle {
                return Err(misplaced(
                    cx,
                    a.span().start,
                    "angle",
                    "only a revolute joint has an angle",
                ));
            }
            if let Some(c) = &j.clockwise {
                return Err(misplaced(
                    cx,
                    c.span().start,
                    "clockwise",
                    "only a revolute joint turns",
                ));
            }
            let Some(direction) = &j.direction else {
                return Err(misplaced(
                    cx,
                    spanned.span().start,
                    "direction",
                    "a prismatic joint needs its direction [x, z] in the parent's frame",
                ));
            };
            Ok(Motion::Prismatic {
                direction: cx.vector(&Some(direction.get_ref().clone()), names)?,
            })
        }
    }
}

/// A joint's value: free (coordinate `next`, with its spring, damper and stoppers) or fixed (with none).
fn state(
    cx: &Checker,
    j: &format::Joint,
    names: &[&str],
    next: usize,
) -> Result<State, DescriptionError> {
    if let Some(value) = &j.fixed {
        let extra = [
            j.spring.as_ref().map(|s| ("spring", s.span().start)),
            j.damper.as_ref().map(|s| ("damper", s.span().start)),
            j.stoppers.as_ref().map(|s| ("stoppers", s.span().start)),
        ];
        if let Some((field, offset)) = extra.into_iter().flatten().next() {
            return Err(cx.at(
                offset,
                Problem::Field {
                    field,
                    reason: "only a free joint has a spring, a damper or stoppers".to_string(),
                },
            ));
        }
        return Ok(State::Fixed(cx.expr(value, names)?));
    }
    let spring = match &j.spring {
        Some(s) => Some((
            cx.expr(&s.get_ref().stiffness, names)?,
            cx.expr(&s.get_ref().rest, names)?,
        )),
        None => None,
    };
    let damper = match &j.damper {
        Some(d) => Some(cx.expr(&d.get_ref().coefficient, names)?),
        None => None,
    };
    let mut stoppers = [None, None];
    if let Some(s) = &j.stoppers {
        for (slot, field) in stoppers
            .iter_mut()
            .zip([&s.get_ref().lower, &s.get_ref().upper])
        {
            if let Some(f) = field {
                *slot = Some(cx.expr(f, names)?);
            }
        }
    }
    Ok(State::Free(Free {
        coordinate: next,
        spring,
        damper,
        stoppers,
    }))
}
