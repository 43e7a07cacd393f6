//! The `vrw orbit` command: its options and the summary it prints.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;

use vrw::app::{run_orbit, run_walker_orbit, OrbitJob, Walker, WalkerOrbitJob, WalkerRange};
use vrw::study::orbit::OrbitSpec;
use vrw::study::SweepSpec;

use super::{interrupt_flag, progress_bar, ModelArgs};

#[derive(Debug, Args)]
pub(super) struct OrbitArgs {
    #[command(flatten)]
    params: ModelArgs,
    /// The walker: `vrw` (default), `simplest`, `compass` or `telescopic` (docs/model.md section 13): for all
    /// but the wheel the
    /// diagram draws the section's first coordinate (the stance angle) and lambda_I4 along `--param`.
    #[arg(long, default_value = "vrw")]
    model: String,
    /// The parameter along the diagram: one of the real-valued keys (as for sweep).
    #[arg(long, default_value = "viscosity")]
    param: String,
    /// First value.
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    from: f64,
    /// Last value.
    #[arg(long, default_value_t = 150.0, allow_hyphen_values = true)]
    to: f64,
    /// Number of values (ends included).
    #[arg(long, default_value_t = 300)]
    points: usize,
    /// Steps walked at each value before recording (4 times as many where a walk starts afresh).
    #[arg(long, default_value_t = 32)]
    transient: usize,
    /// Steps recorded at each value.
    #[arg(long, default_value_t = 64)]
    steps: usize,
    /// Where the first walk starts, `L2,thetadot,L2dot` (with friction, `,slip` after them for a slipping stance
    /// tip); default as for simulate. For another model its section's coordinates.
    #[arg(
        long,
        value_name = "L2,THETADOT,L2DOT[,SLIP]",
        allow_hyphen_values = true
    )]
    initial: Option<String>,
    /// Do not compute and draw the period-1 branch.
    #[arg(long)]
    no_branch: bool,
    /// The DLS indicator the second panel draws.
    #[arg(long, default_value = "lambda_I4", value_parser = vrw::app::ORBIT_QUANTITIES)]
    plot: String,
    /// Output directory for orbit.csv, branch.csv, orbit.json and orbit.png.
    #[arg(long, default_value = "out/orbit")]
    out: PathBuf,
    /// Replace a run of another vrw command in the output directory (its files are removed and listed);
    /// without it such a directory is refused. A directory with files vrw did not write is always refused.
    #[arg(long)]
    overwrite: bool,
}

/// Run `vrw orbit` and print its summary.
pub(super) fn run(args: OrbitArgs) -> Result<()> {
    let sets = &args.params.set;
    if let Some(walker) = Walker::load(&args.model, args.params.config.as_deref(), sets)? {
        return run_walker(&args, walker);
    }
    let initial = super::wheel_initial("orbit", args.initial.as_deref());
    let job = OrbitJob {
        config: args.params.load()?,
        spec: OrbitSpec {
            range: SweepSpec {
                param: args.param.clone(),
                from: args.from,
                to: args.to,
                points: args.points,
            },
            transient: args.transient,
            steps: args.steps,
        },
        initial,
        branch: !args.no_branch,
        plot: args.plot.clone(),
        out_dir: args.out.clone(),
        overwrite: args.overwrite,
    };
    // Ctrl-C stops the grid between points; what is complete is written.
    interrupt_flag();
    let bar = progress_bar(
        Some(args.points as u64),
        "{bar:40} {pos}/{len} {msg} [{elapsed_precise}]",
    );
    let started = std::time::Instant::now();
    super::check_out(&job.out_dir, "orbit", job.overwrite)?;
    let summary = run_orbit(&job, &|c| {
        bar.set_message(format!("{} = {:.4}: {}", args.param, c.value, c.status));
        bar.inc(1);
    })
    .context("orbit")?;
    bar.finish_and_clear();
    let outcomes: Vec<String> = summary
        .outcomes
        .iter()
        .map(|(k, n)| format!("{k} {n}"))
        .collect();
    println!(
        "vrw orbit: {} from {} to {} ({} values, {} + {} steps each): {}; {:.2} s (diagram {:.2} s, branch {:.2} s)",
        args.param,
        args.from,
        args.to,
        args.points,
        args.transient,
        args.steps,
        outcomes.join(", "),
        started.elapsed().as_secs_f64(),
        summary.seconds[0],
        summary.seconds[1]
    );
    super::print_parallelism(&summary.parallelism);
    if !args.no_branch {
        println!(
            "period-1 branch: a gait at {} values, stable at {}",
            summary.branch_gaits[0], summary.branch_gaits[1]
        );
    }
    println!(
        "wrote {}/{{{}}}",
        args.out.display(),
        summary.files.join(", ")
    );
    Ok(())
}

/// `vrw orbit --model NAME` for a walker other than the wheel: its diagram, its summary, its files.
fn run_walker(args: &OrbitArgs, walker: Walker) -> Result<()> {
    if args.plot != "lambda_I4" {
        anyhow::bail!(
            "`plot` chooses one of the wheel's three DLS indicators; the model `{}` has lambda_I4 only",
            walker.name()
        );
    }
    let job = WalkerOrbitJob {
        walker,
        range: WalkerRange {
            param: args.param.clone(),
            from: args.from,
            to: args.to,
            points: args.points,
        },
        transient: args.transient,
        steps: args.steps,
        initial: super::walker_initial(args.initial.as_deref())?,
        branch: !args.no_branch,
        out_dir: args.out.clone(),
        overwrite: args.overwrite,
    };
    interrupt_flag();
    super::check_out(&job.out_dir, "orbit", job.overwrite)?;
    let started = std::time::Instant::now();
    let s = run_walker_orbit(&job).context("orbit")?;
    let outcomes: Vec<String> = s.outcomes.iter().map(|(k, n)| format!("{k} {n}")).collect();
    println!(
        "vrw orbit --model {}: {} from {} to {} ({} values, {} + {} steps each): {}; {:.2} s",
        s.model,
        args.param,
        args.from,
        args.to,
        args.points,
        args.transient,
        args.steps,
        outcomes.join(", "),
        started.elapsed().as_secs_f64()
    );
    if !args.no_branch {
        println!(
            "period-1 branch: a gait at {} values, stable at {}",
            s.branch_gaits[0], s.branch_gaits[1]
        );
    }
    super::print_wrote(&args.out);
    Ok(())
}
