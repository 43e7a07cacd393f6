//! Command-line options (clap derive) and the human summaries printed after each job.

use std::path::PathBuf;

use std::io::IsTerminal;

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};

use vrw::app::{run_gait, run_simulate, run_sweep, GaitJob, SimulateJob, SweepJob};
use vrw::gait::GaitOptions;
use vrw::gait::SweepSpec;
use vrw::params::Config;
use vrw::walk::SectionState;

/// Passive dynamic walking of a viscoelastic-legged rimless wheel, with the DLS indicators.
#[derive(Debug, Parser)]
#[command(name = "vrw", version, about)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Walk N steps from a Poincare-section state and report every touchdown.
    Simulate(SimulateArgs),
    /// Find the walking gait (limit cycle), its DLS indicators and Floquet multipliers.
    Gait(GaitArgs),
    /// Sweep a parameter with continuation, locate the thresholds and draw Fig. 2.
    Sweep(SweepArgs),
}

/// Model parameters: a TOML file and `key=value` overrides.
#[derive(Debug, Args)]
struct ModelArgs {
    /// TOML file with parameters (flat keys, e.g. `viscosity = 50`); defaults are the paper's Table 1.
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
    /// Override one parameter, e.g. `--set viscosity=120` (repeatable, applied after --config).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
}

impl ModelArgs {
    fn load(&self) -> Result<Config> {
        let mut config = match &self.config {
            Some(path) => Config::from_file(path)?,
            None => Config::default(),
        };
        for assignment in &self.set {
            config.apply_override(assignment)?;
        }
        config.validate()?;
        Ok(config)
    }
}

#[derive(Debug, Args)]
struct SimulateArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// Number of steps (touchdowns) to walk.
    #[arg(long, default_value_t = 20)]
    steps: usize,
    /// Initial Poincare-section state `L2,thetadot,L2dot` \[m, rad/s, m/s\]; default 0.72,1.0,0.0
    /// (L0,1.0,0.0 with rigid_legs).
    #[arg(long, value_name = "L2,THETADOT,L2DOT", allow_hyphen_values = true)]
    initial: Option<SectionState>,
    /// Output directory for steps.csv, trajectory.csv and summary.json.
    #[arg(long, default_value = "out/simulate")]
    out: PathBuf,
    /// Sampling interval of trajectory.csv \[s\].
    #[arg(long, default_value_t = 0.005)]
    sample_dt: f64,
}

#[derive(Debug, Args)]
struct GaitArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// Where the search starts on the Poincare section, `L2,thetadot,L2dot`; default 0.72,1.0,0.0.
    #[arg(long, value_name = "L2,THETADOT,L2DOT", allow_hyphen_values = true)]
    initial: Option<SectionState>,
    /// Steps walked before Newton's method starts.
    #[arg(long, default_value_t = GaitOptions::default().transient_steps)]
    transient: usize,
    /// Newton tolerance on max |P(s) - s|.
    #[arg(long, default_value_t = GaitOptions::default().tolerance)]
    tolerance: f64,
    /// Output directory for gait.json.
    #[arg(long, default_value = "out/gait")]
    out: PathBuf,
}

#[derive(Debug, Args)]
struct SweepArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// The parameter to sweep (any numeric key, e.g. viscosity, slope, stiffness).
    #[arg(long, default_value = "viscosity")]
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
    /// Where the search at the first point starts, `L2,thetadot,L2dot`; default 0.72,1.0,0.0.
    #[arg(long, value_name = "L2,THETADOT,L2DOT", allow_hyphen_values = true)]
    initial: Option<SectionState>,
    /// Output directory for sweep.csv, thresholds.json, fig2.svg and fig2.png.
    #[arg(long, default_value = "out/sweep")]
    out: PathBuf,
}

/// Run the parsed command.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Simulate(args) => simulate(args),
        Command::Gait(args) => gait(args),
        Command::Sweep(args) => sweep(args),
    }
}

fn simulate(args: SimulateArgs) -> Result<()> {
    let job = SimulateJob {
        config: args.model.load()?,
        initial: args.initial,
        steps: args.steps,
        sample_dt: args.sample_dt,
        out_dir: args.out.clone(),
    };
    let summary = run_simulate(&job).context("simulate")?;
    println!(
        "vrw simulate: c = {} N s/m, slope = {} rad, impact = {}; start (L2, thetadot, L2dot) = ({}, {}, {})",
        job.config.params.viscosity,
        job.config.params.slope,
        job.config.params.impact,
        summary.initial.l2,
        summary.initial.theta_dot,
        summary.initial.l2_dot
    );
    println!(
        "{} of {} steps in {:.4} s; max |energy residual| = {:.2e} J",
        summary.steps_completed,
        summary.steps_requested,
        summary.end_time,
        summary.max_abs_energy_residual
    );
    if let Some(last) = summary.steps.last() {
        let i = &last.indicators;
        println!(
            "step {}: lambda_I4 = {:.6} N s, lambda_2+ = {:.6} N, lambda_4+ = {:.6} N, branch {}, DLS {:.4} s, \
             period {:.4} s, step {:.4} m, speed {:.4} m/s{}{}",
            last.step,
            i.lambda_i4,
            i.lambda_2_plus,
            i.lambda_4_plus,
            last.branch,
            last.dls_duration,
            last.period,
            last.step_length,
            last.speed,
            if last.scuffing { ", scuffing" } else { "" },
            if last.bounce { ", bounce" } else { "" },
        );
    }
    println!(
        "wrote {}/{{steps.csv, trajectory.csv, summary.json}}",
        args.out.display()
    );
    if let Some(message) = &summary.message {
        bail!(
            "walk stopped after {} steps: {message}",
            summary.steps_completed
        );
    }
    Ok(())
}

fn gait(args: GaitArgs) -> Result<()> {
    if !(args.tolerance.is_finite() && args.tolerance > 0.0) {
        bail!(
            "invalid --tolerance {}: must be a positive number",
            args.tolerance
        );
    }
    let job = GaitJob {
        config: args.model.load()?,
        initial: args.initial,
        options: GaitOptions {
            transient_steps: args.transient,
            tolerance: args.tolerance,
            ..GaitOptions::default()
        },
        out_dir: args.out.clone(),
    };
    let summary = run_gait(&job).context("gait")?;
    let p = &job.config.params;
    println!(
        "vrw gait: c = {} N s/m, slope = {} rad, impact = {}",
        p.viscosity, p.slope, p.impact
    );
    let Some(g) = &summary.gait else {
        println!("wrote {}/gait.json", args.out.display());
        bail!(
            "no gait found: {}",
            summary.message.as_deref().unwrap_or("unknown reason")
        );
    };
    let s = &g.section;
    println!(
        "gait at (L2, thetadot, L2dot) = ({:.9}, {:.9}, {:.9}), theta = {:.6} rad; residual {:.1e} after {} Newton iterations",
        s.l2, s.theta_dot, s.l2_dot, g.theta, g.residual, g.iterations
    );
    println!(
        "lambda_I4 = {:.6} N s, lambda_2+ = {:.6} N, lambda_4+ = {:.6} N, branch {}{}{}",
        g.lambda_i4,
        g.lambda_2_plus,
        g.lambda_4_plus,
        g.branch,
        if g.scuffing { ", scuffing" } else { "" },
        if g.bounce { ", bounce" } else { "" },
    );
    println!(
        "period {:.6} s, step {:.6} m, speed {:.6} m/s, DLS {:.6} s",
        g.period, g.step_length, g.speed, g.dls_duration
    );
    let multipliers: Vec<String> = g
        .floquet_multipliers
        .iter()
        .map(|[re, im]| {
            if *im == 0.0 {
                format!("{re:.6}")
            } else {
                format!("{re:.6}{im:+.6}i")
            }
        })
        .collect();
    println!(
        "Floquet multipliers [{}] (Jacobian error ~{:.0e}): {}",
        multipliers.join(", "),
        g.jacobian_error,
        if g.stable { "stable" } else { "UNSTABLE" }
    );
    println!("wrote {}/gait.json", args.out.display());
    Ok(())
}

fn sweep(args: SweepArgs) -> Result<()> {
    let job = SweepJob {
        config: args.model.load()?,
        spec: SweepSpec {
            param: args.param.clone(),
            from: args.from,
            to: args.to,
            points: args.points,
        },
        initial: args.initial,
        options: GaitOptions::for_sweeps(),
        out_dir: args.out.clone(),
    };
    let bar = if std::io::stderr().is_terminal() {
        ProgressBar::new(args.points as u64)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} {msg} [{elapsed_precise}]")
            .expect("the template is valid"),
    );
    let started = std::time::Instant::now();
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
        println!(
            "  {:<18} {} = {:.6}  (bracket [{:.7}, {:.7}], residual {:.1e}){}",
            t.name,
            args.param,
            t.value,
            t.bracket[0],
            t.bracket[1],
            t.residual,
            t.detail
                .as_deref()
                .map(|d| format!(": {d}"))
                .unwrap_or_default()
        );
    }
    println!(
        "wrote {}/{{sweep.csv, thresholds.json, fig2.svg, fig2.png}}",
        args.out.display()
    );
    if summary.gaits_found == 0 {
        bail!("no gait found anywhere in the sweep (see sweep.csv for the reasons)");
    }
    Ok(())
}
