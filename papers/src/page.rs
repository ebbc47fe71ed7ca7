//! The HTML page a command writes with `--html` ([`gibench_harness::report::html`]): its command line,
//! the runs with their folders, and the line pointing the user at it.

use std::path::{Path, PathBuf};

use gibench_harness::measure::results::RunResult;
use gibench_harness::report;
use gibench_harness::Result;

/// The runs paired with the folder they were written to.
pub fn with_folder(dir: &Path, results: Vec<RunResult>) -> Vec<(PathBuf, RunResult)> {
    results
        .into_iter()
        .map(|r| (dir.to_path_buf(), r))
        .collect()
}

/// This command as a user would type it: `gibench` and its arguments (not the executable's
/// path on this machine, which names a user's folders and means nothing elsewhere).
pub fn command_line() -> String {
    std::iter::once("gibench".to_string())
        .chain(std::env::args().skip(1))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Writes an HTML page ([`gibench_harness::report::html`]) with this process's command line.
pub fn write_page(
    path: &Path,
    title: String,
    tables: Vec<report::Table>,
    figures: Vec<PathBuf>,
    runs: Vec<(PathBuf, RunResult)>,
) -> Result<()> {
    gibench_harness::report::html::Page {
        title,
        command: command_line(),
        tables,
        figures,
        runs,
    }
    .write(path)
}

/// "\nreport: PATH (open it in a browser)", the page's path made absolute.
pub fn page_line(page: &Path) -> String {
    let shown = std::env::current_dir()
        .map(|d| d.join(page))
        .unwrap_or_else(|_| page.to_path_buf());
    format!("\nreport: {} (open it in a browser)", shown.display())
}
