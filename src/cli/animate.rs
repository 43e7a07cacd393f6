//! The `vrw animate` command: its options and the summary it prints.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;

use vrw::app::{run_animate, run_still, AnimateJob};
use vrw::output::animate::AnimateOptions;

#[derive(Debug, Args)]
pub(super) struct AnimateArgs {
    /// Output directory of `vrw simulate` or `vrw gait` (walk.gif is written there).
    dir: PathBuf,
    /// Frames per second (at most 50).
    #[arg(long, default_value_t = AnimateOptions::default().fps)]
    fps: u32,
    /// Playback speed: simulated seconds per second of playback.
    #[arg(long, default_value_t = AnimateOptions::default().speed, allow_hyphen_values = true)]
    speed: f64,
    /// Start of the time window [s] (default: the start of the run).
    #[arg(long, allow_hyphen_values = true)]
    from: Option<f64>,
    /// End of the time window [s] (default: the end of the run).
    #[arg(long, allow_hyphen_values = true)]
    to: Option<f64>,
    /// Frame width [px].
    #[arg(long, default_value_t = AnimateOptions::default().width)]
    width: u32,
    /// Frame height [px].
    #[arg(long, default_value_t = AnimateOptions::default().height)]
    height: u32,
    /// Draw the slope horizontal instead of inclined.
    #[arg(long)]
    horizontal: bool,
    /// Instead of the GIF, write the single frame at this time [s] as DIR/walk-frame.png.
    #[arg(long, value_name = "TIME", allow_hyphen_values = true)]
    still: Option<f64>,
    /// Draw the complete rows of a run that did not finish (killed, or failed).
    #[arg(long)]
    partial: bool,
}

/// Run `vrw animate` and print its summary.
pub(super) fn run(args: AnimateArgs) -> Result<()> {
    super::interrupt_flag();
    let job = AnimateJob {
        dir: args.dir,
        options: AnimateOptions {
            fps: args.fps,
            speed: args.speed,
            from: args.from,
            to: args.to,
            width: args.width,
            height: args.height,
            horizontal: args.horizontal,
        },
        partial: args.partial,
    };
    if let Some(time) = args.still {
        let path = run_still(&job, time).context("animate")?;
        println!("wrote {}", path.display());
        return Ok(());
    }
    let started = std::time::Instant::now();
    let outcome = run_animate(&job).context("animate")?;
    for w in &outcome.warnings {
        eprintln!("warning: {w}");
    }
    let report = outcome.report;
    println!(
        "vrw animate: {} frames ({} in slow motion) of t = {:.3} .. {:.3} s, {:.1} s of playback, {:.2} MB in {:.2} s",
        report.frames,
        report.slow_frames,
        report.window.0,
        report.window.1,
        report.playback,
        report.bytes as f64 / 1e6,
        started.elapsed().as_secs_f64()
    );
    println!("wrote {}", report.path.display());
    Ok(())
}
