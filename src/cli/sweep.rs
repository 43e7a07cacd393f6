//! The `vrw sweep` command: its options and the summary it prints.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;

use vrw::app::{run_sweep, run_walker_sweep, SweepJob, Walker, WalkerRange, WalkerSweepJob};
use vrw::gait::GaitOptions;
use vrw::params::Config;
use vrw::study::{SweepSpec, Threshold};

use super::{
    confirmed_count, interrupt_flag, print_warnings, progress_bar, second_route_words, ModelArgs,
};

#[derive(Debug, Args)]
pub(super) struct SweepArgs {
    #[command(flatten)]
    params: ModelArgs,
    /// The walker: `vrw` (default), `simplest`, `compass` or `telescopic` (docs/model.md section 13): for all
    /// but the wheel, the
    /// gait along `--param` (one of the model's keys) continued from value to value, sweep.csv and
    /// thresholds.json (where the largest multiplier crosses 1, bisected).
    #[arg(long, default_value = "vrw")]
    model: String,
    /// The parameter to sweep: one of the real-valued keys (listed by `--help`).
    #[arg(long, default_value = "viscosity", help = param_help())]
    param: String,
    /// First value.
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    from: f64,
    /// Last value.
    #[arg(long, default_value_t = 300.0, allow_hyphen_values = true)]
    to: f64,
    /// Number of values (ends included).
    #[arg(long, default_value_t = 300)]
    points: usize,
    /// Where the search at the first point starts, `L2,thetadot,L2dot` (with friction, `,slip` after them for a
    /// slipping stance tip); default as for simulate. For another model its section's coordinates.
    #[arg(
        long,
        value_name = "L2,THETADOT,L2DOT[,SLIP]",
        allow_hyphen_values = true
    )]
    initial: Option<String>,
    /// Search every threshold again by a second route, the whole sweep with the other integrator (dopri5 for
    /// the default dop853), and say of each whether it is confirmed (in thresholds.json: `second_route`).
    #[arg(long)]
    second_route: bool,
    /// Output directory for sweep.csv, thresholds.json, fig2.svg and fig2.png.
    #[arg(long, default_value = "out/sweep")]
    out: PathBuf,
    /// Replace a run of another vrw command in the output directory (its files are removed and listed);
    /// without it such a directory is refused. A directory with files vrw did not write is always refused.
    #[arg(long)]
    overwrite: bool,
}

/// Help of `sweep --param`: the keys that can be swept, from [`Config::numeric_keys`].
fn param_help() -> String {
    format!(
        "The parameter to sweep, one of: {}",
        Config::numeric_keys().join(", ")
    )
}

/// Run `vrw sweep` and print its summary.
pub(super) fn run(args: SweepArgs) -> Result<()> {
    let sets = &args.params.set;
    if let Some(walker) = Walker::load(&args.model, args.params.config.as_deref(), sets)? {
        return run_walker(&args, walker);
    }
    let job = sweep_job(&args)?;
    let routes = if args.second_route { 2 } else { 1 };
    // Ctrl-C stops the grid between points; what is complete is written.
    interrupt_flag();
    let bar = progress_bar(
        Some(routes * args.points as u64),
        "{bar:40} {pos}/{len} {msg} [{elapsed_precise}]",
    );
    let started = std::time::Instant::now();
    super::check_out(&job.out_dir, "sweep", job.overwrite)?;
    let summary = run_sweep(&job, &|p| {
        bar.set_message(format!("{} = {:.4}: {}", args.param, p.value, p.status));
        bar.inc(1);
    })
    .context("sweep")?;
    bar.finish_and_clear();
    println!(
        "vrw sweep: {} from {} to {} ({} points): gait found at {} points; {:.2} s (sweep {:.2} s, thresholds {:.2} s)",
        args.param,
        args.from,
        args.to,
        args.points,
        summary.gaits_found,
        started.elapsed().as_secs_f64(),
        summary.seconds[0],
        summary.seconds[1]
    );
    for t in &summary.thresholds {
        print_threshold(&args.param, t);
    }
    super::print_parallelism(&summary.parallelism);
    if args.second_route {
        println!(
            "  second route: {:.2} s; {}",
            summary.second_route_seconds,
            confirmed_count(summary.thresholds.iter())
        );
    }
    print_warnings(&summary.warnings, "thresholds.json");
    println!(
        "wrote {}/{{{}}}",
        args.out.display(),
        summary.files.join(", ")
    );
    if summary.gaits_found == 0 {
        bail!("no gait found anywhere in the sweep (see sweep.csv for the reasons)");
    }
    Ok(())
}

/// The sweep the options describe (the model loaded from its file and flags).
fn sweep_job(args: &SweepArgs) -> Result<SweepJob> {
    let initial = super::wheel_initial("sweep", args.initial.as_deref());
    Ok(SweepJob {
        config: args.params.load()?,
        spec: SweepSpec {
            param: args.param.clone(),
            from: args.from,
            to: args.to,
            points: args.points,
        },
        initial,
        options: GaitOptions::for_sweeps(),
        second_route: args.second_route,
        out_dir: args.out.clone(),
        overwrite: args.overwrite,
    })
}

/// One threshold along `param`: where (or that it was not located), its bracket and residual, its detail and
/// the second route's verdict.
fn print_threshold(param: &str, t: &Threshold) {
    // A threshold whose search failed has no value: its bracket and the reason instead of NaN.
    let at = if t.value.is_finite() {
        format!("{} = {:.6}", param, t.value)
    } else {
        format!("{} not located", param)
    };
    let residual = if t.residual.is_finite() {
        format!(", residual {:.1e}", t.residual)
    } else {
        String::new()
    };
    println!(
        "  {:<18} {at}  (bracket [{:.7}, {:.7}]{residual}){}{}",
        t.name,
        t.bracket[0],
        t.bracket[1],
        t.detail
            .as_deref()
            .map(|d| format!(": {d}"))
            .unwrap_or_default(),
        t.second_route
            .as_ref()
            .map(|r| format!("\n    {}", second_route_words(r)))
            .unwrap_or_default()
    );
}

/// `vrw sweep --model NAME` for a walker other than the wheel: its gaits along the parameter, the thresholds.
fn run_walker(args: &SweepArgs, walker: Walker) -> Result<()> {
    if args.second_route {
        bail!(
            "`second_route` takes the wheel's integrators; the model `{}` walks with DOP853 only so far \
             (docs/model.md section 13)",
            walker.name()
        );
    }
    let job = WalkerSweepJob {
        walker,
        range: WalkerRange {
            param: args.param.clone(),
            from: args.from,
            to: args.to,
            points: args.points,
        },
        initial: super::walker_initial(args.initial.as_deref())?,
        out_dir: args.out.clone(),
        overwrite: args.overwrite,
    };
    interrupt_flag();
    super::check_out(&job.out_dir, "sweep", job.overwrite)?;
    let started = std::time::Instant::now();
    let s = run_walker_sweep(&job).context("sweep")?;
    println!(
        "vrw sweep --model {}: {} from {} to {} ({} points): gait found at {}, stable at {}; {:.2} s",
        s.model,
        args.param,
        args.from,
        args.to,
        args.points,
        s.gaits_found,
        s.stable,
        started.elapsed().as_secs_f64()
    );
    for t in &s.thresholds {
        let multipliers: Vec<String> = t
            .multipliers
            .iter()
            .map(|[re, im]| match *im {
                0.0 => format!("{re:.6}"),
                im => format!("{re:.6}{im:+.6}i"),
            })
            .collect();
        println!(
            "  {:<16} {} = {:.9}  (bracket [{}, {}]; multipliers {}){}",
            t.kind,
            args.param,
            t.value,
            vrw::fmt::short(t.bracket[0]),
            vrw::fmt::short(t.bracket[1]),
            multipliers.join(", "),
            t.note
                .as_deref()
                .map(|n| format!(": {n}"))
                .unwrap_or_default()
        );
    }
    super::print_wrote(&args.out);
    if s.gaits_found == 0 {
        bail!("no gait found anywhere in the sweep (see sweep.csv for the reasons)");
    }
    Ok(())
}
