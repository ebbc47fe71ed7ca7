//! A lost GPU device (a driver reset, a GPU timeout) mid-run, on every portable backend
//! present: the device is destroyed on purpose (`GIBENCH_TEST_LOSE_DEVICE=TECHNIQUE:FRAME`).
//! The command fails with an error naming the technique, the frame and the stage, writes the
//! runs (or a sweep's points) completed before it and lists the one that did not complete;
//! `reproduce all` keeps its completed targets for a resume. No panic, no hang.

use std::path::Path;
use std::process::Output;
use std::time::{Duration, Instant};

use crate::support;

/// Runs gibench with the device lost before `lose`, waiting at most two minutes (a hang fails).
fn lost_run(lose: &str, args: &[&str], out: &Path) -> Output {
    let mut c = support::GIBENCH.command();
    c.env("GIBENCH_TEST_LOSE_DEVICE", lose)
        .env("GIBENCH_TEST_SIZE", "tiny")
        .args(args)
        .arg("--out")
        .arg(out)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped());
    let mut child = c.spawn().unwrap();
    let began = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if began.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("gibench {args:?} hung after losing the device");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    child.wait_with_output().unwrap()
}

/// Catches: a lost device that panics, hangs, or reports a bare driver error (no technique,
/// frame or stage); a run that loses the techniques completed before it (nothing written) or
/// writes the lost one's half-made results; a summary that does not list the runs left out;
/// success reported after a loss.
#[test]
fn a_lost_device_names_where_and_keeps_the_completed_runs() {
    let backends = gibench_test_support::gpu::backends_for("device_loss");
    // Lost in the stage-timing pass (each stage waited for) and in the frame-timing pass
    // (frames in flight, found at a timestamp readback).
    for (backend, lose) in backends
        .iter()
        .flat_map(|b| [(*b, "keller-full:4"), (*b, "keller-full:4:2")])
    {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("run");
        let o = lost_run(
            lose,
            &[
                "run",
                "--technique",
                "direct,keller-full,laine",
                "--frames",
                "3",
                "--resolution",
                "64x48",
                "--backend",
                backend,
            ],
            &out,
        );
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{backend} {lose}:\n{err}");
        assert!(!err.contains("panicked"), "{backend} {lose}:\n{err}");
        assert!(
            err.contains("error: the GPU device was lost")
                && err.contains("at keller-full's frame 4, stage '"),
            "{backend} {lose}: the error does not say where:\n{err}"
        );
        assert!(
            out.join("cornell-direct.json").is_file(),
            "{backend}: direct's run is gone"
        );
        assert!(!out.join("cornell-keller-full.json").exists());
        assert!(!out.join("cornell-laine.json").exists());
        let skipped = std::fs::read_to_string(out.join("cornell-skipped.json")).unwrap();
        assert!(skipped.contains("keller-full") && skipped.contains("not completed"));
        assert!(skipped.contains("laine") && skipped.contains("not run"));
        let summary = std::fs::read_to_string(out.join("cornell-summary.md")).unwrap();
        assert!(summary.contains("keller-full") && summary.contains("device was lost"));
    }
}

/// Catches: a sweep that loses its completed points with the device (nothing written), or
/// writes the lost point's, or reports success.
#[test]
fn a_sweep_keeps_the_points_before_a_lost_device() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("sweep");
    let o = lost_run(
        "keller-full:4:2",
        &[
            "sweep",
            "--technique",
            "keller-full",
            "--sweep",
            "vpls=16,32,64",
            "--timing",
            "stages",
            "--frames",
            "3",
            "--resolution",
            "64x48",
        ],
        &out,
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("at keller-full's frame 4, stage '"), "{err}");
    assert!(err.contains("not completed: vpls=32,64"), "{err}");
    assert!(
        out.join("cornell-keller-full-vpls-16.json").is_file(),
        "{err}"
    );
    assert!(!out.join("cornell-keller-full-vpls-32.json").exists());
    let table = std::fs::read_to_string(out.join("cornell-keller-full-sweep-vpls.md")).unwrap();
    assert!(table.contains("16") && !table.contains("| 64 "), "{table}");
}

/// Catches: `reproduce all` that drops its completed targets on a lost device (the rerun
/// would run them again) or publishes a half set; and a rerun that does not resume.
#[test]
fn reproduce_all_keeps_its_completed_targets_when_the_device_is_lost() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("all");
    let args = [
        "reproduce",
        "all",
        "--quick",
        "--quiet",
        "--only",
        "reference,laine-quality,ism-pull-push-spot",
    ];
    let o = lost_run("ism:2", &args, &out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("the GPU device was lost") && err.contains("at ism's frame 2"),
        "{err}"
    );
    let partial = std::fs::read_to_string(out.join("reproduce-all.partial.json")).unwrap();
    assert!(partial.contains("device was lost"), "{partial}");
    assert!(
        !out.join("reproduce-all.json").exists(),
        "a half set was published"
    );
    let again = lost_run("none:0", &args, &out);
    let err = String::from_utf8_lossy(&again.stderr);
    assert!(again.status.success(), "{err}");
    assert!(err.contains("2 target(s) complete there are kept"), "{err}");
}
