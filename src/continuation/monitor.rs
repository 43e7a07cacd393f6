//! Quantities monitored along a family and their extrema (docs/model.md section 11).
//!
//! A monitored quantity `q(x, p)` is a function of a point of the map ([`Monitor`]: the VRW's speed, period,
//! largest multiplier's modulus, ...). Along a family `z(s) = (x(s), p(s) / sigma)` its derivative with
//! respect to the arclength is `dq/ds = grad q . t`, `t` the family's unit tangent, the null vector of the
//! exact `J = [DP - I, sigma dP/dp]`. The quantity's own gradient is not known exactly (a walk's report has
//! no derivatives, a multiplier's would need second derivatives of `P`), so `grad q . t` is the central
//! difference of `q` along the tangent, `(q(z + h t) - q(z - h t)) / 2h` with `h =` [`MONITOR_STEP`]: one
//! evaluation of the map each way. Along the tangent line (not the family) this differs from `dq/ds` by
//! `O(h^2)` only, the family being tangent to the line.
//!
//! **Extrema.** Where `dq/ds` changes sign between two successive points of a family, `q` is stationary in
//! between. If the two points lie on the same smooth piece of `q` (the same event sequence, and for the
//! largest multiplier's modulus the same kind of largest multiplier, [`Monitor::shape`]), the zero of `dq/ds`
//! is located by regula falsi (Illinois) with bisection steps along the chord between them, each probe a
//! corrected family point with its own tangent and derivative, until the bracket is below [`EXTREMUM_TOL`]
//! in the parameter and in the state: a smooth `max` or `min`. If they lie on different pieces the change of
//! piece is bracketed by bisection to the same width and the stationary point is a **corner** there, never a
//! smooth extremum: its kind comes from one-sided differences of `q` on either side of the bracket (a corner
//! whose one-sided slopes have the same sign is no extremum, and the sign change is reported unlocated).

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use super::corrector::{
    augmented, bordered, correct, point_at, solve_on_hyperplane, split, ContinuationOptions,
    FamilyPoint,
};
use super::special::{SpecialKind, SpecialPoint};
use super::{Family, FamilyMap, MapFailure};

/// Step (in the scaled unknowns) of the central differences of a monitored quantity along the tangent.
pub const MONITOR_STEP: f64 = 1e-4;

/// Extrema (and corners) are located to this in the parameter and in the state.
pub const EXTREMUM_TOL: f64 = 1e-8;

/// Probes allowed to locate one extremum.
const MAX_EXTREMUM_PROBES: usize = 100;

/// A quantity of a point of a family's map, monitored along the family.
pub trait Monitor<I>: Sync {
    /// Its name.
    fn name(&self) -> &str;

    /// Its value at the point `at` (`NaN` where it has none).
    fn value(&self, at: &At<'_, I>) -> f64;

    /// The smooth piece of its formula at the point (the largest multiplier's modulus: a real multiplier or a
    /// complex pair); points on different pieces are separated by a corner of the quantity. Empty where one
    /// formula holds everywhere.
    fn shape(&self, _at: &At<'_, I>) -> String {
        String::new()
    }
}

/// A point of a family's map where a monitored quantity is read: the state, the parameter, `DP` there and
/// what the map records of it.
#[derive(Debug, Clone, Copy)]
pub struct At<'a, I> {
    /// The state.
    pub x: &'a DVector<f64>,
    /// The parameter.
    pub p: f64,
    /// `DP` there.
    pub jacobian: &'a DMatrix<f64>,
    /// What the map records of the point.
    pub info: &'a I,
}

impl<'a, I> At<'a, I> {
    /// A family point.
    pub fn point(point: &'a FamilyPoint<I>) -> At<'a, I> {
        At {
            x: &point.x,
            p: point.param,
            jacobian: &point.jacobian,
            info: &point.info,
        }
    }
}

/// A monitored quantity at a point of a family.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Monitored {
    /// Its value.
    pub value: f64,
    /// `dq/ds` along the family's arclength (in the scaled unknowns), in the direction of increasing
    /// arclength; `NaN` where a difference's evaluation fails.
    pub derivative: f64,
}

/// A maximum or a minimum.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ExtremumKind {
    /// `dq/ds` goes from positive to negative.
    Max,
    /// `dq/ds` goes from negative to positive.
    Min,
}

impl std::fmt::Display for ExtremumKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ExtremumKind::Max => "max",
            ExtremumKind::Min => "min",
        })
    }
}

/// An extremum of a monitored quantity along a family.
#[derive(Debug, Clone, PartialEq)]
pub struct Extremum<I> {
    /// The quantity's name.
    pub quantity: String,
    /// `max` or `min`.
    pub kind: ExtremumKind,
    /// `None`: smooth (a zero of `dq/ds`); else a corner, and why the quantity is not smooth there.
    pub corner: Option<String>,
    /// The quantity there.
    pub value: f64,
    /// The parameters of the located bracket's ends (width at most [`EXTREMUM_TOL`] where located).
    pub located_bracket: [f64; 2],
    /// The point as a special point of kind [`SpecialKind::Extremum`]: `test_value` is `dq/ds` there (`NaN`
    /// at a corner), `bracket` the two family points it was detected between.
    pub special: SpecialPoint<I>,
}

/// The family's points' tangents, oriented along increasing arclength.
fn oriented_tangents<I>(family: &Family<I>, sigma: f64) -> Vec<DVector<f64>> {
    let pts = &family.points;
    let n = pts.len();
    (0..n)
        .map(|i| {
            let t = &pts[i].tangent;
            if n < 2 {
                return t.clone();
            }
            let chord = pts[(i + 1).min(n - 1)].z(sigma) - pts[i.saturating_sub(1)].z(sigma);
            if t.dot(&chord) < 0.0 {
                -t
            } else {
                t.clone()
            }
        })
        .collect()
}

/// The map evaluated at `z + step t` (`None` where it fails), to read monitored quantities from.
struct Evaluated<I> {
    x: DVector<f64>,
    p: f64,
    ev: super::Evaluation<I>,
}

impl<I> Evaluated<I> {
    /// The monitor's value here.
    fn value(&self, monitor: &dyn Monitor<I>) -> f64 {
        monitor.value(&At {
            x: &self.x,
            p: self.p,
            jacobian: &self.ev.jacobian,
            info: &self.ev.info,
        })
    }
}

/// [`Evaluated`] at `z + step t`.
fn evaluated<M: FamilyMap>(
    map: &M,
    z: &DVector<f64>,
    t: &DVector<f64>,
    step: f64,
    sigma: f64,
) -> Option<Evaluated<M::Info>> {
    let (x, p) = split(&(z + step * t), sigma);
    let ev = map.eval(&x, p).ok()?;
    Some(Evaluated { x, p, ev })
}

/// `dq/ds` of each monitor at `z` along the unit tangent `t`: central differences along `t` (step
/// [`MONITOR_STEP`]), `NaN` where an evaluation fails.
pub fn derivatives<M: FamilyMap>(
    map: &M,
    monitors: &[&dyn Monitor<M::Info>],
    z: &DVector<f64>,
    t: &DVector<f64>,
    sigma: f64,
) -> Vec<f64> {
    let (plus, minus) = rayon::join(
        || evaluated(map, z, t, MONITOR_STEP, sigma),
        || evaluated(map, z, t, -MONITOR_STEP, sigma),
    );
    monitors
        .iter()
        .map(|m| match (&plus, &minus) {
            (Some(a), Some(b)) => (a.value(*m) - b.value(*m)) / (2.0 * MONITOR_STEP),
            _ => f64::NAN,
        })
        .collect()
}

/// Every monitor at every point of `family` (`[point][monitor]`), with its derivative along the family.
pub fn monitor_family<M: FamilyMap>(
    map: &M,
    family: &Family<M::Info>,
    monitors: &[&dyn Monitor<M::Info>],
) -> Vec<Vec<Monitored>> {
    let sigma = family.options.param_scale;
    let tangents = oriented_tangents(family, sigma);
    family
        .points
        .iter()
        .zip(&tangents)
        .map(|(point, t)| {
            let d = derivatives(map, monitors, &point.z(sigma), t, sigma);
            monitors
                .iter()
                .zip(d)
                .map(|(m, derivative)| Monitored {
                    value: m.value(&At::point(point)),
                    derivative,
                })
                .collect()
        })
        .collect()
}

/// The extrema of `monitor` along `family`, from its values at the family's points (`monitored`, one per
/// point): one per sign change of `dq/ds` between successive points (see the module documentation).
pub fn extrema<M: FamilyMap>(
    map: &M,
    family: &Family<M::Info>,
    monitor: &dyn Monitor<M::Info>,
    monitored: &[Monitored],
) -> Vec<Extremum<M::Info>> {
    let sigma = family.options.param_scale;
    let tangents = oriented_tangents(family, sigma);
    let pts = &family.points;
    (1..pts.len().min(monitored.len()))
        .filter(|&i| {
            let (ga, gb) = (monitored[i - 1].derivative, monitored[i].derivative);
            ga.is_finite() && gb.is_finite() && (ga < 0.0) != (gb < 0.0)
        })
        .map(|i| {
            let a = Probe::of(&pts[i - 1], &tangents[i - 1], monitored[i - 1].derivative);
            let b = Probe::of(&pts[i], &tangents[i], monitored[i].derivative);
            locate(map, monitor, &a, &b, &family.options)
        })
        .collect()
}

/// A corrected family point with its tangent (along increasing arclength) and `dq/ds`.
#[derive(Debug, Clone)]
struct Probe<I> {
    point: FamilyPoint<I>,
    tangent: DVector<f64>,
    derivative: f64,
}

impl<I: Clone> Probe<I> {
    fn of(point: &FamilyPoint<I>, tangent: &DVector<f64>, derivative: f64) -> Probe<I> {
        Probe {
            point: point.clone(),
            tangent: tangent.clone(),
            derivative,
        }
    }
}

/// The piece of `monitor` at a point: the event sequence and the quantity's own shape.
fn piece_of<M: FamilyMap>(
    map: &M,
    monitor: &dyn Monitor<M::Info>,
    p: &FamilyPoint<M::Info>,
) -> String {
    let shape = monitor.shape(&At::point(p));
    format!("{} | {shape}", map.piece(&p.info))
}

/// The extremum between the successive family points `a` and `b`, where `dq/ds` changes sign.
fn locate<M: FamilyMap>(
    map: &M,
    monitor: &dyn Monitor<M::Info>,
    a: &Probe<M::Info>,
    b: &Probe<M::Info>,
    options: &ContinuationOptions,
) -> Extremum<M::Info> {
    let kind = if a.derivative > 0.0 {
        ExtremumKind::Max
    } else {
        ExtremumKind::Min
    };
    let (piece_a, piece_b) = (
        piece_of(map, monitor, &a.point),
        piece_of(map, monitor, &b.point),
    );
    let located = if piece_a == piece_b {
        zero_of_derivative(map, monitor, a, b, options)
    } else {
        corner(map, monitor, a, b, options, (&piece_a, &piece_b))
    };
    let sigma = options.param_scale;
    let mut special = SpecialPoint {
        kind: SpecialKind::Extremum,
        param: 0.5 * (a.point.param + b.point.param),
        x: (&a.point.x + &b.point.x) * 0.5,
        arclength: 0.5 * (a.point.arclength + b.point.arclength),
        bracket: [a.point.param, b.point.param],
        located: false,
        method: "not located".to_string(),
        iterations: 0,
        residual: f64::NAN,
        test_value: f64::NAN,
        multipliers: Vec::new(),
        border: None,
        sides: None,
        info: None,
        note: None,
        direction: a.tangent.clone(),
        ends_family: false,
        jump: f64::NAN,
    };
    let mut extremum = Extremum {
        quantity: monitor.name().to_string(),
        kind,
        corner: None,
        value: f64::NAN,
        located_bracket: [f64::NAN; 2],
        special: special.clone(),
    };
    match located {
        Ok(found) => {
            let p = &found.at.point;
            special.param = p.param;
            special.x = p.x.clone();
            let along = (p.z(sigma) - a.point.z(sigma)).norm();
            special.arclength =
                a.point.arclength + along.min(b.point.arclength - a.point.arclength);
            special.located = true;
            special.method = found.method;
            special.iterations = found.probes;
            special.residual = p.residual;
            // At a corner dq/ds has no value (the central difference there straddles it).
            special.test_value = if found.corner.is_some() {
                f64::NAN
            } else {
                found.at.derivative
            };
            special.multipliers = p.multipliers.clone();
            special.info = Some(p.info.clone());
            special.direction = found.at.tangent.clone();
            extremum.kind = found.kind.unwrap_or(kind);
            extremum.corner = found.corner;
            extremum.value = monitor.value(&At::point(p));
            extremum.located_bracket = found.bracket;
        }
        Err(why) => special.note = Some(why),
    }
    extremum.special = special;
    extremum
}

/// A located extremum: the point, its bracket, how, and for a corner its kind (from one-sided slopes) and
/// why it is one.
struct Found<I> {
    at: Probe<I>,
    bracket: [f64; 2],
    probes: usize,
    method: String,
    kind: Option<ExtremumKind>,
    corner: Option<String>,
}

/// The family point on the hyperplane normal to the chord `a -> b` through `a + w (b - a)` (the chord method
/// with `a`'s matrix, else Newton's method with `DP` at every iterate), with its tangent oriented along the
/// chord.
fn probe_at<M: FamilyMap>(
    map: &M,
    monitor: &dyn Monitor<M::Info>,
    (a, b): (&FamilyPoint<M::Info>, &FamilyPoint<M::Info>),
    w: f64,
    options: &ContinuationOptions,
) -> Result<Probe<M::Info>, MapFailure> {
    let sigma = options.param_scale;
    let (za, zb) = (a.z(sigma), b.z(sigma));
    let d = (&zb - &za).normalize();
    let z = &za + w * (&zb - &za);
    let m = bordered(&augmented(&a.jacobian, &a.dparam, sigma), &d);
    let zc = correct(map, &z, &d, &m, options)
        .map(|(z, _)| z)
        .or_else(|_| solve_on_hyperplane(map, &z, &d, options))?;
    let point = point_at(map, &zc, &d, options)?;
    let derivative = derivatives(map, &[monitor], &zc, &point.tangent, sigma)[0];
    Ok(Probe {
        tangent: point.tangent.clone(),
        point,
        derivative,
    })
}

/// Is the bracket `[lo, hi]` narrower than [`EXTREMUM_TOL`] in the parameter and the state?
fn narrow<I>(lo: &FamilyPoint<I>, hi: &FamilyPoint<I>) -> bool {
    (hi.param - lo.param).abs() <= EXTREMUM_TOL && (&hi.x - &lo.x).amax() <= EXTREMUM_TOL
}

/// The zero of `dq/ds` between `a` and `b` (on one smooth piece): regula falsi (Illinois) along the chord, a
/// bisection step wherever the bracket did not halve.
fn zero_of_derivative<M: FamilyMap>(
    map: &M,
    monitor: &dyn Monitor<M::Info>,
    a: &Probe<M::Info>,
    b: &Probe<M::Info>,
    options: &ContinuationOptions,
) -> Result<Found<M::Info>, String> {
    let (mut wl, mut lo) = (0.0, a.clone());
    let (mut wh, mut hi) = (1.0, b.clone());
    let (mut gl, mut gh) = (a.derivative, b.derivative);
    let mut last_side = 0;
    let mut width = 1.0;
    for probes in 1..=MAX_EXTREMUM_PROBES {
        if narrow(&lo.point, &hi.point) {
            let at = if lo.derivative.abs() <= hi.derivative.abs() {
                lo.clone()
            } else {
                hi.clone()
            };
            return Ok(Found {
                bracket: [lo.point.param, hi.point.param],
                probes: probes - 1,
                method: format!(
                    "regula falsi on dq/ds along the family: {} probes",
                    probes - 1
                ),
                kind: None,
                corner: hidden_corner(map, monitor, &at, options.param_scale),
                at,
            });
        }
        let secant = wl - gl * (wh - wl) / (gh - gl);
        let w = if wh - wl > 0.5 * width || !(secant > wl && secant < wh) {
            0.5 * (wl + wh)
        } else {
            secant
        };
        width = wh - wl;
        let probe = probe_at(map, monitor, (&a.point, &b.point), w, options)
            .map_err(|e| format!("a probe at {w} of the bracket failed: {}", e.message))?;
        let g = probe.derivative;
        if !g.is_finite() {
            return Err(format!("dq/ds is not defined at p = {}", probe.point.param));
        }
        if (g < 0.0) == (gl < 0.0) {
            (wl, gl, lo) = (w, g, probe);
            // Illinois: halve the other end's value when the same end moves twice.
            if last_side == -1 {
                gh *= 0.5;
            }
            last_side = -1;
        } else {
            (wh, gh, hi) = (w, g, probe);
            if last_side == 1 {
                gl *= 0.5;
            }
            last_side = 1;
        }
    }
    Err(format!("not located in {MAX_EXTREMUM_PROBES} probes"))
}

/// The corner between `a` and `b`, whose quantities lie on different pieces: the change of piece bracketed by
/// bisection, then its kind from the one-sided slopes of `q` on either side of the bracket.
fn corner<M: FamilyMap>(
    map: &M,
    monitor: &dyn Monitor<M::Info>,
    a: &Probe<M::Info>,
    b: &Probe<M::Info>,
    options: &ContinuationOptions,
    (piece_a, piece_b): (&str, &str),
) -> Result<Found<M::Info>, String> {
    let (mut wl, mut lo) = (0.0, a.clone());
    let (mut wh, mut hi) = (1.0, b.clone());
    let mut probes = 0;
    while !narrow(&lo.point, &hi.point) {
        if probes == MAX_EXTREMUM_PROBES {
            return Err(format!(
                "the corner was not bracketed in {MAX_EXTREMUM_PROBES} probes"
            ));
        }
        probes += 1;
        let w = 0.5 * (wl + wh);
        let probe = probe_at(map, monitor, (&a.point, &b.point), w, options)
            .map_err(|e| format!("a probe at {w} of the bracket failed: {}", e.message))?;
        if piece_of(map, monitor, &probe.point) == piece_a {
            (wl, lo) = (w, probe);
        } else {
            (wh, hi) = (w, probe);
        }
    }
    let sigma = options.param_scale;
    let (before, after) = (
        one_sided(map, monitor, &lo, -MONITOR_STEP, sigma),
        one_sided(map, monitor, &hi, MONITOR_STEP, sigma),
    );
    let why = corner_words(piece_a, piece_b);
    let kind = match (before < 0.0, after < 0.0) {
        _ if !(before.is_finite() && after.is_finite()) => {
            return Err(format!("{why}; its one-sided slopes could not be computed"))
        }
        (false, true) => ExtremumKind::Max,
        (true, false) => ExtremumKind::Min,
        _ => {
            return Err(format!(
                "{why}, but q has the same monotony on both sides of it (one-sided dq/ds {before:.3e} and \
                 {after:.3e}): dq/ds changes sign elsewhere in the bracket, not located"
            ))
        }
    };
    Ok(Found {
        bracket: [lo.point.param, hi.point.param],
        probes,
        method: format!(
            "bisection on the change of piece along the family: {probes} probes; one-sided dq/ds {before:.6e} \
             and {after:.6e}"
        ),
        kind: Some(kind),
        corner: Some(why),
        at: lo,
    })
}

/// Why the quantity has a corner between the pieces `a` and `b` (`event sequence | shape`).
fn corner_words(a: &str, b: &str) -> String {
    let split = |s: &str| -> (String, String) {
        let mut parts = s.splitn(2, " | ");
        (
            parts.next().unwrap_or_default().to_string(),
            parts.next().unwrap_or_default().to_string(),
        )
    };
    let ((seq_a, shape_a), (seq_b, shape_b)) = (split(a), split(b));
    if seq_a != seq_b {
        format!("the event sequence changes from {seq_a} to {seq_b}")
    } else {
        format!("the quantity changes from {shape_a} to {shape_b}")
    }
}

/// The one-sided difference of `q` at the probe `p` along its tangent with the signed `step`:
/// `(q(z + step t) - q(z)) / step`; `NaN` where the evaluation fails.
fn one_sided<M: FamilyMap>(
    map: &M,
    monitor: &dyn Monitor<M::Info>,
    p: &Probe<M::Info>,
    step: f64,
    sigma: f64,
) -> f64 {
    evaluated(map, &p.point.z(sigma), &p.tangent, step, sigma).map_or(f64::NAN, |e| {
        (e.value(monitor) - monitor.value(&At::point(&p.point))) / step
    })
}

/// At a zero of `dq/ds` found on one piece of `q`: is `q` smooth there? The one-sided differences at steps
/// `h` and `h / 2` ([`MONITOR_STEP`]) of a smooth `q` halve with the step (they are `q'' h / 2`); at a corner
/// the shape test did not see (two real multipliers whose moduli cross) they keep their slopes. `None`:
/// smooth; else the corner in words. Differences that cannot be computed leave it smooth.
fn hidden_corner<M: FamilyMap>(
    map: &M,
    monitor: &dyn Monitor<M::Info>,
    at: &Probe<M::Info>,
    sigma: f64,
) -> Option<String> {
    let h = MONITOR_STEP;
    let d = |step: f64| one_sided(map, monitor, at, step, sigma);
    let (f1, f2, b1, b2) = (d(h), d(0.5 * h), d(-h), d(-0.5 * h));
    let halves = |wide: f64, narrow: f64| {
        let ratio = wide / narrow;
        !ratio.is_finite() || (1.5..=2.5).contains(&ratio) || (wide - narrow).abs() < 1e-12
    };
    if !(f1.is_finite() && f2.is_finite() && b1.is_finite() && b2.is_finite()) {
        return None;
    }
    (!(halves(f1, f2) && halves(b1, b2))).then(|| {
        format!(
            "the one-sided dq/ds do not vanish at the stationary point ({b2:.3e} before, {f2:.3e} after, at \
             steps {:e}): q has a corner there",
            0.5 * h
        )
    })
}
