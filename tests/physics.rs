//! The physics checks of docs/model.md section 7 on the full walk.

use approx::assert_relative_eq;
use nalgebra::Vector2;

use vrw::contact::ActiveSet;
use vrw::dynamics::{Coords, Model, L1, L2, THETA, Z};
use vrw::integrate::{Dopri5, Tolerances};
use vrw::mechanism::Role;
use vrw::params::{Config, ImpactModel, Params, SolverOptions};
use vrw::reference::RigidRimlessWheel;
use vrw::walk::{simulate, Branch, PhaseSystem, SectionState, WalkVector, Walker};

/// Relative drift of `T + V` allowed over 2 s without damping: the walk then conserves `T + V` up to the
/// integration error.
const ENERGY_DRIFT_TOL: f64 = 1e-9;
/// Largest energy-audit residual allowed per step [J] (docs/model.md section 7).
const AUDIT_TOL: f64 = 1e-8;

fn default_start() -> SectionState {
    SectionState {
        l2: 0.72,
        theta_dot: 1.0,
        l2_dot: 0.0,
        slip: 0.0,
    }
}

/// Integrate one phase with a fixed active set for `duration` and return the largest relative change of
/// `T + V`.
fn energy_drift(params: &Params, q: Coords, qd: Coords, active: ActiveSet, duration: f64) -> f64 {
    let model = Model::new(params).unwrap();
    let mut y = WalkVector::zeros();
    y.fixed_rows_mut::<6>(0).copy_from(&q);
    y.fixed_rows_mut::<6>(6).copy_from(&qd);
    let sys = PhaseSystem::at(&model, active, &y);
    let tol = Tolerances {
        rtol: 1e-12,
        atol: 1e-13,
        ..Tolerances::default()
    };
    let mut solver = Dopri5::new(&sys, 0.0, y, tol);
    let e0 = model.energy(&q, &qd);
    let mut worst: f64 = 0.0;
    while solver.t() < duration {
        solver.step(&sys, duration).unwrap();
        let y = solver.y();
        let (q, qd) = (
            y.fixed_rows::<6>(0).into_owned(),
            y.fixed_rows::<6>(6).into_owned(),
        );
        worst = worst.max(((model.energy(&q, &qd) - e0) / e0).abs());
    }
    worst
}

fn undamped() -> Params {
    Params {
        viscosity: 0.0,
        hub_inertia: 0.2,
        ..Params::default()
    }
}

#[test]
fn energy_is_conserved_without_damping_in_single_support() {
    let params = undamped();
    let model = Model::new(&params).unwrap();
    let (q, qd) = default_start().to_coords(&model);
    let mut qd = qd;
    // Leg 1's tip at rest (J_SLS q' = 0): the section velocities hold Leg 2's tip still instead.
    qd[vrw::dynamics::X] = 0.0;
    qd[Z] = 0.0;
    qd[L1] = -0.3; // the stance spring oscillates
    qd[L2] = 0.2; // and so does the airborne rear leg
    let active = ActiveSet {
        contact1: true,
        ..Default::default()
    };
    let drift = energy_drift(&params, q, qd, active, 2.0);
    assert!(drift < ENERGY_DRIFT_TOL, "relative drift {drift:e}");
}

/// With a swinging leg (`L3`, rear_exit = continue) as a sixth coordinate: its spring, its sliding mass coupled
/// with the wheel, all conservative without damping.
#[test]
fn energy_is_conserved_without_damping_with_a_swinging_leg() {
    let params = undamped();
    let model = Model::new(&params).unwrap();
    let (mut q, mut qd) = default_start().to_coords(&model);
    qd[vrw::dynamics::X] = 0.0;
    qd[Z] = 0.0;
    qd[L1] = -0.3;
    qd[L2] = 0.2;
    (q[vrw::dynamics::L3], qd[vrw::dynamics::L3]) = (0.9, 0.4);
    let active = ActiveSet {
        contact1: true,
        ..Default::default()
    };
    let drift = energy_drift(&params, q, qd, active, 2.0);
    assert!(drift < ENERGY_DRIFT_TOL, "relative drift {drift:e}");
}

#[test]
fn energy_is_conserved_without_damping_in_double_support() {
    let params = undamped();
    let model = Model::new(&params).unwrap();
    let (q, qd) = default_start().to_coords(&model);
    // Leg 1's tip at rest too: project the velocity onto J_DLS q' = 0 with the impulse problem.
    let active = ActiveSet {
        contact1: true,
        contact2: true,
        ..Default::default()
    };
    let qd = vrw::contact::impulse(&model, &q, &qd, &active)
        .unwrap()
        .qd_plus;
    let drift = energy_drift(&params, q, qd, active, 2.0);
    assert!(drift < ENERGY_DRIFT_TOL, "relative drift {drift:e}");
}

/// Events do not depend on the integrator's steps being short: with steps up to four times longer
/// (`max_step = 0.16`) the event functions are still checked every `event_spacing` (0.01 s), so the twenty
/// default steps meet the same events in the same phases and branches, and the gait agrees to the
/// integration tolerance.
#[test]
fn longer_steps_keep_the_event_resolution() {
    let config = Config::default();
    let model = Model::new(&config.params).unwrap();
    let short = simulate(&model, &config.solver, &default_start(), 20, None).unwrap();
    let long_opts = SolverOptions {
        max_step: 0.16,
        ..config.solver.clone()
    };
    let long = simulate(&model, &long_opts, &default_start(), 20, None).unwrap();
    assert!(short.failure.is_none() && long.failure.is_none());
    assert!(long.work.accepted < short.work.accepted);
    assert_eq!(long.work.events, short.work.events);
    assert_eq!(long.work.crossings, short.work.crossings);
    for (a, b) in short.steps.iter().zip(&long.steps) {
        assert_eq!(
            (a.branch, a.events),
            (b.branch, b.events),
            "step {}",
            a.step
        );
        assert!(a.section.distance(&b.section) < 1e-8, "step {}", a.step);
    }
}

#[test]
fn energy_audit_closes_over_twenty_steps() {
    let config = Config::default();
    let model = Model::new(&config.params).unwrap();
    let run = simulate(&model, &config.solver, &default_start(), 20, None).unwrap();
    assert!(run.failure.is_none(), "{:?}", run.failure);
    assert_eq!(run.steps.len(), 20);
    for s in &run.steps {
        let e = &s.energy;
        assert!(
            e.residual.abs() < AUDIT_TOL,
            "step {}: residual {:e}",
            s.step,
            e.residual
        );
        // Dissipation and impact losses are losses: never negative.
        assert!(
            e.damper >= 0.0 && e.impact >= 0.0 && e.stopper >= 0.0,
            "step {}: {e:?}",
            s.step
        );
        assert!(e.loss > 0.0);
    }
}

#[test]
fn touchdown_is_located_on_the_ground_and_the_section_is_consistent() {
    let config = Config::default();
    let model = Model::new(&config.params).unwrap();
    let mut walker = Walker::new(&model, &config.solver, &default_start()).unwrap();
    for _ in 0..5 {
        walker.step(None).unwrap();
        let state = walker.state();
        // The new Leg 1 touched down: its tip is on the ground to the event tolerance.
        assert!(state.q[Z].abs() < 1e-11, "tip height {:e}", state.q[Z]);
        // Leg 2 (the old stance leg) is on the ground and at rest at the section.
        let tip = model.tip(&state.q, &state.qd, Role::Rear.index());
        assert!(
            tip.position.y.abs() < 1e-9,
            "rear tip height {:e}",
            tip.position.y
        );
        assert!(tip.velocity(&state.qd).norm() < 1e-9);
        assert_relative_eq!(state.q[L1], model.params().stopper_length);
    }
}

#[test]
fn dlsi_procedure_records_indicators_and_branches() {
    let config = Config::default();
    let model = Model::new(&config.params).unwrap();
    let run = simulate(&model, &config.solver, &default_start(), 5, None).unwrap();
    for s in &run.steps {
        let i = &s.indicators;
        // The paper: lambda_I4 > 0, and then lambda_2+, lambda_4+ decide; here both are positive: DLS.
        assert!(i.lambda_i4 > 0.0);
        assert!(i.lambda_2_plus > 0.0 && i.lambda_4_plus > 0.0);
        assert_eq!(s.branch, Branch::Dls);
        assert!(s.dls_duration > 0.0 && s.dls_duration < s.period);
        assert!(!s.bounce);
    }
}

#[test]
fn traditional_exchange_with_positive_lambda_i4_drives_the_rear_tip_into_the_ground() {
    let mut config = Config::default();
    config.params.impact = ImpactModel::Traditional;
    let model = Model::new(&config.params).unwrap();
    let run = simulate(&model, &config.solver, &default_start(), 3, None).unwrap();
    assert!(run.failure.is_none(), "{:?}", run.failure);
    let dlsi = simulate(&model_dlsi(), &config.solver, &default_start(), 1, None).unwrap();
    for s in &run.steps {
        assert_eq!(s.branch, Branch::Sls);
        // The indicators are still computed for comparison.
        assert!(s.indicators.lambda_i4.is_finite());
    }
    // Same first touchdown, same indicators. Since lambda_I4 > 0, the J_SLS exchange drives the rear tip into
    // the ground (the paper's argument for J_DLS): it comes back at once, an extra re-contact event.
    let (trad, dls) = (&run.steps[0], &dlsi.steps[0]);
    assert_eq!(trad.indicators, dls.indicators);
    assert!(trad.indicators.lambda_i4 > 0.0);
    assert!(trad.scuffing);
    assert_eq!(trad.events, dls.events + 1);
}

fn model_dlsi() -> Model {
    Model::new(&Params::default()).unwrap()
}

/// Rigid special case (docs/model.md section 7): the step map of the walk equals the closed form.
#[test]
fn rigid_legs_follow_the_closed_form_step_map() {
    let mut config = Config::default();
    config.params.rigid_legs = true;
    let wheel = RigidRimlessWheel {
        params: config.params.clone(),
    };
    let model = Model::new(&config.params).unwrap();
    let mut omega = 2.0;
    let start = SectionState {
        l2: config.params.stopper_length,
        theta_dot: omega,
        l2_dot: 0.0,
        slip: 0.0,
    };
    let run = simulate(&model, &config.solver, &start, 6, None).unwrap();
    assert!(run.failure.is_none(), "{:?}", run.failure);
    for s in &run.steps {
        assert_relative_eq!(s.section.theta_dot, omega, max_relative = 1e-9);
        assert_relative_eq!(s.theta, -model.alpha() / 2.0, epsilon = 1e-10);
        assert_relative_eq!(
            s.step_length,
            2.0 * (model.alpha() / 2.0).sin(),
            max_relative = 1e-9
        );
        omega = wheel.step_map(omega);
    }
    // and the walk converges towards the closed-form fixed point
    assert!(
        (run.steps[5].section.theta_dot - wheel.fixed_point()).abs()
            < (2.0 - wheel.fixed_point()).abs()
    );
}

/// Regression: right after the rear lift-off at lambda_4 = 0 (with a non-zero tangential force) the freed
/// rear tip fell back at once, and the re-contact dropped the loaded fore leg instead (the wheel "hopped"
/// on its rear leg and touched down with three legs). The fore leg must stay on the ground.
#[test]
fn rear_scuff_does_not_lift_the_loaded_fore_leg() {
    let config = Config::default();
    let model = Model::new(&config.params).unwrap();
    let run = simulate(&model, &config.solver, &default_start(), 3, None).unwrap();
    assert!(run.failure.is_none(), "{:?}", run.failure);
    assert!(run.steps.iter().all(|s| !s.bounce));
}

/// The grazing guard: with the literal docs/model.md rule (rebound) the walk must neither hang nor chatter forever.
#[test]
fn rebound_option_terminates_with_a_status() {
    let mut config = Config::default();
    config.params.inconsistent_contact = vrw::params::ContactInconsistency::Rebound;
    let model = Model::new(&config.params).unwrap();
    let run = simulate(&model, &config.solver, &default_start(), 5, None).unwrap();
    if let Some(failure) = &run.failure {
        assert!(
            matches!(failure, vrw::walk::WalkError::Chatter { .. }),
            "{failure}"
        );
    }
    for s in &run.steps {
        assert!(s.energy.residual.abs() < AUDIT_TOL);
    }
}

#[test]
fn a_walk_that_stops_is_a_status_and_the_steps_before_it_are_kept() {
    let mut config = Config::default();
    // Below the slopes where the gait exists: one step, then the wheel rolls back.
    config.params.slope = 0.08;
    let model = Model::new(&config.params).unwrap();
    let run = simulate(&model, &config.solver, &default_start(), 20, None).unwrap();
    let failure = run.failure.expect("the wheel cannot keep walking");
    assert_eq!(failure.kind(), "rolled_back", "{failure}");
    assert_eq!(run.steps.len(), 1);
    assert!(run
        .steps
        .iter()
        .all(|s| s.energy.residual.abs() < AUDIT_TOL));
    match failure {
        vrw::walk::WalkError::RolledBack { time, phase } => {
            let last = run.steps.last().unwrap();
            assert!(
                time > last.time + last.period,
                "the failure comes after the kept steps"
            );
            assert_eq!(phase, vrw::contact::Phase::DoubleSupport);
        }
        other => panic!("{other}"),
    }
}

#[test]
fn invalid_section_states_are_rejected() {
    let model = Model::new(&Params::default()).unwrap();
    let opts = SolverOptions::default();
    for s in ["1.2,1,0", "0.8,-1,0", "0.8,NaN,0"] {
        let state: SectionState = s.parse().unwrap();
        let err = Walker::new(&model, &opts, &state).unwrap_err();
        assert_eq!(err.kind(), "invalid_section", "{s}");
    }
    assert!("0.8,1".parse::<SectionState>().is_err());
    assert!("a,b,c".parse::<SectionState>().is_err());
}

#[test]
fn section_coordinates_put_both_tips_on_the_ground() {
    let model = Model::new(&Params::default()).unwrap();
    let s = SectionState {
        l2: 0.8,
        theta_dot: 0.9,
        l2_dot: -0.3,
        slip: 0.0,
    };
    let (q, qd) = s.to_coords(&model);
    assert_relative_eq!(model.tip_height(&q, 1), 0.0, epsilon = 1e-14);
    let tip = model.tip(&q, &qd, 1);
    assert_relative_eq!(tip.velocity(&qd), Vector2::zeros(), epsilon = 1e-14);
    assert_eq!(SectionState::from_coords(&q, &qd), s);
    assert!(q[THETA] < 0.0);
}

/// No airborne tip sinks below the ground and no free leg passes its stopper by more than the grazing guards
/// allow (regression: a re-contact located at `-recontact_gap` left a guard that could never fire, and the rear
/// tip sank by millimetres).
#[test]
fn airborne_tips_never_penetrate_and_free_legs_never_pass_their_stoppers() {
    for mode in [
        vrw::params::ContactInconsistency::Slide,
        vrw::params::ContactInconsistency::Rebound,
    ] {
        let mut config = Config::default();
        config.params.inconsistent_contact = mode;
        let model = Model::new(&config.params).unwrap();
        let mut trajectory = vrw::walk::Trajectory::new(2e-4);
        let run = simulate(
            &model,
            &config.solver,
            &default_start(),
            4,
            Some(&mut trajectory),
        )
        .unwrap();
        assert!(!run.steps.is_empty() || run.failure.is_some());
        let gap = config.solver.recontact_gap;
        let l0 = config.params.stopper_length;
        let events = run.steps.iter().map(|s| s.events).sum::<usize>() + 200;
        for s in &trajectory.samples {
            for leg in Role::BOTH {
                if !s.active.contact(leg) {
                    let h = model.tip_height(&s.q, leg.index());
                    // each disarmed re-contact may start a further gap lower: bounded by the event count
                    assert!(
                        h > -(events as f64) * gap,
                        "{mode:?} t = {}: {leg:?} tip at {h:e}",
                        s.time
                    );
                }
                if !s.active.lock(leg) {
                    let l = s.q[vrw::dynamics::Model::stroke_coordinate(leg)];
                    assert!(l < l0 + 1e-7, "{mode:?} t = {}: {leg:?} length {l}", s.time);
                }
            }
        }
    }
}

/// The Poincare section `(L2, thetadot, L2dot)` assumes Leg 2's tip at rest at touchdown. Where the stance tip
/// slides into a touchdown (traditional impact, light hub, c = 6), a step map started from a section state is
/// not the walk: the walker says so (`off_section`) instead of handing out a wrong section state, and the walk
/// itself goes on.
#[test]
fn a_stance_tip_sliding_into_touchdown_is_off_the_section() {
    let mut config = Config::default();
    for o in [
        "impact=traditional",
        "hub_mass=2",
        "stiffness=300",
        "slope=0.15",
        "viscosity=6",
    ] {
        config.apply_override(o).unwrap();
    }
    let model = Model::new(&config.params).unwrap();
    let start = SectionState {
        l2: 0.9,
        theta_dot: 1.5,
        l2_dot: 0.0,
        slip: 0.0,
    };
    let mut walker = Walker::new(&model, &config.solver, &start).unwrap();
    let mut off = 0;
    for _ in 0..30 {
        if walker.step(None).is_err() {
            break;
        }
        match walker.section() {
            Err(e) => {
                assert_eq!(e.kind(), "off_section", "{e}");
                off += 1;
            }
            Ok(s) => assert!(s.validate(&model).is_ok()),
        }
    }
    assert!(off > 0, "this walk slides into its touchdowns");
}
