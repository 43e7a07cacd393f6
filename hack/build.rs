//! Empty: a build script makes the `[build-dependencies]` of `Cargo.toml` count in feature unification.
fn main() {}
