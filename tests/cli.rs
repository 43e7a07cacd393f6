//! The `vrw` binary end to end: what `vrw simulate` writes, and how it refuses bad input (exit code 1, an
//! `Error:` line naming the problem, never a panic).

use std::fs;
use std::path::PathBuf;
use std::process::{Command, Output};

use serde_json::Value;
use tempfile::TempDir;

/// Columns `steps.csv` must have (the DLS indicators, the step measures, the flags and the energy audit).
const STEPS_COLUMNS: [&str; 11] = [
    "lambda_I4",
    "lambda_2_plus",
    "lambda_4_plus",
    "branch",
    "dls_duration",
    "period",
    "step_length",
    "speed",
    "scuffing",
    "bounce",
    "energy_residual",
];

/// The exit code of a run that failed (bad input, or a walk that stopped early).
const EXIT_FAILURE: i32 = 1;

/// What one run of the binary left behind.
struct Run {
    output: Output,
    /// Keeps the temporary directory alive while the test reads `out`.
    _dir: TempDir,
    /// The `--out` directory.
    out: PathBuf,
}

impl Run {
    fn stdout(&self) -> String {
        String::from_utf8_lossy(&self.output.stdout).into_owned()
    }

    fn stderr(&self) -> String {
        String::from_utf8_lossy(&self.output.stderr).into_owned()
    }

    fn code(&self) -> Option<i32> {
        self.output.status.code()
    }

    fn read(&self, file: &str) -> String {
        let path = self.out.join(file);
        fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
    }

    fn summary(&self) -> Value {
        serde_json::from_str(&self.read("summary.json")).expect("summary.json is not valid JSON")
    }
}

/// A fresh temporary directory, with `files` (name, contents) written into it.
fn temp_dir_with(files: &[(&str, &str)]) -> TempDir {
    let dir = tempfile::tempdir().expect("cannot create a temporary directory");
    for (name, contents) in files {
        fs::write(dir.path().join(name), contents).expect("cannot write a test input file");
    }
    dir
}

/// Run `vrw simulate <args> --out <dir>/out` in `dir`, where `dir` may hold input files.
fn simulate_in(dir: TempDir, args: &[&str]) -> Run {
    command_in(dir, "simulate", args)
}

/// Run `vrw <command> <args> --out <dir>/out` in `dir`.
fn command_in(dir: TempDir, command: &str, args: &[&str]) -> Run {
    let out = dir.path().join("out");
    let output = Command::new(env!("CARGO_BIN_EXE_vrw"))
        .arg(command)
        .args(args)
        .arg("--out")
        .arg(&out)
        .current_dir(dir.path())
        .output()
        .expect("cannot run the vrw binary");
    Run {
        output,
        _dir: dir,
        out,
    }
}

fn simulate(args: &[&str]) -> Run {
    simulate_in(temp_dir_with(&[]), args)
}

/// The run failed with exit code 1 and an `Error:` line on stderr that contains every one of `needles`;
/// it did not panic.
fn assert_error(run: &Run, needles: &[&str]) {
    let stderr = run.stderr();
    assert!(
        !stderr.contains("panicked"),
        "vrw panicked:\n{stderr}\nstdout:\n{}",
        run.stdout()
    );
    assert_eq!(
        run.code(),
        Some(EXIT_FAILURE),
        "exit code, stderr:\n{stderr}"
    );
    let line = stderr
        .lines()
        .find(|l| l.starts_with("Error:"))
        .unwrap_or_else(|| panic!("no `Error:` line on stderr:\n{stderr}"));
    for needle in needles {
        assert!(
            stderr.contains(needle),
            "the error does not mention {needle:?}: {line}\nstderr:\n{stderr}"
        );
    }
}

/// Bad input must also not leave results behind.
fn assert_no_output(run: &Run) {
    assert!(
        !run.out.join("summary.json").exists(),
        "summary.json written for rejected input"
    );
}

/// The last sample of `trajectory` (default sampling interval 0.005 s) lies within one interval before
/// `end_time`: nothing computed was lost, and nothing was sampled past the end.
fn assert_trajectory_reaches(trajectory: &str, end_time: f64) {
    let last_time: f64 = trajectory
        .lines()
        .last()
        .and_then(|row| row.split(',').next())
        .and_then(|t| t.parse().ok())
        .expect("trajectory.csv has samples");
    assert!(
        last_time <= end_time && end_time - last_time < 0.005 + 1e-9,
        "last sample at {last_time} s, end time {end_time} s"
    );
}

fn data_rows(csv: &str) -> usize {
    csv.lines().skip(1).filter(|l| !l.trim().is_empty()).count()
}

#[test]
fn simulate_three_steps_writes_all_results() {
    let run = simulate(&["--steps", "3"]);
    assert_eq!(
        run.code(),
        Some(0),
        "stdout:\n{}\nstderr:\n{}",
        run.stdout(),
        run.stderr()
    );

    let steps = run.read("steps.csv");
    let header: Vec<&str> = steps
        .lines()
        .next()
        .expect("empty steps.csv")
        .split(',')
        .collect();
    assert_eq!(&header[..2], ["step", "time"], "header: {header:?}");
    for column in STEPS_COLUMNS {
        assert!(
            header.contains(&column),
            "steps.csv has no column {column}: {header:?}"
        );
    }
    assert_eq!(header, vrw::output::STEPS_HEADER);
    assert_eq!(data_rows(&steps), 3, "steps.csv:\n{steps}");
    for (k, row) in steps.lines().skip(1).enumerate() {
        let fields: Vec<&str> = row.split(',').collect();
        assert_eq!(fields.len(), header.len(), "row {}: {row}", k + 1);
        assert_eq!(fields[0], (k + 1).to_string(), "step number of row {row}");
    }

    let trajectory = run.read("trajectory.csv");
    let trajectory_header = trajectory.lines().next().expect("empty trajectory.csv");
    assert!(
        trajectory_header.starts_with("time,"),
        "trajectory.csv header: {trajectory_header}"
    );
    assert!(
        data_rows(&trajectory) > 3,
        "trajectory.csv has almost no samples"
    );

    let summary = run.summary();
    assert_eq!(summary["status"], "completed");
    assert_eq!(summary["steps_completed"], 3);
    assert_eq!(summary["steps_requested"], 3);
    assert_eq!(summary["config"]["viscosity"], 50.0);
    assert!(summary["message"].is_null());
    assert_eq!(summary["steps"].as_array().map(Vec::len), Some(3));
}

#[test]
fn negative_hub_mass_is_rejected() {
    let run = simulate(&["--steps", "1", "--set", "hub_mass=-1"]);
    assert_error(&run, &["hub_mass"]);
    assert_no_output(&run);
}

#[test]
fn two_legs_are_rejected() {
    let run = simulate(&["--steps", "1", "--set", "legs=2"]);
    assert_error(&run, &["legs"]);
    assert_no_output(&run);
}

#[test]
fn spring_shorter_than_stopper_is_rejected() {
    let run = simulate(&["--steps", "1", "--set", "spring_natural_length=0.9"]);
    assert_error(&run, &["spring_natural_length", "stopper_length"]);
    assert_no_output(&run);
}

#[test]
fn unknown_key_is_rejected() {
    let run = simulate(&["--steps", "1", "--set", "foo=1"]);
    assert_error(&run, &["unknown key", "foo"]);
    assert_no_output(&run);
}

#[test]
fn non_numeric_value_is_rejected() {
    let run = simulate(&["--steps", "1", "--set", "viscosity=abc"]);
    assert_error(&run, &["viscosity", "abc"]);
    assert_no_output(&run);
}

#[test]
fn override_without_equals_sign_is_rejected() {
    let run = simulate(&["--steps", "1", "--set", "viscosity"]);
    assert_error(&run, &["viscosity", "key=value"]);
    assert_no_output(&run);
}

#[test]
fn malformed_config_file_is_rejected_with_its_path() {
    let dir = temp_dir_with(&[("bad.toml", "viscosity = [\n")]);
    let path = dir.path().join("bad.toml");
    let path = path
        .to_str()
        .expect("temporary path is not UTF-8")
        .to_owned();
    let run = simulate_in(dir, &["--steps", "1", "--config", &path]);
    assert_error(&run, &[&path, "TOML"]);
    assert_no_output(&run);
}

#[test]
fn missing_config_file_is_rejected_with_its_path() {
    let run = simulate(&["--steps", "1", "--config", "no_such_config.toml"]);
    assert_error(&run, &["no_such_config.toml"]);
    assert_no_output(&run);
}

/// `--initial` with two numbers is refused while the command line is parsed, by clap: a usage error, which
/// clap reports with exit code 2 and a lowercase `error:` line (not the `Error:` / exit 1 of `main`).
#[test]
fn initial_state_with_two_values_is_a_usage_error() {
    let run = simulate(&["--steps", "1", "--initial", "0.8,1"]);
    let stderr = run.stderr();
    assert!(!stderr.contains("panicked"), "vrw panicked:\n{stderr}");
    assert_eq!(run.code(), Some(2), "stderr:\n{stderr}");
    assert!(stderr.contains("error:"), "stderr:\n{stderr}");
    assert!(stderr.contains("--initial"), "stderr:\n{stderr}");
    assert!(stderr.contains("2 values given"), "stderr:\n{stderr}");
    assert_no_output(&run);
}

#[test]
fn initial_leg_longer_than_stopper_is_rejected() {
    let run = simulate(&["--steps", "1", "--initial", "1.5,1,0"]);
    assert_error(&run, &["L2", "1.5", "stopper_length"]);
    assert_no_output(&run);
}

#[test]
fn zero_sample_interval_is_rejected() {
    let run = simulate(&["--steps", "1", "--sample-dt", "0"]);
    assert_error(&run, &["--sample-dt"]);
    assert_no_output(&run);
}

/// A sampling interval so small that the sampler would run for ages is refused.
#[test]
fn tiny_sample_interval_is_refused() {
    let run = simulate(&["--steps", "1", "--sample-dt", "1e-300"]);
    assert_error(&run, &["--sample-dt", "1e-300"]);
    assert_no_output(&run);
}

/// Too slow to pass over the front leg: the walk stops in the first step. The run fails, but every result
/// file is still written.
#[test]
fn walk_that_stops_early_fails_but_keeps_its_results() {
    let run = simulate(&["--steps", "3", "--initial", "0.72,0.05,0.0"]);
    assert_error(&run, &["stopped"]);

    let summary = run.summary();
    let status = summary["status"].as_str().expect("status is not a string");
    assert_ne!(status, "completed");
    assert_eq!(summary["steps_requested"], 3);
    let completed = summary["steps_completed"]
        .as_u64()
        .expect("steps_completed is not a count");
    assert!(completed < 3, "steps_completed = {completed}");
    assert!(
        summary["message"].is_string(),
        "no failure message: {summary}"
    );

    let steps = run.read("steps.csv");
    assert!(steps.starts_with("step,time,"), "steps.csv:\n{steps}");
    assert_eq!(data_rows(&steps) as u64, completed);
    assert!(run.read("trajectory.csv").starts_with("time,"));
}

#[test]
fn set_overrides_config_file() {
    let dir = temp_dir_with(&[("walk.toml", "viscosity = 80\n")]);
    let run = simulate_in(
        dir,
        &[
            "--steps",
            "1",
            "--config",
            "walk.toml",
            "--set",
            "viscosity=60",
        ],
    );
    let summary = run.summary();
    assert_eq!(
        summary["config"]["viscosity"],
        60.0,
        "stderr:\n{}",
        run.stderr()
    );
}

#[test]
fn config_file_sets_parameters() {
    let dir = temp_dir_with(&[("walk.toml", "viscosity = 80\n")]);
    let run = simulate_in(dir, &["--steps", "1", "--config", "walk.toml"]);
    let summary = run.summary();
    assert_eq!(
        summary["config"]["viscosity"],
        80.0,
        "stderr:\n{}",
        run.stderr()
    );
}

#[test]
fn gait_writes_the_fixed_point_and_its_multipliers() {
    let run = command_in(temp_dir_with(&[]), "gait", &[]);
    assert_eq!(run.code(), Some(0), "{}", run.stderr());
    let gait: Value = serde_json::from_str(&run.read("gait.json")).unwrap();
    assert_eq!(gait["status"], "found");
    for key in ["L2", "thetadot", "L2dot", "theta"] {
        assert!(gait["section"][key].is_f64(), "section.{key}");
    }
    for key in [
        "lambda_I4",
        "lambda_2_plus",
        "lambda_4_plus",
        "period",
        "step_length",
        "speed",
        "dls_duration",
        "rear_contact_duration",
        "pull_force",
        "pull_impulse",
        "penetration",
    ] {
        assert!(gait[key].is_f64(), "{key}");
    }
    assert!(gait.get("lambda_i4").is_none(), "one spelling per quantity");
    assert_eq!(gait["branch"], "DLS");
    assert_eq!(gait["stability"], "stable");
    assert_eq!(gait["stable"], true);
    let multipliers = gait["floquet_multipliers"].as_array().unwrap();
    assert_eq!(multipliers.len(), 3);
    assert!(multipliers.iter().all(|z| z.as_array().unwrap().len() == 2));
    assert!(run.stdout().contains("stable"));
}

#[test]
fn gait_search_that_fails_says_why_and_keeps_the_file() {
    let run = command_in(temp_dir_with(&[]), "gait", &["--set", "viscosity=250"]);
    assert_eq!(run.code(), Some(EXIT_FAILURE));
    assert!(
        run.stderr().contains("no gait found") && run.stderr().contains("rolled back"),
        "{}",
        run.stderr()
    );
    let gait: Value = serde_json::from_str(&run.read("gait.json")).unwrap();
    assert_eq!(gait["status"], "rolled_back");
}

#[test]
fn sweep_writes_table_thresholds_and_figure() {
    let args = ["--from", "130", "--to", "140", "--points", "6"];
    let run = command_in(temp_dir_with(&[]), "sweep", &args);
    assert_eq!(run.code(), Some(0), "{}", run.stderr());
    let table = run.read("sweep.csv");
    assert!(table.starts_with("viscosity,status,"));
    assert!(table.contains("max_floquet"));
    assert_eq!(data_rows(&table), 6);
    let thresholds: Value = serde_json::from_str(&run.read("thresholds.json")).unwrap();
    let list = thresholds["thresholds"].as_array().unwrap();
    // The gait is lost between 134 and 136: located by bisection to 1e-6.
    let lost = list
        .iter()
        .find(|t| t["name"] == "gait_lost")
        .expect("a gait_lost threshold");
    let [a, b] = [
        lost["bracket"][0].as_f64().unwrap(),
        lost["bracket"][1].as_f64().unwrap(),
    ];
    assert!(b - a <= 1e-6 && a > 134.0 && b < 136.0, "{lost}");
    let png = fs::read(run.out.join("fig2.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    assert!(run.read("fig2.svg").contains("<svg"));
}

/// `--second-route` searches every threshold again with the other integrator and says whether it is confirmed:
/// the gait end near c = 135.5 is (the two integrators agree on it to 1e-6); the output says so on the terminal
/// and in thresholds.json.
#[test]
fn sweep_second_route_confirms_the_threshold() {
    let args = [
        "--from",
        "130",
        "--to",
        "140",
        "--points",
        "6",
        "--second-route",
    ];
    let run = command_in(temp_dir_with(&[]), "sweep", &args);
    assert_eq!(run.code(), Some(0), "{}", run.stderr());
    assert!(
        run.stdout()
            .contains("confirmed by integrator = dopri5: gait_lost at 135.48923"),
        "{}",
        run.stdout()
    );
    assert!(run.stdout().contains("1 of 1 located thresholds confirmed"));
    let thresholds: Value = serde_json::from_str(&run.read("thresholds.json")).unwrap();
    let lost = &thresholds["thresholds"][0];
    assert_eq!(lost["name"], "gait_lost");
    let second = &lost["second_route"];
    assert_eq!(second["route"], "integrator = dopri5");
    assert_eq!(second["confirmed"], true);
    assert!(second["difference"].as_f64().unwrap() <= 2e-6, "{second}");
    // Without the option, no second route is claimed.
    let run = command_in(
        temp_dir_with(&[]),
        "sweep",
        &["--from", "130", "--to", "140", "--points", "6"],
    );
    let thresholds: Value = serde_json::from_str(&run.read("thresholds.json")).unwrap();
    assert!(thresholds["thresholds"][0].get("second_route").is_none());
}

/// A second route of the curves needs the curves: `--second-route --no-curves` is a usage error.
#[test]
fn map_second_route_without_curves_is_a_usage_error() {
    let run = command_in(
        temp_dir_with(&[]),
        "map",
        &["--nx", "2", "--ny", "2", "--no-curves", "--second-route"],
    );
    assert_eq!(run.code(), Some(2), "{}", run.stderr());
    assert!(run.stderr().contains("--no-curves"), "{}", run.stderr());
    assert!(!run.out.exists());
}

#[test]
fn sweep_of_an_unknown_parameter_is_rejected() {
    let run = command_in(
        temp_dir_with(&[]),
        "sweep",
        &["--param", "colour", "--points", "3"],
    );
    assert_error(&run, &["colour"]);
}

#[test]
fn sweep_with_an_empty_range_is_rejected() {
    let run = command_in(temp_dir_with(&[]), "sweep", &["--from", "5", "--to", "5"]);
    assert_error(&run, &["range"]);
}

/// A sweep whose range leaves the parameter's domain (a negative viscosity) is refused before anything is
/// computed, instead of being reported as a physical threshold.
#[test]
fn sweep_range_below_domain_is_refused_before_computing() {
    let run = command_in(
        temp_dir_with(&[]),
        "sweep",
        &["--from=-10", "--to", "50", "--points", "3"],
    );
    assert_error(&run, &["viscosity", "-10", "non-negative"]);
    assert!(!run.out.exists(), "the sweep wrote {}", run.out.display());
}

/// Tolerances have upper bounds: a huge `event_time_tol` would silently change every event time.
#[test]
fn huge_event_time_tol_is_refused() {
    for value in ["0.01", "1e308"] {
        let run = simulate(&["--steps", "1", "--set", &format!("event_time_tol={value}")]);
        assert_error(&run, &["event_time_tol", value, "between"]);
        assert_no_output(&run);
    }
}

/// Errors quote numbers as given, in short form: no 300-digit expansions, no Rust debug output.
#[test]
fn errors_print_numbers_in_short_form() {
    for (assignment, value) in [
        ("leg_mass=1e-300", "1e-300"),
        ("slope=1e308", "1e308"),
        ("rtol=1e-300", "1e-300"),
    ] {
        let run = simulate(&["--steps", "1", "--set", assignment]);
        assert_error(&run, &[value]);
        let stderr = run.stderr();
        assert!(
            !stderr.contains("0000000") && !stderr.contains('{') && !stderr.contains("Some("),
            "{assignment}: {stderr}"
        );
    }
    let run = simulate(&["--steps", "1", "--initial", "1e300,1,0"]);
    assert_error(&run, &["L2 = 1e300"]);
}

/// `--out` naming an existing file says so, for every command.
#[test]
fn out_naming_a_file_is_refused() {
    for command in ["simulate", "gait", "sweep"] {
        let run = command_in(temp_dir_with(&[("out", "not a directory")]), command, &[]);
        assert_error(&run, &["is an existing file", "--out"]);
    }
}

/// A run that fails in its first step ends at the time of the failure, not at 0.
#[test]
fn end_time_of_a_run_failing_in_its_first_step_is_the_failure_time() {
    let run = simulate(&["--steps", "3", "--set", "legs=3"]);
    assert_error(&run, &["stopped"]);
    let summary = run.summary();
    assert_eq!(summary["steps_completed"], 0);
    let end_time = summary["end_time"].as_f64().expect("end_time is a number");
    assert!(end_time > 0.0, "end_time = {end_time}");
    let message = summary["message"].as_str().expect("message is a string");
    assert!(
        message.contains(&format!("t = {end_time:.6} s")),
        "end_time {end_time} is not the failure time: {message}"
    );
    assert_trajectory_reaches(&run.read("trajectory.csv"), end_time);
}

/// `simulate` streams steps.csv and summary.json keeps its aggregates; `--no-trajectory` writes no
/// trajectory.csv.
#[test]
fn simulate_streams_and_no_trajectory_skips_file() {
    // A trajectory.csv of an earlier run would not match: it goes.
    let dir = temp_dir_with(&[]);
    let earlier = Command::new(env!("CARGO_BIN_EXE_vrw"))
        .args(["simulate", "--steps", "1", "--out", "out"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(earlier.status.success());
    assert!(dir.path().join("out/trajectory.csv").exists());
    let run = simulate_in(dir, &["--steps", "4", "--no-trajectory"]);
    assert_eq!(run.code(), Some(0), "stderr:\n{}", run.stderr());
    assert!(!run.out.join("trajectory.csv").exists());
    assert!(run.stdout().contains("simulated time"), "{}", run.stdout());
    assert!(!run.stdout().contains("trajectory.csv"), "{}", run.stdout());
    assert_eq!(data_rows(&run.read("steps.csv")), 4);
    let summary = run.summary();
    assert_eq!(summary["status"], "completed");
    assert_eq!(
        summary["files"],
        serde_json::json!(["steps.csv", "summary.json"])
    );
    let branches: u64 = summary["branches"]
        .as_object()
        .expect("branches is an object")
        .values()
        .map(|n| n.as_u64().unwrap())
        .sum();
    assert_eq!(branches, 4);
    assert!(summary["warnings"].is_array());
}

/// Ctrl-C (SIGINT) stops a long walk at the next touchdown; every completed step is in steps.csv and
/// summary.json says `interrupted`.
#[cfg(unix)]
#[test]
fn interrupted_run_keeps_what_was_computed() {
    use std::time::{Duration, Instant};
    let dir = temp_dir_with(&[]);
    let out = dir.path().join("out");
    let mut child = Command::new(env!("CARGO_BIN_EXE_vrw"))
        .args(["simulate", "--steps", "10000000", "--out"])
        .arg(&out)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("cannot run the vrw binary");
    let started = Instant::now();
    let steps_path = out.join("steps.csv");
    while fs::read_to_string(&steps_path).map_or(0, |s| data_rows(&s)) < 3 {
        if started.elapsed() > Duration::from_secs(120) {
            child.kill().ok();
            panic!("no steps streamed to steps.csv within 120 s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let signal = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("cannot run kill");
    assert!(signal.success());
    let waited = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if waited.elapsed() > Duration::from_secs(60) {
            child.kill().ok();
            panic!("vrw did not stop within 60 s of SIGINT");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut stderr = String::new();
    std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut stderr).unwrap();
    assert_eq!(status.code(), Some(EXIT_FAILURE), "stderr:\n{stderr}");
    assert!(stderr.contains("interrupted"), "stderr:\n{stderr}");

    let summary: Value =
        serde_json::from_str(&fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["status"], "interrupted");
    let completed = summary["steps_completed"].as_u64().unwrap();
    assert!(completed >= 3, "{completed}");
    assert_eq!(
        data_rows(&fs::read_to_string(&steps_path).unwrap()) as u64,
        completed
    );
    let end_time = summary["end_time"].as_f64().unwrap();
    assert_trajectory_reaches(
        &fs::read_to_string(out.join("trajectory.csv")).unwrap(),
        end_time,
    );
}

/// A Newton tolerance below what the step map can reach is refused with a hint.
#[test]
fn gait_tolerance_below_reach_is_refused_with_a_hint() {
    let run = command_in(temp_dir_with(&[]), "gait", &["--tolerance", "1e-20"]);
    assert_error(&run, &["--tolerance", "1e-20", "1e-13"]);
}

/// `--help` of every command is plain text: no rustdoc escapes such as `\[s\]`; `sweep --param` lists the
/// keys that can be swept.
#[test]
fn help_has_no_backslashes_and_lists_sweepable_keys() {
    for command in [None, Some("simulate"), Some("gait"), Some("sweep")] {
        let output = Command::new(env!("CARGO_BIN_EXE_vrw"))
            .args(command)
            .arg("--help")
            .output()
            .unwrap();
        let help = String::from_utf8_lossy(&output.stdout);
        assert!(output.status.success(), "{command:?}");
        assert!(!help.contains('\\'), "{command:?} --help:\n{help}");
        if command == Some("sweep") {
            for key in vrw::params::Config::numeric_keys() {
                assert!(help.contains(key), "sweep --help lacks {key}:\n{help}");
            }
        }
    }
}

/// With rigid legs the default start is the rigid wheel's gait, so `vrw simulate --set rigid_legs=true` walks.
#[test]
fn rigid_legs_default_start_walks() {
    let run = simulate(&[
        "--steps",
        "5",
        "--set",
        "rigid_legs=true",
        "--no-trajectory",
    ]);
    assert_eq!(run.code(), Some(0), "stderr:\n{}", run.stderr());
    assert_eq!(run.summary()["status"], "completed");
}

/// A sweep that finds no gait used to print "wrote ... fig2.svg, fig2.png" though it wrote no figure, and left
/// the figure of an earlier sweep into the same directory beside its new tables.
#[test]
fn sweep_without_gait_lists_only_what_it_wrote_and_removes_an_old_figure() {
    let dir = temp_dir_with(&[]);
    let path = dir.path().join("out");
    let earlier = Command::new(env!("CARGO_BIN_EXE_vrw"))
        .args(["sweep", "--points", "3", "--out", "out"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(earlier.status.success());
    assert!(path.join("fig2.png").exists() && path.join("fig2.svg").exists());
    // Uphill the wheel cannot walk, whatever the viscosity.
    let run = command_in(
        dir,
        "sweep",
        &[
            "--set",
            "slope=-0.1",
            "--from",
            "40",
            "--to",
            "60",
            "--points",
            "3",
        ],
    );
    assert_ne!(run.code(), Some(0));
    assert!(
        run.stdout().contains("{sweep.csv, thresholds.json}"),
        "{}",
        run.stdout()
    );
    assert!(!run.stdout().contains("fig2"), "{}", run.stdout());
    assert!(path.join("sweep.csv").exists());
    assert!(!path.join("fig2.png").exists() && !path.join("fig2.svg").exists());
    let thresholds: Value = serde_json::from_str(&run.read("thresholds.json")).unwrap();
    assert_eq!(
        thresholds["files"],
        serde_json::json!(["sweep.csv", "thresholds.json"])
    );
}
#[test]
fn orbit_and_basin_write_their_files() {
    let args = [
        "--from",
        "40",
        "--to",
        "60",
        "--points",
        "3",
        "--transient",
        "4",
        "--steps",
        "6",
    ];
    let run = command_in(temp_dir_with(&[]), "orbit", &args);
    assert_eq!(run.code(), Some(0), "{}", run.stderr());
    let table = run.read("orbit.csv");
    assert!(table.starts_with("viscosity,status,period_k,step,L2,thetadot,L2dot,lambda_I4"));
    assert_eq!(data_rows(&table), 3 * 6);
    assert_eq!(data_rows(&run.read("branch.csv")), 3);
    assert_eq!(
        &fs::read(run.out.join("orbit.png")).unwrap()[..8],
        b"\x89PNG\r\n\x1a\n"
    );
    let args = ["--nx", "3", "--ny", "2", "--max-steps", "20"];
    let run = command_in(temp_dir_with(&[]), "basin", &args);
    assert_eq!(run.code(), Some(0), "{}", run.stderr());
    assert_eq!(data_rows(&run.read("basin.csv")), 6);
    let summary: Value = serde_json::from_str(&run.read("basin.json")).unwrap();
    assert_eq!(summary["gait"]["period_k"], 1);
    assert_eq!(
        &fs::read(run.out.join("basin.png")).unwrap()[..8],
        b"\x89PNG\r\n\x1a\n"
    );
}

/// Bad orbit and basin options: an error naming the option, never a panic.
#[test]
fn orbit_and_basin_refuse_bad_options() {
    let run = command_in(temp_dir_with(&[]), "orbit", &["--steps", "0"]);
    assert_error(&run, &["--steps"]);
    let run = command_in(temp_dir_with(&[]), "basin", &["--x", "L2", "--y", "L2"]);
    assert_error(&run, &["--x/--y", "different"]);
    for (args, needle) in [
        (&["--x", "speed"][..], "unknown section coordinate"),
        (&["--x-range", "1"][..], "is not a range"),
        (&["--y-range", "1,a"][..], "is not a number"),
    ] {
        let run = command_in(temp_dir_with(&[]), "basin", args);
        assert!(!run.stderr().contains("panicked"), "{}", run.stderr());
        assert_ne!(run.code(), Some(0));
        assert!(run.stderr().contains(needle), "{}", run.stderr());
    }
}

/// A 3 x 3 map across the lower end of existence in stiffness (c = 30 to 70, k = 440 to 560).
const SMALL_MAP: [&str; 12] = [
    "--x-from", "30", "--x-to", "70", "--nx", "3", "--y-from", "440", "--y-to", "560", "--ny", "3",
];

/// `vrw map` on a small grid across the lower end of existence in stiffness writes the table, the curves and
/// the figure; the curves pass through refined points and say which line each was refined on.
#[test]
fn map_writes_table_curves_and_figure() {
    let args = [&SMALL_MAP[..], &["--mark", "50,500,a point"]].concat();
    let run = command_in(temp_dir_with(&[]), "map", &args);
    assert_eq!(run.code(), Some(0), "{}", run.stderr());
    let table = run.read("map.csv");
    assert!(
        table.starts_with("viscosity,stiffness,status,branch,"),
        "{table}"
    );
    assert!(table.contains("max_floquet") && table.contains("stability"));
    assert_eq!(data_rows(&table), 9);
    let curves: Value = serde_json::from_str(&run.read("curves.json")).unwrap();
    let list = curves["curves"].as_array().unwrap();
    let end = list
        .iter()
        .find(|c| c["name"] == "existence_end")
        .expect("the end of existence crosses the map");
    let points = end["points"].as_array().unwrap();
    assert_eq!(points.len(), end["refined_on"].as_array().unwrap().len());
    assert!(points
        .iter()
        .all(|p| p[1].as_f64().unwrap() > 440.0 && p[1].as_f64().unwrap() < 560.0));
    let png = fs::read(run.out.join("map.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    assert!(run.read("map.svg").contains("<svg"));
}

/// `vrw map` follows the `lambda_2+ = 0` curve by continuation across a small grid near `c = 4`: the curve runs
/// through the whole map, lies on the refined crossings of the lines it crosses (the column at `c = 4` among
/// them, at the README's `k = 564.367191`) to `LINE_CHECK_TOL`, and says how it was computed; with
/// `--curve-method crossings` the same curve is joined from the crossings instead.
#[test]
fn map_continues_the_indicator_curves() {
    let args = [
        "--x-from", "1", "--x-to", "7", "--nx", "3", "--y-from", "540", "--y-to", "600", "--ny",
        "4",
    ];
    let run = command_in(temp_dir_with(&[]), "map", &args);
    assert_eq!(run.code(), Some(0), "{}", run.stderr());
    let curves: Value = serde_json::from_str(&run.read("curves.json")).unwrap();
    let list = curves["curves"].as_array().unwrap();
    let continued = list
        .iter()
        .find(|c| c["name"] == "lambda_2_plus = 0" && c["method"]["kind"] == "continuation")
        .expect("a continued lambda_2+ curve");
    let method = &continued["method"];
    assert_eq!(method["condition"], "lambda_2_plus");
    assert_eq!(
        method["ends"],
        serde_json::json!(["left_range", "left_range"])
    );
    assert!(method["lines_checked"].as_u64().unwrap() >= 3, "{method}");
    assert!(
        method["max_line_difference"].as_f64().unwrap() <= 2e-6,
        "{method}"
    );
    assert!(method["max_residual"].as_f64().unwrap() < 1e-9, "{method}");
    let points = continued["points"].as_array().unwrap();
    let (first, last) = (&points[0], &points[points.len() - 1]);
    assert_eq!(
        (first[0].as_f64(), last[0].as_f64()),
        (Some(1.0), Some(7.0))
    );
    // The column at c = 4 crosses the curve where the README's sweep along k at c = 4 loses the DLS gait.
    let column = curves["thresholds"]
        .as_array()
        .unwrap()
        .iter()
        .find(|t| {
            t["along"] == "y" && t["line"] == 1 && t["threshold"]["name"] == "lambda_2_plus = 0"
        })
        .expect("the column at c = 4 crosses lambda_2+ = 0");
    let k = column["threshold"]["value"].as_f64().unwrap();
    assert!((k - 564.367191).abs() < 1e-6, "{k}");
    assert!(
        run.stdout().contains("1 continued, on the crossings of"),
        "{}",
        run.stdout()
    );
    let run = command_in(
        temp_dir_with(&[]),
        "map",
        &[&args[..], &["--curve-method", "crossings"]].concat(),
    );
    assert_eq!(run.code(), Some(0), "{}", run.stderr());
    let curves: Value = serde_json::from_str(&run.read("curves.json")).unwrap();
    assert!(curves["curves"]
        .as_array()
        .unwrap()
        .iter()
        .all(|c| c["method"]["kind"] == "crossings"));
}

/// `vrw map --second-route` on the same small grid: every row's and column's end of existence is found again
/// by the other integrator and confirmed, in curves.json and on the terminal.
#[test]
fn map_second_route_confirms_the_curves_points() {
    let args = [&SMALL_MAP[..], &["--second-route"]].concat();
    let run = command_in(temp_dir_with(&[]), "map", &args);
    assert_eq!(run.code(), Some(0), "{}", run.stderr());
    let curves: Value = serde_json::from_str(&run.read("curves.json")).unwrap();
    let thresholds = curves["thresholds"].as_array().unwrap();
    assert!(!thresholds.is_empty());
    for t in thresholds {
        let second = &t["threshold"]["second_route"];
        assert_eq!(second["route"], "integrator = dopri5", "{t}");
        assert_eq!(second["confirmed"], true, "{t}");
    }
    let all = format!("{0} of {0} located thresholds confirmed", thresholds.len());
    assert!(run.stdout().contains(&all), "{}", run.stdout());
}

/// Bad map specifications are refused with an error naming the problem, before anything is computed.
#[test]
fn map_rejects_bad_input() {
    for (args, needles) in [
        (vec!["--x", "colour"], vec!["colour"]),
        (vec!["--y", "viscosity"], vec!["different parameters"]),
        (vec!["--nx", "1"], vec!["between 2 and"]),
        (vec!["--y-from=-5", "--ny", "2"], vec!["stiffness", "-5"]),
    ] {
        let run = command_in(temp_dir_with(&[]), "map", &args);
        assert_error(&run, &needles);
        assert!(!run.out.join("map.csv").exists(), "{args:?}");
    }
    // A malformed --mark is a usage error (clap's exit code 2) naming the value.
    let run = command_in(temp_dir_with(&[]), "map", &["--mark", "1,x"]);
    assert_eq!(run.code(), Some(2), "{}", run.stderr());
    assert!(
        run.stderr().contains("not a finite number"),
        "{}",
        run.stderr()
    );
}

/// A slope sweep's figure title used to say "slope phi = 0.1 rad" (the configured value of the swept
/// parameter), and its x axis stopped where the gaits did: the title names the fixed parameters only, and the
/// axis spans the whole range asked for.
#[test]
fn slope_sweep_figure_names_only_fixed_parameters_and_spans_the_range() {
    let args = [
        "--param", "slope", "--from", "0.05", "--to", "0.12", "--points", "4",
    ];
    let run = command_in(temp_dir_with(&[]), "sweep", &args);
    assert_eq!(run.code(), Some(0), "{}", run.stderr());
    let svg = run.read("fig2.svg");
    assert!(
        svg.contains("Gaits along φ: c = 50 N s/m, k = 500 N/m"),
        "title"
    );
    assert!(
        !svg.contains("φ = 0.1 rad"),
        "the swept parameter's configured value is not in the title"
    );
    // No gait at 0.05 (the family begins near 0.0849): the axis still starts there, with the span shaded.
    let ticks: Vec<&str> = svg.lines().map(str::trim).collect();
    for tick in ["0.05", "0.06", "0.07", "0.08", "0.12"] {
        assert!(ticks.contains(&tick), "the x axis has a tick at {tick}");
    }
}

/// `vrw continue` writes its three kinds of files for one family, with the fold of the slope family.
#[test]
fn continue_writes_the_family_and_its_fold() {
    let args = [
        "--param",
        "slope",
        "--from",
        "0.3",
        "--to",
        "0.34",
        "--start",
        "0.32",
        "--no-switch",
    ];
    let run = command_in(temp_dir_with(&[]), "continue", &args);
    assert_eq!(run.code(), Some(0), "{}", run.stderr());
    assert!(
        run.stdout().contains("LP family 1: slope = 0.33116292"),
        "{}",
        run.stdout()
    );
    let table = run.read("branch.csv");
    assert!(table.starts_with("family,period_k,least_period,point,arclength,slope,L2,thetadot"));
    assert!(table.contains(",unstable,") && table.contains(",stable,"));
    let summary: Value = serde_json::from_str(&run.read("special_points.json")).unwrap();
    assert_eq!(summary["special_points"][0]["kind"], "LP");
    assert_eq!(summary["special_points"][0]["located"], true);
    assert_eq!(
        summary["files"],
        serde_json::json!([
            "branch.csv",
            "special_points.json",
            "bifurcation.svg",
            "bifurcation.png"
        ])
    );
    assert_eq!(
        &fs::read(run.out.join("bifurcation.png")).unwrap()[..8],
        b"\x89PNG\r\n\x1a\n"
    );
}

/// Bad continuation options: an error naming the option, never a panic, and no files.
#[test]
fn continue_refuses_bad_options() {
    for (args, needle) in [
        (&["--start", "500"][..], "outside the range"),
        (&["--plot", "colour"][..], "unknown quantity"),
        (&["--param", "legs"][..], "unknown parameter"),
        (&["--from", "10", "--to", "5"][..], "from < to"),
        (&["--max-points", "0"][..], "--max-points"),
        (&["--max-step=-1"][..], "the longest continuation step"),
        (&["--period", "9"][..], "--period"),
        (
            &[
                "--param", "slope", "--from", "0.6", "--to", "0.7", "--start", "0.65",
            ][..],
            "no gait",
        ),
    ] {
        let run = command_in(temp_dir_with(&[]), "continue", args);
        assert_error(&run, &[needle]);
        assert!(!run.out.join("branch.csv").exists());
    }
}

/// `vrw continue --two-param`: the curve of the border collision in a second parameter, its table and figure.
#[test]
fn continue_follows_a_border_curve_in_two_parameters() {
    let args = [
        "--param",
        "stiffness",
        "--set",
        "viscosity=20",
        "--from",
        "585",
        "--to",
        "600",
        "--start",
        "590",
        "--no-switch",
        "--two-param",
        "viscosity",
        "--two-range",
        "18,22",
    ];
    let run = command_in(temp_dir_with(&[]), "continue", &args);
    assert_eq!(run.code(), Some(0), "{}", run.stderr());
    let table = run.read("curves.csv");
    assert!(table.starts_with("curve,condition,stiffness,viscosity,L2"));
    assert!(data_rows(&table) > 5);
    let summary: Value = serde_json::from_str(&run.read("special_points.json")).unwrap();
    assert_eq!(summary["curves"][0]["condition"], "lambda_2_plus");
    assert_eq!(summary["curves"][0]["kind"], "BC");
    // The curve ends on the range's bound c = 22, where a family followed in k alone at c = 22 meets the
    // same border: the two agree to 1e-6.
    let last = table.lines().last().unwrap().split(',').collect::<Vec<_>>();
    assert_eq!(last[3].parse::<f64>().unwrap(), 22.0);
    let line = command_in(
        temp_dir_with(&[]),
        "continue",
        &[
            "--param",
            "stiffness",
            "--set",
            "viscosity=22",
            "--from",
            "585",
            "--to",
            "605",
            "--start",
            "590",
            "--no-switch",
        ],
    );
    assert_eq!(line.code(), Some(0), "{}", line.stderr());
    let one: Value = serde_json::from_str(&line.read("special_points.json")).unwrap();
    let threshold = one["special_points"][0]["param"].as_f64().unwrap();
    let on_curve = last[2].parse::<f64>().unwrap();
    assert!(
        (on_curve - threshold).abs() < 1e-6,
        "curve {on_curve} vs family {threshold}"
    );
    let run = command_in(
        temp_dir_with(&[]),
        "continue",
        &["--two-param", "viscosity", "--two-range", "1,10"],
    );
    assert_error(&run, &["--two-param"]);
}

/// `vrw gait --model simplest` and `--model compass` find the classic walkers' gaits (docs/model.md section 13):
/// gait.json names the section by the model's coordinates and holds the period and the multipliers; the
/// parameters come from --set and a TOML file as the wheel's do.
#[test]
fn gait_of_the_classic_walkers() {
    let run = command_in(
        temp_dir_with(&[]),
        "gait",
        &["--model", "simplest", "--set", "slope=0.009"],
    );
    assert_eq!(run.code(), Some(0), "{}", run.stderr());
    let gait: Value = serde_json::from_str(&run.read("gait.json")).unwrap();
    assert_eq!(gait["model"], "simplest");
    let theta = gait["gait"]["section"]["theta"].as_f64().unwrap();
    assert!((theta - 0.2003).abs() < 5e-5, "{gait}");
    assert!(gait["gait"]["section"]["theta_dot"].as_f64().unwrap() < 0.0);
    assert_eq!(gait["gait"]["stability"], "stable");
    assert_eq!(
        gait["gait"]["floquet_multipliers"]
            .as_array()
            .unwrap()
            .len(),
        2
    );
    let dir = temp_dir_with(&[("compass.toml", "leg_mass = 5\nslope = 0.0523598775598\n")]);
    let run = command_in(
        dir,
        "gait",
        &["--model", "compass", "--config", "compass.toml"],
    );
    assert_eq!(run.code(), Some(0), "{}", run.stderr());
    let gait: Value = serde_json::from_str(&run.read("gait.json")).unwrap();
    let section = gait["gait"]["section"].as_object().unwrap();
    let names: Vec<&str> = section.keys().map(String::as_str).collect();
    assert_eq!(names.len(), 3, "{section:?}");
    assert!(["theta1", "theta1_dot", "theta2_dot"]
        .iter()
        .all(|n| section.contains_key(*n)));
    assert!(gait["gait"]["period"].as_f64().unwrap() > 0.0);
    assert!(gait["gait"]["lambda_I4"].as_f64().unwrap() < 0.0);
    assert!(run.stdout().contains("stable"), "{}", run.stdout());
}

/// A walker's bad input names the problem: an unknown model, a key it does not have, a bad value, a start of
/// the wrong size, a derivative in a parameter it does not have.
#[test]
fn bad_walker_input_names_the_problem() {
    let cases: [(&[&str], &str); 6] = [
        (&["--model", "biped"], "unknown model \"biped\""),
        (
            &["--model", "simplest", "--set", "slope=1e-400"],
            "too small for a 64-bit float",
        ),
        (
            &["--model", "simplest", "--set", "viscosity=3"],
            "unknown key `viscosity`",
        ),
        (
            &["--model", "compass", "--set", "hip_mass=-1"],
            "`hip_mass`",
        ),
        (
            &["--model", "simplest", "--initial", "0.2"],
            "the section of `simplest` has 2",
        ),
        (
            &["--model", "simplest", "--parameter", "hip_mass"],
            "`hip_mass` is not a parameter of the model `simplest`",
        ),
    ];
    for (args, needle) in cases {
        let run = command_in(temp_dir_with(&[]), "gait", args);
        assert_error(&run, &[needle]);
        assert!(!run.out.join("gait.json").exists(), "{args:?}");
    }
}

/// `vrw gait --model compass --check-jacobian --parameter slope` compares the exact `DP` and `dP/dp` with
/// extrapolated central differences: they agree, gait.json holds the check and `dP_dparam`, and the multipliers
/// are said to be the exact `DP`'s.
#[test]
fn a_walkers_exact_derivatives_are_checked() {
    let args = [
        "--model",
        "compass",
        "--check-jacobian",
        "--parameter",
        "slope",
    ];
    let run = command_in(temp_dir_with(&[]), "gait", &args);
    assert_eq!(run.code(), Some(0), "{}", run.stderr());
    assert!(run.stdout().contains("agree"), "{}", run.stdout());
    let gait: Value = serde_json::from_str(&run.read("gait.json")).unwrap();
    let check = &gait["jacobian_check"];
    assert_eq!(check["agree"], true, "{check}");
    assert!(check["difference"].as_f64().unwrap() < 1e-8, "{check}");
    assert_eq!(check["exact"][0].as_array().unwrap().len(), 4, "{check}");
    let d = &gait["gait"]["dP_dparam"];
    assert_eq!(d["parameter"], "slope");
    assert!(d["values"]["theta1"].as_f64().unwrap().is_finite(), "{d}");
    assert!(gait["gait"]["derivative"]
        .as_str()
        .unwrap()
        .starts_with("exact"));
}

/// `vrw continue --model simplest --param slope` follows the simplest walker's gaits and locates their period
/// doubling near `slope = 0.0151` (the paper's 0.015), written to special_points.json with branch.csv.
#[test]
fn continue_locates_the_simplest_walkers_period_doubling() {
    let args = [
        "--model", "simplest", "--param", "slope", "--from", "0.005", "--to", "0.017", "--start",
        "0.009",
    ];
    let run = command_in(temp_dir_with(&[]), "continue", &args);
    assert_eq!(run.code(), Some(0), "{}", run.stderr());
    let summary: Value = serde_json::from_str(&run.read("special_points.json")).unwrap();
    let special = summary["special_points"].as_array().unwrap();
    assert_eq!(special.len(), 1, "{summary}");
    assert_eq!(special[0]["kind"], "PD");
    assert_eq!(special[0]["located"], true);
    let value = special[0]["value"].as_f64().unwrap();
    assert!((value - 0.0150884).abs() < 1e-6, "{value}");
    let branch = run.read("branch.csv");
    assert!(branch.starts_with("slope,theta,theta_dot,largest_multiplier,period,lambda_I4"));
    assert!(data_rows(&branch) > 20);
    let run = command_in(
        temp_dir_with(&[]),
        "continue",
        &[
            "--model",
            "compass",
            "--two-param",
            "leg_mass",
            "--two-range",
            "4,6",
        ],
    );
    assert_error(&run, &["`--two-param`"]);
}
