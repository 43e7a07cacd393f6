//! Tests of described walkers: the shipped descriptions against the built-in compass gait and wheel, Lagrange's
//! equations from the energies, exact derivatives through dual numbers, and every refusal naming its line.

use nalgebra::{DVector, SVector};

use super::super::compass::Compass;
use super::super::rigid::{RigidOptions, RigidWalker};
use super::super::rigid_gait::{rigid_gait, JacobianRoute};
use super::super::{Equations, Mechanism, PointKinematics};
use super::{load, parse, AnyDescribed, Described};
use crate::dynamics::Model;
use crate::params::Params;

/// The shipped description `models/NAME.toml`.
pub(super) fn shipped(name: &str) -> AnyDescribed {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("models/{name}.toml"));
    load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// A reproducible stream of numbers in `[-1, 1)` (a linear congruential generator: the tests need no more).
pub(super) struct Stream(pub(super) u64);

impl Stream {
    pub(super) fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    pub(super) fn vector<const N: usize>(
        &mut self,
        scale: [f64; N],
        offset: [f64; N],
    ) -> SVector<f64, N> {
        SVector::from_fn(|i, _| offset[i] + scale[i] * self.next())
    }
}

/// The largest difference between two sets of numbers.
pub(super) fn max_diff<'a>(
    a: impl IntoIterator<Item = &'a f64>,
    b: impl IntoIterator<Item = &'a f64>,
) -> f64 {
    a.into_iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

/// The largest difference between two mechanisms' equations and points.
fn equations_diff<const N: usize>(a: &Equations<f64, N>, b: &Equations<f64, N>) -> f64 {
    max_diff(a.mass.iter(), b.mass.iter()).max(max_diff(a.bias.iter(), b.bias.iter()))
}

fn point_diff<const N: usize>(a: &PointKinematics<f64, N>, b: &PointKinematics<f64, N>) -> f64 {
    max_diff(a.position.iter(), b.position.iter())
        .max(max_diff(a.jacobian.iter(), b.jacobian.iter()))
        .max(max_diff(
            a.velocity_product.iter(),
            b.velocity_product.iter(),
        ))
}

fn compass_toml() -> Described<4> {
    match shipped("compass") {
        AnyDescribed::N4(w) => w,
        other => panic!(
            "compass.toml has 4 coordinates, not {:?}",
            other.description().coordinates
        ),
    }
}

/// `models/compass.toml` is the built-in compass gait: the same coordinates and parameters, and `M`, `h` and
/// the feet's kinematics equal at random states (and at a non-default parameter point).
#[test]
fn the_described_compass_is_the_built_in_one() {
    let described = compass_toml();
    assert_eq!(described.coordinates(), Compass::default().coordinates());
    let mut keys = super::super::rigid_family::Parametrized::parameter_keys(&Compass::default());
    keys.sort_unstable();
    let mut ours: Vec<&str> = described.parameters().iter().map(|(k, _)| *k).collect();
    ours.sort_unstable();
    assert_eq!(ours, keys);
    let other = Compass {
        hip_mass: 7.0,
        leg_mass_offset: 0.35,
        slope: 0.08,
        ..Compass::default()
    };
    let other_described = described
        .with_value("hip_mass", 7.0)
        .and_then(|w| w.with_value("leg_mass_offset", 0.35))
        .and_then(|w| w.with_value("slope", 0.08))
        .unwrap();
    let mut stream = Stream(7);
    let mut worst = 0.0f64;
    for (built_in, ours) in [(Compass::default(), &described), (other, &other_described)] {
        for _ in 0..200 {
            let q = stream.vector([0.5, 0.5, 0.6, 0.6], [0.0, 0.9, 0.0, 0.0]);
            let qd = stream.vector([2.0; 4], [0.0; 4]);
            let (cb, co) = (built_in.constants_f64(), ours.constants_f64());
            worst = worst.max(equations_diff(
                &built_in.equations(&cb, &q, &qd),
                &ours.equations(&co, &q, &qd),
            ));
            for i in 0..2 {
                worst = worst.max(point_diff(
                    &built_in.contact(&cb, &q, &qd, i),
                    &ours.contact(&co, &q, &qd, i),
                ));
            }
            worst = worst.max((built_in.potential_energy(&q) - ours.potential_energy(&q)).abs());
            worst = worst.max((built_in.energy(&q, &qd) - ours.energy(&q, &qd)).abs());
        }
    }
    println!("compass.toml against the built-in compass: max difference {worst:e}");
    assert!(worst < 1e-12, "{worst:e}");
}

/// The described compass walks the built-in's gait down 3 degrees: the same section, period and multipliers to
/// 1e-10 (the issue's done-means), and the same section state and step from a point off the gait.
#[test]
fn the_described_compass_walks_the_built_in_gait() {
    let described = compass_toml().with_value("slope", 0.0523598775598).unwrap();
    let built_in = Compass {
        slope: 0.0523598775598,
        ..Compass::default()
    };
    let s = DVector::from_column_slice(&[0.25, -1.0, -0.4]);
    let (a, b) = (
        built_in.state_at_section(&s),
        described.state_at_section(&s),
    );
    let state = max_diff(a.0.iter(), b.0.iter()).max(max_diff(a.1.iter(), b.1.iter()));
    assert!(state < 1e-15, "section state differs by {state:e}");
    let options = RigidOptions::default();
    let start = built_in.default_start();
    let (g1, g2) = (
        rigid_gait(&built_in, &start, &options).unwrap(),
        rigid_gait(&described, &start, &options).unwrap(),
    );
    let section = max_diff(g1.section.iter(), g2.section.iter());
    let period = (g1.step.period - g2.step.period).abs();
    let multipliers = max_diff(
        g1.multipliers.iter().flatten(),
        g2.multipliers.iter().flatten(),
    );
    println!("gait: section {section:e}, period {period:e}, multipliers {multipliers:e}");
    assert!(section < 1e-10 && period < 1e-10 && multipliers < 1e-10);
    assert_eq!(described.section_names(), built_in.section_names());
    assert!((g1.step.lambda_i4 - g2.step.lambda_i4).abs() < 1e-10);
}

/// The described compass's step map has the built-in's exact derivatives: `DP` and `dP/dp` in the slope, a mass
/// and the leg's length (which moves the section's state: the implicit differentiation of the contact
/// conditions), on the gait and off it, to 1e-10; its gait's multipliers are exact, not differences.
#[test]
fn the_described_compass_has_the_built_in_exact_derivatives() {
    let described = compass_toml().with_value("slope", 0.0523598775598).unwrap();
    let built_in = Compass {
        slope: 0.0523598775598,
        ..Compass::default()
    };
    let options = RigidOptions::default();
    let gait = rigid_gait(&described, &built_in.default_start(), &options).unwrap();
    assert_eq!(gait.derivative, JacobianRoute::Exact);
    let off = DVector::from_column_slice(&[0.25, -1.0, -0.4]);
    for x in [&gait.section, &off] {
        for key in ["slope", "hip_mass", "leg_length"] {
            let a = built_in
                .step_map_derivative(x, Some(key), 1, &options)
                .unwrap();
            let b = described
                .step_map_derivative(x, Some(key), 1, &options)
                .unwrap();
            let jacobian = max_diff(a.jacobian.iter(), b.jacobian.iter());
            let dparam = max_diff(
                a.dparam.as_ref().unwrap().iter(),
                b.dparam.as_ref().unwrap().iter(),
            );
            println!(
                "{key} at {:?}: DP {jacobian:e}, dP/dp {dparam:e}",
                x.as_slice()
            );
            assert!(
                jacobian < 1e-10 && dparam < 1e-10,
                "{key}: {jacobian:e}, {dparam:e}"
            );
        }
    }
}

/// The section's positions are solved by Newton's method from the guesses, not taken from them: a poor guess
/// of the swing leg's angle reaches the same state, and one that leads to the landing foot ahead is refused.
#[test]
fn the_section_state_is_solved_from_the_contact_conditions() {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/models/compass.toml"))
        .unwrap();
    let poor = text.replace(
        "guess = { theta2 = \"-theta1\" }",
        "guess = { theta2 = \"-0.5 * theta1 - 0.1\" }",
    );
    let wrong = text.replace(
        "guess = { theta2 = \"-theta1\" }",
        "guess = { theta2 = \"theta1 + 0.01\" }",
    );
    let s = DVector::from_column_slice(&[0.27, -1.09, -0.38]);
    let exact = compass_toml().section_state(&s).unwrap();
    let AnyDescribed::N4(poor) = parse("poor.toml", &poor).unwrap() else {
        panic!()
    };
    let solved = poor.section_state(&s).unwrap();
    let d =
        max_diff(exact.0.iter(), solved.0.iter()).max(max_diff(exact.1.iter(), solved.1.iter()));
    assert!(d < 1e-14, "{d:e}");
    let AnyDescribed::N4(wrong) = parse("wrong.toml", &wrong).unwrap() else {
        panic!()
    };
    let e = wrong.section_state(&s).unwrap_err().to_string();
    assert!(e.contains("not behind"), "{e}");
}

fn wheel_toml() -> Described<6> {
    match shipped("wheel") {
        AnyDescribed::N6(w) => w,
        other => panic!(
            "wheel.toml has 6 coordinates, not {:?}",
            other.description().coordinates
        ),
    }
}

/// The largest difference between the described wheel and the built-in one with `params` over random states
/// with a swinging leg (`L3` nonzero): `M`, `h`, the tips of Legs 1 and 2 (contacts 0, 1) and of the front
/// leg (contact 2), the energies (up to the wheel's constant, see below) and the damper power.
fn wheel_difference(described: &Described<6>, params: &Params) -> f64 {
    let model = Model::new(params).unwrap();
    let (cm, cd) = (model.constants_f64(), described.constants_f64());
    let mut stream = Stream(11);
    let mut worst = 0.0f64;
    for _ in 0..200 {
        let q = stream.vector(
            [0.3, 0.1, 0.4, 0.1, 0.1, 0.1],
            [0.0, 0.9, 0.0, 0.9, 0.9, 0.9],
        );
        let qd = stream.vector([1.0; 6], [0.0; 6]);
        worst = worst.max(equations_diff(
            &model.equations(&cm, &q, &qd),
            &described.equations(&cd, &q, &qd),
        ));
        for (ours, theirs) in [(0, 0), (1, 1), (2, model.front_leg())] {
            let tip = model.tip_with(&cm, &q, &qd, theirs);
            worst = worst.max(point_diff(&tip, &described.contact(&cd, &q, &qd, ours)));
        }
        // The wheel's V leaves out the swinging leg's spring energy at the spoke length, so that V is continuous
        // where the leg relocks as a spoke (`Model::potential_energy`): a constant.
        let relock =
            0.5 * params.stiffness * (params.spring_natural_length - params.stopper_length).powi(2);
        worst = worst.max((model.energy(&q, &qd) - (described.energy(&q, &qd) - relock)).abs());
        worst = worst.max(
            (Mechanism::damper_power(&model, &q, &qd) - described.damper_power(&q, &qd)).abs(),
        );
    }
    worst
}

/// `models/wheel.toml` is the built-in wheel (8 legs, a swinging leg), at its defaults and with parameters set
/// as `--set` sets them.
#[test]
fn the_described_wheel_is_the_built_in_one() {
    let described = wheel_toml();
    assert_eq!(
        described.coordinates(),
        ["x", "z", "theta", "L1", "L2", "L3"]
    );
    let params = Params {
        hub_inertia: 0.0,
        ..Params::default()
    };
    let at_defaults = wheel_difference(&described, &params);
    let set = [
        ("hub_inertia", 0.3),
        ("stiffness", 800.0),
        ("leg_mass_offset", 0.25),
        ("slope", 0.05),
        ("spring_natural_length", 1.05),
        ("viscosity", 20.0),
    ];
    let mut changed = described.clone();
    let mut config = crate::params::Config::default();
    for (key, value) in set {
        changed = changed.with_value(key, value).unwrap();
        config.set_numeric(key, value).unwrap();
    }
    let at_set = wheel_difference(&changed, &config.params);
    println!("wheel.toml against the built-in wheel: {at_defaults:e} at the defaults, {at_set:e} with --set");
    assert!(at_defaults < 1e-12 && at_set < 1e-12);
}

/// A floating pendulum with a telescopic arm (5 coordinates): a base sliding in `x` and `z`, a mount held at a
/// fixed angle, an arm turning (`phi`, relative to the mount) and extending (`r`, along a slanted direction) with
/// a spring (`k = 40`, rest 0.8) and a damper (0.7), and a flag turning by an absolute angle (`psi`) from the
/// bob; rigid bodies with inertias and centres off their frames' origins.
pub(super) const PENDULUM: &str = r#"
name = "pendulum"
[parameters]
m = 1.3
k = 40
slope = 0.2
gravity = 9.81
[[bodies]]
name = "base"
mass = 2
[[bodies]]
name = "cart"
mass = 0.5
inertia = 0.1
centre = [0.1, 0.05]
[[bodies]]
name = "mount"
mass = 0.3
inertia = 0.05
centre = [0.1, 0.05]
[[bodies]]
name = "arm"
mass = 0.4
inertia = 0.02
centre = [0, -0.2]
[[bodies]]
name = "bob"
mass = "m"
inertia = "m / 10"
centre = [0.05, -0.1]
[[bodies]]
name = "flag"
mass = 0.2
inertia = 0.01
centre = [0.15, 0]
[[joints]]
name = "x"
kind = "prismatic"
parent = "ground"
child = "base"
direction = [1, 0]
[[joints]]
name = "z"
kind = "prismatic"
parent = "base"
child = "cart"
direction = [0, 1]
[[joints]]
name = "tilt"
kind = "revolute"
parent = "cart"
child = "mount"
at = [0.2, 0.1]
fixed = 0.3
[[joints]]
name = "phi"
kind = "revolute"
parent = "mount"
child = "arm"
at = [0, -0.1]
[[joints]]
name = "r"
kind = "prismatic"
parent = "arm"
child = "bob"
at = [0.05, -0.3]
direction = [0.6, -0.8]
spring = { stiffness = "k", rest = 0.8 }
damper = { coefficient = 0.7 }
stoppers = { lower = 0.2, upper = 1.5 }
[[joints]]
name = "psi"
kind = "revolute"
parent = "bob"
child = "flag"
at = [0.1, 0]
angle = "absolute"
clockwise = true
[[contacts]]
name = "tip"
body = "flag"
at = [0.3, 0]
"#;

fn pendulum() -> Described<5> {
    match parse("pendulum.toml", PENDULUM).unwrap() {
        AnyDescribed::N5(w) => w,
        _ => panic!("the pendulum has 5 coordinates"),
    }
}

type Q5 = SVector<f64, 5>;

fn unit5(k: usize) -> Q5 {
    Q5::from_fn(|i, _| f64::from(u8::from(i == k)))
}

/// `M` is the Hessian of `T` in `q'` with `T` from the bodies themselves (`1/2 m |v_c|^2 + 1/2 I w^2`, the
/// velocities by finite differences of the positions and angles), and `h` is Lagrange's
/// `dM/dt q' - dT/dq + dV/dq + c q'` from finite differences of the energies, for a walker with revolute
/// (relative, absolute, fixed) and prismatic joints, a spring and a damper.
#[test]
fn the_equations_are_lagranges_from_the_energies() {
    let w = pendulum();
    let q = Q5::from([0.1, 0.9, 0.4, 0.7, -0.3]);
    let qd = Q5::from([0.3, -0.2, 1.1, -0.6, 0.8]);
    let c = w.constants_f64();
    let e = w.equations(&c, &q, &qd);
    // T from the frames: positions and angles at q +- h q', central differences.
    let h = 1e-6;
    let bodies_t = |q: &Q5, qd: &Q5| {
        let d = &w.description;
        let at = |s: f64| super::kinematics::frames(d, &c, &(q + s * qd), &Q5::zeros());
        let (plus, minus) = (at(h), at(-h));
        d.bodies
            .iter()
            .enumerate()
            .map(|(b, body)| {
                let centre = c.vector(&body.centre);
                let v =
                    (plus[b].point(centre).position - minus[b].point(centre).position) / (2.0 * h);
                let rate = (plus[b].angle - minus[b].angle) / (2.0 * h);
                0.5 * c.of(&body.mass) * v.norm_squared() + 0.5 * c.of(&body.inertia) * rate * rate
            })
            .sum::<f64>()
    };
    let t_direct = bodies_t(&q, &qd);
    assert!(
        (t_direct - w.kinetic_energy(&q, &qd)).abs() < 1e-8,
        "{t_direct} vs {}",
        w.kinetic_energy(&q, &qd)
    );
    for i in 0..5 {
        for j in 0..5 {
            let t = |a: f64, b: f64| w.kinetic_energy(&q, &(a * unit5(i) + b * unit5(j)));
            let fd = (t(1.0, 1.0) - t(1.0, -1.0) - t(-1.0, 1.0) + t(-1.0, -1.0)) / 4.0;
            assert!(
                (e.mass[(i, j)] - fd).abs() < 1e-12,
                "M[{i},{j}] {} vs {fd}",
                e.mass[(i, j)]
            );
        }
    }
    let h = 1e-5;
    let m_at = |s: f64| w.equations(&c, &(q + s * qd), &qd).mass;
    let mut expected = (m_at(h) - m_at(-h)) / (2.0 * h) * qd;
    for k in 0..5 {
        let dq = unit5(k) * h;
        let dt = (w.kinetic_energy(&(q + dq), &qd) - w.kinetic_energy(&(q - dq), &qd)) / (2.0 * h);
        let dv = (w.potential_energy(&(q + dq)) - w.potential_energy(&(q - dq))) / (2.0 * h);
        expected[k] += -dt + dv;
    }
    expected[3] += 0.7 * qd[3];
    let d = max_diff(e.bias.iter(), expected.iter());
    assert!(d < 1e-7, "h {} vs {expected}: {d:e}", e.bias);
    assert!((w.damper_power(&q, &qd) - 0.7 * qd[3] * qd[3]).abs() < 1e-15);
    // The spring's energy is in V: 1/2 k (r - rest)^2.
    let slack = w.with_value("k", 0.0).unwrap();
    let spring = 0.5 * 40.0 * (q[3] - 0.8) * (q[3] - 0.8);
    assert!((w.potential_energy(&q) - slack.potential_energy(&q) - spring).abs() < 1e-12);
    // The contact point's Jacobian and velocity product are those of its position.
    let tip = w.contact(&c, &q, &qd, 0);
    for k in 0..5 {
        let p = |s: f64| w.contact(&c, &(q + s * unit5(k)), &qd, 0).position;
        let fd = (p(h) - p(-h)) / (2.0 * h);
        assert!((tip.jacobian.column(k) - fd).amax() < 1e-9, "J column {k}");
    }
    let jq = |s: f64| w.contact(&c, &(q + s * qd), &qd, 0).jacobian * qd;
    assert!(((jq(h) - jq(-h)) / (2.0 * h) - tip.velocity_product).amax() < 1e-8);
}

/// The equations over dual numbers carry their exact derivative in a parameter: `d(M q'' + h)/dp` for the
/// bob's mass `m` and the spring's `k`, and for the slope, equals central differences.
#[test]
fn the_equations_differentiate_exactly_in_a_parameter() {
    use crate::variational::Dual;
    let w = pendulum();
    let q = Q5::from([0.1, 0.9, 0.4, 0.7, -0.3]);
    let qd = Q5::from([0.3, -0.2, 1.1, -0.6, 0.8]);
    let qdd = Q5::from([0.5, 0.1, -0.7, 0.2, 1.3]);
    let seed = |on: bool, x: f64| Dual::<1>::new(x, SVector::from([f64::from(u8::from(on))]));
    let lift = |x: &Q5| x.map(|v| seed(false, v));
    let residual = |e: Equations<f64, 5>| e.mass * qdd + e.bias;
    for key in ["m", "k", "slope"] {
        let c = w.constants(&|k, v| seed(k == key, v));
        let dual = w.equations(&c, &lift(&q), &lift(&qd));
        let exact = dual.mass * lift(&qdd) + dual.bias;
        let h = 1e-6;
        let at = |v: f64| {
            let shifted = w.with_value(key, v).unwrap();
            residual(shifted.equations(&shifted.constants_f64(), &q, &qd))
        };
        let value = w.value(key).unwrap();
        let fd = (at(value + h) - at(value - h)) / (2.0 * h);
        for k in 0..5 {
            let e = exact[k].eps[0];
            assert!(
                (e - fd[k]).abs() < 1e-7 * (1.0 + fd[k].abs()),
                "{key}, row {k}: {e} vs {}",
                fd[k]
            );
        }
        assert!(
            exact.iter().any(|d| d.eps[0].abs() > 1e-3),
            "{key}: a derivative that is not 0"
        );
    }
}

/// The wheel's description, three telescopic legs and no `[gait]` table, cannot walk through a description
/// and says why: the compliant walk takes two legs that take turns, and the wheel walks built in.
#[test]
fn the_wheel_says_why_it_cannot_walk() {
    let wheel = shipped("wheel");
    let e = wheel.walkable().unwrap_err().to_string();
    for needle in [
        "its joints L1, L2, L3 have stoppers (3 telescopic legs)",
        "takes two legs that take turns",
        "`--model vrw`",
    ] {
        assert!(e.contains(needle), "{e}");
    }
    assert!(!wheel.walks_compliant());
    assert!(shipped("compass").walkable().is_ok());
    let telescopic = shipped("telescopic");
    assert!(telescopic.walks_compliant());
    let e = telescopic.walkable().unwrap_err().to_string();
    assert!(e.contains("walks by the compliant walk"), "{e}");
    let free: Vec<usize> = wheel
        .description()
        .free_joints()
        .filter(|(_, f)| f.stoppers.iter().all(Option::is_some))
        .map(|(_, f)| f.coordinate)
        .collect();
    assert_eq!(free, [3, 4, 5]);
}
