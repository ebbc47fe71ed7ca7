//! **Compare**: whether CURRENT runs are faster or slower than BASE runs of the same benchmark,
//! stage by stage, with a verdict only where the repeats' spread allows one (`gibench compare`).
//!
//! Runs are matched by scene, technique, resolution and parameters; each side needs at least
//! [`MIN_REPEATS`] repeats of every run it is compared on (run them alternating BASE and
//! CURRENT, so that a shared machine's drift falls on both). For every stage (the tables'
//! figure: flushed wall time, else GPU timestamps), and for the whole frame where it was timed:
//!
//! * each repeat's median is divided by the calibration workload timed in the same session
//!   ([`crate::calibrate`]), so drift between sessions cancels — when every repeat of the run
//!   on both sides has one; otherwise both sides are compared raw (the row says so);
//! * the **ratio** is median(CURRENT) / median(BASE) over the repeats, normalised (and raw
//!   beside it);
//! * the **band** is [min CURRENT / max BASE, max CURRENT / min BASE]: every pairing of a
//!   CURRENT repeat with a BASE repeat lies in it;
//! * the **verdict** is *slower* when the whole band lies above 1 + tolerance, *faster* when it
//!   lies below 1 / (1 + tolerance), and *unchanged* otherwise. A stage timed at 0 ms in some
//!   BASE repeat has no ratio: it is *slower* when every CURRENT repeat took time and every
//!   BASE repeat none, *unchanged* otherwise (and the reverse for *faster*).
//!
//! CPU stages also report the median thread CPU time of each side.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::report::{stage_ms, Cell, Table};
use crate::results::RunResult;
use crate::stats::median;
use crate::{Error, Result};

/// Repeats each side needs of every run it is compared on.
pub const MIN_REPEATS: usize = 3;

/// What a comparison concludes for one stage.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    Faster,
    Slower,
    Unchanged,
}

impl Verdict {
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Faster => "faster",
            Verdict::Slower => "slower",
            Verdict::Unchanged => "unchanged",
        }
    }
}

/// One stage of one run, compared.
#[derive(Clone, Debug, Serialize)]
pub struct CompareRow {
    /// `scene/technique/WxH` plus any parameters.
    pub run: String,
    pub stage: String,
    /// Median over the repeats of each repeat's median, milliseconds.
    pub base_ms: f64,
    pub current_ms: f64,
    /// current / base, raw; `None` where a time is 0.
    pub ratio_raw: Option<f64>,
    /// current / base, each repeat divided by its session's calibration (raw where a repeat
    /// has none: see `calibrated`); `None` where a time is 0.
    pub ratio: Option<f64>,
    /// Whether `ratio` and `band` are calibrated (every repeat on both sides has a calibration).
    pub calibrated: bool,
    /// The band of ratios (see the module docs); `None` where a time is 0.
    pub band: Option<[f64; 2]>,
    pub verdict: Verdict,
    pub repeats: [usize; 2],
    /// CPU stages: median thread CPU time, base and current.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cpu_ms: Option<[f64; 2]>,
}

/// The key runs are matched by.
fn run_key(r: &RunResult) -> String {
    let params: Vec<String> = r
        .parameters
        .iter()
        .map(|(k, v)| format!("{k}={}", v.to_string().trim_matches('"')))
        .collect();
    let mut key = format!(
        "{}/{}/{}x{}",
        r.scene, r.technique, r.resolution[0], r.resolution[1]
    );
    if !params.is_empty() {
        key.push_str(&format!(" ({})", params.join(", ")));
    }
    key
}

/// One stage of one run: (raw ms, calibrated or raw, thread CPU ms).
type Figure = (f64, f64, Option<f64>);

/// Whether `r` carries a calibration that can be divided by.
fn has_calibration(r: &RunResult) -> bool {
    r.calibration_ms.is_some_and(|c| {
        (crate::results::CALIBRATION_MS.0..=crate::results::CALIBRATION_MS.1).contains(&c)
    })
}

/// Per stage (and "frame"): the [`Figure`] of one run, its second value divided by the run's
/// calibration when `calibrated`.
fn figures(r: &RunResult, calibrated: bool) -> BTreeMap<String, Figure> {
    let scale = match r.calibration_ms {
        Some(c) if calibrated => 1.0 / c,
        _ => 1.0,
    };
    let mut out = BTreeMap::new();
    for s in &r.stages {
        if let Some(ms) = stage_ms(s).filter(|m| m.is_finite()) {
            let cpu = s.cpu_ms.as_ref().map(|c| c.median);
            out.insert(s.name.clone(), (ms, ms * scale, cpu));
        }
    }
    if let Some(f) = &r.frame {
        let ms = f.frame_ms.median;
        if ms.is_finite() {
            out.insert("frame".to_string(), (ms, ms * scale, None));
        }
    }
    out
}

/// The band and verdict for one stage's repeats (see the module docs): `base` and `current`
/// are each repeat's figure, non-negative.
pub fn judge(base: &[f64], current: &[f64], tolerance: f64) -> (Option<[f64; 2]>, Verdict) {
    let max_of = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
    let min_of = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
    if min_of(base) <= 0.0 || min_of(current) <= 0.0 {
        let verdict = if max_of(base) == 0.0 && min_of(current) > 0.0 {
            Verdict::Slower
        } else if max_of(current) == 0.0 && min_of(base) > 0.0 {
            Verdict::Faster
        } else {
            Verdict::Unchanged
        };
        return (None, verdict);
    }
    let band = [
        min_of(current) / max_of(base),
        max_of(current) / min_of(base),
    ];
    let verdict = if band[0] > 1.0 + tolerance {
        Verdict::Slower
    } else if band[1] < 1.0 / (1.0 + tolerance) {
        Verdict::Faster
    } else {
        Verdict::Unchanged
    };
    (Some(band), verdict)
}

/// `a / b`, or `None` when either is 0.
fn ratio(a: f64, b: f64) -> Option<f64> {
    (a > 0.0 && b > 0.0).then(|| a / b)
}

/// Runs grouped by [`run_key`].
fn group(runs: &[RunResult]) -> BTreeMap<String, Vec<&RunResult>> {
    let mut g: BTreeMap<String, Vec<&RunResult>> = BTreeMap::new();
    for r in runs {
        g.entry(run_key(r)).or_default().push(r);
    }
    g
}

/// Compares `current` with `base` (see the module docs). Errors name the run that has too few
/// repeats on either side, or say that no run is on both sides.
pub fn compare(
    base: &[RunResult],
    current: &[RunResult],
    tolerance: f64,
) -> Result<Vec<CompareRow>> {
    if !(tolerance.is_finite() && tolerance >= 0.0) {
        return Err(Error::param(
            "tolerance",
            format!("must be a number >= 0 (got {tolerance})"),
        ));
    }
    let (b, c) = (group(base), group(current));
    let common: Vec<&String> = b.keys().filter(|k| c.contains_key(*k)).collect();
    if common.is_empty() {
        return Err(Error::Invalid(format!(
            "no run is in both BASE ({}) and CURRENT ({}): runs are matched by scene, technique, resolution and parameters",
            b.keys().cloned().collect::<Vec<_>>().join("; "),
            c.keys().cloned().collect::<Vec<_>>().join("; ")
        )));
    }
    let mut rows = Vec::new();
    for key in common {
        let (bs, cs) = (&b[key], &c[key]);
        for (side, runs) in [("BASE", bs), ("CURRENT", cs)] {
            if runs.len() < MIN_REPEATS {
                return Err(Error::Invalid(format!(
                    "{side} has {} repeat(s) of {key}; a comparison needs at least {MIN_REPEATS} on each side (run it again into separate folders, alternating BASE and CURRENT)",
                    runs.len()
                )));
            }
        }
        let calibrated = bs.iter().chain(cs.iter()).all(|r| has_calibration(r));
        let bf: Vec<_> = bs.iter().map(|r| figures(r, calibrated)).collect();
        let cf: Vec<_> = cs.iter().map(|r| figures(r, calibrated)).collect();
        let mut stages: Vec<String> = Vec::new();
        for f in bf.iter().chain(&cf) {
            for name in f.keys() {
                if !stages.contains(name) {
                    stages.push(name.clone());
                }
            }
        }
        for stage in stages {
            let take = |fs: &[BTreeMap<String, Figure>]| {
                fs.iter()
                    .filter_map(|f| f.get(&stage).copied())
                    .collect::<Vec<_>>()
            };
            let (bv, cv) = (take(&bf), take(&cf));
            if bv.len() < MIN_REPEATS || cv.len() < MIN_REPEATS {
                continue;
            }
            let raw = |v: &[Figure]| v.iter().map(|x| x.0).collect::<Vec<_>>();
            let norm = |v: &[Figure]| v.iter().map(|x| x.1).collect::<Vec<_>>();
            let cpu = |v: &[Figure]| {
                let c: Vec<f64> = v.iter().filter_map(|x| x.2).collect();
                (!c.is_empty()).then(|| median(&c))
            };
            let (bn, cn) = (norm(&bv), norm(&cv));
            let (band, verdict) = judge(&bn, &cn, tolerance);
            let (base_ms, current_ms) = (median(&raw(&bv)), median(&raw(&cv)));
            rows.push(CompareRow {
                run: key.clone(),
                stage,
                base_ms,
                current_ms,
                ratio_raw: ratio(current_ms, base_ms),
                ratio: ratio(median(&cn), median(&bn)),
                calibrated,
                band,
                verdict,
                repeats: [bv.len(), cv.len()],
                cpu_ms: cpu(&bv).zip(cpu(&cv)).map(|(a, b)| [a, b]),
            });
        }
    }
    Ok(rows)
}

/// The comparison as a table (see the module docs for the columns' meaning).
pub fn compare_table(rows: &[CompareRow], tolerance: f64) -> Table {
    let columns = [
        "run",
        "stage",
        "base ms",
        "current ms",
        "ratio (raw)",
        "ratio (calibrated)",
        "band",
        "verdict",
        "CPU ms base / current",
    ]
    .map(String::from)
    .to_vec();
    let rows_out = rows
        .iter()
        .map(|r| {
            vec![
                Cell::text(&r.run),
                Cell::text(&r.stage),
                Cell::Ms(Some(r.base_ms)),
                Cell::Ms(Some(r.current_ms)),
                Cell::Num(r.ratio_raw, 3),
                Cell::Num(r.ratio.filter(|_| r.calibrated), 3),
                Cell::text(r.band.map_or("–".to_string(), |[a, b]| {
                    format!(
                        "{}–{}{}",
                        Cell::Num(Some(a), 3).display(),
                        Cell::Num(Some(b), 3).display(),
                        if r.calibrated { "" } else { " (raw)" }
                    )
                })),
                Cell::text(r.verdict.name()),
                Cell::text(
                    r.cpu_ms
                        .map_or("–".to_string(), |[a, b]| format!("{a:.2} / {b:.2}")),
                ),
            ]
        })
        .collect();
    let slower = rows.iter().filter(|r| r.verdict == Verdict::Slower).count();
    let faster = rows.iter().filter(|r| r.verdict == Verdict::Faster).count();
    Table {
        title: format!(
            "Comparison: {slower} slower, {faster} faster, {} unchanged",
            rows.len() - slower - faster
        ),
        columns,
        rows: rows_out,
        notes: vec![format!(
            "Per stage, the median over the repeats of each repeat's median (ms). Ratios are CURRENT / BASE; \
             \"calibrated\" divides each repeat by the calibration workload timed in its session. Band: every \
             pairing of a CURRENT repeat with a BASE repeat (calibrated; \"(raw)\" where a repeat on either side has \
             no calibration, and then both sides are compared raw). Verdict: slower when the whole band \
             is above {:.2}, faster when it is below {:.3}, else unchanged (tolerance {tolerance}); a stage \
             timed at 0 ms has no ratio.",
            1.0 + tolerance,
            1.0 / (1.0 + tolerance)
        )],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::results::{StageKind, StageResult};
    use crate::stats::Stats;

    fn run(stages: &[(&str, f64)], calibration: impl Into<Option<f64>>) -> RunResult {
        let mut r: RunResult = serde_json::from_value(serde_json::json!({
            "schema_version": crate::results::SCHEMA_VERSION,
            "gibench_version": "0", "git_commit": "x", "timestamp": 0, "scene": "cornell",
            "technique": "direct", "parameters": {}, "settings": {}, "resolution": [64, 48],
            "frames": {"warmup": 3, "measured": 10, "first": 3}, "seed": 1, "timing_mode": "stages",
            "device": {"adapter": "a", "backend": "vulkan", "device_type": "Cpu", "driver": "d",
                       "driver_info": "i", "timestamp_queries": false, "timestamp_period_ns": 1.0},
            "stages": [], "frame": null
        }))
        .unwrap();
        r.calibration_ms = calibration.into();
        r.stages = stages
            .iter()
            .map(|(name, ms)| StageResult {
                name: name.to_string(),
                kind: StageKind::Gpu,
                gpu_ms: None,
                wall_ms: Some(Stats::of(&[*ms])),
                cpu_ms: None,
            })
            .collect();
        r
    }

    /// Noise within the band and a machine twice as slow in one session give "unchanged"; a
    /// stage 1.5× slower is "slower" and the others stay "unchanged"; too few repeats is an
    /// error naming the run.
    #[test]
    fn verdicts_follow_the_band_and_the_calibration() {
        let base: Vec<RunResult> = [1.0, 1.04, 0.97]
            .iter()
            .map(|n| run(&[("a", 2.0 * n), ("b", 5.0 * n)], 10.0))
            .collect();
        // The same work; the second session ran on a machine twice as slow, and its
        // calibration says so.
        let same: Vec<RunResult> = [(1.02, 10.0), (2.0, 20.0), (0.99, 10.0)]
            .iter()
            .map(|(n, c)| run(&[("a", 2.0 * n), ("b", 5.0 * n)], *c))
            .collect();
        let rows = compare(&base, &same, 0.1).unwrap();
        assert!(
            rows.iter().all(|r| r.verdict == Verdict::Unchanged),
            "{rows:?}"
        );
        let slow: Vec<RunResult> = [1.0, 1.03, 0.98]
            .iter()
            .map(|n| run(&[("a", 3.0 * n), ("b", 5.0 * n)], 10.0))
            .collect();
        let rows = compare(&base, &slow, 0.1).unwrap();
        let verdict = |s: &str| rows.iter().find(|r| r.stage == s).unwrap().verdict;
        assert_eq!(verdict("a"), Verdict::Slower);
        assert_eq!(verdict("b"), Verdict::Unchanged);
        let rows = compare(&slow, &base, 0.1).unwrap();
        assert_eq!(
            rows.iter().find(|r| r.stage == "a").unwrap().verdict,
            Verdict::Faster
        );
        let e = compare(&base[..2], &slow, 0.1).unwrap_err().to_string();
        assert!(
            e.contains("BASE has 2 repeat(s) of cornell/direct/64x48"),
            "{e}"
        );
    }

    /// The band's edges decide exactly: a band wholly above 1 + tolerance is slower, one
    /// touching it is not; wholly below 1 / (1 + tolerance) is faster.
    #[test]
    fn the_verdict_is_decided_by_the_band_edges() {
        let (band, v) = judge(&[1.0, 2.0, 1.5], &[2.4, 2.5, 2.45], 0.1);
        assert_eq!(band, Some([1.2, 2.5]));
        assert_eq!(v, Verdict::Slower);
        let (_, v) = judge(&[1.0, 2.0], &[2.2, 3.0], 0.1);
        assert_eq!(
            v,
            Verdict::Unchanged,
            "band [1.1, 3]: its lower edge is not above 1.1"
        );
        let (_, v) = judge(&[2.0, 2.0], &[1.0, 1.8], 0.1);
        assert_eq!(v, Verdict::Faster, "band [0.5, 0.9] lies below 1/1.1");
        let (_, v) = judge(&[2.0, 2.0], &[1.0, 1.85], 0.1);
        assert_eq!(v, Verdict::Unchanged, "band [0.5, 0.925]");
    }

    /// A side whose files carry no calibration: both sides are compared raw. Before, the
    /// calibrated side was divided by its 10 ms and the other not, and every stage was
    /// "slower" (or "faster") although the times were the same.
    #[test]
    fn a_side_without_calibration_is_compared_raw() {
        let side = |calibration: Option<f64>| -> Vec<RunResult> {
            [1.0, 1.02, 0.99]
                .iter()
                .map(|n| run(&[("a", 2.0 * n), ("b", 5.0 * n)], calibration))
                .collect()
        };
        for (base, current) in [(Some(10.0), None), (None, Some(10.0))] {
            let rows = compare(&side(base), &side(current), 0.1).unwrap();
            assert_eq!(rows.len(), 2);
            for r in &rows {
                assert_eq!(r.verdict, Verdict::Unchanged, "{r:?}");
                assert!(!r.calibrated);
                assert!((r.ratio.unwrap() - 1.0).abs() < 1e-12, "{r:?}");
            }
        }
        // One repeat without calibration among calibrated ones: raw as well.
        let mut mixed = side(Some(10.0));
        mixed[1].calibration_ms = None;
        let rows = compare(&side(Some(10.0)), &mixed, 0.1).unwrap();
        assert!(rows
            .iter()
            .all(|r| !r.calibrated && r.verdict == Verdict::Unchanged));
        let table = compare_table(&rows, 0.1).to_terminal();
        assert!(table.contains("(raw)"), "{table}");
    }

    /// A stage timed at 0 ms has no ratio (before: "inf–inf" and a verdict from it); a stage
    /// that took no time before and takes some now is slower, and the reverse faster.
    #[test]
    fn zero_ms_stages_have_no_ratio() {
        let side = |a: f64, b: f64| -> Vec<RunResult> {
            (0..3).map(|_| run(&[("a", a), ("b", b)], 10.0)).collect()
        };
        let rows = compare(&side(0.0, 0.0), &side(0.0, 1.0), 0.1).unwrap();
        let row = |s: &str| rows.iter().find(|r| r.stage == s).unwrap();
        assert_eq!(row("a").verdict, Verdict::Unchanged);
        assert_eq!(row("b").verdict, Verdict::Slower);
        for r in &rows {
            assert!(
                r.ratio.is_none() && r.ratio_raw.is_none() && r.band.is_none(),
                "{r:?}"
            );
        }
        let table = compare_table(&rows, 0.1).to_terminal();
        assert!(!table.contains("inf"), "{table}");
        let rows = compare(&side(1.0, 1.0), &side(0.0, 1.0), 0.1).unwrap();
        assert_eq!(
            rows.iter().find(|r| r.stage == "a").unwrap().verdict,
            Verdict::Faster
        );
    }
}
