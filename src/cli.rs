//! Command-line options (clap derive) and the human summaries printed after each job.

use std::path::PathBuf;

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};

use vrw::app::{
    run_animate, run_basin, run_gait, run_map, run_orbit, run_plot, run_simulate, run_still,
    run_sweep, AnimateJob, BasinJob, GaitJob, MapJob, OrbitJob, SimulateEvent, SimulateJob,
    SweepJob, DEFAULT_SAMPLE_DT,
};
use vrw::gait::basin::Coordinate;
use vrw::gait::orbit::OrbitSpec;
use vrw::gait::GaitOptions;
use vrw::gait::{MapSpec, SecondRoute, SweepSpec, Threshold, SECOND_ROUTE_TOL};
use vrw::output::animate::AnimateOptions;
use vrw::output::map_plot::MapMark;
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
    /// Find the walking gait (limit cycle, or a period-k gait up to k = 8), its DLS indicators and Floquet
    /// multipliers.
    Gait(GaitArgs),
    /// Sweep a parameter with continuation, locate the thresholds and draw Fig. 2.
    Sweep(SweepArgs),
    /// Orbit diagram along one parameter: the states the walk visits after a transient, with the period-1
    /// branch (solid where stable, dashed where not).
    Orbit(OrbitArgs),
    /// Basin of the gait on a slice of the Poincare section: what the walk from every grid point does.
    Basin(BasinArgs),
    /// Map the gait over two parameters: map.csv, the threshold curves (curves.json) and heat maps (map.png).
    Map(MapArgs),
    /// Animate a run: DIR/walk.gif from the output directory of `simulate` or `gait`.
    Animate(AnimateArgs),
    /// Figures of a run: DIR/run.{png,svg} against time, DIR/steps.{png,svg} against step number.
    Plot(PlotArgs),
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
        Ok(Config::load(self.config.as_deref(), &self.set)?)
    }
}

#[derive(Debug, Args)]
struct SimulateArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// Number of steps (touchdowns) to walk.
    #[arg(long, default_value_t = 20)]
    steps: usize,
    /// Initial Poincare-section state `L2,thetadot,L2dot` (m, rad/s, m/s); default 0.72,1.0,0.0
    /// (with rigid_legs: L0 and the rigid wheel's gait speed, from its closed form).
    #[arg(long, value_name = "L2,THETADOT,L2DOT", allow_hyphen_values = true)]
    initial: Option<SectionState>,
    /// Output directory for steps.csv, trajectory.csv and summary.json.
    #[arg(long, default_value = "out/simulate")]
    out: PathBuf,
    /// Sampling interval of trajectory.csv, in seconds of simulated time.
    #[arg(long, default_value_t = DEFAULT_SAMPLE_DT)]
    sample_dt: f64,
    /// Do not write trajectory.csv (steps.csv and summary.json only); an old one in --out is removed.
    #[arg(long)]
    no_trajectory: bool,
}

/// `GaitOptions::default().tolerance` as `--help` shows it (a test checks that they agree).
const DEFAULT_TOLERANCE: &str = "1e-10";

#[derive(Debug, Args)]
struct GaitArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// Where the search starts on the Poincare section, `L2,thetadot,L2dot`; default as for simulate.
    #[arg(long, value_name = "L2,THETADOT,L2DOT", allow_hyphen_values = true)]
    initial: Option<SectionState>,
    /// Steps walked before Newton's method starts.
    #[arg(long, default_value_t = GaitOptions::default().transient_steps)]
    transient: usize,
    /// Newton tolerance on max |P(s) - s|; at least 1e-13, about what the step map can resolve.
    #[arg(long, default_value = DEFAULT_TOLERANCE)]
    tolerance: f64,
    /// Output directory for gait.json and one period of the gait (steps.csv, trajectory.csv, summary.json).
    #[arg(long, default_value = "out/gait")]
    out: PathBuf,
}

#[derive(Debug, Args)]
struct SweepArgs {
    #[command(flatten)]
    model: ModelArgs,
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
    /// Where the search at the first point starts, `L2,thetadot,L2dot`; default as for simulate.
    #[arg(long, value_name = "L2,THETADOT,L2DOT", allow_hyphen_values = true)]
    initial: Option<SectionState>,
    /// Search every threshold again by a second route, the whole sweep with the other integrator (dopri5 for
    /// the default dop853), and say of each whether it is confirmed (in thresholds.json: `second_route`).
    #[arg(long)]
    second_route: bool,
    /// Output directory for sweep.csv, thresholds.json, fig2.svg and fig2.png.
    #[arg(long, default_value = "out/sweep")]
    out: PathBuf,
}

#[derive(Debug, Args)]
struct MapArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// The parameter along the horizontal axis (rows), one of the keys `sweep --help` lists.
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
    /// Where the search at the first point of every row starts, `L2,thetadot,L2dot`; default as for simulate.
    #[arg(long, value_name = "L2,THETADOT,L2DOT", allow_hyphen_values = true)]
    initial: Option<SectionState>,
    /// Mark a point on the heat maps, `X,Y` or `X,Y,LABEL` (repeatable), e.g. `--mark "220,500,paper λ4+ = 0"`.
    #[arg(long, value_name = "X,Y[,LABEL]", allow_hyphen_values = true)]
    mark: Vec<MarkArg>,
    /// Skip the threshold curves (map.csv and the heat maps only).
    #[arg(long)]
    no_curves: bool,
    /// Refine the curves' crossings on at most this many columns, evenly spread with both ends (every row is
    /// refined); at least 2, and a value of --nx or more refines every column.
    #[arg(long, default_value_t = vrw::gait::map::DEFAULT_CURVE_COLUMNS as u64,
          value_parser = clap::value_parser!(u64).range(2..))]
    curve_columns: u64,
    /// Search every threshold again by a second route, the whole map with the other integrator (dopri5 for
    /// the default dop853), and say of each whether it is confirmed (in curves.json: `second_route`).
    #[arg(long, conflicts_with = "no_curves")]
    second_route: bool,
    /// Output directory for map.csv, curves.json, map.svg and map.png.
    #[arg(long, default_value = "out/map")]
    out: PathBuf,
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

/// Help of `sweep --param`: the keys that can be swept, from [`Config::numeric_keys`].
fn param_help() -> String {
    format!(
        "The parameter to sweep, one of: {}",
        Config::numeric_keys().join(", ")
    )
}

#[derive(Debug, Args)]
struct OrbitArgs {
    #[command(flatten)]
    model: ModelArgs,
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
    /// Where the first walk starts, `L2,thetadot,L2dot`; default as for simulate.
    #[arg(long, value_name = "L2,THETADOT,L2DOT", allow_hyphen_values = true)]
    initial: Option<SectionState>,
    /// Do not compute and draw the period-1 branch.
    #[arg(long)]
    no_branch: bool,
    /// Output directory for orbit.csv, branch.csv, orbit.json and orbit.png.
    #[arg(long, default_value = "out/orbit")]
    out: PathBuf,
}

/// A range `A,B` of two numbers.
fn parse_range(s: &str) -> std::result::Result<(f64, f64), String> {
    let (a, b) = s
        .split_once(',')
        .ok_or_else(|| format!("'{s}' is not a range A,B"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<f64>()
            .map_err(|_| format!("'{}' in the range '{s}' is not a number", v.trim()))
    };
    Ok((parse(a)?, parse(b)?))
}

#[derive(Debug, Args)]
struct BasinArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// Where the gait search starts, `L2,thetadot,L2dot`; default as for simulate.
    #[arg(long, value_name = "L2,THETADOT,L2DOT", allow_hyphen_values = true)]
    initial: Option<SectionState>,
    /// Horizontal coordinate of the slice: L2, thetadot or L2dot.
    #[arg(long, default_value = "L2")]
    x: Coordinate,
    /// Vertical coordinate of the slice (the third is held at the gait's value).
    #[arg(long, default_value = "thetadot")]
    y: Coordinate,
    /// Range of x, `A,B` (default: L2 from L0/2 to L0, thetadot from 0.05 to 3 times the gait's, L2dot the
    /// gait's +- 1.5 m/s).
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
}

fn orbit(args: OrbitArgs) -> Result<()> {
    let job = OrbitJob {
        config: args.model.load()?,
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
        initial: args.initial,
        branch: !args.no_branch,
        out_dir: args.out.clone(),
    };
    let bar = progress_bar(
        Some(args.points as u64),
        "{bar:40} {pos}/{len} {msg} [{elapsed_precise}]",
    );
    let started = std::time::Instant::now();
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

fn basin(args: BasinArgs) -> Result<()> {
    let job = BasinJob {
        config: args.model.load()?,
        initial: args.initial,
        coordinates: [args.x, args.y],
        ranges: [args.x_range, args.y_range],
        points: [args.nx, args.ny],
        max_steps: args.max_steps,
        tolerance: args.tolerance,
        out_dir: args.out.clone(),
    };
    let bar = progress_bar(
        Some((args.nx * args.ny) as u64),
        "{bar:40} {pos}/{len} starts [{elapsed_precise}, eta {eta}]",
    );
    let started = std::time::Instant::now();
    let summary = run_basin(&job, &|_| bar.inc(1)).context("basin")?;
    bar.finish_and_clear();
    let g = &summary.gait;
    println!(
        "vrw basin: {} x {} starts on the slice ({}, {}) through the {}gait at (L2, thetadot, L2dot) = ({:.6}, {:.6}, {:.6}); {:.2} s ({:.2} s for the grid)",
        args.nx,
        args.ny,
        args.x.name(),
        args.y.name(),
        if g.period_k > 1 { format!("period-{} ", g.period_k) } else { String::new() },
        g.section.l2,
        g.section.theta_dot,
        g.section.l2_dot,
        started.elapsed().as_secs_f64(),
        summary.seconds
    );
    for (kind, n) in &summary.outcomes {
        println!("  {kind:<20} {n}");
    }
    println!(
        "wrote {}/{{{}}}",
        args.out.display(),
        summary.files.join(", ")
    );
    Ok(())
}

#[derive(Debug, Args)]
struct AnimateArgs {
    /// Output directory of `vrw simulate` or `vrw gait` (walk.gif is written there).
    dir: PathBuf,
    /// Frames per second (at most 50).
    #[arg(long, default_value_t = AnimateOptions::default().fps)]
    fps: u32,
    /// Playback speed: simulated seconds per second of playback.
    #[arg(long, default_value_t = AnimateOptions::default().speed, allow_hyphen_values = true)]
    speed: f64,
    /// Start of the time window [s] (default: the start of the run).
    #[arg(long, allow_hyphen_values = true)]
    from: Option<f64>,
    /// End of the time window [s] (default: the end of the run).
    #[arg(long, allow_hyphen_values = true)]
    to: Option<f64>,
    /// Frame width [px].
    #[arg(long, default_value_t = AnimateOptions::default().width)]
    width: u32,
    /// Frame height [px].
    #[arg(long, default_value_t = AnimateOptions::default().height)]
    height: u32,
    /// Draw the slope horizontal instead of inclined.
    #[arg(long)]
    horizontal: bool,
    /// Instead of the GIF, write the single frame at this time [s] as DIR/walk-frame.png.
    #[arg(long, value_name = "TIME", allow_hyphen_values = true)]
    still: Option<f64>,
}

#[derive(Debug, Args)]
struct PlotArgs {
    /// Output directory of `vrw simulate` or `vrw gait` (the figures are written there).
    dir: PathBuf,
}

/// Run the parsed command.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Simulate(args) => simulate(args),
        Command::Gait(args) => gait(args),
        Command::Sweep(args) => sweep(args),
        Command::Orbit(args) => orbit(args),
        Command::Basin(args) => basin(args),
        Command::Map(args) => map(args),
        Command::Animate(args) => animate(args),
        Command::Plot(args) => plot(&args),
    }
}

/// A progress bar on stderr when it is a terminal (hidden otherwise), with `template`.
fn progress_bar(len: Option<u64>, template: &str) -> ProgressBar {
    let bar = match len {
        _ if !std::io::stderr().is_terminal() => ProgressBar::hidden(),
        Some(len) => ProgressBar::new(len),
        None => ProgressBar::new_spinner(),
    };
    bar.set_style(ProgressStyle::with_template(template).expect("the template is valid"));
    bar
}

/// A flag set by Ctrl-C (a second Ctrl-C exits at once with code 130).
fn interrupt_flag() -> Arc<AtomicBool> {
    let flag = Arc::new(AtomicBool::new(false));
    let handler_flag = Arc::clone(&flag);
    let installed = ctrlc::set_handler(move || {
        if handler_flag.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
    });
    if let Err(e) = installed {
        eprintln!("warning: Ctrl-C will not stop the walk cleanly: {e}");
    }
    flag
}

fn animate(args: AnimateArgs) -> Result<()> {
    let job = AnimateJob {
        dir: args.dir,
        options: AnimateOptions {
            fps: args.fps,
            speed: args.speed,
            from: args.from,
            to: args.to,
            width: args.width,
            height: args.height,
            horizontal: args.horizontal,
        },
    };
    if let Some(time) = args.still {
        let path = run_still(&job, time).context("animate")?;
        println!("wrote {}", path.display());
        return Ok(());
    }
    let started = std::time::Instant::now();
    let report = run_animate(&job).context("animate")?;
    println!(
        "vrw animate: {} frames ({} in slow motion) of t = {:.3} .. {:.3} s, {:.1} s of playback, {:.2} MB in {:.2} s",
        report.frames,
        report.slow_frames,
        report.window.0,
        report.window.1,
        report.playback,
        report.bytes as f64 / 1e6,
        started.elapsed().as_secs_f64()
    );
    println!("wrote {}", report.path.display());
    Ok(())
}

fn plot(args: &PlotArgs) -> Result<()> {
    let report = run_plot(&args.dir).context("plot")?;
    for f in &report.files {
        println!("wrote {}", f.display());
    }
    Ok(())
}

fn simulate(args: SimulateArgs) -> Result<()> {
    let job = SimulateJob {
        config: args.model.load()?,
        initial: args.initial,
        steps: args.steps,
        sample_dt: args.sample_dt,
        trajectory: !args.no_trajectory,
        out_dir: args.out.clone(),
        interrupt: Some(interrupt_flag()),
    };
    let bar = progress_bar(
        Some(args.steps as u64),
        "{bar:40} {pos}/{len} steps {msg} [{elapsed_precise}, eta {eta}]",
    );
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
        "vrw simulate: c = {} N s/m, slope = {} rad, impact = {}; start (L2, thetadot, L2dot) = ({}, {}, {})",
        job.config.params.viscosity,
        job.config.params.slope,
        job.config.params.impact,
        summary.initial.l2,
        summary.initial.theta_dot,
        summary.initial.l2_dot
    );
    println!(
        "{} of {} steps in {:.4} s of simulated time; max |energy residual| = {:.2e} J",
        summary.steps_completed,
        summary.steps_requested,
        summary.end_time,
        summary.max_abs_energy_residual
    );
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
    println!(
        "wrote {}/{{{}}}",
        args.out.display(),
        summary.files.join(", ")
    );
    if summary.warnings_total > summary.warnings.len() {
        eprintln!(
            "warning: {} warnings in all ({} listed in summary.json)",
            summary.warnings_total,
            summary.warnings.len()
        );
    }
    match &summary.message {
        Some(_) if summary.status == "interrupted" => bail!(
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

fn gait(args: GaitArgs) -> Result<()> {
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
    let bar = progress_bar(
        None,
        "{spinner} searching the gait ({msg}) [{elapsed_precise}]",
    );
    bar.set_message(format!(
        "{} transient steps, then Newton's method",
        args.transient
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
        println!("wrote {}/gait.json", args.out.display());
        bail!(
            "no gait found: {}",
            summary.message.as_deref().unwrap_or("unknown reason")
        );
    };
    let s = &g.section;
    if g.period_k > 1 {
        println!(
            "period-{} gait (a fixed point of P^{}, not of P): its steps",
            g.period_k, g.period_k
        );
        for r in &g.cycle {
            let (c, i) = (&r.section, &r.indicators);
            println!(
                "  step {}: (L2, thetadot, L2dot) = ({:.9}, {:.9}, {:.9}); lambda_I4 = {:.6} N s, lambda_2+ = {:.6} N, \
                 lambda_4+ = {:.6} N, branch {}, period {:.6} s",
                r.step, c.l2, c.theta_dot, c.l2_dot, i.lambda_i4, i.lambda_2_plus, i.lambda_4_plus, r.branch, r.period
            );
        }
        println!(
            "the first step in detail, and the multipliers of P^{}:",
            g.period_k
        );
    }
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
        "period {:.6} s, step {:.6} m, speed {:.6} m/s, DLS {:.6} s, rear contact {:.6} s",
        g.period, g.step_length, g.speed, g.dls_duration, g.rear_contact_duration
    );
    let c = &g.contact;
    println!(
        "contact audit: pull force {:.1e} N, pull impulse {:.1e} N s, penetration {:.1e} m; energy residual {:.1e} J",
        c.pull_force, c.pull_impulse, c.penetration, g.energy_residual
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
        g.stability
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
        second_route: args.second_route,
        out_dir: args.out.clone(),
    };
    let routes = if args.second_route { 2 } else { 1 };
    let bar = progress_bar(
        Some(routes * args.points as u64),
        "{bar:40} {pos}/{len} {msg} [{elapsed_precise}]",
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
            "  {:<18} {} = {:.6}  (bracket [{:.7}, {:.7}], residual {:.1e}){}{}",
            t.name,
            args.param,
            t.value,
            t.bracket[0],
            t.bracket[1],
            t.residual,
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
    if args.second_route {
        println!(
            "  second route: {:.2} s; {}",
            summary.second_route_seconds,
            confirmed_count(summary.thresholds.iter())
        );
    }
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

fn map(args: MapArgs) -> Result<()> {
    let job = MapJob {
        config: args.model.load()?,
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
        initial: args.initial,
        // The refined Jacobian gives each gait's stability verdict its error estimate.
        options: GaitOptions::default(),
        curves: !args.no_curves,
        curve_columns: usize::try_from(args.curve_columns).unwrap_or(usize::MAX),
        second_route: args.second_route,
        marks: args.mark.into_iter().map(|m| m.0).collect(),
        out_dir: args.out.clone(),
    };
    let routes = if args.second_route { 2 } else { 1 };
    let total = args.nx.saturating_mul(args.ny).saturating_mul(routes);
    let bar = progress_bar(
        Some(total as u64),
        "{bar:40} {pos}/{len} points {msg} [{elapsed_precise}, eta {eta}]",
    );
    let started = std::time::Instant::now();
    let summary = run_map(&job, &|_| bar.inc(1)).context("map")?;
    bar.finish_and_clear();
    println!(
        "vrw map: {} from {} to {} ({}) x {} from {} to {} ({}): gait found at {} of {} points; {:.2} s \
         (gaits {:.2} s, curves {:.2} s)",
        args.x,
        args.x_from,
        args.x_to,
        args.nx,
        args.y,
        args.y_from,
        args.y_to,
        args.ny,
        summary.gaits_found,
        summary.points,
        started.elapsed().as_secs_f64(),
        summary.seconds[0],
        summary.seconds[1]
    );
    let unrefined = summary
        .thresholds
        .iter()
        .filter(|t| !t.threshold.value.is_finite())
        .count();
    let mut names: Vec<&str> = summary.curves.iter().map(|c| c.name.as_str()).collect();
    names.dedup();
    for name in names {
        let own: Vec<_> = summary.curves.iter().filter(|c| c.name == name).collect();
        println!(
            "  {:<18} {} polyline(s), {} refined points",
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
    if args.second_route {
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
                    vrw::gait::map::Along::X => &args.x,
                    vrw::gait::map::Along::Y => &args.y,
                };
                println!(
                    "    {} {} = {:.6} on {} {}: {}",
                    t.threshold.name,
                    param,
                    t.threshold.value,
                    if t.along == vrw::gait::map::Along::X {
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
    println!(
        "wrote {}/{{map.csv, curves.json, map.svg, map.png}}",
        args.out.display()
    );
    if summary.gaits_found == 0 {
        bail!("no gait found anywhere on the map (see map.csv for the reasons)");
    }
    Ok(())
}

/// A threshold's second route in words.
fn second_route_words(r: &SecondRoute) -> String {
    let found = match &r.name {
        Some(name) if r.value.is_finite() => format!("{name} at {:.6}", r.value),
        Some(name) => format!("{name}, not located either"),
        None => "nothing between the same grid points".to_string(),
    };
    if r.confirmed {
        format!(
            "confirmed by {}: {found} (difference {:.1e})",
            r.route, r.difference
        )
    } else {
        format!("NOT confirmed by {}: it finds {found}", r.route)
    }
}

/// "N of M located thresholds confirmed" for the thresholds of a run with a second route (a threshold whose
/// search failed, value NaN, is counted apart: it was never stated).
fn confirmed_count<'a>(thresholds: impl Iterator<Item = &'a Threshold>) -> String {
    let (mut confirmed, mut located, mut lost) = (0, 0, 0);
    for t in thresholds {
        if t.value.is_finite() {
            located += 1;
            confirmed += usize::from(t.second_route.as_ref().is_some_and(|r| r.confirmed));
        } else {
            lost += 1;
        }
    }
    let mut words = format!(
        "{confirmed} of {located} located thresholds confirmed (same kind, values within \
         {SECOND_ROUTE_TOL:.0e})"
    );
    if lost > 0 {
        words += &format!("; {lost} not located by the first route");
    }
    words
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
