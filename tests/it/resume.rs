//! Preemption: `reproduce all` killed (SIGKILL) or stopped politely (SIGTERM) and started again
//! on the same `--out` goes on from the targets it completed, redoes none of them, and publishes
//! the folder an uninterrupted run publishes (timings aside). Tiny test size (docs/fleet.md).

use std::collections::BTreeSet;
use std::io::Read;
use std::path::Path;
use std::process::Child;
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crate::fleet::{assert_same_tables, manifest, start};

/// Six cheap targets on the Cornell box (CPU-only, command and paper targets).
const ONLY: &str =
    "reference,keller-lag,clamp-cornell-laine,laine-management,laine-quality,ism-pull-push-spot";

/// The targets `reproduce-all.partial.json` in `out` lists as complete (none without one).
fn complete(out: &Path) -> BTreeSet<String> {
    let Ok(bytes) = std::fs::read(out.join("reproduce-all.partial.json")) else {
        return BTreeSet::new();
    };
    let Ok(v) = serde_json::from_slice::<serde_json::Value>(&bytes) else {
        return BTreeSet::new(); // being replaced: read again
    };
    v["done"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["record"]["name"].as_str().unwrap().to_string())
        .collect()
}

/// Waits until `out` records more than `n` complete targets; panics if `child` ends first.
fn wait_beyond(child: &mut Child, out: &Path, n: usize) {
    let began = Instant::now();
    while complete(out).len() <= n {
        if let Some(status) = child.try_wait().unwrap() {
            panic!("the run ended ({status}) before it completed a target more than {n}");
        }
        assert!(
            began.elapsed() < Duration::from_secs(600),
            "no progress in 10 minutes"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// A run whose standard error is read as it is written.
struct Running {
    child: Child,
    err: Arc<Mutex<String>>,
    reader: JoinHandle<()>,
}

impl Running {
    fn new(mut child: Child) -> Self {
        let mut pipe = child.stderr.take().unwrap();
        let err = Arc::new(Mutex::new(String::new()));
        let sink = Arc::clone(&err);
        let reader = std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            while let Ok(n @ 1..) = pipe.read(&mut buf) {
                sink.lock()
                    .unwrap()
                    .push_str(&String::from_utf8_lossy(&buf[..n]));
            }
        });
        Self { child, err, reader }
    }

    /// Waits until the run has printed `text`; panics if it ends first.
    fn wait_for(&mut self, text: &str) {
        let began = Instant::now();
        while !self.err.lock().unwrap().contains(text) {
            if let Some(status) = self.child.try_wait().unwrap() {
                panic!("the run ended ({status}) before it printed {text:?}");
            }
            assert!(
                began.elapsed() < Duration::from_secs(600),
                "no {text:?} in 10 minutes"
            );
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    /// Ends the run with `signal` (9 or 15) and returns its standard error and its status.
    fn stop(mut self, signal: i32) -> (String, std::process::ExitStatus) {
        let pid = self.child.id().to_string();
        let ok = std::process::Command::new("kill")
            .args([format!("-{signal}"), pid])
            .status()
            .unwrap()
            .success();
        assert!(ok, "kill -{signal} failed");
        let status = self.child.wait().unwrap();
        self.reader.join().unwrap();
        let err = self.err.lock().unwrap().clone();
        (err, status)
    }
}

/// The targets a run's standard error says it ran to the end.
fn ran(stderr: &str) -> BTreeSet<String> {
    stderr
        .lines()
        .filter_map(|l| l.split_once(" done in ").map(|(t, _)| t.to_string()))
        .filter(|t| ONLY.split(',').any(|o| o == t))
        .collect()
}

/// Catches: a resume that runs completed targets again (counted from each run's own report
/// against what the folder recorded before it started), one that drops or mixes a completed
/// target's files (the final tables differ from the uninterrupted run's), a target half-done
/// when killed taken over as complete (its files differ or are missing), a SIGTERM that does
/// not stop (the run ends successfully), exits with another status, or keeps nothing, a
/// record made by another build taken over (the tampered key below), and files of a killed
/// target left behind (the folders' listings differ).
#[test]
fn killed_and_stopped_runs_resume_to_the_uninterrupted_tables() {
    let tmp = tempfile::tempdir().unwrap();
    let (single, out) = (tmp.path().join("single"), tmp.path().join("resumed"));
    let one = start(ONLY, &single, &[]);
    let o = one.wait_with_output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let mut reports = Vec::new();
    // SIGKILL once a target is complete, SIGKILL while starting (once the completed targets
    // are taken over: a slow machine may take seconds to get there), SIGKILL just after the
    // next target completes, then SIGTERM likewise.
    for (signal, after) in [(9, Some(0)), (9, None), (9, Some(1)), (15, Some(2))] {
        let before = complete(&out);
        let mut run = Running::new(start(ONLY, &out, &[]));
        match after {
            Some(n) => wait_beyond(&mut run.child, &out, n.max(before.len())),
            None => run.wait_for("complete there are kept"),
        }
        let (err, status) = run.stop(signal);
        assert!(
            !status.success(),
            "the run ended before it was stopped:\n{err}"
        );
        if signal == 15 {
            assert_eq!(status.code(), Some(75), "SIGTERM's status:\n{err}");
            assert!(err.contains("stopped by SIGTERM"), "{err}");
            let partial: serde_json::Value = serde_json::from_slice(
                &std::fs::read(out.join("reproduce-all.partial.json")).unwrap(),
            )
            .unwrap();
            assert!(partial["stopped"].as_str().unwrap().contains("SIGTERM"));
            assert!(!partial["missing"].as_array().unwrap().is_empty());
        }
        reports.push((before, err));
    }
    // A record made by another build is not taken over: its target runs again.
    let path = out.join("reproduce-all.partial.json");
    let mut partial: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    let tampered = partial["done"][0]["record"]["name"]
        .as_str()
        .unwrap()
        .to_string();
    partial["done"][0]["key"] = "another build".into();
    std::fs::write(&path, serde_json::to_vec(&partial).unwrap()).unwrap();
    let before = complete(&out);
    let last = start(ONLY, &out, &[]).wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&last.stderr).into_owned();
    assert!(last.status.success(), "the last resume failed:\n{err}");
    assert!(
        err.contains(&format!(
            "{tampered} of the interrupted run is run again: made by another build"
        )),
        "{err}"
    );
    assert!(
        ran(&err).contains(&tampered),
        "{tampered} was not run again:\n{err}"
    );
    let mut others = before.clone();
    others.remove(&tampered);
    reports.push((others, err));
    for (i, (before, err)) in reports.iter().enumerate() {
        let again: Vec<String> = ran(err).intersection(before).cloned().collect();
        assert!(
            again.is_empty(),
            "run {i} redid completed targets {again:?}:\n{err}"
        );
        if !before.is_empty() {
            assert!(
                err.contains(&format!(
                    "{} target(s) complete there are kept",
                    before.len()
                )),
                "run {i} does not say it resumed {before:?}:\n{err}"
            );
        }
    }
    assert!(
        reports[0].0.is_empty() && reports[1].0.len() == 1 && reports[3].0.len() >= 2,
        "the kills did not land where planned: {:?}",
        reports.iter().map(|r| &r.0).collect::<Vec<_>>()
    );
    assert!(!out.join("reproduce-all.partial.json").exists());
    assert!(!out.join(".gibench-staging").exists());
    assert_eq!(manifest(&out)["targets"].as_array().unwrap().len(), 6);
    assert_same_tables(&single, &out);
    assert_eq!(
        every_file(&single),
        every_file(&out),
        "the folders' files differ"
    );
}

/// Every file under `dir`, relative, sorted (hidden ones too).
fn every_file(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            if e.file_type().unwrap().is_dir() {
                todo.push(e.path());
            } else {
                let rel = e.path().strip_prefix(dir).unwrap().to_path_buf();
                out.push(rel.to_string_lossy().into_owned());
            }
        }
    }
    out.sort();
    out
}
