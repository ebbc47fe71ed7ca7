//! `gibench compare --format markdown`: the comparison as the short Markdown a reviewer reads.

use std::collections::BTreeMap;

use super::{CompareRow, Settings, Verdict};
use crate::report::Cell;

/// Each run's label for [`compare_markdown`]: its [`run_key`](super::run_key) without the parameters that all
/// compared runs of its scene, technique and resolution share (`cornell/laine/128x96` when it
/// is the only one; `cornell/ism/256x192 (vpls=256)` among a sweep's points). The parameters
/// are read back from the key (`NAME=VALUE` pairs joined by ", "); a key that does not parse so
/// keeps its whole self.
pub(super) fn short_labels(rows: &[CompareRow]) -> BTreeMap<&str, String> {
    type Params<'a> = Vec<(&'a str, &'a str)>;
    let mut by_base: BTreeMap<&str, Vec<(&str, Params)>> = BTreeMap::new();
    for r in rows {
        let (base, params) = match r.run.split_once(" (") {
            Some((base, rest)) => {
                let inner = rest.strip_suffix(')').unwrap_or(rest);
                let pairs: Option<Params> =
                    inner.split(", ").map(|kv| kv.split_once('=')).collect();
                match pairs {
                    Some(p) => (base, p),
                    None => continue,
                }
            }
            None => (r.run.as_str(), Vec::new()),
        };
        let runs = by_base.entry(base).or_default();
        if !runs.iter().any(|(k, _)| *k == r.run.as_str()) {
            runs.push((r.run.as_str(), params));
        }
    }
    let mut labels = BTreeMap::new();
    for (base, runs) in by_base {
        for (key, params) in &runs {
            let differing: Vec<String> = params
                .iter()
                .filter(|(k, v)| {
                    runs.iter()
                        .any(|(_, other)| !other.iter().any(|(ok, ov)| ok == k && ov == v))
                })
                .map(|(k, v)| format!("{k}={v}"))
                .collect();
            let label = if differing.is_empty() {
                base.to_string()
            } else {
                format!("{base} ({})", differing.join(", "))
            };
            labels.insert(*key, label);
        }
    }
    labels
}

/// The comparison as the short Markdown a reviewer reads in a pull request's comment or a CI
/// job's summary (`gibench compare --format markdown`): a title naming both sides, the rows
/// that changed (*slower* first, largest ratio first; then *faster*, smallest ratio first)
/// with run, stage, both medians, the ratio the verdict was decided on, p and the verdict, then
/// one line counting the unchanged stages, then `notes` (runs not compared). `sides` are the
/// BASE and CURRENT folders as given.
pub fn compare_markdown(
    rows: &[CompareRow],
    settings: &Settings,
    sides: [&str; 2],
    notes: &[String],
) -> String {
    let cell = |s: &str| s.replace('|', "\\|");
    let code = |s: &str| format!("`{}`", s.replace('`', "'"));
    let mut out = format!(
        "### gibench compare: {} (CURRENT) against {} (BASE)\n\n",
        code(sides[1]),
        code(sides[0])
    );
    let count = |v: Verdict| rows.iter().filter(|r| r.verdict == v).count();
    let (slower, faster) = (count(Verdict::Slower), count(Verdict::Faster));
    let unchanged = rows.len() - slower - faster;
    out.push_str(&format!(
        "**{slower} slower, {faster} faster**, {unchanged} unchanged of {} stages. Each \
         repeat's {}{}; a verdict needs p < {} (two-sided Mann–Whitney U) and a ratio beyond \
         {:.2} or {:.3}.\n\n",
        rows.len(),
        settings.statistic.name(),
        if settings.calibrate {
            ", divided by its session's calibration"
        } else {
            ", raw"
        },
        settings.alpha,
        1.0 + settings.tolerance,
        1.0 / (1.0 + settings.tolerance),
    ));
    // Slower by ratio, largest first; faster by ratio, smallest first (a stage timed at 0 ms
    // on one side has no ratio and leads its group).
    let key = |r: &&CompareRow, sign: f64| r.ratio.map_or(f64::NEG_INFINITY, |x| sign * x);
    let mut changed: Vec<&CompareRow> = rows
        .iter()
        .filter(|r| r.verdict == Verdict::Slower)
        .collect();
    changed.sort_by(|a, b| key(a, -1.0).total_cmp(&key(b, -1.0)));
    let mut better: Vec<&CompareRow> = rows
        .iter()
        .filter(|r| r.verdict == Verdict::Faster)
        .collect();
    better.sort_by(|a, b| key(a, 1.0).total_cmp(&key(b, 1.0)));
    changed.extend(better);
    let labels = short_labels(rows);
    if changed.is_empty() {
        out.push_str("No stage is slower or faster.\n\n");
    } else {
        out.push_str(&format!(
            "| run | stage | base ms | current ms | ratio{} | p | verdict |\n\
             |---|---|---:|---:|---:|---:|---|\n",
            if settings.calibrate {
                " (calibrated)"
            } else {
                ""
            }
        ));
        for r in changed {
            let verdict = match r.verdict {
                Verdict::Slower => "**slower**",
                v => v.name(),
            };
            out.push_str(&format!(
                "| {} | {} | {} | {} | {} | {} | {verdict} |\n",
                cell(labels.get(r.run.as_str()).map_or(&r.run, |l| l)),
                cell(&r.stage),
                Cell::Ms(Some(r.base_ms)).display(),
                Cell::Ms(Some(r.current_ms)).display(),
                Cell::Num(r.ratio, 3).display(),
                r.p_value.map_or("–".to_string(), |p| format!("{p:.4}")),
            ));
        }
        out.push('\n');
    }
    out.push_str(&format!(
        "Unchanged: {unchanged} of {} stages.\n",
        rows.len()
    ));
    for note in notes {
        out.push_str(&format!("\n{note}\n"));
    }
    out
}
