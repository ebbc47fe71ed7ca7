//! Shards: one machine of many runs a deterministic 1/N of a command's work units.
//!
//! The shard (index `i` of `N`, 0-based) comes from `--shard i/N`, or else from the environment
//! of the job array that started the process, read here once:
//!
//! * Slurm arrays: `SLURM_ARRAY_TASK_ID` − `SLURM_ARRAY_TASK_MIN` (0 when unset), divided by
//!   `SLURM_ARRAY_TASK_STEP` (1 when unset), of `SLURM_ARRAY_TASK_COUNT`;
//! * Kubernetes Indexed Jobs: `JOB_COMPLETION_INDEX`, of `--shard-count N` or else
//!   `GIBENCH_SHARD_COUNT` (Kubernetes does not pass the Job's `completions` to the pod: the
//!   manifest in `deploy/` sets `GIBENCH_SHARD_COUNT` to the same number);
//! * Buildkite parallel steps: `BUILDKITE_PARALLEL_JOB` of `BUILDKITE_PARALLEL_JOB_COUNT`.
//!
//! A flag and an environment that disagree, or two environments that disagree, are refused,
//! naming both. [`assign`] splits the units: longest estimate first, each to the least-loaded
//! shard (ties by name, then by the lower shard), so every machine computes the same split
//! from the same estimates, whatever the timing.

use std::fmt;

use clap::Args;
use gibench_harness::{Error, Result};

/// The command-line side of sharding (flattened into the commands that shard).
#[derive(Args, Clone, Default, Debug)]
pub struct ShardArgs {
    /// Run only shard I of N (0-based: 0/3, 1/3, 2/3) of the work units, balanced by their
    /// estimates; default: from a Slurm array, Kubernetes Indexed Job or Buildkite parallel
    /// step's environment, else all of them.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    /// The shard count where the environment gives only an index (Kubernetes'
    /// `JOB_COMPLETION_INDEX`); also read from `GIBENCH_SHARD_COUNT`.
    #[arg(long, value_name = "N")]
    pub shard_count: Option<String>,
}

/// One shard: `index` of `count` (0-based), and where it came from (printed).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
    pub source: String,
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// An error naming `name`: an environment variable (upper case) or an option.
fn err(name: &str, message: impl Into<String>) -> Error {
    if name.chars().all(|c| c.is_ascii_uppercase() || c == '_') {
        Error::Invalid(format!("environment variable {name}: {}", message.into()))
    } else {
        Error::param(name, message)
    }
}

/// Parses a whole non-negative number given to `name`.
fn number(name: &str, value: &str, expected: &str) -> Result<usize> {
    value
        .trim()
        .parse::<usize>()
        .map_err(|_| err(name, format!("expected {expected}, got '{value}'")))
}

/// Checks `index` < `count` and `count` ≥ 1, naming `name`.
fn shard(name: &str, index: usize, count: usize, source: String) -> Result<Shard> {
    if count == 0 {
        return Err(err(
            name,
            format!("the shard count must be at least 1 (got {index}/{count})"),
        ));
    }
    if index >= count {
        return Err(err(
            name,
            format!(
                "the shard index is 0-based and must be below the count: 0/{count} to {}/{count} (got {index}/{count})",
                count - 1
            ),
        ));
    }
    Ok(Shard {
        index,
        count,
        source,
    })
}

/// `--shard I/N`.
fn from_flag(value: &str) -> Result<Shard> {
    let expected = "I/N: shard I (0-based) of N, e.g. 0/3";
    let (i, n) = value
        .split_once('/')
        .ok_or_else(|| err("shard", format!("expected {expected}, got '{value}'")))?;
    let i = number("shard", i, expected)?;
    let n = number("shard", n, expected)?;
    shard("shard", i, n, format!("--shard {value}"))
}

/// The shards the environment `env` describes (one per job system present).
fn from_env(env: &dyn Fn(&str) -> Option<String>, count_flag: Option<&str>) -> Result<Vec<Shard>> {
    let mut found = Vec::new();
    if let Some(id) = env("SLURM_ARRAY_TASK_ID") {
        let what = "a whole number (the Slurm array task id)";
        let id = number("SLURM_ARRAY_TASK_ID", &id, what)?;
        let min = match env("SLURM_ARRAY_TASK_MIN") {
            Some(m) => number("SLURM_ARRAY_TASK_MIN", &m, "a whole number")?,
            None => 0,
        };
        let step = match env("SLURM_ARRAY_TASK_STEP") {
            Some(s) => number("SLURM_ARRAY_TASK_STEP", &s, "a whole number of at least 1")?,
            None => 1,
        };
        let count = env("SLURM_ARRAY_TASK_COUNT").ok_or_else(|| {
            err(
                "SLURM_ARRAY_TASK_COUNT",
                "is not set beside SLURM_ARRAY_TASK_ID; expected the array's task count",
            )
        })?;
        let count = number("SLURM_ARRAY_TASK_COUNT", &count, "a whole number")?;
        if id < min || step == 0 || (id - min) % step != 0 {
            return Err(err(
                "SLURM_ARRAY_TASK_ID",
                format!("expected SLURM_ARRAY_TASK_MIN ({min}) plus a multiple of SLURM_ARRAY_TASK_STEP ({step}), got {id}"),
            ));
        }
        found.push(shard(
            "SLURM_ARRAY_TASK_ID",
            (id - min) / step,
            count,
            format!("Slurm array: SLURM_ARRAY_TASK_ID={id} (min {min}, step {step}) of SLURM_ARRAY_TASK_COUNT={count}"),
        )?);
    }
    if let Some(index) = env("JOB_COMPLETION_INDEX") {
        let index = number(
            "JOB_COMPLETION_INDEX",
            &index,
            "a whole number (the Kubernetes Indexed Job's completion index)",
        )?;
        let (count, from) = match (count_flag, env("GIBENCH_SHARD_COUNT")) {
            (Some(c), _) => (number("shard-count", c, "a whole number")?, "--shard-count"),
            (None, Some(c)) => (
                number("GIBENCH_SHARD_COUNT", &c, "a whole number")?,
                "GIBENCH_SHARD_COUNT",
            ),
            (None, None) => {
                return Err(err(
                    "shard-count",
                    format!(
                        "JOB_COMPLETION_INDEX={index} gives the shard index but not the count; \
                         expected --shard-count N or GIBENCH_SHARD_COUNT=N (the Job's completions)"
                    ),
                ))
            }
        };
        found.push(shard(
            "JOB_COMPLETION_INDEX",
            index,
            count,
            format!("Kubernetes Indexed Job: JOB_COMPLETION_INDEX={index} of {from}={count}"),
        )?);
    }
    if let Some(job) = env("BUILDKITE_PARALLEL_JOB") {
        let job = number("BUILDKITE_PARALLEL_JOB", &job, "a whole number")?;
        let count = env("BUILDKITE_PARALLEL_JOB_COUNT").ok_or_else(|| {
            err(
                "BUILDKITE_PARALLEL_JOB_COUNT",
                "is not set beside BUILDKITE_PARALLEL_JOB; expected the step's parallelism",
            )
        })?;
        let count = number("BUILDKITE_PARALLEL_JOB_COUNT", &count, "a whole number")?;
        found.push(shard(
            "BUILDKITE_PARALLEL_JOB",
            job,
            count,
            format!(
                "Buildkite: BUILDKITE_PARALLEL_JOB={job} of BUILDKITE_PARALLEL_JOB_COUNT={count}"
            ),
        )?);
    }
    Ok(found)
}

impl ShardArgs {
    /// The shard this process runs (`None`: all the units), from the flags and the process's
    /// environment.
    pub fn resolve(&self) -> Result<Option<Shard>> {
        self.resolve_with(&|k| std::env::var(k).ok())
    }

    /// [`ShardArgs::resolve`] with the environment `env` (tests pass their own).
    pub fn resolve_with(&self, env: &dyn Fn(&str) -> Option<String>) -> Result<Option<Shard>> {
        let flag = self.shard.as_deref().map(from_flag).transpose()?;
        if let (Some(f), Some(c)) = (&flag, &self.shard_count) {
            let c = number("shard-count", c, "a whole number")?;
            if c != f.count {
                return Err(err(
                    "shard-count",
                    format!("{c} disagrees with --shard {f} (count {})", f.count),
                ));
            }
        }
        let found = from_env(env, self.shard_count.as_deref())?;
        // Every source given must name the same shard.
        let mut all: Vec<Shard> = flag.into_iter().chain(found).collect();
        if let Some(first) = all.first() {
            if let Some(other) = all
                .iter()
                .find(|s| (s.index, s.count) != (first.index, first.count))
            {
                return Err(err(
                    "shard",
                    format!(
                        "the sources disagree: {} says shard {first}, {} says shard {other}; expected one shard",
                        first.source, other.source
                    ),
                ));
            }
        }
        if all.is_empty() && self.shard_count.is_some() {
            return Err(err(
                "shard-count",
                "given without a shard index; expected --shard I/N or JOB_COMPLETION_INDEX",
            ));
        }
        Ok((!all.is_empty()).then(|| all.remove(0)))
    }
}

/// Splits units (name, estimated cost) over `count` shards: longest estimate first (ties by
/// name), each to the least-loaded shard so far (ties: the lower shard). Returns each unit's
/// shard, in the order given. The same names and estimates give the same split on every
/// machine.
pub fn assign(units: &[(&str, f64)], count: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..units.len()).collect();
    order.sort_by(|&a, &b| {
        units[b]
            .1
            .total_cmp(&units[a].1)
            .then_with(|| units[a].0.cmp(units[b].0))
    });
    let mut load = vec![0.0f64; count.max(1)];
    let mut shard = vec![0; units.len()];
    for u in order {
        let least = (0..load.len())
            .min_by(|&a, &b| load[a].total_cmp(&load[b]).then(a.cmp(&b)))
            .unwrap_or(0);
        load[least] += units[u].1.max(0.0);
        shard[u] = least;
    }
    shard
}

/// This shard's part of `units` (name, estimate), split by [`assign`]: prints the whole split
/// (every shard's units, `label` giving each unit's estimate in words, `basis` what the
/// estimates are) and returns, in the order given, whether each unit is this shard's.
pub fn own_units(
    units: &[(&str, f64)],
    s: &Shard,
    label: &dyn Fn(f64) -> String,
    basis: &str,
) -> Vec<bool> {
    let split = assign(units, s.count);
    for k in 0..s.count {
        let part: Vec<String> = units
            .iter()
            .zip(&split)
            .filter(|(_, &i)| i == k)
            .map(|(u, _)| format!("{} ({})", u.0, label(u.1)))
            .collect();
        eprintln!(
            "  shard {k}/{}{}: {}",
            s.count,
            if k == s.index { " (this one)" } else { "" },
            if part.is_empty() {
                "nothing".to_string()
            } else {
                part.join(", ")
            }
        );
    }
    eprintln!("  (balanced by {basis})");
    split.iter().map(|&k| k == s.index).collect()
}

/// The file a shard of `gibench run` or `gibench sweep` leaves beside its results, which
/// `gibench merge` reads: [`ShardRecord`].
pub const RECORD: &str = "gibench-shard.json";

/// What a shard of `gibench run` / `gibench sweep` ran, out of what, with which settings.
#[derive(serde::Serialize, serde::Deserialize, Clone, Debug)]
pub struct ShardRecord {
    /// `run` or `sweep`.
    pub command: String,
    /// `I/N`.
    pub shard: String,
    /// Where the shard came from (the flag or the job system's variables).
    pub source: String,
    /// Every unit of the whole selection, in the command's order (`SCENE-TECHNIQUE` for a
    /// run, the swept value for a sweep).
    pub units: Vec<String>,
    /// This shard's units and each one's results file (relative to the folder).
    pub ran: Vec<(String, String)>,
    /// The settings every shard must share (frames, resolution, timing, seed, …, the commit):
    /// name → value.
    pub settings: std::collections::BTreeMap<String, String>,
}

impl ShardRecord {
    /// The record of `shard` of `command` (`run` or `sweep`) over `units`, before any ran.
    pub fn new(
        command: &str,
        shard: &Shard,
        units: Vec<String>,
        settings: std::collections::BTreeMap<String, String>,
    ) -> ShardRecord {
        ShardRecord {
            command: command.into(),
            shard: shard.to_string(),
            source: shard.source.clone(),
            units,
            ran: Vec::new(),
            settings,
        }
    }

    /// Reads `dir`'s record, naming the file on error.
    pub fn read(dir: &std::path::Path) -> Result<ShardRecord> {
        let path = dir.join(RECORD);
        // Bounded: a record is a few kilobytes; /dev/zero put in its place is refused.
        let bytes = gibench_harness::error::read_bounded(&path, 16 << 20)?;
        serde_json::from_slice(&bytes).map_err(|e| {
            Error::bad_file(&path, format!("not a gibench run/sweep shard record: {e}"))
        })
    }

    /// Writes the record into `dir` (inside the open output set).
    pub fn write(&self, dir: &std::path::Path) -> Result<()> {
        let bytes = serde_json::to_vec_pretty(self).map_err(|e| Error::Invalid(e.to_string()))?;
        gibench_harness::output::write_atomic(&dir.join(RECORD), &bytes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env<'a>(vars: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<String> + 'a {
        move |k| {
            vars.iter()
                .find(|(n, _)| *n == k)
                .map(|(_, v)| v.to_string())
        }
    }

    fn resolve(
        shard: Option<&str>,
        count: Option<&str>,
        vars: &[(&str, &str)],
    ) -> Result<Option<Shard>> {
        ShardArgs {
            shard: shard.map(String::from),
            shard_count: count.map(String::from),
        }
        .resolve_with(&env(vars))
    }

    /// Catches: a split that depends on the input order, leaves a unit out, gives one to two
    /// shards, or ignores the estimates (a count split would put both long units together).
    #[test]
    fn assignment_is_deterministic_complete_and_balanced_by_estimate() {
        let units = [
            ("a", 10.0),
            ("b", 1.0),
            ("c", 9.0),
            ("d", 1.0),
            ("e", 1.0),
            ("f", 1.0),
            ("g", 0.0),
        ];
        let split = assign(&units, 2);
        // Every unit on exactly one shard in range.
        assert_eq!(split.len(), units.len());
        assert!(split.iter().all(|&s| s < 2));
        // LPT: a (10) to 0, c (9) to 1, then the 1s to the lighter shard: 10 | 9+1+1 … → loads 12, 11.
        let load = |s: usize| -> f64 {
            units
                .iter()
                .zip(&split)
                .filter(|(_, &k)| k == s)
                .map(|(u, _)| u.1)
                .sum()
        };
        assert_ne!(
            split[0], split[2],
            "the two long units share a shard: {split:?}"
        );
        assert!((load(0) - load(1)).abs() <= 1.0, "unbalanced: {split:?}");
        // The same units in another order get the same shards.
        let mut reversed: Vec<(&str, f64)> = units.to_vec();
        reversed.reverse();
        let split_rev = assign(&reversed, 2);
        for (i, u) in units.iter().enumerate() {
            let j = reversed.iter().position(|r| r.0 == u.0).unwrap();
            assert_eq!(split[i], split_rev[j], "{} moved with the order", u.0);
        }
        // Over N shards for several N: each unit exactly once, no shard beyond N.
        for n in 1..=9 {
            let split = assign(&units, n);
            assert!(split.iter().all(|&s| s < n));
            let total: usize = (0..n)
                .map(|s| split.iter().filter(|&&k| k == s).count())
                .sum();
            assert_eq!(total, units.len());
        }
        // Equal estimates: ties by name, so a and b go to different shards, in name order.
        assert_eq!(assign(&[("b", 1.0), ("a", 1.0)], 2), vec![1, 0]);
    }

    /// Catches: an environment read wrongly (Slurm's id not offset by its minimum, the
    /// Kubernetes count not taken from --shard-count / GIBENCH_SHARD_COUNT).
    #[test]
    fn the_job_systems_environments_give_the_shard() {
        let s = resolve(
            None,
            None,
            &[
                ("SLURM_ARRAY_TASK_ID", "5"),
                ("SLURM_ARRAY_TASK_MIN", "4"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ],
        )
        .unwrap()
        .unwrap();
        assert_eq!((s.index, s.count), (1, 3));
        assert!(s.source.contains("SLURM_ARRAY_TASK_ID=5"), "{}", s.source);
        let s = resolve(
            None,
            None,
            &[("JOB_COMPLETION_INDEX", "2"), ("GIBENCH_SHARD_COUNT", "4")],
        )
        .unwrap()
        .unwrap();
        assert_eq!((s.index, s.count), (2, 4));
        let s = resolve(None, Some("3"), &[("JOB_COMPLETION_INDEX", "2")])
            .unwrap()
            .unwrap();
        assert_eq!((s.index, s.count), (2, 3));
        let s = resolve(
            None,
            None,
            &[
                ("BUILDKITE_PARALLEL_JOB", "0"),
                ("BUILDKITE_PARALLEL_JOB_COUNT", "2"),
            ],
        )
        .unwrap()
        .unwrap();
        assert_eq!((s.index, s.count), (0, 2));
        // The flag agreeing with the environment is fine; nothing at all is no shard.
        let s = resolve(
            Some("1/3"),
            None,
            &[
                ("SLURM_ARRAY_TASK_ID", "1"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ],
        )
        .unwrap()
        .unwrap();
        assert_eq!((s.index, s.count), (1, 3));
        assert_eq!(resolve(None, None, &[]).unwrap(), None);
    }

    /// Catches: bad shard input accepted, or refused without naming the option or variable
    /// and what was expected.
    #[test]
    fn bad_shards_are_refused_by_name() {
        for (shard, count, vars, names) in [
            (Some("3/3"), None, vec![], vec!["shard", "0/3 to 2/3"]),
            (Some("0/0"), None, vec![], vec!["shard", "at least 1"]),
            (Some("x"), None, vec![], vec!["shard", "I/N"]),
            (Some("1/x"), None, vec![], vec!["shard", "I/N"]),
            (
                None,
                None,
                vec![
                    ("SLURM_ARRAY_TASK_ID", "one"),
                    ("SLURM_ARRAY_TASK_COUNT", "3"),
                ],
                vec!["SLURM_ARRAY_TASK_ID", "whole number"],
            ),
            (
                None,
                None,
                vec![("SLURM_ARRAY_TASK_ID", "1")],
                vec!["SLURM_ARRAY_TASK_COUNT"],
            ),
            (
                None,
                None,
                vec![
                    ("SLURM_ARRAY_TASK_ID", "3"),
                    ("SLURM_ARRAY_TASK_COUNT", "3"),
                ],
                vec!["SLURM_ARRAY_TASK_ID", "0/3 to 2/3"],
            ),
            (
                Some("0/3"),
                None,
                vec![
                    ("SLURM_ARRAY_TASK_ID", "1"),
                    ("SLURM_ARRAY_TASK_COUNT", "3"),
                ],
                vec!["--shard 0/3", "SLURM_ARRAY_TASK_ID=1", "disagree"],
            ),
            (
                None,
                None,
                vec![("JOB_COMPLETION_INDEX", "1")],
                vec!["shard-count", "GIBENCH_SHARD_COUNT"],
            ),
            (
                Some("0/3"),
                Some("4"),
                vec![],
                vec!["shard-count", "disagrees"],
            ),
            (
                None,
                Some("4"),
                vec![],
                vec!["shard-count", "without a shard index"],
            ),
            (
                None,
                None,
                vec![
                    ("BUILDKITE_PARALLEL_JOB", "-1"),
                    ("BUILDKITE_PARALLEL_JOB_COUNT", "2"),
                ],
                vec!["BUILDKITE_PARALLEL_JOB", "whole number"],
            ),
        ] {
            let e = resolve(shard, count, &vars)
                .expect_err(&format!("{shard:?} {vars:?} accepted"))
                .to_string();
            for n in names {
                assert!(
                    e.contains(n),
                    "{shard:?} {vars:?}: '{e}' does not say '{n}'"
                );
            }
        }
    }
}
