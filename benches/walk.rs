//! Speed of the walk on the paper's parameters (Table 1, c = 50 N s/m) from the reference start
//! `(L2, thetadot, L2dot) = (0.72, 1.0, 0.0)`.
//!
//! Run with `cargo bench --bench walk` (add `-- --quick` for a fast estimate).
//!
//! - `walking_step`: one `Walker::step` (touchdown impact, the DLS/SLS phases and their events, re-indexing)
//!   from a state on the gait, reached by first walking `SETTLE_STEPS` steps; `walking_step_friction_0.6` the
//!   same with Coulomb friction `mu = 0.6` (the rear tip slips at every touchdown, docs/model.md section 12).
//! - `rhs/<active set>`: one evaluation of the constrained dynamics (`vrw::contact::constrained_dynamics`,
//!   the integrator's right-hand side) at a stance state, for the active sets the walk spends its time in.
//! - `twenty_steps`: `vrw::walk::simulate` for 20 steps from the reference start, without a trajectory.
//! - `gait_after_transient`: the gait search once its transient is done: Newton's method from the state
//!   reached after `SETTLE_STEPS` steps, to a residual below 1e-10, plus the Floquet multipliers
//!   (`central`: one central-difference Jacobian, as in sweeps; `refined`: with the Richardson error estimate,
//!   as `vrw gait` does).
//! - `family/300_points`: one gait family of 300 points by pseudo-arclength continuation (`vrw continue`'s
//!   core, without its end analysis and files).
//! - `map_curves/continued_21x21`: the indicator curves of the default map by continuation, given its gaits
//!   and crossings (the 100 x 100 map's take 0.94 s, printed by `vrw map --nx 100 --ny 100` as "continued").
//! - `gait_job`: the whole `vrw gait` search on the defaults (`vrw::app::compute_gait`: transient, Newton,
//!   refined multipliers), the function the Python binding's `vrw.find_gait(vrw.Params())` calls;
//!   `python/bench/overhead.py` compares the two.
//!
//! The default sweep (300 viscosities with thresholds and Fig. 2) is timed by the command itself, which
//! prints its wall time split into sweep and thresholds: `cargo run --release -- sweep`. So is the default map
//! (41 x 41 gaits, curves, heat maps), split into gaits and curves: `cargo run --release -- map`; a 100 x 100
//! map: `cargo run --release -- map --nx 100 --ny 100`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};

use vrw::app::{compute_gait, GaitJob};
use vrw::contact::{constrained_dynamics, ActiveSet};
use vrw::continuation::{continue_family, ContinuationOptions};
use vrw::dynamics::{Coords, Model};
use vrw::family::GaitFamily;
use vrw::gait::{find_gait, GaitOptions, StepMap};
use vrw::params::Config;
use vrw::reference::default_initial;
use vrw::study::map::DEFAULT_CURVE_COLUMNS;
use vrw::study::map_curves as map_curves_of;
use vrw::study::map_curves::continue_map_curves;
use vrw::study::{map_gaits, CurveMethod, MapSpec, SweepSpec};
use vrw::walk::{simulate, Walker};

/// Steps walked from the reference start before timing a single step, so that the step timed is on the
/// gait rather than in the initial transient.
const SETTLE_STEPS: usize = 10;
/// Steps of the `twenty_steps` benchmark.
const WALK_STEPS: usize = 20;

fn walking_step(c: &mut Criterion) {
    let config = Config::default();
    walking_step_of(c, &config, "walking_step");
    // Coulomb friction with a realistic coefficient: the rear tip slips at every touchdown (issue goal: within
    // twice `walking_step`).
    let mut friction = Config::default();
    friction
        .apply_override("friction=0.6")
        .expect("a valid friction coefficient");
    walking_step_of(c, &friction, "walking_step_friction_0.6");
}

/// One `Walker::step` on the gait of `config`, named `name`.
fn walking_step_of(c: &mut Criterion, config: &Config, name: &str) {
    let model = Model::new(&config.params).expect("the paper's parameters are valid");
    let mut walker = Walker::new(&model, &config.solver, &default_initial(config))
        .expect("the reference start is a valid section state");
    for k in 0..SETTLE_STEPS {
        walker
            .step(None)
            .unwrap_or_else(|e| panic!("step {} of the reference walk failed: {e}", k + 1));
    }

    let mut group = c.benchmark_group("walk");
    group.sample_size(20);
    group.measurement_time(Duration::from_secs(5));
    group.bench_function(name, |b| {
        b.iter_batched(
            || walker.clone(),
            |mut w| black_box(w.step(None).expect("a step on the gait failed")),
            BatchSize::SmallInput,
        )
    });
    group.finish();
}

fn rhs(c: &mut Criterion) {
    let config = Config::default();
    let model = Model::new(&config.params).expect("the paper's parameters are valid");
    // A stance state near double support: Leg 1 compressed, Leg 2 near its stopper.
    let q = Coords::new(0.0, 0.0, -0.3, 0.97, 0.99, 0.0);
    let qd = Coords::new(0.0, 0.0, 1.0, -0.2, 0.1, 0.0);
    let sets = [
        (
            "sls",
            ActiveSet {
                contact1: true,
                ..Default::default()
            },
        ),
        (
            "sls_lock2",
            ActiveSet {
                contact1: true,
                lock2: true,
                ..Default::default()
            },
        ),
        (
            "dls",
            ActiveSet {
                contact1: true,
                contact2: true,
                ..Default::default()
            },
        ),
        (
            "rear_support",
            ActiveSet {
                contact2: true,
                lock1: true,
                ..Default::default()
            },
        ),
    ];
    let mut group = c.benchmark_group("rhs");
    group.sample_size(20);
    group.measurement_time(Duration::from_secs(2));
    for (name, active) in sets {
        group.bench_function(name, |b| {
            b.iter(|| {
                constrained_dynamics(&model, black_box(&q), black_box(&qd), black_box(&active))
                    .expect("a regular active set")
            })
        });
    }
    group.finish();
}

fn twenty_steps(c: &mut Criterion) {
    let config = Config::default();
    let model = Model::new(&config.params).expect("the paper's parameters are valid");
    let initial = default_initial(&config);

    let mut group = c.benchmark_group("walk");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(10));
    group.bench_function("twenty_steps", |b| {
        b.iter(|| {
            let run = simulate(
                black_box(&model),
                &config.solver,
                black_box(&initial),
                WALK_STEPS,
                None,
            )
            .expect("the reference start is a valid section state");
            assert!(
                run.failure.is_none(),
                "the reference walk stopped: {:?}",
                run.failure
            );
            black_box(run)
        })
    });
    group.finish();
}

fn gait_after_transient(c: &mut Criterion) {
    let config = Config::default();
    let model = Model::new(&config.params).expect("the paper's parameters are valid");
    let map = StepMap::new(&model, &config.solver);
    let mut start = default_initial(&config);
    for _ in 0..SETTLE_STEPS {
        start = map.eval(&start).expect("the reference walk").next;
    }
    let mut group = c.benchmark_group("gait");
    group.sample_size(20);
    group.measurement_time(Duration::from_secs(5));
    // The exact Jacobian without and with its error estimate (a second exact Jacobian at 100x tighter
    // tolerances).
    for (name, refine_jacobian) in [("exact", false), ("exact_with_error", true)] {
        let options = GaitOptions {
            transient_steps: 0,
            refine_jacobian,
            ..GaitOptions::default()
        };
        group.bench_function(name, |b| {
            b.iter(|| {
                let gait = find_gait(&map, black_box(&start), &options, None).expect("the gait");
                assert!(gait.residual < 1e-10);
                black_box(gait)
            })
        });
    }
    group.finish();
}

/// One gait's `DP` by each route, in the units of the goal (step-map evaluations): `eval` is one step of
/// the map, `exact_dp` the step with its exact `DP` (three directions, what Newton's method and the multipliers
/// take), `exact` the step with `DP` and `dP/dp` (four), `central` the central differences (6 evaluations).
fn jacobian_routes(c: &mut Criterion) {
    let config = Config::default();
    let model = Model::new(&config.params).expect("the paper's parameters are valid");
    let map = StepMap::new(&model, &config.solver);
    let gait = find_gait(
        &map,
        &default_initial(&config),
        &GaitOptions::default(),
        None,
    )
    .expect("the gait");
    let s = gait.section;
    let mut group = c.benchmark_group("jacobian");
    group.sample_size(20);
    group.measurement_time(Duration::from_secs(4));
    group.bench_function("eval", |b| b.iter(|| black_box(map.eval(black_box(&s)))));
    group.bench_function("exact_dp", |b| {
        b.iter(|| black_box(map.eval_with_derivatives(black_box(&s), None)))
    });
    group.bench_function("exact", |b| {
        b.iter(|| black_box(map.eval_with_derivatives(black_box(&s), Some("viscosity"))))
    });
    group.bench_function("central", |b| {
        b.iter(|| black_box(map.central_jacobian(black_box(&s), 1e-4)))
    });
    group.finish();
}

/// `family/300_points`: pseudo-arclength continuation of the default family (`vrw::continuation`) from the gait
/// at c = 50, 150 points each way with steps of at most 0.01 (c from about 3 to 98), special points
/// detected: the "one family of 300 points".
fn family(c: &mut Criterion) {
    let config = Config::default();
    let model = Model::new(&config.params).expect("the paper's parameters are valid");
    let map = StepMap::new(&model, &config.solver);
    let gait = find_gait(
        &map,
        &default_initial(&config),
        &GaitOptions::default(),
        None,
    )
    .expect("the gait");
    let parameter = vrw::family::Parameter::named(&config, "viscosity").expect("a numeric key");
    let family_map = GaitFamily::new(parameter, gait.section);
    let x0 = family_map.reduce(&gait.section);
    let options = ContinuationOptions {
        max_points: 150,
        max_step: 0.01,
        ..ContinuationOptions::for_range(1.0, 300.0)
    };
    let mut group = c.benchmark_group("family");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(8));
    group.bench_function("300_points", |b| {
        b.iter(|| {
            let family = continue_family(&family_map, &x0, 50.0, black_box(&options))
                .expect("the family starts");
            assert_eq!(family.points.len(), 301);
            black_box(family)
        })
    });
    group.finish();
}

/// `map_curves/continued_21x21`: the indicator curves of the default 21 x 21 map followed by continuation
/// (`vrw::study::map_curves`: the seeds' row families, the curves across the map, each row's and column's
/// crossing solved for on the curve), given the map's gaits and crossings (computed once, outside the timing).
fn map_curves(c: &mut Criterion) {
    let config = Config::default();
    let spec = MapSpec {
        x: SweepSpec {
            param: "viscosity".to_string(),
            from: 1.0,
            to: 300.0,
            points: 21,
        },
        y: SweepSpec {
            param: "stiffness".to_string(),
            from: 300.0,
            to: 1500.0,
            points: 21,
        },
    };
    let options = GaitOptions::default();
    let map = map_gaits(&config, &spec, &default_initial(&config), &options, &|_| {})
        .expect("the default map");
    let crossings =
        map_curves_of(&config, &map, &options, DEFAULT_CURVE_COLUMNS).expect("valid keys");
    let mut group = c.benchmark_group("map_curves");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(15));
    group.bench_function("continued_21x21", |b| {
        b.iter_batched(
            || crossings.clone(),
            |mut curves| {
                let warnings = continue_map_curves(&config, &map, &mut curves);
                assert!(curves
                    .curves
                    .iter()
                    .any(|c| matches!(c.method, CurveMethod::Continuation(_))));
                black_box((curves, warnings))
            },
            BatchSize::LargeInput,
        )
    });
    group.finish();
}

fn gait_job(c: &mut Criterion) {
    let job = GaitJob {
        config: Config::default(),
        initial: None,
        options: GaitOptions::default(),
        out_dir: Default::default(),
        overwrite: false,
        check_jacobian: false,
        interrupt: None,
    };
    let mut group = c.benchmark_group("gait");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(5));
    group.bench_function("job", |b| {
        b.iter(|| {
            let summary = compute_gait(black_box(&job)).expect("valid parameters");
            assert!(summary.gait.is_some());
            black_box(summary)
        })
    });
    group.finish();
}

criterion_group!(
    benches,
    walking_step,
    rhs,
    twenty_steps,
    gait_after_transient,
    jacobian_routes,
    family,
    map_curves,
    gait_job
);
criterion_main!(benches);
