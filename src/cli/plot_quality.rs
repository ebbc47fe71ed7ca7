//! `gibench plot-quality`: per-frame error against the reference, plotted from results files
//! made with `run --quality --quality-all`.

use std::path::PathBuf;

use clap::Args;
use gibench_harness::report;
use gibench_harness::{Error, Result};

use super::results_io::{read_results, shown_list};
use gibench_papers::files::writable_file;

#[derive(Args)]
pub(crate) struct PlotQualityArgs {
    /// Results JSON files (or directories holding them).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// rmse, rel_mse, mae, bias, flip or flicker.
    #[arg(long, default_value = "rmse")]
    metric: String,
    /// Output SVG.
    #[arg(long, default_value = "results/local/quality-per-frame.svg")]
    out: PathBuf,
}

/// `gibench plot-quality`: one SVG of the metric per frame for every run given.
pub(crate) fn exec(args: &PlotQualityArgs) -> Result<()> {
    report::check_per_frame_metric(&args.metric)?;
    writable_file("out", &args.out, "quality-per-frame.svg")?;
    let results = read_results(&args.inputs)?;
    if report::per_frame_lines(&results, &args.metric)?.is_empty() {
        return Err(Error::Invalid(format!(
            "{}: no results hold per-frame quality values ('{}'); `gibench run --quality \
             --quality-all` makes them",
            shown_list(&args.inputs),
            args.metric
        )));
    }
    report::quality_over_frames_svg(
        &results,
        &args.metric,
        &args.out,
        &format!("{} against the reference per frame", args.metric),
    )?;
    eprintln!("wrote {}", args.out.display());
    Ok(())
}
