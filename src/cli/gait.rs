//! The `vrw gait` command: its options and the summary it prints.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;

use vrw::app::{run_gait, run_walker_gait, GaitJob, Walker, WalkerGait, WalkerGaitJob};
use vrw::dynamics::DIFFERENTIABLE_KEYS;
use vrw::gait::{Gait, GaitOptions, JacobianCheck};
use vrw::mechanism::derivative_check::DerivativeCheck;
use vrw::walk::SectionState;

use super::{progress_bar, ModelArgs};

mod legged;

/// `GaitOptions::default().tolerance` as `--help` shows it (a test checks that they agree).
const DEFAULT_TOLERANCE: &str = "1e-10";

#[derive(Debug, Args)]
pub(super) struct GaitArgs {
    #[command(flatten)]
    params: ModelArgs,
    /// The walker: `vrw`, the viscoelastic-legged rimless wheel (default); `simplest`, the simplest walking
    /// model of Garcia et al.; `compass`, the compass gait of Goswami et al.; `telescopic`, the compass gait
    /// with the paper's telescopic viscoelastic legs; or a walker described in a TOML
    /// file (`models/compass.toml`; docs/model.md section 13). For all but the wheel, --config and --set take
    /// their parameters and gait.json names the section by their coordinates.
    #[arg(long, default_value = "vrw")]
    model: String,
    /// Where the search starts on the Poincare section: for the wheel `L2,thetadot,L2dot` (with friction,
    /// `,slip` after them for a slipping stance tip), default as for simulate; for another model its section's
    /// coordinates (`theta,theta_dot` for simplest, `theta1,theta1_dot,theta2_dot` for compass).
    #[arg(
        long,
        value_name = "L2,THETADOT,L2DOT[,SLIP]",
        allow_hyphen_values = true
    )]
    initial: Option<String>,
    /// Steps walked before Newton's method starts.
    #[arg(long = "transient", default_value_t = GaitOptions::default().transient_steps)]
    transient_steps: usize,
    /// Newton tolerance on max |P(s) - s|; at least 1e-13, about what the step map can resolve.
    #[arg(long, default_value = DEFAULT_TOLERANCE)]
    tolerance: f64,
    /// Also compute dP/dp of the gait for this parameter (gait.json's dP_dparam): for the wheel one of
    /// hub_mass, hub_inertia, leg_mass, leg_mass_offset, stopper_length, spring_natural_length, stiffness,
    /// viscosity, slope, gravity (and friction); for another model one of its parameters (simplest: slope;
    /// compass: hip_mass, leg_mass, leg_length, leg_mass_offset, gravity, slope; a described walker: those of
    /// its file).
    #[arg(long, value_name = "KEY")]
    parameter: Option<String>,
    /// Check the exact Jacobian against central differences with Richardson extrapolation: print both and their
    /// difference, and fail if they disagree beyond the two error estimates.
    #[arg(long)]
    check_jacobian: bool,
    /// Output directory for gait.json and one period of the gait (steps.csv, trajectory.csv, summary.json).
    #[arg(long, default_value = "out/gait")]
    out: PathBuf,
    /// Replace a run of another vrw command in the output directory (its files are removed and listed);
    /// without it such a directory is refused. A directory with files vrw did not write is always refused.
    #[arg(long)]
    overwrite: bool,
}

/// The wheel's refusal of a parameter it has no derivative in.
fn no_derivative(key: &str) -> String {
    format!(
        "no derivative with respect to {:?}: the parameter must be one of {}",
        vrw::fmt::clip(key),
        DIFFERENTIABLE_KEYS.join(", ")
    )
}

/// The parameter of `--parameter` for the wheel: one of its [`DIFFERENTIABLE_KEYS`] (another model's keys are
/// checked by its job, which knows them: a described walker's come from its file).
fn wheel_parameter(key: Option<&str>) -> Result<Option<&'static str>> {
    match key {
        None => Ok(None),
        Some(key) => match DIFFERENTIABLE_KEYS.iter().find(|k| **k == key) {
            Some(known) => Ok(Some(known)),
            None => bail!(
                "invalid value '{}' for '--parameter <KEY>': {}",
                vrw::fmt::clip(key),
                no_derivative(key)
            ),
        },
    }
}

/// Run `vrw gait` and print its summary.
pub(super) fn run(args: GaitArgs) -> Result<()> {
    let sets = &args.params.set;
    if let Some(walker) = Walker::load(&args.model, args.params.config.as_deref(), sets)? {
        return run_walker(&args, walker);
    }
    let job = gait_job(&args)?;
    super::check_out(&job.out_dir, "gait", job.overwrite)?;
    let bar = progress_bar(
        None,
        "{spinner} searching the gait ({msg}) [{elapsed_precise}]",
    );
    bar.set_message(format!(
        "{} transient steps, then Newton's method",
        args.transient_steps
    ));
    bar.enable_steady_tick(std::time::Duration::from_millis(120));
    let result = run_gait(&job);
    bar.finish_and_clear();
    let summary = result.context("gait")?;
    let p = &job.config.params;
    println!(
        "vrw gait: c = {} N s/m, slope = {} rad, impact = {}",
        p.viscosity, p.slope, p.impact
    );
    let Some(g) = &summary.gait else {
        super::print_wrote(&args.out);
        bail!(
            "no gait found: {}",
            summary.message.as_deref().unwrap_or("unknown reason")
        );
    };
    if g.period_k > 1 {
        print_cycle(g);
    }
    print_gait(g);
    print_multipliers(g);
    let check = summary.jacobian_check.as_ref().map(print_check).transpose();
    for warning in &summary.warnings {
        eprintln!("warning: {warning}");
    }
    super::print_wrote(&args.out);
    check.map(|_| ())
}

/// The gait search the options describe (the model loaded from its file and flags, Ctrl-C armed).
fn gait_job(args: &GaitArgs) -> Result<GaitJob> {
    let initial = args
        .initial
        .as_deref()
        .map(|text| {
            text.parse::<SectionState>()
                .with_context(|| format!("invalid value '{}' for `initial`", vrw::fmt::clip(text)))
        })
        .transpose()?;
    Ok(GaitJob {
        config: args.params.load()?,
        initial,
        options: GaitOptions {
            transient_steps: args.transient_steps,
            tolerance: args.tolerance,
            parameter: wheel_parameter(args.parameter.as_deref())?,
            ..GaitOptions::default()
        },
        out_dir: args.out.clone(),
        overwrite: args.overwrite,
        check_jacobian: args.check_jacobian,
        interrupt: Some(super::interrupt_flag()),
    })
}

/// The steps of a period-k gait, one line each, before the first step's detail.
fn print_cycle(g: &Gait) {
    println!(
        "period-{} gait (a fixed point of P^{}, not of P): its steps",
        g.period_k, g.period_k
    );
    for r in &g.cycle {
        let (c, i) = (&r.section, &r.indicators);
        println!(
            "  step {}: {}; lambda_I4 = {:.6} N s, lambda_2+ = {:.6} N, \
             lambda_4+ = {:.6} N, branch {}, period {:.6} s",
            r.step,
            c.labelled(Some(9)),
            i.lambda_i4,
            i.lambda_2_plus,
            i.lambda_4_plus,
            r.branch,
            r.period
        );
    }
    println!(
        "the first step in detail, and the multipliers of P^{}:",
        g.period_k
    );
}

/// The gait's section state, indicators, step quantities, contact audit, sticks and slips and friction.
fn print_gait(g: &Gait) {
    let s = &g.section;
    println!(
        "gait at {}, theta = {:.6} rad; residual {:.1e} after {} Newton iterations",
        s.labelled(Some(9)),
        g.theta,
        g.residual,
        g.iterations
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
        "period {:.6} s, step {:.6} m, speed {:.6} m/s, DLS {:.6} s, rear contact {:.6} s",
        g.period, g.step_length, g.speed, g.dls_duration, g.rear_contact_duration
    );
    let c = &g.contact;
    println!(
        "contact audit: pull force {:.1e} N, pull impulse {:.1e} N s, penetration {:.1e} m, stopper overrun {:.1e} m; energy residual {:.1e} J",
        c.pull_force, c.pull_impulse, c.penetration, c.stopper_overrun, g.energy_residual
    );
    if let Some(signature) = &g.signature {
        println!("sticks and slips: {signature}");
    }
    if let Some(f) = &c.friction {
        let work: f64 = g.cycle.iter().filter_map(|s| s.energy.friction).sum();
        println!(
            "friction: work {work:.6} J per period between impacts; audit: cone violation {:.1e} N, impulse {:.1e} N s, slip power {:.1e} W",
            f.cone_violation, f.cone_violation_impulse, f.slip_power
        );
    }
}

/// The Floquet multipliers with the stability verdict, a missing Jacobian and the parameter derivative.
fn print_multipliers(g: &Gait) {
    let multipliers = multiplier_texts(&g.floquet_multipliers, 6);
    println!(
        "Floquet multipliers [{}] (exact Jacobian, error ~{:.0e}): {}",
        multipliers.join(", "),
        g.jacobian_error,
        g.stability
    );
    if g.rear_held {
        println!(
            "(Leg 2 is held at its compression stop at the section: the map acts on dtheta/dt alone; the other \
             two multipliers are 0)"
        );
    }
    if let Some(failure) = &g.jacobian_failure {
        println!("no Jacobian: {failure}");
    }
    if let Some(d) = &g.dp_dparam {
        let values: Vec<String> = d.values.iter().map(|v| format!("{v:.9e}")).collect();
        println!(
            "dP/d{} = [{}] (error ~{:.0e})",
            d.parameter,
            values.join(", "),
            d.error
        );
    }
}

/// Print the Jacobian check of `--check-jacobian`; an error if the two routes disagree.
fn print_check(check: &JacobianCheck) -> Result<()> {
    if let Some(failure) = &check.failure {
        bail!("Jacobian check failed: {failure}");
    }
    let show = |name: &str, m: &[Vec<f64>]| {
        println!("{name}:");
        for row in m {
            let row: Vec<String> = row.iter().map(|v| format!("{v:+.12e}")).collect();
            println!("  [{}]", row.join(", "));
        }
    };
    show("exact DP", &check.exact);
    show(
        &format!(
            "finite-difference DP (Richardson, rtol {:e})",
            check.finite_difference_rtol
        ),
        &check.finite_difference,
    );
    print_agreement(
        "the exact Jacobian",
        check.difference,
        (check.exact_error, check.finite_difference_error),
        check.agree,
    )
}

/// `vrw gait --model NAME` for a walker other than the wheel: the search, its summary, gait.json.
fn run_walker(args: &GaitArgs, walker: Walker) -> Result<()> {
    let initial = super::walker_initial(args.initial.as_deref())?;
    let job = WalkerGaitJob {
        walker,
        initial,
        transient_steps: args.transient_steps,
        parameter: args.parameter.clone(),
        check_jacobian: args.check_jacobian,
        out_dir: args.out.clone(),
        overwrite: args.overwrite,
    };
    super::interrupt_flag();
    super::check_out(&job.out_dir, "gait", job.overwrite)?;
    let summary = run_walker_gait(&job).context("gait")?;
    println!(
        "vrw gait --model {}: {}",
        summary.model,
        parameters_in_words(&summary.parameters)?
    );
    let Some(g) = &summary.gait else {
        super::print_wrote(&args.out);
        bail!(
            "no gait found: {}",
            summary.message.as_deref().unwrap_or("unknown reason")
        );
    };
    print_walker_gait(g);
    if let Some(check) = &summary.jacobian_check {
        print_walker_check(check)?;
    }
    super::print_wrote(&args.out);
    Ok(())
}

/// A walker's parameters in words: `key = value, ...`.
pub(super) fn parameters_in_words(walker: &Walker) -> Result<String> {
    let parameters = serde_json::to_value(walker)?;
    let shown: Vec<String> = parameters
        .as_object()
        .into_iter()
        .flatten()
        .map(|(k, v)| format!("{k} = {v}"))
        .collect();
    Ok(shown.join(", "))
}

/// Print a walker's check of `--check-jacobian`; an error if the two routes disagree.
fn print_walker_check(check: &DerivativeCheck) -> Result<()> {
    if let Some(failure) = &check.failure {
        bail!("Jacobian check failed: {failure}");
    }
    let columns = match &check.parameter {
        Some(key) => format!("DP | dP/d{key}"),
        None => "DP".to_string(),
    };
    print_rows(&format!("exact {columns}"), &check.exact);
    print_rows(
        &format!(
            "finite-difference {columns} (Richardson, the best of relative steps 1e-3 to 1e-5)"
        ),
        &check.finite_difference,
    );
    print_agreement(
        "the exact derivatives",
        check.difference,
        (check.exact_error, check.finite_difference_error),
        check.agree,
    )
}

/// The verdict of a derivative check: the largest difference of `exact` (the exact derivatives, named so) and
/// the finite differences, their error estimates, and an error where they disagree.
fn print_agreement(
    exact: &str,
    difference: f64,
    (exact_error, finite_difference_error): (f64, f64),
    agree: bool,
) -> Result<()> {
    println!(
        "largest difference {difference:.1e}; error estimates: exact {exact_error:.1e}, finite difference \
         {finite_difference_error:.1e}: {}",
        if agree { "agree" } else { "DISAGREE" }
    );
    if !agree {
        bail!(
            "{exact} and the finite differences disagree by {difference:.1e}, beyond their error estimates"
        );
    }
    Ok(())
}

/// Floquet multipliers as text, `digits` decimals: `re`, or `re+imi` for a complex one.
fn multiplier_texts(multipliers: &[[f64; 2]], digits: usize) -> Vec<String> {
    multipliers
        .iter()
        .map(|[re, im]| {
            if *im == 0.0 {
                format!("{re:.digits$}")
            } else {
                format!("{re:.digits$}{im:+.digits$}i")
            }
        })
        .collect()
}

/// A matrix, one row a line, under its name.
fn print_rows(name: &str, m: &[Vec<f64>]) {
    println!("{name}:");
    for row in m {
        let row: Vec<String> = row.iter().map(|v| format!("{v:+.12e}")).collect();
        println!("  [{}]", row.join(", "));
    }
}

/// A walker's gait, as `vrw gait --model NAME` prints it.
fn print_walker_gait(g: &WalkerGait) {
    let section: Vec<String> = g
        .section
        .iter()
        .map(|(n, v)| format!("{n} = {v:.9}"))
        .collect();
    println!(
        "gait: {} (residual {:.1e}, {} Newton iterations)",
        section.join(", "),
        g.residual,
        g.newton_iterations
    );
    if let Some(account) = &g.legged {
        legged::print_legged_gait(g, account);
        print_dp_dparam(g);
        return;
    }
    println!(
        "period {:.9}, lambda_I4 = {:.9} (the rear foot leaves), impact loss {:.6e}, energy audit {:.1e}, \
         {} scuff(s) per step",
        g.period, g.lambda_i4, g.impact_loss, g.energy_drift, g.scuffs
    );
    let multipliers = multiplier_texts(&g.floquet_multipliers, 9);
    println!(
        "Floquet multipliers ({}): {} (largest modulus {:.9}): {}",
        g.derivative,
        multipliers.join(", "),
        g.largest_multiplier,
        g.stability
    );
    print_dp_dparam(g);
}

/// A walker's `dP/dp` at its gait, if asked for (with the differences' error estimate where they stand in).
fn print_dp_dparam(g: &WalkerGait) {
    if let Some(d) = &g.dp_dparam {
        let values: Vec<String> = d
            .values
            .iter()
            .map(|(n, v)| format!("{n} {v:.9e}"))
            .collect();
        let error = d
            .error
            .map_or(String::new(), |e| format!(", error estimate {e:.1e}"));
        println!(
            "dP/d{} = [{}] ({}{error})",
            d.parameter,
            values.join(", "),
            d.derivative
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gait_tolerance_default_is_the_library_default() {
        assert_eq!(
            DEFAULT_TOLERANCE.parse::<f64>().unwrap(),
            GaitOptions::default().tolerance
        );
    }
}
