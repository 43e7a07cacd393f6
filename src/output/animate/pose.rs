//! The wheel's geometry at an instant: the trajectory interpolated by physical leg (hub, leg angle, leg
//! lengths), and what each leg shows in a frame (colour, tip state, stopper).

use plotters::style::RGBColor;

use super::super::read::{Geometry, TipState, TrajectoryRow};
use super::super::style::{COLOR_BLUE, COLOR_VERMILLION};

/// The wheel at one instant, by physical leg (so that re-indexing at a touchdown does not break the
/// interpolation between samples).
#[derive(Debug, Clone)]
pub(super) struct Pose {
    /// Hub position in the slope frame \[m\].
    pub(super) hub: (f64, f64),
    /// Angle `psi` of physical leg 0, unwrapped over the run \[rad\].
    pub(super) psi0: f64,
    /// Length of each physical leg \[m\].
    pub(super) lengths: Vec<f64>,
}

/// Per-sample data prepared once: the pose, and the unwrapped leg angle.
pub(super) struct Track<'a> {
    samples: &'a [TrajectoryRow],
    geometry: Geometry,
    psi0: Vec<f64>,
}

impl<'a> Track<'a> {
    pub(super) fn new(samples: &'a [TrajectoryRow], geometry: Geometry) -> Track<'a> {
        let alpha = geometry.alpha();
        let mut psi0 = Vec::with_capacity(samples.len());
        let mut prev: Option<f64> = None;
        for s in samples {
            // psi of physical leg p is theta + (p - leg1) alpha.
            let mut v = s.theta - s.leg1 as f64 * alpha;
            if let Some(p) = prev {
                v += std::f64::consts::TAU * ((p - v) / std::f64::consts::TAU).round();
            }
            psi0.push(v);
            prev = Some(v);
        }
        Track {
            samples,
            geometry,
            psi0,
        }
    }

    fn pose_of(&self, k: usize) -> Pose {
        let s = &self.samples[k];
        let n = self.geometry.legs;
        let mut lengths = vec![self.geometry.spoke_length; n];
        lengths[s.leg1 % n] = s.l1;
        lengths[(s.leg1 + 1) % n] = s.l2;
        // The swinging leg (rear_exit = continue), one behind Leg 2, while it swings.
        if s.l3 > 0.0 {
            lengths[(s.leg1 + 2) % n] = s.l3;
        }
        Pose {
            hub: (s.x + s.l1 * s.theta.sin(), s.z + s.l1 * s.theta.cos()),
            psi0: self.psi0[k],
            lengths,
        }
    }

    /// Index of the sample in force at `t` (the last at or before it; the first if `t` precedes all).
    pub(super) fn index_at(&self, t: f64) -> usize {
        self.samples
            .partition_point(|s| s.time <= t)
            .saturating_sub(1)
    }

    /// The pose at `t`, interpolated linearly between the samples around it.
    pub(super) fn pose_at(&self, t: f64) -> Pose {
        let k = self.index_at(t);
        let a = self.pose_of(k);
        let Some(next) = self.samples.get(k + 1) else {
            return a;
        };
        let t0 = self.samples[k].time;
        if next.time <= t0 || t <= t0 {
            return a;
        }
        let w = ((t - t0) / (next.time - t0)).clamp(0.0, 1.0);
        let b = self.pose_of(k + 1);
        let mix = |u: f64, v: f64| u + w * (v - u);
        Pose {
            hub: (mix(a.hub.0, b.hub.0), mix(a.hub.1, b.hub.1)),
            psi0: mix(a.psi0, b.psi0),
            lengths: a
                .lengths
                .iter()
                .zip(&b.lengths)
                .map(|(&u, &v)| mix(u, v))
                .collect(),
        }
    }
}

/// What the frame shows about one leg.
pub(super) struct LegState {
    /// Length \[m\].
    pub(super) length: f64,
    /// `Some((colour, tip state, stopper locked))` for Leg 1 and Leg 2.
    pub(super) compliant: Option<(RGBColor, TipState, bool)>,
}

/// What each physical leg shows at a frame: its length, and for Leg 1 and Leg 2 their colour, tip state and
/// stopper.
pub(super) fn leg_states(
    geometry: &Geometry,
    pose: &Pose,
    sample: &TrajectoryRow,
) -> Vec<LegState> {
    let n = geometry.legs;
    let [tip1, tip2] = sample.tips();
    pose.lengths
        .iter()
        .enumerate()
        .map(|(p, &length)| LegState {
            length,
            compliant: if p == sample.leg1 % n {
                Some((COLOR_BLUE, tip1, sample.lock1 != 0))
            } else if p == (sample.leg1 + 1) % n {
                Some((COLOR_VERMILLION, tip2, sample.lock2 != 0))
            } else {
                None
            },
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::plan::tests::sample;
    use super::*;

    #[test]
    fn pose_is_continuous_through_reindexing() {
        // A touchdown at 0.5 s: theta drops by alpha and Leg 1 moves to the previous physical leg; the wheel
        // itself does not move.
        let geometry = Geometry {
            legs: 8,
            stopper_length: 1.0,
            spring_natural_length: 1.02,
            leg_mass_offset: 0.3,
            slope: 0.1,
            viscosity: 50.0,
            rear_stopper: true,
            min_length: 0.0,
            spoke_length: 1.0,
        };
        let alpha = geometry.alpha();
        let before = TrajectoryRow {
            leg1: 0,
            theta: 0.3,
            ..sample(0.5, true, false)
        };
        let after = TrajectoryRow {
            leg1: 7,
            theta: 0.3 - alpha,
            ..sample(0.5, true, false)
        };
        let samples = [before, after];
        let track = Track::new(&samples, geometry);
        assert!((track.psi0[0] - track.psi0[1]).abs() < 1e-12);
    }
}
