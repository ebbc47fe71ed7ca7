//! **Resume**: `reproduce all` killed (SIGKILL, a lost machine) or stopped (SIGTERM, SIGINT)
//! and started again on the same `--out` continues from the targets it completed.
//!
//! Every completed target stays staged in the output set (nothing is published before the
//! end, so the folder never mixes two runs), and after each one [`PARTIAL`] in `--out` records
//! what is complete — each target's manifest entry and the key of what made it: the build (its
//! commit and a hash of the binary), the mode, the adapter and the target's command — and what
//! is missing. A polite stop also records what stopped it and where.
//!
//! The next `reproduce all` on that folder takes over the staged files of every target whose
//! key is the same (counted and named on standard error; the run redoes none of them), runs
//! again any whose key differs (saying why) and removes the rest of what was staged. The
//! published folder is then the one an uninterrupted run writes, timings aside; [`PARTIAL`] is
//! removed once it is published.

use std::collections::hash_map::DefaultHasher;
use std::hash::Hasher;
use std::io::Read;
use std::path::{Path, PathBuf};

use gibench_harness::output::write_atomic_direct;
use gibench_harness::Result;

use super::manifest::Record;
use super::planned::Planned;

/// The record of an unfinished `reproduce all`, in its `--out`.
pub(super) const PARTIAL: &str = "reproduce-all.partial.json";

/// [`PARTIAL`]'s content.
#[derive(serde::Serialize, serde::Deserialize)]
struct Partial {
    /// Why it stopped (a signal, and where), when it stopped politely; absent after a kill.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    stopped: Option<String>,
    /// The command to run again to resume.
    resume_with: String,
    done: Vec<Done>,
    /// The targets not complete.
    missing: Vec<String>,
}

/// A completed target: its key and its manifest entry.
#[derive(serde::Serialize, serde::Deserialize)]
struct Done {
    key: String,
    record: Record,
}

/// What a run records of its progress, and what it took over from an earlier one.
pub(super) struct Checkpoint {
    root: PathBuf,
    command: String,
    /// Per planned target: its key.
    keys: Vec<String>,
    names: Vec<String>,
}

/// The binary's identity: its commit and a hash of its contents (a dirty tree's commit does not
/// say which build made a file).
fn build() -> String {
    let commit = gibench_harness::run::runner::git_commit();
    let hash = std::env::current_exe()
        .and_then(std::fs::File::open)
        .and_then(|mut f| {
            let mut h = DefaultHasher::new();
            let mut buf = vec![0u8; 1 << 20];
            loop {
                let n = f.read(&mut buf)?;
                if n == 0 {
                    return Ok(h.finish());
                }
                h.write(&buf[..n]);
            }
        });
    match hash {
        Ok(h) => format!("{commit}, binary {h:016x}"),
        // Unknown contents: a key no later run matches, so nothing is taken over.
        Err(e) => format!(
            "{commit}, binary unreadable ({e}, pid {})",
            std::process::id()
        ),
    }
}

impl Checkpoint {
    pub(super) fn new(
        root: &Path,
        planned: &[Planned],
        mode: &str,
        adapter: &str,
        shard: Option<String>,
        command: String,
    ) -> Checkpoint {
        let build = build();
        let shard = shard.map(|s| format!(", shard {s}")).unwrap_or_default();
        Checkpoint {
            root: root.to_path_buf(),
            command,
            keys: planned
                .iter()
                .map(|p| {
                    let on = if p.needs_gpu() { adapter } else { "CPU only" };
                    format!("{build}; {mode} sizes on {on}{shard}; {}", p.command)
                })
                .collect(),
            names: planned.iter().map(|p| p.target.name.to_string()).collect(),
        }
    }

    /// Which of `present` (the files an earlier run staged in the folder) to take over, and
    /// the entries of the targets they belong to (per planned target): those [`PARTIAL`] lists
    /// as complete with this run's key and all their files present. Says on standard error
    /// what it takes over and what it runs again.
    pub(super) fn take_over(&self, present: &[PathBuf]) -> (Vec<PathBuf>, Vec<Option<Record>>) {
        let mut resumed: Vec<Option<Record>> = self.names.iter().map(|_| None).collect();
        let mut keep = Vec::new();
        let path = self.root.join(PARTIAL);
        let partial = gibench_harness::error::read_bounded(&path, 64 << 20).and_then(|b| {
            serde_json::from_slice::<Partial>(&b)
                .map_err(|e| gibench_harness::Error::bad_file(&path, e.to_string()))
        });
        let partial = match partial {
            Ok(p) => p,
            Err(e) => {
                if path.exists() {
                    eprintln!("gibench reproduce all: not resuming, every target runs again: {e}");
                }
                return (keep, resumed);
            }
        };
        for d in &partial.done {
            let Some(i) = self.names.iter().position(|n| *n == d.record.name) else {
                continue;
            };
            let files: Vec<PathBuf> = d.record.files.iter().map(PathBuf::from).collect();
            let why = if d.key != self.keys[i] {
                Some(format!("made by {}, not {}", d.key, self.keys[i]))
            } else {
                files
                    .iter()
                    .find(|f| !present.contains(f))
                    .map(|f| format!("its staged file {} is gone", f.display()))
            };
            match why {
                Some(why) => eprintln!(
                    "gibench reproduce all: {} of the interrupted run is run again: {why}",
                    d.record.name
                ),
                None => {
                    keep.extend(files);
                    resumed[i] = Some(d.record.clone());
                }
            }
        }
        let n = resumed.iter().flatten().count();
        if n > 0 || partial.stopped.is_some() {
            eprintln!(
                "gibench reproduce all: resuming the run interrupted in {}{}: {n} target(s) \
                 complete there are kept, not run again: {}",
                self.root.display(),
                partial
                    .stopped
                    .map(|s| format!(" ({s})"))
                    .unwrap_or_default(),
                resumed
                    .iter()
                    .flatten()
                    .map(|r| r.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
        (keep, resumed)
    }

    /// Writes [`PARTIAL`]: the targets complete in `records`, the others missing, and what
    /// stopped the run (if it stopped politely).
    pub(super) fn save(&self, records: &[Option<Record>], stopped: Option<&str>) -> Result<()> {
        let partial = Partial {
            stopped: stopped.map(str::to_string),
            resume_with: self.command.clone(),
            done: (records.iter().zip(&self.keys))
                .filter_map(|(r, k)| {
                    r.as_ref().filter(|r| r.left_out.is_none()).map(|r| Done {
                        key: k.clone(),
                        record: r.clone(),
                    })
                })
                .collect(),
            missing: self.missing(records),
        };
        let json = serde_json::to_vec_pretty(&partial)
            .map_err(|e| gibench_harness::Error::Invalid(format!("{PARTIAL}: {e}")))?;
        write_atomic_direct(&self.root.join(PARTIAL), &json)
    }

    /// Removes [`PARTIAL`] (the run was published).
    pub(super) fn finish(&self) {
        let _ = std::fs::remove_file(self.root.join(PARTIAL));
    }

    /// The targets [`Checkpoint::save`] would list as missing.
    pub(super) fn missing(&self, records: &[Option<Record>]) -> Vec<String> {
        (records.iter().zip(&self.names))
            .filter(|(r, _)| r.as_ref().is_none_or(|r| r.left_out.is_some()))
            .map(|(_, n)| n.clone())
            .collect()
    }
}
