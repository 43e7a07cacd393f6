//! The `vrw plot` command: its options and the files it reports.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;

use vrw::app::run_plot;

#[derive(Debug, Args)]
pub(super) struct PlotArgs {
    /// Output directory of `vrw simulate` or `vrw gait` (the figures are written there).
    dir: PathBuf,
    /// Draw the complete rows of a run that did not finish (killed, or failed); the figures say "partial".
    #[arg(long)]
    partial: bool,
}

/// Run `vrw plot` and print its summary.
pub(super) fn run(args: &PlotArgs) -> Result<()> {
    let report = run_plot(&args.dir, args.partial).context("plot")?;
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    for f in &report.files {
        println!("wrote {}", f.display());
    }
    Ok(())
}
