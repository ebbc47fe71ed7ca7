//! `gibench report`: tables (Markdown, CSV, LaTeX), a stacked-bar SVG and optionally an HTML
//! page from results files.

use std::path::PathBuf;

use clap::Args;
use gibench_harness::measure::results::RunResult;
use gibench_harness::output::OutputSet;
use gibench_harness::report;
use gibench_harness::Result;

use super::results_io::read_results_with_folders;
use gibench_papers::files::check_stem;
use gibench_papers::page::{page_line, write_page};

#[derive(Args)]
pub(crate) struct ReportArgs {
    /// Results JSON files (or directories holding them).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// Output directory for the tables and the plot.
    #[arg(long, default_value = "results/local")]
    out: PathBuf,
    /// File name stem of the outputs.
    #[arg(long, default_value = "report")]
    stem: String,
    /// Also print full statistics (median, mean, p5, p95, min, max) per stage, and each GPU
    /// stage's fraction of the device's measured bandwidth and arithmetic rate (a roofline).
    #[arg(long)]
    detailed: bool,
    /// Also write an HTML page (`{stem}.html`): the table, the runs' images beside the
    /// reference (from their folders), error maps, time versus error.
    #[arg(long)]
    html: bool,
    /// Also compare the devices the runs were made on: per run made on the first device and
    /// another, each stage's and the frame's time on both and the speedup (the first device's
    /// time over the other's), printed and written as `{stem}-speedup.{md,csv,tex}`.
    #[arg(long)]
    speedup: bool,
    /// The summary table's columns after its identifying ones (scene, technique, resolution,
    /// setting), comma-separated, by header in lower case with `-` for spaces: e.g.
    /// `frame,fps,relmse,flip` or stage names; `sum` for "Σ stages". Default: every column.
    #[arg(long, value_delimiter = ',')]
    columns: Vec<String>,
    /// Which table files to write (the summary's and `--speedup`'s): `markdown`, `csv`,
    /// `latex` (comma-separated; default all three).
    #[arg(long, value_delimiter = ',')]
    format: Vec<String>,
}

/// `gibench report`: the tables, plots and page of the given results.
pub(crate) fn exec(args: &ReportArgs) -> Result<()> {
    check_stem(&args.stem)?;
    let runs = read_results_with_folders(&args.inputs)?;
    let results: Vec<RunResult> = runs.iter().map(|(_, r)| r.clone()).collect();
    // Checked before anything is written.
    let speedup = args
        .speedup
        .then(|| report::speedup_table(&results))
        .transpose()?;
    let formats = if args.format.is_empty() {
        report::TableFormat::ALL.to_vec()
    } else {
        (args.format.iter())
            .map(|f| report::TableFormat::parse("format", f.trim()))
            .collect::<Result<Vec<_>>>()?
    };
    let mut table = report::stage_table(&results);
    if !args.columns.is_empty() {
        table = table.select_columns("columns", &args.columns)?;
    }
    let set = OutputSet::begin("out", &args.out)?;
    // Files of this stem that only some reports write: an earlier report's would describe
    // other runs.
    let stem = &args.stem;
    for f in [
        format!("{stem}-equal-time.md"),
        format!("{stem}-equal-time.csv"),
        format!("{stem}-equal-time.tex"),
        format!("{stem}-time-vs-error.svg"),
        format!("{stem}-time-vs-error.pdf"),
        format!("{stem}-speedup.md"),
        format!("{stem}-speedup.csv"),
        format!("{stem}-speedup.tex"),
        format!("{stem}.html"),
    ] {
        set.replace_files(&f)?;
    }
    println!("{}", table.to_terminal());
    if args.detailed {
        for r in &results {
            println!("{}", report::stage_table_detailed(r).to_terminal());
            println!("{}", report::roofline_table(r).to_terminal());
        }
    }
    report::write_tables_as(&table, &args.out, &args.stem, &formats)?;
    if let Some(speedup) = &speedup {
        println!("{}", speedup.to_terminal());
        report::write_tables_as(
            speedup,
            &args.out,
            &format!("{}-speedup", args.stem),
            &formats,
        )?;
    }
    let equal_time = report::equal_time_table(&results);
    if let Some(equal) = &equal_time {
        println!("{}", equal.to_terminal());
        let stem = format!("{}-equal-time", args.stem);
        report::write_tables_as(equal, &args.out, &stem, &formats)?;
    }
    let mut figures = vec![args.out.join(format!("{}.svg", args.stem))];
    report::stacked_bar_svg(&results, &figures[0], "Per-stage times")?;
    if !report::time_error_points(&results).is_empty() {
        let svg = args.out.join(format!("{}-time-vs-error.svg", args.stem));
        report::time_vs_error_svg(&results, &svg, "Time versus error")?;
        figures.push(svg);
    }
    let page = args.out.join(format!("{}.html", args.stem));
    if args.html {
        let title = table.title.clone();
        let tables = std::iter::once(table).chain(equal_time).collect();
        write_page(&page, title, tables, figures, runs)?;
    }
    set.publish()?;
    if args.html {
        eprintln!("{}", page_line(&page).trim_start());
    }
    Ok(())
}
