//! The `vrw continue` command: its options and the summary it prints.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;

use vrw::app::{
    run_continuation, ContinueJob, ContinueResult, ContinueSummary, ExtremumRecord, SpecialRecord,
    DIAGRAM_QUANTITIES,
};
use vrw::continuation::{CurveEnd, CurvePoint, FamilyEnd};
use vrw::family::monitor::MONITORED_QUANTITIES;
use vrw::family::GaitInfo;
use vrw::walk::SectionState;

use super::{interrupt_flag, print_warnings, ModelArgs};
use vrw::app::{run_walker_continuation, Walker, WalkerContinueJob};

#[derive(Debug, Args)]
pub(super) struct ContinueArgs {
    #[command(flatten)]
    params: ModelArgs,
    /// The walker: `vrw` (default), `simplest`, `compass`, `telescopic` or a walker described in a TOML file
    /// (`models/compass.toml`; docs/model.md section 13); for all but the wheel the family of the start's gait
    /// alone, branch.csv and special_points.json (no figure yet).
    #[arg(long, default_value = "vrw")]
    model: String,
    /// The parameter followed: one of the real-valued keys (as for sweep).
    #[arg(long, default_value = "viscosity")]
    param: String,
    /// Where the first gait is searched: the parameter's value (default: its value in the configuration).
    #[arg(long, allow_hyphen_values = true)]
    start: Option<f64>,
    /// Lower end of the range the families are followed in.
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    from: f64,
    /// Upper end of the range.
    #[arg(long, default_value_t = 300.0, allow_hyphen_values = true)]
    to: f64,
    /// Where the search for the first gait starts, `L2,thetadot,L2dot` (with friction, `,slip` after them for a
    /// slipping stance tip); default as for simulate.
    #[arg(
        long,
        value_name = "L2,THETADOT,L2DOT[,SLIP]",
        allow_hyphen_values = true
    )]
    initial: Option<SectionState>,
    /// Start from a gait of period at most K (the least period the walk settles on, as `vrw gait` finds it;
    /// fixed points of P^k); default: any period up to 8, period 1 first.
    #[arg(long)]
    period: Option<usize>,
    /// Most points of a family in each direction from its start.
    #[arg(long, default_value_t = 300)]
    max_points: usize,
    /// Largest continuation step, in the scaled unknowns (section state, parameter / (range / 10)).
    #[arg(long, default_value_t = 0.1)]
    max_step: f64,
    /// Follow the start's family only: not the period-2 family of each period doubling, the other piece's family
    /// at a border where a family ends, nor the family of the gait a walk past an end settles on.
    #[arg(long)]
    no_switch: bool,
    /// The quantity the diagram draws against the parameter.
    #[arg(long, default_value = "thetadot", help = plot_help())]
    plot: String,
    /// Follow the curve of every located special point (a DLS indicator crossing zero, a fold, a period
    /// doubling, a Neimark-Sacker point) in this second parameter too: curves.csv and curves.png (needs
    /// --two-range).
    #[arg(long, value_name = "NAME", requires = "two_range")]
    two_param: Option<String>,
    /// The second parameter's range, `A,B`.
    #[arg(long, value_name = "A,B", value_parser = super::parse_range, allow_hyphen_values = true)]
    two_range: Option<(f64, f64)>,
    /// Locate where this gait quantity is stationary along every family (repeatable): its maxima and minima,
    /// smooth or at a corner, as special points EX in special_points.json and the diagram, and every monitored
    /// quantity with its derivative along the family in monitored.csv.
    #[arg(long, value_name = "NAME", help = extremum_help())]
    extremum: Vec<String>,
    /// Output directory for branch.csv, special_points.json and bifurcation.{svg,png}.
    #[arg(long, default_value = "out/continue")]
    out: PathBuf,
    /// Replace a run of another vrw command in the output directory (its files are removed and listed);
    /// without it such a directory is refused. A directory with files vrw did not write is always refused.
    #[arg(long)]
    overwrite: bool,
}

/// Help of `continue --plot`.
fn plot_help() -> String {
    format!(
        "The quantity the diagram draws against the parameter, one of: {}",
        DIAGRAM_QUANTITIES.join(", ")
    )
}

/// Help of `continue --extremum`.
fn extremum_help() -> String {
    format!(
        "Locate where this gait quantity is stationary along every family (repeatable): maxima and minima, \
         smooth or at a corner, as special points EX in special_points.json and the diagram, and every \
         monitored quantity with its derivative along the family in monitored.csv. One of: {}",
        MONITORED_QUANTITIES.join(", ")
    )
}

/// How a family ends, in words.
fn end_words(end: &FamilyEnd) -> String {
    match end {
        FamilyEnd::LeftRange { bound } => format!("reaches the end of the range at {bound}"),
        FamilyEnd::Closed => "closes on itself".to_string(),
        FamilyEnd::MaxPoints => "followed to --max-points".to_string(),
        FamilyEnd::Interrupted { param } => {
            format!("followed to {param:.9} when the job was interrupted (not an end)")
        }
        FamilyEnd::Ended {
            failure, message, ..
        } if failure == "border" => format!("ends at a border collision, {message}"),
        FamilyEnd::Ended {
            param,
            beyond,
            failure,
            message,
        } if beyond.is_nan() => format!("ends at {param:.9} ({failure}: {message})"),
        FamilyEnd::Ended {
            param,
            beyond,
            failure,
            ..
        } => format!("ends at {param:.9} ({failure} at {beyond:.9})"),
    }
}

/// Run `vrw continue` and print its summary.
pub(super) fn run(args: ContinueArgs) -> Result<()> {
    let sets = &args.params.set;
    if let Some(walker) = Walker::load(&args.model, args.params.config.as_deref(), sets)? {
        return run_walker(&args, walker);
    }
    let job = continue_job(&args)?;
    super::check_out(&job.out_dir, "continue", job.overwrite)?;
    let result = run_continuation(&job).context("continue")?;
    let s = &result.summary;
    println!(
        "vrw continue: {} from {} to {}, from the period-{} gait at {}: {} families, {} special points; {:.2} s",
        s.param,
        args.from,
        args.to,
        result.families.first().map_or(1, |f| f.period),
        s.start,
        s.families.len(),
        s.special_points.len(),
        s.seconds
    );
    for f in &s.families {
        println!(
            "  family {} (period {}, {} points, from {}): {}; {}",
            f.family,
            f.period_k,
            f.points,
            f.origin,
            end_words(&f.ends[0].end),
            end_words(&f.ends[1].end)
        );
    }
    print_special_points(s);
    print_curves(&result);
    print_warnings(&s.warnings, "special_points.json");
    println!("wrote {}/{{{}}}", args.out.display(), s.files.join(", "));
    Ok(())
}

/// `vrw continue --model NAME` for a walker other than the wheel: its start's family, branch.csv and
/// special_points.json.
fn run_walker(args: &ContinueArgs, walker: Walker) -> Result<()> {
    if args.two_param.is_some()
        || args.initial.is_some()
        || args.period.is_some()
        || !args.extremum.is_empty()
    {
        bail!(
            "`two_param`, `initial`, `period` and `extremum` take the wheel's continuation; the model `{}` follows its \
             start's family only so far (docs/model.md section 13)",
            walker.name()
        );
    }
    let job = WalkerContinueJob {
        walker,
        param: args.param.clone(),
        start: args.start,
        range: (args.from, args.to),
        max_points: args.max_points,
        max_step: args.max_step,
        out_dir: args.out.clone(),
        overwrite: args.overwrite,
    };
    super::interrupt_flag();
    super::check_out(&job.out_dir, "continue", job.overwrite)?;
    let s = run_walker_continuation(&job).context("continue")?;
    println!(
        "vrw continue --model {}: {} from {} to {}, from the gait at {}: {} points, {} special points \
         ({}); {}; {}",
        s.model,
        s.param,
        args.from,
        args.to,
        s.start,
        s.points,
        s.special_points.len(),
        s.derivative,
        end_words(&s.ends[0]),
        end_words(&s.ends[1])
    );
    for sp in &s.special_points {
        let moduli: Vec<String> = sp
            .multipliers
            .iter()
            .map(|[re, im]| format!("{:.6}", re.hypot(*im)))
            .collect();
        let how = if sp.located {
            "located".to_string()
        } else {
            format!(
                "detected, not located: {}",
                sp.note.as_deref().unwrap_or("no reason given")
            )
        };
        println!(
            "  {} at {} = {:.9} (multiplier moduli {}): {how}",
            sp.kind,
            s.param,
            sp.value,
            moduli.join(", ")
        );
    }
    super::print_wrote(&args.out);
    Ok(())
}

/// The continuation the options describe (Ctrl-C armed, then the model loaded from its file and flags).
fn continue_job(args: &ContinueArgs) -> Result<ContinueJob> {
    let flag = interrupt_flag();
    Ok(ContinueJob {
        config: args.params.load()?,
        param: args.param.clone(),
        start: args.start,
        from: args.from,
        to: args.to,
        initial: args.initial,
        period: args.period,
        max_points: args.max_points,
        max_step: args.max_step,
        switch: !args.no_switch,
        plot: args.plot.clone(),
        out_dir: args.out.clone(),
        overwrite: args.overwrite,
        interrupt: Some(flag),
        two_param: args
            .two_param
            .clone()
            .zip(args.two_range)
            .map(|(name, (a, b))| (name, a, b)),
        extremum: args.extremum.clone(),
    })
}

/// One line per special point: its kind, family, parameter, border or modulus, and whether it was located.
fn print_special_points(s: &ContinueSummary) {
    for sp in &s.special_points {
        if let Some(e) = &sp.extremum {
            print_extremum(s, sp, e);
            continue;
        }
        let located = if sp.located {
            ""
        } else {
            " (detected, not located)"
        };
        let what = sp
            .border
            .as_deref()
            .map(|b| format!(" {b}"))
            .unwrap_or_default();
        let modulus = sp
            .multipliers
            .first()
            .map(|m| format!(", |mu| = {:.6}", m[0].hypot(m[1])))
            .unwrap_or_default();
        println!(
            "  {} family {}: {} = {:.9}{what}{modulus}{located}",
            serde_json::to_value(sp.kind)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_default(),
            sp.family,
            s.param,
            sp.param,
        );
    }
}

/// The line of an extremum of `--extremum`: its kind and quantity, where, its value and the speed there, or
/// why it was not located.
fn print_extremum(s: &ContinueSummary, sp: &SpecialRecord, e: &ExtremumRecord) {
    let kind = serde_json::to_value(e.extremum)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default();
    if !sp.located {
        println!(
            "  EX family {}: {kind} of {} between {} = {:.9} and {:.9}, not located: {}",
            sp.family,
            e.quantity,
            s.param,
            sp.bracket[0],
            sp.bracket[1],
            sp.note.as_deref().unwrap_or("no reason given")
        );
        return;
    }
    let shape = match &e.corner {
        Some(why) => format!(
            "a corner ({why}) in [{:.9}, {:.9}]",
            e.located_bracket[0], e.located_bracket[1]
        ),
        None => "smooth".to_string(),
    };
    println!(
        "  EX family {}: {kind} of {} at {} = {:.9}, {} = {:.9}, speed = {:.9} m/s; {shape}",
        sp.family, e.quantity, s.param, sp.param, e.quantity, e.value, e.speed
    );
}

/// One line per two-parameter curve: its condition, family, points and where and why it ends.
fn print_curves(result: &ContinueResult) {
    let s = &result.summary;
    for (c, curve) in s.curves.iter().zip(&result.curves) {
        let at = |p: Option<&CurvePoint<GaitInfo>>| {
            p.map(|p| format!("({:.9}, {:.9})", p.p1, p.p2))
                .unwrap_or_default()
        };
        let end = |e: &CurveEnd| match e {
            CurveEnd::LeftRange => "the range's bound".to_string(),
            CurveEnd::MaxPoints => "the most points".to_string(),
            CurveEnd::Ended { message } => format!("its end ({message})"),
        };
        println!(
            "  curve {} ({} = 0 of family {}) in ({}, {}): {} points from {} at {} to {} at {}",
            c.curve,
            c.condition,
            c.family,
            s.param,
            c.param2,
            c.points,
            at(curve.points.first()),
            end(&c.ends[0]),
            at(curve.points.last()),
            end(&c.ends[1]),
        );
    }
}
