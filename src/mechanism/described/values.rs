//! The rules on a description's values at one parameter point (docs/model.md section 13): each parameter in its
//! domain, no negative mass, inertia, stiffness or damping, unit directions, stoppers in order. They are checked
//! at the defaults when the file is read (naming the line) and at every point a `--set` or a continuation asks
//! for (naming the parameter).

use super::checker::Checker;
use super::error::{DescriptionError, Problem};
use super::expr::Expr;
use super::model::{
    Description, Motion, Parameter, State, DAMPER_LINE, DIRECTION_LINE, SPRING_LINE, STOPPERS_LINE,
};

/// Why `value` is outside `p`'s domain, if it is.
pub fn outside_domain(p: &Parameter, value: f64) -> Option<String> {
    if !value.is_finite() {
        return Some("a finite number".to_string());
    }
    if p.positive && value <= 0.0 {
        return Some("above 0".to_string());
    }
    match (p.min, p.max) {
        (Some(lo), _) if value < lo => Some(format!("at least {lo}")),
        (_, Some(hi)) if value > hi => Some(format!("at most {hi}")),
        _ => None,
    }
}

/// Directions are unit vectors to this.
pub const UNIT_TOL: f64 = 1e-9;

/// Every broken rule at the parameter values `values`, each with its line.
pub fn problems(d: &Description, values: &[f64]) -> Vec<(usize, Problem)> {
    let of = |e: &Expr| e.eval(values);
    let mut out = Vec::new();
    let mut nonnegative = |line: usize, what: String, value: f64| {
        if !(value >= 0.0 && value.is_finite()) {
            out.push((
                line,
                Problem::OutOfRange {
                    what,
                    value,
                    rule: "finite and at least 0".to_string(),
                },
            ));
        }
    };
    for b in &d.bodies {
        nonnegative(
            b.lines[0],
            format!("the mass of body `{}`", b.name),
            of(&b.mass),
        );
        nonnegative(
            b.lines[1],
            format!("the inertia of body `{}`", b.name),
            of(&b.inertia),
        );
    }
    for j in &d.joints {
        if let State::Free(f) = &j.state {
            if let Some((k, _)) = &f.spring {
                nonnegative(
                    j.field_lines[SPRING_LINE],
                    format!("the stiffness of joint `{}`", j.name),
                    of(k),
                );
            }
            if let Some(c) = &f.damper {
                nonnegative(
                    j.field_lines[DAMPER_LINE],
                    format!("the damping of joint `{}`", j.name),
                    of(c),
                );
            }
        }
    }
    for j in &d.joints {
        out.extend(joint_problems(d, j, values));
    }
    out
}

/// A prismatic joint's direction not a unit vector (or, for the gait's sliding coordinate, not along the
/// slope), or a free joint's stoppers out of order.
fn joint_problems(
    d: &Description,
    j: &super::model::Joint,
    values: &[f64],
) -> Option<(usize, Problem)> {
    let of = |e: &Expr| e.eval(values);
    let at = |line: usize, p: Problem| Some((j.field_lines[line], p));
    if let Motion::Prismatic { direction } = &j.motion {
        let (x, z) = (of(&direction[0]), of(&direction[1]));
        let norm = x.hypot(z);
        // NaN is no unit length either.
        let unit = (norm - 1.0).abs() <= UNIT_TOL;
        if !unit {
            return at(
                DIRECTION_LINE,
                Problem::OutOfRange {
                    what: format!("the length of joint `{}`'s direction", j.name),
                    value: norm,
                    rule: "1 (a unit vector)".to_string(),
                },
            );
        }
        let shifted = d.gait.as_ref().and_then(|g| g.shift);
        let is_shift = matches!(&j.state, State::Free(f) if Some(f.coordinate) == shifted);
        if is_shift && z != 0.0 {
            return at(
                DIRECTION_LINE,
                Problem::OutOfRange {
                    what: format!("the z of joint `{}`'s direction (the gait's shift)", j.name),
                    value: z,
                    rule: "0: the shifted coordinate slides the walker along the slope".to_string(),
                },
            );
        }
    }
    if let State::Free(f) = &j.state {
        if let [Some(lo), Some(hi)] = &f.stoppers {
            let (lo, hi) = (of(lo), of(hi));
            let ordered = lo < hi;
            if !ordered {
                return at(
                    STOPPERS_LINE,
                    Problem::OutOfRange {
                        what: format!("the lower stopper of joint `{}`", j.name),
                        value: lo,
                        rule: format!("below the upper one, {hi}"),
                    },
                );
            }
        }
    }
    None
}

/// The first broken rule at the defaults, as an error at its line.
pub fn check_defaults(cx: &Checker, d: &Description) -> Result<(), DescriptionError> {
    let defaults: Vec<f64> = d.parameters.iter().map(|p| p.default).collect();
    match problems(d, &defaults).into_iter().next() {
        None => Ok(()),
        Some((line, problem)) => Err(DescriptionError::At {
            file: cx.file.to_string(),
            line,
            problem,
        }),
    }
}
