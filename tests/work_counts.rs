//! Snapshots of the work the paper's walk and gait take (STYLE.md point 10): integrator steps (accepted and
//! rejected), right-hand-side evaluations, located event crossings and root-search evaluations, events by
//! kind and impacts, with both integrators. Any change to the integrator, the event search or the impact
//! procedure that alters the numerics shows here as a changed count; if the change is intended, review the
//! new counts (`cargo insta review`, or `INSTA_UPDATE=always cargo test --release --test work_counts`) and
//! commit the updated `tests/snapshots/`.

use vrw::dynamics::Model;
use vrw::gait::{find_gait, GaitOptions, StepMap};
use vrw::integrate::Method;
use vrw::params::Config;
use vrw::reference::default_initial;
use vrw::walk::{simulate, WorkCounts};

/// Steps of the paper's walk (the default of `vrw simulate`).
const WALK_STEPS: usize = 20;

fn config(method: Method) -> Config {
    let mut config = Config::default();
    config.solver.integrator = method;
    config
}

/// The work of the paper's walk: `WALK_STEPS` steps from the default start.
fn walk_work(method: Method) -> WorkCounts {
    let config = config(method);
    let model = Model::new(&config.params).unwrap();
    let run = simulate(
        &model,
        &config.solver,
        &default_initial(&config),
        WALK_STEPS,
        None,
    )
    .unwrap();
    assert!(run.failure.is_none(), "{:?}", run.failure);
    assert_eq!(run.steps.len(), WALK_STEPS);
    assert_eq!(run.work.steps, WALK_STEPS);
    assert_eq!(run.work.events.touchdown, WALK_STEPS);
    run.work
}

/// The work of the paper's gait search (transient, Newton, Jacobian) from the default start.
fn gait_work(method: Method) -> WorkCounts {
    let config = config(method);
    let model = Model::new(&config.params).unwrap();
    let map = StepMap::new(&model, &config.solver);
    let gait = find_gait(
        &map,
        &default_initial(&config),
        &GaitOptions::default(),
        None,
    )
    .unwrap();
    assert!(gait.stable, "{gait:?}");
    map.work()
}

#[test]
fn paper_walk_work_dop853() {
    insta::assert_yaml_snapshot!(walk_work(Method::Dop853));
}

#[test]
fn paper_walk_work_dopri5() {
    insta::assert_yaml_snapshot!(walk_work(Method::Dopri5));
}

#[test]
fn paper_gait_work_dop853() {
    insta::assert_yaml_snapshot!(gait_work(Method::Dop853));
}

#[test]
fn paper_gait_work_dopri5() {
    insta::assert_yaml_snapshot!(gait_work(Method::Dopri5));
}

/// A walk's counts are its steps' counts: the same walk split in two gives the same total.
#[test]
fn work_adds_up_over_steps() {
    let config = Config::default();
    let model = Model::new(&config.params).unwrap();
    let start = default_initial(&config);
    let mut walker = vrw::walk::Walker::new(&model, &config.solver, &start).unwrap();
    let mut sum = WorkCounts::default();
    for _ in 0..3 {
        let before = walker.work();
        walker.step(None).unwrap();
        sum += walker.work().since(&before);
    }
    let run = simulate(&model, &config.solver, &start, 3, None).unwrap();
    assert_eq!(sum, run.work);
    assert_eq!(sum, walker.work());
}
