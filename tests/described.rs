//! The jobs with `--model path/to/walker.toml` (docs/model.md section 13): the shipped compass gait description
//! walks the built-in's gait (`gait`, `continue`) and walks (`simulate`, `sweep`, `orbit`, `plot`, `animate`), the shipped wheel says what it lacks, and a bad
//! description stops the program with the line of the problem.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A shipped description.
fn model(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("models")
        .join(name)
}

/// `vrw <args> --out <dir>/out` in a fresh temporary directory holding `files`.
fn vrw(args: &[&str], files: &[(&str, &str)]) -> (Output, tempfile::TempDir) {
    let dir = tempfile::tempdir().expect("a temporary directory");
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).expect("a test file");
    }
    let output = Command::new(env!("CARGO_BIN_EXE_vrw"))
        .args(args)
        .arg("--out")
        .arg(dir.path().join("out"))
        .current_dir(dir.path())
        .output()
        .expect("the vrw binary runs");
    (output, dir)
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// The described compass gait finds the built-in's gait at 3 degrees: the same printed lines but the model's
/// name, and the same gait.json but the name.
#[test]
fn the_described_compass_walks_from_the_command_line() {
    let path = model("compass.toml");
    let set = ["--set", "slope=0.0523598775598"];
    let (described, d1) = vrw(
        &[&["gait", "--model", path.to_str().unwrap()][..], &set].concat(),
        &[],
    );
    let (built_in, d2) = vrw(&[&["gait", "--model", "compass"][..], &set].concat(), &[]);
    assert!(described.status.success(), "{}", text(&described.stderr));
    assert!(built_in.status.success(), "{}", text(&built_in.stderr));
    let out = text(&described.stdout);
    assert!(out.starts_with("vrw gait --model compass-toml: "), "{out}");
    assert!(
        out.contains("theta1 = 0.271028680, theta1_dot = -1.092383590, theta2_dot = -0.377373949"),
        "{out}"
    );
    let lines = |o: &str| {
        o.lines()
            .skip(1)
            .filter(|l| !l.starts_with("wrote"))
            .map(String::from)
            .collect::<Vec<_>>()
    };
    assert_eq!(lines(&out), lines(&text(&built_in.stdout)));
    let json =
        |d: &tempfile::TempDir| std::fs::read_to_string(d.path().join("out/gait.json")).unwrap();
    assert_eq!(
        json(&d1).replace("\"compass-toml\"", "\"compass\""),
        json(&d2)
    );
}

/// `--config` and `--set` take the description's parameters; an unknown key or a value outside its domain is
/// refused with its name.
#[test]
fn the_description_parameters_are_set_like_any_walkers() {
    let path = model("compass.toml");
    let p = path.to_str().unwrap();
    let (ok, _d) = vrw(
        &["gait", "--model", p, "--config", "c.toml"],
        &[("c.toml", "slope = 0.06\nhip_mass = 8\n")],
    );
    assert!(ok.status.success(), "{}", text(&ok.stderr));
    assert!(
        text(&ok.stdout).contains("hip_mass = 8.0") && text(&ok.stdout).contains("slope = 0.06")
    );
    for (set, needle) in [
        (
            "hip_mass=-1",
            "invalid value -1 for `hip_mass`: it must be above 0",
        ),
        ("legs=8", "unknown key `legs`"),
        ("slope=2", "it must be at most 1.5"),
    ] {
        let (bad, _d) = vrw(&["gait", "--model", p, "--set", set], &[]);
        assert_eq!(bad.status.code(), Some(1), "{set}");
        assert!(
            text(&bad.stderr).contains(needle),
            "{set}: {}",
            text(&bad.stderr)
        );
    }
}

/// A bad description file stops the program (exit code 1, no panic) with the file, the line and the problem;
/// the wheel's description says what it lacks to walk.
#[test]
fn a_bad_description_names_its_line() {
    let good = std::fs::read_to_string(model("compass.toml")).unwrap();
    let bad = good.replacen("kind = \"revolute\"", "kind = \"hinge\"", 1);
    let line = 1 + bad[..bad.find("\"hinge\"").unwrap()].matches('\n').count();
    let (run, _d) = vrw(&["gait", "--model", "bad.toml"], &[("bad.toml", &bad)]);
    let err = text(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains(&format!("bad.toml line {line}: unknown variant `hinge`")),
        "{err}"
    );
    let wheel = model("wheel.toml");
    let (run, _d) = vrw(&["gait", "--model", wheel.to_str().unwrap()], &[]);
    let err = text(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{err}");
    assert!(
        err.contains("cannot walk: its joints L1, L2, L3 have stoppers (3 telescopic legs)")
            && err.contains("takes two legs that take turns")
            && err.contains("`--model vrw`"),
        "{err}"
    );
    let (run, _d) = vrw(
        &["continue", "--model", "missing.toml", "--param", "slope"],
        &[],
    );
    assert_eq!(run.status.code(), Some(1));
    assert!(
        text(&run.stderr).contains("missing.toml"),
        "{}",
        text(&run.stderr)
    );
}

/// `vrw continue --model models/compass.toml --param slope` locates the built-in compass gait's period doubling.
#[test]
fn the_described_compass_continues_in_the_slope() {
    let path = model("compass.toml");
    let args = [
        "continue",
        "--model",
        path.to_str().unwrap(),
        "--param",
        "slope",
        "--from",
        "0.04",
        "--to",
        "0.08",
    ];
    let (run, _d) = vrw(&args, &[]);
    let out = text(&run.stdout);
    assert!(run.status.success(), "{}", text(&run.stderr));
    assert!(out.contains("PD at slope = 0.076635632"), "{out}");
}

/// `vrw simulate`, `sweep` and `orbit` of the described compass gait walk the built-in's walk: the same files
/// but the model's name and the drawing's points (the description's: its masses, feet and hinges), which lie
/// where the built-in's do; `plot` and `animate` draw the run.
#[test]
fn the_described_compass_walks_every_walker_job() {
    let path = model("compass.toml");
    let path = path.to_str().unwrap();
    let jobs: [&[&str]; 3] = [
        &["simulate", "--steps", "3"],
        &[
            "sweep", "--param", "slope", "--from", "0.04", "--to", "0.06", "--points", "3",
        ],
        &[
            "orbit", "--param", "slope", "--from", "0.06", "--to", "0.07", "--points", "3",
        ],
    ];
    for job in jobs {
        let (described, d1) = vrw(&[job, &["--model", path]].concat(), &[]);
        let (built_in, d2) = vrw(&[job, &["--model", "compass"]].concat(), &[]);
        assert!(
            described.status.success(),
            "{job:?}: {}",
            text(&described.stderr)
        );
        assert!(
            built_in.status.success(),
            "{job:?}: {}",
            text(&built_in.stderr)
        );
        let body = |o: &Output| {
            text(&o.stdout)
                .lines()
                .skip(1)
                .map(String::from)
                .collect::<Vec<_>>()
        };
        let wrote = |o: &Output| {
            body(o)
                .into_iter()
                .map(|l| {
                    l.replace(&d1.path().display().to_string(), "")
                        .replace(&d2.path().display().to_string(), "")
                })
                .collect::<Vec<_>>()
        };
        assert_eq!(wrote(&described), wrote(&built_in), "{job:?}");
        let csv = if job[0] == "simulate" {
            "steps.csv"
        } else {
            &format!("{}.csv", job[0])
        };
        let read = |d: &tempfile::TempDir| {
            std::fs::read_to_string(d.path().join("out").join(csv)).unwrap()
        };
        assert_eq!(read(&d1), read(&d2), "{job:?}: {csv}");
    }
    // The trajectory: the same coordinates and energies; the described hip and feet where the built-in's are.
    let (_, d1) = vrw(&["simulate", "--steps", "2", "--model", path], &[]);
    let (_, d2) = vrw(&["simulate", "--steps", "2", "--model", "compass"], &[]);
    let table = |d: &tempfile::TempDir| {
        let text = std::fs::read_to_string(d.path().join("out/trajectory.csv")).unwrap();
        let mut lines = text.lines();
        let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
        let rows: Vec<Vec<f64>> = lines
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect();
        (header, rows)
    };
    let ((h1, r1), (h2, r2)) = (table(&d1), table(&d2));
    assert_eq!(r1.len(), r2.len());
    let column = |h: &[String], name: &str| {
        h.iter()
            .position(|c| c == name)
            .unwrap_or_else(|| panic!("{name}"))
    };
    for (a, b) in [
        ("energy", "energy"),
        ("theta1", "theta1"),
        ("hip_x", "hip_x"),
        ("hip_z", "hip_z"),
        ("foot1_x", "stance_foot_x"),
        ("foot2_z", "swing_foot_z"),
        ("theta1_hinge_z", "hip_z"),
        ("leg2_x", "swing_leg_mass_x"),
    ] {
        let (i, j) = (column(&h1, a), column(&h2, b));
        for (x, y) in r1.iter().zip(&r2) {
            assert!(
                (x[i] - y[j]).abs() < 1e-12,
                "{a} {} against {b} {}",
                x[i],
                y[j]
            );
        }
    }
    for job in [&["plot"][..], &["animate", "--still", "0.5"]] {
        let run = Command::new(env!("CARGO_BIN_EXE_vrw"))
            .args(job)
            .arg(d1.path().join("out"))
            .output()
            .unwrap();
        assert!(run.status.success(), "{job:?}: {}", text(&run.stderr));
    }
    assert!(
        d1.path().join("out/run.png").exists() && d1.path().join("out/walk-frame.png").exists()
    );
}

/// `vrw gait --model models/telescopic.toml` runs the compliant walk's gait search and finds the built-in
/// telescopic walker's gait: the same printed gait, heel strike, period and multipliers (all but the model's
/// name, the Newton residual and the energy audit's last digits), and `gait.json` with the same section; its
/// simulated steps are the built-in's.
#[test]
fn the_described_telescopic_walker_walks_from_the_command_line() {
    let path = model("telescopic.toml");
    let (described, d1) = vrw(&["gait", "--model", path.to_str().unwrap()], &[]);
    let (built_in, d2) = vrw(&["gait", "--model", "telescopic"], &[]);
    assert!(described.status.success(), "{}", text(&described.stderr));
    assert!(built_in.status.success(), "{}", text(&built_in.stderr));
    let out = text(&described.stdout);
    assert!(
        out.starts_with("vrw gait --model telescopic-toml: "),
        "{out}"
    );
    let lines = |o: &str| {
        o.lines()
            .skip(1)
            .filter(|l| !l.starts_with("wrote") && !l.starts_with("energy audit"))
            .map(|l| l.split(" (residual").next().unwrap_or(l).to_string())
            // Both DPs are exact, from two section maps: the three multipliers that are not 0 alone, after the
            // route (the two at 0 come out real or as a pair at 1e-9).
            .map(|l| match l.strip_prefix("Floquet multipliers (") {
                Some(rest) => rest.split_once("): ").map_or(l.clone(), |(_, m)| {
                    m.split(", ").take(3).collect::<Vec<_>>().join(", ")
                }),
                None => l,
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(lines(&out), lines(&text(&built_in.stdout)));
    assert!(out.contains("branch DLS"), "{out}");
    let json = |d: &tempfile::TempDir| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(d.path().join("out/gait.json")).unwrap())
            .unwrap()
    };
    let (j1, j2) = (json(&d1), json(&d2));
    assert_eq!(j1["model"], "telescopic-toml");
    assert_eq!(j1["parameters"], j2["parameters"]);
    let section = |j: &serde_json::Value| -> Vec<(String, f64)> {
        j["gait"]["section"]
            .as_object()
            .unwrap()
            .iter()
            .map(|(k, v)| (k.clone(), v.as_f64().unwrap()))
            .collect()
    };
    for ((n1, v1), (n2, v2)) in section(&j1).into_iter().zip(section(&j2)) {
        assert_eq!(n1, n2);
        assert!((v1 - v2).abs() < 1e-10, "{n1}: {v1} {v2}");
    }
    // It walks in the other walker jobs too: two steps of `simulate` print the built-in's lines.
    let two = ["simulate", "--steps", "2", "--model"];
    let (described, _d1) = vrw(&[&two[..], &[path.to_str().unwrap()]].concat(), &[]);
    let (built_in, _d2) = vrw(&[&two[..], &["telescopic"]].concat(), &[]);
    assert!(described.status.success(), "{}", text(&described.stderr));
    let steps = |o: &Output| {
        text(&o.stdout)
            .lines()
            .filter(|l| l.starts_with("step ") || l.starts_with("its heel strike"))
            .map(|l| l.split("; energy audit").next().unwrap_or(l).to_string())
            .collect::<Vec<_>>()
    };
    assert_eq!(steps(&described), steps(&built_in));
    assert!(!steps(&described).is_empty());
}
