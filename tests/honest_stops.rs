//! Honest stops and safe directories (issue 39): Ctrl-C in every phase of a job is answered at once and never
//! turns into a result (a family end, a curve, a complete run), a second Ctrl-C never leaves a run `running`,
//! options and the output directory are checked before the work, and nothing vrw did not write is removed.

mod common;

use common::{assert_error, json, ok, simulated, stderr, vrw};

use std::fs;
use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

fn manifest(dir: &Path) -> Value {
    serde_json::from_str(&fs::read_to_string(dir.join("manifest.json")).unwrap()).unwrap()
}

fn spawn(args: &[&str], dir: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_vrw"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn sigint(child: &Child) {
    let sent = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
}

/// Wait until `ready` holds (at most a minute), then a little longer, so that the job is in the phase
/// `ready` marks.
fn wait_for(ready: impl Fn() -> bool, then: Duration) {
    let clock = Instant::now();
    while !ready() && clock.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(10));
    }
    assert!(ready(), "the job never reached the phase to interrupt");
    std::thread::sleep(then);
}

/// `vrw continue` interrupted while it follows a family (Ctrl-C used to be saved as a completed run whose
/// family "ends at 50.000000000 (interrupted at 49.999999995)"): `interrupted`, exit 1, no figure, the points
/// followed kept and the cut ends named `interrupted`, never an end with a cause.
#[test]
fn ctrl_c_in_continue_is_not_a_family_end() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("C");
    let args = [
        "continue",
        "--set",
        "friction=0.105",
        "--out",
        out.to_str().unwrap(),
    ];
    let child = spawn(&args, tmp.path());
    // The first gait takes a fraction of a second; the family several seconds.
    std::thread::sleep(Duration::from_millis(2500));
    sigint(&child);
    let output = child.wait_with_output().unwrap();
    assert_error(&output, &["interrupted (Ctrl-C)", "branch.csv"]);
    let m = manifest(&out);
    assert_eq!(m["status"], "interrupted");
    assert_eq!(
        m["files"],
        serde_json::json!(["branch.csv", "special_points.json"])
    );
    assert!(!out.join("bifurcation.png").exists());
    let summary = json(&out.join("special_points.json"));
    assert!(summary["interrupted"].is_string(), "{summary}");
    let ends: Vec<&Value> = summary["families"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|f| f["ends"].as_array().unwrap())
        .collect();
    assert!(ends.iter().any(|e| e["kind"] == "interrupted"), "{ends:?}");
    assert!(
        ends.iter().all(|e| e["failure"] != "interrupted"),
        "an interrupt became a family end: {ends:?}"
    );
    let rows = fs::read_to_string(out.join("branch.csv")).unwrap();
    assert!(rows.lines().count() > 2, "no point kept");
}

/// Ctrl-C in the map's curve phase (it used to run on to the end and say `completed`): `interrupted`, the
/// complete `map.csv` kept, no curve.
#[test]
fn ctrl_c_in_the_map_curve_phase_keeps_the_map_only() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("M");
    let grid = ["map", "--nx", "21", "--ny", "21", "--out"];
    let whole = tmp.path().join("whole");
    ok(&vrw(
        &[&grid[..], &[whole.to_str().unwrap()]].concat(),
        tmp.path(),
    ));
    let child = spawn(&[&grid[..], &[out.to_str().unwrap()]].concat(), tmp.path());
    // map.csv is written when the gaits are done: the curves (four fifths of the work) follow.
    wait_for(|| out.join("map.csv").exists(), Duration::from_millis(300));
    sigint(&child);
    let output = child.wait_with_output().unwrap();
    assert_error(
        &output,
        &[
            "interrupted (Ctrl-C) while tracing the threshold curves",
            "map.csv",
        ],
    );
    let m = manifest(&out);
    assert_eq!(m["status"], "interrupted");
    assert_eq!(m["files"], serde_json::json!(["map.csv"]));
    assert!(!out.join("curves.json").exists() && !out.join("map.png").exists());
    assert_eq!(
        fs::read(out.join("map.csv")).unwrap(),
        fs::read(whole.join("map.csv")).unwrap()
    );
}

/// `vrw gait` answers Ctrl-C (it used to exit 130 without a word): exit 1, a message, nothing written.
#[test]
fn ctrl_c_in_gait_says_so_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("G");
    let child = spawn(
        &[
            "gait",
            "--transient",
            "20000",
            "--out",
            out.to_str().unwrap(),
        ],
        tmp.path(),
    );
    std::thread::sleep(Duration::from_millis(800));
    sigint(&child);
    let output = child.wait_with_output().unwrap();
    assert_error(
        &output,
        &[
            "interrupted (Ctrl-C) while searching the gait",
            "nothing is written",
        ],
    );
    assert!(!out.join("manifest.json").exists());
}

/// The gait search of another walker (`--model`) answers Ctrl-C as the wheel's does: exit 1, a message that
/// names no manifest, nothing written.
#[test]
fn ctrl_c_in_a_walkers_gait_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("W");
    let args = [
        "gait",
        "--model",
        "simplest",
        "--transient",
        "10000000",
        "--out",
        out.to_str().unwrap(),
    ];
    let child = spawn(&args, tmp.path());
    std::thread::sleep(Duration::from_millis(800));
    sigint(&child);
    let output = child.wait_with_output().unwrap();
    assert_error(
        &output,
        &[
            "interrupted (Ctrl-C) while searching the gait",
            "nothing is written",
        ],
    );
    assert!(
        !stderr(&output).contains("manifest.json"),
        "{}",
        stderr(&output)
    );
    assert!(!out.join("manifest.json").exists());
}

/// A second Ctrl-C right after the first quits at once, but the manifest says `interrupted`, never
/// `running`.
#[test]
fn a_second_ctrl_c_leaves_the_run_interrupted() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("S");
    let child = spawn(
        &["sweep", "--points", "300", "--out", out.to_str().unwrap()],
        tmp.path(),
    );
    wait_for(
        || out.join("manifest.json").exists(),
        Duration::from_millis(200),
    );
    sigint(&child);
    std::thread::sleep(Duration::from_millis(2));
    sigint(&child);
    let output: Output = child.wait_with_output().unwrap();
    let code = output.status.code();
    assert!(
        matches!(code, Some(1 | 130)),
        "{code:?}: {}",
        stderr(&output)
    );
    assert_eq!(
        manifest(&out)["status"],
        "interrupted",
        "{}",
        stderr(&output)
    );
    let temporary = fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .find(|n| n.contains(".vrw-tmp"));
    assert_eq!(temporary, None);
}

/// `vrw animate` interrupted while it encodes: exit 1, no GIF and no temporary GIF left.
#[test]
fn ctrl_c_in_animate_leaves_no_temporary_gif() {
    let (tmp, sim) = simulated("20");
    let child = spawn(
        &[
            "animate",
            sim.to_str().unwrap(),
            "--fps",
            "50",
            "--speed",
            "0.1",
        ],
        tmp.path(),
    );
    wait_for(
        || sim.join(".walk.vrw-tmp.gif").exists(),
        Duration::from_millis(200),
    );
    sigint(&child);
    let output = child.wait_with_output().unwrap();
    assert_error(
        &output,
        &["interrupted (Ctrl-C)", "no animation is written"],
    );
    assert!(!sim.join("walk.gif").exists());
    assert!(!sim.join(".walk.vrw-tmp.gif").exists());
    assert_eq!(manifest(&sim)["status"], "completed");
}

/// A directory of files vrw did not write is refused, naming them, and every file stays (`vrw gait --out
/// mydir` used to delete a user's `fig2.png`, `map.csv`, `basin.png` and `run.svg`).
#[test]
fn a_users_files_are_never_removed() {
    let tmp = tempfile::tempdir().unwrap();
    let mine = tmp.path().join("mydir");
    fs::create_dir(&mine).unwrap();
    let files = ["basin.png", "fig2.png", "map.csv", "run.svg"];
    for f in files {
        fs::write(mine.join(f), "mine").unwrap();
    }
    for command in ["gait", "simulate", "sweep"] {
        let output = vrw(&[command, "--out", "mydir", "--overwrite"], tmp.path());
        assert_error(
            &output,
            &[
                "files vrw did not write",
                "basin.png, fig2.png, map.csv, run.svg",
            ],
        );
    }
    for f in files {
        assert_eq!(fs::read_to_string(mine.join(f)).unwrap(), "mine");
    }
}

/// Another command's run is refused (`vrw sweep --out s; vrw gait --out s` used to remove the sweep without a
/// word); with `--overwrite` it is replaced and the removed files are listed.
#[test]
fn another_commands_run_is_replaced_only_when_asked() {
    let tmp = tempfile::tempdir().unwrap();
    ok(&vrw(&["sweep", "--points", "3", "--out", "s"], tmp.path()));
    let s = tmp.path().join("s");
    assert_error(
        &vrw(&["gait", "--out", "s"], tmp.path()),
        &["holds a run of `vrw sweep`", "sweep.csv", "--overwrite"],
    );
    assert!(s.join("sweep.csv").exists() && s.join("fig2.png").exists());
    let replaced = vrw(&["gait", "--out", "s", "--overwrite"], tmp.path());
    let printed = ok(&replaced);
    assert!(
        stderr(&replaced).contains("removing fig2.png, fig2.svg, sweep.csv, thresholds.json"),
        "{}",
        stderr(&replaced)
    );
    assert!(!s.join("sweep.csv").exists());
    assert_eq!(manifest(&s)["replaced"]["command"], "sweep");
    // Every file written is named, the manifest among them.
    assert!(
        printed.contains(
            "wrote s/{manifest.json, gait.json, steps.csv, trajectory.csv, summary.json}"
        ),
        "{printed}"
    );
}

/// `continue --two-param` is checked before the continuation (its bad range used to be rejected after a
/// second of work, and at a start with no gait the gait's failure was reported instead).
#[test]
fn continue_checks_its_second_parameter_first() {
    let tmp = tempfile::tempdir().unwrap();
    let output = vrw(
        &[
            "continue",
            "--set",
            "viscosity=200",
            "--two-param",
            "viscosity",
            "--two-range",
            "1,2",
        ],
        tmp.path(),
    );
    assert_error(
        &output,
        &["--two-param", "other than the followed parameter"],
    );
    assert!(!tmp.path().join("out/continue/manifest.json").exists());
}

/// Every figure's title names the keys that differ from the defaults (Fig. 2 of a sweep with friction said
/// nothing of mu), and the orbit diagram draws the indicator asked for.
#[test]
fn figures_say_what_they_were_made_with() {
    let tmp = tempfile::tempdir().unwrap();
    ok(&vrw(
        &[
            "sweep",
            "--set",
            "friction=0.6",
            "--points",
            "3",
            "--out",
            "s",
        ],
        tmp.path(),
    ));
    let svg = fs::read_to_string(tmp.path().join("s/fig2.svg")).unwrap();
    assert!(svg.contains("μ = 0.6"), "no μ in Fig. 2's title");
    let orbit = [
        "orbit",
        "--points",
        "3",
        "--transient",
        "2",
        "--steps",
        "2",
        "--no-branch",
    ];
    ok(&vrw(
        &[&orbit[..], &["--plot", "lambda_4_plus", "--out", "o"]].concat(),
        tmp.path(),
    ));
    let refused = vrw(
        &[&orbit[..], &["--plot", "speed", "--out", "o2"]].concat(),
        tmp.path(),
    );
    assert!(!refused.status.success());
    assert!(stderr(&refused).contains("lambda_2_plus, lambda_4_plus"));
}
