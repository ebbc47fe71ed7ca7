//! `reproduce-all.json`, `.md` and `.html`: what the last `reproduce all` into a folder ran and
//! wrote, per target its command, work, estimate, time and files; read back for the next run's
//! estimate.

use std::path::{Path, PathBuf};

use gibench_harness::gpu::GpuContext;
use gibench_harness::{Error, Result};

use super::targets::TARGETS;

/// One target's entry in `reproduce-all.json`.
#[derive(serde::Serialize, serde::Deserialize, Clone)]
pub(super) struct Record {
    pub(super) name: String,
    pub(super) dir: String,
    pub(super) what: String,
    pub(super) command: String,
    pub(super) frames: u64,
    pub(super) units: u64,
    pub(super) estimate_s: Option<f64>,
    pub(super) seconds: Option<f64>,
    /// Relative to the results root.
    pub(super) files: Vec<String>,
    /// Not run this time: the entry (and its files) are from this earlier commit's run.
    pub(super) carried_from: Option<String>,
    /// The adapter the target ran on ("CPU only" for targets that need none).
    #[serde(default)]
    pub(super) adapter: String,
    /// Not run because of `--budget`: why (its estimate did not fit what was left, or it had
    /// none). Files listed are an earlier run's (`carried_from`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) left_out: Option<String>,
}

/// `reproduce-all.json`: what the last `reproduce all` into a folder ran and wrote.
#[derive(serde::Serialize, serde::Deserialize)]
pub(super) struct Manifest {
    pub(super) mode: String,
    pub(super) adapter: String,
    pub(super) driver: String,
    pub(super) git_commit: String,
    pub(super) cpu_threads: usize,
    pub(super) seconds: f64,
    pub(super) estimate_s: Option<f64>,
    pub(super) targets: Vec<Record>,
    /// `--budget`, in seconds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) budget_s: Option<f64>,
    /// The shard this run was ("1/3") and where that came from: its `targets` are that shard's
    /// part of `selected`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) shard: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) shard_source: Option<String>,
    /// Every target selected before sharding (what the shards' manifests must cover together).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub(super) selected: Vec<String>,
    /// `gibench merge`: the folders pooled into this one.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub(super) merged_from: Vec<String>,
    /// The file it was read from (empty for one made by this run).
    #[serde(skip)]
    pub(super) source: PathBuf,
}

/// The file stem of the manifest (`.json`, `.md`, `.html`).
pub(super) const MANIFEST: &str = "reproduce-all";

impl Manifest {
    /// Where an earlier manifest is looked for: `root`, then `results/`.
    pub(super) fn places(root: &Path) -> Vec<PathBuf> {
        let mut places = vec![root.join(format!("{MANIFEST}.json"))];
        let committed = Path::new("results").join(format!("{MANIFEST}.json"));
        if places[0] != committed {
            places.push(committed);
        }
        places
    }

    /// The manifest in `root`, else in `results/`.
    pub(super) fn previous(root: &Path) -> Option<Manifest> {
        Self::places(root).into_iter().find_map(|p| {
            let text = gibench_harness::error::read_bounded(&p, 16 << 20).ok()?;
            let mut m: Manifest = serde_json::from_slice(&text).ok()?;
            m.source = p;
            Some(m)
        })
    }

    /// Seconds for `target` doing `units` of work, from its recorded rate, and the adapter
    /// that rate was measured on.
    pub(super) fn estimate(&self, target: &str, units: u64) -> Option<(f64, String)> {
        let r = self.targets.iter().find(|r| r.name == target)?;
        let s = r.seconds?;
        let adapter = if r.adapter.is_empty() {
            self.adapter.clone()
        } else {
            r.adapter.clone()
        };
        (r.units > 0).then(|| (s * units as f64 / r.units as f64, adapter))
    }

    pub(super) fn new(
        mode: &str,
        adapter: &str,
        gpu: Option<&GpuContext>,
        seconds: f64,
        estimate_s: Option<f64>,
        mut targets: Vec<Record>,
        previous: Option<&Manifest>,
    ) -> Manifest {
        // Targets not run this time keep their earlier entry (their files are untouched).
        if let Some(prev) = previous.filter(|p| p.mode == mode) {
            // A target left out by the budget keeps the files (and date) of its earlier entry:
            // its folder was not touched.
            for t in targets.iter_mut().filter(|t| t.left_out.is_some()) {
                if let Some(r) = prev
                    .targets
                    .iter()
                    .find(|r| r.name == t.name && r.left_out.is_none())
                {
                    t.files = r.files.clone();
                    t.carried_from = Some(
                        r.carried_from
                            .clone()
                            .unwrap_or_else(|| prev.git_commit.clone()),
                    );
                }
            }
            for r in &prev.targets {
                if !targets.iter().any(|t| t.name == r.name) {
                    let mut r = r.clone();
                    r.carried_from
                        .get_or_insert_with(|| prev.git_commit.clone());
                    if r.adapter.is_empty() {
                        r.adapter = prev.adapter.clone();
                    }
                    targets.push(r);
                }
            }
            let order = |name: &str| TARGETS.iter().position(|t| t.name == name);
            targets.sort_by_key(|r| order(&r.name));
        }
        Manifest {
            mode: mode.to_string(),
            adapter: adapter.to_string(),
            driver: gpu.map(|g| g.info.driver.clone()).unwrap_or_default(),
            git_commit: gibench_harness::run::runner::git_commit(),
            cpu_threads: std::thread::available_parallelism()
                .map(|n| n.get())
                .unwrap_or(1),
            seconds,
            estimate_s,
            targets,
            budget_s: None,
            shard: None,
            shard_source: None,
            selected: Vec::new(),
            merged_from: Vec::new(),
            source: PathBuf::new(),
        }
    }

    /// The manifest of `dir` (`gibench merge`'s input), or an error naming the file.
    pub(super) fn read(dir: &Path) -> Result<Manifest> {
        let p = dir.join(format!("{MANIFEST}.json"));
        let text = gibench_harness::error::read_bounded(&p, 16 << 20)?;
        let mut m: Manifest = serde_json::from_slice(&text).map_err(|e| Error::BadFile {
            path: p.clone(),
            message: format!("not a reproduce-all manifest: {e}"),
        })?;
        m.source = p;
        Ok(m)
    }

    /// The committed manifest (`results/reproduce-all.json` under the working directory): the
    /// one estimate source every machine of a fleet has alike (a checkout of the same commit).
    pub(super) fn committed() -> Option<Manifest> {
        let p = Path::new("results").join(format!("{MANIFEST}.json"));
        let text = gibench_harness::error::read_bounded(&p, 16 << 20).ok()?;
        let mut m: Manifest = serde_json::from_slice(&text).ok()?;
        m.source = p;
        Some(m)
    }

    /// The entries carried from an earlier run dated by the commit their files record, where
    /// they record one: a target regenerated on its own since that run was made by another
    /// commit than the one the earlier manifest names.
    pub(super) fn dated_by_their_files(mut self, root: &Path) -> Manifest {
        for r in &mut self.targets {
            if r.carried_from.is_some() {
                if let Some(commit) = recorded_commit(root, &r.files) {
                    r.carried_from = Some(commit);
                }
            }
        }
        self
    }

    /// Tables (`.md`, with `.csv` and `.tex` beside) and figures (`.svg`, `--html`'s pages, the
    /// reference's `.png` images) of a record.
    fn outputs(r: &Record) -> (Vec<&str>, Vec<&str>, usize) {
        let figure = |f: &str| {
            f.ends_with(".svg")
                || f.ends_with(".html")
                || (r.name == "reference" && f.ends_with(".png"))
        };
        let tables: Vec<&str> = r
            .files
            .iter()
            .filter(|f| f.ends_with(".md"))
            .map(String::as_str)
            .collect();
        let figures: Vec<&str> = r
            .files
            .iter()
            .filter(|f| figure(f))
            .map(String::as_str)
            .collect();
        (tables, figures, r.files.len())
    }

    pub(super) fn write(&self, root: &Path) -> Result<()> {
        let json = serde_json::to_vec_pretty(self).map_err(|e| Error::Invalid(e.to_string()))?;
        gibench_harness::output::write_atomic(&root.join(format!("{MANIFEST}.json")), &json)?;
        let mut md = format!(
            "# gibench reproduce all ({} sizes)\n\nLast run: on {}{}, git {}, {} CPU threads: {} ({}). \
             Targets it did not run keep the entry of the run that made their files (\"from git …\").\n\n\
             | target | what | command | ran on | time (estimate) | tables | figures | files |\n|---|---|---|---|---|---|---|---|\n",
            self.mode,
            self.adapter,
            if self.driver.is_empty() {
                String::new()
            } else {
                format!(" (driver {})", self.driver)
            },
            self.git_commit,
            self.cpu_threads,
            duration(self.seconds),
            self.estimate_s
                .map(|e| format!("estimated {}", duration(e)))
                .unwrap_or_else(|| "no estimate".into()),
        );
        if self.mode.ends_with("-tiny") {
            md.insert_str(0, "**TEST SIZE tiny** (`--test-size` / `GIBENCH_TEST_SIZE`): every target cut to a few frames at tiny sizes; not benchmark results.\n\n");
        }
        let mut notes = String::new();
        if let Some(b) = self.budget_s {
            notes.push_str(&format!(
                "Budget: {} (targets in priority order; a target left out says why).\n",
                duration(b)
            ));
        }
        if let Some(s) = &self.shard {
            notes.push_str(&format!(
                "Shard {s} of the selection {} ({}).\n",
                self.selected.join(", "),
                self.shard_source.as_deref().unwrap_or_default()
            ));
        }
        if !self.merged_from.is_empty() {
            notes.push_str(&format!(
                "Merged by `gibench merge` from: {} (\"ran on\" names each target's device).\n",
                self.merged_from.join(", ")
            ));
        }
        if !notes.is_empty() {
            let at = md.find("| target |").unwrap_or(md.len());
            md.insert_str(at, &format!("{notes}\n"));
        }
        for r in &self.targets {
            let (tables, figures, files) = Self::outputs(r);
            let time = match (r.seconds, &r.carried_from) {
                _ if r.left_out.is_some() => format!(
                    "**left out**: {}{}",
                    r.left_out.as_deref().unwrap_or_default(),
                    r.carried_from
                        .as_ref()
                        .map(|c| format!(" (files from git {c})"))
                        .unwrap_or_default()
                ),
                (_, Some(c)) => format!("from git {c}"),
                (Some(s), None) => format!(
                    "{} ({})",
                    duration(s),
                    r.estimate_s.map(duration).unwrap_or_else(|| "?".into())
                ),
                (None, None) => "?".into(),
            };
            md.push_str(&format!(
                "| {} | {} | `{}` | {} | {time} | {} | {} | {files} |\n",
                r.name,
                r.what,
                r.command,
                r.adapter,
                tables.join("<br>"),
                figures.join("<br>"),
            ));
        }
        gibench_harness::output::write_atomic(&root.join(format!("{MANIFEST}.md")), md.as_bytes())
    }

    /// `reproduce-all.html`: every target with its pages, tables and figures.
    pub(super) fn write_index(&self, root: &Path) -> Result<()> {
        let entries: Vec<gibench_harness::report::html::IndexEntry> = self
            .targets
            .iter()
            .map(|r| gibench_harness::report::html::IndexEntry {
                name: r.name.clone(),
                what: r.what.clone(),
                time: match (r.seconds, &r.carried_from) {
                    _ if r.left_out.is_some() => {
                        format!("left out: {}", r.left_out.as_deref().unwrap_or_default())
                    }
                    (_, Some(c)) => format!("from the run of git {c}"),
                    (Some(s), None) => duration(s),
                    (None, None) => "?".into(),
                },
                files: r.files.clone(),
            })
            .collect();
        gibench_harness::report::html::write_index(
            &root.join(format!("{MANIFEST}.html")),
            &format!(
                "gibench reproduce all ({} sizes) on {}",
                self.mode, self.adapter
            ),
            &crate::page::command_line(),
            &entries,
        )
    }

    /// Every table and figure, per target, for the terminal.
    pub(super) fn listing(&self, root: &Path) -> String {
        let mut out = format!(
            "gibench reproduce all ({} sizes) took {} ({}); wrote into {}:",
            self.mode,
            duration(self.seconds),
            self.estimate_s
                .map(|e| format!("estimated {}", duration(e)))
                .unwrap_or_else(|| "no estimate".into()),
            root.display()
        );
        for r in self
            .targets
            .iter()
            .filter(|r| r.carried_from.is_none() && r.left_out.is_none())
        {
            let (tables, figures, files) = Self::outputs(r);
            out.push_str(&format!("\n  {} ({files} files)", r.name));
            for t in tables {
                out.push_str(&format!("\n    table  {t} (.csv, .tex beside)"));
            }
            for f in figures {
                let kind = if f.ends_with(".html") {
                    "page  "
                } else {
                    "figure"
                };
                out.push_str(&format!("\n    {kind} {f}"));
            }
        }
        for r in self.targets.iter().filter(|r| r.left_out.is_some()) {
            out.push_str(&format!(
                "\n  left out: {} ({})",
                r.name,
                r.left_out.as_deref().unwrap_or_default()
            ));
        }
        out.push_str(&format!(
            "\n  and {MANIFEST}.json / {MANIFEST}.md: every target's command, time and files"
        ));
        out.push_str(&format!(
            "\n  and {MANIFEST}.html: every target's pages, tables and figures on one page"
        ));
        out
    }
}

/// The `git_commit` the first of `files` (relative to `root`) that is a JSON object naming one
/// records: the commit that made a target's files.
fn recorded_commit(root: &Path, files: &[String]) -> Option<String> {
    files.iter().filter(|f| f.ends_with(".json")).find_map(|f| {
        let bytes = gibench_harness::error::read_bounded(&root.join(f), 64 << 20).ok()?;
        let v: serde_json::Value = serde_json::from_slice(&bytes).ok()?;
        let commit = v.get("git_commit")?.as_str()?;
        (!commit.is_empty()).then(|| commit.to_string())
    })
}

/// "12m03s" (one word, for scripts reading `--list`).
pub(super) fn duration(seconds: f64) -> String {
    let s = seconds.round() as u64;
    if s >= 60 {
        format!("{}m{:02}s", s / 60, s % 60)
    } else {
        format!("{seconds:.1}s")
    }
}
