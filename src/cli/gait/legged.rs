//! The lines `vrw gait --model telescopic` prints of the gait of a walker with compliant legs (docs/model.md
//! section 13): its heel strike's DLS indicators and branch, its double support, the step's audits and the
//! multipliers with the route of `DP` (exact, checked against Richardson-extrapolated differences).

use vrw::app::WalkerGait;
use vrw::mechanism::legged::walk::StepAccount;
use vrw::output::walker_run::branch_text;

/// An energy audit beyond this is a warning \[J\].
const AUDIT_WARNING: f64 = 1e-6;

/// The legged walker's gait `g` with its step's account `a`, after its section's line.
pub(super) fn print_legged_gait(g: &WalkerGait, a: &StepAccount) {
    let indicator = |x: Option<f64>| x.map_or("undefined".to_string(), |x| format!("{x:.6} N"));
    println!(
        "heel strike: lambda_I4 = {:.9} N s, lambda_2+ = {}, lambda_4+ = {}, branch {}",
        a.lambda_i4,
        indicator(a.lambda_2_plus),
        indicator(a.lambda_4_plus),
        branch_text(a.branch)
    );
    println!(
        "period {:.9} s, DLS {:.6} s, rear contact {:.6} s, {} events, {} scuff(s) per step",
        g.period, a.dls_duration, a.rear_contact_duration, a.events, a.scuffs
    );
    println!(
        "energy audit {:.1e} J (heel strike {:.6} J, stoppers {:.6} J, landings {:.6} J, dampers {:.6} J), \
         penetration {:.1e} m",
        a.energy_residual,
        a.losses.heel_strike,
        a.losses.stoppers,
        a.losses.landings,
        a.damper_work,
        a.penetration
    );
    if a.energy_residual.abs() > AUDIT_WARNING {
        eprintln!(
            "warning: the step's energy audit is {:.1e} J, above {AUDIT_WARNING:.0e} J",
            a.energy_residual
        );
    }
    let multipliers = super::multiplier_texts(&g.floquet_multipliers, 6);
    let error = g.jacobian_error.unwrap_or(f64::NAN);
    let route = if g.derivative == vrw::mechanism::legged::gait::EXACT_ROUTE {
        format!("exact DP, Richardson-extrapolated differences agree to {error:.0e}")
    } else {
        format!("Richardson-extrapolated differences, DP to {error:.0e}")
    };
    println!(
        "Floquet multipliers ({route}): {} (largest modulus {:.6}): {}",
        multipliers.join(", "),
        g.largest_multiplier,
        g.stability
    );
}
