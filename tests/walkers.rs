//! The jobs of the walkers other than the wheel (`--model simplest|compass|telescopic`; docs/model.md section 13), run
//! through the binary: `simulate`, `sweep`, `orbit`, `plot` and `animate` of their runs, Ctrl-C, and the jobs
//! a walker cannot do yet refusing it by name.

// The helpers every test binary shares; this one does not walk the wheel (`simulated`).
#[allow(dead_code)]
mod common;

use std::fs;
use std::path::Path;
use std::process::Command;

use common::{assert_error, json, ok, table, vrw};
use serde_json::Value;

/// `vrw simulate --model M` writes the walk named by the model's coordinates, and `vrw plot` and
/// `vrw animate` draw it.
#[test]
fn simulate_plot_and_animate_each_walker() {
    let cases: [(&str, &[&str], &[&str]); 2] = [
        ("simplest", &["theta", "theta_dot"], &["theta", "phi"]),
        (
            "compass",
            &["theta1", "theta1_dot", "theta2_dot"],
            &["x", "z", "theta1", "theta2"],
        ),
    ];
    for (model, section, coordinates) in cases {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("sim");
        let o = out.to_str().unwrap();
        let printed = ok(&vrw(
            &["simulate", "--model", model, "--steps", "4", "--out", o],
            tmp.path(),
        ));
        assert!(printed.contains(&format!("--model {model}")), "{printed}");
        let (header, rows) = table(&out.join("steps.csv"));
        assert_eq!(&header[2..2 + section.len()], section, "{header:?}");
        assert!(
            header.contains(&"lambda_I4".to_string())
                && header.contains(&"energy_drift".to_string())
        );
        assert_eq!(rows.len(), 4);
        let lambda = header.iter().position(|h| h == "lambda_I4").unwrap();
        assert!(rows.iter().all(|r| r[lambda].parse::<f64>().unwrap() < 0.0));
        let (trajectory, samples) = table(&out.join("trajectory.csv"));
        assert_eq!(
            &trajectory[3..3 + coordinates.len()],
            coordinates,
            "{trajectory:?}"
        );
        assert!(trajectory.contains(&"hip_x".to_string()) && samples.len() > 100);
        let summary = json(&out.join("summary.json"));
        assert_eq!(summary["model"], model);
        assert_eq!(summary["status"], "completed");
        assert_eq!(summary["steps_completed"], 4);
        assert!(
            summary["max_energy_drift"].as_f64().unwrap() < 1e-9,
            "{summary}"
        );
        let manifest = json(&out.join("manifest.json"));
        assert_eq!(manifest["command"], "simulate");
        // The manifest names the walker (the wheel's has no `model`: its files are as before).
        assert_eq!(manifest["model"], model);
        ok(&vrw(&["plot", o], tmp.path()));
        ok(&vrw(&["animate", o, "--still", "1.0"], tmp.path()));
        ok(&vrw(
            &["animate", o, "--speed", "4", "--fps", "10"],
            tmp.path(),
        ));
        let listed = json(&out.join("manifest.json"))["files"].to_string();
        for f in ["run.png", "run.svg", "walk-frame.png", "walk.gif"] {
            assert!(out.join(f).is_file() && listed.contains(f), "{f}: {listed}");
        }
    }
}

/// `vrw sweep --model M --param slope` continues the gait along the slope and bisects where it loses
/// stability: the period doublings that `vrw continue` locates (0.015088438 and 0.076635632 rad).
#[test]
fn sweep_bisects_each_walkers_period_doubling() {
    let cases = [
        ("simplest", "0.013", "0.016", 0.015088438),
        ("compass", "0.07", "0.08", 0.076635632),
    ];
    for (model, from, to, doubling) in cases {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("sweep");
        let args = [
            "sweep",
            "--model",
            model,
            "--param",
            "slope",
            "--from",
            from,
            "--to",
            to,
            "--points",
            "6",
            "--out",
            out.to_str().unwrap(),
        ];
        ok(&vrw(&args, tmp.path()));
        let (header, rows) = table(&out.join("sweep.csv"));
        assert_eq!(header[0], "slope");
        assert!(header.contains(&"max_floquet".to_string()));
        assert_eq!(rows.len(), 6);
        assert_eq!(rows[0][1], "stable");
        assert_eq!(rows[5][1], "unstable");
        let thresholds = json(&out.join("thresholds.json"));
        assert_eq!(thresholds["model"], model);
        let found = &thresholds["thresholds"][0];
        assert_eq!(found["kind"], "period_doubling", "{thresholds}");
        let value = found["value"].as_f64().unwrap();
        assert!((value - doubling).abs() < 2e-9, "{model}: {value}");
    }
}

/// `vrw orbit --model simplest --param slope`: period 1 below the period doubling, and above it (slope
/// 0.016) the walk alternates between two distinct stance angles, read from orbit.csv.
#[test]
fn orbit_of_the_simplest_walker_doubles_its_period() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("orbit");
    let args = [
        "orbit",
        "--model",
        "simplest",
        "--param",
        "slope",
        "--from",
        "0.010",
        "--to",
        "0.016",
        "--points",
        "4",
        "--transient",
        "300",
        "--steps",
        "8",
        "--out",
        out.to_str().unwrap(),
    ];
    ok(&vrw(&args, tmp.path()));
    let (header, rows) = table(&out.join("orbit.csv"));
    assert_eq!(
        header[..5],
        ["slope", "status", "period_k", "step", "theta"].map(String::from)
    );
    let thetas = |slope: &str| -> Vec<f64> {
        rows.iter()
            .filter(|r| r[0] == slope)
            .map(|r| r[4].parse().unwrap())
            .collect()
    };
    let (below, above) = (thetas("0.014"), thetas("0.016"));
    assert_eq!((below.len(), above.len()), (8, 8));
    assert!(
        below.windows(2).all(|w| (w[0] - w[1]).abs() < 1e-6),
        "{below:?}"
    );
    assert!((above[0] - above[1]).abs() > 1e-3, "{above:?}");
    assert!(
        above.windows(3).all(|w| (w[0] - w[2]).abs() < 1e-6),
        "{above:?}"
    );
    assert!(rows.iter().filter(|r| r[0] == "0.016").all(|r| r[2] == "2"));
    // The paper's long-period gait (a step of about 3.9 time units), followed from slope 0.010.
    assert!(
        rows.iter().all(|r| r[7].parse::<f64>().unwrap() > 3.5),
        "{rows:?}"
    );
    let summary = json(&out.join("orbit.json"));
    assert_eq!(summary["outcomes"]["period_2"], 1, "{summary}");
    assert!(out.join("orbit.png").is_file() && out.join("branch.csv").is_file());
    let (_, branch) = table(&out.join("branch.csv"));
    assert_eq!(branch.last().unwrap().last().unwrap(), "unstable");
}

/// The compass gait's orbit diagram: one stance angle at 0.07 rad, two at 0.08 (past the period doubling), the section named by its coordinates.
#[test]
fn orbit_of_the_compass_gait() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("orbit");
    let args = [
        "orbit",
        "--model",
        "compass",
        "--param",
        "slope",
        "--from",
        "0.07",
        "--to",
        "0.08",
        "--points",
        "3",
        "--transient",
        "150",
        "--steps",
        "4",
        "--no-branch",
        "--out",
        out.to_str().unwrap(),
    ];
    ok(&vrw(&args, tmp.path()));
    let (header, rows) = table(&out.join("orbit.csv"));
    assert_eq!(
        header[4..7],
        ["theta1", "theta1_dot", "theta2_dot"].map(String::from)
    );
    assert_eq!(rows[0][2], "1");
    assert_eq!(rows[8][2], "2", "{rows:?}");
    assert!(!out.join("branch.csv").exists());
}

/// Ctrl-C stops a walker's long walk: exit status 1, the complete steps in steps.csv, `interrupted` in
/// summary.json and the manifest (never a finished result).
#[cfg(unix)]
#[test]
fn interrupted_walker_walk_keeps_its_complete_steps() {
    use std::time::{Duration, Instant};
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("sim");
    let mut child = Command::new(env!("CARGO_BIN_EXE_vrw"))
        .args([
            "simulate",
            "--model",
            "simplest",
            "--steps",
            "10000000",
            "--no-trajectory",
            "--out",
        ])
        .arg(&out)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let rows = |p: &Path| fs::read_to_string(p).map_or(0, |s| s.lines().count().saturating_sub(1));
    let started = Instant::now();
    while rows(&out.join("steps.csv")) < 3 {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "no steps streamed"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap()
        .success());
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "vrw did not stop"
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut stderr = String::new();
    std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut stderr).unwrap();
    assert_eq!(status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("interrupted"), "{stderr}");
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["status"], "interrupted");
    assert_eq!(json(&out.join("manifest.json"))["status"], "interrupted");
    let completed = summary["steps_completed"].as_u64().unwrap() as usize;
    assert!(completed >= 3);
    assert_eq!(rows(&out.join("steps.csv")), completed);
}

/// Options only the wheel has, a parameter the model lacks, and `plot` of a walker's gait run (which holds no
/// walk) are refused, named (`map` and `basin`: tests/walker_maps.rs).
#[test]
fn jobs_a_walker_cannot_do_say_so() {
    let tmp = tempfile::tempdir().unwrap();
    let cases: [(&[&str], &[&str]); 4] = [
        (
            &[
                "sweep",
                "--model",
                "simplest",
                "--param",
                "viscosity",
                "--out",
                "s",
            ],
            &["viscosity", "slope"],
        ),
        (
            &[
                "sweep",
                "--model",
                "compass",
                "--param",
                "slope",
                "--second-route",
                "--out",
                "s",
            ],
            &["`--second-route`"],
        ),
        (
            &[
                "orbit", "--model", "simplest", "--param", "slope", "--from", "0.01", "--to",
                "0.01",
            ],
            &["`--from/--to`"],
        ),
        (
            &[
                "simulate",
                "--model",
                "compass",
                "--initial",
                "0.2,1",
                "--out",
                "c",
            ],
            &["`compass` has 3"],
        ),
    ];
    for (args, needles) in cases {
        let run = vrw(args, tmp.path());
        assert_error(&run, needles);
    }
    for dir in ["s", "c"] {
        assert!(
            !tmp.path().join(dir).join("manifest.json").exists(),
            "{dir}"
        );
    }
    ok(&vrw(
        &["gait", "--model", "simplest", "--out", "g"],
        tmp.path(),
    ));
    assert_error(
        &vrw(&["plot", "g"], tmp.path()),
        &["`vrw gait`", "`simplest`", "simulate"],
    );
}

/// `vrw gait --model telescopic`: the compass gait with the paper's telescopic legs walks with double support
/// after its heel strike, its energy audit closed, and a bad parameter is refused by name.
#[test]
fn the_telescopic_biped_walks_with_double_support() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("tel");
    let printed = ok(&vrw(
        &[
            "gait",
            "--model",
            "telescopic",
            "--out",
            out.to_str().unwrap(),
        ],
        tmp.path(),
    ));
    assert!(printed.contains("branch DLS"), "{printed}");
    let gait = json(&out.join("gait.json"));
    assert_eq!(gait["model"], "telescopic");
    assert_eq!(gait["status"], "found");
    let g = &gait["gait"];
    let legged = &g["legged"];
    assert_eq!(legged["branch"], "DLS");
    assert!(g["lambda_I4"].as_f64().unwrap() > 0.0);
    assert!(legged["dls_duration"].as_f64().unwrap() > 1e-3, "{g}");
    assert!(
        legged["energy_residual"].as_f64().unwrap().abs() < 1e-9,
        "{g}"
    );
    assert!(g["largest_multiplier"].as_f64().unwrap() < 1.0, "{g}");
    assert_eq!(g["derivative"], "exact_replay");
    assert!(g["jacobian_error"].as_f64().unwrap() < 1e-6, "{g}");
    let section: Vec<&str> = g["section"]
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    assert_eq!(section.len(), 5, "{section:?}");
    let refused = vrw(
        &[
            "gait",
            "--model",
            "telescopic",
            "--set",
            "foot_mass=-1",
            "--out",
            out.to_str().unwrap(),
        ],
        tmp.path(),
    );
    assert_error(&refused, &["foot_mass"]);
}

/// `vrw gait --model telescopic --parameter viscosity --check-jacobian` writes the exact `dP/dp` (`dP_dparam`,
/// said exact) and the check of the exact `DP | dP/dp` against Richardson-extrapolated differences
/// (`jacobian_check`, agreeing within their error estimates), and the walker's description in
/// `models/telescopic.toml` gives the same numbers to 1e-9; a key the walker does not have is refused, naming
/// its keys.
#[test]
fn the_telescopic_walkers_derivatives_are_checked() {
    let tmp = tempfile::tempdir().unwrap();
    let description = concat!(env!("CARGO_MANIFEST_DIR"), "/models/telescopic.toml");
    let run = |model: &str, out: &str| {
        let out = tmp.path().join(out);
        let args = [
            "gait",
            "--model",
            model,
            "--parameter",
            "viscosity",
            "--check-jacobian",
            "--out",
            out.to_str().unwrap(),
        ];
        let printed = ok(&vrw(&args, tmp.path()));
        assert!(printed.contains("dP/dviscosity = [theta1 "), "{printed}");
        assert!(printed.contains(": agree"), "{printed}");
        json(&out.join("gait.json"))
    };
    let (built_in, described) = (run("telescopic", "b"), run(description, "d"));
    let numbers = |gait: &Value| -> Vec<f64> {
        let check = &gait["jacobian_check"];
        assert_eq!(check["agree"], true, "{check}");
        assert_eq!(check["parameter"], "viscosity");
        let difference = check["difference"].as_f64().unwrap();
        let errors = check["exact_error"].as_f64().unwrap()
            + check["finite_difference_error"].as_f64().unwrap();
        assert!(difference <= errors && difference < 1e-7, "{check}");
        let exact: Vec<Vec<f64>> = serde_json::from_value(check["exact"].clone()).unwrap();
        assert_eq!((exact.len(), exact[0].len()), (5, 6), "{check}");
        let d = &gait["gait"]["dP_dparam"];
        assert_eq!(d["parameter"], "viscosity");
        assert_eq!(d["derivative"], "exact_replay");
        assert!(d.get("error").is_none(), "{d}");
        let section = ["theta1", "L2", "theta1_dot", "theta2_dot", "L2_dot"];
        let values: Vec<f64> = section
            .iter()
            .map(|n| d["values"][n].as_f64().unwrap())
            .collect();
        // The check's exact last column is dP/dp.
        let column: Vec<f64> = exact.iter().map(|row| row[5]).collect();
        assert_eq!(values, column);
        exact.into_iter().flatten().collect()
    };
    let (a, b) = (numbers(&built_in), numbers(&described));
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() <= 1e-9 * x.abs().max(1e-3), "{x} against {y}");
    }
    for model in ["telescopic", description] {
        let refused = vrw(
            &["gait", "--model", model, "--parameter", "stifness"],
            tmp.path(),
        );
        assert_error(
            &refused,
            &[
                "`stifness` is not a parameter of the model",
                "viscosity, gravity",
            ],
        );
    }
}

/// Regression (the spurious heel strike at the legs' coincidence): at slope 0.014 from the default start,
/// `vrw gait --model simplest` once found a 1.69-time-unit "gait" and `vrw simulate` walked onto it; every
/// step of either is now a real heel strike (the paper's steps last about 3 time units or more: this start's
/// walk falls after 3 of them, the stance foot lifting off, and the search says so).
#[test]
fn the_simplest_walker_has_no_short_spurious_gait_at_slope_0_014() {
    let tmp = tempfile::tempdir().unwrap();
    let gait_out = tmp.path().join("gait");
    let run = vrw(
        &[
            "gait",
            "--model",
            "simplest",
            "--set",
            "slope=0.014",
            "--out",
        ]
        .into_iter()
        .chain([gait_out.to_str().unwrap()])
        .collect::<Vec<_>>(),
        tmp.path(),
    );
    let gait = json(&gait_out.join("gait.json"));
    let period = gait["gait"]["period"].as_f64();
    assert!(period.is_none_or(|p| p > 3.0), "{gait}");
    if period.is_none() {
        assert_error(
            &run,
            &["no gait found", "stance foot would leave the ground"],
        );
    }
    let sim = tmp.path().join("sim");
    let o = sim.to_str().unwrap();
    let _ = vrw(
        &[
            "simulate",
            "--model",
            "simplest",
            "--set",
            "slope=0.014",
            "--steps",
            "30",
            "--out",
            o,
        ],
        tmp.path(),
    );
    let (header, rows) = table(&sim.join("steps.csv"));
    let column = header.iter().position(|h| h == "period").unwrap();
    assert!(!rows.is_empty());
    for row in &rows {
        let p: f64 = row[column].parse().unwrap();
        assert!(p > 3.0, "a step of {p} time units: {rows:?}");
    }
}

/// `vrw simulate --model telescopic` writes the legged walk's account in `steps.csv` (branch, DLS duration,
/// audits) and its springs in the drawing, and `vrw plot` and `vrw animate` draw it; `--initial` of the wrong
/// length and an unknown `--param` are refused by name.
#[test]
fn the_telescopic_biped_simulates_and_is_drawn() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("sim");
    let o = out.to_str().unwrap();
    let args = [
        "simulate",
        "--model",
        "telescopic",
        "--steps",
        "3",
        "--out",
        o,
    ];
    ok(&vrw(&args, tmp.path()));
    let (header, rows) = table(&out.join("steps.csv"));
    assert_eq!(
        &header[2..7],
        ["theta1", "L2", "theta1_dot", "theta2_dot", "L2_dot"]
    );
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    assert_eq!(rows.len(), 3);
    for r in &rows {
        assert_eq!(r[col("branch")], "DLS");
        assert!(r[col("dls_duration")].parse::<f64>().unwrap() > 1e-3);
        assert!(r[col("energy_residual")].parse::<f64>().unwrap().abs() < 1e-9);
    }
    let (trajectory, _) = table(&out.join("trajectory.csv"));
    assert_eq!(
        &trajectory[3..9],
        ["x", "z", "theta1", "theta2", "L1", "L2"]
    );
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["figure"]["springs"].as_array().unwrap().len(), 2);
    assert!(
        summary["last_step"]["legged"]["dls_duration"]
            .as_f64()
            .unwrap()
            > 1e-3
    );
    ok(&vrw(&["plot", o], tmp.path()));
    ok(&vrw(&["animate", o, "--still", "1.0"], tmp.path()));
    let wrong = vrw(
        &[
            "simulate",
            "--model",
            "telescopic",
            "--initial",
            "0.28,1",
            "--out",
            "w",
        ],
        tmp.path(),
    );
    assert_error(
        &wrong,
        &[
            "initial",
            "2 values",
            "theta1, L2, theta1_dot, theta2_dot, L2_dot",
        ],
    );
    let unknown = vrw(
        &[
            "continue",
            "--model",
            "telescopic",
            "--param",
            "stifness",
            "--out",
            "c",
        ],
        tmp.path(),
    );
    assert_error(&unknown, &["stifness", "stiffness", "viscosity"]);
    let unknown = vrw(
        &[
            "sweep",
            "--model",
            "telescopic",
            "--param",
            "leg_length",
            "--out",
            "s",
        ],
        tmp.path(),
    );
    assert_error(&unknown, &["leg_length", "stopper_length"]);
}

/// `vrw continue --model telescopic --param viscosity`: a gait on the family (`branch.csv`) is the gait
/// `vrw gait --set viscosity=VALUE` finds there, to 1e-9, and the family's derivatives are said to be
/// Richardson differences.
#[test]
fn the_telescopic_family_holds_the_gaits_of_vrw_gait() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("cont");
    let args = [
        "continue",
        "--model",
        "telescopic",
        "--param",
        "viscosity",
        "--from",
        "950",
        "--to",
        "1050",
        "--max-points",
        "3",
        "--out",
    ];
    let o = out.to_str().unwrap();
    ok(&vrw(
        &args.iter().copied().chain([o]).collect::<Vec<_>>(),
        tmp.path(),
    ));
    let summary = json(&out.join("special_points.json"));
    let route = summary["derivative"].as_str().unwrap();
    assert!(route.starts_with("exact"), "{route}");
    let (header, rows) = table(&out.join("branch.csv"));
    assert_eq!(
        &header[1..6],
        ["theta1", "L2", "theta1_dot", "theta2_dot", "L2_dot"]
    );
    let row = rows
        .iter()
        .find(|r| r[0] != "1000")
        .expect("a point off the start");
    let gait_out = tmp.path().join("gait");
    let set = format!("viscosity={}", row[0]);
    let gait_args = ["gait", "--model", "telescopic", "--set", &set, "--out"];
    let g = gait_out.to_str().unwrap();
    ok(&vrw(
        &gait_args.iter().copied().chain([g]).collect::<Vec<_>>(),
        tmp.path(),
    ));
    let gait = json(&gait_out.join("gait.json"));
    for (k, name) in header[1..6].iter().enumerate() {
        let family: f64 = row[1 + k].parse().unwrap();
        let found = gait["gait"]["section"][name].as_f64().unwrap();
        assert!(
            (family - found).abs() < 1e-9,
            "{name}: {family} against {found}"
        );
    }
}
