//! Tests of the interface on the compass gait: the laws its equations and the general solves must obey.

use nalgebra::{SVector, Vector2};

use super::compass::{Compass, THETA1, THETA2, X, Z};
use super::constrained::{accelerations, impulse, Row};
use super::rigid::{RigidOptions, RigidWalker};
use super::rigid_gait::{rigid_gait, RigidGait};
use super::simplest::Simplest;
use super::Mechanism;
use crate::integrate::Tolerances;
use nalgebra::DVector;

type Q = SVector<f64, 4>;

/// The compass gait just before heel strike: Leg 1 the stance leg behind the hip (`theta1 = -a`), Leg 2's
/// foot reaching the ground ahead (`theta2 = a`), velocities made consistent with Leg 1's foot held.
fn before_heel_strike(compass: &Compass, a: f64) -> (Q, Q) {
    let q = Q::from([0.0, a.cos(), -a, a]);
    let guess = Q::from([0.9, 0.1, -1.1, 0.6]);
    let held = impulse(compass, &q, &guess, &Row::contact(0)).unwrap();
    (q, held.qd_plus)
}

/// `sum m (p - o) x v` over the walker's masses (`o` the point about which), or over Leg 1's mass alone.
fn angular_momentum(compass: &Compass, q: &Q, qd: &Q, about: Vector2<f64>, leg1_only: bool) -> f64 {
    let from_hip = compass.leg_length - compass.leg_mass_offset;
    let hip = Vector2::new(q[X], q[Z]);
    let hip_v = Vector2::new(qd[X], qd[Z]);
    let leg = |k: usize| {
        let (s, c) = q[k].sin_cos();
        let p = hip + from_hip * Vector2::new(s, -c);
        let v = hip_v + from_hip * qd[k] * Vector2::new(c, s);
        (p, v)
    };
    let cross = |m: f64, (p, v): (Vector2<f64>, Vector2<f64>)| m * (p - about).perp(&v);
    if leg1_only {
        return cross(compass.leg_mass, leg(THETA1));
    }
    cross(compass.hip_mass, (hip, hip_v))
        + cross(compass.leg_mass, leg(THETA1))
        + cross(compass.leg_mass, leg(THETA2))
}

/// The mass matrix is symmetric positive definite, and the potential energy is that of the three masses.
#[test]
fn the_compass_mass_matrix_is_symmetric_positive_definite() {
    let compass = Compass::default();
    let q = Q::from([0.3, 0.9, -0.25, 0.4]);
    let e = compass.equations(&compass.constants_f64(), &q, &Q::zeros());
    assert_eq!(e.mass, e.mass.transpose());
    assert!(e.mass.symmetric_eigenvalues().min() > 0.0);
    // Total mass on the hip's translation.
    let total = compass.hip_mass + 2.0 * compass.leg_mass;
    assert!((e.mass[(X, X)] - total).abs() < 1e-12 && (e.mass[(Z, Z)] - total).abs() < 1e-12);
    let g = compass.gravity;
    let (sp, cp) = compass.slope.sin_cos();
    let height = |p: Vector2<f64>| g * (-p.x * sp + p.y * cp);
    let b = compass.leg_length - compass.leg_mass_offset;
    let hip = Vector2::new(q[X], q[Z]);
    let leg = |t: f64| hip + b * Vector2::new(t.sin(), -t.cos());
    let expected = compass.hip_mass * height(hip)
        + compass.leg_mass * (height(leg(q[THETA1])) + height(leg(q[THETA2])));
    assert!((compass.potential_energy(&q) - expected).abs() < 1e-12);
}

/// In single support (Leg 1's foot held) the walker conserves `T + V` and its foot stays put: the bias `h`
/// holds the right Coriolis and gravity terms (integrated by RK4 over 0.4 s).
#[test]
fn single_support_conserves_energy_and_holds_the_foot() {
    let compass = Compass::default();
    let (q0, qd0) = before_heel_strike(&compass, 0.15);
    let rows = Row::contact(0);
    let field = |q: &Q, qd: &Q| (*qd, accelerations(&compass, q, qd, &rows).unwrap().qdd);
    let (mut q, mut qd) = (q0, qd0);
    let dt = 1e-3;
    for _ in 0..400 {
        let k1 = field(&q, &qd);
        let k2 = field(&(q + 0.5 * dt * k1.0), &(qd + 0.5 * dt * k1.1));
        let k3 = field(&(q + 0.5 * dt * k2.0), &(qd + 0.5 * dt * k2.1));
        let k4 = field(&(q + dt * k3.0), &(qd + dt * k3.1));
        q += dt / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
        qd += dt / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
    }
    let drift = compass.energy(&q, &qd) - compass.energy(&q0, &qd0);
    assert!(drift.abs() < 1e-9, "energy drift {drift:e} J");
    let c = compass.constants_f64();
    let foot0 = compass.contact(&c, &q0, &qd0, 0).position;
    let foot = compass.contact(&c, &q, &qd, 0);
    assert!((foot.position - foot0).amax() < 1e-9 && foot.velocity(&qd).amax() < 1e-9);
}

/// Heel strike with the traditional impact (the new foot held, the rear one released): the general impulse
/// solve conserves the walker's angular momentum about the new foot and Leg 1's about the hip, the two laws
/// Goswami, Thuilot and Espiau's impact model is made of (their Eq. (4)), and the new foot stops.
#[test]
fn heel_strike_conserves_goswamis_angular_momenta() {
    let compass = Compass::default();
    let (q, qd) = before_heel_strike(&compass, 0.2);
    let c = compass.constants_f64();
    let new_foot = compass.contact(&c, &q, &qd, 1).position;
    assert!(new_foot.y.abs() < 1e-12, "Leg 2's foot is on the ground");
    let after = impulse(&compass, &q, &qd, &Row::contact(1)).unwrap();
    let hip = Vector2::new(q[X], q[Z]);
    for (about, leg1_only) in [(new_foot, false), (hip, true)] {
        let before = angular_momentum(&compass, &q, &qd, about, leg1_only);
        let after = angular_momentum(&compass, &q, &after.qd_plus, about, leg1_only);
        assert!((after - before).abs() < 1e-12, "{before} -> {after}");
    }
    assert!(
        compass
            .contact(&c, &q, &after.qd_plus, 1)
            .velocity(&after.qd_plus)
            .amax()
            < 1e-12
    );
    // The rear foot leaves the ground (its normal velocity is upward), and the impact loses energy.
    assert!(
        compass
            .contact(&c, &q, &after.qd_plus, 0)
            .velocity(&after.qd_plus)
            .y
            > 0.0
    );
    assert!(compass.energy(&q, &after.qd_plus) < compass.energy(&q, &qd));
}

/// The DLS indicator `lambda_I4` of the compass gait (docs/model.md section 13): the rear foot's normal impulse
/// of the impact with both feet held (the paper's (A1)). Rigid legs leave double support no freedom (four rows
/// for four coordinates: the walker stops), so its sign decides the impact: negative, the ground would have to
/// pull the rear foot down to stop the walker, which it cannot, and the rear foot leaves (the traditional
/// impact); positive, the walker stops in double support.
#[test]
fn the_rear_foot_of_the_compass_gait_leaves_at_heel_strike() {
    let compass = Compass::default();
    let (q, qd) = before_heel_strike(&compass, 0.2);
    let both = [Row::contact(0), Row::contact(1)].concat();
    let held = impulse(&compass, &q, &qd, &both).unwrap();
    assert!(
        held.qd_plus.amax() < 1e-12,
        "held by both feet, the walker stops: {:?}",
        held.qd_plus
    );
    let lambda_i4 = held.impulses[1];
    assert!(lambda_i4 < 0.0, "lambda_I4 = {lambda_i4}");
}

/// Bad parameters are refused, every broken rule named.
#[test]
fn bad_compass_parameters_name_every_key() {
    let bad = Compass {
        hip_mass: -1.0,
        leg_mass_offset: 2.0,
        slope: 2.0,
        ..Compass::default()
    };
    let message = bad.validate().unwrap_err().to_string();
    for key in ["hip_mass", "leg_mass_offset", "slope"] {
        assert!(message.contains(key), "{message}");
    }
    assert!(Compass::default().validate().is_ok());
    // A leg with its mass at the hip has no inertia, and a hip a billion times the legs makes M singular to
    // rounding: both are refused before any walk.
    let at_hip = Compass {
        leg_mass_offset: 1.0,
        ..Compass::default()
    };
    assert!(at_hip
        .validate()
        .unwrap_err()
        .to_string()
        .contains("below the hip"));
    let heavy = Compass {
        hip_mass: 1e9,
        ..Compass::default()
    };
    assert!(heavy
        .validate()
        .unwrap_err()
        .to_string()
        .contains("leg_mass / hip_mass"));
}

/// The compass gait's equations over dual numbers carry their exact derivatives (as the wheel's do for the
/// step map's `DP` and `dP/dp`, docs/model.md section 10): `d(M, h)/d leg_mass` and `d(M, h)/d theta1` agree with
/// central differences.
#[test]
fn the_compass_equations_differentiate_exactly() {
    use crate::variational::Dual;
    let compass = Compass::default();
    let q = Q::from([0.1, 0.95, -0.2, 0.3]);
    let qd = Q::from([0.8, -0.1, -1.2, 0.9]);
    let flat = |e: super::Equations<f64, 4>| {
        let mut v: Vec<f64> = e.mass.as_slice().to_vec();
        v.extend_from_slice(e.bias.as_slice());
        v
    };
    let seed = |on: bool, x: f64| Dual::<1>::new(x, SVector::from([f64::from(u8::from(on))]));
    // By the mass of the legs: the constants seeded.
    let c = compass.constants(&|key, v| seed(key == "leg_mass", v));
    let lift = |x: &Q| x.map(|v| seed(false, v));
    let dual = compass.equations(&c, &lift(&q), &lift(&qd));
    let exact: Vec<f64> = dual
        .mass
        .iter()
        .chain(dual.bias.iter())
        .map(|d| d.eps[0])
        .collect();
    let h = 1e-6;
    let at = |m: f64| {
        let shifted = Compass {
            leg_mass: m,
            ..compass
        };
        flat(shifted.equations(&shifted.constants_f64(), &q, &qd))
    };
    let (plus, minus) = (at(compass.leg_mass + h), at(compass.leg_mass - h));
    for (k, e) in exact.iter().enumerate() {
        let fd = (plus[k] - minus[k]) / (2.0 * h);
        assert!(
            (e - fd).abs() < 1e-7 * (1.0 + fd.abs()),
            "entry {k}: {e} vs {fd}"
        );
    }
    // By the angle of Leg 1: the coordinate seeded.
    let c = compass.constants(&|_, v| seed(false, v));
    let mut qs = lift(&q);
    qs[THETA1] = seed(true, q[THETA1]);
    let dual = compass.equations(&c, &qs, &lift(&qd));
    let exact: Vec<f64> = dual
        .mass
        .iter()
        .chain(dual.bias.iter())
        .map(|d| d.eps[0])
        .collect();
    let at = |t: f64| {
        let mut shifted = q;
        shifted[THETA1] = t;
        flat(compass.equations(&compass.constants_f64(), &shifted, &qd))
    };
    let (plus, minus) = (at(q[THETA1] + h), at(q[THETA1] - h));
    for (k, e) in exact.iter().enumerate() {
        let fd = (plus[k] - minus[k]) / (2.0 * h);
        assert!(
            (e - fd).abs() < 1e-7 * (1.0 + fd.abs()),
            "entry {k}: {e} vs {fd}"
        );
    }
}

/// The gait of `walker` from `start`, with the walk's default options.
fn gait_of<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    start: &[f64],
) -> RigidGait<N> {
    rigid_gait(
        walker,
        &DVector::from_column_slice(start),
        &RigidOptions::default(),
    )
    .unwrap()
}

/// Garcia, Chatterjee, Ruina and Coleman's stable gait at `gamma = 0.009`: the paper's fixed point
/// `(theta, theta') = (0.2003, -0.1998)` (their section 4), stable with a complex pair of multipliers. Second
/// routes: over a step the hip's loss at heel strike is gravity's work `sin(gamma)` times the step length
/// `2 sin(theta)` (the energy balance of a period), the step conserves `T + V`, and the fixed point is the same
/// with the integrator's tolerance 100 times looser.
#[test]
fn the_simplest_walkers_gait_is_garcias() {
    let walker = Simplest { slope: 0.009 };
    let gait = gait_of(&walker, &[0.2, -0.2]);
    let (theta, w) = (gait.section[0], gait.section[1]);
    assert!(
        (theta - 0.2003).abs() < 5e-5 && (w + 0.1998).abs() < 5e-5,
        "{theta}, {w}"
    );
    assert!(
        gait.largest_multiplier() < 1.0 && gait.multipliers[0][1].abs() > 0.1,
        "{:?}",
        gait.multipliers
    );
    let work = walker.slope.sin() * 2.0 * theta.sin();
    assert_balanced(&gait, work, 1e-12, 1e-10);
    let loose = RigidOptions {
        tolerances: Tolerances {
            rtol: 1e-10,
            atol: 1e-11,
            ..RigidOptions::default().tolerances
        },
        ..RigidOptions::default()
    };
    let other = rigid_gait(&walker, &gait.section, &loose).unwrap();
    assert!((other.section - &gait.section).amax() < 1e-9);
}

/// The energy balance of a period of `gait`: its heel strike takes gravity's `work` over the step (to `relative`),
/// single support conserves `T + V` (to `drift`), and the rear foot leaves at the heel strike after one scuff.
fn assert_balanced<const N: usize>(gait: &RigidGait<N>, work: f64, relative: f64, drift: f64) {
    let step = &gait.step;
    let loss = step.impact_loss;
    assert!(
        (loss - work).abs() < relative * work.max(1.0),
        "{loss} vs {work}"
    );
    assert!(step.energy_drift < drift, "{:e}", step.energy_drift);
    assert!(step.lambda_i4 < 0.0 && step.scuffs == 1, "{step:?}");
}

/// The largest multiplier's modulus less 1 of the walker's gait at `value`, continued from `start`.
fn past_unit_circle<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    start: &mut DVector<f64>,
) -> f64 {
    let gait = rigid_gait(walker, start, &RigidOptions::default()).unwrap();
    *start = gait.section.clone();
    assert!(
        gait.multipliers[0][1] == 0.0 && gait.multipliers[0][0] < 0.0,
        "{:?}",
        gait.multipliers
    );
    gait.largest_multiplier() - 1.0
}

/// The simplest walker's gait loses its stability at the first period doubling of its cascade, near
/// `gamma = 0.015` (the paper: stable for `0 < gamma < 0.015`): a real multiplier crosses -1, located by
/// bisection to 1e-9 in `gamma`.
#[test]
fn the_simplest_walker_period_doubles_near_0_015() {
    let (mut lo, mut hi) = (0.0150, 0.0155);
    let mut start = gait_of(&Simplest { slope: lo }, &[0.2367, -0.2315]).section;
    assert!(past_unit_circle(&Simplest { slope: lo }, &mut start) < 0.0);
    assert!(past_unit_circle(&Simplest { slope: hi }, &mut start.clone()) > 0.0);
    while hi - lo > 1e-9 {
        let mid = 0.5 * (lo + hi);
        if past_unit_circle(&Simplest { slope: mid }, &mut start) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    println!("simplest walker: period doubling at gamma = {lo:.9}");
    assert!((0.0150..0.0152).contains(&lo), "{lo}");
}

/// The compass gait of Goswami, Thuilot and Espiau walks down 3 degrees with a stable symmetric gait, and its
/// energy balance closes: the heel strike takes gravity's work over the step, `(mH + 2 m) g sin(phi)` times
/// the step length `2 l sin(theta)`. Steeper, its first period doubling comes between 4.25 and 4.5 degrees.
#[test]
fn the_compass_gait_walks_down_three_degrees() {
    let compass = Compass::default();
    let gait = gait_of(&compass, &[0.27, -1.09, -0.38]);
    assert!(gait.largest_multiplier() < 1.0, "{:?}", gait.multipliers);
    let theta = gait.section[0];
    let weight = (compass.hip_mass + 2.0 * compass.leg_mass) * compass.gravity;
    let work = weight * compass.slope.sin() * 2.0 * compass.leg_length * theta.sin();
    assert_balanced(&gait, work, 1e-9, 1e-9);
    let mut start = gait.section.clone();
    let at = |deg: f64| Compass {
        slope: deg.to_radians(),
        ..compass
    };
    for deg in [3.5, 4.0, 4.25] {
        let g = rigid_gait(&at(deg), &start, &RigidOptions::default()).unwrap();
        start = g.section.clone();
    }
    assert!(past_unit_circle(&at(4.25), &mut start) < 0.0);
    assert!(past_unit_circle(&at(4.5), &mut start) > 0.0);
}

/// The continuation engine follows the simplest walker's gaits in the slope and locates their period doubling
/// by its test function `det(DP + I)` with the exact `DP`: the same slope as the bisection on the largest
/// multiplier (a second route) to 1e-9.
#[test]
fn continuation_locates_the_simplest_walkers_period_doubling() {
    use super::rigid_family::RigidFamily;
    use crate::continuation::{continue_family, ContinuationOptions, SpecialKind};
    let walker = Simplest { slope: 0.009 };
    let gait = gait_of(&walker, &[0.2, -0.2]);
    let family: RigidFamily<Simplest, 2, 4> = RigidFamily::new(&walker, "slope").unwrap();
    let options = ContinuationOptions::for_range(0.005, 0.017);
    let followed = continue_family(&family, &gait.section, 0.009, &options).unwrap();
    let doublings: Vec<f64> = followed
        .special
        .iter()
        .filter(|s| s.kind == SpecialKind::PeriodDoubling && s.located)
        .map(|s| s.param)
        .collect();
    let at = |slope: f64| Simplest { slope };
    let mut start = gait_of(&at(0.0150), &[0.2367, -0.2315]).section;
    let bisected = bisect_doubling(&at, (0.0150, 0.0155), &mut start);
    println!(
        "period doublings at {doublings:?}, by bisection at {bisected:.12}; ends {:?}",
        followed.ends
    );
    assert_eq!(doublings.len(), 1, "{doublings:?}");
    assert!(
        (doublings[0] - bisected).abs() < 1e-9,
        "{doublings:?} vs {bisected}"
    );
    assert!(
        (doublings[0] - 0.015088438).abs() < 1e-9,
        "{}",
        doublings[0]
    );
}

/// Where the largest multiplier of `walker(value)`'s gait crosses the unit circle in `[lo, hi]`, by bisection
/// to 1e-11 (each gait continued from the last, from `start`).
fn bisect_doubling<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &impl Fn(f64) -> W,
    (mut lo, mut hi): (f64, f64),
    start: &mut DVector<f64>,
) -> f64 {
    assert!(past_unit_circle(&walker(lo), start) < 0.0);
    assert!(past_unit_circle(&walker(hi), &mut start.clone()) > 0.0);
    while hi - lo > 1e-11 {
        let mid = 0.5 * (lo + hi);
        if past_unit_circle(&walker(mid), start) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The compass gait's parameters for continuation are those of its configuration.
#[test]
fn the_compass_parameters_are_its_configuration_keys() {
    use super::rigid_family::Parametrized;
    let compass = Compass::default();
    let table = toml::Table::try_from(compass).unwrap();
    let mut keys = compass.parameter_keys();
    keys.sort_unstable();
    let mut expected: Vec<&str> = table.keys().map(String::as_str).collect();
    expected.sort_unstable();
    assert_eq!(keys, expected);
    for key in keys {
        let moved = compass.with_parameter(key, 0.6).unwrap();
        assert_ne!(moved, compass, "{key}");
    }
    assert!(compass.with_parameter("leg_mass", -1.0).is_err());
    assert!(compass.with_parameter("viscosity", 1.0).is_err());
}

/// The compass gait's first period doubling in the slope, detected by the continuation engine (a sign change of
/// `det(DP + I)`) and located by its Newton's method on the extended system with the exact `DP` (with `DP` by
/// central differences it did not converge here, and said so: `located: false`), equals the bisection on the
/// largest multiplier to 1e-9 rad.
#[test]
fn continuation_locates_the_compass_gaits_period_doubling() {
    use super::rigid_family::RigidFamily;
    use crate::continuation::{continue_family, ContinuationOptions, SpecialKind};
    let compass = Compass::default();
    let gait = gait_of(&compass, compass.default_start().as_slice());
    let family: RigidFamily<Compass, 4, 8> = RigidFamily::new(&compass, "slope").unwrap();
    let options = ContinuationOptions::for_range(0.04, 0.08);
    let followed = continue_family(&family, &gait.section, compass.slope, &options).unwrap();
    let doublings: Vec<(f64, bool)> = followed
        .special
        .iter()
        .filter(|s| s.kind == SpecialKind::PeriodDoubling)
        .map(|s| (s.param, s.located))
        .collect();
    let at = |slope: f64| Compass { slope, ..compass };
    let mut start = gait.section.clone();
    for deg in [3.5, 4.0, 4.25] {
        start = rigid_gait(&at(f64::to_radians(deg)), &start, &RigidOptions::default())
            .unwrap()
            .section;
    }
    let range = (4.25f64.to_radians(), 4.5f64.to_radians());
    let bisected = bisect_doubling(&at, range, &mut start);
    println!("compass gait: period doubling at {doublings:?}, by bisection at {bisected:.12} rad");
    assert_eq!(doublings.len(), 1, "{doublings:?}");
    let (value, located) = doublings[0];
    assert!(located, "{:?}", followed.special);
    assert!((value - bisected).abs() < 1e-9, "{value} vs {bisected}");
    assert!((value - 0.076635632).abs() < 1e-9, "{value}");
}

/// Regression: the swing foot passing the stance foot from above while under the ground (the legs' coincidence
/// near mid-swing) is scuffing, not a heel strike. The event function once switched there from a positive
/// placeholder to the foot's (negative) height, and the simplest walker had a spurious period-1 "gait" at slope
/// 0.014 (a step of 1.6905 time units from `(0.186197702, -0.260652416)`); from that state the walk now goes on
/// past the coincidence (and the stance foot lifts off), and the paper's long step (3.9 time units) is kept.
#[test]
fn a_swing_foot_passing_the_stance_foot_under_the_ground_is_no_heel_strike() {
    let walker = Simplest { slope: 0.014 };
    let options = RigidOptions::default();
    let spurious = DVector::from_column_slice(&[0.186197702, -0.260652416]);
    let (q, qd) = walker.state_at_section(&spurious);
    let step = super::rigid::rigid_step(&walker, &q, &qd, &options);
    assert!(
        !matches!(&step, Ok(s) if s.period < 3.0),
        "a heel strike at the legs' coincidence: {step:?}"
    );
    let gait = gait_of(&walker, &[0.2314, -0.2271]);
    assert!(
        (gait.step.period - 3.907370566).abs() < 1e-8,
        "{}",
        gait.step.period
    );
    assert_eq!(gait.step.scuffs, 1);
}
