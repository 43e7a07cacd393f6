//! The `vrw map` command: its options (with `--mark`) and the summary it prints.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;

use vrw::app::{run_map, run_walker_map, MapJob, MapSummary, Walker, WalkerMapJob, WalkerRange};
use vrw::gait::GaitOptions;
use vrw::output::map_plot::MapMark;
use vrw::study::{CurveMethod, MapSpec, SecondRoute, SweepSpec};

use super::{
    confirmed_count, interrupt_flag, print_warnings, progress_bar, second_route_words, ModelArgs,
};

#[derive(Debug, Args)]
pub(super) struct MapArgs {
    #[command(flatten)]
    params: ModelArgs,
    /// The walker: `vrw` (default), `simplest` or `compass` (docs/model.md section 13): for the last two, the
    /// gait at every point (continued from its neighbour's) with its stability, map.csv, map.json (with every
    /// change of stability along the rows, bisected) and map.png; give the axes with --x, --y and their ranges.
    #[arg(long, default_value = "vrw")]
    model: String,
    /// The parameter along the horizontal axis (rows), one of the keys `sweep --help` lists (for another model,
    /// one of its parameters).
    #[arg(long, default_value = "viscosity")]
    x: String,
    /// First x value.
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    x_from: f64,
    /// Last x value.
    #[arg(long, default_value_t = 300.0, allow_hyphen_values = true)]
    x_to: f64,
    /// Number of x values (ends included).
    #[arg(long, default_value_t = 21)]
    nx: usize,
    /// The parameter along the vertical axis (columns).
    #[arg(long, default_value = "stiffness")]
    y: String,
    /// First y value.
    #[arg(long, default_value_t = 300.0, allow_hyphen_values = true)]
    y_from: f64,
    /// Last y value.
    #[arg(long, default_value_t = 1500.0, allow_hyphen_values = true)]
    y_to: f64,
    /// Number of y values (ends included).
    #[arg(long, default_value_t = 21)]
    ny: usize,
    /// Where the search at the first point of every row starts, `L2,thetadot,L2dot` (with friction, `,slip` after
    /// them for a slipping stance tip); default as for simulate. For another model its section's coordinates
    /// (the search at the first point only; the others continue their neighbours' gaits).
    #[arg(
        long,
        value_name = "L2,THETADOT,L2DOT[,SLIP]",
        allow_hyphen_values = true
    )]
    initial: Option<String>,
    /// Mark a point on the heat maps, `X,Y` or `X,Y,LABEL` (repeatable), e.g. `--mark "220,500,paper λ4+ = 0"`.
    #[arg(long, value_name = "X,Y[,LABEL]", allow_hyphen_values = true)]
    mark: Vec<MarkArg>,
    /// Skip the threshold curves (map.csv and the heat maps only); for another model, the bisected changes of
    /// stability.
    #[arg(long)]
    no_curves: bool,
    /// Refine the curves' crossings on at most this many columns, evenly spread with both ends (every row is
    /// refined); at least 2, and a value of --nx or more refines every column.
    #[arg(long, default_value_t = vrw::study::map::DEFAULT_CURVE_COLUMNS as u64,
          value_parser = clap::value_parser!(u64).range(2..))]
    curve_columns: u64,
    /// How the indicator curves (lambda = 0), folds and losses of stability are traced: `continuation`
    /// (followed in both parameters from a crossing a row or column found, checked against every line it
    /// crosses) or `crossings` (the refined crossings of rows and columns joined cell by cell, as the ends of
    /// existence always are).
    #[arg(long, default_value = "continuation", value_parser = ["continuation", "crossings"])]
    curve_method: String,
    /// Search every threshold again by a second route, the whole map with the other integrator (dopri5 for
    /// the default dop853), and say of each whether it is confirmed (in curves.json: `second_route`).
    #[arg(long, conflicts_with = "no_curves")]
    second_route: bool,
    /// Output directory for map.csv, curves.json, map.svg and map.png.
    #[arg(long, default_value = "out/map")]
    out: PathBuf,
    /// Replace a run of another vrw command in the output directory (its files are removed and listed);
    /// without it such a directory is refused. A directory with files vrw did not write is always refused.
    #[arg(long)]
    overwrite: bool,
}

/// `--mark X,Y[,LABEL]`.
#[derive(Debug, Clone)]
struct MarkArg(MapMark);

impl std::str::FromStr for MarkArg {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        let mut parts = s.splitn(3, ',');
        let mut number = |what: &str| -> std::result::Result<f64, String> {
            let text = parts.next().unwrap_or("").trim();
            match text.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(format!(
                    "{what} of `{s}` is `{text}`, not a finite number (expected X,Y or X,Y,LABEL)"
                )),
            }
        };
        let (x, y) = (number("X")?, number("Y")?);
        let label = parts
            .next()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .map_or_else(|| format!("({x}, {y})"), str::to_string);
        Ok(MarkArg(MapMark { label, x, y }))
    }
}

/// Run `vrw map` and print its summary.
pub(super) fn run(args: MapArgs) -> Result<()> {
    let sets = &args.params.set;
    if let Some(walker) = Walker::load(&args.model, args.params.config.as_deref(), sets)? {
        return run_walker(&args, walker);
    }
    let job = map_job(&args)?;
    let routes = if args.second_route { 2 } else { 1 };
    let total = args.nx.saturating_mul(args.ny).saturating_mul(routes);
    // Ctrl-C stops the grid between points; what is complete is written.
    interrupt_flag();
    let bar = progress_bar(
        Some(total as u64),
        "{bar:40} {pos}/{len} points {msg} [{elapsed_precise}, eta {eta}]",
    );
    let started = std::time::Instant::now();
    super::check_out(&job.out_dir, "map", job.overwrite)?;
    let summary = run_map(&job, &|_| bar.inc(1)).context("map")?;
    bar.finish_and_clear();
    print_totals(&args, &summary, started.elapsed().as_secs_f64());
    print_curves(&summary);
    super::print_parallelism(&summary.parallelism);
    if args.second_route {
        print_second_route(&args, &summary);
    }
    print_warnings(&summary.warnings, "curves.json");
    let swept = [job.spec.x.param.as_str(), job.spec.y.param.as_str()];
    let signatures = if vrw::output::friction_columns(&job.config, &swept) {
        ", signatures.svg, signatures.png"
    } else {
        ""
    };
    println!(
        "wrote {}/{{map.csv, curves.json, map.svg, map.png{signatures}}}",
        args.out.display()
    );
    if summary.gaits_found == 0 {
        bail!("no gait found anywhere on the map (see map.csv for the reasons)");
    }
    Ok(())
}

/// The map job the options describe (the model loaded from its file and flags).
fn map_job(args: &MapArgs) -> Result<MapJob> {
    Ok(MapJob {
        config: args.params.load()?,
        spec: MapSpec {
            x: SweepSpec {
                param: args.x.clone(),
                from: args.x_from,
                to: args.x_to,
                points: args.nx,
            },
            y: SweepSpec {
                param: args.y.clone(),
                from: args.y_from,
                to: args.y_to,
                points: args.ny,
            },
        },
        initial: super::wheel_initial("map", args.initial.as_deref()),
        // The refined Jacobian gives each gait's stability verdict its error estimate.
        options: GaitOptions::default(),
        curves: !args.no_curves,
        curve_columns: usize::try_from(args.curve_columns).unwrap_or(usize::MAX),
        continue_curves: args.curve_method == "continuation",
        second_route: args.second_route,
        marks: args.mark.iter().map(|m| m.0.clone()).collect(),
        out_dir: args.out.clone(),
        overwrite: args.overwrite,
    })
}

/// The map's two axes as the first summary line names them: `X from A to B (NX) x Y from C to D (NY)`.
fn axes(args: &MapArgs) -> String {
    format!(
        "{} from {} to {} ({}) x {} from {} to {} ({})",
        args.x, args.x_from, args.x_to, args.nx, args.y, args.y_from, args.y_to, args.ny
    )
}

/// The first summary line: the two axes, the gaits found and the time spent (`seconds` in all).
fn print_totals(args: &MapArgs, summary: &MapSummary, seconds: f64) {
    println!(
        "vrw map: {}: gait found at {} of {} points; {:.2} s (gaits {:.2} s, curves {:.2} s, of which \
         continued {:.2} s)",
        axes(args),
        summary.gaits_found,
        summary.points,
        seconds,
        summary.seconds[0],
        summary.seconds[1],
        summary.continuation_seconds
    );
}

/// One line per curve name (its polylines, points and how they were traced), then the crossings that could
/// not be refined.
fn print_curves(summary: &MapSummary) {
    let unrefined = summary
        .thresholds
        .iter()
        .filter(|t| !t.threshold.value.is_finite())
        .count();
    let mut names: Vec<&str> = summary.curves.iter().map(|c| c.name.as_str()).collect();
    names.sort_unstable();
    names.dedup();
    for name in names {
        let own: Vec<_> = summary.curves.iter().filter(|c| c.name == name).collect();
        let continued: Vec<_> = own
            .iter()
            .filter_map(|c| match &c.method {
                CurveMethod::Continuation(m) => Some(m),
                CurveMethod::Crossings => None,
            })
            .collect();
        let how = if continued.is_empty() {
            "refined points".to_string()
        } else {
            format!(
                "points; {} continued, on the crossings of {} rows and columns to {:.1e}",
                continued.len(),
                continued.iter().map(|m| m.lines_checked).sum::<usize>(),
                continued
                    .iter()
                    .map(|m| m.max_line_difference)
                    .fold(0.0, f64::max)
            )
        };
        println!(
            "  {:<18} {} polyline(s), {} {how}",
            name,
            own.len(),
            own.iter().map(|c| c.points.len()).sum::<usize>()
        );
    }
    if unrefined > 0 {
        println!(
            "  {unrefined} crossings could not be refined (listed in curves.json with the reason)"
        );
    }
}

/// The second route's time and count, then every threshold it did not confirm.
fn print_second_route(args: &MapArgs, summary: &MapSummary) {
    println!(
        "  second route: {:.2} s; {}",
        summary.second_route_seconds,
        confirmed_count(summary.thresholds.iter().map(|t| &t.threshold))
    );
    for t in &summary.thresholds {
        // Thresholds neither route located are among the crossings that could not be refined.
        let shown = |r: &&SecondRoute| {
            !r.confirmed && (t.threshold.value.is_finite() || r.value.is_finite())
        };
        if let Some(r) = t.threshold.second_route.as_ref().filter(shown) {
            let param = match t.along {
                vrw::study::map::Along::X => &args.x,
                vrw::study::map::Along::Y => &args.y,
            };
            println!(
                "    {} {} = {:.6} on {} {}: {}",
                t.threshold.name,
                param,
                t.threshold.value,
                if t.along == vrw::study::map::Along::X {
                    "row"
                } else {
                    "column"
                },
                t.line,
                second_route_words(r)
            );
        }
    }
}

/// `vrw map --model NAME` for a walker other than the wheel: its map, its summary, its files. The wheel's
/// options for its curves and marks are refused, named.
fn run_walker(args: &MapArgs, walker: Walker) -> Result<()> {
    let wheel_only = [
        ("--mark", !args.mark.is_empty()),
        ("--second-route", args.second_route),
        ("--curve-method", args.curve_method != "continuation"),
        (
            "--curve-columns",
            args.curve_columns != vrw::study::map::DEFAULT_CURVE_COLUMNS as u64,
        ),
    ];
    if let Some((flag, _)) = wheel_only.iter().find(|(_, given)| *given) {
        bail!(
            "`{flag}` is an option of the wheel's map; the model `{}` has no threshold curves (its \
             changes of stability are bisected along the rows: `--no-curves` skips them)",
            walker.name()
        );
    }
    let range = |param: &String, from, to, points| WalkerRange {
        param: param.clone(),
        from,
        to,
        points,
    };
    let job = WalkerMapJob {
        walker,
        x: range(&args.x, args.x_from, args.x_to, args.nx),
        y: range(&args.y, args.y_from, args.y_to, args.ny),
        initial: super::walker_initial(args.initial.as_deref())?,
        thresholds: !args.no_curves,
        out_dir: args.out.clone(),
        overwrite: args.overwrite,
    };
    interrupt_flag();
    let bar = progress_bar(
        Some(args.nx.saturating_mul(args.ny) as u64),
        "{bar:40} {pos}/{len} points [{elapsed_precise}, eta {eta}]",
    );
    super::check_out(&job.out_dir, "map", job.overwrite)?;
    let started = std::time::Instant::now();
    let s = run_walker_map(&job, &|_| bar.inc(1)).context("map")?;
    bar.finish_and_clear();
    let statuses: Vec<String> = s.statuses.iter().map(|(k, n)| format!("{k} {n}")).collect();
    println!(
        "vrw map --model {}: {}: {}; {:.2} s",
        s.model,
        axes(args),
        statuses.join(", "),
        started.elapsed().as_secs_f64()
    );
    println!(
        "  lambda_I4 >= 0 (double support kept) at {} gaits",
        s.keeps_double_support
    );
    for t in &s.thresholds {
        let th = &t.threshold;
        println!(
            "  {:<16} {} = {:.9} at {} = {}  (bracket [{}, {}])",
            th.kind,
            args.x,
            th.value,
            args.y,
            vrw::fmt::short(t.y),
            vrw::fmt::short(th.bracket[0]),
            vrw::fmt::short(th.bracket[1])
        );
    }
    super::print_wrote(&args.out);
    if s.gaits_found == 0 {
        bail!("no gait found anywhere on the map (see map.csv for the reasons)");
    }
    Ok(())
}
