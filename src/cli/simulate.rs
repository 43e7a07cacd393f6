//! The `vrw simulate` command: its options and the summary it prints.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;

use vrw::app::{
    run_simulate, run_walker_simulate, SimulateEvent, SimulateJob, Walker, WalkerSimulateJob,
    DEFAULT_SAMPLE_DT,
};

use super::{interrupt_flag, progress_bar, ModelArgs};

#[derive(Debug, Args)]
pub(super) struct SimulateArgs {
    #[command(flatten)]
    params: ModelArgs,
    /// The walker: `vrw`, the viscoelastic-legged rimless wheel (default); `simplest`, `compass` or
    /// `telescopic` (docs/model.md section 13), whose run names its coordinates (steps.csv, trajectory.csv, summary.json).
    #[arg(long, default_value = "vrw")]
    model: String,
    /// Number of steps (touchdowns) to walk.
    #[arg(long, default_value_t = 20)]
    steps: usize,
    /// Initial Poincare-section state `L2,thetadot,L2dot` (m, rad/s, m/s), and with friction the stance tip's
    /// slip velocity `,slip` (m/s) where it slips; default: derived from the parameters
    /// (0.72,1.0,0.0 for Table 1; docs/model.md section 6)
    /// (with rigid_legs: L0 and the rigid wheel's gait speed, from its closed form). For another model its
    /// section's coordinates (`theta,theta_dot` for simplest, `theta1,theta1_dot,theta2_dot` for compass).
    #[arg(
        long,
        value_name = "L2,THETADOT,L2DOT[,SLIP]",
        allow_hyphen_values = true
    )]
    initial: Option<String>,
    /// Output directory for steps.csv, trajectory.csv and summary.json.
    #[arg(long, default_value = "out/simulate")]
    out: PathBuf,
    /// Replace a run of another vrw command in the output directory (its files are removed and listed);
    /// without it such a directory is refused. A directory with files vrw did not write is always refused.
    #[arg(long)]
    overwrite: bool,
    /// Sampling interval of trajectory.csv, in seconds of simulated time.
    #[arg(long, default_value_t = DEFAULT_SAMPLE_DT)]
    sample_dt: f64,
    /// Do not write trajectory.csv (steps.csv and summary.json only); an old one in --out is removed.
    #[arg(long)]
    no_trajectory: bool,
}

/// Run `vrw simulate` and print its summary.
pub(super) fn run(args: SimulateArgs) -> Result<()> {
    let sets = &args.params.set;
    if let Some(walker) = Walker::load(&args.model, args.params.config.as_deref(), sets)? {
        return run_walker(&args, walker);
    }
    let initial = super::wheel_initial("simulate", args.initial.as_deref());
    let job = SimulateJob {
        config: args.params.load()?,
        initial,
        steps: args.steps,
        sample_dt: args.sample_dt,
        trajectory: !args.no_trajectory,
        out_dir: args.out.clone(),
        overwrite: args.overwrite,
        interrupt: Some(interrupt_flag()),
    };
    let bar = progress_bar(
        Some(args.steps as u64),
        "{bar:40} {pos}/{len} steps {msg} [{elapsed_precise}, eta {eta}]",
    );
    super::check_out(&job.out_dir, "simulate", job.overwrite)?;
    let summary = run_simulate(&job, &mut |event| match event {
        SimulateEvent::Step(report) => {
            bar.set_message(format!("t = {:.1} s", report.time + report.period));
            bar.inc(1);
        }
        SimulateEvent::Warning(warning) => bar.suspend(|| eprintln!("warning: {warning}")),
    })
    .context("simulate")?;
    bar.finish_and_clear();
    println!(
        "vrw simulate: c = {} N s/m, slope = {} rad, impact = {}; start {}",
        job.config.params.viscosity,
        job.config.params.slope,
        job.config.params.impact,
        summary.initial.labelled(None)
    );
    println!(
        "{} of {} steps in {:.4} s of simulated time; max |energy residual| = {:.2e} J",
        summary.steps_completed,
        summary.steps_requested,
        summary.end_time,
        summary.max_abs_energy_residual
    );
    print_last_step(&summary);
    super::print_wrote(&args.out);
    if summary.warnings_total > summary.warnings.len() {
        eprintln!(
            "warning: {} warnings in all ({} listed in summary.json)",
            summary.warnings_total,
            summary.warnings.len()
        );
    }
    match &summary.message {
        Some(_) if summary.status == vrw::app::WalkEnded::Interrupted => bail!(
            "interrupted (Ctrl-C) after {} of {} steps; the results so far are written",
            summary.steps_completed,
            summary.steps_requested
        ),
        Some(message) => bail!(
            "walk stopped after {} steps: {message}",
            summary.steps_completed
        ),
        None => Ok(()),
    }
}

/// The wheel's last step, in words.
fn print_last_step(summary: &vrw::app::SimulateSummary) {
    if let Some(last) = summary.steps.last() {
        let i = &last.indicators;
        println!(
            "step {}: lambda_I4 = {:.6} N s, lambda_2+ = {:.6} N, lambda_4+ = {:.6} N, branch {}, DLS {:.4} s, \
             rear contact {:.4} s, period {:.4} s, step {:.4} m, speed {:.4} m/s{}{}",
            last.step,
            i.lambda_i4,
            i.lambda_2_plus,
            i.lambda_4_plus,
            last.branch,
            last.dls_duration,
            last.rear_contact_duration,
            last.period,
            last.step_length,
            last.speed,
            if last.scuffing { ", scuffing" } else { "" },
            if last.bounce { ", bounce" } else { "" },
        );
    }
}

/// `vrw simulate --model NAME` for a walker other than the wheel: the walk, its summary, its files.
fn run_walker(args: &SimulateArgs, walker: Walker) -> Result<()> {
    let job = WalkerSimulateJob {
        walker,
        initial: super::walker_initial(args.initial.as_deref())?,
        steps: args.steps,
        sample_dt: args.sample_dt,
        trajectory: !args.no_trajectory,
        out_dir: args.out.clone(),
        overwrite: args.overwrite,
    };
    interrupt_flag();
    super::check_out(&job.out_dir, "simulate", job.overwrite)?;
    let s = run_walker_simulate(&job).context("simulate")?;
    let start: Vec<String> = s
        .initial
        .iter()
        .map(|(n, v)| format!("{n} = {v}"))
        .collect();
    println!(
        "vrw simulate --model {}: {}; start {}",
        s.model,
        super::gait::parameters_in_words(&s.parameters)?,
        start.join(", ")
    );
    println!(
        "{} of {} steps in {:.6} time units, {:.6} along the slope; largest energy audit {:.1e}",
        s.steps_completed, s.steps_requested, s.end_time, s.distance, s.max_energy_drift
    );
    if let Some(last) = &s.last_step {
        let section: Vec<String> = last
            .section
            .iter()
            .map(|(n, v)| format!("{n} = {v:.9}"))
            .collect();
        println!(
            "step {} from {}: period {:.9}, stride {:.9}, lambda_I4 = {:.9}, impact loss {:.6e}, {} scuff(s)",
            last.step,
            section.join(", "),
            last.period,
            last.stride,
            last.lambda_i4,
            last.impact_loss,
            last.scuffs
        );
        if let Some(a) = &last.legged {
            let force = |x: Option<f64>| x.map_or("undefined".to_string(), |x| format!("{x:.6} N"));
            println!(
                "its heel strike: branch {}, lambda_2+ = {}, lambda_4+ = {}; DLS {:.6} s; dampers {:.6} J; \
                 energy audit {:.1e} J",
                vrw::output::walker_run::branch_text(a.branch),
                force(a.lambda_2_plus),
                force(a.lambda_4_plus),
                a.dls_duration,
                a.damper_work,
                a.energy_residual
            );
        }
    }
    super::print_wrote(&args.out);
    match &s.message {
        Some(m) if s.status == vrw::app::WalkEnded::Interrupted => {
            bail!("{m}; the complete steps are written")
        }
        Some(m) => bail!("walk stopped after {} steps: {m}", s.steps_completed),
        None => Ok(()),
    }
}
