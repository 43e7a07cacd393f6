//! Every value that reaches the library is checked where it enters, with the command line's rules and
//! messages: regression tests named after the symptoms a hostile tester found (unchecked values, unbounded
//! work, messages that named the wrong thing).

use std::path::Path;
use std::process::{Command, Output};

use vrw::dynamics::Model;
use vrw::gait::{find_gait, GaitError, GaitOptions, StepMap};
use vrw::params::{Config, ConfigError, MAX_CONFIG_BYTES};
use vrw::reference::default_initial;
use vrw::study::sweep_values;

/// `vrw <args>` in a fresh temporary directory (kept alive by the returned guard).
fn vrw(args: &[&str]) -> (Output, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_vrw"))
        .args(args)
        .current_dir(dir.path())
        .output()
        .unwrap();
    (output, dir)
}

/// The run failed with exit code 1, no panic, and an error that contains every one of `needles`.
fn assert_refused(output: &Output, needles: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    for needle in needles {
        assert!(stderr.contains(needle), "no {needle:?} in: {stderr}");
    }
    stderr
}

/// Sweeps a value list with the default settings (no progress).
fn sweep_list(config: &Config, param: &str, values: &[f64]) -> Result<usize, ConfigError> {
    let initial = default_initial(config);
    sweep_values(
        config,
        param,
        values,
        &initial,
        &GaitOptions::for_sweeps(),
        &|_| {},
    )
    .map(|points| points.len())
}

/// `vrw.sweep(Params(), "viscosity", [1, 2, -1])` reported `gait_found` at the domain's edge (1.19e-7) as if it
/// were a physical threshold: the value is refused before anything is computed, naming it and the rule.
#[test]
fn sweep_viscosity_list_with_minus_one_is_refused_not_a_gait_found_threshold() {
    let error = sweep_list(&Config::default(), "viscosity", &[1.0, 2.0, -1.0]).unwrap_err();
    let message = error.to_string();
    assert!(
        message.contains("`sweep viscosity`") && message.contains("-1"),
        "{message}"
    );
    assert!(
        message.contains("value 3 of 3") && message.contains("must be non-negative"),
        "{message}"
    );
    let error = sweep_list(&Config::default(), "viscosity", &[1.0, f64::NAN]).unwrap_err();
    assert!(error.to_string().contains("not a finite number"), "{error}");
}

/// `vrw.sweep(Params(), "rtol", [1e-10, 1.0])` reported a `gait_lost` at 0.00099993 (the edge of rtol's range).
#[test]
fn sweep_rtol_to_one_is_refused_not_a_gait_lost_threshold() {
    let error = sweep_list(&Config::default(), "rtol", &[1e-10, 1.0]).unwrap_err();
    let message = error.to_string();
    assert!(
        message.contains("`sweep rtol`") && message.contains("must be between 1e-14 and 0.001"),
        "{message}"
    );
}

/// `vrw.find_gait(p, fd_step=1e-16)` said "unstable" with a multiplier of 1430 (true: 0.044), and
/// `fd_step <= 1e-18` hung: the search refuses the setting before it starts.
#[test]
fn find_gait_with_fd_step_1e_minus_16_is_refused_not_unstable() {
    let config = Config::default();
    let model = Model::new(&config.params).unwrap();
    let map = StepMap::new(&model, &config.solver);
    for fd_step in [1e-16, 1e-18, 0.0] {
        let options = GaitOptions {
            fd_step,
            ..GaitOptions::default()
        };
        let error = find_gait(&map, &default_initial(&config), &options, None).unwrap_err();
        assert!(matches!(error, GaitError::InvalidOptions { .. }), "{error}");
        assert_eq!(error.kind(), "invalid_options");
        assert!(error.to_string().contains("`fd_step`"), "{error}");
    }
}

/// `vrw gait --transient 0 --tolerance 1` returned the start as a gait.
#[test]
fn gait_transient_0_tolerance_1_is_refused_not_the_start_as_a_gait() {
    let (output, _dir) = vrw(&["gait", "--transient", "0", "--tolerance", "1"]);
    assert_refused(
        &output,
        &["`--tolerance`", "must be between 1e-13 and 1e-6"],
    );
}

/// `vrw gait --transient 100000000` ran on for hours.
#[test]
fn gait_transient_100000000_is_refused() {
    let (output, _dir) = vrw(&["gait", "--transient", "100000000"]);
    assert_refused(&output, &["`--transient`", "100000000", "100000"]);
}

/// `--set viscosity=1e9` took 47 s and larger values ran on with no progress: legs that stiff are refused
/// naming the key and the time scale; stiff but workable legs draw a warning before the run.
#[test]
fn set_viscosity_1e9_is_refused_as_too_stiff_and_1e5_warns() {
    let error = Config::load(None, &["viscosity=1e9"]).unwrap_err();
    assert_eq!(error.key(), Some("viscosity"), "{error}");
    assert!(error.to_string().contains("too stiff"), "{error}");
    let error = Config::load(None, &["stiffness=1e13"]).unwrap_err();
    assert_eq!(error.key(), Some("stiffness"), "{error}");
    // Rigid legs have no leg dynamics: nothing to refuse.
    Config::load(None, &["viscosity=1e9", "rigid_legs=true"]).unwrap();

    let (output, _dir) = vrw(&["simulate", "--set", "viscosity=1e9", "--steps", "1"]);
    assert_refused(&output, &["`viscosity`", "too stiff"]);
    let (output, _dir) = vrw(&["simulate", "--set", "viscosity=1e5", "--steps", "1"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("warning: stiff legs") && stderr.contains("`viscosity`"),
        "{stderr}"
    );
}

/// `--config` naming a FIFO waited for a writer for ever: it is refused before it is opened.
#[test]
fn config_fifo_is_refused_without_waiting() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("params.toml");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|s| s.success()) {
        return; // no mkfifo here: nothing to check
    }
    let (send, receive) = std::sync::mpsc::channel();
    let path = fifo.clone();
    std::thread::spawn(move || send.send(Config::from_file(&path).map(|_| ())));
    let error = receive
        .recv_timeout(std::time::Duration::from_secs(20))
        .expect("reading a FIFO as --config hangs")
        .unwrap_err();
    assert!(error.to_string().contains("a pipe"), "{error}");
}

/// `--config /dev/zero` read forever (6.7 GB after 8 s): only a regular file of at most
/// `MAX_CONFIG_BYTES` is read.
#[test]
fn config_dev_zero_and_a_huge_file_are_refused_not_read_forever() {
    if Path::new("/dev/zero").exists() {
        let error = Config::from_file(Path::new("/dev/zero")).unwrap_err();
        assert!(
            matches!(error, ConfigError::NotAConfigFile { .. }),
            "{error}"
        );
        assert!(error.to_string().contains("not a regular file"), "{error}");
        let (output, _dir) = vrw(&["simulate", "--config", "/dev/zero"]);
        assert_refused(&output, &["/dev/zero", "not a regular file"]);
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.toml");
    let comment = format!("# {}\n", "x".repeat(1000));
    let text = comment.repeat(MAX_CONFIG_BYTES as usize / comment.len() + 1);
    std::fs::write(&path, text).unwrap();
    let error = Config::from_file(&path).unwrap_err();
    assert!(error.to_string().contains("larger than"), "{error}");
    let error = Config::from_file(dir.path()).unwrap_err();
    assert!(error.to_string().contains("directory"), "{error}");
}

/// `vrw animate DIR --speed 1e-9` aborted allocating 675 GB: the frame count is computed first and refused
/// above the limit, naming the options that set it.
#[test]
fn animate_speed_1e_minus_9_is_refused_before_allocating_frames() {
    let (output, dir) = vrw(&["simulate", "--steps", "1", "--out", "run"]);
    assert!(output.status.success(), "{output:?}");
    let run = dir.path().join("run");
    let output = Command::new(env!("CARGO_BIN_EXE_vrw"))
        .args(["animate", run.to_str().unwrap(), "--speed", "1e-9"])
        .output()
        .unwrap();
    assert_refused(&output, &["--speed", "--fps", "frames"]);
}

/// `map --y-from 0` said `--from` and "sweep viscosity"; `map --nx 1` stated the sweep's limit.
#[test]
fn map_y_from_0_names_y_from_and_map_nx_1_states_the_maps_limit() {
    let (output, _dir) = vrw(&["map", "--y-from", "0"]);
    let stderr = assert_refused(
        &output,
        &["`--y-from` 0", "map y stiffness", "must be positive"],
    );
    assert!(
        !stderr.contains("sweep") && !stderr.contains(" --from"),
        "{stderr}"
    );
    let (output, _dir) = vrw(&["map", "--nx", "1"]);
    let stderr = assert_refused(&output, &["`--nx` 1", "map x takes between 2 and 2000"]);
    assert!(!stderr.contains("100000"), "{stderr}");
}

/// `1e300` was printed with 301 digits; `1e-400` must not silently become 0.
#[test]
fn huge_and_tiny_values_print_short_and_are_not_rounded_to_zero() {
    let error = Config::load(None, &["hub_mass=-1e300"]).unwrap_err();
    let message = error.to_string();
    assert!(
        message.contains("-1e300") && message.len() < 200,
        "{message}"
    );
    let error = Config::load(None, &["viscosity=1e-400"]).unwrap_err();
    assert_eq!(error.key(), Some("viscosity"), "{error}");
}

/// A rule between two keys reported only the first broken rule: every problem of one input is listed,
/// each naming the key the user gave.
#[test]
fn rules_between_keys_report_every_problem_naming_the_given_keys() {
    let error = Config::load(
        None,
        &["stopper_length=0.2", "spring_natural_length=0.1", "rtol=1"],
    )
    .unwrap_err();
    let keys: Vec<_> = error.problems().iter().map(|e| e.key()).collect();
    assert_eq!(
        keys,
        [
            Some("stopper_length"),
            Some("spring_natural_length"),
            Some("rtol"),
            // fall_hub_height (default 0.3) must be below the stopper_length given.
            Some("stopper_length"),
        ],
        "{error}"
    );
    assert!(error.to_string().starts_with("4 problems: 1) "), "{error}");

    // Values of the wrong type are all listed too, not only the first.
    let error = Config::from_toml_str("legs = 8.5\nviscosity = \"a\"\nfoo = 1").unwrap_err();
    let mut keys: Vec<_> = error.problems().iter().filter_map(|e| e.key()).collect();
    keys.sort_unstable();
    assert_eq!(keys, ["foo", "legs", "viscosity"], "{error}");
}

/// A walk could only be interrupted at a touchdown, and a step with stiff legs takes millions of integrator
/// steps: the walker reads the interrupt flag every `INTERRUPT_CHECK_STEPS` integrator steps.
#[test]
fn interrupt_stops_a_step_in_progress_not_only_at_touchdowns() {
    use std::sync::atomic::{AtomicBool, Ordering};
    use vrw::walk::{WalkError, Walker};

    let config = Config::default();
    let model = Model::new(&config.params).unwrap();
    let flag = AtomicBool::new(false);
    let mut walker = Walker::new(&model, &config.solver, &default_initial(&config))
        .unwrap()
        .with_interrupt(Some(&flag));
    walker.step(None).unwrap();
    flag.store(true, Ordering::Relaxed);
    let error = walker.step(None).unwrap_err();
    assert!(matches!(error, WalkError::Interrupted { .. }), "{error}");
    assert_eq!(error.kind(), "interrupted");
}

/// A start with absurd rates is refused before the walk (`--initial 0.72,1,1e5` ran 72 s before it failed).
#[test]
fn initial_rates_beyond_any_walk_are_refused() {
    for (initial, field) in [("0.72,1,1e5", "L2dot"), ("0.72,1e5,0", "thetadot")] {
        let (output, _dir) = vrw(&["simulate", "--steps", "1", "--initial", initial]);
        assert_refused(&output, &[field, "100 sqrt(g L0)"]);
    }
    // Below the bound, the rate is the walk's to judge.
    let (output, _dir) = vrw(&["simulate", "--steps", "1", "--initial", "0.72,1,-50"]);
    assert!(!String::from_utf8_lossy(&output.stderr).contains("sqrt(g L0)"));
}

/// A message quotes at most 200 characters of what the user typed, however long (clap's and vrw's own).
#[test]
fn long_inputs_are_quoted_clipped() {
    let long = "9".repeat(5000);
    let cases = [
        vec![
            "simulate".to_string(),
            "--set".into(),
            format!("viscosity=x{long}"),
        ],
        vec!["simulate".to_string(), "--set".into(), format!("{long}=1")],
        vec![
            "simulate".to_string(),
            "--initial".into(),
            format!("0.7,{long}x"),
        ],
        vec!["basin".to_string(), "--x-range".into(), format!("1;{long}")],
        vec!["continue".to_string(), "--plot".into(), format!("q{long}")],
    ];
    for case in cases {
        let args: Vec<&str> = case.iter().map(String::as_str).collect();
        let (output, _dir) = vrw(&args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_ne!(output.status.code(), Some(0), "{stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert!(
            stderr.len() < 2500 && stderr.contains("characters in all"),
            "{} characters: {}",
            stderr.len(),
            &stderr[..stderr.len().min(600)]
        );
    }
}
