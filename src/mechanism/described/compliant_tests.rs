//! Tests of described walkers with telescopic legs: `models/telescopic.toml` against the built-in telescopic
//! walker (its equations, contacts, energies and everything the compliant walk asks of it at random states,
//! its section and its gait), and the contacts put in the walk's order.

use nalgebra::{DVector, SVector};

use super::super::legged::gait::{legged_gait, legged_step_map};
use super::super::legged::walk::LeggedOptions;
use super::super::legged::Legged;
use super::super::rigid_family::Parametrized;
use super::super::telescopic::{Telescopic, KEYS};
use super::super::Mechanism;
use super::tests::{max_diff, shipped, Stream};
use super::{parse, AnyDescribed, Described};

/// Agreement asked of the description with the built-in, relative to each quantity's size.
const RELATIVE: f64 = 1e-10;

type Q = SVector<f64, 6>;

fn telescopic_toml() -> Described<6> {
    match shipped("telescopic") {
        AnyDescribed::N6(w) => w,
        other => panic!(
            "telescopic.toml has 6 coordinates, not {:?}",
            other.description().coordinates
        ),
    }
}

/// The largest difference between `a` and `b` relative to the larger of their largest entries (at least 1e-300).
fn relative<'a>(a: &'a [f64], b: &'a [f64]) -> f64 {
    let size = a.iter().chain(b).fold(1e-300f64, |m, x| m.max(x.abs()));
    max_diff(a, b) / size
}

/// The largest relative difference between the two walkers at `(q, q')`: `M`, `h`, both contacts' positions,
/// Jacobians and `(dJ/dt) q'`, `T`, `V`, the damper power, and what the legged walk asks (strokes, the hip's
/// height, the progress, the relabeling, the section's values).
fn difference(built_in: &Telescopic, ours: &Described<6>, q: &Q, qd: &Q) -> f64 {
    let (cb, co) = (built_in.constants_f64(), ours.constants_f64());
    let (eb, eo) = (built_in.equations(&cb, q, qd), ours.equations(&co, q, qd));
    let mut worst = relative(eb.mass.as_slice(), eo.mass.as_slice())
        .max(relative(eb.bias.as_slice(), eo.bias.as_slice()));
    for i in 0..2 {
        let (pb, po) = (built_in.contact(&cb, q, qd, i), ours.contact(&co, q, qd, i));
        worst = worst
            .max(relative(pb.position.as_slice(), po.position.as_slice()))
            .max(relative(pb.jacobian.as_slice(), po.jacobian.as_slice()))
            .max(relative(
                pb.velocity_product.as_slice(),
                po.velocity_product.as_slice(),
            ));
    }
    let scalars = [
        (built_in.kinetic_energy(q, qd), ours.kinetic_energy(q, qd)),
        (built_in.potential_energy(q), ours.potential_energy(q)),
        (built_in.damper_power(q, qd), ours.damper_power(q, qd)),
        (built_in.hip_height(q), ours.hip_height(q)),
        (built_in.progress(q, qd), ours.progress(q, qd)),
    ];
    for (a, b) in scalars {
        worst = worst.max(relative(&[a], &[b]));
    }
    let ((qb, qdb), (qo, qdo)) = (built_in.relabel(q, qd), ours.relabel(q, qd));
    worst = worst
        .max(relative(qb.as_slice(), qo.as_slice()))
        .max(relative(qdb.as_slice(), qdo.as_slice()));
    let (sb, so) = (built_in.section_of(q, qd), ours.section_of(q, qd));
    worst.max(relative(sb.as_slice(), so.as_slice()))
}

/// `models/telescopic.toml` is the built-in telescopic walker: the same coordinates, parameters and strokes,
/// and `M`, `h`, the tips' kinematics, the energies, the damper power, the hip, the relabeling and the section's
/// values equal to 1e-10 relative at 400 random states, at the defaults and at another parameter point.
#[test]
fn the_described_telescopic_walker_is_the_built_in_one() {
    let described = telescopic_toml();
    assert_eq!(described.coordinates(), Telescopic::default().coordinates());
    let mut keys = KEYS.to_vec();
    keys.sort_unstable();
    let mut ours: Vec<&str> = described.parameters().iter().map(|(k, _)| *k).collect();
    ours.sort_unstable();
    assert_eq!(ours, keys);
    for (k, v) in described.parameters() {
        let built_in = serde_json::to_value(Telescopic::default()).unwrap()[k].as_f64();
        assert_eq!(Some(v), built_in, "the default of {k}");
    }
    let set = [
        ("foot_mass", 0.8),
        ("stiffness", 15000.0),
        ("leg_mass_offset", 0.4),
        ("stopper_length", 0.95),
        ("viscosity", 700.0),
        ("slope", 0.07),
    ];
    let mut other = Telescopic::default();
    let mut other_described = described.clone();
    for (k, v) in set {
        other = other.with_parameter(k, v).unwrap();
        other_described = other_described.with_value(k, v).unwrap();
    }
    let mut stream = Stream(11);
    let mut worst = 0.0f64;
    for (built_in, ours) in [
        (Telescopic::default(), &described),
        (other, &other_described),
    ] {
        assert_eq!(built_in.strokes(), ours.strokes());
        assert_eq!(built_in.section_names(), ours.section_names());
        for _ in 0..200 {
            let q = stream.vector(
                [0.5, 0.3, 0.6, 0.6, 0.1, 0.1],
                [0.0, 0.9, 0.0, 0.0, 0.95, 0.95],
            );
            let qd = stream.vector([2.0; 6], [0.0; 6]);
            worst = worst.max(difference(&built_in, ours, &q, &qd));
        }
    }
    println!(
        "telescopic.toml against the built-in telescopic walker: max relative difference {worst:e}"
    );
    assert!(worst < RELATIVE, "{worst:e}");
}

/// The section's state from the contact conditions (Newton's method from the guess `theta2 = -theta1`) is the
/// built-in's closed form (`theta2 = -acos(L0 cos theta1 / L2)`, the hip moving about the rear tip at rest), and
/// where the rear leg is too short to reach the ground neither has one.
#[test]
fn the_described_telescopic_section_is_the_built_in_one() {
    let (built_in, described) = (Telescopic::default(), telescopic_toml());
    for s in [
        [0.28196, 0.99728, -1.65060, -1.47117, 0.00937],
        [0.2, 0.99, -1.2, -0.9, -0.05],
        [0.35, 0.96, -2.0, -1.0, 0.2],
    ] {
        let s = DVector::from_column_slice(&s);
        let (a, b) = (
            built_in.state_at_section(&s).unwrap(),
            described.state_at_section(&s).unwrap(),
        );
        let d = max_diff(a.0.iter(), b.0.iter()).max(max_diff(a.1.iter(), b.1.iter()));
        assert!(d < 1e-14, "section state at {s:?} differs by {d:e}");
    }
    let short = DVector::from_column_slice(&[0.28, 0.5, -1.6, -1.4, 0.0]);
    assert!(built_in.state_at_section(&short).is_none());
    assert!(described.state_at_section(&short).is_none());
}

/// `models/telescopic.toml` walks the built-in's gait: the same step from a point off the gait, the same fixed
/// point and period to 1e-10, the same heel strike (branch, DLS indicators, double support), and the same
/// multipliers to their accuracy (Richardson-extrapolated differences, each to its `jacobian_error`: two
/// estimates differ by at most the sum).
#[test]
fn the_described_telescopic_walker_walks_the_built_in_gait() {
    let (built_in, described) = (Telescopic::default(), telescopic_toml());
    let options = LeggedOptions::default();
    let off = DVector::from_column_slice(&[0.27, 0.998, -1.6, -1.4, 0.0]);
    let (a, _) = legged_step_map::<_, 6, 13>(&built_in, &off, &options).unwrap();
    let (b, _) = legged_step_map::<_, 6, 13>(&described, &off, &options).unwrap();
    let step = max_diff(a.iter(), b.iter());
    let start = built_in.default_start();
    let g1 = legged_gait::<_, 6, 13>(&built_in, &start, &options).unwrap();
    let g2 = legged_gait::<_, 6, 13>(&described, &start, &options).unwrap();
    let section = max_diff(g1.section.iter(), g2.section.iter());
    let period = (g1.step.period - g2.step.period).abs();
    let multipliers = max_diff(
        g1.multipliers.iter().flatten(),
        g2.multipliers.iter().flatten(),
    );
    let accuracy = g1.jacobian_error + g2.jacobian_error;
    let (h1, h2) = (&g1.step.account, &g2.step.account);
    println!(
        "step off the gait {step:e}; gait: section {section:e}, period {period:e}, multipliers {multipliers:e} \
         (DP to {accuracy:e}), lambda_I4 {:e}, DLS {:e}",
        (h1.lambda_i4 - h2.lambda_i4).abs(),
        (h1.dls_duration - h2.dls_duration).abs()
    );
    assert!(step < 1e-10 && section < 1e-10 && period < 1e-10);
    assert!(multipliers < accuracy, "{multipliers:e} > {accuracy:e}");
    assert_eq!(h1.branch, h2.branch);
    assert!((h1.lambda_i4 - h2.lambda_i4).abs() < 1e-10 * h1.lambda_i4.abs());
    for (x, y) in [
        (h1.lambda_2_plus, h2.lambda_2_plus),
        (h1.lambda_4_plus, h2.lambda_4_plus),
    ] {
        let (x, y) = (x.unwrap(), y.unwrap());
        assert!((x - y).abs() < 1e-10 * x.abs(), "{x} {y}");
    }
    assert!((h1.dls_duration - h2.dls_duration).abs() < 1e-10);
    assert!(h2.energy_residual.abs() < 1e-9, "{}", h2.energy_residual);
}

/// The compliant walk takes contact point 0 as the stance tip and 1 as the landing tip: a description that lists
/// its contacts in another order (and with a third) is read in the walk's order, the same walker.
#[test]
fn the_legs_contacts_are_put_first() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/models/telescopic.toml"
    ))
    .unwrap();
    let contacts = "[[contacts]]\nname = \"foot1\"\nbody = \"foot1\"\n\n[[contacts]]\nname = \"foot2\"\nbody = \"foot2\"\n";
    assert!(text.contains(contacts));
    let reordered = text.replace(
        contacts,
        "[[contacts]]\nname = \"knee\"\nbody = \"sleeve1\"\n\n[[contacts]]\nname = \"foot2\"\nbody = \"foot2\"\n\n\
         [[contacts]]\nname = \"foot1\"\nbody = \"foot1\"\n",
    );
    let AnyDescribed::N6(w) = parse("reordered.toml", &reordered).unwrap() else {
        panic!("6 coordinates")
    };
    let names: Vec<&str> = w
        .description
        .contacts
        .iter()
        .map(|c| c.name.as_str())
        .collect();
    assert_eq!(names, ["foot1", "foot2", "knee"]);
    let (q, qd) = (
        Q::from([0.1, 0.95, 0.3, -0.2, 0.98, 0.97]),
        Q::from([1.2, -0.3, -1.5, 0.8, -0.2, 0.1]),
    );
    assert!(difference(&Telescopic::default(), &w, &q, &qd) < RELATIVE);
}

/// The described walker's exact derivatives (its section differentiated implicitly from the contact conditions
/// with the fore leg at its stopper) are the built-in's: `DP` and `dP/dp` at the gait for a parameter of the
/// masses (`leg_mass`) and for the stoppers' length (which moves the section's held leg and the stopper events),
/// each to 1e-8; and the described gait's multipliers are the built-in's exact ones to 1e-9.
#[test]
fn the_described_telescopic_walker_has_the_built_in_derivatives() {
    use super::super::legged::derivative::LeggedDerivatives;
    use super::super::legged::gait::{legged_gait_exact, EXACT_ROUTE};
    let (built_in, described) = (Telescopic::default(), telescopic_toml());
    let options = LeggedOptions::default();
    let gait =
        legged_gait_exact::<_, 6, 13>(&built_in, &built_in.default_start(), &options).unwrap();
    for key in ["leg_mass", "stopper_length"] {
        let a = built_in
            .exact_step_map(&gait.section, Some(key), &options)
            .unwrap();
        let b = described
            .exact_step_map(&gait.section, Some(key), &options)
            .unwrap();
        let dp = max_diff(a.jacobian.iter(), b.jacobian.iter());
        let (pa, pb) = (a.dparam.unwrap(), b.dparam.unwrap());
        let dpdp = max_diff(pa.iter(), pb.iter());
        println!("{key}: DP {dp:e}, dP/dp {dpdp:e} (of {:e})", pa.amax());
        assert!(
            dp < 1e-8 && dpdp < 1e-8 * pa.amax().max(1.0),
            "{key}: {dp:e}, {dpdp:e}"
        );
    }
    let ours =
        legged_gait_exact::<_, 6, 13>(&described, &built_in.default_start(), &options).unwrap();
    assert_eq!(ours.derivative, EXACT_ROUTE);
    let multipliers = max_diff(
        gait.multipliers.iter().flatten(),
        ours.multipliers.iter().flatten(),
    );
    assert!(multipliers < 1e-9, "{multipliers:e}");
}
