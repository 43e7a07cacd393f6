//! One compilation of the core for every build (`hack/Cargo.toml`): the crates the core depends on get the same
//! features in `cargo build`, in `cargo test` (whose dev-dependencies turn on more) and in the Python extension
//! (whose pyo3 and numpy do), so none of the three compiles `vrw` again. A dependency update that turns on a new
//! feature in one of them fails here, naming the crate and the features to add to `hack/Cargo.toml`.

use std::collections::BTreeMap;
use std::process::Command;

/// Each package of `cargo tree -p PACKAGE -e EDGES` (name and version) with its features.
fn features(package: &str, edges: &str) -> BTreeMap<String, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string());
    let output = Command::new(cargo)
        .args(["tree", "--locked", "-p", package, "-e", edges])
        .args(["--prefix", "none", "--no-dedupe", "-f", "{p}|{f}"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo tree runs");
    assert!(
        output.status.success(),
        "cargo tree -p {package} -e {edges}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8_lossy(&output.stdout)
        .lines()
        .filter_map(|line| {
            let (package, features) = line.split_once('|')?;
            // `name vX.Y.Z (path)` or `name vX.Y.Z (*)`: the name and version.
            let id: Vec<&str> = package.split_whitespace().take(2).collect();
            let features = features.trim_end_matches(" (*)").to_string();
            Some((id.join(" "), features))
        })
        .collect()
}

#[test]
fn the_core_builds_with_the_same_features_for_tests_binary_and_extension() {
    let build = features("vrw", "features,normal");
    let others = [
        ("cargo test", features("vrw", "features,normal,dev")),
        (
            "the Python extension",
            features("vrw-python", "features,normal"),
        ),
    ];
    let mut differences = Vec::new();
    for (which, other) in &others {
        for (package, wanted) in &build {
            match other.get(package) {
                Some(got) if got != wanted => differences.push(format!(
                    "{package}: [{wanted}] in cargo build, [{got}] in {which}"
                )),
                _ => {}
            }
        }
    }
    assert!(
        build.len() > 20 && others.iter().all(|(_, o)| o.len() > build.len()),
        "cargo tree listed too few packages: {build:?}"
    );
    assert!(
        differences.is_empty(),
        "the core would be compiled again (add the features to hack/Cargo.toml):\n{}",
        differences.join("\n")
    );
}
