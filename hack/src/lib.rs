//! Feature unification for the vrw workspace: no code. See `Cargo.toml`.
