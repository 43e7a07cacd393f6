//! The `vrw basin` command: its options and the summary it prints.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;

use vrw::app::{run_basin, BasinJob};
use vrw::study::basin::Coordinate;
use vrw::walk::SectionState;

use super::{interrupt_flag, parse_range, progress_bar, ModelArgs};

#[derive(Debug, Args)]
pub(super) struct BasinArgs {
    #[command(flatten)]
    params: ModelArgs,
    /// The walker: only `vrw`, the wheel, so far; another model (`simplest`, `compass`) is refused, naming the
    /// job (docs/model.md section 13).
    #[arg(long, default_value = "vrw")]
    model: String,
    /// Where the gait search starts, `L2,thetadot,L2dot` (with friction, `,slip` after them for a slipping stance
    /// tip); default as for simulate.
    #[arg(
        long,
        value_name = "L2,THETADOT,L2DOT[,SLIP]",
        allow_hyphen_values = true
    )]
    initial: Option<SectionState>,
    /// Horizontal coordinate of the slice: L2, thetadot or L2dot.
    #[arg(long, default_value = "L2")]
    x: Coordinate,
    /// Vertical coordinate of the slice (the third is held at the gait's value).
    #[arg(long, default_value = "thetadot")]
    y: Coordinate,
    /// Range of x, `A,B` (default: L2 from max(L0/2, min_length) to L0, thetadot from 0.05 to 3 times the
    /// gait's, L2dot the gait's +- 1.5 m/s).
    #[arg(long, value_name = "A,B", value_parser = parse_range, allow_hyphen_values = true)]
    x_range: Option<(f64, f64)>,
    /// Range of y, `A,B` (defaults as for --x-range).
    #[arg(long, value_name = "A,B", value_parser = parse_range, allow_hyphen_values = true)]
    y_range: Option<(f64, f64)>,
    /// Grid points along x.
    #[arg(long, default_value_t = 61)]
    nx: usize,
    /// Grid points along y.
    #[arg(long, default_value_t = 61)]
    ny: usize,
    /// Steps walked at most from each start.
    #[arg(long, default_value_t = 100)]
    max_steps: usize,
    /// A return this close to a gait state (largest coordinate difference) has reached the gait.
    #[arg(long, default_value_t = 1e-3)]
    tolerance: f64,
    /// Output directory for basin.csv, basin.json and basin.png.
    #[arg(long, default_value = "out/basin")]
    out: PathBuf,
    /// Replace a run of another vrw command in the output directory (its files are removed and listed);
    /// without it such a directory is refused. A directory with files vrw did not write is always refused.
    #[arg(long)]
    overwrite: bool,
}

/// Run `vrw basin` and print its summary.
pub(super) fn run(args: BasinArgs) -> Result<()> {
    vrw::app::wheel_only(&args.model, "basin")?;
    let job = BasinJob {
        config: args.params.load()?,
        initial: args.initial,
        coordinates: [args.x, args.y],
        ranges: [args.x_range, args.y_range],
        points: [args.nx, args.ny],
        max_steps: args.max_steps,
        tolerance: args.tolerance,
        out_dir: args.out.clone(),
        overwrite: args.overwrite,
    };
    // Ctrl-C stops the grid between points; what is complete is written.
    interrupt_flag();
    let bar = progress_bar(
        Some((args.nx * args.ny) as u64),
        "{bar:40} {pos}/{len} starts [{elapsed_precise}, eta {eta}]",
    );
    let started = std::time::Instant::now();
    super::check_out(&job.out_dir, "basin", job.overwrite)?;
    let summary = run_basin(&job, &|_| bar.inc(1)).context("basin")?;
    bar.finish_and_clear();
    let g = &summary.gait;
    println!(
        "vrw basin: {} x {} starts on the slice ({}, {}) through the {}gait at {}; {:.2} s ({:.2} s for the grid)",
        args.nx,
        args.ny,
        args.x.name(),
        args.y.name(),
        if g.period_k > 1 { format!("period-{} ", g.period_k) } else { String::new() },
        g.section.labelled(Some(6)),
        started.elapsed().as_secs_f64(),
        summary.seconds
    );
    for (kind, n) in &summary.outcomes {
        println!("  {kind:<20} {n}");
    }
    println!(
        "wrote {}/{{{}}}",
        args.out.display(),
        summary.files.join(", ")
    );
    Ok(())
}
