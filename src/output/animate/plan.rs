//! Frame planning: which simulated time each frame of the animation shows, and the slow-motion frames that
//! make a phase no regular frame falls into visible (the "Frame times" paragraph of the module doc).

use super::super::read::{RunData, TrajectoryRow};
use super::{AnimateError, AnimateOptions};
use crate::fmt::short;

/// Extra frames given to a phase that no regular frame falls into.
pub(crate) const SLOW_FRAMES: usize = 3;

/// A short phase shown in slow motion.
#[derive(Debug, Clone, PartialEq)]
pub struct SlowMotion {
    /// The phase, in words.
    pub phase: String,
    /// Its real duration \[s\].
    pub duration: f64,
    /// Frames it is shown in.
    pub frames: usize,
}

/// One planned frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameTime {
    /// Simulated time shown \[s\].
    pub time: f64,
    /// Set on frames added to show a short phase.
    pub slow: Option<SlowMotion>,
}

/// The most frames an animation has: an hour of playback at 25 frames per second. The regular frames number
/// `(to - from) fps / speed + 1` over the window `[from, to]` of simulated time.
pub const MAX_ANIMATION_FRAMES: usize = 90_000;

/// Refuses an animation of more than [`MAX_ANIMATION_FRAMES`] frames, counted before any is planned.
pub(super) fn check_frame_count(run: &RunData, opts: &AnimateOptions) -> Result<(), AnimateError> {
    let (start, end) = run.time_span();
    let from = opts.from.unwrap_or(start).max(start);
    let to = opts.to.unwrap_or(end).min(end);
    let frames = ((to - from).max(0.0) * f64::from(opts.fps) / opts.speed).floor() + 1.0;
    if frames > MAX_ANIMATION_FRAMES as f64 {
        return Err(AnimateError::InvalidOption {
            option: "speed",
            reason: format!(
                "{} s of simulated time at speed {} and {} frames per second is {} frames, more than \
                 {MAX_ANIMATION_FRAMES}: raise `speed`, lower `fps` or narrow the window with `from`/`to`",
                short(to - from),
                short(opts.speed),
                opts.fps,
                short(frames)
            ),
        });
    }
    Ok(())
}

/// The simulated window `[from, to]` of the animation, clipped to the samples.
pub(super) fn window(run: &RunData, opts: &AnimateOptions) -> Result<(f64, f64), AnimateError> {
    let (start, end) = run.time_span();
    let from = opts.from.unwrap_or(start).max(start);
    let to = opts.to.unwrap_or(end).min(end);
    if from > to || (from == to && start < end) {
        return Err(AnimateError::EmptyWindow {
            path: run.path("trajectory.csv"),
            from: opts.from.unwrap_or(start),
            to: opts.to.unwrap_or(end),
            start,
            end,
        });
    }
    Ok((from, to))
}

/// The frame times: regular frames every `speed / fps` of simulated time over `[from, to]`, plus
/// `SLOW_FRAMES` frames over every phase that no regular frame falls into (see the module doc).
pub fn plan_frames(
    samples: &[TrajectoryRow],
    (from, to): (f64, f64),
    fps: u32,
    speed: f64,
) -> Vec<FrameTime> {
    let h = speed / f64::from(fps);
    let count = ((to - from) / h * (1.0 + 1e-12)).floor() as usize + 1;
    let regular: Vec<f64> = (0..count).map(|k| from + k as f64 * h).collect();
    let mut frames: Vec<FrameTime> = regular
        .iter()
        .map(|&time| FrameTime { time, slow: None })
        .collect();
    // Phases: maximal runs of samples with the same discrete mode, each ending where the next begins.
    let first = samples
        .partition_point(|s| s.time <= from)
        .saturating_sub(1);
    let mut k = first;
    while k < samples.len() && samples[k].time <= to {
        let mode = samples[k].mode();
        let mut e = k + 1;
        while e < samples.len() && samples[e].mode() == mode {
            e += 1;
        }
        let a = samples[k].time.max(from);
        let b = samples.get(e).map_or(to, |s| s.time.min(to));
        let covered = regular
            .iter()
            .any(|&t| a <= t && (t < b || (t == b && b == to)));
        if !covered {
            let n = if b > a { SLOW_FRAMES } else { 1 };
            let slow = SlowMotion {
                phase: samples[k].phase_name(),
                duration: b - a,
                frames: n,
            };
            frames.extend((0..n).map(|m| FrameTime {
                time: a + (b - a) * m as f64 / n as f64,
                slow: Some(slow.clone()),
            }));
        }
        k = e;
    }
    frames.sort_by(|x, y| x.time.total_cmp(&y.time));
    frames
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// A sample at `time` with the given contacts and slides of Leg 2 (Leg 1 stuck, leg 0 is Leg 1).
    pub(crate) fn sample(time: f64, contact2: bool, slide2: bool) -> TrajectoryRow {
        TrajectoryRow {
            time,
            x: 0.0,
            z: 0.0,
            theta: -0.5 + 0.1 * time,
            l1: 0.9,
            l2: 0.8,
            theta_dot: 0.1,
            l1_dot: 0.0,
            l2_dot: 0.0,
            contact1: true,
            contact2,
            slide1: false,
            slide2,
            lock1: 0,
            lock2: u8::from(!contact2),
            lambda_1: 0.0,
            lambda_2: 1.0,
            lambda_3: 0.0,
            lambda_4: 1.0,
            leg1: 0,
            l3: 0.0,
        }
    }

    /// Samples every 0.005 s over [0, 1] s with a 0.03 s slide of Leg 2 starting at 0.405 s (between the
    /// frames at 0.40 and 0.44 s of 25 frames/s), then single support.
    fn with_short_slide() -> Vec<TrajectoryRow> {
        let mut out = Vec::new();
        for k in 0..=200 {
            let t = k as f64 * 0.005;
            if t > 0.405 && t < 0.4051 {
                out.push(sample(0.405, true, true));
            }
            let (contact2, slide2) = if t < 0.405 {
                (true, false)
            } else if t < 0.435 {
                (true, true)
            } else {
                (false, false)
            };
            if (t - 0.435).abs() < 1e-12 {
                out.push(sample(0.435, false, false));
                continue;
            }
            out.push(sample(t, contact2, slide2));
        }
        out
    }

    #[test]
    fn regular_frames_cover_the_window() {
        let samples = with_short_slide();
        let frames = plan_frames(&samples, (0.0, 1.0), 25, 1.0);
        let regular: Vec<&FrameTime> = frames.iter().filter(|f| f.slow.is_none()).collect();
        assert_eq!(regular.len(), 26, "0, 0.04, ..., 1.0");
        assert!(frames.windows(2).all(|w| w[0].time <= w[1].time));
    }

    #[test]
    fn short_slide_gets_slow_motion_frames() {
        let samples = with_short_slide();
        let frames = plan_frames(&samples, (0.0, 1.0), 25, 1.0);
        let slow: Vec<&FrameTime> = frames.iter().filter(|f| f.slow.is_some()).collect();
        assert_eq!(slow.len(), SLOW_FRAMES);
        for f in &slow {
            assert!((0.405..0.435).contains(&f.time), "{}", f.time);
            let s = f.slow.as_ref().unwrap();
            assert!(s.phase.contains("slides"), "{}", s.phase);
            assert!((s.duration - 0.03).abs() < 1e-12);
        }
        // The first slow frame is the event instant itself.
        assert_eq!(slow[0].time, 0.405);
    }

    #[test]
    fn slide_covered_by_a_regular_frame_is_not_slowed() {
        let samples = with_short_slide();
        // At 50 frames/s a frame falls at 0.42 s, inside the slide.
        let frames = plan_frames(&samples, (0.0, 1.0), 50, 1.0);
        assert!(frames.iter().all(|f| f.slow.is_none()));
    }
}
