//! Exact derivatives of the step map (docs/model.md section 8) against the closed form of the rigid wheel and
//! against finite differences of the whole map on gaits of every branch (`vrw gait --check-jacobian`'s check).

use approx::assert_relative_eq;

use vrw::dynamics::Model;
use vrw::gait::{check_jacobian, find_gait, find_gait_any_period, GaitOptions, StepMap};
use vrw::params::Config;
use vrw::reference::{default_initial, RigidRimlessWheel};
use vrw::walk::SectionState;

/// Agreement of the rigid wheel's multiplier with `eta^2` (the 1e-12; finite differences gave 5e-11).
const RIGID_EXACT_TOL: f64 = 1e-12;

fn config_of(overrides: &[&str]) -> Config {
    let mut config = Config::default();
    for o in overrides {
        config.apply_override(o).unwrap();
    }
    config
}

/// docs/model.md section 7: the rigid wheel's step map `P(w) = eta^2 w^2 + ...` has `P'(w*) = eta^2` at its
/// fixed point, in closed form. Through the gait search, as `vrw gait` reports it.
#[test]
fn rigid_wheel_multiplier_is_eta_squared_to_1e_12() {
    let config = config_of(&["rigid_legs=true"]);
    let wheel = RigidRimlessWheel {
        params: config.params.clone(),
    };
    let model = Model::new(&config.params).unwrap();
    let map = StepMap::new(&model, &config.solver);
    let start = SectionState {
        l2: 1.0,
        theta_dot: 1.6,
        l2_dot: 0.0,
        slip: 0.0,
    };
    let gait = find_gait(&map, &start, &GaitOptions::default(), None).unwrap();
    let [re, im] = gait.floquet_multipliers[0];
    eprintln!(
        "rigid wheel: multiplier {re}, eta^2 {}, difference {:e}, error estimate {:e}",
        wheel.eta().powi(2),
        re - wheel.eta().powi(2),
        gait.jacobian_error
    );
    assert_relative_eq!(re, wheel.eta().powi(2), epsilon = RIGID_EXACT_TOL);
    assert_eq!(im, 0.0);
    assert!(gait.jacobian_error < RIGID_EXACT_TOL);
}

/// On gaits of every branch (DLS with a slide, SLS, SLS_B3, BOUNCE, stiff legs with flight and Zeno locks,
/// period 2, and with Coulomb friction), the exact `DP` agrees with the Richardson finite difference within the
/// two error estimates.
#[test]
fn exact_jacobian_agrees_with_finite_differences_on_every_branch() {
    let cases: [(&[&str], &str, usize); 10] = [
        (&[], "DLS", 1),
        // The stroke-limited leg: Leg 2 held at its compression stop at the section, the map on dtheta/dt.
        (
            &[
                "rear_exit=reset",
                "rear_stopper=false",
                "min_length=1.0",
                "stopper_length=1.02",
                "spring_natural_length=1.02",
            ],
            "DLS",
            1,
        ),
        (&["impact=traditional"], "SLS", 1),
        (&["viscosity=80", "stiffness=1450"], "SLS_B3", 1),
        (&["viscosity=4", "stiffness=640"], "BOUNCE", 1),
        (&["stiffness=3000", "spring_natural_length=1.0"], "DLS", 1),
        (
            &[
                "hub_mass=2",
                "viscosity=3",
                "stiffness=300",
                "slope=0.15",
                "impact=traditional",
            ],
            "SLS",
            2,
        ),
        // Coulomb friction: slipping impacts, slip phases, slip starts and stops ...
        (&["friction=0.6"], "DLS", 1),
        // ... the (B3) parameters, where friction makes the gait DLS, with a slip that reverses ...
        (
            &["friction=0.6", "viscosity=80", "stiffness=1450"],
            "DLS",
            1,
        ),
        // ... and the stance tip slipping at the section (the map on four coordinates).
        (&["friction=0.105"], "DLS", 1),
    ];
    for (overrides, branch, period) in cases {
        let config = config_of(overrides);
        let model = Model::new(&config.params).unwrap();
        let map = StepMap::new(&model, &config.solver);
        let options = GaitOptions::default();
        let gait = find_gait_any_period(&map, &default_initial(&config), &options, 4).unwrap();
        assert_eq!(
            (gait.branch.to_string().as_str(), gait.period_k),
            (branch, period),
            "{overrides:?}"
        );
        assert!(gait.jacobian_failure.is_none(), "{overrides:?}");
        let check =
            check_jacobian(&map.iterated(gait.period_k), &gait.section, options.fd_step).unwrap();
        eprintln!(
            "{overrides:?}: exact vs finite differences {:.1e} (estimates {:.1e}, {:.1e}), max |multiplier| {}",
            check.difference, check.exact_error, check.finite_difference_error, gait.max_floquet
        );
        assert!(check.agree, "{overrides:?}: {check:?}");
        // With the stance tip slipping at the section the map has the slip as a fourth coordinate.
        let on = map.on_section_of(&gait.section);
        assert_eq!(check.exact.len(), on.free_coordinate_names().len());
        assert_eq!(
            gait.section.slips(),
            check.exact.len() == 4,
            "{overrides:?}"
        );
        // The exact route is the more accurate one by orders of magnitude.
        assert!(check.exact_error < 0.1 * check.finite_difference_error);
    }
}

/// Stiff legs on a steep slope (issue 19): there the finite differences' integration noise at the run's
/// tolerances was 70 times their Richardson spread, and the check failed (a difference of 2.7e-7 against
/// estimates of 7.5e-10 and 3.6e-9) although `DP` was right. Taken at the tighter tolerances, with their noise
/// in their error estimate, they agree.
#[test]
fn the_finite_difference_check_counts_its_noise_on_stiff_legs() {
    let config = config_of(&["slope=0.2", "viscosity=300", "stiffness=3000"]);
    let model = Model::new(&config.params).unwrap();
    let map = StepMap::new(&model, &config.solver);
    let start = SectionState {
        l2: 0.999738613076006,
        theta_dot: 2.541822774788133,
        l2_dot: 0.14543688477616845,
        slip: 0.0,
    };
    let options = GaitOptions {
        transient_steps: 0,
        ..GaitOptions::default()
    };
    let gait = find_gait_any_period(&map, &start, &options, 8).unwrap();
    let map = map.iterated(gait.period_k);
    let check = check_jacobian(&map, &gait.section, options.fd_step).unwrap();
    eprintln!(
        "stiff, steep, period {}: exact vs finite differences {:.1e} (estimates {:.1e}, {:.1e})",
        gait.period_k, check.difference, check.exact_error, check.finite_difference_error
    );
    assert!(check.agree, "{check:?}");
    assert!(check.finite_difference_rtol < config.solver.rtol);
}

/// `dP/dp` reported for a gait (`gait.json`'s `dP_dparam`) moves the fixed point as the implicit function
/// theorem says: `ds*/dp = (I - DP)^-1 dP/dp` matches the gait found at a neighbouring parameter value.
#[test]
fn parameter_derivative_predicts_the_neighbouring_gait() {
    let config = Config::default();
    let model = Model::new(&config.params).unwrap();
    let map = StepMap::new(&model, &config.solver);
    let options = GaitOptions {
        parameter: Some("viscosity"),
        ..GaitOptions::default()
    };
    let gait = find_gait(&map, &default_initial(&config), &options, None).unwrap();
    let d = gait.dp_dparam.clone().unwrap();
    assert_eq!(d.parameter, "viscosity");
    let dp = gait.jacobian_matrix();
    let n = dp.nrows();
    let ds = (nalgebra::DMatrix::identity(n, n) - dp)
        .lu()
        .solve(&nalgebra::DVector::from_vec(d.values.clone()))
        .unwrap();
    let h = 1e-3;
    let moved = |c: f64| {
        let config = config_of(&[&format!("viscosity={c}")]);
        let model = Model::new(&config.params).unwrap();
        let map = StepMap::new(&model, &config.solver);
        let g = find_gait(&map, &gait.section, &GaitOptions::default(), None).unwrap();
        map.reduce(&g.section)
    };
    let fd = (moved(50.0 + h) - moved(50.0 - h)) / (2.0 * h);
    eprintln!(
        "ds*/dc: exact {}, finite differences {}",
        ds.transpose(),
        fd.transpose()
    );
    assert!((ds - &fd).amax() < 1e-6 * (1.0 + fd.amax()));
}

/// A gait exactly on a border collision (its `lambda_2+` zero to 1e-11: the DLS family at `c = 20` ends there,
/// README) has no derivative: `gait.json` says so instead of giving multipliers.
#[test]
fn gait_on_a_border_collision_reports_no_derivative() {
    let lambda_2_at = |k: f64, from: &SectionState| {
        let config = config_of(&["viscosity=20", &format!("stiffness={k}")]);
        let model = Model::new(&config.params).unwrap();
        let map = StepMap::new(&model, &config.solver);
        let options = GaitOptions {
            transient_steps: 0,
            ..GaitOptions::default()
        };
        let gait = find_gait(&map, from, &options, None).unwrap();
        (gait.lambda_2_plus, gait)
    };
    let start = {
        let config = config_of(&["viscosity=20", "stiffness=593.86"]);
        let model = Model::new(&config.params).unwrap();
        let map = StepMap::new(&model, &config.solver);
        find_gait(
            &map,
            &default_initial(&config),
            &GaitOptions::default(),
            None,
        )
        .unwrap()
        .section
    };
    // The secant method on lambda_2+(k), from the DLS side.
    let (mut k0, mut k1) = (593.86, 593.866);
    let (mut f0, _) = lambda_2_at(k0, &start);
    let (mut f1, mut gait) = lambda_2_at(k1, &start);
    for _ in 0..20 {
        if f1.abs() < 1e-11 {
            break;
        }
        let k2 = k1 - f1 * (k1 - k0) / (f1 - f0);
        let (f2, g2) = lambda_2_at(k2, &gait.section);
        (k0, f0, k1, f1, gait) = (k1, f1, k2, f2, g2);
    }
    eprintln!(
        "lambda_2+ = {f1:e} at k = {k1}: {:?}",
        gait.jacobian_failure
    );
    assert!(
        f1.abs() < 1e-11,
        "the secant did not reach the border: {f1:e} at {k1}"
    );
    let failure = gait.jacobian_failure.expect("no derivative on the border");
    assert!(
        failure.contains("lambda_2_plus") && failure.contains("border"),
        "{failure}"
    );
    assert!(gait.floquet_multipliers.is_empty());
    assert_eq!(gait.stability, vrw::gait::Stability::Uncertain);
}

/// `dP/dp` of the rigid wheel against its closed-form step map (differentiated in the slope and the leg length
/// by central differences of the formula itself, not of a simulation).
#[test]
fn rigid_wheel_parameter_derivatives_match_the_closed_form() {
    let config = config_of(&["rigid_legs=true"]);
    let wheel = RigidRimlessWheel {
        params: config.params.clone(),
    };
    let model = Model::new(&config.params).unwrap();
    let map = StepMap::new(&model, &config.solver);
    let omega = 1.3;
    let s = SectionState {
        l2: config.params.stopper_length,
        theta_dot: omega,
        l2_dot: 0.0,
        slip: 0.0,
    };
    for (key, value) in [("slope", config.params.slope), ("stopper_length", 1.0)] {
        let exact = map.eval_with_derivatives(&s, Some(key)).unwrap();
        let h = 1e-6;
        let closed = |v: f64| {
            let c = config_of(&["rigid_legs=true", &format!("{key}={v}")]);
            RigidRimlessWheel { params: c.params }.step_map(omega)
        };
        let fd = (closed(value + h) - closed(value - h)) / (2.0 * h);
        let d = exact.dparam.unwrap()[0];
        eprintln!("rigid wheel dP/d{key}: exact {d}, closed form {fd}");
        assert_relative_eq!(d, fd, max_relative = 1e-7);
        // And the value itself.
        assert_relative_eq!(
            exact.outcome.next.theta_dot,
            wheel.step_map(omega),
            max_relative = 1e-11
        );
    }
}

/// `DP` alone is carried along three directions, `DP` with `dP/dp` along four: the same `DP`, bit for bit
/// (each direction's arithmetic is its own), on a period-1 and an iterated map.
#[test]
fn dp_without_a_parameter_is_the_same_dp() {
    let config = Config::default();
    let model = Model::new(&config.params).unwrap();
    let map = StepMap::new(&model, &config.solver);
    let gait = find_gait(
        &map,
        &default_initial(&config),
        &GaitOptions::default(),
        None,
    )
    .unwrap();
    for iterated in [map.clone(), map.iterated(2)] {
        let alone = iterated.eval_with_derivatives(&gait.section, None).unwrap();
        for key in ["viscosity", "slope"] {
            let with = iterated
                .eval_with_derivatives(&gait.section, Some(key))
                .unwrap();
            assert_eq!(alone.jacobian, with.jacobian, "{key}");
            assert_eq!(alone.outcome.next, with.outcome.next);
            assert!(alone.dparam.is_none() && with.dparam.is_some());
        }
    }
}
