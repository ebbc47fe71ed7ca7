//! `report`, `compare` and `plot-quality` on results files they must refuse: runs compared
//! with themselves, a file counted twice, impossible values, nothing per frame to plot.

use super::*;

/// `compare` refuses runs compared with themselves: the same folder twice, the same files on
/// both sides (nested folders), byte-identical copies on both sides or within one.
#[test]
fn compare_refuses_runs_compared_with_themselves() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    copy_baseline(&dir.join("a"));
    copy_baseline(&dir.join("copy"));
    let cmp = |base: &str, current: &str, expect: &[&str]| {
        command_fails(dir, &[], &["compare", base, current, "--out", "o"], expect);
    };
    cmp(
        "a",
        "a",
        &["parameter 'current'", "the same folder as BASE"],
    );
    cmp("a", "a/r1", &["the same file as"]);
    cmp("a", "copy", &["a byte-identical copy of", "in BASE"]);
    // CURRENT made distinct from BASE (a trailing newline), then one repeat copied over another.
    for e in std::fs::read_dir(dir.join("copy")).unwrap() {
        for f in std::fs::read_dir(e.unwrap().path()).unwrap() {
            let f = f.unwrap().path();
            let mut bytes = std::fs::read(&f).unwrap();
            bytes.push(b'\n');
            std::fs::write(&f, bytes).unwrap();
        }
    }
    std::fs::copy(
        dir.join("copy/r1/cornell-direct.json"),
        dir.join("copy/r2/cornell-direct.json"),
    )
    .unwrap();
    cmp("a", "copy", &["a byte-identical copy of", "in CURRENT;"]);
    assert!(!dir.join("o").exists());
}

/// `report` and `plot-quality` refuse a results file reached twice (`F F`, `DIR DIR/F`)
/// instead of counting its run twice.
#[test]
fn report_and_plot_quality_count_each_file_once() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    copy_baseline(dir);
    let f = "r1/cornell-direct.json";
    for args in [
        ["report", f, f],
        ["report", "r1", "./r1/cornell-direct.json"],
        ["plot-quality", f, f],
    ] {
        let mut args = args.to_vec();
        args.extend(["--out", "o"]);
        command_fails(dir, &[], &args, &["cornell-direct.json", "given twice"]);
    }
    assert!(!dir.join("o").exists());
}

/// `plot-quality` on results without per-frame values names its inputs and says how to make
/// them; a bad `--out` is named; its help lists every metric it takes.
#[test]
fn plot_quality_inputs_out_and_metrics() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    copy_baseline(dir);
    let err = command_fails(
        dir,
        &[],
        &[
            "plot-quality",
            "r1/cornell-direct.json",
            "--out",
            "pq/one.svg",
        ],
        &["r1/cornell-direct.json", "run --quality --quality-all"],
    );
    assert!(!err.contains("one.svg"), "{err}");
    command_fails(
        dir,
        &[],
        &["plot-quality", "r1", "--out", "pq/x.svg"],
        &["r1: no results hold per-frame quality values"],
    );
    command_fails(
        dir,
        &[],
        &["plot-quality", "r1", "--out", "r2"],
        &["parameter 'out'", "is a folder"],
    );
    command_fails(
        dir,
        &[],
        &["plot-quality", "r1", "--out", "r1/cornell-ism.json/x.svg"],
        &["parameter 'out'", "is a file, not a folder"],
    );
    let err = command_fails(
        dir,
        &[],
        &["plot-quality", "r1", "--metric", "nope"],
        &["parameter 'metric'"],
    );
    let help = support::GIBENCH
        .command()
        .args(["plot-quality", "--help"])
        .output()
        .unwrap();
    let help = String::from_utf8_lossy(&help.stdout);
    let listed = err.split("expected ").nth(1).unwrap().split(" (got").next();
    for metric in listed
        .unwrap()
        .split([',', ' '])
        .filter(|m| !m.is_empty() && *m != "or")
    {
        assert!(help.contains(metric), "--help lacks '{metric}':\n{help}");
    }
    assert!(!dir.join("pq").exists());
}

/// A results file that parses but would print wrong tables is refused by `report`, naming the
/// file and the field: a negative time, an empty technique name, a stage listed twice (its
/// time would count twice in Σ).
#[test]
fn results_files_with_impossible_values_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    copy_baseline(dir);
    let file = dir.join("r1/cornell-keller-full.json");
    let good = std::fs::read(&file).unwrap();
    type Edit = (
        &'static str,
        fn(&mut serde_json::Value),
        &'static [&'static str],
    );
    let edits: [Edit; 3] = [
        (
            "negative",
            |v| v["stages"][0]["wall_ms"]["median"] = serde_json::json!(-5.0),
            &["wall_ms.median is -5", "not negative"],
        ),
        (
            "unnamed",
            |v| v["technique"] = serde_json::json!(""),
            &["'technique' is empty"],
        ),
        (
            "repeated",
            |v| {
                let first = v["stages"][0].clone();
                v["stages"].as_array_mut().unwrap().push(first);
            },
            &["listed twice"],
        ),
    ];
    for (what, edit, expect) in edits {
        let mut v: serde_json::Value = serde_json::from_slice(&good).unwrap();
        edit(&mut v);
        std::fs::write(&file, serde_json::to_vec(&v).unwrap()).unwrap();
        let mut all = vec!["cornell-keller-full.json"];
        all.extend(expect);
        let err = command_fails(dir, &[], &["report", "r1", "--out", "o"], &all);
        assert!(!dir.join("o").exists(), "{what}: {err}");
    }
}
