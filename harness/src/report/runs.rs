//! What the tables and plots read from a run: its label, its stages' names and times.

use super::table::finite;
use crate::measure::results::{RunResult, StageResult};

/// "technique @ scene", the label of a run in plots and notes.
pub(super) fn run_label(r: &RunResult) -> String {
    format!("{} @ {}", r.technique, r.scene)
}

/// The union of the runs' stage names in execution order: a stage first seen in a later run is
/// placed just before the next stage of that run already listed (else at the end).
pub(super) fn stage_names<'a>(results: impl IntoIterator<Item = &'a RunResult>) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for r in results {
        for (i, s) in r.stages.iter().enumerate() {
            if names.contains(&s.name) {
                continue;
            }
            let next_known = r.stages[i + 1..]
                .iter()
                .find_map(|t| names.iter().position(|n| *n == t.name));
            match next_known {
                Some(p) => names.insert(p, s.name.clone()),
                None => names.push(s.name.clone()),
            }
        }
    }
    names
}

/// A stage's plotted/tabulated time, treating non-finite values as missing.
pub fn stage_ms(s: &StageResult) -> Option<f64> {
    finite(s.best_ms())
}

/// Sum of the run's stage times; `None` when no stage has a time.
pub(super) fn stage_sum(r: &RunResult) -> Option<f64> {
    let times: Vec<f64> = r.stages.iter().filter_map(stage_ms).collect();
    (!times.is_empty()).then(|| times.iter().sum())
}
