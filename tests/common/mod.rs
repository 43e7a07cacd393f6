//! Helpers shared by the integration tests that run the `vrw` binary on temporary directories.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use tempfile::TempDir;

/// Run the `vrw` binary with `args` in `dir`.
pub fn vrw(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_vrw"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("cannot run the vrw binary")
}

/// What the run printed on stderr.
pub fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// The run succeeded; returns what it printed on stdout.
pub fn ok(output: &Output) -> String {
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(
        output.status.success(),
        "vrw failed:\n{}\nstdout:\n{stdout}",
        stderr(output)
    );
    stdout
}

/// The run failed with exit code 1, without a panic, and its `Error:` line names every one of `needles`.
pub fn assert_error(output: &Output, needles: &[&str]) {
    let err = stderr(output);
    assert!(!err.contains("panicked"), "vrw panicked:\n{err}");
    assert_eq!(output.status.code(), Some(1), "exit code; stderr:\n{err}");
    let line = err
        .lines()
        .find(|l| l.starts_with("Error:"))
        .unwrap_or_else(|| panic!("no `Error:` line:\n{err}"));
    for needle in needles {
        assert!(
            line.contains(needle),
            "the error does not name {needle:?}: {line}"
        );
    }
}

/// A temporary directory holding a `vrw simulate --steps N` run in `sim/`.
pub fn simulated(steps: &str) -> (TempDir, PathBuf) {
    let tmp = tempfile::tempdir().expect("temporary directory");
    let out = tmp.path().join("sim");
    ok(&vrw(
        &["simulate", "--steps", steps, "--out", out.to_str().unwrap()],
        tmp.path(),
    ));
    (tmp, out)
}

/// The JSON file `path` (not every test binary reads one: hence the `allow`).
#[allow(dead_code)]
pub fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The header and the rows of the CSV file `path` (split at every comma: for files whose fields hold none).
#[allow(dead_code)]
pub fn table(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text
        .lines()
        .map(|l| l.split(',').map(String::from).collect::<Vec<_>>());
    (lines.next().unwrap(), lines.collect())
}
