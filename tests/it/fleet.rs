//! Beyond one machine: `reproduce all` split over shards (from a Slurm array's or a Kubernetes
//! Indexed Job's environment, each shard its own process) and pooled again by `gibench merge`
//! gives the tables of one unsharded run; `--budget` leaves out what does not fit and says so.
//! Runs at `GIBENCH_TEST_SIZE=tiny` (docs/fleet.md): the manifests record it.

use crate::support;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

/// Every job-system variable a shard reads, removed from the test's own environment.
const SHARD_VARS: &[&str] = &[
    "SLURM_ARRAY_TASK_ID",
    "SLURM_ARRAY_TASK_COUNT",
    "SLURM_ARRAY_TASK_MIN",
    "SLURM_ARRAY_TASK_STEP",
    "JOB_COMPLETION_INDEX",
    "GIBENCH_SHARD_COUNT",
    "BUILDKITE_PARALLEL_JOB",
    "BUILDKITE_PARALLEL_JOB_COUNT",
];

/// `gibench reproduce all --quick --quiet --only ONLY --out OUT` at the tiny test size, with
/// `vars` as its job system's environment, started (not waited for).
pub(crate) fn start(only: &str, out: &Path, vars: &[(&str, String)]) -> Child {
    let mut c: Command = support::GIBENCH.command();
    for v in SHARD_VARS {
        c.env_remove(v);
    }
    c.env("GIBENCH_TEST_SIZE", "tiny")
        .args([
            "reproduce",
            "all",
            "--quick",
            "--quiet",
            "--only",
            only,
            "--out",
        ])
        .arg(out)
        .envs(vars.iter().map(|(k, v)| (*k, v.as_str())))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("gibench starts")
}

fn finish(child: Child, what: &str) -> String {
    let o = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{what} failed:\n{stderr}");
    stderr
}

pub(crate) fn manifest(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("reproduce-all.json")).unwrap()).unwrap()
}

/// A results JSON without what timing and the process change: keys of times and rates
/// (`*_ms`, `fps`, `seconds`, `timestamp`, `samples_ms`, …) and the process's peak memory
/// dropped at every depth. What remains (scene,
/// parameters, settings, stage names, counters, VPL counts, image error) must agree exactly.
fn untimed(v: &serde_json::Value) -> serde_json::Value {
    use serde_json::Value;
    let timing = |k: &str| {
        k.ends_with("_ms")
            || k.ends_with("_s")
            || k.contains("seconds")
            || k.contains("time")
            || k == "fps"
            || k == "timestamp"
            || k == "peak_memory_mb"
            // Measured, not computed: the bounds' kernel sizes grow with the device's speed,
            // the per-frame GPU spans are timings, and whether a reference was rendered or
            // found in the cache depends on which process got there first.
            || k == "device_bounds"
            || k == "gpu_spans"
            || k == "reference_work"
    };
    match v {
        Value::Object(m) => Value::Object(
            m.iter()
                .filter(|(k, _)| !timing(k))
                .map(|(k, v)| (k.clone(), untimed(v)))
                .collect(),
        ),
        Value::Array(a) => Value::Array(a.iter().map(untimed).collect()),
        other => other.clone(),
    }
}

/// A Markdown table file with every number replaced by `#` and the Pareto front's line by a
/// placeholder: its title, columns, row labels and notes, which timing does not change (the
/// numbers are compared in the results JSON; which runs make the front, timings decide: seen
/// differing between a sharded and an unsharded run on a busy machine).
fn shape(md: &str) -> String {
    // The Pareto front's line names the runs on the front, which their timings decide.
    let md: Vec<&str> = (md.lines())
        .map(|l| match l.starts_with("Pareto front") {
            true => "Pareto front (runs chosen by their timings)",
            false => l,
        })
        .collect();
    let mut out = String::new();
    let mut in_number = false;
    for c in md.join("\n").chars() {
        let digit = c.is_ascii_digit() || (in_number && (c == '.' || c == '-'));
        if digit {
            if !in_number {
                out.push('#');
            }
            in_number = true;
        } else {
            in_number = false;
            out.push(c);
        }
    }
    out
}

/// Each target's files (relative, sorted) in a manifest, by target name (targets it ran).
fn files_by_target(m: &serde_json::Value) -> BTreeMap<String, Vec<String>> {
    m["targets"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|t| t["carried_from"].is_null() && t["left_out"].is_null())
        .map(|t| {
            let mut f: Vec<String> = t["files"]
                .as_array()
                .unwrap()
                .iter()
                .map(|f| f.as_str().unwrap().to_string())
                .collect();
            f.sort();
            (t["name"].as_str().unwrap().to_string(), f)
        })
        .collect()
}

/// `merged` holds what `single` holds: the same targets with the same files, every results
/// JSON equal but for timings, every Markdown table equal but for its numbers.
pub(crate) fn assert_same_tables(single: &Path, merged: &Path) {
    let (a, b) = (manifest(single), manifest(merged));
    assert_eq!(a["mode"], b["mode"]);
    assert_eq!(
        a["mode"], "quick-tiny",
        "the test size is recorded as the mode"
    );
    let (fa, fb) = (files_by_target(&a), files_by_target(&b));
    assert_eq!(
        fa.keys().collect::<Vec<_>>(),
        fb.keys().collect::<Vec<_>>(),
        "the merged targets differ"
    );
    for (target, files) in &fa {
        assert_eq!(files, &fb[target], "{target}'s files differ");
        for f in files {
            let (x, y) = (single.join(f), merged.join(f));
            assert!(y.is_file(), "{f} listed but not in the merged folder");
            if f.ends_with(".json") {
                let x: serde_json::Value =
                    serde_json::from_slice(&std::fs::read(&x).unwrap()).unwrap();
                let y: serde_json::Value =
                    serde_json::from_slice(&std::fs::read(&y).unwrap()).unwrap();
                assert_eq!(untimed(&x), untimed(&y), "{f} differs beyond its timings");
            } else if f.ends_with(".md") {
                let x = std::fs::read_to_string(&x).unwrap();
                let y = std::fs::read_to_string(&y).unwrap();
                assert_eq!(
                    shape(&x),
                    shape(&y),
                    "{f}'s table differs beyond its numbers"
                );
            }
        }
    }
}

/// Runs `only` unsharded and as `count` shards (each its own process, all at once, the
/// shard's environment from `vars(i)`), merges the shards and checks the merged folder
/// against the unsharded one. Returns the shards' standard error.
fn shards_match_one_run(
    tmp: &Path,
    only: &str,
    count: usize,
    vars: &dyn Fn(usize) -> Vec<(&'static str, String)>,
) -> Vec<String> {
    let single = tmp.join("single");
    let shard_dirs: Vec<PathBuf> = (0..count).map(|i| tmp.join(format!("shard{i}"))).collect();
    let one = start(only, &single, &[]);
    let shards: Vec<Child> = shard_dirs
        .iter()
        .enumerate()
        .map(|(i, d)| start(only, d, &vars(i)))
        .collect();
    finish(one, "the unsharded run");
    let logs: Vec<String> = shards
        .into_iter()
        .enumerate()
        .map(|(i, c)| finish(c, &format!("shard {i}")))
        .collect();
    // Every target in exactly one shard.
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    for d in &shard_dirs {
        for t in files_by_target(&manifest(d)).keys() {
            *seen.entry(t.clone()).or_default() += 1;
        }
    }
    let expected: Vec<&str> = only.split(',').collect();
    assert_eq!(seen.keys().map(String::as_str).collect::<Vec<_>>(), {
        let mut e = expected.clone();
        e.sort();
        e
    });
    assert!(
        seen.values().all(|&n| n == 1),
        "a target ran in two shards: {seen:?}"
    );
    let merged = tmp.join("merged");
    let mut args: Vec<PathBuf> = vec!["merge".into()];
    args.extend(shard_dirs.iter().cloned());
    args.push("--out".into());
    args.push(merged.clone());
    support::GIBENCH.run_ok(&args);
    assert_same_tables(&single, &merged);
    logs
}

/// Catches: shards that overlap (a target in two shards: counted above, and refused by
/// merge), lose a target (the merged targets differ), read the Slurm or Kubernetes variables
/// wrongly (no or the wrong split), or a merge that mixes two targets' files or drops some
/// (the files or their contents differ from the unsharded run's).
#[test]
fn shards_from_slurm_and_kubernetes_merge_to_the_unsharded_tables() {
    let tmp = tempfile::tempdir().unwrap();
    let slurm = tmp.path().join("slurm");
    let logs = shards_match_one_run(&slurm, "laine-tables,keller-tiles,ism-vpls", 3, &|i| {
        vec![
            ("SLURM_ARRAY_TASK_ID", i.to_string()),
            ("SLURM_ARRAY_TASK_COUNT", "3".into()),
        ]
    });
    // A command target's table at the tiny size is marked as a smoke run's, as the paper
    // targets' are (it said nothing before).
    let tiles = slurm.join("single/keller/tiles/cornell-keller-full-sweep-tiles.md");
    let md = std::fs::read_to_string(&tiles).unwrap();
    assert!(
        md.starts_with("### SMOKE RUN: ") && md.contains("SMOKE RUN (--test-size tiny"),
        "{md}"
    );
    // The shard and where it came from are printed.
    assert!(
        logs[1].contains("shard 1/3") && logs[1].contains("SLURM_ARRAY_TASK_ID=1"),
        "{}",
        logs[1]
    );
    // Kubernetes: the index from JOB_COMPLETION_INDEX, the count from GIBENCH_SHARD_COUNT (a
    // cheaper selection: two shards over Laine's three CPU-light targets).
    let k8s = tmp.path().join("k8s");
    let logs = shards_match_one_run(
        &k8s,
        "laine-tables,laine-management,laine-dispersion",
        2,
        &|i| {
            vec![
                ("JOB_COMPLETION_INDEX", i.to_string()),
                ("GIBENCH_SHARD_COUNT", "2".into()),
            ]
        },
    );
    assert!(logs[0].contains("JOB_COMPLETION_INDEX=0"), "{}", logs[0]);
    // Merging a shard twice, or without the others, is refused by name.
    let s0 = slurm.join("shard0");
    let s1 = slurm.join("shard1");
    for (dirs, expect) in [
        (vec![&s0, &s0, &s1], "both shard 0/3"),
        (vec![&s0, &s1], "shard 2/3 is missing"),
        (vec![&s0, &k8s.join("shard1")], "one shard count"),
    ] {
        let out = tmp.path().join("bad-merge");
        let mut args: Vec<PathBuf> = vec!["merge".into()];
        args.extend(dirs.iter().map(|d| d.to_path_buf()));
        args.extend(["--out".into(), out.clone()]);
        let o = support::GIBENCH.run(&args);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(
            !o.status.success() && stderr.contains(expect),
            "{dirs:?}: {stderr}"
        );
        assert!(!out.exists(), "a refused merge wrote {out:?}");
    }
}

/// A hand-written reproduce-all.json for merge's checks (no run needed).
fn fake(dir: &Path, mode: &str, commit: &str, targets: &[&str]) {
    std::fs::create_dir_all(dir).unwrap();
    let targets: Vec<serde_json::Value> = targets
        .iter()
        .map(|t| {
            serde_json::json!({"name": t, "dir": t, "what": "", "command": "", "frames": 1,
                "units": 1, "estimate_s": null, "seconds": 1.0, "files": [],
                "carried_from": null, "adapter": "x"})
        })
        .collect();
    let m = serde_json::json!({"mode": mode, "adapter": "x", "driver": "", "git_commit": commit,
        "cpu_threads": 1, "seconds": 1.0, "estimate_s": null, "targets": targets});
    std::fs::write(
        dir.join("reproduce-all.json"),
        serde_json::to_vec(&m).unwrap(),
    )
    .unwrap();
}

/// Catches: merge pooling runs of different modes (quick with paper, a test size with real
/// sizes) or commits, or the same target from two machines, instead of refusing by name.
#[test]
fn merge_refuses_mixed_settings_and_duplicates() {
    let tmp = tempfile::tempdir().unwrap();
    let d = |n: &str| tmp.path().join(n);
    fake(&d("a"), "quick", "abc", &["keller-tiles"]);
    fake(&d("paper"), "paper", "abc", &["ism-vpls"]);
    fake(&d("tiny"), "quick-tiny", "abc", &["ism-vpls"]);
    fake(&d("other"), "quick", "def", &["ism-vpls"]);
    fake(&d("dup"), "quick", "abc", &["keller-tiles"]);
    fake(&d("ok"), "quick", "abc", &["ism-vpls"]);
    for (other, expect) in [
        ("paper", "mode differs: 'quick'"),
        ("tiny", "mode differs"),
        ("other", "git_commit differs"),
        ("dup", "target 'keller-tiles' ran in both"),
        ("missing", "reproduce-all.json"),
    ] {
        let out = d("out");
        let o = support::GIBENCH.run(&[
            "merge".as_ref(),
            d("a").as_os_str(),
            d(other).as_os_str(),
            "--out".as_ref(),
            out.as_os_str(),
        ]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(
            !o.status.success() && stderr.contains(expect),
            "{other}: {stderr}"
        );
        assert!(!out.exists(), "{other}: a refused merge wrote {out:?}");
    }
    // Different targets of one mode and commit pool (the control: the refusals above are
    // about the settings, not about merging at all).
    let out = d("out");
    support::GIBENCH.run_ok(&[
        "merge".as_ref(),
        d("a").as_os_str(),
        d("ok").as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert_eq!(files_by_target(&manifest(&out)).len(), 2);
}

/// Catches: `--budget` starting a target whose estimate does not fit (or one without an
/// estimate), writing a left-out target's folder, or not saying what it left out and why.
/// The estimates come from a reproduce-all.json put in the output folder.
#[test]
fn a_budget_runs_what_fits_and_lists_what_it_left_out() {
    let tmp = tempfile::tempdir().unwrap();
    // A first run gives the manifest (with the work units the estimates scale by).
    let first = tmp.path().join("first");
    finish(
        start("laine-management,laine-dispersion", &first, &[]),
        "the first run",
    );
    let mut m = manifest(&first);
    for t in m["targets"].as_array_mut().unwrap() {
        // laine-dispersion: 1 s (fits 2 minutes); laine-management: a day (does not).
        t["seconds"] = serde_json::json!(if t["name"] == "laine-dispersion" {
            1.0
        } else {
            86400.0
        });
        t["files"] = serde_json::json!([]);
    }
    let out = tmp.path().join("budget");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(
        out.join("reproduce-all.json"),
        serde_json::to_vec(&m).unwrap(),
    )
    .unwrap();
    // keller-tiles has no estimate there: left out too.
    let began = std::time::Instant::now();
    let mut c = support::GIBENCH.command();
    for v in SHARD_VARS {
        c.env_remove(v);
    }
    let o = c
        .env("GIBENCH_TEST_SIZE", "tiny")
        .args([
            "reproduce",
            "all",
            "--quick",
            "--quiet",
            "--budget",
            "2m",
            "--only",
            "keller-tiles,laine-management,laine-dispersion",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    let took = began.elapsed().as_secs_f64();
    let stdout = String::from_utf8_lossy(&o.stdout);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(took < 120.0, "the 2m budget took {took:.0} s");
    assert!(
        stdout.contains("left out: laine-management (its estimate"),
        "{stdout}"
    );
    assert!(
        stdout.contains("left out: keller-tiles (no estimate"),
        "{stdout}"
    );
    assert!(out.join("laine/laine-dispersion.md").is_file());
    assert!(
        !out.join("laine/laine-management.md").exists(),
        "a left-out target was written"
    );
    assert!(
        !out.join("keller").exists(),
        "a left-out target's folder was written"
    );
    let m = manifest(&out);
    let entry = |n: &str| {
        m["targets"]
            .as_array()
            .unwrap()
            .iter()
            .find(|t| t["name"] == n)
            .unwrap()
            .clone()
    };
    assert!(entry("laine-dispersion")["left_out"].is_null());
    assert!(entry("laine-dispersion")["seconds"].as_f64().unwrap() > 0.0);
    assert!(entry("laine-management")["left_out"]
        .as_str()
        .unwrap()
        .contains("did not fit"));
    assert!(entry("keller-tiles")["left_out"]
        .as_str()
        .unwrap()
        .contains("no estimate"));
    assert_eq!(m["budget_s"].as_f64(), Some(120.0));
    let md = std::fs::read_to_string(out.join("reproduce-all.md")).unwrap();
    assert!(
        md.contains("**left out**") && md.contains("Budget: 2m00s"),
        "{md}"
    );
    assert!(md.contains("TEST SIZE tiny"), "{md}");
}

/// Catches: within a budget (a GPU slot), one failing target costing the others (the whole
/// output set discarded), publishing any file of the failed target, or exiting 0 after a
/// failure. `GIBENCH_TEST_FAIL_TARGET` makes laine-management fail after writing its files.
#[test]
fn a_target_failing_within_a_budget_is_left_out_and_the_rest_published() {
    let tmp = tempfile::tempdir().unwrap();
    let first = tmp.path().join("first");
    finish(
        start("laine-management,laine-dispersion", &first, &[]),
        "the first run",
    );
    let mut m = manifest(&first);
    for t in m["targets"].as_array_mut().unwrap() {
        t["seconds"] = serde_json::json!(1.0);
        t["files"] = serde_json::json!([]);
    }
    let out = tmp.path().join("budget");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(
        out.join("reproduce-all.json"),
        serde_json::to_vec(&m).unwrap(),
    )
    .unwrap();
    let mut c = support::GIBENCH.command();
    for v in SHARD_VARS {
        c.env_remove(v);
    }
    let o = c
        .env("GIBENCH_TEST_SIZE", "tiny")
        .env("GIBENCH_TEST_FAIL_TARGET", "laine-management")
        .args([
            "reproduce",
            "all",
            "--quick",
            "--quiet",
            "--budget",
            "5m",
            "--only",
            "laine-management,laine-dispersion",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "a failed target must fail the command");
    assert!(
        stderr.contains("1 target(s) failed and were left out: laine-management"),
        "{stderr}"
    );
    assert!(out.join("laine/laine-dispersion.md").is_file(), "{stderr}");
    assert!(
        !out.join("laine/laine-management.md").exists(),
        "the failed target's files were published"
    );
    let m = manifest(&out);
    let entry = m["targets"]
        .as_array()
        .unwrap()
        .iter()
        .find(|t| t["name"] == "laine-management")
        .unwrap()
        .clone();
    assert!(
        entry["left_out"]
            .as_str()
            .unwrap()
            .starts_with("failed: GIBENCH_TEST_FAIL_TARGET"),
        "{entry}"
    );
    assert_eq!(entry["files"], serde_json::json!([]));
}

/// Catches: bad shard and budget values reaching the work (or a panic) instead of an error
/// naming the option or variable and what was expected.
#[test]
fn bad_shards_and_budgets_are_refused_before_any_work() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    for (args, vars, expect) in [
        (vec!["--shard", "3/3"], vec![], "0/3 to 2/3"),
        (vec!["--shard", "0/0"], vec![], "at least 1"),
        (vec!["--shard", "x"], vec![], "parameter 'shard'"),
        (
            vec![],
            vec![
                ("SLURM_ARRAY_TASK_ID", "a"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ],
            "SLURM_ARRAY_TASK_ID",
        ),
        (
            vec!["--shard", "0/3"],
            vec![
                ("SLURM_ARRAY_TASK_ID", "2"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ],
            "disagree",
        ),
        (
            vec![],
            vec![("JOB_COMPLETION_INDEX", "0")],
            "GIBENCH_SHARD_COUNT",
        ),
        (vec!["--budget", "9x"], vec![], "--budget"),
        (vec!["--budget", "0s"], vec![], "--budget"),
    ] {
        let mut c = support::GIBENCH.command();
        for v in SHARD_VARS {
            c.env_remove(v);
        }
        let o = c
            .args(["reproduce", "all", "--quick", "--only", "laine-dispersion"])
            .args(&args)
            .arg("--out")
            .arg(&out)
            .envs(vars.iter().copied())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(
            !o.status.success() && stderr.contains(expect),
            "{args:?} {vars:?}: {stderr}"
        );
        assert!(!out.exists(), "{args:?} wrote {out:?}");
    }
}

/// `gibench run` on the Cornell box and its omni-light variant (a scene whose name extends
/// the other's: units `cornell-laine` and `cornell-omni-laine`) at 64x48, `frames` measured frames, no images, `extra`
/// added, into `out` with `vars` as its job system's environment, started (not waited for).
fn start_run(
    techniques: &str,
    frames: &str,
    out: &Path,
    vars: &[(&str, String)],
    extra: &[&str],
) -> Child {
    let mut c: Command = support::GIBENCH.command();
    for v in SHARD_VARS {
        c.env_remove(v);
    }
    c.args([
        "run",
        "--scene",
        "cornell,cornell-omni",
        "--technique",
        techniques,
        "--frames",
        frames,
        "--warmup",
        "1",
        "--timing",
        "stages",
        "--resolution",
        "64x48",
        "--shadow-size",
        "64",
        "--no-images",
        "--quiet",
        "--out",
    ])
    .arg(out)
    .args(extra)
    .envs(vars.iter().map(|(k, v)| (*k, v.as_str())))
    .stdout(Stdio::piped())
    .stderr(Stdio::piped())
    .spawn()
    .expect("gibench starts")
}

/// The results files of a run folder (`*.json` but the shard record), sorted.
fn results_files(dir: &Path) -> Vec<String> {
    let mut f: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".json") && n != "gibench-shard.json")
        .collect();
    f.sort();
    f
}

/// `gibench merge DIRS --out OUT`: its exit status and standard error.
fn merge(dirs: &[PathBuf], out: &Path) -> (bool, String) {
    let mut args: Vec<PathBuf> = vec!["merge".into()];
    args.extend(dirs.iter().cloned());
    args.extend(["--out".into(), out.to_path_buf()]);
    let o = support::GIBENCH.run(&args);
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// `gibench sweep` of laine's tiles over three points at 64x48, two frames, into `out` with
/// `extra` added: its exit status and standard error.
fn sweep(out: &Path, extra: &[&str]) -> (bool, String) {
    let mut c: Command = support::GIBENCH.command();
    for v in SHARD_VARS {
        c.env_remove(v);
    }
    let o = c
        .args([
            "sweep",
            "--technique",
            "laine",
            "--sweep",
            "tiles=2x2,4x4,8x8",
            "--frames",
            "2",
            "--warmup",
            "1",
            "--timing",
            "stages",
            "--resolution",
            "64x48",
            "--shadow-size",
            "64",
            "--no-images",
            "--quiet",
            "--out",
        ])
        .arg(out)
        .args(extra)
        .output()
        .expect("gibench starts");
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// Catches: a `gibench sweep` shard that drops or repeats a point, or a merge that draws the
/// sweep's table from anything but the pooled points in the sweep's order.
#[test]
fn sweep_shards_merge_to_the_unsharded_sweep() {
    let tmp = tempfile::tempdir().unwrap();
    let single = tmp.path().join("single");
    let (ok, e) = sweep(&single, &[]);
    assert!(ok, "the unsharded sweep failed: {e}");
    let dirs: Vec<PathBuf> = (0..2)
        .map(|i| tmp.path().join(format!("shard{i}")))
        .collect();
    for (i, d) in dirs.iter().enumerate() {
        let (ok, e) = sweep(d, &["--shard", &format!("{i}/2")]);
        assert!(ok, "shard {i} failed: {e}");
    }
    let mut all: Vec<String> = dirs.iter().flat_map(|d| results_files(d)).collect();
    all.sort();
    assert_eq!(all, results_files(&single), "the shards' points");
    let merged = tmp.path().join("merged");
    let (ok, e) = merge(&dirs, &merged);
    assert!(ok, "merge failed: {e}");
    assert_eq!(results_files(&merged), results_files(&single));
    for f in [
        "cornell-laine-sweep-tiles.md",
        "cornell-laine-sweep-tiles.csv",
    ] {
        let read = |d: &Path| std::fs::read_to_string(d.join(f)).unwrap();
        assert_eq!(
            shape(&read(&single)),
            shape(&read(&merged)),
            "{f} differs beyond its numbers"
        );
    }
    // The points in the sweep's order (the shape above hides the values).
    let md = std::fs::read_to_string(merged.join("cornell-laine-sweep-tiles.md")).unwrap();
    let at: Vec<usize> = ["| 2x2 |", "| 4x4 |", "| 8x8 |"]
        .iter()
        .map(|v| md.find(v).unwrap_or_else(|| panic!("no row {v}:\n{md}")))
        .collect();
    assert!(
        at.windows(2).all(|w| w[0] < w[1]),
        "rows out of order:\n{md}"
    );
}

/// Catches: a `gibench run` shard that drops a (scene, technique) unit or runs one another
/// shard runs (the merged results differ from the unsharded run's), a Slurm environment not
/// read by `run`, a merge that draws a scene's summary table from anything but that scene's
/// pooled results in the run's order (its shape differs; tried: units split at the first
/// scene prefix put cornell-omni's runs in cornell's table), a merge of `--html` shards
/// without a page of all their runs, or one that pools a shard twice, a unit twice, shards of
/// other settings, or `run` shards with `reproduce all` folders, instead of refusing by name.
#[test]
fn run_shards_merge_to_the_unsharded_run() {
    let tmp = tempfile::tempdir().unwrap();
    let techniques = "direct,keller-full,laine";
    let single = tmp.path().join("single");
    let dirs: Vec<PathBuf> = (0..3)
        .map(|i| tmp.path().join(format!("shard{i}")))
        .collect();
    let one = start_run(techniques, "2", &single, &[], &["--html"]);
    let shards: Vec<Child> = (dirs.iter().enumerate())
        .map(|(i, d)| {
            let vars = [
                ("SLURM_ARRAY_TASK_ID", i.to_string()),
                ("SLURM_ARRAY_TASK_COUNT", "3".to_string()),
            ];
            start_run(techniques, "2", d, &vars, &["--html"])
        })
        .collect();
    // A shard of other settings (three frames), for the refusal below.
    let other = tmp.path().join("other");
    let odd = start_run(techniques, "3", &other, &[], &["--shard", "2/3"]);
    finish(one, "the unsharded run");
    let logs: Vec<String> = (shards.into_iter().enumerate())
        .map(|(i, c)| finish(c, &format!("shard {i}")))
        .collect();
    finish(odd, "the three-frame shard");
    assert!(
        logs[1].contains("shard 1/3") && logs[1].contains("SLURM_ARRAY_TASK_ID=1"),
        "{}",
        logs[1]
    );
    // Three techniques on two scenes over three shards: two each, none twice.
    let mut all: Vec<String> = dirs.iter().flat_map(|d| results_files(d)).collect();
    for d in &dirs {
        assert_eq!(results_files(d).len(), 2, "{d:?}: {:?}", results_files(d));
    }
    all.sort();
    assert_eq!(all, results_files(&single));
    let merged = tmp.path().join("merged");
    let (ok, stderr) = merge(&dirs, &merged);
    assert!(ok, "merge failed: {stderr}");
    assert_eq!(results_files(&merged), results_files(&single));
    for f in results_files(&single) {
        let read = |d: &Path| -> serde_json::Value {
            serde_json::from_slice(&std::fs::read(d.join(&f)).unwrap()).unwrap()
        };
        assert_eq!(
            untimed(&read(&single)),
            untimed(&read(&merged)),
            "{f} differs beyond its timings"
        );
    }
    for f in [
        "cornell-summary.md",
        "cornell-summary.csv",
        "cornell-summary.tex",
        "cornell-omni-summary.md",
    ] {
        let read = |d: &Path| std::fs::read_to_string(d.join(f)).unwrap();
        assert_eq!(
            shape(&read(&single)),
            shape(&read(&merged)),
            "{f} differs beyond its numbers"
        );
    }
    assert!(merged.join("cornell-summary.svg").is_file());
    assert!(merged.join("cornell-omni-summary.svg").is_file());
    // The shards ran with --html: the merged set has each scene's page, of every shard's runs.
    for scene in ["cornell", "cornell-omni"] {
        let page = std::fs::read_to_string(merged.join(format!("{scene}-report.html")))
            .unwrap_or_else(|e| panic!("no merged {scene} page: {e}"));
        for t in techniques.split(',') {
            assert!(
                page.contains(&format!("<summary>{t} on {scene}, ")),
                "the merged {scene} page lacks {t}"
            );
        }
    }
    // Refused by name, nothing written.
    let dup = tmp.path().join("dup");
    std::fs::create_dir_all(&dup).unwrap();
    for f in std::fs::read_dir(&dirs[1]).unwrap().flatten() {
        if f.file_type().unwrap().is_file() {
            std::fs::copy(f.path(), dup.join(f.file_name())).unwrap();
        }
    }
    let record = std::fs::read_to_string(dup.join("gibench-shard.json")).unwrap();
    std::fs::write(
        dup.join("gibench-shard.json"),
        record.replace("\"1/3\"", "\"2/3\""),
    )
    .unwrap();
    let plain = tmp.path().join("plain");
    fake(&plain, "quick", "abc", &["keller-tiles"]);
    let (s0, s1, s2) = (dirs[0].clone(), dirs[1].clone(), dirs[2].clone());
    for (set, expect) in [
        (vec![s0.clone(), s0.clone(), s1.clone()], "both shard 0/3"),
        (vec![s0.clone(), s1.clone()], "shard 2/3 is missing"),
        (vec![s0.clone(), s1.clone(), dup], "ran in both"),
        (vec![s0.clone(), s1.clone(), other], "frames differs"),
        (vec![s0, s1, s2, plain], "all of one kind"),
    ] {
        let out = tmp.path().join("bad-merge");
        let (ok, stderr) = merge(&set, &out);
        assert!(!ok && stderr.contains(expect), "{set:?}: {stderr}");
        assert!(!out.exists(), "a refused merge wrote {out:?}");
    }
}
