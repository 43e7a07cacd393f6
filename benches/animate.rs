//! Speed of `vrw animate` and `vrw plot` on the default run: 20 steps from the reference start on the
//! paper's parameters (Table 1, c = 50 N s/m), about 52 s of motion.
//!
//! Run with `cargo bench --bench animate`. Target (README, "Speed"): the GIF of 20 steps at the defaults (25
//! frames/s, 640 x 360) in under 10 s and under 10 MB; the size is printed once before timing.
//!
//! - `animate_20_steps`: `write_animation` with the default options (reading the run directory excluded).
//! - `plot_20_steps`: `run.png`/`run.svg` and `steps.png`/`steps.svg`.
//!
//! The same can be timed end to end with the command line, which prints its own wall time:
//! `cargo run --release -- simulate && cargo run --release -- animate out/simulate`.

use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};

use vrw::app::{run_simulate, SimulateJob, DEFAULT_SAMPLE_DT};
use vrw::output::animate::{write_animation, AnimateOptions};
use vrw::output::read::{read_run, RunData};
use vrw::output::{run_plot, steps_plot};
use vrw::params::Config;

/// Steps of the benchmarked run.
const WALK_STEPS: usize = 20;

fn default_run(dir: &std::path::Path) -> RunData {
    let job = SimulateJob {
        config: Config::default(),
        initial: None,
        steps: WALK_STEPS,
        sample_dt: DEFAULT_SAMPLE_DT,
        trajectory: true,
        out_dir: dir.to_path_buf(),
        overwrite: false,
        interrupt: None,
    };
    run_simulate(&job, &mut |_| {}).expect("the default run walks");
    read_run(dir).expect("the run directory reads back")
}

fn animate(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("temporary directory");
    let run = default_run(dir.path());
    let gif = dir.path().join("walk.gif");
    let opts = AnimateOptions::default();
    let report = write_animation(&run, &opts, &gif).expect("animation");
    println!(
        "animate_20_steps: {} frames ({} slow motion), {:.2} MB",
        report.frames,
        report.slow_frames,
        report.bytes as f64 / 1e6
    );
    let mut group = c.benchmark_group("figures");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(30));
    group.bench_function("animate_20_steps", |b| {
        b.iter(|| write_animation(&run, &opts, &gif).expect("animation"))
    });
    group.bench_function("plot_20_steps", |b| {
        b.iter(|| {
            run_plot::write_run_figure(&run).expect("run figure");
            steps_plot::write_steps_figure(&run).expect("steps figure");
        })
    });
    group.finish();
}

criterion_group!(benches, animate);
criterion_main!(benches);
