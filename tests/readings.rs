//! The paper's readings (issue 21): options that make a reading of the model the paper leaves open
//! expressible. Here `rear_exit`: what becomes of the old rear leg when it leaves the coordinates at a
//! touchdown (docs/model.md section 5).

use vrw::dynamics::{Model, L1, L2};
use vrw::gait::GaitOptions;
use vrw::params::{Config, RearExit};
use vrw::reference::default_initial;
use vrw::study::sweep_values;
use vrw::walk::{simulate, StepReport, Trajectory, WalkError, WalkRun};

/// Stiff legs where the old rear leg bounces on its stopper and is still free (within a micrometre of `L0`)
/// at a touchdown of the transient: `rear_exit = "relock"` stops there.
fn stiff(rear_exit: RearExit) -> Config {
    let mut c = Config::default();
    c.params.viscosity = 28.181818181818183;
    c.params.stiffness = 1945.4545454545455;
    c.params.rear_exit = rear_exit;
    c
}

/// The step's audits hold: the energy balance closes to 1e-8 J, no pulling force (1e-6 N) or impulse
/// (1e-9 N s), no tip deeper than 1e-9 m, no leg past its stopper by more than 1e-8 m.
fn assert_audits_clean(s: &StepReport, at: &str) {
    assert!(s.energy.residual.abs() < 1e-8, "{at}: {:?}", s.energy);
    let c = &s.contact;
    assert!(
        c.pull_force <= 1e-6 && c.pull_impulse <= 1e-9,
        "{at}: {c:?}"
    );
    assert!(
        c.penetration <= 1e-9 && c.stopper_overrun <= 1e-8,
        "{at}: {c:?}"
    );
}

fn walk(config: &Config, steps: usize) -> WalkRun {
    walk_into(config, steps, None)
}

/// `steps` steps from the default start, sampled into `trajectory` if given.
fn walk_into(config: &Config, steps: usize, trajectory: Option<&mut Trajectory>) -> WalkRun {
    let model = Model::new(&config.params).unwrap();
    simulate(
        &model,
        &config.solver,
        &default_initial(config),
        steps,
        trajectory,
    )
    .unwrap()
}

/// The gaits along `param` at `values`, as a sweep follows them from the default start.
fn sweep(config: &Config, param: &str, values: &[f64]) -> Vec<vrw::study::SweepPoint> {
    sweep_values(
        config,
        param,
        values,
        &default_initial(config),
        &GaitOptions::for_sweeps(),
        &|_| {},
    )
    .unwrap()
}

/// `T + V` of the whole wheel is continuous through re-indexing up to the origin's move down the slope and the
/// reset: the next step starts with `end - reset + M g sin(phi) step_length` (an independent check of the
/// reset's energy, from the step reports' own energies).
fn assert_energy_carries_over(run: &WalkRun, config: &Config, tol: f64) {
    let p = &config.params;
    let total_mass = p.hub_mass + p.legs as f64 * p.leg_mass;
    for pair in run.steps.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        let carried =
            a.energy.end - a.energy.reset + total_mass * p.gravity * p.slope.sin() * a.step_length;
        assert!(
            (carried - b.energy.start).abs() < tol,
            "step {}: {carried} carried over, {} at the next start",
            a.step,
            b.energy.start
        );
    }
}

#[test]
fn relock_stops_where_the_old_rear_leg_is_still_free() {
    let run = walk(&stiff(RearExit::Relock), 60);
    assert!(
        matches!(run.failure, Some(WalkError::RearLegNotLocked { .. })),
        "{:?}",
        run.failure
    );
    assert!(run.steps.iter().all(|s| s.energy.reset == 0.0));
}

#[test]
fn reset_walks_on_with_clean_audits_and_reports_the_energy_it_changes() {
    let config = stiff(RearExit::Reset);
    let run = walk(&config, 60);
    assert!(run.failure.is_none(), "{:?}", run.failure);
    assert_eq!(run.steps.len(), 60);
    for s in &run.steps {
        assert_audits_clean(s, &format!("step {}", s.step));
    }
    // Some touchdowns did discard a free rear leg's state (a tiny energy here: it was within the stopper gap).
    assert!(run.steps.iter().any(|s| s.energy.reset != 0.0));
    assert_energy_carries_over(&run, &config, 1e-9);
}

/// Where the rear leg is always relocked in time, `reset` discards nothing: the walk is the same, bit for bit.
#[test]
fn reset_leaves_a_walk_whose_rear_leg_relocks_unchanged() {
    let relock = walk(&Config::default(), 8);
    let mut config = Config::default();
    config.params.rear_exit = RearExit::Reset;
    let reset = walk(&config, 8);
    assert_eq!(relock.steps, reset.steps);
    assert_energy_carries_over(&reset, &config, 1e-9);
}

/// `continue`: the old rear leg that is still free at the touchdown swings on as `L3` and locks on its stopper
/// soon after (an impact counted with the stopper losses), so the walk that `relock` stops goes on, every step
/// with clean audits and `T + V` carried through re-indexing, nothing discarded.
#[test]
fn continue_walks_on_where_relock_stops_with_clean_audits() {
    let config = stiff(RearExit::Continue);
    let run = walk(&config, 60);
    assert!(run.failure.is_none(), "{:?}", run.failure);
    assert_eq!(run.steps.len(), 60);
    for s in &run.steps {
        assert_audits_clean(s, &format!("step {}", s.step));
        assert_eq!(s.energy.reset, 0.0);
    }
    assert!(run.work.events.swing_lock > 0, "{:?}", run.work.events);
    assert_energy_carries_over(&run, &config, 1e-9);
    // Up to the touchdown where relock stops, the two walks are the same (compared as text: airborne steps have
    // NaN indicators).
    let relock = walk(&stiff(RearExit::Relock), 60);
    let n = relock.steps.len();
    assert_eq!(
        format!("{:?}", relock.steps),
        format!("{:?}", &run.steps[..n])
    );
}

/// Where the rear leg is always relocked in time (the default gait), `continue` has no leg to carry: the walk
/// and the gait are the same, bit for bit.
#[test]
fn continue_leaves_the_default_gait_unchanged() {
    let mut config = Config::default();
    config.params.rear_exit = RearExit::Continue;
    assert_eq!(walk(&Config::default(), 8).steps, walk(&config, 8).steps);
    let gait = |c: &Config| {
        let model = Model::new(&c.params).unwrap();
        let map = vrw::gait::StepMap::new(&model, &c.solver);
        vrw::gait::find_gait(&map, &default_initial(c), &GaitOptions::default(), None).unwrap()
    };
    let (relock, carried) = (gait(&Config::default()), gait(&config));
    assert_eq!(relock.section, carried.section);
    assert_eq!(relock.jacobian, carried.jacobian);
    assert_eq!(relock.floquet_multipliers, carried.floquet_multipliers);
}

#[test]
fn continue_needs_a_rear_stopper_and_no_compression_stop() {
    let mut config = Config::default();
    config.params.rear_exit = RearExit::Continue;
    config.params.min_length = 0.9;
    let error = config.params.validate().unwrap_err().to_string();
    assert!(
        error.contains("min_length") && error.contains("continue"),
        "{error}"
    );
    let mut config = third_party();
    config.params.rear_exit = RearExit::Continue;
    let error = config.params.validate().unwrap_err().to_string();
    assert!(error.contains("rear_stopper"), "{error}");
    let config = Config::from_toml_str("rear_exit = \"continue\"").unwrap();
    assert_eq!(config.params.rear_exit, RearExit::Continue);
}

#[test]
fn rear_exit_reads_and_writes_its_names() {
    let config = Config::from_toml_str("rear_exit = \"reset\"").unwrap();
    assert_eq!(config.params.rear_exit, RearExit::Reset);
    let error = Config::from_toml_str("rear_exit = \"drop\"").unwrap_err();
    assert!(error.to_string().contains("rear_exit"), "{error}");
    // The default is left out of written configurations (they stay as before the key existed).
    let json = serde_json::to_string(&Config::default()).unwrap();
    assert!(!json.contains("rear_exit"), "{json}");
    assert!(serde_json::to_string(&config)
        .unwrap()
        .contains("\"rear_exit\":\"reset\""));
}

/// The third-party code's reading: Leg 2 without its stopper (`rear_stopper = false`), its state discarded
/// at the next touchdown (`rear_exit = "reset"`).
fn third_party() -> Config {
    let mut c = Config::default();
    c.params.rear_stopper = false;
    c.params.rear_exit = RearExit::Reset;
    c
}

#[test]
fn without_a_rear_stopper_leg_2_extends_past_l0_and_the_audits_stay_clean() {
    let config = third_party();
    let mut trajectory = Trajectory::new(0.002);
    let run = walk_into(&config, 12, Some(&mut trajectory));
    assert!(run.failure.is_none(), "{:?}", run.failure);
    let l0 = config.params.stopper_length;
    let longest_rear = trajectory
        .samples
        .iter()
        .map(|s| s.q[L2])
        .fold(0.0, f64::max);
    let longest_fore = trajectory
        .samples
        .iter()
        .map(|s| s.q[L1])
        .fold(0.0, f64::max);
    assert!(
        longest_rear > l0 + 1e-3,
        "Leg 2 reached only {longest_rear}"
    );
    assert!(
        longest_fore <= l0 + 1e-8,
        "Leg 1 went past its stopper: {longest_fore}"
    );
    for s in &run.steps {
        assert_audits_clean(s, &format!("step {}", s.step));
        // The extended rear leg is reset to `L0` at every touchdown, which adds the spring energy back.
        assert!(s.energy.reset < 0.0, "step {}: {:?}", s.step, s.energy);
    }
    assert_energy_carries_over(&run, &config, 1e-9);
}

#[test]
fn a_rear_leg_without_a_stopper_needs_reset_and_soft_legs() {
    let mut config = third_party();
    config.params.rear_exit = RearExit::Relock;
    let error = config.validate().unwrap_err().to_string();
    assert!(
        error.contains("rear_stopper") && error.contains("reset"),
        "{error}"
    );
    let mut config = third_party();
    config.params.rigid_legs = true;
    let error = config.validate().unwrap_err().to_string();
    assert!(
        error.contains("rear_stopper") && error.contains("rigid"),
        "{error}"
    );
    assert!(third_party().validate().is_ok());
    // Left out of written configurations at its default, written when false.
    assert!(!serde_json::to_string(&Config::default())
        .unwrap()
        .contains("rear_stopper"));
    assert!(serde_json::to_string(&third_party())
        .unwrap()
        .contains("\"rear_stopper\":false"));
}

/// Every reading in `readings/` loads, and on a sweep of `c` over 1..300 every gait it has passes the audits:
/// the energy balance closes, the ground never pulls, no tip goes below it, no leg past its stopper.
#[test]
fn every_reading_walks_with_clean_audits_where_it_has_a_gait() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("readings");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 5, "{files:?}");
    let values: Vec<f64> = (0..12).map(|i| 1.0 + 299.0 * i as f64 / 11.0).collect();
    for file in files {
        let config = Config::from_file(&file).unwrap();
        let points = sweep(&config, "viscosity", &values);
        let gaits: Vec<_> = points
            .iter()
            .filter_map(|p| p.gait.as_ref().map(|g| (p.value, g)))
            .collect();
        if file.ends_with("tension.toml") {
            // The tension reading has no gait: every walk rolls back (the README's table).
            assert!(gaits.is_empty(), "{}: a gait", file.display());
            assert!(points
                .iter()
                .all(|p| p.status == vrw::study::PointStatus::NoGait("rolled_back")));
        } else {
            assert!(!gaits.is_empty(), "{}: no gait", file.display());
        }
        for (c, g) in gaits {
            let at = format!("{} at c = {c}", file.display());
            assert!(
                g.energy_residual.abs() < 1e-8,
                "{at}: {}",
                g.energy_residual
            );
            for s in &g.cycle {
                assert_audits_clean(s, &at);
            }
        }
    }
}

/// A spring shorter than its stopper (the tension reading) needs `rear_exit = "reset"`; with it, the fore leg
/// leaves its stopper as it lands and the step's audits are clean (the wheel then rolls back: no gait).
#[test]
fn a_spring_shorter_than_its_stopper_needs_reset_and_walks_with_clean_audits() {
    let mut config = Config::default();
    config.params.stopper_length = 1.02;
    config.params.spring_natural_length = 1.0;
    let error = config.validate().unwrap_err().to_string();
    assert!(
        error.contains("spring_natural_length") && error.contains("reset"),
        "{error}"
    );
    config.params.rear_exit = RearExit::Reset;
    config.validate().unwrap();
    let mut trajectory = Trajectory::new(0.001);
    let run = walk_into(&config, 3, Some(&mut trajectory));
    assert!(
        matches!(run.failure, Some(WalkError::RolledBack { .. })),
        "{:?}",
        run.failure
    );
    assert_audits_clean(&run.steps[0], "the walked step");
    // In tension from the touchdown on: Leg 1 is off its stopper at once, and shortens.
    let after = &trajectory.samples[1];
    assert!(!after.active.lock1 && after.q[L1] < config.params.stopper_length);
}

/// The stroke-limited reading (`readings/stroke-limited.toml`): a rigid compression stop at 1.0 m, stopper and
/// natural length 1.02 m, the rear leg reset and without its stopper.
fn stroke_limited() -> Config {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("readings/stroke-limited.toml");
    Config::from_file(&path).unwrap()
}

/// Issue 21's "done means" for the stroke-limited leg: a gait at every `c` from 5 to 300 at `k = 500`, with
/// `lambda_I4 > 0`, `lambda_4+` falling through zero between 51 and 52.3 (the README's refined threshold
/// 51.627) and the (B3) branch past it, the stance leg held at its compression stop at every touchdown (the
/// step map on `dtheta/dt` alone, one multiplier), and clean audits on every step, the legs never below the
/// stop (the stopper audit).
#[test]
fn the_stroke_limited_leg_has_the_papers_shape_with_its_threshold_near_52() {
    let config = stroke_limited();
    let model = Model::new(&config.params).unwrap();
    let mut values: Vec<f64> = (0..12).map(|i| 5.0 + 295.0 * i as f64 / 11.0).collect();
    values.extend([51.0, 52.3]);
    values.sort_by(f64::total_cmp);
    let points = sweep(&config, "viscosity", &values);
    let mut last_lambda_4 = f64::INFINITY;
    for p in &points {
        let at = format!("stroke-limited at c = {}", p.value);
        let g = p
            .gait
            .as_ref()
            .unwrap_or_else(|| panic!("{at}: {:?}", p.message));
        assert!(
            g.section.rear_held(&model) && g.rear_held,
            "{at}: {:?}",
            g.section
        );
        assert_eq!(g.floquet_multipliers.len(), 1, "{at}");
        assert!(g.lambda_i4 > 0.0, "{at}: {}", g.lambda_i4);
        assert!(g.lambda_4_plus < last_lambda_4, "{at}: lambda_4+ rises");
        last_lambda_4 = g.lambda_4_plus;
        let b3 = g.branch.to_string() == "SLS_B3";
        assert_eq!(
            g.lambda_4_plus < 0.0,
            b3,
            "{at}: {} {}",
            g.branch,
            g.lambda_4_plus
        );
        assert_eq!(
            g.lambda_4_plus > 0.0,
            p.value <= 51.0,
            "{at}: {}",
            g.lambda_4_plus
        );
        assert!(g.lambda_2_plus > 0.0, "{at}: {}", g.lambda_2_plus);
        for s in &g.cycle {
            assert_audits_clean(s, &at);
        }
    }
}

/// `min_length` is refused where it is not a compression stop: negative, at or above the stopper, with rigid
/// legs; and a section state with Leg 2 below it is not a state of the wheel.
#[test]
fn a_compression_stop_is_validated_where_it_enters() {
    for (set, needle) in [
        ("min_length=-0.1", "must be non-negative"),
        ("min_length=1.0", "must be < stopper_length (1)"),
        ("min_length=1.5", "must be < stopper_length (1)"),
        ("min_length=nan", "min_length"),
    ] {
        let error = Config::load(None, &[set]).unwrap_err().to_string();
        assert!(error.contains(needle), "{set}: {error}");
    }
    let error = Config::load(None, &["min_length=0.9", "rigid_legs=true"])
        .unwrap_err()
        .to_string();
    assert!(error.contains("rigid legs never shorten"), "{error}");
    let config = stroke_limited();
    let model = Model::new(&config.params).unwrap();
    let below = vrw::walk::SectionState {
        l2: 0.99,
        theta_dot: 2.0,
        l2_dot: 0.0,
        slip: 0.0,
    };
    let error = below.validate(&model).unwrap_err().to_string();
    assert!(error.contains("min_length"), "{error}");
    // Written configurations leave the key out at its default (0, none), and keep it otherwise.
    let text = toml::to_string(&Config::default()).unwrap();
    assert!(!text.contains("min_length"), "{text}");
    assert!(toml::to_string(&config)
        .unwrap()
        .contains("min_length = 1.0"));
}

/// A touchdown length inside the stroke (`touchdown_length`, between `min_length` and the stopper) lands every
/// leg free at that length (the spokes have it too), with clean audits and the energy carried over through the
/// resets; outside the stroke, or shorter than the stopper without `rear_exit = "reset"`, it is refused.
#[test]
fn a_touchdown_length_inside_the_stroke_lands_the_leg_free_there() {
    for (sets, needle) in [
        (
            &["touchdown_length=1.2"][..],
            "must be <= stopper_length (1)",
        ),
        (&["touchdown_length=0.9"][..], "needs rear_exit = \"reset\""),
        (
            &["rear_exit=reset", "touchdown_length=0.2"][..],
            "must be > leg_mass_offset (0.3)",
        ),
        (
            &["rear_exit=reset", "min_length=0.95", "touchdown_length=0.9"][..],
            "must be >= min_length (0.95)",
        ),
    ] {
        let error = Config::load(None, sets).unwrap_err().to_string();
        assert!(error.contains(needle), "{sets:?}: {error}");
    }
    let mut config = stroke_limited();
    config.params.touchdown_length = 1.01;
    config.params.viscosity = 30.0;
    config.validate().unwrap();
    let mut trajectory = Trajectory::new(0.01);
    let run = walk_into(&config, 6, Some(&mut trajectory));
    assert!(run.failure.is_none(), "{:?}", run.failure);
    for s in &run.steps {
        assert_audits_clean(s, &format!("step {}", s.step));
        let landed = trajectory
            .samples
            .iter()
            .find(|x| x.time >= s.time)
            .unwrap();
        assert_eq!(landed.q[L1], 1.01, "step {}", s.step);
        assert!(!landed.active.lock1, "step {}", s.step);
    }
    assert_energy_carries_over(&run, &config, 1e-9);
}

/// A sweep in `min_length` itself carries the held leg with the stop (the gait at one value is the start at the
/// next, held at the new stop): a gait at every value, each held at its own stop. Before, every step up the line
/// started below the new stop and the sweep reported a false end of the gait.
#[test]
fn a_sweep_in_min_length_moves_the_held_leg_with_the_stop() {
    let config = stroke_limited();
    let model_at = |v: f64| {
        let mut c = config.clone();
        c.params.min_length = v;
        Model::new(&c.params).unwrap()
    };
    let values = [0.99, 0.995, 1.0, 1.005, 1.01];
    let points = sweep(&config, "min_length", &values);
    for p in &points {
        let g = p
            .gait
            .as_ref()
            .unwrap_or_else(|| panic!("{}: {:?}", p.value, p.message));
        assert!(
            g.rear_held && g.section.rear_held(&model_at(p.value)),
            "{}",
            p.value
        );
        assert_eq!(g.section.l2, p.value);
    }
    // lambda_4+ changes sign between 1.0 and 1.005 (the sweep's refined threshold: 1.001078).
    let sign = |v: f64| {
        let g = points
            .iter()
            .find(|p| p.value == v)
            .unwrap()
            .gait
            .as_ref()
            .unwrap();
        g.lambda_4_plus > 0.0
    };
    assert!(sign(1.0) && !sign(1.005));
}
