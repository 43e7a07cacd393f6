//! The saltation-based derivatives against finite differences of the whole step map, over walks that meet
//! every kind of event (the anchors' lesson: saltation code fails silently, so this cross-check stays in the
//! suite), and `dP/dp` against finite differences in every differentiable parameter.

use std::collections::BTreeSet;

use nalgebra::DMatrix;

use crate::contact::{impulse, ActiveSet, Role};
use crate::dynamics::{Model, DIFFERENTIABLE_KEYS};
use crate::gait::{DerivativeError, StepMap};
use crate::params::Config;
use crate::walk::tape::StepTape;
use crate::walk::{EventKind, SectionState, Walker};

use super::NotDifferentiable;

/// Relative step of the central differences.
const FD_STEP: f64 = 1e-5;
/// Agreement required of the exact derivatives with the central differences, relative to the largest entry
/// of the column: the differences' truncation (~FD_STEP^2) and noise (~1e-12 / FD_STEP) are well below it; a
/// missing or wrong saltation term is of the order of the entries.
const FD_AGREEMENT: f64 = 2e-5;

/// The walks: `(overrides, start)`. Together they meet every kind of event (asserted below).
fn cases() -> Vec<(Vec<&'static str>, SectionState)> {
    let s = |l2, theta_dot, l2_dot| SectionState {
        l2,
        theta_dot,
        l2_dot,
        slip: 0.0,
    };
    vec![
        // The paper's gait: DLS, rear lift-off into a slide, stopper lock of the rear leg.
        (vec![], s(0.714888348, 0.964139462, -0.423466119)),
        // Leg 1 bounces: fore lift-off, landing.
        (vec!["viscosity=4", "stiffness=640"], s(0.72, 1.0, 0.0)),
        // The traditional exchange: the rear leg leaves at once and lands again (re-contact).
        (vec!["impact=traditional"], s(0.72, 1.0, 0.0)),
        // Stiff legs from a fast start: Leg 1 lifts off, the wheel flies, Zeno locks of the stoppers.
        (
            vec!["stiffness=6000", "spring_natural_length=1.0"],
            s(0.995, 1.8, 0.0),
        ),
        // The (B3) branch.
        (vec!["viscosity=80", "stiffness=1450"], s(0.93, 1.2, 0.0)),
        // A start far from the gait: the rear tip lands again.
        (vec!["stiffness=300"], s(0.9, 1.3, 0.3)),
        // The stroke-limited leg (readings/stroke-limited.toml): Leg 2 held at its compression stop at the
        // section (the map on dtheta/dt alone), and free within its stroke.
        (STROKE_LIMITED.to_vec(), s(1.0, 2.0, 0.0)),
        (STROKE_LIMITED.to_vec(), s(1.01, 2.0, -0.05)),
        // ... landing free, inside its stroke (the section's and the re-indexing's touchdown length).
        (
            [
                &STROKE_LIMITED[..],
                &["touchdown_length=1.01", "viscosity=30"],
            ]
            .concat(),
            s(1.005, 2.0, 0.0),
        ),
        // Stiff legs with a compression stop inside the spring's range: the stance leg bottoms out and is
        // released again in single support as its load falls (a compression unlock).
        (
            vec![
                "stiffness=3000",
                "spring_natural_length=1.0",
                "min_length=0.95",
            ],
            s(0.99, 1.2, 0.0),
        ),
        // Coulomb friction (the gaits of `vrw gait --set friction=...`): both tips slip through the touchdown
        // impact, stick, slip again at the edge of the cone, lift off while slipping.
        (
            vec!["friction=0.3"],
            s(0.719768087, 1.063339047, -0.335804049),
        ),
        // ... a slip that reverses (the (B3) parameters).
        (
            vec!["friction=0.6", "viscosity=80", "stiffness=1450"],
            s(0.946482987, 2.288104242, 0.503231508),
        ),
        // ... the stance tip slipping at the section: the map on four coordinates.
        (
            vec!["friction=0.105"],
            SectionState {
                slip: 0.067750417,
                ..s(0.726069600, 1.274670977, -0.395701883)
            },
        ),
    ]
}

/// The stroke-limited reading: a compression stop at 1.0 m, stopper and natural length 1.02 m.
const STROKE_LIMITED: [&str; 5] = [
    "rear_exit=reset",
    "rear_stopper=false",
    "min_length=1.0",
    "stopper_length=1.02",
    "spring_natural_length=1.02",
];

fn config_of(overrides: &[&str]) -> Config {
    let mut config = Config::default();
    for o in overrides {
        config.apply_override(o).unwrap();
    }
    config
}

/// The kinds of event (and of reset) a tape holds, named.
fn kinds(tape: &StepTape) -> BTreeSet<String> {
    let mut kinds = BTreeSet::new();
    if tape.impacts.len() > 1 {
        kinds.insert("zeno lock at touchdown".to_string());
    }
    let slipping_impact = |sets: &[ActiveSet]| sets.iter().any(ActiveSet::any_slip);
    if slipping_impact(&tape.impacts) {
        kinds.insert("slipping impact".to_string());
    }
    if tape.segments.first().is_some_and(|s| s.active.slip1 != 0) {
        kinds.insert("slipping section".to_string());
    }
    for (segment, next) in tape.segments.iter().zip(tape.segments.iter().skip(1)) {
        let reversed = |leg| segment.active.slip(leg) * next.active.slip(leg) < 0;
        if reversed(Role::Fore) || reversed(Role::Rear) {
            kinds.insert("slip reversal".to_string());
        }
    }
    for segment in &tape.segments {
        let ActiveSet { slide1, slide2, .. } = segment.active;
        if segment.active.any_slip() {
            kinds.insert("coulomb slip".to_string());
        } else if slide1 || slide2 {
            kinds.insert("slide".to_string());
        }
        if let Some(end) = &segment.end {
            let name = match end.kind {
                EventKind::LiftOff(Role::Fore) => "fore lift-off",
                EventKind::LiftOff(Role::Rear) => "rear lift-off",
                EventKind::Unlock(_) => "stopper unlock",
                EventKind::Landing(Role::Fore) => "landing of Leg 1",
                EventKind::Landing(Role::Rear) => "rear re-contact",
                EventKind::StopperHit(_) => "stopper lock",
                EventKind::CompressionHit(_) => "compression lock",
                EventKind::CompressionUnlock(_) => "compression unlock",
                EventKind::Touchdown => "touchdown",
                EventKind::Fall | EventKind::RollBack => "failure",
                EventKind::SwingLock | EventKind::SwingLanding => "swinging leg",
                EventKind::ConeLimit(_) => "slip start",
                EventKind::SlipStop(_) => "slip stop",
            };
            kinds.insert(name.to_string());
            if end.impacts.len() > 1 {
                kinds.insert("zeno lock".to_string());
            }
            if slipping_impact(&end.impacts) {
                kinds.insert("slipping impact".to_string());
            }
        }
    }
    kinds
}

/// Central differences of the reduced map at `s`, column by column.
fn central(map: &StepMap, s: &SectionState) -> DMatrix<f64> {
    map.central_jacobian(s, FD_STEP).unwrap()
}

fn assert_columns_agree(exact: &DMatrix<f64>, fd: &DMatrix<f64>, context: &str) {
    for j in 0..exact.ncols() {
        let scale = fd.column(j).amax().max(1e-3);
        let diff = (exact.column(j) - fd.column(j)).amax();
        assert!(
            diff <= FD_AGREEMENT * scale,
            "{context}, column {j}: exact {}, finite differences {}, difference {diff:e}",
            exact.column(j).transpose(),
            fd.column(j).transpose()
        );
    }
}

/// A stopper unlock is crossed by the code of a lift-off (a force guard differentiated through the KKT solve,
/// then an identity reset); the stopper rows of that derivative are checked for every active set in
/// `kkt.rs`. No walk here meets one: after an impact the complementarity problem frees a loaded leg at once,
/// and a search over preloads of 100 to 250 N (`spring_natural_length` 1.2 to 1.5) and starts of 0.8 to 1.5
/// rad/s found no unlock event in four steps.
#[test]
fn saltation_based_jacobian_matches_finite_differences_at_every_event_kind() {
    let mut covered = BTreeSet::new();
    for (overrides, s) in cases() {
        let config = config_of(&overrides);
        let model = Model::new(&config.params).unwrap();
        let map = StepMap::new(&model, &config.solver).on_section_of(&s);
        let mut tape = StepTape::default();
        Walker::new(&model, &config.solver, &s)
            .unwrap()
            .step_taped(&mut tape)
            .unwrap();
        let seen = kinds(&tape);
        let exact = map
            .eval_with_derivatives(&s, None)
            .unwrap_or_else(|e| panic!("{overrides:?} from {s:?} ({seen:?}): {e}"));
        assert_columns_agree(
            &exact.jacobian,
            &central(&map, &s),
            &format!("{overrides:?} from {s:?} ({seen:?})"),
        );
        covered.extend(seen);
    }
    for kind in [
        "touchdown",
        "rear lift-off",
        "fore lift-off",
        "slide",
        "stopper lock",
        "landing of Leg 1",
        "rear re-contact",
        "zeno lock",
        "compression lock",
        "compression unlock",
        "slipping impact",
        "coulomb slip",
        "slip start",
        "slip stop",
        "slip reversal",
        "slipping section",
    ] {
        assert!(
            covered.contains(kind),
            "no walk meets a {kind}: {covered:?}"
        );
    }
}

#[test]
fn parameter_derivatives_match_finite_differences_for_every_key() {
    // Two frictionless walks and two with Coulomb slip (one from a slipping section). Without friction
    // `dP/dfriction` is 0 (no tip slips) and has no finite difference (friction is infinite).
    let cases = cases();
    let frictional = cases
        .iter()
        .filter(|(o, _)| o.first().is_some_and(|o| o.starts_with("friction")));
    for (overrides, s) in cases.iter().take(2).chain(frictional.step_by(2)) {
        // A hub inertia inside its domain, so that both differences exist.
        let mut config = config_of(overrides);
        config.params.hub_inertia = 0.2;
        let model = Model::new(&config.params).unwrap();
        let map = StepMap::new(&model, &config.solver).on_section_of(s);
        for key in DIFFERENTIABLE_KEYS {
            let exact = map.eval_with_derivatives(s, Some(key)).unwrap();
            if key == "friction" && !config.params.has_friction() {
                assert!(exact.dparam.unwrap().iter().all(|&d| d == 0.0));
                continue;
            }
            let value = |c: &Config| match key {
                "hub_mass" => c.params.hub_mass,
                "hub_inertia" => c.params.hub_inertia,
                "leg_mass" => c.params.leg_mass,
                "leg_mass_offset" => c.params.leg_mass_offset,
                "stopper_length" => c.params.stopper_length,
                "spring_natural_length" => c.params.spring_natural_length,
                "stiffness" => c.params.stiffness,
                "viscosity" => c.params.viscosity,
                "slope" => c.params.slope,
                "gravity" => c.params.gravity,
                "friction" => c.params.friction,
                _ => unreachable!(),
            };
            let p0 = value(&config);
            let h = FD_STEP * p0.abs().max(1.0);
            let at = |p: f64| {
                let c = config.with(key, p).unwrap();
                let model = Model::new(&c.params).unwrap();
                let map = StepMap::new(&model, &c.solver).on_section_of(s);
                map.reduce(&map.eval(s).unwrap().next)
            };
            let fd = (at(p0 + h) - at(p0 - h)) / (2.0 * h);
            let exact = exact.dparam.unwrap();
            let fd = DMatrix::from_column_slice(fd.len(), 1, fd.as_slice());
            let exact = DMatrix::from_column_slice(exact.len(), 1, exact.as_slice());
            assert_columns_agree(&exact, &fd, &format!("dP/d{key} at {overrides:?}"));
        }
    }
}

/// The replay takes the state's vector field from the walk's log of its evaluations ([`StepTape::logging`])
/// instead of solving the constrained dynamics again: on walks that meet every kind of event it finds every
/// state there, the walk is the same with and without the log, and so are the sensitivities, bit for bit.
#[test]
fn the_replay_finds_every_state_in_the_walks_log() {
    use super::{augmented, replay_step, Sensitivity};
    for (overrides, s) in cases() {
        let config = config_of(&overrides);
        let model = Model::new(&config.params).unwrap();
        let (q, qd) = s.to_coords(&model);
        let s0 = Sensitivity::<3>::from_fn(|i, j| ((i + 3 * j) as f64).sin());
        let replay = |tape: &StepTape| {
            replay_step::<3, 4, { augmented(3) }>(
                &model,
                &config.solver,
                None,
                (&q, &qd),
                &s0,
                tape,
            )
            .map(|d| d.sensitivity)
        };
        let (mut plain, mut logged) = (StepTape::default(), StepTape::logging());
        let walk = |tape: &mut StepTape| {
            let mut walker = Walker::new(&model, &config.solver, &s).unwrap();
            let report = walker.step_taped(tape).unwrap();
            (report, walker.state().clone())
        };
        assert_eq!(walk(&mut plain), walk(&mut logged), "{overrides:?}");
        let (without, with) = (replay(&plain), replay(&logged));
        assert_eq!(without, with, "{overrides:?}");
        let (found, missed) = logged.stages.as_ref().unwrap().lookups();
        assert!(
            found > 100 && missed == 0,
            "{overrides:?}: {found} found, {missed} missed"
        );
    }
}

/// With Coulomb friction at the ratio of the paper's no-slip touchdown impulse's tangential to normal part, that
/// impulse lies on the edge of its cone: the border between a sticking and a slipping impact, where the step map
/// has no derivative, and the replay says so. Away from the edge the derivative exists.
#[test]
fn an_impulse_on_the_edge_of_its_cone_has_no_derivative() {
    let (overrides, s) = &cases()[0];
    let config = config_of(overrides);
    let model = Model::new(&config.params).unwrap();
    let mut tape = StepTape::default();
    Walker::new(&model, &config.solver, s)
        .unwrap()
        .step_taped(&mut tape)
        .unwrap();
    let (q, qd) = s.to_coords(&model);
    let sol = impulse(&model, &q, &qd, &tape.impacts[0]).unwrap();
    let ratio = (sol.impulses[2] / sol.impulses[3]).abs();
    assert!(ratio > 10.0, "the rear tip's impulse ratio {ratio}");
    let at = |mu: f64| {
        let c = config.with("friction", mu).unwrap();
        let model = Model::new(&c.params).unwrap();
        StepMap::new(&model, &c.solver)
            .eval_with_derivatives(s, None)
            .map(|_| ())
    };
    match at(ratio * (1.0 + 1e-13)) {
        Err(DerivativeError::NotDifferentiable(NotDifferentiable::ImpulseBorder { .. })) => {}
        other => panic!("mu = {ratio}: {other:?}"),
    }
    assert_eq!(at(ratio * 1.01), Ok(()));
    assert_eq!(at(ratio * 0.99), Ok(()));
}

/// A map whose section slips, evaluated where the stance tip is at rest, is on the border between the sticking
/// and slipping sections: no derivative (Newton's method takes a finite difference there).
#[test]
fn a_slipping_map_at_rest_has_no_derivative() {
    let (overrides, slipping) = cases().pop().unwrap();
    assert!(slipping.slips());
    let config = config_of(&overrides);
    let model = Model::new(&config.params).unwrap();
    let map = StepMap::new(&model, &config.solver).on_section_of(&slipping);
    let at_rest = SectionState {
        slip: 0.0,
        ..slipping
    };
    assert_eq!(
        map.eval_with_derivatives(&at_rest, None).err(),
        Some(DerivativeError::NotDifferentiable(
            NotDifferentiable::SectionAtRest
        ))
    );
    assert!(map.eval_with_derivatives(&slipping, None).is_ok());
}
