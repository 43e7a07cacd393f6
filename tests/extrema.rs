//! `vrw continue --extremum` (docs/model.md section 11): the quantities monitored along a gait family, their
//! derivatives along it against a finite-difference route (gaits searched at nearby parameters), and their
//! extrema against the gaits around them.

use std::path::PathBuf;

use vrw::app::{compute_continuation, ContinueJob, ContinueResult, SpecialRecord};
use vrw::continuation::monitor::ExtremumKind;
use vrw::dynamics::Model;
use vrw::family::monitor::MONITORED_QUANTITIES;
use vrw::gait::{find_gait, Gait, GaitOptions, StepMap};
use vrw::params::Config;
use vrw::walk::SectionState;

/// `vrw continue --no-switch --param KEY --start START --from A --to B --extremum ...`.
fn continued(key: &str, start: f64, (from, to): (f64, f64), names: &[&str]) -> ContinueResult {
    let job = ContinueJob {
        param: key.to_string(),
        start: Some(start),
        from,
        to,
        extremum: names.iter().map(|n| n.to_string()).collect(),
        ..continued_job()
    };
    compute_continuation(&job).unwrap()
}

/// The gait of the paper's wheel with `key = value`, searched by Newton's method from `near` (no transient
/// steps: it may be unstable).
fn gait(key: &str, value: f64, near: SectionState) -> Gait {
    let mut config = Config::default();
    config.set_numeric(key, value).unwrap();
    let model = Model::new(&config.params).unwrap();
    let map = StepMap::new(&model, &config.solver);
    let options = GaitOptions {
        transient_steps: 0,
        ..GaitOptions::default()
    };
    find_gait(&map, &near, &options, None).unwrap()
}

/// A monitored quantity of a gait, read from its own fields.
fn of_gait(g: &Gait, name: &str) -> f64 {
    match name {
        "speed" => g.speed,
        "period" => g.period,
        "step_length" => g.step_length,
        "dls_duration" => g.dls_duration,
        "rear_contact_duration" => g.rear_contact_duration,
        "lambda_I4" => g.lambda_i4,
        "lambda_2_plus" => g.lambda_2_plus,
        "lambda_4_plus" => g.lambda_4_plus,
        "max_floquet" => g.max_floquet,
        "damper_loss" => g.cycle[0].energy.damper,
        "impact_loss" => g.cycle[0].energy.impact,
        other => panic!("no quantity {other}"),
    }
}

/// The section state of a special point.
fn section_of(sp: &SpecialRecord) -> SectionState {
    SectionState {
        l2: sp.section.l2,
        theta_dot: sp.section.thetadot,
        l2_dot: sp.section.l2dot,
        slip: 0.0,
    }
}

/// The extrema of a continuation, with their records.
fn extrema(result: &ContinueResult) -> Vec<&SpecialRecord> {
    result
        .summary
        .special_points
        .iter()
        .filter(|s| s.extremum.is_some())
        .collect()
}

/// Every monitored quantity's derivative along the default family, at points away from its corners, against
/// a finite-difference route along the family: the gaits at `c +- 1e-3` (each a fixed point found by Newton's
/// method) give `dq/dc`, times `dc/ds = sigma t_c` of the point's tangent.
#[test]
fn derivatives_along_the_family_agree_with_differences_of_gaits() {
    let result = continued("viscosity", 50.0, (1.0, 300.0), &["speed"]);
    let family = &result.families[0];
    let sigma = family.options.param_scale;
    let monitored = &result.extrema.monitored[0];
    let mut compared = 0;
    for i in [5, 12, 20, 28] {
        let point = &family.points[i];
        let dc_ds = sigma
            * point.tangent[point.tangent.len() - 1].abs()
            * (family.points[i + 1].param - family.points[i - 1].param).signum();
        let near = point.info.report.section;
        let delta = 1e-3;
        let (below, above) = (
            gait("viscosity", point.param - delta, near),
            gait("viscosity", point.param + delta, near),
        );
        for (j, name) in MONITORED_QUANTITIES.iter().enumerate() {
            let route = (of_gait(&above, name) - of_gait(&below, name)) / (2.0 * delta) * dc_ds;
            let d = monitored[i][j].derivative;
            assert!(
                (d - route).abs() <= 1e-4 * route.abs().max(1e-3),
                "{name} at c = {}: dq/ds {d} along the tangent, {route} by the gaits",
                point.param
            );
            compared += 1;
        }
    }
    assert_eq!(compared, 4 * MONITORED_QUANTITIES.len());
}

/// The most stable gait of the default family: the largest multiplier's modulus is least at a corner, where its
/// complex pair splits into two real multipliers (c = 94.4728); the gaits searched at `c* + k 1e-3`,
/// `k = -5..5`, are least at `k = 0`, with the pair complex below and real above, and the speed reported is the
/// gait's there.
#[test]
fn max_floquet_is_least_at_a_corner_of_the_default_family() {
    let result = continued("viscosity", 50.0, (1.0, 300.0), &["max_floquet"]);
    let found = extrema(&result);
    assert_eq!(found.len(), 1, "{found:?}");
    let sp = found[0];
    let e = sp.extremum.as_ref().unwrap();
    assert!(sp.located, "{sp:?}");
    assert_eq!(e.extremum, ExtremumKind::Min);
    assert_eq!(e.shape, "corner");
    assert!(
        e.corner.as_deref().unwrap().contains("complex pair"),
        "{e:?}"
    );
    let [lo, hi] = e.located_bracket;
    assert!(
        hi - lo <= 1e-8 && lo <= sp.param && sp.param <= hi,
        "{lo} {hi}"
    );
    let c = sp.param;
    assert!((c - 94.4728).abs() < 1e-3, "{c}");
    let near = section_of(sp);
    let at_c = gait("viscosity", c, near);
    assert!(
        (at_c.speed - e.speed).abs() < 1e-9,
        "{} {}",
        at_c.speed,
        e.speed
    );
    assert!(
        (at_c.max_floquet - e.value).abs() < 1e-6,
        "{} {}",
        at_c.max_floquet,
        e.value
    );
    let sweep: Vec<Gait> = (-5..=5)
        .map(|k| gait("viscosity", c + f64::from(k) * 1e-3, near))
        .collect();
    let least = (0..sweep.len())
        .min_by(|&a, &b| sweep[a].max_floquet.total_cmp(&sweep[b].max_floquet))
        .unwrap();
    assert_eq!(
        least,
        5,
        "{:?}",
        sweep.iter().map(|g| g.max_floquet).collect::<Vec<_>>()
    );
    assert_ne!(
        sweep[4].floquet_multipliers[0][1], 0.0,
        "a complex pair below"
    );
    assert_eq!(
        sweep[6].floquet_multipliers[0][1], 0.0,
        "real multipliers above"
    );
}

/// Smooth maxima along the slope family (through its fold): the damper's and the impacts' losses per step, and
/// `lambda_2+`. Each is confirmed by the gaits at `p*` and `p* +- delta`: the quantity is largest at `p*`, and
/// the vertex of the parabola through the three, extrapolated to
/// `delta = 0` from `delta = 2e-4` and `1e-4`, lies within `1e-8` of `p*`.
#[test]
fn smooth_maxima_along_the_slope_family_are_confirmed_by_the_gaits_around_them() {
    let names = ["damper_loss", "impact_loss", "lambda_2_plus"];
    let result = continued("slope", 0.1, (0.05, 0.35), &names);
    let found = extrema(&result);
    assert_eq!(found.len(), 3, "{found:?}");
    for sp in found {
        let e = sp.extremum.as_ref().unwrap();
        assert!(sp.located && e.shape == "smooth", "{sp:?}");
        assert_eq!(e.extremum, ExtremumKind::Max);
        let p = sp.param;
        let near = section_of(sp);
        let vertex = |delta: f64| {
            let q: Vec<f64> = [-delta, 0.0, delta]
                .iter()
                .map(|d| of_gait(&gait("slope", p + d, near), &e.quantity))
                .collect();
            assert!(
                (q[1] - e.value).abs() < 1e-8 * e.value.abs().max(1.0),
                "{q:?} {}",
                e.value
            );
            assert!(q[1] > q[0] && q[1] > q[2], "{}: {q:?}", e.quantity);
            p + delta * (q[0] - q[2]) / (2.0 * (q[0] - 2.0 * q[1] + q[2]))
        };
        // The vertex moves with delta^2 (the cubic term): Richardson's extrapolation to delta = 0.
        let (v2, v1) = (vertex(2e-4), vertex(1e-4));
        let limit = (4.0 * v1 - v2) / 3.0;
        assert!(
            (limit - p).abs() < 1e-8,
            "{}: vertex {limit}, located {p}",
            e.quantity
        );
    }
}

/// An unknown quantity is refused, naming the known ones; without `extremum` nothing is monitored.
#[test]
fn an_unknown_quantity_is_refused_naming_the_known_ones() {
    let mut job = ContinueJob {
        extremum: vec!["fastness".to_string()],
        ..continued_job()
    };
    let message = compute_continuation(&job).unwrap_err().to_string();
    assert!(message.contains("fastness"), "{message}");
    for name in MONITORED_QUANTITIES {
        assert!(message.contains(name), "{message}");
    }
    job.extremum.clear();
    let result = compute_continuation(&job).unwrap();
    assert!(result.extrema.monitored.is_empty());
    assert!(extrema(&result).is_empty());
}

/// A short job of the default family.
fn continued_job() -> ContinueJob {
    ContinueJob {
        config: Config::default(),
        param: "viscosity".to_string(),
        start: Some(50.0),
        from: 40.0,
        to: 60.0,
        initial: None,
        period: None,
        max_points: 300,
        max_step: 0.1,
        switch: false,
        plot: "thetadot".to_string(),
        out_dir: PathBuf::new(),
        overwrite: false,
        interrupt: None,
        two_param: None,
        extremum: Vec::new(),
    }
}
