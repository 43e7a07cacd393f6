//! The orbit diagram and the basin of attraction (README, "Orbit diagram, basin of attraction,
//! period-k gaits"), checked by direct simulation.

use std::path::Path;

use vrw::app::{run_basin, run_orbit, BasinJob, OrbitJob, SliceGrid};
use vrw::dynamics::Model;
use vrw::family::natural::section_distance;
use vrw::gait::{find_gait, GaitOptions, StepMap};
use vrw::params::Config;
use vrw::reference::default_initial;
use vrw::reference::period_two_config;
use vrw::study::basin::{basin, Axis, BasinSpec, Coordinate, OutcomeKind};
use vrw::study::orbit::{orbit_diagram, OrbitSpec};
use vrw::study::SweepSpec;
use vrw::walk::simulate;

/// The basin's distance to the gait.
const TOLERANCE: f64 = 1e-4;

/// Every basin point of a small grid through the paper's gait, walked again with `simulate`: a `gait` point
/// first comes within the tolerance of the gait after exactly its number of steps, and a failed point fails
/// with the same kind in the same step.
#[test]
fn basin_points_agree_with_direct_simulation() {
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
    let spec = BasinSpec {
        x: Axis {
            coordinate: Coordinate::L2,
            from: 0.55,
            to: 1.0,
            points: 4,
        },
        y: Axis {
            coordinate: Coordinate::ThetaDot,
            from: 0.1,
            to: 2.5,
            points: 4,
        },
        through: gait.section,
        max_steps: 50,
        tolerance: TOLERANCE,
    };
    let grid = basin(&model, &config.solver, &gait, &spec, &|_| {});
    assert_eq!(grid.len(), 4);
    let mut kinds = std::collections::BTreeSet::new();
    for p in grid.iter().flatten() {
        let o = &p.outcome;
        kinds.insert(o.kind.to_string());
        assert_eq!(p.start.l2_dot, gait.section.l2_dot);
        match o.kind {
            OutcomeKind::Gait => {
                let run = simulate(&model, &config.solver, &p.start, o.steps + 1, None).unwrap();
                let d: Vec<f64> = run
                    .steps
                    .iter()
                    .map(|r| section_distance(&r.section, &gait.section))
                    .collect();
                assert!(d[o.steps] < TOLERANCE, "{p:?}: {d:?}");
                assert!(d[..o.steps].iter().all(|&x| x >= TOLERANCE), "{p:?}: {d:?}");
            }
            OutcomeKind::Other | OutcomeKind::Undecided | OutcomeKind::InvalidStart => {}
            OutcomeKind::Failed(kind) => {
                let run = simulate(&model, &config.solver, &p.start, o.steps, None).unwrap();
                assert_eq!(run.failure.as_ref().map(|e| e.kind()), Some(kind), "{p:?}");
                assert_eq!(run.steps.len(), o.steps - 1, "{p:?}");
            }
        }
    }
    assert!(kinds.contains("gait"), "{kinds:?}");
    assert!(kinds.len() > 1, "no failure on the grid: {kinds:?}");
}

/// The orbit diagram of the paper's parameters over a short viscosity range: period 1 everywhere, on the
/// gait that Newton's method finds at each value (a second route).
#[test]
fn orbit_diagram_sits_on_the_period_one_gait() {
    let config = Config::default();
    let spec = OrbitSpec {
        range: SweepSpec {
            param: "viscosity".to_string(),
            from: 40.0,
            to: 60.0,
            points: 3,
        },
        transient: 20,
        steps: 8,
    };
    let columns = orbit_diagram(&config, &spec, &default_initial(&config), &|_| {}).unwrap();
    assert_eq!(columns.len(), 3);
    for c in &columns {
        assert_eq!(c.status, vrw::study::orbit::WalkStatus::Walking);
        assert_eq!(c.period_k, Some(1));
        assert_eq!(c.returns.len(), 8);
        let mut at = config.clone();
        at.params.viscosity = c.value;
        let model = Model::new(&at.params).unwrap();
        let map = StepMap::new(&model, &at.solver);
        let gait = find_gait(&map, &default_initial(&at), &GaitOptions::default(), None).unwrap();
        for r in &c.returns {
            assert!(section_distance(&r.section, &gait.section) < 1e-6);
        }
    }
    assert_eq!(columns[1].continued_from, Some(40.0));
}

/// At the period-2 reference parameters the orbit diagram shows two points per value.
#[test]
fn orbit_diagram_shows_the_period_two_gait() {
    let config = period_two_config();
    let spec = OrbitSpec {
        range: SweepSpec {
            param: "viscosity".to_string(),
            from: 3.0,
            to: 3.1,
            points: 2,
        },
        transient: 60,
        steps: 8,
    };
    let columns = orbit_diagram(&config, &spec, &default_initial(&config), &|_| {}).unwrap();
    assert!(columns.iter().all(|c| c.period_k == Some(2)), "{columns:?}");
}

fn basin_job(dir: &Path) -> BasinJob {
    BasinJob {
        config: Config::default(),
        initial: None,
        coordinates: [Coordinate::L2, Coordinate::ThetaDot],
        grid: SliceGrid {
            ranges: [None, None],
            points: [3, 3],
            max_steps: 30,
            tolerance: TOLERANCE,
        },
        out_dir: dir.to_path_buf(),
        overwrite: false,
    }
}

/// `vrw basin` writes basin.csv (one row per start), basin.json and basin.png.
#[test]
fn basin_job_writes_its_files() {
    let dir = tempfile::tempdir().unwrap();
    let summary = run_basin(&basin_job(dir.path()), &|_| {}).unwrap();
    assert_eq!(summary.outcomes.values().sum::<usize>(), 9);
    let csv = std::fs::read_to_string(dir.path().join("basin.csv")).unwrap();
    assert_eq!(csv.lines().count(), 10);
    assert!(csv.starts_with("ix,iy,L2,thetadot,L2dot,outcome"));
    assert!(dir.path().join("basin.png").exists());
    assert!(dir.path().join("basin.json").exists());
}

/// Bad basin options are refused with a message naming them.
#[test]
fn basin_job_refuses_bad_options() {
    let dir = tempfile::tempdir().unwrap();
    let mut job = basin_job(dir.path());
    job.coordinates = [Coordinate::L2, Coordinate::L2];
    let e = run_basin(&job, &|_| {}).unwrap_err().to_string();
    assert!(e.contains("`x/y`") && e.contains("different"), "{e}");
    let mut job = basin_job(dir.path());
    job.grid.points = [1, 3];
    let e = run_basin(&job, &|_| {}).unwrap_err().to_string();
    assert!(e.contains("`nx`"), "{e}");
    let mut job = basin_job(dir.path());
    job.grid.ranges[1] = Some((1.0, f64::NAN));
    let e = run_basin(&job, &|_| {}).unwrap_err().to_string();
    assert!(e.contains("`y_range`"), "{e}");
}

/// `vrw orbit` writes orbit.csv (one row per recorded step), branch.csv, orbit.json and orbit.png; bad step
/// counts are refused.
#[test]
fn orbit_job_writes_its_files() {
    let dir = tempfile::tempdir().unwrap();
    let mut job = OrbitJob {
        config: Config::default(),
        spec: OrbitSpec {
            range: SweepSpec {
                param: "viscosity".to_string(),
                from: 130.0,
                to: 140.0,
                points: 3,
            },
            transient: 4,
            steps: 3,
        },
        initial: None,
        branch: true,
        plot: "lambda_I4".to_string(),
        out_dir: dir.path().to_path_buf(),
        overwrite: false,
    };
    let summary = run_orbit(&job, &|_| {}).unwrap();
    assert_eq!(summary.outcomes.values().sum::<usize>(), 3);
    // Past c = 135.5 the wheel rolls back: one row without steps.
    assert_eq!(summary.outcomes.get("rolled_back"), Some(&1));
    let csv = std::fs::read_to_string(dir.path().join("orbit.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 3 + 3 + 1);
    for f in ["branch.csv", "orbit.json", "orbit.png"] {
        assert!(dir.path().join(f).exists(), "{f}");
    }
    job.spec.steps = 0;
    let e = run_orbit(&job, &|_| {}).unwrap_err().to_string();
    assert!(e.contains("`steps`"), "{e}");
}

/// The grid runner's promise holds for the orbit diagram and the basin: the same results on one thread as
/// on the default pool.
#[test]
fn orbit_and_basin_do_not_depend_on_the_thread_count() {
    let config = period_two_config();
    let spec = OrbitSpec {
        range: SweepSpec {
            param: "viscosity".to_string(),
            from: 2.0,
            to: 5.0,
            points: 12,
        },
        transient: 8,
        steps: 6,
    };
    let start = default_initial(&config);
    let run = || orbit_diagram(&config, &spec, &start, &|_| {}).unwrap();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(run);
    assert_eq!(one, run());
    let dir = tempfile::tempdir().unwrap();
    let job = basin_job(dir.path());
    let basin_once = || run_basin(&job, &|_| {}).unwrap().outcomes;
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(basin_once);
    assert_eq!(one, basin_once());
    let csv_default = std::fs::read_to_string(dir.path().join("basin.csv")).unwrap();
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(basin_once);
    assert_eq!(
        std::fs::read_to_string(dir.path().join("basin.csv")).unwrap(),
        csv_default
    );
}
