//! Speed of the orbit diagram and the basin (README, "Speed"), scaled down so that criterion can repeat them;
//! the full sizes are timed by the commands themselves (README, "Speed"):
//! `cargo run --release -- orbit --no-branch` (300 values x 64 steps) and
//! `cargo run --release -- basin --nx 200 --ny 200`.
//!
//! Run with `cargo bench --bench attractors` (add `-- --quick` for a fast estimate).
//!
//! - `orbit_30x64`: 30 viscosities from 1 to 150 N s/m, 32 transient and 64 recorded steps each (a tenth of the
//!   default diagram);
//! - `basin_20x20`: 400 starts on the default slice through the paper's gait (a hundredth of 200 x 200).

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};

use vrw::app::default_basin_range;
use vrw::dynamics::Model;
use vrw::gait::{find_gait, GaitOptions, StepMap};
use vrw::params::Config;
use vrw::reference::default_initial;
use vrw::study::basin::{basin, Axis, BasinSpec, Coordinate};
use vrw::study::orbit::{orbit_diagram, OrbitSpec};
use vrw::study::SweepSpec;

fn orbit(c: &mut Criterion) {
    let config = Config::default();
    let spec = OrbitSpec {
        range: SweepSpec {
            param: "viscosity".to_string(),
            from: 1.0,
            to: 150.0,
            points: 30,
        },
        transient: 32,
        steps: 64,
    };
    let start = default_initial(&config);
    c.bench_function("orbit_30x64", |b| {
        b.iter(|| black_box(orbit_diagram(&config, &spec, &start, &|_| {}).unwrap()))
    });
}

fn basin_grid(c: &mut Criterion) {
    let config = Config::default();
    let model = Model::new(&config.params).expect("the paper's parameters are valid");
    let map = StepMap::new(&model, &config.solver);
    let gait = find_gait(
        &map,
        &default_initial(&config),
        &GaitOptions::default(),
        None,
    )
    .expect("the paper's gait exists");
    let axis = |coordinate: Coordinate, at: f64| {
        let (from, to) = default_basin_range(&config, coordinate, at);
        Axis {
            coordinate,
            from,
            to,
            points: 20,
        }
    };
    let spec = BasinSpec {
        x: axis(Coordinate::L2, gait.section.l2),
        y: axis(Coordinate::ThetaDot, gait.section.theta_dot),
        through: gait.section,
        max_steps: 100,
        tolerance: 1e-3,
    };
    c.bench_function("basin_20x20", |b| {
        b.iter(|| black_box(basin(&model, &config.solver, &gait, &spec, &|_| {})))
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).measurement_time(Duration::from_secs(20));
    targets = orbit, basin_grid
}
criterion_main!(benches);
