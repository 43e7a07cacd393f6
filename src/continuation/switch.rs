//! Branch switching (docs/model.md section 11): from a period doubling to the family of period-2 orbits it
//! gives birth to, and from a border collision where a family ends to the family of the other piece of the
//! map through the same point.

use nalgebra::{DMatrix, DVector};

use super::arclength::{continue_family, ContinuationError, Family};
use super::corrector::{
    augmented, bordered, correct, solve_on_hyperplane, split, tangent, ContinuationOptions,
};
use super::special::{SpecialKind, SpecialPoint, JUMP_TOL, SIDE_OFFSET};
use super::FamilyMap;

/// Branch switching at a period doubling (docs/model.md section 11): the family of fixed points of `P^2`
/// (period-2 orbits of `P`) born at the located `PD` point `pd` of a family of `map`, followed in both
/// directions. At the period doubling the fixed point of `P` is a branch point of `P^2 - I`, and the new
/// family leaves it along the eigenvector `v` of `DP` for the multiplier -1 at constant parameter; its first
/// point is the fixed point of `P^2` on the hyperplane `v . (x - x* - d v) = 0` with `d` =
/// [`SWITCH_OFFSET`], found by Newton's method from `x* + d v`.
pub fn switch_at_period_doubling<M: FamilyMap>(
    map: &M,
    pd: &SpecialPoint<M::Info>,
    options: &ContinuationOptions,
) -> Result<Family<M::Info>, ContinuationError> {
    let no_start = |reason: String| ContinuationError::NoStart {
        value: pd.param,
        reason,
    };
    if pd.kind != SpecialKind::PeriodDoubling || !pd.located {
        return Err(no_start("not a located period doubling".to_string()));
    }
    let sigma = options.param_scale;
    let n = pd.x.len();
    let ev = map.eval(&pd.x, pd.param).map_err(|e| no_start(e.message))?;
    // The eigenvector of DP for -1: the right singular vector of DP + I for its smallest singular value.
    let svd = (&ev.jacobian + DMatrix::identity(n, n)).svd(false, true);
    let v_t = svd
        .v_t
        .ok_or_else(|| no_start("no singular vectors of DP + I".to_string()))?;
    let k = svd
        .singular_values
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))
        .map_or(0, |(k, _)| k);
    let v = v_t.row(k).transpose();
    let doubled = map.iterated(2);
    let mut errors = Vec::new();
    for d in [SWITCH_OFFSET, -SWITCH_OFFSET, 0.1 * SWITCH_OFFSET] {
        let mut z0 = DVector::zeros(n + 1);
        z0.rows_mut(0, n).copy_from(&(&pd.x + d * &v));
        z0[n] = pd.param / sigma;
        let mut row = DVector::zeros(n + 1);
        row.rows_mut(0, n).copy_from(&v);
        match solve_on_hyperplane(&doubled, &z0, &row, options) {
            Ok(z) => {
                let (x, p) = split(&z, sigma);
                // Not the period-1 fixed point again.
                if (map.value(&x, p).map_err(|e| no_start(e.message))? - &x).amax()
                    < 1e3 * options.tolerance
                {
                    errors.push(format!("offset {d}: converged back to the period-1 family"));
                    continue;
                }
                let p = p.clamp(options.from, options.to);
                return continue_family(&doubled, &x, p, options);
            }
            Err(e) => errors.push(format!("offset {d}: {}", e.message)),
        }
    }
    Err(no_start(format!(
        "no period-2 orbit found next to the period doubling ({})",
        errors.join("; ")
    )))
}

/// Distance along the period-doubling eigenvector (in the section coordinates) at which the period-2 family
/// is first looked for.
pub const SWITCH_OFFSET: f64 = 1e-2;

/// Branch switching at a border collision where a family ends (`bc.ends_family`): the family of fixed points
/// of the map's other piece through the same point. On the border both pieces have the fixed point; the other
/// piece's fixed points near it form a curve whose tangent `t_B` is the null vector of that piece's `J` (taken
/// at [`SIDE_OFFSET`] past the border). Of `+t_B` and `-t_B`, the direction whose first point (a corrector
/// from `z* + d t_B`, `d` = [`BORDER_SWITCH_STEP`]) lies on the other piece is the new family's (at a
/// nonsmooth fold it turns back in the parameter); it is followed from there in both directions (one of which
/// ends at the same border).
pub fn switch_at_border<M: FamilyMap>(
    map: &M,
    bc: &SpecialPoint<M::Info>,
    options: &ContinuationOptions,
) -> Result<Family<M::Info>, ContinuationError> {
    let no_start = |reason: String| ContinuationError::NoStart {
        value: bc.param,
        reason,
    };
    let Some(sides) = bc.sides.as_ref().filter(|_| bc.ends_family && bc.located) else {
        return Err(no_start(
            "not a located border collision that ends a family".to_string(),
        ));
    };
    if bc.jump.is_nan() || bc.jump > JUMP_TOL {
        return Err(no_start(format!(
            "the step map jumps by {:.3e} across the border: no fixed point of the other piece is near",
            bc.jump
        )));
    }
    let other_piece = &sides[1].piece;
    let sigma = options.param_scale;
    let n = bc.x.len();
    let mut z_star = DVector::zeros(n + 1);
    z_star.rows_mut(0, n).copy_from(&bc.x);
    z_star[n] = bc.param / sigma;
    let (x_b, p_b) = split(&(&z_star + SIDE_OFFSET * &bc.direction), sigma);
    let ev = map.eval(&x_b, p_b).map_err(|e| no_start(e.message))?;
    let j = augmented(&ev.jacobian, &ev.dparam, sigma);
    let t_b = tangent(&j, &bc.direction)
        .ok_or_else(|| no_start("the other piece has no unique tangent here".to_string()))?;
    let mut errors = Vec::new();
    for sign in [1.0, -1.0] {
        let t = sign * &t_b;
        let z_pred = &z_star + BORDER_SWITCH_STEP * &t;
        let m = bordered(&j, &t);
        match correct(map, &z_pred, &t, &m, options) {
            Ok((z, _)) => {
                let (x, p) = split(&z, sigma);
                let piece = map
                    .eval(&x, p)
                    .map(|ev| map.piece(&ev.info))
                    .map_err(|e| no_start(e.message))?;
                if &piece == other_piece && (options.from..=options.to).contains(&p) {
                    return continue_family(map, &x, p, options);
                }
                errors.push(format!("direction {sign}: on the piece {piece:?}"));
            }
            Err(e) => errors.push(format!("direction {sign}: {}", e.message)),
        }
    }
    Err(no_start(format!(
        "no fixed point of the other piece ({other_piece}) next to the border ({})",
        errors.join("; ")
    )))
}

/// Distance (in the scaled unknowns) from a border collision at which the other piece's family is first
/// looked for.
pub const BORDER_SWITCH_STEP: f64 = 1e-4;
