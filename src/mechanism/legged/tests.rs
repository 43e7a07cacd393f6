//! Tests of the legged walk on the telescopic-legged compass gait.

use nalgebra::{SVector, Vector2};

use super::gait::{legged_gait, legged_gait_exact, LeggedGait, DIFFERENCES_ROUTE, EXACT_ROUTE};
use super::impact::Branch;
use super::walk::LeggedOptions;
use super::Legged;
use crate::mechanism::telescopic::{Telescopic, LENGTH1, LENGTH2, THETA1, THETA2, X, Z};
use crate::mechanism::Mechanism;

type Q = SVector<f64, 6>;

/// The walker's points written out by hand (hip, sleeves, feet) with their masses: a second route to `M`, `h`
/// and the energies, independent of the assembly.
fn points(w: &Telescopic, q: &Q) -> Vec<(f64, Vector2<f64>)> {
    let hip = Vector2::new(q[X], q[Z]);
    let along = |angle: f64, r: f64| hip + r * Vector2::new(angle.sin(), -angle.cos());
    let sleeve = w.stopper_length - w.leg_mass_offset;
    vec![
        (w.hip_mass, hip),
        (w.leg_mass, along(q[THETA1], sleeve)),
        (w.leg_mass, along(q[THETA2], sleeve)),
        (w.foot_mass, along(q[THETA1], q[LENGTH1])),
        (w.foot_mass, along(q[THETA2], q[LENGTH2])),
    ]
}

/// `T`, from the points' velocities by central differences along `q'`.
fn kinetic(w: &Telescopic, q: &Q, qd: &Q) -> f64 {
    let h = 1e-6;
    let (before, after) = (points(w, &(q - h * qd)), points(w, &(q + h * qd)));
    before
        .iter()
        .zip(&after)
        .map(|((m, a), (_, b))| 0.5 * m * ((b - a) / (2.0 * h)).norm_squared())
        .sum()
}

/// `V`: gravity in the slope frame and the two springs.
fn potential(w: &Telescopic, q: &Q) -> f64 {
    let up = w.gravity * Vector2::new(-w.slope.sin(), w.slope.cos());
    let gravity: f64 = points(w, q).iter().map(|(m, p)| m * up.dot(p)).sum();
    gravity
        + [LENGTH1, LENGTH2]
            .iter()
            .map(|&l| 0.5 * w.stiffness * (w.spring_natural_length - q[l]).powi(2))
            .sum::<f64>()
}

/// A state in the walk's range.
fn state(k: usize) -> (Q, Q) {
    let s = k as f64;
    (
        Q::from([
            0.1 * s,
            0.95,
            0.3 - 0.1 * s,
            -0.2 + 0.05 * s,
            0.98 + 0.01 * s,
            0.97,
        ]),
        Q::from([1.2, -0.3 + 0.1 * s, -1.5, 0.8 * s, -0.2, 0.1 * s]),
    )
}

#[test]
fn the_telescopic_equations_are_lagranges() {
    let w = Telescopic::default();
    let c = w.constants_f64();
    for k in 0..3 {
        let (q, qd) = state(k);
        let e = w.equations(&c, &q, &qd);
        // T = 1/2 q'^T M q' for every q'; the energies against the hand-written points.
        let t = kinetic(&w, &q, &qd);
        assert!((w.kinetic_energy(&q, &qd) - t).abs() < 1e-7 * t, "T {t}");
        assert!((w.potential_energy(&q) - potential(&w, &q)).abs() < 1e-9);
        // h = d/dt(dT/dq') - M q'' - dT/dq + dV/dq + c L' (Lagrange), by differences: the q'' part of
        // d/dt(dT/dq') is M q'', the rest is the mixed derivative along q'.
        let step = 1e-5;
        for i in 0..6 {
            let unit = Q::from_fn(|r, _| f64::from(u8::from(r == i)));
            let dt_dqd = |q: &Q| {
                (w.kinetic_energy(q, &(qd + step * unit))
                    - w.kinetic_energy(q, &(qd - step * unit)))
                    / (2.0 * step)
            };
            let mixed = (dt_dqd(&(q + step * qd)) - dt_dqd(&(q - step * qd))) / (2.0 * step);
            let dt_dq = (kinetic(&w, &(q + step * unit), &qd)
                - kinetic(&w, &(q - step * unit), &qd))
                / (2.0 * step);
            let dv_dq = (potential(&w, &(q + step * unit)) - potential(&w, &(q - step * unit)))
                / (2.0 * step);
            let damping = if i == LENGTH1 || i == LENGTH2 {
                w.viscosity * qd[i]
            } else {
                0.0
            };
            let h = mixed - dt_dq + dv_dq + damping;
            assert!(
                (e.bias[i] - h).abs() < 1e-4 * (1.0 + h.abs()),
                "state {k}, h[{i}] = {} against Lagrange's {h}",
                e.bias[i]
            );
        }
    }
}

/// The gait with the default parameters from the default start, with `rtol`.
fn gait_at(rtol: f64) -> LeggedGait<6> {
    let w = Telescopic::default();
    let mut options = LeggedOptions::default();
    options.tolerances.rtol = rtol;
    options.tolerances.atol = rtol / 10.0;
    legged_gait_exact::<_, 6, 13>(&w, &w.default_start(), &options).expect("the default gait")
}

#[test]
fn the_telescopic_biped_walks_with_double_support() {
    let gait = gait_at(1e-11);
    let step = &gait.step;
    assert!(gait.residual < 1e-11, "residual {}", gait.residual);
    assert_eq!(step.account.branch, Branch::Dls);
    assert!(
        step.account.lambda_i4 > 0.0,
        "lambda_I4 {}",
        step.account.lambda_i4
    );
    let (fore, rear) = (
        step.account.lambda_2_plus.expect("(A4) taken"),
        step.account.lambda_4_plus.expect("(A4) taken"),
    );
    assert!(
        fore > 0.0 && rear > 0.0,
        "lambda_2+ {fore}, lambda_4+ {rear}"
    );
    assert!(
        step.account.dls_duration > 1e-3,
        "DLS lasts {} s",
        step.account.dls_duration
    );
    assert!(step.account.rear_contact_duration >= step.account.dls_duration);
    // The energy audit closes: T + V at the start less at the end is what the impacts and the dampers took.
    assert!(
        step.account.energy_residual.abs() < 1e-9,
        "residual {:e} J",
        step.account.energy_residual
    );
    assert!(step.account.losses.heel_strike > 0.0 && step.account.damper_work > 0.0);
    assert!(
        step.account.penetration < 1e-8,
        "penetration {:e} m",
        step.account.penetration
    );
    let largest = gait.multipliers[0][0].hypot(gait.multipliers[0][1]);
    assert!(largest < 1.0, "multipliers {:?}", gait.multipliers);
    // A step is some 0.83 s, between the rigid compass gait's 0.73 s and a slower, softer walk.
    assert!((0.7..1.0).contains(&step.period), "period {}", step.period);
}

#[test]
fn the_telescopic_gait_does_not_depend_on_the_tolerance() {
    let (a, b) = (gait_at(1e-11), gait_at(1e-12));
    assert!((a.step.period - b.step.period).abs() < 1e-9);
    assert!((&a.section - &b.section).amax() < 1e-8);
    // The exact DP of the replay at the fixed point, checked against Richardson-extrapolated central differences
    // (plain central differences of step 1e-6 were noise-bound: at rtol 1e-11, 1e-12 and 1e-13 their
    // multipliers differed by up to 5.3e-5).
    assert_eq!((a.derivative, b.derivative), (EXACT_ROUTE, EXACT_ROUTE));
    println!(
        "exact DP against differences: {:e}, {:e}",
        a.jacobian_error, b.jacobian_error
    );
    assert!(a.jacobian_error < 1e-6 && b.jacobian_error < 1e-6);
    for (x, y) in a.multipliers.iter().zip(&b.multipliers).take(3) {
        println!("multiplier {x:?} against {y:?}");
        assert!(
            (x[0] - y[0]).abs() + (x[1] - y[1]).abs() < 1e-9,
            "{:?} against {:?}",
            a.multipliers,
            b.multipliers
        );
    }
}

#[test]
fn a_heel_strike_stops_both_tips() {
    let w = Telescopic::default();
    let (q, qd) = w
        .state_at_section(&w.default_start())
        .expect("on the section");
    let strike = super::impact::heel_strike(&w, (&q, &qd), super::walk::legs_held(&w, &q), 0.0)
        .expect("the heel strike");
    let c = w.constants_f64();
    for i in 0..2 {
        let v = w
            .contact(&c, &q, &strike.impact.qd_plus, i)
            .velocity(&strike.impact.qd_plus);
        assert!(v.norm() < 1e-12, "tip {i} moves at {v:?} after the impact");
    }
    // The impact takes energy, and the legs compress (their stoppers let go).
    assert!(strike.impact.loss > 0.0);
    assert_eq!(strike.impact.took.held, [false, false]);
}

#[test]
fn bad_telescopic_parameters_name_every_key() {
    let w = Telescopic {
        foot_mass: -1.0,
        leg_mass_offset: 2.0,
        viscosity: -3.0,
        ..Telescopic::default()
    };
    let text = w.validate().expect_err("refused").to_string();
    for key in ["foot_mass", "leg_mass_offset", "viscosity"] {
        assert!(text.contains(key), "{key} not named in: {text}");
    }
    use crate::mechanism::rigid_family::Parametrized;
    assert!(Telescopic::default()
        .with_parameter("stifness", 1.0)
        .is_err());
}

#[test]
fn a_step_answers_the_stop_at_its_first_phase() {
    let w = Telescopic::default();
    let options = LeggedOptions {
        stop: Some(|| true),
        ..LeggedOptions::default()
    };
    let outcome = super::gait::legged_step_map::<_, 6, 13>(&w, &w.default_start(), &options);
    assert!(
        matches!(outcome, Err(super::LeggedError::Interrupted)),
        "{outcome:?}"
    );
}

#[test]
fn the_exact_derivatives_agree_with_differences() {
    use super::derivative::LeggedDerivatives;
    use crate::mechanism::derivative_check::richardson_jacobian;
    use crate::mechanism::rigid_family::Parametrized;
    let w = Telescopic::default();
    let options = LeggedOptions::default();
    let gait = gait_at(1e-11);
    let key = "viscosity";
    let exact = w
        .exact_step_map(&gait.section, Some(key), &options)
        .expect("the gait's step map is differentiable");
    // The value is the walk's, bit for bit.
    let (value, _) = super::gait::legged_step_map::<_, 6, 13>(&w, &gait.section, &options).unwrap();
    assert_eq!(exact.value, value);
    // DP against Richardson-extrapolated differences (gait.jacobian), within their error estimate.
    let dp = (&exact.jacobian - &gait.jacobian).amax();
    println!(
        "DP: exact against differences {dp:e} (their error {:e})",
        gait.jacobian_error
    );
    assert!(dp < 1e-6, "DP differs by {dp:e}");
    // dP/dp against differences in the parameter: a damper's, and the stoppers' length (which moves the
    // section's held leg and every stopper event).
    for key in [key, "stopper_length"] {
        let exact = w
            .exact_step_map(&gait.section, Some(key), &options)
            .unwrap();
        let p = crate::mechanism::legged::derivative::constant_value(&w, key).unwrap();
        let (dpdp, error) = richardson_jacobian(5, &[p], |_, t| {
            let moved = w.with_parameter(key, p + t).unwrap();
            Ok::<_, super::LeggedError>(
                super::gait::legged_step_map::<_, 6, 13>(&moved, &gait.section, &options)?.0,
            )
        })
        .unwrap();
        let exact_dpdp = exact.dparam.expect("dP/dp asked for");
        let diff = (&exact_dpdp - dpdp.column(0)).amax();
        println!(
            "dP/d{key}: largest {:e}, against differences {diff:e} (their error {error:e})",
            exact_dpdp.amax()
        );
        assert!(
            diff < 1e-6 * exact_dpdp.amax().max(1.0),
            "dP/d{key} differs by {diff:e}"
        );
    }
}

#[test]
fn a_walker_without_exact_derivatives_takes_differences() {
    // The same walker through the differences' route: the same gait, its multipliers within their estimate.
    let w = Telescopic::default();
    let options = LeggedOptions::default();
    let by_differences = legged_gait::<_, 6, 13>(&w, &w.default_start(), &options).unwrap();
    let exact = gait_at(1e-11);
    assert_eq!(by_differences.derivative, DIFFERENCES_ROUTE);
    assert!((&by_differences.section - &exact.section).amax() < 1e-9);
    let error = by_differences.jacobian_error.max(1e-9);
    assert!((&by_differences.jacobian - &exact.jacobian).amax() < 2.0 * error);
}

/// The period doubling in the viscosity that `vrw continue --model telescopic` locates at 662.442241790: the
/// exact `DP`'s multiplier passes through -1 between 662.44214 and 662.44234, and Richardson's differences'
/// (a second route, whose multipliers differ from the exact ones by up to 1e-7 here) between 662.4412 and
/// 662.4432.
#[test]
fn the_period_doubling_in_the_viscosity_is_bracketed_by_both_routes() {
    use crate::mechanism::rigid_family::Parametrized;
    let w = Telescopic::default();
    let options = LeggedOptions::default();
    let largest = |c: f64, exact: bool| {
        let at = w.with_parameter("viscosity", c).unwrap();
        let g = if exact {
            legged_gait_exact::<_, 6, 13>(&at, &w.default_start(), &options)
        } else {
            legged_gait::<_, 6, 13>(&at, &w.default_start(), &options)
        };
        let m = g.unwrap().multipliers[0];
        assert_eq!(m[1], 0.0, "c = {c}: {m:?}");
        m[0]
    };
    for (below, above, exact) in [(662.44214, 662.44234, true), (662.4412, 662.4432, false)] {
        let (a, b) = (largest(below, exact), largest(above, exact));
        println!("exact {exact}: {a} at {below}, {b} at {above}");
        assert!(
            a < -1.0 && b > -1.0,
            "exact {exact}: {a} at {below}, {b} at {above}"
        );
    }
}
