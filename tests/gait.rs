//! Gait analysis checks (docs/model.md sections 6-7).

use approx::assert_relative_eq;

use vrw::app::default_initial;
use vrw::dynamics::Model;
use vrw::gait::{find_gait, sweep, GaitOptions, StepMap, SweepSpec};
use vrw::params::Config;
use vrw::reference::RigidRimlessWheel;
use vrw::walk::SectionState;

/// Agreement of the finite-difference Floquet multiplier with the closed form of the rigid wheel.
const RIGID_MULTIPLIER_TOL: f64 = 1e-8;

/// The gait of the paper's parameters, searched from the default start.
fn paper_gait(map: &StepMap, config: &Config) -> vrw::gait::Gait {
    find_gait(map, &default_initial(config), &GaitOptions::default(), None).unwrap()
}

fn rigid_config() -> Config {
    let mut config = Config::default();
    config.params.rigid_legs = true;
    config
}

/// docs/model.md section 7: the rigid rimless wheel's fixed point and Floquet multiplier in closed form.
#[test]
fn rigid_wheel_gait_matches_the_closed_form() {
    let config = rigid_config();
    let wheel = RigidRimlessWheel {
        params: config.params.clone(),
    };
    let model = Model::new(&config.params).unwrap();
    let map = StepMap::new(&model, &config.solver);
    let start = SectionState {
        l2: 1.0,
        theta_dot: 1.6,
        l2_dot: 0.0,
    };
    let gait = find_gait(&map, &start, &GaitOptions::default(), None).unwrap();
    assert!(gait.residual < 1e-10);
    assert_relative_eq!(
        gait.section.theta_dot,
        wheel.fixed_point(),
        max_relative = 1e-10
    );
    assert_eq!(gait.floquet_multipliers.len(), 1);
    let [re, im] = gait.floquet_multipliers[0];
    // At the fixed point P'(omega*) = eta^2.
    assert_relative_eq!(
        re,
        wheel.step_map_derivative(wheel.fixed_point()),
        epsilon = RIGID_MULTIPLIER_TOL
    );
    assert_relative_eq!(re, wheel.eta().powi(2), epsilon = RIGID_MULTIPLIER_TOL);
    assert_eq!(im, 0.0);
    assert!(gait.stable);
    assert!(gait.jacobian_error < RIGID_MULTIPLIER_TOL);
}

/// The step map's Jacobian from the gait search agrees with independent finite differences of `P` at
/// several step sizes (the Richardson error estimate is honest).
#[test]
fn gait_jacobian_matches_finite_differences_of_the_step_map() {
    let config = Config::default();
    let model = Model::new(&config.params).unwrap();
    let map = StepMap::new(&model, &config.solver);
    let gait = paper_gait(&map, &config);
    let dp = gait.jacobian_matrix();
    // Forward differences with a different step: first-order accurate, so a looser tolerance.
    let h = 1e-5;
    let x = map.reduce(&gait.section);
    let p0 = map.reduce(&map.eval(&gait.section).unwrap().next);
    for j in 0..3 {
        let mut shifted = x.clone();
        shifted[j] += h;
        let p1 = map.reduce(&map.eval(&map.expand(&gait.section, &shifted)).unwrap().next);
        let column = (p1 - &p0) / h;
        for i in 0..3 {
            assert!(
                (dp[(i, j)] - column[i]).abs() < 1e-4 * (1.0 + dp[(i, j)].abs()),
                "DP[{i},{j}] = {} vs forward difference {}",
                dp[(i, j)],
                column[i]
            );
        }
    }
    // Central differences at two other steps agree with the extrapolated value to its error estimate.
    for h in [2e-4, 5e-5] {
        let other = map.central_jacobian(&gait.section, h).unwrap();
        let diff = (&other - &dp).abs().max();
        assert!(diff < 1e-6, "h = {h}: max difference {diff:e}");
    }
    assert!(gait.jacobian_error < 1e-6, "{:e}", gait.jacobian_error);
}

#[test]
fn paper_parameters_have_a_stable_gait_with_dls() {
    let config = Config::default();
    let model = Model::new(&config.params).unwrap();
    let map = StepMap::new(&model, &config.solver);
    let gait = paper_gait(&map, &config);
    assert!(gait.residual < 1e-10);
    assert!(gait.stable && gait.max_floquet < 1.0);
    assert!(gait.lambda_i4 > 0.0 && gait.lambda_2_plus > 0.0 && gait.lambda_4_plus > 0.0);
    assert!(gait.dls_duration > 0.0);
    // P(s*) = s* to the tolerance, evaluated independently.
    let next = map.eval(&gait.section).unwrap().next;
    for (a, b) in next.to_array().iter().zip(gait.section.to_array()) {
        assert!((a - b).abs() < 1e-10);
    }
}

#[test]
fn a_parameter_set_without_gait_says_why() {
    let mut config = Config::default();
    config.params.viscosity = 250.0;
    let model = Model::new(&config.params).unwrap();
    let map = StepMap::new(&model, &config.solver);
    let err = find_gait(
        &map,
        &default_initial(&config),
        &GaitOptions::default(),
        None,
    )
    .unwrap_err();
    assert_eq!(err.kind(), "rolled_back", "{err}");
}

fn small_sweep() -> Vec<vrw::gait::SweepPoint> {
    let config = Config::default();
    let spec = SweepSpec {
        param: "viscosity".into(),
        from: 20.0,
        to: 60.0,
        points: 23,
    };
    let options = GaitOptions {
        refine_jacobian: false,
        ..GaitOptions::default()
    };
    sweep(&config, &spec, &default_initial(&config), &options, &|_| {}).unwrap()
}

/// Results are bitwise identical whatever the number of threads (continuation chunks are fixed by the sweep).
#[test]
fn sweep_is_bitwise_identical_across_thread_counts() {
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(small_sweep)
    };
    let one = run(1);
    let three = run(3);
    assert_eq!(one.len(), 23);
    assert!(
        one.iter().all(|p| p.gait.is_some()),
        "every point has a gait"
    );
    for (a, b) in one.iter().zip(&three) {
        let (ga, gb) = (a.gait.as_ref().unwrap(), b.gait.as_ref().unwrap());
        assert_eq!(a.value.to_bits(), b.value.to_bits());
        assert_eq!(
            ga.section.to_array().map(f64::to_bits),
            gb.section.to_array().map(f64::to_bits)
        );
        assert_eq!(ga.lambda_4_plus.to_bits(), gb.lambda_4_plus.to_bits());
        assert_eq!(ga.max_floquet.to_bits(), gb.max_floquet.to_bits());
    }
}

#[test]
fn sweep_rejects_bad_specifications() {
    let config = Config::default();
    let options = GaitOptions::default();
    let start = default_initial(&config);
    for (param, from, to, points) in [
        ("foo", 1.0, 2.0, 3),
        ("viscosity", 1.0, 1.0, 3),
        ("viscosity", 1.0, 2.0, 1),
    ] {
        let spec = SweepSpec {
            param: param.into(),
            from,
            to,
            points,
        };
        assert!(
            sweep(&config, &spec, &start, &options, &|_| {}).is_err(),
            "{param} {from} {to} {points}"
        );
    }
    // A range leaving the parameter's domain is refused before anything is computed, at either end.
    for (from, to) in [(-10.0, 10.0), (10.0, -10.0)] {
        let spec = SweepSpec {
            param: "viscosity".into(),
            from,
            to,
            points: 3,
        };
        let error = sweep(&config, &spec, &start, &options, &|_| {}).unwrap_err();
        let message = error.to_string();
        assert!(
            message.contains("viscosity") && message.contains("-10"),
            "{message}"
        );
    }
}

/// Locks the numerics (STYLE.md point 10): the paper-parameter gait as computed when this test was written.
/// An intended change of the numerics (tolerances, event handling, the model) updates these values and says
/// why in its commit message; an unintended one fails here.
#[test]
fn paper_gait_snapshot() {
    /// Relative agreement required: far above rounding differences between machines, far below any change
    /// of the model or of the event handling.
    const SNAPSHOT_TOL: f64 = 1e-7;
    let config = Config::default();
    let model = Model::new(&config.params).unwrap();
    let map = StepMap::new(&model, &config.solver);
    let g = find_gait(
        &map,
        &default_initial(&config),
        &GaitOptions::default(),
        None,
    )
    .unwrap();
    let expected = [
        (g.section.l2, 0.709843787336971),
        (g.section.theta_dot, 0.8954383386443644),
        (g.section.l2_dot, -0.4797624014976493),
        (g.theta, -0.781527471509902),
        (g.lambda_i4, 0.07137566453544389),
        (g.lambda_2_plus, 18.009031491329296),
        (g.lambda_4_plus, 155.0875802019337),
        (g.period, 2.691666212526113),
        (g.step_length, 0.7071120782469035),
    ];
    for (got, want) in expected {
        assert_relative_eq!(got, want, max_relative = SNAPSHOT_TOL, epsilon = 1e-12);
    }
    assert_relative_eq!(g.max_floquet, 0.016147, max_relative = 1e-4);
}
