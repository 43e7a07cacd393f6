//! Branch switching (docs/model.md section 11): from a period doubling to the family of period-2 orbits it
//! gives birth to.

use nalgebra::{DMatrix, DVector};

use super::arclength::{continue_family, ContinuationError, Family};
use super::corrector::{solve_on_hyperplane, split, ContinuationOptions};
use super::special::{SpecialKind, SpecialPoint};
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
