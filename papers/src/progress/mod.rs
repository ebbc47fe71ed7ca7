//! Progress bars and where a command reports: a bar of its own, or its share of `gibench
//! reproduce all`'s ([`Bars`]); and the typed runs executed under them.

use gibench_harness::gpu::GpuContext;
use gibench_harness::measure::results::RunResult;
use gibench_harness::report;
use gibench_harness::run::session::{self, Progress, RunSpec};
use gibench_harness::Result;

mod overall;
pub use overall::Overall;

/// Runs `spec` with a progress bar (hidden when `quiet`).
pub fn execute_with_bar(bars: &Bars, gpu: &GpuContext, spec: &RunSpec) -> Result<Vec<RunResult>> {
    let (results, skipped) = execute_skipping_with_bar(bars, gpu, spec, false)?;
    match session::device_lost(&skipped) {
        Some(e) => Err(e),
        None => Ok(results),
    }
}

/// [`execute_with_bar`] leaving out, with `skip_unfit`, the techniques that cannot take the
/// scene or the device ([`session::execute_skipping`]); each is named with its reason.
pub fn execute_skipping_with_bar(
    bars: &Bars,
    gpu: &GpuContext,
    spec: &RunSpec,
    skip_unfit: bool,
) -> Result<(Vec<RunResult>, Vec<session::Skipped>)> {
    let executed = match bars {
        Bars::Own(quiet) => {
            let bar = progress_bar(*quiet, spec.total_frames());
            let scene = &spec.scene.descriptor.name;
            let executed = session::execute_skipping(gpu, spec, skip_unfit, &mut |p| match p {
                Progress::Preparing(name) => bar.set_message(format!("{name}: preparing")),
                Progress::Prepared(name, s) => match slow_preparation(name, scene, s) {
                    Some(line) if !*quiet && bar.is_hidden() => eprintln!("{line}"),
                    Some(line) if !*quiet => bar.println(line),
                    _ => {}
                },
                Progress::Technique(name) => bar.set_message(name.to_string()),
                Progress::Frame => bar.inc(1),
            });
            bar.finish_and_clear();
            executed
        }
        Bars::Shared(all) => {
            let scene = &spec.scene.descriptor.name;
            session::execute_skipping(gpu, spec, skip_unfit, &mut |p| match p {
                Progress::Preparing(name) => all.technique(&format!("{name}: preparing")),
                Progress::Prepared(name, s) => {
                    if let Some(line) = slow_preparation(name, scene, s) {
                        all.note(&line);
                    }
                }
                Progress::Technique(name) => all.technique(name),
                Progress::Frame => all.frame(),
            })
        }
    };
    if let Ok((results, skipped)) = &executed {
        for s in skipped {
            bars.note(&format!(
                "skipped {} on {}: {}",
                s.technique, spec.scene.descriptor.name, s.reason
            ));
        }
        for r in results {
            for w in &r.warnings {
                bars.note(&format!("warning: {} on {}: {w}", r.technique, r.scene));
            }
        }
    }
    executed
}

/// Preparations shorter than this pass without a line (the bar's message says "preparing"
/// while they run).
const SLOW_PREPARATION_S: f64 = 2.0;

/// The line that reports a preparation of `seconds` when it was slow enough to notice.
fn slow_preparation(technique: &str, scene: &str, seconds: f64) -> Option<String> {
    (seconds >= SLOW_PREPARATION_S)
        .then(|| format!("prepared {technique} on {scene} in {seconds:.1} s"))
}

/// Where a command reports its progress: a bar of its own (hidden when quiet), or its share of
/// `gibench reproduce all`'s bar.
pub enum Bars<'a> {
    Own(bool),
    Shared(&'a Overall),
}

impl Bars<'_> {
    /// A line for the terminal (above the shared bar, not through it).
    pub fn note(&self, line: &str) {
        match self {
            Bars::Own(_) => eprintln!("{line}"),
            Bars::Shared(all) => all.note(line),
        }
    }

    /// A result table for the terminal: printed by a command of its own; under `reproduce all`
    /// it is in the files only.
    pub fn table(&self, table: &report::Table) {
        if let Bars::Own(_) = self {
            println!("{}", table.to_terminal());
        }
    }
}

/// A bar of `total` frames with the technique running as its message (hidden when `quiet`).
pub fn progress_bar(quiet: bool, total: u64) -> indicatif::ProgressBar {
    let bar = if quiet {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(total)
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{msg:>24} [{bar:30}] {pos}/{len} frames ({elapsed})",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar
}

#[cfg(test)]
mod tests {
    /// Catches: every preparation reported (a line per technique per run), or a slow one not:
    /// barczak's 8-28 s on Sibenik printed nothing until the first frame.
    #[test]
    fn only_slow_preparations_get_a_line() {
        assert_eq!(super::slow_preparation("laine", "cornell", 0.01), None);
        assert_eq!(
            super::slow_preparation("barczak", "sibenik", 8.34).as_deref(),
            Some("prepared barczak on sibenik in 8.3 s")
        );
    }
}
