//! **Compare**: whether CURRENT runs are faster or slower than BASE runs of the same benchmark,
//! stage by stage, decided by a rank test and a minimum effect size (`gibench compare`).
//!
//! Runs are matched by scene, technique, resolution and parameters; each side needs at least
//! [`MIN_REPEATS`] repeats of every run it is compared on (run them alternating BASE and
//! CURRENT, so that a shared machine's drift falls on both). For every stage (the tables'
//! figure: flushed wall time, else GPU timestamps), and for the whole frame where it was timed:
//!
//! * each repeat's **figure** is its fastest frame of the stage ([`Statistic::Min`], the
//!   default) or its median frame ([`Statistic::Median`]). Other processes on a shared machine
//!   only ever add time to a frame, so a repeat's fastest frame is its least disturbed estimate
//!   of the stage's own cost (Chen and Revels 2016, "Robust benchmarking in noisy
//!   environments"): on the 2-core machine beside two `yes > /dev/null`, `direct`'s stages
//!   varied from run to run by 16–67 % (coefficient of variation of twelve runs' medians) and
//!   by 2–7 % by their fastest frames. A change that slows only some frames (a stutter) moves
//!   the median, p95 and p99, not the fastest frame: `--statistic median` judges those;
//! * with [`Settings::calibrate`] the figure is divided by the
//!   calibration workload timed in the same session ([`crate::measure::calibrate`]), for runs made in
//!   sessions far apart — when every repeat of the run on both sides has one; otherwise both
//!   sides are compared raw (the row says so). Runs made alternating in one session are
//!   compared raw: on the shared 2-core machine (load about 7) the calibration of 10 runs in a
//!   row ranged from 5.5 to 13.6 ms while their stages varied by about 10 %, and dividing by
//!   it made a 30 % slowdown visible in 20 % of 5-against-5 draws instead of all (median figures);
//! * the **ratio** is median(CURRENT) / median(BASE) over the repeats' figures (and raw
//!   beside it);
//! * the **p-value** is the two-sided Mann–Whitney U test of the CURRENT repeats against the
//!   BASE repeats ([`crate::measure::stats::mann_whitney_u`]: exact for fewer than 8 repeats a side
//!   without ties, else the normal approximation with tie correction; the row says which), as
//!   Google Benchmark's `compare.py` decides;
//! * the **verdict** is *slower* when p < alpha **and** the ratio exceeds 1 + tolerance,
//!   *faster* when p < alpha and the ratio is below 1 / (1 + tolerance), and *unchanged*
//!   otherwise: the test says whether the repeats differ beyond their spread, the tolerance
//!   whether the difference is large enough to matter. A stage timed at 0 ms in some repeat has
//!   no ratio: it is *slower* when every CURRENT repeat took time and every BASE repeat none,
//!   *unchanged* otherwise (and the reverse for *faster*).
//!
//! CPU stages also report the median thread CPU time of each side.
//!
//! [`compare_table`] renders every row (terminal, Markdown, CSV, LaTeX files);
//! [`compare_markdown`] only the changed ones, regressions first, for a review
//! (`gibench compare --format markdown`).

use std::collections::BTreeMap;

use serde::Serialize;

use crate::measure::results::RunResult;
use crate::measure::stats::{mann_whitney_u, median};
use crate::report::{Cell, Table};
use crate::{Error, Result};

mod markdown;
mod terminal;
pub use markdown::compare_markdown;
pub use terminal::compare_terminal;

/// Repeats each side needs of every run it is compared on: with 5 against 5 the rank test's
/// smallest two-sided p-value is 2/252 ≈ 0.008, so a shift can reach alpha 0.05 (with 3
/// against 3 it could never go below 0.1).
pub const MIN_REPEATS: usize = 5;

/// The default significance level of the rank test, Google Benchmark's `compare.py`'s. With 5
/// repeats against 5 it allows at most two of the 25 pairings the other way (p = 8/252 ≈
/// 0.032; complete separation gives 2/252): at 0.01 only complete separation would count, and
/// one stray repeat would hide a real change (a 30 % slower stage was missed in that way in
/// `tests/compare.rs`). A comparison tests every stage of every run, so some p below 0.05
/// come by chance: the tolerance is what keeps them from a verdict.
pub const DEFAULT_ALPHA: f64 = 0.05;

/// The default minimum effect (see [`Settings::tolerance`]): half the 30 % slowdown
/// `tests/compare.rs` must find. On the 2-core machine beside two `yes > /dev/null`, seven
/// against seven repeats of the same build (fastest frames) never reached it in 200 draws,
/// and the 30 % was seen as 16–46 %; a tolerance of 0.25 missed it in 17 % of those draws.
pub const DEFAULT_TOLERANCE: f64 = 0.15;

/// Which of a repeat's per-frame statistics is its figure (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Statistic {
    /// The fastest frame: robust to a shared machine's load, blind to stutters.
    #[default]
    Min,
    /// The median frame, as the tables show: sees a change in the typical frame, and moves
    /// with the machine's load.
    Median,
}

impl Statistic {
    pub fn name(self) -> &'static str {
        match self {
            Statistic::Min => "fastest frame",
            Statistic::Median => "median frame",
        }
    }

    fn of(self, s: &crate::measure::stats::Stats) -> f64 {
        match self {
            Statistic::Min => s.min,
            Statistic::Median => s.median,
        }
    }
}

/// How a comparison decides, checked by [`Settings::new`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Smallest relative change a verdict needs: the median ratio above 1 + tolerance (or
    /// below 1 / (1 + tolerance)).
    pub tolerance: f64,
    /// Significance level of the rank test: a verdict needs p < alpha.
    pub alpha: f64,
    /// Divide each repeat by its session's calibration (when every repeat has one).
    pub calibrate: bool,
    /// Each repeat's figure.
    pub statistic: Statistic,
}

impl Settings {
    /// Checked settings: an error names `tolerance` (a number >= 0) or `alpha` (between 0 and
    /// 1).
    pub fn new(
        tolerance: f64,
        alpha: f64,
        calibrate: bool,
        statistic: Statistic,
    ) -> Result<Settings> {
        if !(tolerance.is_finite() && tolerance >= 0.0) {
            return Err(Error::param(
                "tolerance",
                format!("must be a number >= 0 (got {tolerance})"),
            ));
        }
        if !(alpha > 0.0 && alpha < 1.0) {
            return Err(Error::param(
                "alpha",
                format!("must be a significance level between 0 and 1, exclusive (got {alpha})"),
            ));
        }
        Ok(Settings {
            tolerance,
            alpha,
            calibrate,
            statistic,
        })
    }
}

impl Default for Settings {
    fn default() -> Settings {
        Settings {
            tolerance: DEFAULT_TOLERANCE,
            alpha: DEFAULT_ALPHA,
            calibrate: false,
            statistic: Statistic::default(),
        }
    }
}

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
    /// Median over the repeats of each repeat's figure ([`Settings::statistic`]), milliseconds.
    pub base_ms: f64,
    pub current_ms: f64,
    /// Each repeat's figure: `min` (fastest frame) or `median`.
    pub statistic: Statistic,
    /// current / base, raw; `None` where a time is 0.
    pub ratio_raw: Option<f64>,
    /// current / base of the figures the verdict was decided on (calibrated where `calibrated`);
    /// `None` where a time is 0.
    pub ratio: Option<f64>,
    /// current / base, each repeat divided by its session's calibration, where every repeat on
    /// both sides has one (shown whether or not the verdict used it).
    pub ratio_calibrated: Option<f64>,
    /// Whether `ratio` and `p_value` are of calibrated figures (`--calibrate` given and every
    /// repeat on both sides has a calibration).
    pub calibrated: bool,
    /// The two-sided Mann–Whitney U test's p-value (see the module docs); `None` where a time
    /// is 0.
    pub p_value: Option<f64>,
    /// Whether `p_value` is exact (else the normal approximation).
    pub p_exact: bool,
    pub verdict: Verdict,
    pub repeats: [usize; 2],
    /// CPU stages: median thread CPU time, base and current.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cpu_ms: Option<[f64; 2]>,
}

/// The key runs are matched by: `scene/technique/WxH`, then the parameters in brackets.
pub fn run_key(r: &RunResult) -> String {
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
        (crate::measure::results::CALIBRATION_MS.0..=crate::measure::results::CALIBRATION_MS.1)
            .contains(&c)
    })
}

/// Per stage (and "frame"): the [`Figure`] of one run, its second value divided by the run's
/// calibration when `calibrated`.
fn figures(r: &RunResult, calibrated: bool, statistic: Statistic) -> BTreeMap<String, Figure> {
    let scale = match r.calibration_ms {
        Some(c) if calibrated => 1.0 / c,
        _ => 1.0,
    };
    let mut out = BTreeMap::new();
    for s in &r.stages {
        if let Some(ms) = s
            .best_stats()
            .map(|f| statistic.of(f))
            .filter(|m| m.is_finite())
        {
            let cpu = s.cpu_ms.as_ref().map(|c| c.median);
            out.insert(s.name.clone(), (ms, ms * scale, cpu));
        }
    }
    if let Some(f) = &r.frame {
        let ms = statistic.of(&f.frame_ms);
        if ms.is_finite() {
            out.insert("frame".to_string(), (ms, ms * scale, None));
        }
    }
    out
}

/// The rank test and verdict for one stage's repeats (see the module docs): `base` and
/// `current` are each repeat's figure, non-negative. Returns the test (`None` where a time is 0)
/// and the verdict.
pub fn judge(
    base: &[f64],
    current: &[f64],
    settings: &Settings,
) -> (Option<crate::measure::stats::RankTest>, Verdict) {
    let Settings {
        tolerance, alpha, ..
    } = *settings;
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
    let test = mann_whitney_u(current, base);
    let ratio = median(current) / median(base);
    let verdict = if test.p >= alpha {
        Verdict::Unchanged
    } else if ratio > 1.0 + tolerance {
        Verdict::Slower
    } else if ratio < 1.0 / (1.0 + tolerance) {
        Verdict::Faster
    } else {
        Verdict::Unchanged
    };
    (Some(test), verdict)
}

/// `a / b`, or `None` when either is 0.
fn ratio(a: f64, b: f64) -> Option<f64> {
    (a > 0.0 && b > 0.0).then(|| a / b)
}

/// Runs grouped by [`run_key`] (the repeats of each run).
pub fn group(runs: &[RunResult]) -> BTreeMap<String, Vec<&RunResult>> {
    let mut g: BTreeMap<String, Vec<&RunResult>> = BTreeMap::new();
    for r in runs {
        g.entry(run_key(r)).or_default().push(r);
    }
    g
}

/// The runs (by [`run_key`]) that are on one side only, BASE's then CURRENT's: [`compare`]
/// passes over them, since runs are matched by scene, technique, resolution and parameters (a
/// technique that gained a parameter since the BASE runs has no match until they are run again).
pub fn unmatched(base: &[RunResult], current: &[RunResult]) -> [Vec<String>; 2] {
    let (b, c) = (group(base), group(current));
    let only = |x: &BTreeMap<String, Vec<&RunResult>>, y: &BTreeMap<String, Vec<&RunResult>>| {
        x.keys().filter(|k| !y.contains_key(*k)).cloned().collect()
    };
    [only(&b, &c), only(&c, &b)]
}

/// Compares `current` with `base` (see the module docs). Errors name the side and the run
/// that has too few repeats, or say that no run is on both sides.
pub fn compare(
    base: &[RunResult],
    current: &[RunResult],
    settings: &Settings,
) -> Result<Vec<CompareRow>> {
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
        let all_calibrated = bs.iter().chain(cs.iter()).all(|r| has_calibration(r));
        let calibrated = settings.calibrate && all_calibrated;
        let bf: Vec<_> = bs
            .iter()
            .map(|r| figures(r, all_calibrated, settings.statistic))
            .collect();
        let cf: Vec<_> = cs
            .iter()
            .map(|r| figures(r, all_calibrated, settings.statistic))
            .collect();
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
            let (bd, cd) = if calibrated {
                (bn.clone(), cn.clone())
            } else {
                (raw(&bv), raw(&cv))
            };
            let (test, verdict) = judge(&bd, &cd, settings);
            let (base_ms, current_ms) = (median(&raw(&bv)), median(&raw(&cv)));
            rows.push(CompareRow {
                run: key.clone(),
                stage,
                base_ms,
                current_ms,
                statistic: settings.statistic,
                ratio_raw: ratio(current_ms, base_ms),
                ratio: ratio(median(&cd), median(&bd)),
                ratio_calibrated: ratio(median(&cn), median(&bn)).filter(|_| all_calibrated),
                calibrated,
                p_value: test.map(|t| t.p),
                p_exact: test.is_some_and(|t| t.exact),
                verdict,
                repeats: [bv.len(), cv.len()],
                cpu_ms: cpu(&bv).zip(cpu(&cv)).map(|(a, b)| [a, b]),
            });
        }
    }
    Ok(rows)
}

/// The comparison as a table (see the module docs for the columns' meaning).
pub fn compare_table(rows: &[CompareRow], settings: &Settings) -> Table {
    let Settings {
        tolerance,
        alpha,
        calibrate,
        statistic,
    } = *settings;
    let columns = [
        "run",
        "stage",
        "base ms",
        "current ms",
        "ratio (raw)",
        "ratio (calibrated)",
        "p",
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
                Cell::Num(r.ratio_calibrated, 3),
                Cell::text(r.p_value.map_or("–".to_string(), |p| {
                    format!(
                        "{p:.4}{}{}",
                        if r.p_exact { "" } else { " (normal)" },
                        if r.calibrated || !calibrate {
                            ""
                        } else {
                            " (raw)"
                        }
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
            "Per stage, the median over the repeats of each repeat's {} (ms{}). Ratios are CURRENT / BASE; \
             \"calibrated\" divides each repeat by the calibration workload timed in its session{}. p: the \
             two-sided Mann–Whitney U test of the CURRENT repeats against the BASE repeats ({}), exact \
             (fewer than 8 repeats a side, no ties) or \"(normal)\": the normal approximation with tie \
             correction. Verdict: slower when p < {alpha} and the ratio is above {:.2}, faster \
             when p < {alpha} and it is below {:.3}, else unchanged (tolerance {tolerance}); a stage timed \
             at 0 ms has no ratio.",
            statistic.name(),
            if statistic == Statistic::Min {
                "; --statistic median for the median frame"
            } else {
                ""
            },
            if calibrate { "" } else { " (--calibrate was not given: shown only)" },
            if calibrate {
                "calibrated; \"(raw)\" where a repeat on either side has no calibration, and then both sides are compared raw"
            } else {
                "raw times, as the ratio (raw)"
            },
            1.0 + tolerance,
            1.0 / (1.0 + tolerance)
        )],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::results::{StageKind, StageResult};
    use crate::measure::stats::Stats;

    fn run(stages: &[(&str, f64)], calibration: impl Into<Option<f64>>) -> RunResult {
        let mut r: RunResult = serde_json::from_value(serde_json::json!({
            "schema_version": crate::measure::results::SCHEMA_VERSION,
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

    const A: f64 = DEFAULT_ALPHA;

    /// Settings with this tolerance, the default alpha and the calibration used.
    fn t(tolerance: f64) -> Settings {
        Settings::new(tolerance, A, true, Statistic::Median).unwrap()
    }

    /// Noise and a machine twice as slow in one session give "unchanged"; a stage 1.5× slower
    /// is "slower" and the others stay "unchanged"; too few repeats is an error naming the side
    /// and the run.
    #[test]
    fn verdicts_follow_the_rank_test_and_the_calibration() {
        let noise = [1.0, 1.04, 0.97, 1.01, 0.99];
        let base: Vec<RunResult> = noise
            .iter()
            .map(|n| run(&[("a", 2.0 * n), ("b", 5.0 * n)], 10.0))
            .collect();
        // The same work; two sessions ran on a machine twice as slow, and their calibrations
        // say so.
        let same: Vec<RunResult> = [(1.02, 10.0), (2.0, 20.0), (0.99, 10.0), (2.06, 20.0)]
            .iter()
            .chain(&[(0.98, 10.0)])
            .map(|(n, c)| run(&[("a", 2.0 * n), ("b", 5.0 * n)], *c))
            .collect();
        let rows = compare(&base, &same, &t(0.1)).unwrap();
        assert!(
            rows.iter().all(|r| r.verdict == Verdict::Unchanged),
            "{rows:?}"
        );
        let slow: Vec<RunResult> = [1.0, 1.03, 0.98, 1.02, 0.97]
            .iter()
            .map(|n| run(&[("a", 3.0 * n), ("b", 5.0 * n)], 10.0))
            .collect();
        let rows = compare(&base, &slow, &t(0.1)).unwrap();
        let row = |s: &str| rows.iter().find(|r| r.stage == s).unwrap().clone();
        assert_eq!(row("a").verdict, Verdict::Slower);
        // Every SLOW repeat above every BASE repeat: the exact test's smallest p, 2/252.
        let p = row("a").p_value.unwrap();
        assert!(row("a").p_exact && (p - 2.0 / 252.0).abs() < 1e-12, "{p}");
        assert_eq!(row("b").verdict, Verdict::Unchanged);
        let rows = compare(&slow, &base, &t(0.1)).unwrap();
        assert_eq!(
            rows.iter().find(|r| r.stage == "a").unwrap().verdict,
            Verdict::Faster
        );
        let e = compare(&base[..4], &slow, &t(0.1)).unwrap_err().to_string();
        assert!(
            e.contains("BASE has 4 repeat(s) of cornell/direct/64x48") && e.contains("at least 5"),
            "{e}"
        );
        let e = compare(&base, &slow[..3], &t(0.1)).unwrap_err().to_string();
        assert!(e.contains("CURRENT has 3 repeat(s)"), "{e}");
        let e = Settings::new(0.1, 1.5, true, Statistic::Min)
            .unwrap_err()
            .to_string();
        assert!(e.contains("alpha"), "{e}");
        let e = Settings::new(-0.1, A, true, Statistic::Min)
            .unwrap_err()
            .to_string();
        assert!(e.contains("tolerance"), "{e}");
    }

    /// Repeats of one stage "a" whose frames took `fastest` ms and, in each repeat, some frames
    /// `slowed` times that (a busy machine, or a stutter).
    fn frames(fastest: f64, slowed: &[f64]) -> Vec<RunResult> {
        slowed
            .iter()
            .map(|k| {
                let mut r = run(&[("a", 0.0)], 10.0);
                let f = [
                    fastest,
                    fastest * k,
                    fastest * k,
                    fastest * k.sqrt(),
                    fastest,
                ];
                r.stages[0].wall_ms = Some(Stats::of(&f));
                r
            })
            .collect()
    }

    /// The fastest frame decides by default: a 30 % slower stage on a loaded machine (each
    /// repeat's median frame 1 to 3 times its fastest, at random) is found by the fastest
    /// frames and hidden in the medians' noise; a stutter (most frames twice as slow, the
    /// fastest unchanged) is found by the median and not by the fastest frame. Catches a
    /// figure that ignores `--statistic` (either way round).
    #[test]
    fn the_statistic_chooses_the_figure() {
        let settings = |statistic| Settings::new(0.15, A, false, statistic).unwrap();
        let verdict = |base: &[RunResult], current: &[RunResult], statistic| {
            compare(base, current, &settings(statistic)).unwrap()[0].verdict
        };
        let (load_a, load_b) = ([1.0, 2.9, 1.4, 2.2, 1.1], [2.5, 1.2, 3.0, 1.0, 1.8]);
        let (base, slower) = (frames(1.0, &load_a), frames(1.3, &load_b));
        assert_eq!(verdict(&base, &slower, Statistic::Min), Verdict::Slower);
        assert_eq!(
            verdict(&base, &slower, Statistic::Median),
            Verdict::Unchanged
        );
        let steady = frames(1.0, &[1.0, 1.01, 1.0, 1.02, 1.0]);
        let stutter = frames(1.0, &[2.0, 2.1, 2.0, 1.9, 2.05]);
        assert_eq!(
            verdict(&steady, &stutter, Statistic::Min),
            Verdict::Unchanged
        );
        assert_eq!(
            verdict(&steady, &stutter, Statistic::Median),
            Verdict::Slower
        );
        assert_eq!(Settings::default().statistic, Statistic::Min);
    }

    /// Both conditions decide: a large shift the rank test cannot tell from the spread stays
    /// unchanged (the old band rule's job, now the test's), and a shift the test is sure of but
    /// within the tolerance stays unchanged too; only both together make a verdict.
    #[test]
    fn a_verdict_needs_both_the_test_and_the_effect_size() {
        let base = [1.0, 1.1, 0.9, 1.05, 0.95];
        // Every CURRENT repeat 1.5× its BASE repeat: p = 2/252 and ratio 1.5.
        let slow: Vec<f64> = base.iter().map(|x| x * 1.5).collect();
        let (test, v) = judge(&base, &slow, &t(0.25));
        assert_eq!(v, Verdict::Slower);
        assert!(test.unwrap().p < A);
        // The same ratio of medians, but one CURRENT repeat as fast as BASE: the ranks
        // overlap (U = 22 of 25) and p = 14/252 = 0.0556 (exact;
        // scipy.stats.mannwhitneyu([0.97, 1.5, 1.6, 1.45, 1.55], base) gives 0.05555...).
        let overlapping = [0.97, 1.5, 1.6, 1.45, 1.55];
        let (test, v) = judge(&base, &overlapping, &t(0.25));
        let test = test.unwrap();
        assert!(
            test.exact && test.u == 22.0 && (test.p - 14.0 / 252.0).abs() < 1e-12,
            "{test:?}"
        );
        assert_eq!(v, Verdict::Unchanged, "p {} is not below {A}", test.p);
        // Separated ranks but only 10 % slower, tolerance 25 %: unchanged; tolerance 5 %: slower.
        let slightly: Vec<f64> = [1.0, 1.01, 1.02, 1.03, 1.04].map(|x| x * 1.1).into();
        let tight = [1.0, 1.01, 1.02, 1.03, 1.04];
        assert_eq!(judge(&tight, &slightly, &t(0.25)).1, Verdict::Unchanged);
        assert_eq!(judge(&tight, &slightly, &t(0.05)).1, Verdict::Slower);
        assert_eq!(judge(&slightly, &tight, &t(0.05)).1, Verdict::Faster);
    }

    /// A side whose files carry no calibration: both sides are compared raw. Before, the
    /// calibrated side was divided by its 10 ms and the other not, and every stage was
    /// "slower" (or "faster") although the times were the same.
    #[test]
    fn a_side_without_calibration_is_compared_raw() {
        let side = |calibration: Option<f64>| -> Vec<RunResult> {
            [1.0, 1.02, 0.99, 1.01, 0.98]
                .iter()
                .map(|n| run(&[("a", 2.0 * n), ("b", 5.0 * n)], calibration))
                .collect()
        };
        for (base, current) in [(Some(10.0), None), (None, Some(10.0))] {
            let rows = compare(&side(base), &side(current), &t(0.1)).unwrap();
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
        let rows = compare(&side(Some(10.0)), &mixed, &t(0.1)).unwrap();
        assert!(rows
            .iter()
            .all(|r| !r.calibrated && r.verdict == Verdict::Unchanged));
        let table = compare_table(&rows, &t(0.1)).to_terminal();
        assert!(table.contains("(raw)"), "{table}");
    }

    /// A stage timed at 0 ms has no ratio (before: "inf–inf" and a verdict from it); a stage
    /// that took no time before and takes some now is slower, and the reverse faster.
    #[test]
    fn zero_ms_stages_have_no_ratio() {
        let side = |a: f64, b: f64| -> Vec<RunResult> {
            (0..5).map(|_| run(&[("a", a), ("b", b)], 10.0)).collect()
        };
        let rows = compare(&side(0.0, 0.0), &side(0.0, 1.0), &t(0.1)).unwrap();
        let row = |s: &str| rows.iter().find(|r| r.stage == s).unwrap();
        assert_eq!(row("a").verdict, Verdict::Unchanged);
        assert_eq!(row("b").verdict, Verdict::Slower);
        for r in &rows {
            assert!(
                r.ratio.is_none() && r.ratio_raw.is_none() && r.p_value.is_none(),
                "{r:?}"
            );
        }
        let table = compare_table(&rows, &t(0.1)).to_terminal();
        assert!(!table.contains("inf"), "{table}");
        let rows = compare(&side(1.0, 1.0), &side(0.0, 1.0), &t(0.1)).unwrap();
        assert_eq!(
            rows.iter().find(|r| r.stage == "a").unwrap().verdict,
            Verdict::Faster
        );
    }

    /// The Markdown's run labels keep only the parameters that tell the compared runs of one
    /// scene, technique and resolution apart, and none for a run alone; the regression leads.
    #[test]
    fn markdown_labels_name_only_differing_parameters() {
        let row = |run: &str, stage: &str, verdict: Verdict, ratio: f64| CompareRow {
            run: run.to_string(),
            stage: stage.to_string(),
            base_ms: 1.0,
            current_ms: ratio,
            statistic: Statistic::Min,
            ratio_raw: Some(ratio),
            ratio: Some(ratio),
            ratio_calibrated: None,
            calibrated: false,
            p_value: Some(0.008),
            p_exact: true,
            verdict,
            repeats: [5, 5],
            cpu_ms: None,
        };
        let (a, b) = (
            "cornell/ism/256x192 (tiles=4x4, vpls=256)",
            "cornell/ism/256x192 (tiles=4x4, vpls=1024)",
        );
        let rows = [
            row(a, "pull-push", Verdict::Faster, 0.5),
            row(
                "cornell/laine/128x96 (vpls=64)",
                "compose",
                Verdict::Unchanged,
                1.0,
            ),
            row(b, "split", Verdict::Slower, 1.4),
        ];
        let md = compare_markdown(&rows, &Settings::default(), ["b", "c"], &[]);
        let lines: Vec<&str> = md.lines().filter(|l| l.starts_with("| cornell")).collect();
        assert_eq!(lines.len(), 2, "{md}");
        assert!(
            lines[0].starts_with("| cornell/ism/256x192 (vpls=1024) | split |"),
            "{md}"
        );
        assert!(
            lines[1].starts_with("| cornell/ism/256x192 (vpls=256) | pull-push |"),
            "{md}"
        );
        assert!(md.contains("Unchanged: 1 of 3 stages."), "{md}");
    }
}
