//! `gibench export --format bmf`: Bencher Metric Format JSON from results folders and
//! instruction counts.

use crate::support;

use std::path::{Path, PathBuf};

use serde_json::Value;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Checks `doc` against the shape Bencher documents for BMF JSON
/// (https://bencher.dev/docs/reference/bencher-metric-format/, its JSON Schema
/// `https://bencher.dev/bmf.json`, draft-07): an object whose keys (benchmarks, pattern ".+")
/// map to objects whose keys (measures, pattern ".+") map to objects with a required number
/// `value` and optional numbers `lower_value` and `upper_value`. Also from that page: a
/// benchmark name has at most 1024 characters and a measure slug at most 64. Stricter than the
/// schema (which allows other keys): a metric holds only those three keys, so a misspelt one
/// cannot pass unnoticed; and lower_value <= value <= upper_value.
fn check_bmf_shape(doc: &Value) -> Result<usize, String> {
    let benchmarks = doc.as_object().ok_or("the document is not an object")?;
    let mut metrics = 0;
    for (name, measures) in benchmarks {
        if name.is_empty() || name.chars().count() > 1024 {
            return Err(format!("benchmark name '{name}': 1 to 1024 characters"));
        }
        let measures = measures
            .as_object()
            .ok_or(format!("benchmark '{name}' is not an object"))?;
        if measures.is_empty() {
            return Err(format!("benchmark '{name}' has no measure"));
        }
        for (slug, metric) in measures {
            let slug_ok = !slug.is_empty()
                && slug.len() <= 64
                && slug
                    .chars()
                    .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-');
            if !slug_ok {
                return Err(format!(
                    "{name}: measure '{slug}' is not a slug of at most 64"
                ));
            }
            let m = metric
                .as_object()
                .ok_or(format!("{name}/{slug} is not an object"))?;
            let value = m
                .get("value")
                .and_then(Value::as_f64)
                .ok_or(format!("{name}/{slug}: 'value' missing or not a number"))?;
            for key in m.keys() {
                if !["value", "lower_value", "upper_value"].contains(&key.as_str()) {
                    return Err(format!("{name}/{slug}: unknown key '{key}'"));
                }
            }
            let bound = |k: &str| -> Result<Option<f64>, String> {
                match m.get(k) {
                    None => Ok(None),
                    Some(v) => v
                        .as_f64()
                        .map(Some)
                        .ok_or(format!("{name}/{slug}: '{k}' is not a number")),
                }
            };
            let (lo, hi) = (bound("lower_value")?, bound("upper_value")?);
            if lo.is_some_and(|lo| lo > value) || hi.is_some_and(|hi| hi < value) {
                return Err(format!("{name}/{slug}: not lower <= value <= upper: {m:?}"));
            }
            metrics += 1;
        }
    }
    Ok(metrics)
}

/// Three repeats of the committed baseline's `direct` and `laine` runs, `direct` with a
/// quality block (RMSE 0.1, 0.2, 0.3) so that image error is exported too.
fn inputs(dir: &Path) {
    for i in 1..=3 {
        let d = dir.join(format!("r{i}"));
        std::fs::create_dir_all(&d).unwrap();
        for t in ["direct", "laine"] {
            let src = root().join(format!("results/baseline/r{i}/cornell-{t}.json"));
            let mut v: Value = serde_json::from_slice(&std::fs::read(src).unwrap()).unwrap();
            if t == "direct" {
                let s = |x: f64| serde_json::json!({"count": 1, "mean": x, "median": x, "p5": x, "p95": x, "p99": x, "min": x, "max": x});
                v["quality"] = serde_json::json!({"reference": "r", "frames": [],
                    "rmse": s(0.1 * i as f64), "rel_mse": s(0.01), "mae": s(0.01), "flip_mean": s(0.05)});
            }
            std::fs::write(
                d.join(format!("cornell-{t}.json")),
                serde_json::to_vec(&v).unwrap(),
            )
            .unwrap();
        }
    }
}

/// The export of a folder of repeats and the committed instruction counts passes the
/// documented shape, and carries the right figures: a stage's `latency` in nanoseconds (the
/// built-in measure's unit) is the median of the repeats' medians with their extremes as
/// bounds, image error and instruction counts are there, and `--print-testbed` gives one slug.
/// Catches a misspelt key (`lower`), milliseconds sent as nanoseconds, a metric without
/// `value`, and repeats not folded into one metric.
#[test]
fn export_writes_bmf_that_bencher_documents() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    inputs(&dir.join("runs"));
    let out = dir.join("bmf/history.json");
    let instructions = root().join("results/baseline/instructions.json");
    let o = support::GIBENCH.run_ok(&[
        "export".as_ref(),
        "--format".as_ref(),
        "bmf".as_ref(),
        dir.join("runs").as_os_str(),
        "--instructions".as_ref(),
        instructions.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    let doc: Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    let n = check_bmf_shape(&doc).unwrap_or_else(|e| panic!("{e}\n{doc:#}"));
    assert!(n > 10, "{n} metrics; {stderr}");

    // One stage, by hand from the three files.
    let compose: Vec<f64> = (1..=3)
        .map(|i| {
            let f = dir.join(format!("runs/r{i}/cornell-direct.json"));
            let v: Value = serde_json::from_slice(&std::fs::read(f).unwrap()).unwrap();
            let s = v["stages"]
                .as_array()
                .unwrap()
                .iter()
                .find(|s| s["name"] == "compose")
                .unwrap();
            s["wall_ms"]["median"].as_f64().unwrap() * 1e6
        })
        .collect();
    let mut sorted = compose.clone();
    sorted.sort_by(f64::total_cmp);
    let m = &doc["cornell@128x96/direct/compose"]["latency"];
    let close = |a: &Value, b: f64| (a.as_f64().unwrap() - b).abs() <= 1e-6 * b;
    assert!(close(&m["value"], sorted[1]), "{m} vs {sorted:?}");
    assert!(close(&m["lower_value"], sorted[0]) && close(&m["upper_value"], sorted[2]));
    assert!(doc["cornell@128x96/laine/vpl-management"]["latency"].is_object());
    let rmse = &doc["cornell@128x96/direct/image-error"]["rmse"];
    assert!(
        close(&rmse["value"], 0.2) && close(&rmse["lower_value"], 0.1),
        "{rmse}"
    );
    let counts: Value = serde_json::from_slice(&std::fs::read(&instructions).unwrap()).unwrap();
    for (kernel, count) in counts["kernels"].as_object().unwrap() {
        assert_eq!(
            doc[format!("kernels/{kernel}")]["instructions"]["value"].as_f64(),
            count.as_f64(),
            "{kernel}"
        );
    }

    let o = support::GIBENCH.run_ok(&[
        "export".as_ref(),
        "--format".as_ref(),
        "bmf".as_ref(),
        "--print-testbed".as_ref(),
        dir.join("runs").as_os_str(),
    ]);
    let testbed = String::from_utf8_lossy(&o.stdout).trim().to_string();
    assert!(
        !testbed.is_empty()
            && testbed.len() <= 64
            && testbed
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-'),
        "{testbed:?}"
    );
}

/// The shape check itself fails on what it must catch (a test that cannot fail proves
/// nothing).
#[test]
fn the_shape_check_refuses_malformed_bmf() {
    let bad = [
        serde_json::json!([]),
        serde_json::json!({"b": {"latency": {"lower_value": 1.0}}}),
        serde_json::json!({"b": {"latency": {"value": "1"}}}),
        serde_json::json!({"b": {"latency": {"value": 1.0, "lower": 0.5}}}),
        serde_json::json!({"b": {"latency": {"value": 1.0, "upper_value": 0.5}}}),
        serde_json::json!({"b": {"Latency Time": {"value": 1.0}}}),
        serde_json::json!({"b": {}}),
    ];
    for doc in bad {
        assert!(check_bmf_shape(&doc).is_err(), "{doc}");
    }
    let good = serde_json::json!({"b": {"latency": {"value": 88.0, "lower_value": 87.42, "upper_value": 88.88}}});
    assert_eq!(check_bmf_shape(&good), Ok(1));
}

/// Bad input is named before anything is written: runs of two devices, an instruction file
/// without counts, no input at all.
#[test]
fn export_names_bad_input() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    inputs(&dir.join("runs"));
    let f = dir.join("runs/r2/cornell-direct.json");
    let mut v: Value = serde_json::from_slice(&std::fs::read(&f).unwrap()).unwrap();
    v["device"]["adapter"] = "another GPU".into();
    std::fs::write(&f, serde_json::to_vec(&v).unwrap()).unwrap();
    let out = dir.join("out.json");
    let run = |args: &[&std::ffi::OsStr]| {
        let o = support::GIBENCH.command().args(args).output().unwrap();
        assert!(!o.status.success());
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let e = run(&[
        "export".as_ref(),
        "--format".as_ref(),
        "bmf".as_ref(),
        dir.join("runs").as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert!(e.contains("2 devices") && e.contains("another-gpu"), "{e}");
    let bad = dir.join("bad-instructions.json");
    std::fs::write(&bad, br#"{"counts": {}}"#).unwrap();
    let e = run(&[
        "export".as_ref(),
        "--format".as_ref(),
        "bmf".as_ref(),
        "--instructions".as_ref(),
        bad.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert!(
        e.contains("bad-instructions.json") && e.contains("'kernels'"),
        "{e}"
    );
    let e = run(&["export".as_ref(), "--format".as_ref(), "bmf".as_ref()]);
    assert!(e.contains("inputs"), "{e}");
    // Two runs whose names would print alike: one without the parameter `gained`, one whose
    // `gained` is the word that stands for a missing value.
    let two = dir.join("two");
    std::fs::create_dir_all(&two).unwrap();
    let mut v: Value = serde_json::from_slice(
        &std::fs::read(root().join("results/baseline/r1/cornell-direct.json")).unwrap(),
    )
    .unwrap();
    std::fs::write(two.join("a.json"), serde_json::to_vec(&v).unwrap()).unwrap();
    v["parameters"]["gained"] = "absent".into();
    std::fs::write(two.join("b.json"), serde_json::to_vec(&v).unwrap()).unwrap();
    let e = run(&[
        "export".as_ref(),
        "--format".as_ref(),
        "bmf".as_ref(),
        two.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert!(
        e.contains("inputs") && e.contains("cornell@128x96/direct/gained=absent"),
        "{e}"
    );
    assert!(!out.exists());
}

/// The distinct benchmark prefixes (names without their last segment, the stage) of `doc`.
fn prefixes(doc: &Value) -> std::collections::BTreeSet<String> {
    doc.as_object()
        .unwrap()
        .keys()
        .map(|k| k.rsplit_once('/').unwrap().0.to_string())
        .collect()
}

/// `gibench export --format bmf DIRS...`'s document.
fn export(dirs: &[&Path]) -> Value {
    let mut args: Vec<&std::ffi::OsStr> =
        vec!["export".as_ref(), "--format".as_ref(), "bmf".as_ref()];
    args.extend(dirs.iter().map(|d| d.as_os_str()));
    let o = support::GIBENCH.run_ok(&args);
    serde_json::from_slice(&o.stdout).unwrap()
}

/// The folders under `results` whose every results file was made on the device of
/// `results/baseline` (its `device` record whole: adapter, backend, driver, a software
/// rasteriser's thread setting): one testbed's runs, which export together. Others (a folder
/// made with `LP_NUM_THREADS=0`, or on a GPU) are another testbed's.
fn on_the_baselines_device(results: &Path) -> Vec<PathBuf> {
    fn devices(dir: &Path, out: &mut std::collections::BTreeSet<String>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                devices(&p, out);
            } else if p.extension().is_some_and(|x| x == "json") {
                let v: Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
                if v.get("schema_version").is_some() {
                    out.insert(v["device"].to_string());
                }
            }
        }
    }
    let mut want = std::collections::BTreeSet::new();
    devices(&results.join("baseline"), &mut want);
    assert_eq!(want.len(), 1, "{want:?}");
    let mut folders: Vec<PathBuf> = (std::fs::read_dir(results).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .filter(|p| {
            let mut found = std::collections::BTreeSet::new();
            devices(p, &mut found);
            found == want
        })
        .collect();
    folders.sort();
    folders
}

/// A whole reproduction exports: the committed `results/` folders of one device (its sweeps, where runs of
/// one scene, resolution and technique differ only in parameters, and runs of one technique
/// made with other frame counts by different targets) gives one document that passes the
/// documented shape, with every point of the ISM VPL-count and Keller tile sweeps under its
/// own name; a sweep's folder alone names only the swept parameter
/// (`cornell@256x192/ism/vpls=1024/...`), the baseline's repeats stay one benchmark and a
/// single run keeps the short name. Catches the old refusal ("two runs would share the
/// benchmark names"), sweep points folded together as repeats, and names that carry every
/// parameter (this test failed so).
#[test]
fn a_whole_reproduction_exports_with_sweep_points_apart() {
    let results = root().join("results");
    let folders = on_the_baselines_device(&results);
    let doc = export(&folders.iter().map(PathBuf::as_path).collect::<Vec<_>>());
    let n = check_bmf_shape(&doc).unwrap_or_else(|e| panic!("{e}"));
    assert!(n > 1000, "{n} metrics");
    let names = prefixes(&doc);
    // The values of `param` in the results files of the sweep folder `dir`.
    let swept = |dir: &str, param: &str| -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(results.join(dir))
            .unwrap()
            .filter_map(|e| {
                let p = e.unwrap().path();
                let v: Value = serde_json::from_slice(&std::fs::read(&p).ok()?).ok()?;
                let x = &v["parameters"][param];
                Some(x.as_str().map_or(x.to_string(), String::from)).filter(|_| !x.is_null())
            })
            .collect();
        v.sort();
        v
    };
    // Every point of two sweeps is a benchmark of its own, in the whole export (where other
    // parameters and frame counts differ too) and in its folder's alone (where only the swept
    // parameter is named).
    for (dir, prefix, param) in [
        ("ism/vpls", "cornell@256x192/ism", "vpls"),
        ("keller/tiles", "cornell@256x192/keller-full", "tiles"),
    ] {
        let values = swept(dir, param);
        assert!(values.len() >= 3, "{dir}: {values:?}");
        let alone = prefixes(&export(&[&results.join(dir)]));
        let want: std::collections::BTreeSet<String> = values
            .iter()
            .map(|v| format!("{prefix}/{param}={v}"))
            .collect();
        assert_eq!(alone, want, "{dir}");
        for v in &values {
            let named = |n: &&String| {
                n.strip_prefix(&format!("{prefix}/"))
                    .is_some_and(|rest| rest.split(',').any(|kv| kv == format!("{param}={v}")))
            };
            assert!(names.iter().any(|n| named(&n)), "{param}={v} in {names:#?}");
        }
    }
    // The baseline's five repeats of a run are one benchmark.
    let baseline = prefixes(&export(&[&results.join("baseline")]));
    assert!(baseline.contains("cornell@128x96/laine"), "{baseline:?}");
    // A single run keeps today's short name.
    let tmp = tempfile::tempdir().unwrap();
    std::fs::copy(
        results.join("baseline/r1/cornell-laine.json"),
        tmp.path().join("cornell-laine.json"),
    )
    .unwrap();
    let one = prefixes(&export(&[tmp.path()]));
    assert_eq!(
        one.into_iter().collect::<Vec<_>>(),
        ["cornell@128x96/laine"]
    );
}

/// Criterion's output folder (`--criterion`): `tests/fixtures/criterion` holds three
/// benchmarks' `new/benchmark.json` and `new/estimates.json` copied from a real `cargo bench
/// --bench kernels` (two wall-time, one `reference-cpu` bench in CPU time); a saved baseline
/// (`base/`, here with every figure doubled) and an HTML report folder are added beside them.
/// The export passes the documented shape, names each benchmark `kernels/<criterion id>`,
/// gives the mean's point estimate with its confidence interval in nanoseconds as `latency`
/// (`cpu-time` for the `-cpu` groups), and reads only `new/`. Catches the baseline read
/// instead of the latest run (or both, which would collide), a misread estimate (the median,
/// or the standard error as a bound), and a missing folder accepted.
#[test]
fn criterion_benchmarks_export_as_kernels() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("criterion");
    let fixture = root().join("tests/fixtures/criterion");
    let mut estimates = std::collections::BTreeMap::new();
    for bench in std::fs::read_dir(&fixture).unwrap() {
        let bench = bench.unwrap().path();
        let to = dir.join(bench.file_name().unwrap());
        for sub in ["new", "base"] {
            std::fs::create_dir_all(to.join(sub)).unwrap();
            std::fs::copy(
                bench.join("new/benchmark.json"),
                to.join(sub).join("benchmark.json"),
            )
            .unwrap();
        }
        std::fs::create_dir_all(to.join("report")).unwrap();
        std::fs::write(to.join("report/index.html"), "<html></html>").unwrap();
        let est: Value =
            serde_json::from_slice(&std::fs::read(bench.join("new/estimates.json")).unwrap())
                .unwrap();
        std::fs::write(
            to.join("new/estimates.json"),
            serde_json::to_vec(&est).unwrap(),
        )
        .unwrap();
        let mut base = est.clone();
        for k in ["mean", "median", "slope"] {
            if let Some(m) = base.get_mut(k).filter(|m| m.is_object()) {
                m["point_estimate"] = (m["point_estimate"].as_f64().unwrap() * 2.0).into();
            }
        }
        std::fs::write(
            to.join("base/estimates.json"),
            serde_json::to_vec(&base).unwrap(),
        )
        .unwrap();
        let id: Value =
            serde_json::from_slice(&std::fs::read(bench.join("new/benchmark.json")).unwrap())
                .unwrap();
        estimates.insert(id["full_id"].as_str().unwrap().to_string(), est);
    }
    assert_eq!(estimates.len(), 3);
    let out = tmp.path().join("bmf.json");
    support::GIBENCH.run_ok(&[
        "export".as_ref(),
        "--format".as_ref(),
        "bmf".as_ref(),
        "--criterion".as_ref(),
        dir.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    let doc: Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    assert_eq!(check_bmf_shape(&doc), Ok(3), "{doc:#}");
    for (id, est) in &estimates {
        let measure = if id.starts_with("reference-cpu/") {
            "cpu-time"
        } else {
            "latency"
        };
        let m = &doc[format!("kernels/{id}")][measure];
        let mean = &est["mean"];
        assert_eq!(m["value"], mean["point_estimate"], "{id}: {m}");
        assert_eq!(
            m["lower_value"], mean["confidence_interval"]["lower_bound"],
            "{id}"
        );
        assert_eq!(
            m["upper_value"], mean["confidence_interval"]["upper_bound"],
            "{id}"
        );
    }
    assert!(
        doc["kernels/rays/closest-hit-1024/cornell"]["latency"]["value"]
            .as_f64()
            .unwrap()
            > 1e3
    );

    let empty = tmp.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    for bad in [&empty, &tmp.path().join("missing")] {
        let o = support::GIBENCH
            .command()
            .args(["export", "--format", "bmf", "--criterion"])
            .arg(bad)
            .output()
            .unwrap();
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(
            !o.status.success() && e.contains("criterion") && e.contains("target/criterion"),
            "{e}"
        );
    }
}
