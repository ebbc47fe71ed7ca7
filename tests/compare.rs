//! `gibench compare`.
//!
//! Its verdicts are tested on synthetic results files, exactly: three repeats of a committed
//! baseline run with known stage times for BASE, SAME (within a few percent) and SLOW (one stage
//! 1.5× slower). A real comparison end to end checks only what does not depend on the machine's
//! load: that it runs, has a row for every stage, carries the test hook's warning, and refuses
//! too few repeats — whether a shared machine's noise shows as a verdict is a benchmark's
//! question, not a test's.
//!
//! Hostile results files are named: a side holding a results file that cannot be read (an
//! impossible calibration, a negative time, an unknown stage kind, truncated, a newer schema)
//! says which, and fails when that file's run is in no other file of the side.

mod support;

use std::path::{Path, PathBuf};

use serde_json::Value;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The committed baseline's `direct` run, as JSON.
fn baseline_direct() -> Value {
    let p = root().join("results/baseline/r1/cornell-direct.json");
    serde_json::from_slice(&std::fs::read(p).unwrap()).unwrap()
}

/// Writes `dir/r{i}/cornell-direct.json` for each factor set: the baseline run with every
/// statistic of stage S multiplied by `factor(S)` and the calibration set to `calibration`.
fn synthetic(dir: &Path, repeats: &[f64], factor: impl Fn(&str) -> f64, calibration: Value) {
    for (i, n) in repeats.iter().enumerate() {
        let mut v = baseline_direct();
        for s in v["stages"].as_array_mut().unwrap() {
            let f = n * factor(s["name"].as_str().unwrap());
            for clock in ["gpu_ms", "wall_ms"] {
                if let Some(o) = s[clock].as_object_mut() {
                    for (k, x) in o.iter_mut() {
                        if k != "count" {
                            *x = serde_json::json!(x.as_f64().unwrap() * f);
                        }
                    }
                }
            }
        }
        v["calibration_ms"] = calibration.clone();
        v["timestamp"] = serde_json::json!(i);
        let d = dir.join(format!("r{i}"));
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(
            d.join("cornell-direct.json"),
            serde_json::to_vec_pretty(&v).unwrap(),
        )
        .unwrap();
    }
}

/// `gibench compare BASE CURRENT`: success, the rows' (stage, verdict) pairs, stderr.
fn compare(dir: &Path, base: &str, current: &str) -> (bool, Vec<(String, String)>, String) {
    let out = dir.join(format!("cmp-{base}-{current}"));
    let o = support::gibench()
        .arg("compare")
        .arg(dir.join(base))
        .arg(dir.join(current))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
    let json: Value = std::fs::read(out.join("compare.json"))
        .ok()
        .and_then(|b| serde_json::from_slice(&b).ok())
        .unwrap_or(Value::Null);
    let verdicts = json
        .as_array()
        .into_iter()
        .flatten()
        .map(|r| {
            (
                r["stage"].as_str().unwrap().to_string(),
                r["verdict"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    (o.status.success(), verdicts, stderr)
}

const STAGES: [&str; 4] = ["gbuffer", "direct-shadow-map", "direct-light", "compose"];

#[test]
fn verdicts_on_synthetic_results_are_exact() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let cal = serde_json::json!(10.0);
    synthetic(&dir.join("base"), &[1.0, 1.03, 0.98], |_| 1.0, cal.clone());
    synthetic(&dir.join("same"), &[1.01, 0.99, 1.02], |_| 1.0, cal.clone());
    let slow = |s: &str| if s == "compose" { 1.5 } else { 1.0 };
    synthetic(&dir.join("slow"), &[1.0, 1.02, 0.99], slow, cal.clone());
    // The same times in a session whose machine was twice as slow, and whose calibration
    // says so.
    synthetic(
        &dir.join("busy"),
        &[2.0, 2.04, 1.98],
        |_| 1.0,
        serde_json::json!(20.0),
    );
    let (ok, same, stderr) = compare(dir, "base", "same");
    assert!(ok, "{stderr}");
    assert_eq!(same.len(), STAGES.len(), "{same:?}");
    assert!(same.iter().all(|(_, v)| v == "unchanged"), "{same:?}");
    let (ok, slow, stderr) = compare(dir, "base", "slow");
    assert!(ok, "{stderr}");
    for (stage, verdict) in &slow {
        let want = if stage == "compose" {
            "slower"
        } else {
            "unchanged"
        };
        assert_eq!(verdict, want, "{stage}: {slow:?}");
    }
    let (ok, back, _) = compare(dir, "slow", "base");
    assert!(ok);
    assert!(
        back.contains(&("compose".into(), "faster".into())),
        "{back:?}"
    );
    let (ok, busy, stderr) = compare(dir, "base", "busy");
    assert!(ok, "{stderr}");
    assert!(busy.iter().all(|(_, v)| v == "unchanged"), "{busy:?}");
}

/// A hostile edit of a results file: its name, the edit, what the error must say.
type Edit = (&'static str, fn(&mut Value), &'static str);

/// Results files that cannot be read are named; a side that would lose its run fails.
#[test]
fn unreadable_results_are_named_and_a_lost_run_fails() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let cal = serde_json::json!(10.0);
    synthetic(&dir.join("base"), &[1.0, 1.03, 0.98], |_| 1.0, cal.clone());
    let edits: [Edit; 7] = [
        (
            "no-calibration",
            |v| v["calibration_ms"] = 0.0.into(),
            "calibration_ms is 0",
        ),
        (
            "negative-calibration",
            |v| v["calibration_ms"] = (-5.0).into(),
            "calibration_ms is -5",
        ),
        (
            "tiny-calibration",
            |v| v["calibration_ms"] = 1e-300.into(),
            "calibration_ms is 1e-300",
        ),
        (
            "negative-median",
            |v| v["stages"][1]["wall_ms"]["median"] = (-1.0).into(),
            "median is -1",
        ),
        (
            "unknown-kind",
            |v| v["stages"][0]["kind"] = "quantum".into(),
            "quantum",
        ),
        (
            "newer-schema",
            |v| v["schema_version"] = 999.into(),
            "schema version 999",
        ),
        (
            "negative-rmse",
            |v| {
                v["quality"] = serde_json::json!({"reference": "r", "frames": [],
                "rmse": {"count": 1, "mean": -1.0, "median": -1.0, "p5": -1.0, "p95": -1.0, "min": -1.0, "max": -1.0},
                "rel_mse": {"count": 0, "mean": null, "median": null, "p5": null, "p95": null, "min": null, "max": null},
                "mae": {"count": 0, "mean": null, "median": null, "p5": null, "p95": null, "min": null, "max": null},
                "flip_mean": {"count": 0, "mean": null, "median": null, "p5": null, "p95": null, "min": null, "max": null}});
            },
            "errors are not negative",
        ),
    ];
    for (name, edit, why) in edits {
        let side = dir.join(name);
        synthetic(&side, &[1.005, 1.01, 0.99], |_| 1.0, cal.clone());
        let f = side.join("r1/cornell-direct.json");
        let mut v: Value = serde_json::from_slice(&std::fs::read(&f).unwrap()).unwrap();
        edit(&mut v);
        std::fs::write(&f, serde_json::to_vec_pretty(&v).unwrap()).unwrap();
        // The run is still in r0 and r2: named, and then too few repeats.
        let (ok, _, stderr) = compare(dir, "base", name);
        assert!(!ok, "{name}");
        assert!(
            stderr.contains("skipped") && stderr.contains("r1/cornell-direct.json"),
            "{name}: {stderr}"
        );
        assert!(stderr.contains(why), "{name}: {stderr}");
        assert!(
            stderr.contains("CURRENT has 2 repeat(s)"),
            "{name}: {stderr}"
        );
    }
    // Truncated, beside a run of another technique: named, and the side lost `direct`.
    let side = dir.join("truncated");
    synthetic(&side, &[1.0, 1.01, 0.99], |_| 1.0, cal.clone());
    for i in 0..3 {
        let f = side.join(format!("r{i}/cornell-direct.json"));
        let bytes = std::fs::read(&f).unwrap();
        std::fs::write(&f, &bytes[..bytes.len() / 2]).unwrap();
        std::fs::copy(
            root().join(format!("results/baseline/r{}/cornell-laine.json", i + 1)),
            side.join(format!("r{i}/cornell-laine.json")),
        )
        .unwrap();
    }
    let (ok, _, stderr) = compare(dir, "base", "truncated");
    assert!(!ok);
    // (These files' keys are written sorted, so `technique` lies past the cut and the run is
    // unknown: the side fails all the same, naming each file.)
    assert!(
        stderr.contains("parameter 'current'")
            && stderr.contains("truncated/r0/cornell-direct.json"),
        "{stderr}"
    );
    // Other JSON files (a comparison's own output) are passed over without a word.
    let (ok, _, _) = compare(dir, "base", "base");
    assert!(!ok);
    let (_, _, stderr) = compare(dir, "cmp-base-slow", "base");
    assert!(!stderr.contains("skipped"), "{stderr}");
}

/// A real comparison: three repeats each of `direct` for BASE and SLOW (3 ms added to
/// `compose`'s recorded times through the test hook `GIBENCH_TEST_SLOW_STAGE`). Checked: it
/// runs, every stage has a row with a verdict, SLOW's results carry the hook's warning, and
/// two repeats are refused.
#[test]
fn compare_runs_end_to_end() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let run_into = |out: &Path, slow: bool| {
        let mut c = support::gibench();
        c.args(["run", "--technique", "direct", "--frames", "10"])
            .args([
                "--warmup",
                "2",
                "--timing",
                "stages",
                "--resolution",
                "64x48",
            ])
            .args(["--quiet", "--no-images", "--out"])
            .arg(out);
        if slow {
            c.env("GIBENCH_TEST_SLOW_STAGE", "compose:3");
        } else {
            c.env_remove("GIBENCH_TEST_SLOW_STAGE");
        }
        let o = c.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    for i in 0..3 {
        run_into(&dir.join(format!("base/r{i}")), false);
        run_into(&dir.join(format!("slow/r{i}")), true);
    }
    let (ok, rows, stderr) = compare(dir, "base", "slow");
    assert!(ok, "{stderr}");
    let mut stages: Vec<&str> = rows.iter().map(|(s, _)| s.as_str()).collect();
    stages.sort_unstable();
    let mut want = STAGES.to_vec();
    want.sort_unstable();
    assert_eq!(stages, want, "{rows:?}");
    assert!(rows
        .iter()
        .all(|(_, v)| ["slower", "faster", "unchanged"].contains(&v.as_str())));
    let warned = |side: &str| {
        let f = dir.join(side).join("r0/cornell-direct.json");
        let v: Value = serde_json::from_slice(&std::fs::read(f).unwrap()).unwrap();
        v["warnings"].as_array().is_some_and(|w| {
            w.iter()
                .any(|w| w.as_str().unwrap().contains("GIBENCH_TEST_SLOW_STAGE"))
        })
    };
    assert!(warned("slow") && !warned("base"));
    std::fs::remove_dir_all(dir.join("slow/r2")).unwrap();
    let (ok, _, stderr) = compare(dir, "base", "slow");
    assert!(
        !ok && stderr.contains("CURRENT has 2 repeat(s) of cornell/direct/64x48"),
        "{stderr}"
    );
}
