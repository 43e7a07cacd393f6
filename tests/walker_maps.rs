//! `vrw map --model M` and `vrw basin --model M` for the walkers other than the wheel (docs/model.md section
//! 13), run through the binary: a small map and basin of each rigid walker, and bad input named.

#[allow(dead_code)]
mod common;

use std::fs;

use common::{assert_error, json, ok, table, vrw};

/// `vrw map --model compass` over (slope, leg_mass_offset): a row per point named by the model's section, the
/// summary's counts adding up to the grid, the figure, the manifest.
#[test]
fn a_small_map_of_the_compass_gait() {
    let tmp = tempfile::tempdir().unwrap();
    let printed = ok(&vrw(
        &[
            "map",
            "--model",
            "compass",
            "--x",
            "slope",
            "--x-from",
            "0.06",
            "--x-to",
            "0.08",
            "--nx",
            "5",
            "--y",
            "leg_mass_offset",
            "--y-from",
            "0.4",
            "--y-to",
            "0.5",
            "--ny",
            "2",
            "--out",
            "m",
        ],
        tmp.path(),
    ));
    assert!(printed.contains("vrw map --model compass"), "{printed}");
    assert!(printed.contains("period_doubling"), "{printed}");
    let out = tmp.path().join("m");
    let (header, rows) = table(&out.join("map.csv"));
    assert_eq!(
        header[..6],
        [
            "slope",
            "leg_mass_offset",
            "status",
            "theta1",
            "theta1_dot",
            "theta2_dot"
        ]
    );
    assert!(
        header.contains(&"lambda_I4".to_string()) && header.contains(&"max_floquet".to_string())
    );
    assert_eq!(rows.len(), 10);
    let summary = json(&out.join("map.json"));
    assert_eq!(summary["model"], "compass");
    assert_eq!(summary["x"]["param"], "slope");
    let counted: u64 = summary["statuses"]
        .as_object()
        .unwrap()
        .values()
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert_eq!(counted, 10);
    assert_eq!(
        &fs::read(out.join("map.png")).unwrap()[..8],
        b"\x89PNG\r\n\x1a\n"
    );
    let manifest = json(&out.join("manifest.json"));
    assert_eq!(manifest["command"], "map");
    assert_eq!(manifest["status"], "completed");
}

/// `vrw basin --model M` for the simplest walker and the compass gait: a row per start named by the section,
/// counts per outcome adding up to the grid, the gait reached from its own cell, the figure.
#[test]
fn a_small_basin_of_each_walker() {
    let tmp = tempfile::tempdir().unwrap();
    let cases: [(&str, &[&str], [&str; 2]); 2] = [
        (
            "simplest",
            &["--set", "slope=0.009"],
            ["theta", "theta_dot"],
        ),
        (
            "compass",
            &["--x", "theta1_dot", "--y", "theta2_dot"],
            ["theta1_dot", "theta2_dot"],
        ),
    ];
    for (model, extra, axes) in cases {
        let out = format!("b-{model}");
        let mut args = vec![
            "basin", "--model", model, "--nx", "5", "--ny", "4", "--out", &out,
        ];
        args.extend_from_slice(extra);
        let printed = ok(&vrw(&args, tmp.path()));
        assert!(
            printed.contains(&format!("vrw basin --model {model}")),
            "{printed}"
        );
        let dir = tmp.path().join(&out);
        let (header, rows) = table(&dir.join("basin.csv"));
        assert_eq!(header[..2], ["ix", "iy"]);
        assert!(header.contains(&axes[0].to_string()) && header.contains(&axes[1].to_string()));
        assert!(header.contains(&"outcome".to_string()));
        assert_eq!(rows.len(), 20);
        let summary = json(&dir.join("basin.json"));
        assert_eq!(summary["model"], model);
        assert_eq!(summary["x"]["coordinate"], axes[0]);
        let counted: u64 = summary["outcomes"]
            .as_object()
            .unwrap()
            .values()
            .map(|v| v.as_u64().unwrap())
            .sum();
        assert_eq!(counted, 20, "{summary}");
        assert_eq!(summary["gait"]["stability"], "stable");
        assert_eq!(
            &fs::read(dir.join("basin.png")).unwrap()[..8],
            b"\x89PNG\r\n\x1a\n"
        );
    }
}

/// Bad input names the problem and writes nothing: an unknown parameter key, a model with one parameter, an
/// empty range, a section coordinate that does not exist, the same coordinate twice, an option only the
/// wheel's map has.
#[test]
fn bad_map_and_basin_input_is_named() {
    let tmp = tempfile::tempdir().unwrap();
    // The map's options with `changed` (flag, value) in place of the defaults here.
    let map = |changed: &[&'static str]| {
        let mut args = vec![
            "map", "--model", "compass", "--x", "slope", "--x-from", "0.05", "--x-to", "0.06",
            "--y", "hip_mass", "--y-from", "9", "--y-to", "11", "--out", "m",
        ];
        for pair in changed.chunks(2) {
            match args.iter().position(|a| *a == pair[0]) {
                Some(at) => args[at + 1] = pair[1],
                None => args.extend_from_slice(pair),
            }
        }
        args
    };
    let cases: Vec<(Vec<&str>, &[&str])> = vec![
        (
            map(&["--y", "hip_weight"]),
            &["`--y`", "hip_weight", "hip_mass"],
        ),
        (map(&["--x-to", "0.05"]), &["`--x-from/--x-to`", "both"]),
        (map(&["--ny", "1"]), &["`--ny`"]),
        (map(&["--y", "slope"]), &["different"]),
        (map(&["--mark", "0.05,10"]), &["`--mark`", "compass"]),
        (
            vec![
                "map", "--model", "simplest", "--x", "slope", "--y", "gravity", "--out", "m",
            ],
            &["simplest", "gravity", "slope"],
        ),
        (
            vec!["basin", "--model", "compass", "--x", "theta3", "--out", "b"],
            &["`--x`", "theta3", "theta1, theta1_dot, theta2_dot"],
        ),
        (
            vec![
                "basin", "--model", "compass", "--x", "theta1", "--y", "theta1", "--out", "b",
            ],
            &["`--x/--y`", "different"],
        ),
        (
            vec![
                "basin",
                "--model",
                "simplest",
                "--x-range",
                "0.2,0.2",
                "--out",
                "b",
            ],
            &["`--x-range`", "two different"],
        ),
    ];
    for (args, needles) in cases {
        assert_error(&vrw(&args, tmp.path()), needles);
    }
    for dir in ["m", "b"] {
        assert!(!tmp.path().join(dir).exists(), "{dir}");
    }
}

/// Ctrl-C stops a walker's map or basin once its grid is under way: exit status 1, `interrupted` in the
/// manifest, the complete points in the table (fewer than the grid's) and no summary (never a finished result).
#[cfg(unix)]
#[test]
fn interrupted_map_and_basin_keep_their_complete_points() {
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};
    let tmp = tempfile::tempdir().unwrap();
    let cases: [(&[&str], &str, &str, usize); 2] = [
        (
            &[
                "map", "--model", "compass", "--x", "slope", "--x-from", "0.04", "--x-to", "0.09",
                "--nx", "2000", "--y", "hip_mass", "--y-from", "5", "--y-to", "15", "--ny", "2000",
                "--out",
            ],
            "map.csv",
            "map.json",
            4_000_000,
        ),
        (
            &[
                "basin",
                "--model",
                "compass",
                "--nx",
                "2000",
                "--ny",
                "2000",
                "--max-steps",
                "100000",
                "--tolerance",
                "1e-12",
                "--out",
            ],
            "basin.csv",
            "basin.json",
            4_000_000,
        ),
    ];
    for (args, table_file, summary_file, total) in cases {
        let out = tmp.path().join(args[0]);
        let mut child = Command::new(env!("CARGO_BIN_EXE_vrw"))
            .args(args)
            .arg(&out)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let started = Instant::now();
        while !out.join("manifest.json").exists() {
            assert!(
                started.elapsed() < Duration::from_secs(60),
                "no run started"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
        std::thread::sleep(Duration::from_millis(300));
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
        assert_eq!(json(&out.join("manifest.json"))["status"], "interrupted");
        assert!(!out.join(summary_file).exists(), "{stderr}");
        let (_, rows) = table(&out.join(table_file));
        assert!(rows.len() < total, "{stderr}");
    }
}
