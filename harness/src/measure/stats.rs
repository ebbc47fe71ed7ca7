//! Summary statistics over per-frame samples.

use serde::{Deserialize, Serialize};

/// Statistics of one series of samples (milliseconds for timings). A non-finite value (a
/// technique whose output has NaNs gives NaN metrics) is written as JSON `null` and read back
/// as NaN ([`nullable`]), so such a results file still loads and shows it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Stats {
    pub count: usize,
    #[serde(with = "nullable")]
    pub mean: f64,
    #[serde(with = "nullable")]
    pub median: f64,
    #[serde(with = "nullable")]
    pub p5: f64,
    #[serde(with = "nullable")]
    pub p95: f64,
    /// 99th percentile (stutters: Laine et al. 2007 report them for VPL management).
    #[serde(default, with = "nullable")]
    pub p99: f64,
    #[serde(with = "nullable")]
    pub min: f64,
    #[serde(with = "nullable")]
    pub max: f64,
}

/// Serde for an `f64` that may be non-finite: NaN and ±∞ are written as `null` (JSON has no
/// such numbers) and `null` is read as NaN.
pub mod nullable {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        if x.is_finite() {
            s.serialize_f64(*x)
        } else {
            s.serialize_none()
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
    }
}

impl Stats {
    /// Statistics of `samples` (any order). Percentiles use linear interpolation between the
    /// closest ranks. Empty input gives all zeros and `count` 0.
    pub fn of(samples: &[f64]) -> Stats {
        if samples.is_empty() {
            return Stats::default();
        }
        let mut s: Vec<f64> = samples.to_vec();
        s.sort_by(|a, b| a.total_cmp(b));
        let n = s.len();
        let pct = |p: f64| percentile(&s, p);
        Stats {
            count: n,
            mean: s.iter().sum::<f64>() / n as f64,
            median: pct(0.5),
            p5: pct(0.05),
            p95: pct(0.95),
            p99: pct(0.99),
            min: s[0],
            max: s[n - 1],
        }
    }
}

/// The `p` percentile (0 to 1) of `sorted` (ascending, not empty), interpolated linearly
/// between the closest ranks; a rank hit exactly is that sample (so an infinite neighbour does
/// not make it NaN).
pub fn percentile(sorted: &[f64], p: f64) -> f64 {
    let n = sorted.len();
    let x = p * (n - 1) as f64;
    let i = x.floor() as usize;
    let j = (i + 1).min(n - 1);
    let t = x - i as f64;
    if t == 0.0 {
        return sorted[i];
    }
    sorted[i] + (sorted[j] - sorted[i]) * t
}

/// The median of `samples` (any order, not empty): [`Stats::of`]'s median without the rest.
pub fn median(samples: &[f64]) -> f64 {
    let mut s = samples.to_vec();
    s.sort_by(f64::total_cmp);
    percentile(&s, 0.5)
}

/// A two-sided Mann–Whitney U test of two samples (is one side's distribution shifted from
/// the other's?), as `gibench compare` decides by it (Google Benchmark's `compare.py` uses the
/// same test).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RankTest {
    /// U of the first sample: the pairs (x of the first, y of the second) with x > y, ties
    /// counting one half.
    pub u: f64,
    /// Two-sided p-value: how likely a U at least as far from its mean is when both samples
    /// come from one distribution.
    pub p: f64,
    /// Whether `p` is exact (the distribution of U counted over every split of the pooled
    /// samples) or the normal approximation.
    pub exact: bool,
}

/// [`mann_whitney_u`] is exact when the smaller side has at most this many samples and no
/// value occurs twice, as SciPy's `method="auto"` decides.
pub const EXACT_UP_TO: usize = 8;

/// The two-sided Mann–Whitney U test of `a` against `b` (both non-empty, finite), computed as
/// `scipy.stats.mannwhitneyu(a, b, alternative="two-sided", method="auto",
/// use_continuity=True)` does:
///
/// * **exact** when the smaller side has at most [`EXACT_UP_TO`] samples and no value occurs
///   twice: U's distribution under the null hypothesis is counted over all
///   C(n₁ + n₂, n₁) orderings, and p = 2 · P(U ≥ max(U₁, U₂)), at most 1 (with 5 against 5
///   the smallest p is 2/252 ≈ 0.0079);
/// * otherwise the **normal approximation** with the tie correction of the variance and a
///   continuity correction of 0.5: z = (max(U₁, U₂) − n₁n₂/2 − 0.5) / σ,
///   σ² = n₁n₂/12 · ((n + 1) − Σ(t³ − t) / (n(n − 1))) over the groups of t tied values, and
///   p = 2 · (1 − Φ(z)), at most 1. Where every value is the same (σ = 0) p is 1.
pub fn mann_whitney_u(a: &[f64], b: &[f64]) -> RankTest {
    let (n1, n2) = (a.len(), b.len());
    assert!(
        n1 > 0 && n2 > 0,
        "mann_whitney_u needs samples on both sides"
    );
    // Midranks of the pooled samples (1-based), and the sizes of the tie groups.
    let mut pooled: Vec<(f64, bool)> = a
        .iter()
        .map(|&x| (x, true))
        .chain(b.iter().map(|&y| (y, false)))
        .collect();
    pooled.sort_by(|x, y| x.0.total_cmp(&y.0));
    let n = pooled.len();
    let (mut rank_sum_a, mut tie_term, mut ties) = (0.0, 0.0, false);
    let mut i = 0;
    while i < n {
        let mut j = i + 1;
        while j < n && pooled[j].0 == pooled[i].0 {
            j += 1;
        }
        let t = (j - i) as f64;
        let midrank = (i + j + 1) as f64 / 2.0;
        rank_sum_a += midrank * pooled[i..j].iter().filter(|p| p.1).count() as f64;
        tie_term += t * t * t - t;
        ties |= j - i > 1;
        i = j;
    }
    let (f1, f2) = (n1 as f64, n2 as f64);
    let u1 = rank_sum_a - f1 * (f1 + 1.0) / 2.0;
    let u_big = u1.max(f1 * f2 - u1);
    if n1.min(n2) <= EXACT_UP_TO && !ties {
        let counts = u_counts(n1, n2);
        let total: f64 = counts.iter().sum();
        let at_least: f64 = counts[u_big.round() as usize..].iter().sum();
        return RankTest {
            u: u1,
            p: (2.0 * at_least / total).min(1.0),
            exact: true,
        };
    }
    let nf = n as f64;
    let variance = f1 * f2 / 12.0 * ((nf + 1.0) - tie_term / (nf * (nf - 1.0)));
    let p = if variance > 0.0 {
        let z = (u_big - f1 * f2 / 2.0 - 0.5) / variance.sqrt();
        // 1 − Φ(z) = erfc(z / √2) / 2.
        (libm::erfc(z / std::f64::consts::SQRT_2)).min(1.0)
    } else {
        1.0
    };
    RankTest {
        u: u1,
        p,
        exact: false,
    }
}

/// How many orderings of `m` values of one sample and `n` of another give each U (index u,
/// 0 to m·n), every value distinct: the coefficients of the Gaussian binomial
/// [m + n choose m]_q = ∏ᵢ₌₁..ₘ (1 − q^(n+i)) / (1 − q^i), multiplied out one factor at a time
/// (each division by 1 − q^i is exact). Cost m² · n, so small for the exact test's m ≤ 8.
fn u_counts(m: usize, n: usize) -> Vec<f64> {
    let (m, n) = (m.min(n), m.max(n));
    let mut c = vec![0.0; m * n + 1];
    c[0] = 1.0;
    for i in 1..=m {
        // × (1 − q^(n+i)), from the top down.
        for k in (n + i..=m * n).rev() {
            c[k] -= c[k - n - i];
        }
        // ÷ (1 − q^i): c'[k] = c[k] + c'[k − i], from the bottom up.
        for k in i..=m * n {
            c[k] += c[k - i];
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    /// NaN statistics survive a JSON round trip (as null, read back as NaN) instead of making
    /// the file unreadable.
    #[test]
    fn non_finite_statistics_round_trip_through_json() {
        let s = Stats::of(&[1.0, f64::NAN, f64::INFINITY]);
        let json = serde_json::to_string(&s).unwrap();
        assert!(json.contains("null"), "{json}");
        let back: Stats = serde_json::from_str(&json).unwrap();
        assert_eq!(back.count, 3);
        assert_eq!(back.min, 1.0);
        assert!(back.max.is_nan() && back.mean.is_nan());
    }

    #[test]
    fn percentiles_interpolate() {
        let s = Stats::of(&[4.0, 1.0, 3.0, 2.0, 5.0]);
        assert_eq!(s.count, 5);
        assert_eq!(s.median, 3.0);
        assert_eq!(s.min, 1.0);
        assert_eq!(s.max, 5.0);
        assert!((s.mean - 3.0).abs() < 1e-12);
        assert!((s.p5 - 1.2).abs() < 1e-12);
        assert!((s.p95 - 4.8).abs() < 1e-12);
        assert!((s.p99 - 4.96).abs() < 1e-12);
        assert_eq!(Stats::of(&[]).count, 0);
    }

    /// The median `compare` uses: the middle sample of an odd count even beside an infinity
    /// (a stage that timed out), the midpoint of the two middle samples of an even count.
    #[test]
    fn median_takes_the_middle_sample_and_ignores_an_infinite_neighbour() {
        assert_eq!(median(&[f64::INFINITY, 2.0, 1.0]), 2.0);
        assert_eq!(Stats::of(&[f64::INFINITY, 2.0, 1.0]).median, 2.0);
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), 2.5);
    }

    /// The rank test against SciPy 1.17.1's values, for each input below:
    /// `scipy.stats.mannwhitneyu(a, b, alternative="two-sided", method="auto")` (statistic is
    /// U of `a`). Catches a wrong exact distribution (the counts' recurrence), a one-sided p,
    /// a missing continuity or tie correction, midranks of ties, and the choice between exact
    /// and normal.
    #[test]
    fn mann_whitney_u_matches_scipy() {
        // (a, b, U of a, two-sided p, exact).
        type Case<'a> = (&'a [f64], &'a [f64], f64, f64, bool);
        let cases: [Case; 8] = [
            // Exact: no ties, at most 8 on the smaller side.
            (
                &[1., 2., 3., 4., 5.],
                &[6., 7., 8., 9., 10.],
                0.0,
                0.007936507936507936,
                true,
            ),
            (
                &[1., 3., 5., 7., 9.],
                &[2., 4., 6., 8., 10.],
                10.0,
                0.6904761904761905,
                true,
            ),
            (&[1.2, 3.4, 2.2], &[0.5, 4.1, 5.0, 6.3], 3.0, 0.4, true),
            (
                &[10.1, 10.4, 9.8, 10.0, 10.3, 10.2, 9.9],
                &[10.5, 10.6, 10.35, 10.7, 10.8, 10.9, 10.05],
                5.0,
                0.011072261072261072,
                true,
            ),
            // Ties: the normal approximation with the tie correction.
            (
                &[1., 2., 2., 3., 4.],
                &[2., 3., 3., 5., 6.],
                6.0,
                0.19882894401644247,
                false,
            ),
            // 8 and 9 samples: still exact (the normal approximation gives 0.16294).
            (
                &[1.0, 2.1, 3.2, 4.3, 5.4, 6.5, 7.6, 8.7],
                &[2.5, 3.6, 4.7, 5.8, 6.9, 8.0, 9.1, 10.2, 11.3],
                21.0,
                0.16717400246812014,
                true,
            ),
            // 9 and 9: normal (exact would give 0.29733).
            (
                &[1.0, 2.1, 3.2, 4.3, 5.4, 6.5, 7.6, 8.7, 9.9],
                &[2.5, 3.6, 4.7, 5.8, 6.9, 8.0, 9.1, 10.2, 11.3],
                28.0,
                0.28931483238198774,
                false,
            ),
            // Every value the same: no evidence either way.
            (&[5., 5., 5.], &[5., 5., 5.], 4.5, 1.0, false),
        ];
        for (a, b, u, p, exact) in cases {
            let t = mann_whitney_u(a, b);
            assert_eq!(t.u, u, "{a:?} {b:?}");
            assert!((t.p - p).abs() < 1e-9, "{a:?} {b:?}: p {} (scipy {p})", t.p);
            assert_eq!(t.exact, exact, "{a:?} {b:?}");
            // Two-sided: swapping the sides gives the other U and the same p.
            let back = mann_whitney_u(b, a);
            assert_eq!(back.u, (a.len() * b.len()) as f64 - u);
            assert!((back.p - t.p).abs() < 1e-12);
        }
        // The exact counts over all C(10, 5) = 252 orderings (by hand for the edges: one
        // ordering each gives U = 0, 1 and 25, two give U = 2, three U = 3), and symmetric.
        let counts = u_counts(5, 5);
        assert_eq!(counts.len(), 26);
        assert_eq!(counts.iter().sum::<f64>(), 252.0);
        assert_eq!(&counts[..4], &[1.0, 1.0, 2.0, 3.0]);
        assert_eq!(counts[25], 1.0);
        assert!((0..26).all(|u| counts[u] == counts[25 - u]));
        assert_eq!(u_counts(3, 7), u_counts(7, 3));
        assert_eq!(u_counts(3, 7).iter().sum::<f64>(), 120.0);
    }
}
