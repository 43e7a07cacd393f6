//! Output directories that cannot lie: each holds one run (`manifest.json` lists its files and says whether it
//! finished), an earlier run's files are removed, a killed or interrupted run is recognised, and damaged or
//! impossible data is refused by `vrw plot` / `vrw animate` with the file, row and column.

mod common;

use common::{assert_error, ok, simulated, stderr, vrw};

use std::fs;
use std::path::Path;
use std::process::Command;

use serde_json::Value;

fn manifest(dir: &Path) -> Value {
    serde_json::from_str(&fs::read_to_string(dir.join("manifest.json")).unwrap()).unwrap()
}

/// Make `dir` look like a simulate killed with kill -9: the manifest still says `running`, and the
/// trajectory's last row is cut in the middle.
fn kill_9(dir: &Path) {
    let mut m = manifest(dir);
    m["status"] = "running".into();
    fs::write(dir.join("manifest.json"), m.to_string()).unwrap();
    let path = dir.join("trajectory.csv");
    let text = fs::read_to_string(&path).unwrap();
    fs::write(&path, &text[..text.len() - 7]).unwrap();
}

/// Replace `column` of data row `row` (from 1) of `dir/file` by `value`.
fn set_cell(dir: &Path, file: &str, row: usize, column: &str, value: &str) {
    let path = dir.join(file);
    let text = fs::read_to_string(&path).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let k = lines[0].split(',').position(|c| c == column).unwrap();
    let mut cells: Vec<String> = lines[row].split(',').map(String::from).collect();
    cells[k] = value.to_string();
    lines[row] = cells.join(",");
    fs::write(&path, lines.join("\n") + "\n").unwrap();
}

#[test]
fn gait_without_a_gait_leaves_no_earlier_gait_to_plot() {
    let tmp = tempfile::tempdir().unwrap();
    let g = tmp.path().join("G");
    let g = g.to_str().unwrap();
    ok(&vrw(&["gait", "--out", g], tmp.path()));
    ok(&vrw(&["plot", g], tmp.path()));
    let again = vrw(&["gait", "--set", "viscosity=200", "--out", g], tmp.path());
    assert_eq!(again.status.code(), Some(1));
    for stale in [
        "steps.csv",
        "trajectory.csv",
        "summary.json",
        "run.png",
        "steps.svg",
    ] {
        assert!(
            !Path::new(g).join(stale).exists(),
            "{stale} of the c = 50 run is left"
        );
    }
    let m = manifest(Path::new(g));
    assert_eq!(m["command"], "gait");
    assert_eq!(m["files"], serde_json::json!(["gait.json"]));
    assert_error(&vrw(&["plot", g], tmp.path()), &["found no gait"]);
}

#[test]
fn killed_simulate_is_not_titled_completed() {
    let (tmp, sim) = simulated("5");
    // A killed c = 30 run after a completed c = 50 one: the old summary.json must not describe it.
    kill_9(&sim);
    let dir = sim.to_str().unwrap();
    assert_error(
        &vrw(&["plot", dir], tmp.path()),
        &["did not finish (killed?)", "--partial"],
    );
    assert_error(
        &vrw(&["animate", dir], tmp.path()),
        &["did not finish", "--partial"],
    );
    let partial = vrw(&["plot", dir, "--partial"], tmp.path());
    ok(&partial);
    assert!(
        stderr(&partial).contains("trajectory.csv: the last row"),
        "{}",
        stderr(&partial)
    );
    assert!(fs::read_to_string(sim.join("run.svg"))
        .unwrap()
        .contains("partial"));
}

#[test]
fn simulate_writes_a_running_summary_before_the_walk() {
    let (tmp, sim) = simulated("3");
    let m = manifest(&sim);
    assert_eq!(m["status"], "completed");
    // The wheel's manifest names no model (a walker's does: tests/walkers.rs).
    assert!(m.get("model").is_none(), "{m}");
    assert_eq!(
        m["files"],
        serde_json::json!(["steps.csv", "trajectory.csv", "summary.json"])
    );
    // A repeated run writes the same bytes (no timestamps).
    let first = fs::read(sim.join("manifest.json")).unwrap();
    ok(&vrw(
        &["simulate", "--steps", "3", "--out", sim.to_str().unwrap()],
        tmp.path(),
    ));
    assert_eq!(fs::read(sim.join("manifest.json")).unwrap(), first);
}

#[test]
fn figures_of_an_earlier_run_are_removed() {
    let (tmp, sim) = simulated("3");
    let dir = sim.to_str().unwrap();
    ok(&vrw(&["plot", dir], tmp.path()));
    assert!(manifest(&sim)["files"]
        .as_array()
        .unwrap()
        .contains(&"run.png".into()));
    fs::write(sim.join("notes.txt"), "mine").unwrap();
    ok(&vrw(
        &["simulate", "--steps", "2", "--out", dir, "--no-trajectory"],
        tmp.path(),
    ));
    assert!(!sim.join("run.png").exists());
    assert!(!sim.join("trajectory.csv").exists());
    assert_eq!(fs::read_to_string(sim.join("notes.txt")).unwrap(), "mine");
}

#[test]
fn data_file_of_another_run_is_refused() {
    let (tmp, sim) = simulated("3");
    fs::write(sim.join("gait.json"), "{}").unwrap();
    let dir = sim.to_str().unwrap();
    assert_error(
        &vrw(&["plot", dir], tmp.path()),
        &["gait.json", "not in manifest.json"],
    );
    fs::remove_file(sim.join("gait.json")).unwrap();
    fs::remove_file(sim.join("manifest.json")).unwrap();
    assert_error(&vrw(&["plot", dir], tmp.path()), &["no manifest.json"]);
}

#[test]
fn impossible_trajectory_values_are_refused_with_row_and_column() {
    for (column, value) in [
        ("x", "1e300"),
        ("theta", "NaN"),
        ("leg1", "99999"),
        ("L2", "5"),
    ] {
        let (tmp, sim) = simulated("2");
        set_cell(&sim, "trajectory.csv", 7, column, value);
        let needles = ["trajectory.csv", "data row 7", &format!("column {column}")];
        assert_error(&vrw(&["plot", sim.to_str().unwrap()], tmp.path()), &needles);
        assert_error(
            &vrw(&["animate", sim.to_str().unwrap()], tmp.path()),
            &needles,
        );
    }
}

#[test]
fn read_only_output_directory_is_found_before_computing() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("a-file");
    fs::write(&file, "x").unwrap();
    let out = file.join("orbit");
    let started = std::time::Instant::now();
    assert_error(
        &vrw(&["orbit", "--out", out.to_str().unwrap()], tmp.path()),
        &["a-file"],
    );
    // The check comes before the 5 s of computation (a bound far above the check, far below the work).
    assert!(started.elapsed().as_secs_f64() < 3.0);
}

#[test]
fn ctrl_c_keeps_the_complete_points_of_an_orbit_diagram() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("O");
    let child = Command::new(env!("CARGO_BIN_EXE_vrw"))
        .args(["orbit", "--points", "400", "--out", out.to_str().unwrap()])
        .stderr(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Wait until the job has started (its manifest says `running`), then send SIGINT.
    let clock = std::time::Instant::now();
    while !out.join("manifest.json").exists() && clock.elapsed().as_secs() < 20 {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    std::thread::sleep(std::time::Duration::from_millis(300));
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let output = child.wait_with_output().unwrap();
    assert_error(&output, &["interrupted (Ctrl-C)", "orbit.csv"]);
    let m = manifest(&out);
    assert_eq!(m["status"], "interrupted");
    assert_eq!(m["files"], serde_json::json!(["orbit.csv"]));
    assert!(
        fs::read_to_string(out.join("orbit.csv"))
            .unwrap()
            .lines()
            .count()
            > 1
    );
    assert!(!out.join("orbit.png").exists());
}
