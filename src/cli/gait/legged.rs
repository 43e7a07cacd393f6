//! `vrw gait --model telescopic`: the compass gait with the paper's telescopic legs (docs/model.md section 13),
//! and `--model walker.toml` for a described walker with telescopic legs.

use anyhow::{bail, Context, Result};

use super::GaitArgs;
use vrw::app::{run_legged_gait, LeggedGaitJob, LeggedGaitRecord, LeggedWalker};
use vrw::mechanism::described::AnyDescribed;
use vrw::mechanism::telescopic::Telescopic;
use vrw::params::read_walker_parameters;

/// An energy audit beyond this is a warning \[J\].
const AUDIT_WARNING: f64 = 1e-6;

/// Run `vrw gait --model telescopic` and print its gait.
pub(super) fn run(args: &GaitArgs) -> Result<()> {
    let walker: Telescopic =
        read_walker_parameters(args.params.config.as_deref(), &args.params.set)?;
    walker.validate()?;
    run_walker(args, LeggedWalker::Telescopic(walker))
}

/// Run `vrw gait --model walker.toml` for a described walker with telescopic legs (its parameters already
/// read) and print its gait.
pub(super) fn run_described(args: &GaitArgs, walker: AnyDescribed) -> Result<()> {
    run_walker(args, LeggedWalker::Described(walker))
}

/// The search for `walker`, its lines and `gait.json`.
fn run_walker(args: &GaitArgs, walker: LeggedWalker) -> Result<()> {
    if args.parameter.is_some() || args.check_jacobian {
        bail!(
            "`parameter` and `check_jacobian` are not offered for the model `{}` yet: its gait's DP is checked \
             against differences at every gait (gait.json's `derivative` and `jacobian_error`; docs/model.md \
             section 13)",
            walker.name()
        );
    }
    let job = LeggedGaitJob {
        walker,
        initial: super::super::walker_initial(args.initial.as_deref())?,
        transient_steps: args.transient_steps,
        out_dir: args.out.clone(),
        overwrite: args.overwrite,
    };
    super::super::interrupt_flag();
    super::super::check_out(&job.out_dir, "gait", job.overwrite)?;
    let summary = run_legged_gait(&job).context("gait")?;
    let parameters: Vec<String> = serde_json::to_value(&summary.parameters)?
        .as_object()
        .into_iter()
        .flatten()
        .map(|(k, v)| format!("{k} = {v}"))
        .collect();
    println!(
        "vrw gait --model {}: {}",
        summary.model,
        parameters.join(", ")
    );
    let Some(g) = &summary.gait else {
        super::super::print_wrote(&args.out);
        bail!(
            "no gait found: {}",
            summary.message.as_deref().unwrap_or("unknown reason")
        );
    };
    print_gait(g);
    super::super::print_wrote(&args.out);
    Ok(())
}

/// The gait's lines.
fn print_gait(g: &LeggedGaitRecord) {
    let section: Vec<String> = g
        .section
        .iter()
        .map(|(n, v)| format!("{n} = {v:.9}"))
        .collect();
    println!(
        "gait: {} (residual {:.1e}, {} Newton iterations)",
        section.join(", "),
        g.residual,
        g.iterations
    );
    let indicator = |x: Option<f64>| x.map_or("undefined".to_string(), |x| format!("{x:.6} N"));
    println!(
        "heel strike: lambda_I4 = {:.9} N s, lambda_2+ = {}, lambda_4+ = {}, branch {}",
        g.step.lambda_i4,
        indicator(g.step.lambda_2_plus),
        indicator(g.step.lambda_4_plus),
        serde_json::to_value(g.step.branch)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default()
    );
    println!(
        "period {:.9} s, DLS {:.6} s, rear contact {:.6} s, {} events, {} scuff(s) per step",
        g.period, g.step.dls_duration, g.step.rear_contact_duration, g.step.events, g.step.scuffs
    );
    println!(
        "energy audit {:.1e} J (heel strike {:.6} J, stoppers {:.6} J, landings {:.6} J, dampers {:.6} J), \
         penetration {:.1e} m",
        g.step.energy_residual,
        g.step.losses.heel_strike,
        g.step.losses.stoppers,
        g.step.losses.landings,
        g.step.damper_work,
        g.step.penetration
    );
    if g.step.energy_residual.abs() > AUDIT_WARNING {
        eprintln!(
            "warning: the step's energy audit is {:.1e} J, above {AUDIT_WARNING:.0e} J",
            g.step.energy_residual
        );
    }
    let multipliers = super::multiplier_texts(&g.floquet_multipliers, 6);
    let route = if g.derivative == vrw::mechanism::legged::gait::EXACT_ROUTE {
        format!(
            "exact DP, Richardson-extrapolated differences agree to {:.0e}",
            g.jacobian_error
        )
    } else {
        format!(
            "Richardson-extrapolated differences, DP to {:.0e}",
            g.jacobian_error
        )
    };
    println!(
        "Floquet multipliers ({route}): {} (largest modulus {:.6}): {}",
        multipliers.join(", "),
        g.max_floquet,
        if g.max_floquet < 1.0 {
            "stable"
        } else {
            "unstable"
        }
    );
}
