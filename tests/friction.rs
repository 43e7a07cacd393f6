//! Coulomb friction at the tips (docs/model.md section 12): over a sweep of the friction coefficient and the
//! viscosity, every step's audits are clean (the friction cone holds for sticking contacts and impulses, the
//! friction force never does positive work, the energy audit closes with the friction work added, the ground
//! never pulls), and walks that stop end with a named status. The closed-form checks (the balanced wheel's
//! stick/slip threshold, the oblique landing's Coulomb impulse, the Painleve case) are unit tests of
//! `walk::complementarity` and `contact::coulomb`.

use vrw::dynamics::Model;
use vrw::params::Config;
use vrw::reference::default_initial;
use vrw::walk::{simulate, StepReport, WalkError, Walker};

/// Largest distance outside the friction cone of a sticking contact's force \[N\]: slip-start events fire at
/// `FORCE_EVENT_MARGIN` = 1e-10 N outside.
const CONE_TOL: f64 = 1e-9;
/// Largest energy-audit residual \[J\].
const ENERGY_TOL: f64 = 1e-8;

fn config(overrides: &[String]) -> Config {
    let mut config = Config::default();
    for o in overrides {
        config.apply_override(o).unwrap();
    }
    config.validate().unwrap();
    config
}

/// The steps of a walk of `steps` from the default start, and how it ended (`None`: every step walked).
fn walk(overrides: &[String], steps: usize) -> (Vec<StepReport>, Option<WalkError>) {
    let config = config(overrides);
    let model = Model::new(&config.params).unwrap();
    let run = simulate(
        &model,
        &config.solver,
        &default_initial(&config),
        steps,
        None,
    )
    .unwrap();
    (run.steps, run.failure)
}

#[test]
fn friction_audits_are_clean_over_mu_and_viscosity() {
    let mut walked = 0;
    let mut slipped = 0.0_f64;
    for mu in [0.05, 0.3, 1.0, 1000.0] {
        for c in [1.0, 20.0, 50.0, 130.0] {
            let overrides = [format!("friction={mu}"), format!("viscosity={c}")];
            let (steps, end) = walk(&overrides, 4);
            if let Some(e) = end {
                // A walk may stop (it rolls back with little friction), with a named status.
                assert!(
                    ["rolled_back", "fell", "rear_leg_in_contact"].contains(&e.kind()),
                    "{overrides:?}: {e}"
                );
            }
            for s in &steps {
                let f = s.contact.friction.expect("a friction audit");
                let what = format!("{overrides:?} step {}: {f:?} {:?}", s.step, s.energy);
                assert!(f.cone_violation <= CONE_TOL, "{what}");
                assert!(f.cone_violation_impulse <= CONE_TOL, "{what}");
                assert_eq!(f.slip_power, 0.0, "{what}");
                assert!(s.energy.residual.abs() <= ENERGY_TOL, "{what}");
                assert!(s.contact.pull_force <= 1e-9, "{what}");
                assert!(s.contact.pull_impulse <= 1e-9, "{what}");
                assert!(s.audit_warnings().is_empty(), "{what}");
                let dissipated = s.energy.friction.unwrap();
                assert!(dissipated >= 0.0, "{what}");
                slipped = slipped.max(dissipated);
                walked += 1;
            }
        }
    }
    // Not vacuous: most walks go on, and tips slip.
    assert!(walked >= 40, "only {walked} steps");
    assert!(slipped > 1.0, "largest friction work {slipped} J");
}

/// Without friction (the default) no step has a friction audit or friction work, and the walk is the
/// no-slip model's.
#[test]
fn no_friction_means_no_friction_audit() {
    let (steps, end) = walk(&[], 3);
    assert!(end.is_none());
    for s in steps {
        assert!(s.contact.friction.is_none());
        assert!(s.energy.friction.is_none());
    }
}

/// With friction the rear tip slips at the paper's touchdowns: its tangential impulse (10 to 25 N s) is 50 to
/// 270 times its normal one, so with mu = 0.6 the (A1) collision slips, and the slip shows as friction work
/// and a Leg 2 whose stick (DLS) ends before its contact does.
#[test]
fn the_rear_tip_slips_at_touchdown_with_realistic_friction() {
    let config = config(&["friction=0.6".to_string()]);
    let model = Model::new(&config.params).unwrap();
    let mut walker = Walker::new(&model, &config.solver, &default_initial(&config)).unwrap();
    for _ in 0..3 {
        let s = walker.step(None).unwrap();
        assert!(s.energy.friction.unwrap() > 0.1, "{:?}", s.energy);
        assert!(s.dls_duration < s.rear_contact_duration, "{s:?}");
        assert!(s.indicators.lambda_i4 > 0.0);
    }
}

/// `steps.csv` of a walk with friction has the friction work and audit columns (and only such a walk: the
/// default header is unchanged); each row fills them.
#[test]
fn steps_csv_has_the_friction_columns_with_friction_only() {
    use vrw::output::{steps_header, steps_row, StepsColumns, STEPS_HEADER};
    let plain = StepsColumns::of(&Config::default().params);
    assert_eq!(steps_header(plain), STEPS_HEADER.to_vec());
    let config = config(&["friction=0.6".to_string()]);
    let columns = StepsColumns::of(&config.params);
    let header = steps_header(columns);
    assert_eq!(
        header[STEPS_HEADER.len()..],
        [
            "slip",
            "friction_loss",
            "cone_violation",
            "cone_violation_impulse",
            "slip_power"
        ]
    );
    let (steps, _) = walk(&["friction=0.6".to_string()], 1);
    let row = steps_row(&steps[0], columns);
    assert_eq!(row.len(), header.len());
    let friction_loss = row[STEPS_HEADER.len() + 1].to_csv();
    assert!(
        friction_loss.parse::<f64>().unwrap() > 0.1,
        "{friction_loss}"
    );
}

/// Regression: a slip that starts at rest after a stopper impact and reverses at once (its speed within
/// rounding of 0, the wrong way) is a slip-stop event; it was not, and friction pushed the tip along at up to
/// 3.3 W (`slip_power`) until the next event (mu = 0.3, c = 106.2, from near that gait).
#[test]
fn a_slip_that_reverses_at_once_is_stopped() {
    let config = config(&["friction=0.3".to_string(), "viscosity=106.2".to_string()]);
    let model = Model::new(&config.params).unwrap();
    let start = vrw::walk::SectionState {
        l2: 0.719334558057652,
        theta_dot: 0.7787901670716043,
        l2_dot: -0.2064695963255453,
        slip: 0.0,
    };
    let mut walker = Walker::new(&model, &config.solver, &start).unwrap();
    let s = walker.step(None).unwrap();
    let f = s.contact.friction.unwrap();
    assert_eq!(f.slip_power, 0.0, "{f:?}");
    assert!(s.audit_warnings().is_empty(), "{:?}", s.audit_warnings());
}

/// The README's table "large mu is not the no-slip model": one step from the no-slip gait at c = 37 with
/// mu = 1e3, 1e4, 1e5 and without friction. The stick phase (DLS) converges to the no-slip one as 1/mu, but
/// the slip that follows keeps the tangential force mu lambda_n where the no-slip model's slide is
/// frictionless: Leg 2 touches the ground 0.018 s longer, and friction does 0.017 J of work, however large mu.
#[test]
fn large_mu_is_not_the_no_slip_model() {
    let start = vrw::walk::SectionState {
        l2: 0.7137607593459316,
        theta_dot: 1.0210282344433548,
        l2_dot: -0.4795702983456791,
        slip: 0.0,
    };
    let step = |mu: &str| {
        let config = config(&["viscosity=37".to_string(), format!("friction={mu}")]);
        let model = Model::new(&config.params).unwrap();
        let mut walker = Walker::new(&model, &config.solver, &start).unwrap();
        walker.step(None).unwrap()
    };
    // (mu, DLS [s], rear contact [s], friction work [J]) as the README states them.
    let table = [
        ("inf", 1.788283, 1.826684, f64::NAN),
        ("1e3", 1.788195, 1.844602, 0.017025),
        ("1e4", 1.788274, 1.844644, 0.017018),
        ("1e5", 1.788282, 1.844648, 0.017018),
    ];
    let mut dls = Vec::new();
    for (mu, dls_duration, rear, work) in table {
        let s = step(mu);
        println!(
            "mu {mu}: {} {} {:?}",
            s.dls_duration, s.rear_contact_duration, s.energy.friction
        );
        assert!(
            (s.dls_duration - dls_duration).abs() < 1e-6,
            "mu {mu}: {s:?}"
        );
        assert!(
            (s.rear_contact_duration - rear).abs() < 1e-6,
            "mu {mu}: {s:?}"
        );
        if let Some(w) = s.energy.friction {
            assert!((w - work).abs() < 1e-6, "mu {mu}: {w}");
        }
        dls.push(s.dls_duration);
    }
    // DLS converges as 1/mu: each tenfold mu cuts the difference tenfold.
    let (d3, d4) = (dls[0] - dls[1], dls[0] - dls[2]);
    assert!((8.0..12.0).contains(&(d3 / d4)), "{d3} {d4}");
}

/// Stiff legs chatter on their stoppers and tips, which the Zeno rule locks (docs/model.md section 5); with
/// friction a tip closed there while it moves along the ground closes slipping (a sticking impulse would leave
/// the cone), and the audits stay clean. (The energy audit of such steps closes to 1e-8 J, as without friction.)
/// Regression: at c = 20 and 50 the closing tip was a candidate that had to push, and no mode was consistent.
#[test]
fn zeno_locks_with_friction_keep_the_cone() {
    let mut steps = Vec::new();
    for c in [5, 20, 50] {
        let overrides = [
            "friction=0.6".to_string(),
            format!("viscosity={c}"),
            "stiffness=3000".to_string(),
        ];
        let (walked, end) = walk(&overrides, 8);
        assert!(end.is_none(), "c = {c}: {end:?}");
        steps.extend(walked);
    }
    assert!(
        steps.iter().any(|s| s.contact.zeno_impulse > 0.0),
        "no Zeno lock"
    );
    for s in &steps {
        let f = s.contact.friction.unwrap();
        assert!(f.cone_violation <= CONE_TOL, "{f:?}");
        assert!(f.cone_violation_impulse <= CONE_TOL, "{f:?}");
        assert_eq!(f.slip_power, 0.0);
        assert!(s.energy.residual.abs() < 1e-7, "{:?}", s.energy);
        assert!(s.audit_warnings().is_empty(), "{:?}", s.audit_warnings());
    }
}

/// The gait of `overrides` from the default start (period 1, the command line's search settings).
fn gait(overrides: &[String]) -> Result<vrw::gait::Gait, vrw::gait::GaitError> {
    use vrw::gait::{find_gait, GaitOptions, StepMap};
    let config = config(overrides);
    let model = Model::new(&config.params).unwrap();
    let map = StepMap::new(&model, &config.solver);
    find_gait(
        &map,
        &default_initial(&config),
        &GaitOptions::default(),
        None,
    )
}

/// Just above `tan(slope)` (0.100335) the stance tip still slips at the touchdown: the gait is on the section
/// with its fourth coordinate, the slip velocity, and it is a property of the model, not of the integrator
/// (DOP853 and the order-5 pair at tighter tolerances agree); walked from the fixed point, the wheel comes
/// back to it (the section state holds the whole state at touchdown).
#[test]
fn a_gait_whose_stance_tip_slips_at_touchdown_has_the_slip_as_a_coordinate() {
    let mu = ["friction=0.105".to_string()];
    let g = gait(&mu).unwrap();
    assert!(g.section.slip > 0.05, "{:?}", g.section);
    assert_eq!(
        g.section_coordinates,
        Some(vec!["L2", "thetadot", "L2dot", "slip"])
    );
    assert_eq!(g.jacobian.len(), 4);
    assert!(g.stable && g.max_floquet < 0.8, "{}", g.max_floquet);
    let f = g.contact.friction.unwrap();
    assert!(f.cone_violation <= CONE_TOL && f.slip_power <= 0.0, "{f:?}");
    assert!(g.energy_residual.abs() <= ENERGY_TOL);

    let other = [
        mu[0].clone(),
        "integrator=dopri5".to_string(),
        "rtol=1e-12".to_string(),
        "atol=1e-14".to_string(),
    ];
    let h = gait(&other).unwrap();
    assert!(
        g.section.distance(&h.section) < 1e-7,
        "{:?} {:?}",
        g.section,
        h.section
    );
    assert!((g.period - h.period).abs() < 1e-7);

    let config = config(&mu);
    let model = Model::new(&config.params).unwrap();
    let mut walker = Walker::new(&model, &config.solver, &g.section).unwrap();
    for _ in 0..3 {
        walker.step(None).unwrap();
        let s = walker.section().unwrap();
        assert!(s.distance(&g.section) < 1e-9, "{s:?} vs {:?}", g.section);
    }
}

/// Below `tan(slope)` no gait can exist (the ground cannot hold the wheel along the slope with forces inside
/// the cone): the search says so at once, and the walk confirms it independently, sliding ever faster.
#[test]
fn no_gait_below_the_slope_tangent_and_the_wheel_slides_away() {
    let low = ["friction=0.1".to_string()];
    let e = gait(&low).unwrap_err();
    assert_eq!(e.kind(), "friction_below_slope", "{e}");
    let (steps, end) = walk(&low, 40);
    assert!(end.is_none(), "{end:?}");
    // The walk settles into a slide: its internal state repeats (L2 to 1e-12 m) while the tips keep slipping
    // down the slope, every force and impulse at the cone's edge, so that the momentum balance along the
    // slope gains `g (sin(slope) - mu cos(slope)) T` of slip velocity per step (4.6 mm/s) exactly.
    let (g, slope, mu) = (9.81_f64, 0.1_f64, 0.1_f64);
    for w in steps[34..].windows(2) {
        let (a, b) = (&w[0], &w[1]);
        assert!((b.section.l2 - a.section.l2).abs() < 1e-10);
        let gain = g * (slope.sin() - mu * slope.cos()) * a.period;
        let rise = b.section.slip - a.section.slip;
        assert!((rise / gain - 1.0).abs() < 1e-6, "{rise} vs {gain}");
    }
}

#[test]
fn a_slip_velocity_is_a_section_coordinate_only_with_friction() {
    use vrw::walk::SectionState;
    let s: SectionState = "0.72,1.0,0.0,0.05".parse().unwrap();
    assert_eq!(s.slip, 0.05);
    assert_eq!("0.72,1.0,0.0".parse::<SectionState>().unwrap().slip, 0.0);
    assert!("0.72,1.0,0.0,0.05,1".parse::<SectionState>().is_err());
    let plain = Model::new(&Config::default().params).unwrap();
    let e = s.validate(&plain).unwrap_err();
    assert!(e.to_string().contains("slip"), "{e}");
    let config = config(&["friction=0.3".to_string()]);
    let model = Model::new(&config.params).unwrap();
    s.validate(&model).unwrap();
    // The tip moves along the ground at `slip` and not across it.
    let (q, qd) = s.to_coords(&model);
    let v = model.tip(&q, &qd, 1).velocity(&qd);
    assert!((v.x - 0.05).abs() < 1e-15 && v.y.abs() < 1e-15, "{v:?}");
}

/// A sweep across the border where the mu = 0.3 family's stance tip starts to slip at touchdown (near c = 4.65):
/// Newton's method on the four-coordinate map may land on a state whose slip is exactly 0 (the tip at rest), and
/// its Newton matrix must still be the map's (regression: it was taken on that state's own three-coordinate
/// section, and the sweep panicked on the mismatch). The family continues through the border, slipping, and
/// its end below is reported with the evidence it has.
#[test]
fn a_sweep_across_the_slip_border_keeps_its_newton_matrix() {
    use vrw::app::compute_sweep;
    use vrw::gait::GaitOptions;
    let config = config(&["friction=0.3".to_string()]);
    let values: Vec<f64> = (0..21).map(|i| 4.0 + 0.1 * f64::from(i)).collect();
    let result = compute_sweep(
        &config,
        "viscosity",
        &values,
        None,
        &GaitOptions::for_sweeps(),
        &|_| {},
        &mut |_| Ok(()),
    )
    .unwrap();
    let found: Vec<_> = result
        .points
        .iter()
        .filter_map(|p| p.gait.as_ref())
        .collect();
    assert!(found.len() >= 15, "{} gaits", found.len());
    assert!(
        found.iter().any(|g| g.section.slips()),
        "no slipping gait below c = 4.65"
    );
    assert!(found.iter().any(|g| !g.section.slips()));
    // The family ends near c = 4.41 with an unstable gait: the walk from it fails whatever lies beyond, so the
    // note claims no more than that Newton's method stops there.
    let end = result
        .thresholds
        .iter()
        .find(|t| t.name == "gait_found")
        .expect("the family's end");
    let detail = end.detail.as_deref().unwrap_or_default();
    assert!(
        detail.contains("where its gait is unstable") && !detail.contains("and not at"),
        "{detail}"
    );
}
