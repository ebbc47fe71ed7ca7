//! `gibench`: run real-time indirect-illumination techniques side by side on the same scenes,
//! frames and timing harness, and render their per-stage timing tables.
//!
//! This file holds the command line's top level and the dispatch. The paper work (`run`,
//! `sweep`, `reference`, `reproduce`, `merge`) is the `gibench-papers` library's; every other
//! subcommand (its arguments and its work) is a module of [`cli`].

mod cli;
mod rays;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use cli::compare::CompareArgs;
use cli::export::ExportResultsArgs;
use cli::export_scene::ExportArgs;
use cli::instructions::InstructionsArgs;
use cli::plot_quality::PlotQualityArgs;
use cli::raycast::RaycastArgs;
use cli::report::ReportArgs;
use gibench_papers::merge::MergeArgs;
use gibench_papers::reference::ReferenceArgs;
use gibench_papers::reproduce::ReproduceArgs;
use gibench_papers::run::RunArgs;
use gibench_papers::sweep::SweepArgs;

#[derive(Parser)]
#[command(
    name = "gibench",
    version = concat!(env!("CARGO_PKG_VERSION"), " (", env!("GIBENCH_GIT_COMMIT"), ")"),
    about = "Benchmark suite for real-time indirect illumination"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Run techniques on a scene and write results, images and tables.
    Run(RunArgs),
    /// List the scenes and techniques (with their parameters and defaults).
    List(cli::list::ListArgs),
    /// Render tables (Markdown, CSV, LaTeX) and a stacked-bar SVG from results files.
    Report(ReportArgs),
    /// Render the CPU reference (direct, one-bounce, multi-bounce) for one frame.
    Reference(ReferenceArgs),
    /// Run one technique over a list of values of one parameter (e.g. vpls=64,128,256 or
    /// tiles=1x1,2x2,4x4,8x8) and tabulate and plot per-stage times against it.
    Sweep(SweepArgs),
    /// Regenerate paper tables, figures and sweeps: `all`, or one target (`reproduce all --list`).
    Reproduce(ReproduceArgs),
    /// Pool the folders of several `reproduce all` runs (the shards of a fleet) into one output
    /// set with one reproduce-all.json/.md/.html (docs/fleet.md).
    Merge(MergeArgs),
    /// Plot per-frame error against the reference from results files made with
    /// `run --quality --quality-all` (e.g. the lag of keller-incremental).
    PlotQuality(PlotQualityArgs),
    /// Compare CURRENT runs with BASE runs stage by stage: ratios, a rank test (Mann–Whitney U)
    /// over at least five repeats on each side, and a verdict (faster / slower / unchanged).
    Compare(CompareArgs),
    /// Write results folders (and instruction counts) as Bencher Metric Format JSON, for
    /// `bencher run --adapter json` to keep their history (`--format bmf`).
    Export(ExportResultsArgs),
    /// Count the CPU kernels' instructions under callgrind (deterministic, unlike time) and
    /// compare them with a baseline; fails on a regression beyond the threshold.
    Instructions(InstructionsArgs),
    /// Write one frame of a scene as PLY meshes per material and a JSON of its camera, light
    /// and albedos, for another renderer (`scripts/compare_mitsuba.py`).
    ExportScene(ExportArgs),
    /// Time the reference's BVH on the rays of `export-scene --rays N` (closest hit and shadow
    /// rays, wall and CPU time), for `scripts/compare_mitsuba.py --rays`.
    Raycast(RaycastArgs),
    /// Print the adapter runs would use (`--backend`, `--adapter`); `--require-gpu` refuses a
    /// CPU rasteriser by name (`scripts/gpu-run.sh` checks a slot's device with it).
    Adapter(cli::adapter::AdapterArgs),
}

fn main() -> ExitCode {
    // Results record the commit this binary was built from (build.rs), not the checkout's.
    gibench_harness::run::runner::set_build_commit(env!("GIBENCH_GIT_COMMIT"));
    gibench_harness::cpu::threads::join_global_pool();
    let cli = Cli::parse();
    // The commands whose frame loops stop politely on SIGTERM / SIGINT (the others keep the
    // signals' default action: they have no point to stop at).
    if matches!(
        cli.command,
        None | Some(Command::Run(_) | Command::Sweep(_) | Command::Reproduce(_))
    ) {
        gibench_harness::interrupt::install();
    }
    let outcome = match cli.command {
        None => gibench_papers::run::exec(&RunArgs::parse_default()),
        Some(Command::Run(args)) => gibench_papers::run::exec(&args),
        Some(Command::List(args)) => cli::list::exec(&args),
        Some(Command::Report(args)) => cli::report::exec(&args),
        Some(Command::Reference(args)) => gibench_papers::reference::exec(&args),
        Some(Command::Sweep(args)) => gibench_papers::sweep::exec(&args),
        Some(Command::Merge(args)) => gibench_papers::merge::exec(&args),
        Some(Command::PlotQuality(args)) => cli::plot_quality::exec(&args),
        Some(Command::Compare(args)) => match cli::compare::exec(&args) {
            Ok(status) => return status,
            Err(e) => Err(e),
        },
        Some(Command::Export(args)) => cli::export::exec(&args),
        Some(Command::Instructions(args)) => cli::instructions::exec(&args),
        Some(Command::ExportScene(args)) => cli::export_scene::exec(&args),
        Some(Command::Raycast(args)) => cli::raycast::exec(&args),
        Some(Command::Reproduce(args)) => gibench_papers::reproduce::exec(&args),
        Some(Command::Adapter(args)) => cli::adapter::exec(&args),
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            match e {
                // Stopped by SIGTERM or SIGINT: what completed is kept; run again to go on.
                gibench_harness::Error::Interrupted { .. } => {
                    ExitCode::from(gibench_harness::interrupt::EXIT_STATUS)
                }
                _ => ExitCode::FAILURE,
            }
        }
    }
}
