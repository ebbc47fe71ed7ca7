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
}
