//! The `vrw basin` command: its options and the summary it prints.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;

use vrw::app::{run_basin, run_walker_basin, BasinJob, SliceGrid, Walker, WalkerBasinJob};
use vrw::study::basin::Coordinate;

use super::{interrupt_flag, parse_range, progress_bar, ModelArgs};

#[derive(Debug, Args)]
pub(super) struct BasinArgs {
    #[command(flatten)]
    params: ModelArgs,
    /// The walker: `vrw` (default), `simplest` or `compass` (docs/model.md section 13): for the last two, the
    /// basin of the period-1 gait on a slice of two of its section's coordinates (--x, --y; the others held at
    /// the gait's values).
    #[arg(long, default_value = "vrw")]
    model: String,
    /// Where the gait search starts, `L2,thetadot,L2dot` (with friction, `,slip` after them for a slipping stance
    /// tip); default as for simulate. For another model its section's coordinates.
    #[arg(
        long,
        value_name = "L2,THETADOT,L2DOT[,SLIP]",
        allow_hyphen_values = true
    )]
    initial: Option<String>,
    /// Horizontal coordinate of the slice: L2, thetadot or L2dot [default: L2]; for another model one of its
    /// section's coordinates [default: its first].
    #[arg(long)]
    x: Option<String>,
    /// Vertical coordinate of the slice (the third is held at the gait's value) [default: thetadot]; for
    /// another model [default: its section's second coordinate].
    #[arg(long)]
    y: Option<String>,
    /// Range of x, `A,B` (default: L2 from max(L0/2, min_length) to L0, thetadot from 0.05 to 3 times the
    /// gait's, L2dot the gait's +- 1.5 m/s; for another model from 0 to twice the gait's value).
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

/// The grid and the walks' end the options give (every walker's).
fn slice_grid(args: &BasinArgs) -> SliceGrid {
    SliceGrid {
        ranges: [args.x_range, args.y_range],
        points: [args.nx, args.ny],
        max_steps: args.max_steps,
        tolerance: args.tolerance,
    }
}

/// Run `vrw basin` and print its summary.
pub(super) fn run(args: BasinArgs) -> Result<()> {
    let sets = &args.params.set;
    if let Some(walker) = Walker::load(&args.model, args.params.config.as_deref(), sets)? {
        return run_walker(&args, walker);
    }
    let coordinate = |flag: &str, given: &Option<String>, default: Coordinate| match given {
        Some(text) => text
            .parse::<Coordinate>()
            .map_err(|e| anyhow::anyhow!("invalid value for `{flag}`: {e}")),
        None => Ok(default),
    };
    let (x, y) = (
        coordinate("--x", &args.x, Coordinate::L2)?,
        coordinate("--y", &args.y, Coordinate::ThetaDot)?,
    );
    let job = BasinJob {
        config: args.params.load()?,
        initial: super::wheel_initial("basin", args.initial.as_deref()),
        coordinates: [x, y],
        grid: slice_grid(&args),
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
        x.name(),
        y.name(),
        if g.period_k > 1 { format!("period-{} ", g.period_k) } else { String::new() },
        g.section.labelled(Some(6)),
        started.elapsed().as_secs_f64(),
        summary.seconds
    );
    for (kind, n) in &summary.outcomes {
        println!("  {kind:<20} {n}");
    }
    super::print_parallelism(&summary.parallelism);
    println!(
        "wrote {}/{{{}}}",
        args.out.display(),
        summary.files.join(", ")
    );
    Ok(())
}

/// `vrw basin --model NAME` for a walker other than the wheel: the basin of its gait, its summary, its files.
fn run_walker(args: &BasinArgs, walker: Walker) -> Result<()> {
    let coordinates =
        WalkerBasinJob::slice_coordinates(&walker, [args.x.as_deref(), args.y.as_deref()])?;
    let job = WalkerBasinJob {
        coordinates,
        walker,
        initial: super::walker_initial(args.initial.as_deref())?,
        grid: slice_grid(args),
        out_dir: args.out.clone(),
        overwrite: args.overwrite,
    };
    interrupt_flag();
    let bar = progress_bar(
        Some(args.nx.saturating_mul(args.ny) as u64),
        "{bar:40} {pos}/{len} starts [{elapsed_precise}, eta {eta}]",
    );
    super::check_out(&job.out_dir, "basin", job.overwrite)?;
    let started = std::time::Instant::now();
    let s = run_walker_basin(&job, &|_| bar.inc(1)).context("basin")?;
    bar.finish_and_clear();
    let gait: Vec<String> = s
        .gait
        .section
        .iter()
        .map(|(n, v)| format!("{n} = {v:.9}"))
        .collect();
    println!(
        "vrw basin --model {}: {} x {} starts on the slice ({}, {}) through the gait at {}; {:.2} s",
        s.model,
        args.nx,
        args.ny,
        s.x.coordinate,
        s.y.coordinate,
        gait.join(", "),
        started.elapsed().as_secs_f64()
    );
    for (kind, n) in &s.outcomes {
        println!("  {kind:<24} {n}");
    }
    super::print_wrote(&args.out);
    Ok(())
}
