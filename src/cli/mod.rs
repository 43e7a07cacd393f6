//! The `vrw` command line (clap derive): the [`Cli`] with one subcommand per job, and what the commands share
//! (the model's TOML file and `--set` overrides, the progress bar, the Ctrl-C flag, ranges `A,B`, the second
//! route in words). Each command has its own file with its options beside the summary it prints.

mod animate;
mod basin;
mod continuation;
mod gait;
mod map;
mod orbit;
mod plot;
mod simulate;
mod sweep;

use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};

use vrw::params::Config;
use vrw::study::{SecondRoute, Threshold, SECOND_ROUTE_TOL};
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
    Simulate(simulate::SimulateArgs),
    /// Find the walking gait (limit cycle, or a period-k gait up to k = 8), its DLS indicators and Floquet
    /// multipliers.
    Gait(gait::GaitArgs),
    /// Sweep a parameter with continuation, locate the thresholds and draw Fig. 2.
    Sweep(sweep::SweepArgs),
    /// Orbit diagram along one parameter: the states the walk visits after a transient, with the period-1
    /// branch (solid where stable, dashed where not).
    Orbit(orbit::OrbitArgs),
    /// Basin of the gait on a slice of the Poincare section: what the walk from every grid point does.
    Basin(basin::BasinArgs),
    /// Follow the gait family through folds by pseudo-arclength continuation in one parameter: its special
    /// points (fold, period doubling, Neimark-Sacker, border collision) located by solving for them, why each
    /// family ends, the families born there, branch.csv, special_points.json and a bifurcation diagram.
    Continue(continuation::ContinueArgs),
    /// Map the gait over two parameters: map.csv, the threshold curves (curves.json) and heat maps (map.png).
    Map(map::MapArgs),
    /// Animate a run: DIR/walk.gif from the output directory of `simulate` or `gait`.
    Animate(animate::AnimateArgs),
    /// Figures of a run: DIR/run.{png,svg} against time, DIR/steps.{png,svg} against step number.
    Plot(plot::PlotArgs),
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
    /// The configuration; legs stiff enough to make a run slow draw a warning on stderr before it starts
    /// (`docs/model.md` section 2, "Stiff legs").
    fn load(&self) -> Result<Config> {
        let config = Config::load(self.config.as_deref(), &self.set)?;
        if let Some(warning) = config.params.leg_time_scale().and_then(|s| s.warning()) {
            eprintln!("warning: {warning}");
        }
        Ok(config)
    }
}

/// The flag of each setting that the library names by its field (which is the Python keyword): the long name
/// of the command-line argument whose field has that name, read off clap's definitions of every command (a
/// field has one flag in all of them: `flags_are_one_per_field`). Never a table kept by hand. A field that is
/// also a configuration key (`max_step`: the integrator's largest step, and `vrw continue --max-step`) keeps
/// its name: in a message it is more often the key, set with `--set`.
fn flags() -> &'static BTreeMap<String, String> {
    static FLAGS: OnceLock<BTreeMap<String, String>> = OnceLock::new();
    FLAGS.get_or_init(|| {
        let keys = configuration_keys();
        let cli = <Cli as clap::CommandFactory>::command();
        cli.get_subcommands()
            .flat_map(|c| c.get_arguments())
            .filter(|a| !keys.contains(a.get_id().as_str()))
            .filter_map(|a| Some((a.get_id().to_string(), format!("--{}", a.get_long()?))))
            .collect()
    })
}

/// The keys of the configuration (those of its TOML file).
fn configuration_keys() -> std::collections::BTreeSet<String> {
    toml::Table::try_from(Config::default())
        .map(|table| table.keys().cloned().collect())
        .unwrap_or_default()
}

/// `message` with the settings the library quotes by their fields (`` `sample_dt` ``, or a pair `` `from/to` ``)
/// quoted by their flags instead (`` `--sample-dt` ``, `` `--from/--to` ``): the rule is the library's, the name
/// the command line's. Anything else in backticks (a configuration key, a value) is left as it is.
pub fn flags_in(message: &str) -> String {
    let flags = flags();
    let flagged = |quoted: &str| -> Option<String> {
        let parts: Option<Vec<&String>> = quoted.split('/').map(|f| flags.get(f)).collect();
        Some(
            parts?
                .iter()
                .map(|f| f.as_str())
                .collect::<Vec<_>>()
                .join("/"),
        )
    };
    message
        .split('`')
        .enumerate()
        .map(|(i, part)| match flagged(part) {
            Some(flag) if i % 2 == 1 => flag,
            _ => part.to_string(),
        })
        .collect::<Vec<_>>()
        .join("`")
}

/// The wheel's `--initial` of `command` (`L2,thetadot,L2dot[,slip]`), read as clap reads a flag: a bad value
/// is the usage error clap gives (exit status 2), word for word. (`--initial` is taken as text so that another
/// model can read its own section coordinates from it.)
fn wheel_initial(command: &str, text: Option<&str>) -> Option<SectionState> {
    use clap::builder::TypedValueParser;
    let text = text?;
    let mut cli = <Cli as clap::CommandFactory>::command();
    cli.build();
    let sub = cli
        .find_subcommand(command)
        .expect("the command is one of the Cli's");
    let arg = sub.get_arguments().find(|a| a.get_id() == "initial");
    let parser = clap::builder::StringValueParser::new().try_map(|s| s.parse::<SectionState>());
    match parser.parse_ref(sub, arg, std::ffi::OsStr::new(text)) {
        Ok(state) => Some(state),
        Err(e) => {
            eprint!("{}", clipped_quotes(&e.render().to_string()));
            std::process::exit(e.exit_code());
        }
    }
}

/// `text` with every run of characters between single quotes [`vrw::fmt::clip`]ped (clap quotes the argument
/// it could not read whole, however long).
pub(crate) fn clipped_quotes(text: &str) -> String {
    text.split('\'')
        .enumerate()
        .map(|(i, part)| {
            if i % 2 == 1 {
                vrw::fmt::clip(part)
            } else {
                part.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("'")
}

/// A walker's `--initial`: its section's coordinates, `a,b,...` (their number is checked by the job, which
/// knows the model).
fn walker_initial(text: Option<&str>) -> Result<Option<Vec<f64>>> {
    text.map(|text| {
        text.split(',')
            .map(|v| v.trim().parse::<f64>())
            .collect::<std::result::Result<Vec<f64>, _>>()
            .with_context(|| format!("invalid value '{}' for `initial`", vrw::fmt::clip(text)))
    })
    .transpose()
}

/// Run the parsed command.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Simulate(args) => simulate::run(args),
        Command::Gait(args) => gait::run(args),
        Command::Sweep(args) => sweep::run(args),
        Command::Orbit(args) => orbit::run(args),
        Command::Basin(args) => basin::run(args),
        Command::Continue(args) => continuation::run(args),
        Command::Map(args) => map::run(args),
        Command::Animate(args) => animate::run(args),
        Command::Plot(args) => plot::run(&args),
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

/// A flag set by Ctrl-C, which also sets the library's interrupt flag (every walk of every phase then stops
/// within a fraction of a second, the grid runner between points, and the job writes what is complete); a
/// second Ctrl-C marks the run under way `interrupted` in its manifest and exits at once with code 130.
fn interrupt_flag() -> Arc<AtomicBool> {
    let flag = Arc::new(AtomicBool::new(false));
    let handler_flag = Arc::clone(&flag);
    let installed = ctrlc::set_handler(move || {
        vrw::gait::interrupt_flag().store(true, Ordering::SeqCst);
        if handler_flag.swap(true, Ordering::SeqCst) {
            // The run under way, if any, says it was interrupted, never `running`.
            eprintln!("\ninterrupted again: quit at once (manifest.json: interrupted)");
            vrw::output::manifest::quit_interrupted(
                "quit at once by a second Ctrl-C: the files listed are complete up to their last row",
                130,
            );
        }
        eprintln!("\ninterrupted: finishing the work under way and writing what is complete (Ctrl-C again to quit at once)");
    });
    if let Err(e) = installed {
        eprintln!("warning: Ctrl-C will not stop the walk cleanly: {e}");
    }
    flag
}

/// Check `--out` before the job computes anything (the job checks it again when it starts writing), and say
/// which files of another command's run `--overwrite` will remove.
fn check_out(out: &std::path::Path, command: &str, overwrite: bool) -> Result<()> {
    if !out.exists() {
        // Nothing to replace; the job creates it once its options are checked.
        return Ok(());
    }
    let replaced = vrw::output::manifest::check_out_dir(out, command, overwrite)
        .with_context(|| command.to_string())?;
    if let Some(r) = replaced.filter(|r| r.command != command) {
        eprintln!(
            "--overwrite: the `vrw {}` run in {} is replaced; removing {}",
            r.command,
            out.display(),
            if r.files.is_empty() {
                "only its manifest".to_string()
            } else {
                r.files.join(", ")
            }
        );
    }
    Ok(())
}

/// Print the files of the run in `out` as its manifest lists them, the manifest first: `wrote
/// out/gait/{manifest.json, gait.json, ...}`.
fn print_wrote(out: &std::path::Path) {
    let mut files = vec![vrw::output::manifest::MANIFEST.to_string()];
    if let Ok(m) = vrw::output::manifest::Manifest::read(out) {
        files.extend(m.files);
    }
    println!("wrote {}/{{{}}}", out.display(), files.join(", "));
}

/// A range `A,B` of two numbers.
fn parse_range(s: &str) -> std::result::Result<(f64, f64), String> {
    let (a, b) = s
        .split_once(',')
        .ok_or_else(|| format!("'{}' is not a range A,B", vrw::fmt::clip(s)))?;
    let parse = |v: &str| {
        v.trim().parse::<f64>().map_err(|_| {
            let (v, s) = (vrw::fmt::clip(v.trim()), vrw::fmt::clip(s));
            format!("'{v}' in the range '{s}' is not a number")
        })
    };
    Ok((parse(a)?, parse(b)?))
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

/// Print a grid job's work and span, a line per phase (`vrw::study::parallelism`).
fn print_parallelism(phases: &[vrw::study::parallelism::PhaseWork]) {
    for p in phases {
        println!("  parallelism of the {p}");
    }
}

/// The most audit warnings a command prints; the file it names lists them all.
const PRINTED_WARNINGS: usize = 20;

/// Print audit warnings on stderr (the first [`PRINTED_WARNINGS`], then how many there are in `file`).
fn print_warnings(warnings: &[String], file: &str) {
    for w in warnings.iter().take(PRINTED_WARNINGS) {
        eprintln!("warning: {w}");
    }
    if warnings.len() > PRINTED_WARNINGS {
        eprintln!(
            "warning: {} audit warnings in all, listed in {file}",
            warnings.len()
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A field has one flag in every command that takes it, so that a message names it the same way whatever
    /// the command (`flags` reads all commands' definitions at once).
    #[test]
    fn flags_are_one_per_field() {
        let cli = <Cli as clap::CommandFactory>::command();
        let mut seen: BTreeMap<String, (String, String)> = BTreeMap::new();
        for command in cli.get_subcommands() {
            for arg in command.get_arguments() {
                let Some(long) = arg.get_long() else { continue };
                let (id, here) = (arg.get_id().to_string(), command.get_name().to_string());
                if let Some((first, there)) = seen.get(&id) {
                    assert_eq!(
                        first, long,
                        "`{id}` is --{first} in {there} and --{long} in {here}"
                    );
                } else {
                    seen.insert(id, (long.to_string(), here));
                }
            }
        }
        assert_eq!(
            flags().get("transient_steps").map(String::as_str),
            Some("--transient")
        );
        assert_eq!(
            flags().get("sample_dt").map(String::as_str),
            Some("--sample-dt")
        );
    }

    /// A configuration key quoted in a message (`viscosity`, `max_step`) is never turned into a flag, even where
    /// an option has the same field (`vrw continue --max-step`).
    #[test]
    fn configuration_keys_stay_keys() {
        let keys = configuration_keys();
        assert!(
            keys.contains("viscosity") && keys.contains("max_step"),
            "{keys:?}"
        );
        assert!(keys.iter().all(|k| !flags().contains_key(k)));
        assert_eq!(
            flags_in("`max_step`, `max_points`"),
            "`max_step`, `--max-points`"
        );
    }

    /// The library's messages quote fields; the command line's quote flags, pairs included, and leave
    /// anything else in backticks alone.
    #[test]
    fn messages_name_flags() {
        assert_eq!(
            flags_in("invalid `fps`: 60; raise `speed` or narrow the window with `from`/`to` or `from/to`"),
            "invalid `--fps`: 60; raise `--speed` or narrow the window with `--from`/`--to` or `--from/--to`"
        );
        assert_eq!(
            flags_in("invalid value 1 for `viscosity` (`vrw gait`, `x_from/nowhere`)"),
            "invalid value 1 for `viscosity` (`vrw gait`, `x_from/nowhere`)"
        );
    }
}
