//! The cost of one gait's exact `DP` against one step of the map, for an instruction counter (README, Speed):
//!
//! ```sh
//! CARGO_PROFILE_RELEASE_DEBUG=1 cargo build --release --example dp_cost   # source lines for callgrind_annotate
//! valgrind --tool=callgrind target/release/examples/dp_cost dp 40
//! valgrind --tool=callgrind target/release/examples/dp_cost eval 40
//! ```
//!
//! and `callgrind_annotate --inclusive=yes` on each output: the inclusive count of
//! `StepMap::eval_with_derivatives` (or `StepMap::eval`) over 40 is one call's. Without valgrind it prints the
//! wall time per call, which on a shared machine varies by up to 2x between hours.

use std::time::Instant;

use vrw::dynamics::Model;
use vrw::gait::{find_gait, GaitOptions, StepMap};
use vrw::params::Config;
use vrw::reference::default_initial;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let what = args.next().unwrap_or_else(|| "dp".to_string());
    let calls: u32 = args.next().map_or(Ok(40), |n| n.parse())?;
    if !matches!(what.as_str(), "dp" | "eval") || calls == 0 {
        return Err("usage: dp_cost [dp|eval] [calls > 0]".into());
    }
    let config = Config::default();
    let model = Model::new(&config.params)?;
    let map = StepMap::new(&model, &config.solver);
    let gait = find_gait(
        &map,
        &default_initial(&config),
        &GaitOptions::default(),
        None,
    )?;
    let start = Instant::now();
    for _ in 0..calls {
        if what == "dp" {
            std::hint::black_box(map.eval_with_derivatives(&gait.section, None)?);
        } else {
            std::hint::black_box(map.eval(&gait.section)?);
        }
    }
    let per_call = start.elapsed().as_secs_f64() / f64::from(calls);
    println!("{what}: {:.1} us per call", per_call * 1e6);
    Ok(())
}
