//! The paper's readings (issue 21): options that make a reading of the model the paper leaves open
//! expressible. Here `rear_exit`: what becomes of the old rear leg when it leaves the coordinates at a
//! touchdown (docs/model.md section 5).

use vrw::dynamics::Model;
use vrw::params::{Config, RearExit};
use vrw::reference::default_initial;
use vrw::walk::{simulate, WalkError, WalkRun};

/// Stiff legs where the old rear leg bounces on its stopper and is still free (within a micrometre of `L0`)
/// at a touchdown of the transient: `rear_exit = "relock"` stops there.
fn stiff(rear_exit: RearExit) -> Config {
    let mut c = Config::default();
    c.params.viscosity = 28.181818181818183;
    c.params.stiffness = 1945.4545454545455;
    c.params.rear_exit = rear_exit;
    c
}

fn walk(config: &Config, steps: usize) -> WalkRun {
    let model = Model::new(&config.params).unwrap();
    simulate(
        &model,
        &config.solver,
        &default_initial(config),
        steps,
        None,
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
        assert!(
            s.energy.residual.abs() < 1e-8,
            "step {}: {:?}",
            s.step,
            s.energy
        );
        assert!(
            s.contact.pull_force <= 1e-6,
            "step {}: {:?}",
            s.step,
            s.contact
        );
        assert!(
            s.contact.pull_impulse <= 1e-9,
            "step {}: {:?}",
            s.step,
            s.contact
        );
        assert!(
            s.contact.penetration <= 1e-9,
            "step {}: {:?}",
            s.step,
            s.contact
        );
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
