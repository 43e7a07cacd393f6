//! Exact derivatives of the step map (docs/model.md section 8) against the closed form of the rigid wheel and
//! against finite differences of the whole map.

use approx::assert_relative_eq;

use vrw::dynamics::{Model, DIFFERENTIABLE_KEYS};
use vrw::gait::{find_gait, GaitOptions, StepMap};
use vrw::params::Config;
use vrw::reference::{default_initial, RigidRimlessWheel};
use vrw::walk::SectionState;

#[test]
fn rigid_wheel_multiplier_is_eta_squared_to_1e_12() {
    let mut config = Config::default();
    config.params.rigid_legs = true;
    let wheel = RigidRimlessWheel {
        params: config.params.clone(),
    };
    let model = Model::new(&config.params).unwrap();
    let map = StepMap::new(&model, &config.solver);
    let s = SectionState {
        l2: 1.0,
        theta_dot: wheel.fixed_point(),
        l2_dot: 0.0,
    };
    let d = map.eval_with_derivatives(&s, None).unwrap();
    eprintln!(
        "rigid: DP = {}, eta^2 = {}, diff {:e}",
        d.jacobian[(0, 0)],
        wheel.eta().powi(2),
        d.jacobian[(0, 0)] - wheel.eta().powi(2)
    );
    assert_relative_eq!(d.jacobian[(0, 0)], wheel.eta().powi(2), epsilon = 1e-12);
}

#[test]
fn paper_gait_jacobian_matches_richardson_differences() {
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
    let exact = map
        .eval_with_derivatives(&gait.section, Some("viscosity"))
        .unwrap();
    let fd = gait.jacobian_matrix();
    eprintln!(
        "exact {}\nfd {}\nerr est {:e}",
        exact.jacobian, fd, gait.jacobian_error
    );
    eprintln!("diff {:e}", (&exact.jacobian - &fd).abs().max());
    assert!((&exact.jacobian - &fd).abs().max() < 10.0 * gait.jacobian_error.max(1e-9));
    let _ = DIFFERENTIABLE_KEYS;
}

#[test]
#[ignore]
fn timing_scratch() {
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
    let n = 50;
    let t = std::time::Instant::now();
    for _ in 0..n {
        map.eval(&gait.section).unwrap();
    }
    let e = t.elapsed().as_secs_f64() / n as f64;
    let t = std::time::Instant::now();
    for _ in 0..n {
        map.eval_with_derivatives(&gait.section, Some("viscosity"))
            .unwrap();
    }
    let d = t.elapsed().as_secs_f64() / n as f64;
    let t = std::time::Instant::now();
    for _ in 0..n {
        map.eval_with_derivatives(&gait.section, None).unwrap();
    }
    let d0 = t.elapsed().as_secs_f64() / n as f64;
    eprintln!(
        "eval {e:e} s, with derivatives {d:e} s ({:.2}x), no param {d0:e} ({:.2}x)",
        d / e,
        d0 / e
    );
}
