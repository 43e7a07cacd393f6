//! Tests of the exact derivatives of the rigid walkers' step maps (`rigid_derivative`, `sensitivity`): against
//! a reference problem with closed-form derivatives, against Richardson-extrapolated central differences at two
//! slopes of each walker, the replay's state against the walk's bit for bit, and the typed refusals where the
//! map has no derivative.

use nalgebra::{DVector, SMatrix, SVector};

use super::compass::Compass;
use super::constrained::ConstrainedError;
use super::derivative_check::check_rigid_derivatives;
use super::rigid::{rigid_step_taped, RigidOptions, RigidTape, RigidWalker};
use super::rigid_derivative::DerivativeError;
use super::rigid_gait::{difference_jacobian, multipliers, rigid_gait, JacobianRoute};
use super::sensitivity::{replay, Hybrid, NotDifferentiable, Sensitivity, Tape};
use super::simplest::Simplest;
use super::Real;
use crate::integrate::{locate_root, Dop853, Method, OdeSystem, Tolerances};

/// The largest difference allowed between the exact derivatives and the Richardson-extrapolated differences
/// (whose own error, truncation and integration noise at `rtol = 1e-12`, is near 1e-10).
const AGREEMENT: f64 = 1e-9;

/// A gait of `walker` from `start`, its derivatives exact.
fn gait<W: RigidWalker<N, Y>, const N: usize, const Y: usize>(
    walker: &W,
    start: &[f64],
) -> DVector<f64> {
    let g = rigid_gait(
        walker,
        &DVector::from_column_slice(start),
        &RigidOptions::default(),
    )
    .unwrap();
    assert_eq!(g.derivative, JacobianRoute::Exact);
    g.section
}

/// `DP` and `dP/dp` (slope, and for the compass gait the hip mass) of both walkers at two slopes each equal
/// Richardson-extrapolated central differences (at the best of relative steps 1e-3 to 1e-5) within their error
/// estimates and to
/// [`AGREEMENT`].
#[test]
fn exact_derivatives_equal_extrapolated_differences() {
    let options = RigidOptions::default();
    for slope in [0.009, 0.014] {
        let walker = Simplest { slope };
        let s = gait(&walker, &[0.2, -0.2]);
        let check = check_rigid_derivatives(&walker, &s, Some("slope"), &options).unwrap();
        println!(
            "simplest at {slope}: difference {:.1e}, errors {:.1e} / {:.1e}",
            check.difference, check.exact_error, check.finite_difference_error
        );
        assert!(check.agree && check.difference < AGREEMENT, "{check:?}");
    }
    for (slope, key) in [
        (0.0523598775598, "slope"),
        (0.07, "hip_mass"),
        (0.07, "leg_length"),
    ] {
        let walker = Compass {
            slope,
            ..Compass::default()
        };
        let s = gait(&walker, walker.default_start().as_slice());
        let check = check_rigid_derivatives(&walker, &s, Some(key), &options).unwrap();
        println!(
            "compass at {slope} in {key}: difference {:.1e}, errors {:.1e} / {:.1e}",
            check.difference, check.exact_error, check.finite_difference_error
        );
        assert!(check.agree && check.difference < AGREEMENT, "{check:?}");
    }
}

/// The multipliers of the exact `DP` equal those of the central differences of the gait search (relative step
/// 1e-6) to the differences' accuracy (1e-7), at both walkers' published gaits.
#[test]
fn exact_multipliers_equal_the_differences_ones() {
    let options = RigidOptions::default();
    let simplest = Simplest { slope: 0.009 };
    let compass = Compass::default();
    let cases: [(&str, DVector<f64>, DVector<f64>); 2] = [
        {
            let s = gait(&simplest, &[0.2, -0.2]);
            let exact = simplest
                .step_map_derivative(&s, None, 1, &options)
                .unwrap()
                .jacobian;
            let fd = difference_jacobian(&simplest, &s, &options).unwrap();
            ("simplest", moduli(&exact), moduli(&fd))
        },
        {
            let s = gait(&compass, compass.default_start().as_slice());
            let exact = compass
                .step_map_derivative(&s, None, 1, &options)
                .unwrap()
                .jacobian;
            let fd = difference_jacobian(&compass, &s, &options).unwrap();
            ("compass", moduli(&exact), moduli(&fd))
        },
    ];
    for (name, exact, fd) in cases {
        println!("{name}: exact {exact:?}, differences {fd:?}");
        assert!((&exact - &fd).amax() < 1e-7, "{name}: {exact} vs {fd}");
    }
}

/// The multipliers' real and imaginary parts, in order.
fn moduli(jacobian: &nalgebra::DMatrix<f64>) -> DVector<f64> {
    DVector::from_iterator(
        2 * jacobian.nrows(),
        multipliers(jacobian).into_iter().flatten(),
    )
}

/// The replay takes the walk's integrator steps with the walk's arithmetic: its state at the heel strike is
/// the walk's bit for bit, and a record whose state is off by one unit in the last place is refused as
/// diverged.
#[test]
fn the_replays_state_is_the_walks_bit_for_bit() {
    let compass = Compass::default();
    let s = gait(&compass, compass.default_start().as_slice());
    let (q, qd) = compass.state_at_section(&s);
    let mut tape = RigidTape::<8>::new(Method::Dop853);
    rigid_step_taped(&compass, (&q, &qd), &RigidOptions::default(), &mut tape).unwrap();
    assert!(compass
        .step_map_derivative(&s, None, 1, &RigidOptions::default())
        .is_ok());
    let end = tape.segments[0].end.as_mut().unwrap();
    end.y[2] = f64::from_bits(end.y[2].to_bits() + 1);
    let walk = ReplayOf(&compass);
    let s0 = Sensitivity::<8, 4>::zeros();
    let replayed = replay::<_, 4, 8, 4, 5, 40>(&walk, None, &tape, &s0);
    assert!(
        matches!(replayed, Err(NotDifferentiable::Diverged { .. })),
        "{replayed:?}"
    );
}

/// The compass gait as a hybrid system, for the test above (the library's adapter is private).
struct ReplayOf<'a>(&'a Compass);

impl Hybrid<4> for ReplayOf<'_> {
    type Constants<T: Real> = super::compass::CompassConstants<T>;
    type Phase = super::rigid::SingleSupportPhase;
    type Event = super::rigid::HeelStrikeEvent;

    fn hybrid_constants<T: Real>(
        &self,
        value: &dyn Fn(&'static str, f64) -> T,
    ) -> Self::Constants<T> {
        self.0.rigid_constants(value)
    }

    fn acceleration<T: Real>(
        &self,
        c: &Self::Constants<T>,
        _: Self::Phase,
        (q, qd): (&SVector<T, 4>, &SVector<T, 4>),
    ) -> Result<SVector<T, 4>, ConstrainedError> {
        Ok(self.0.single_support_with(c, q, qd)?.0)
    }

    fn guard<T: Real>(
        &self,
        c: &Self::Constants<T>,
        _: (Self::Phase, Self::Event),
        (q, _): (&SVector<T, 4>, &SVector<T, 4>),
    ) -> Result<T, ConstrainedError> {
        Ok(self.0.swing_foot_with(c, q).0)
    }

    fn reset<T: Real>(
        &self,
        c: &Self::Constants<T>,
        _: Self::Event,
        (q, qd): (&SVector<T, 4>, &SVector<T, 4>),
    ) -> Result<(SVector<T, 4>, SVector<T, 4>), ConstrainedError> {
        let t = self.0.transition_with(c, q, qd)?;
        Ok((t.q, t.qd))
    }
}

/// A reference problem with closed-form derivatives: a ball falling under `gravity` from height `z0` with
/// velocity `v0`, bouncing with restitution `restitution` (`v+ = -e v-`) on a floor at height `floor`, as a
/// hybrid system; the event is the floor (`z - floor = 0`), or, for the grazing test, the apex height
/// `z_apex - z` (`apex` set).
struct Ball {
    gravity: f64,
    restitution: f64,
    floor: f64,
    apex: Option<f64>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Flight;

#[derive(Debug, Clone, Copy, PartialEq)]
struct Bounce;

#[derive(Clone, Copy)]
struct BallConstants<T: Real> {
    gravity: T,
    restitution: T,
    floor: T,
}

impl Hybrid<1> for Ball {
    type Constants<T: Real> = BallConstants<T>;
    type Phase = Flight;
    type Event = Bounce;

    fn hybrid_constants<T: Real>(
        &self,
        value: &dyn Fn(&'static str, f64) -> T,
    ) -> BallConstants<T> {
        BallConstants {
            gravity: value("gravity", self.gravity),
            restitution: value("restitution", self.restitution),
            floor: value("floor", self.floor),
        }
    }

    fn acceleration<T: Real>(
        &self,
        c: &BallConstants<T>,
        _: Flight,
        _: (&SVector<T, 1>, &SVector<T, 1>),
    ) -> Result<SVector<T, 1>, ConstrainedError> {
        Ok(SVector::from([-c.gravity]))
    }

    fn guard<T: Real>(
        &self,
        c: &BallConstants<T>,
        _: (Flight, Bounce),
        (q, _): (&SVector<T, 1>, &SVector<T, 1>),
    ) -> Result<T, ConstrainedError> {
        Ok(match self.apex {
            Some(top) => T::lit(top) - q[0],
            None => q[0] - c.floor,
        })
    }

    fn reset<T: Real>(
        &self,
        c: &BallConstants<T>,
        _: Bounce,
        (q, qd): (&SVector<T, 1>, &SVector<T, 1>),
    ) -> Result<(SVector<T, 1>, SVector<T, 1>), ConstrainedError> {
        Ok((*q, SVector::from([-(c.restitution * qd[0])])))
    }
}

impl OdeSystem<2> for Ball {
    fn rhs(&self, _t: f64, y: &SVector<f64, 2>) -> SVector<f64, 2> {
        SVector::from([y[1], -self.gravity])
    }
}

/// The ball walked from `(z0, v0)` to its event (located on the dense output, as the rigid walk does), recorded.
fn walk_ball(ball: &Ball, z0: f64, v0: f64, event_time: Option<f64>) -> Tape<Flight, Bounce, 2> {
    let tolerances = Tolerances {
        rtol: 1e-12,
        atol: 1e-13,
        h_max: 0.05,
        h_min: 1e-14,
    };
    let y0 = SVector::from([z0, v0]);
    let mut integrator = Dop853::new(ball, 0.0, y0, tolerances);
    let mut tape = Tape::new(Method::Dop853);
    tape.begin(Flight, 0.0, y0);
    loop {
        let step = integrator.step(ball, 10.0).unwrap();
        tape.step(step.h(), step.t1());
        let t = match event_time {
            Some(t) if t <= step.t1() => t,
            Some(_) => continue,
            None if step.y1()[0] > ball.floor => continue,
            None => {
                let g = |y: &SVector<f64, 2>| y[0] - ball.floor;
                let (g0, g1) = (g(step.y0()), g(step.y1()));
                locate_root(&step, |_, y| g(y), step.t0(), g0, step.t1(), g1, 1e-14)
            }
        };
        tape.end(t, Bounce, step.eval(t));
        return tape;
    }
}

/// The ball's bounce on the floor `f`: with `w = sqrt(v0^2 + 2 g (z0 - f))`, `t* = (v0 + w) / g`,
/// `v+ = e w`, `z+ = f`; the replay's `d(z+, v+)/d(z0, v0, p)` and `dt*/d(z0, v0, p)` equal the closed form to
/// 1e-10, for the parameter `p` the gravity (in the flow) and the floor (in the guard).
#[test]
fn the_replay_differentiates_a_bouncing_ball_exactly() {
    let (g, e, f, z0, v0) = (9.81, 0.8, 0.2, 1.3, 0.7);
    let ball = Ball {
        gravity: g,
        restitution: e,
        floor: f,
        apex: None,
    };
    let tape = walk_ball(&ball, z0, v0, None);
    let w = (v0 * v0 + 2.0 * g * (z0 - f)).sqrt();
    let t = (v0 + w) / g;
    for (param, dw_dp, dz_dp) in [("gravity", (z0 - f) / w, 0.0), ("floor", -g / w, 1.0)] {
        // Directions (z0, v0, p).
        let s0 = SMatrix::<f64, 2, 3>::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0);
        let r = replay::<_, 1, 2, 3, 4, 8>(&ball, Some(param), &tape, &s0).unwrap();
        let dw = [g / w, v0 / w, dw_dp];
        let dg = f64::from(param == "gravity");
        let dt = [dw[0] / g, (1.0 + dw[1]) / g, dw[2] / g - dg * t / g];
        let dz = [0.0, 0.0, dz_dp];
        for k in 0..3 {
            let (z, v) = (r.sensitivity[(0, k)], r.sensitivity[(1, k)]);
            assert!(
                (z - dz[k]).abs() < 1e-10,
                "{param}: dz+/d{k}: {z} vs {}",
                dz[k]
            );
            assert!(
                (v - e * dw[k]).abs() < 1e-10,
                "{param}: dv+/d{k}: {v} vs {}",
                e * dw[k]
            );
            assert!(
                (r.duration[k] - dt[k]).abs() < 1e-10,
                "{param}: dt/d{k}: {} vs {}",
                r.duration[k],
                dt[k]
            );
        }
    }
}

/// An event at the ball's apex (`z_apex - z`, touched tangentially) is grazing: the replay refuses it with a
/// typed error instead of a derivative; and a parameter that is not the walker's is refused by name.
#[test]
fn grazing_events_and_unknown_parameters_are_refused() {
    let (g, z0, v0) = (9.81, 1.0, 2.0);
    let ball = Ball {
        gravity: g,
        restitution: 0.8,
        floor: 0.0,
        apex: Some(z0 + v0 * v0 / (2.0 * g)),
    };
    let tape = walk_ball(&ball, z0, v0, Some(v0 / g));
    let s0 = SMatrix::<f64, 2, 3>::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0);
    let r = replay::<_, 1, 2, 3, 4, 8>(&ball, None, &tape, &s0);
    assert!(matches!(r, Err(NotDifferentiable::Grazing { .. })), "{r:?}");
    let walker = Simplest { slope: 0.009 };
    let s = gait(&walker, &[0.2, -0.2]);
    let e = walker.step_map_derivative(&s, Some("hip_mass"), 1, &RigidOptions::default());
    assert!(
        matches!(e, Err(DerivativeError::UnknownParameter { .. })),
        "{e:?}"
    );
}
