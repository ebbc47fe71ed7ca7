//! Summary statistics over per-frame samples.

use serde::{Deserialize, Serialize};

/// Statistics of one series of samples (milliseconds for timings).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Stats {
    pub count: usize,
    pub mean: f64,
    pub median: f64,
    pub p5: f64,
    pub p95: f64,
    /// 99th percentile (stutters: Laine et al. 2007 report them for VPL management).
    #[serde(default)]
    pub p99: f64,
    pub min: f64,
    pub max: f64,
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
        let pct = |p: f64| {
            let x = p * (n - 1) as f64;
            let i = x.floor() as usize;
            let j = (i + 1).min(n - 1);
            s[i] + (s[j] - s[i]) * (x - i as f64)
        };
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
