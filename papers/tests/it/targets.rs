//! The paper targets, run in this process through the library (no binary spawned): each writes
//! its paper's tables with every column of the paper's and the paper's figures beside ours,
//! and its numbers say what the paper's say where a CPU adapter must agree (a small run:
//! Cornell only, a few frames).

use gibench_papers::reproduce::{exec, ReproduceArgs};

/// One reproduction at a time: a process has one output set open at a time (the harness's
/// `output` module refuses a second), so the tests of this module take turns.
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Runs `gibench reproduce TARGET --quick --scenes SCENE --frames N --quiet --out OUT` through
/// the library.
fn reproduce_in(target: &str, scene: &str, frames: u32, out: &std::path::Path) {
    let _turn = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let frames = frames.to_string();
    let out = out.to_str().unwrap();
    #[rustfmt::skip]
    let words = [target, "--quick", "--scenes", scene, "--frames", &frames, "--quiet", "--out", out];
    let args = ReproduceArgs::parse_words(&words).unwrap();
    exec(&args).unwrap();
}

fn reproduce(target: &str, out: &std::path::Path) {
    reproduce_in(target, "cornell", 4, out);
}

#[test]
fn laine_tables_have_the_papers_columns_and_figures() {
    let tmp = tempfile::tempdir().unwrap();
    reproduce("laine-tables", tmp.path());
    let t1 = std::fs::read_to_string(tmp.path().join("laine-table1.md")).unwrap();
    for col in [
        "direct SM+PCF",
        "G-buffer",
        "Σ common",
        "SM ours",
        "SM comp.",
        "FPS comp.",
        "FPS ours",
        "speedup indirect",
        "speedup frame",
    ] {
        assert!(t1.contains(col), "table 1 lacks '{col}'");
    }
    // The paper's Cornell row at 1024x768, labelled with its source.
    assert!(t1.contains("Laine et al. 2007, Table 1 (GeForce 8800 GTX) | CORNELL | 1024x768 | ≤ 256 | 256 | 4.4 | 1.1 | 12.1 | 0.7 | 30.8"), "{t1}");
    assert!(t1.contains("| gibench | cornell | 256x192 |"), "{t1}");
    let t2 = std::fs::read_to_string(tmp.path().join("laine-table2.md")).unwrap();
    for col in ["split", "accum.", "combine", "filter", "Σ common"] {
        assert!(t2.contains(col), "table 2 lacks '{col}'");
    }
    assert!(t2.contains("| 2.1 | 5.7 | 0.7 | 3.6 | 12.1 |"), "{t2}");
    // Our runs: `laine` renders a few new maps per frame where `keller-full` renders all 256
    // (the work behind the paper's speedup; counted, not timed: timings are the benchmark's);
    // the speedup column is the FPS ratio; Table 2's Σ common is the sum of its four steps.
    let run = |technique: &str| -> serde_json::Value {
        serde_json::from_slice(
            &std::fs::read(
                tmp.path()
                    .join(format!("runs/cornell-{technique}-256x192.json")),
            )
            .unwrap(),
        )
        .unwrap()
    };
    let maps = |technique: &str| {
        run(technique)["counters"]["shadow-maps"]["mean"]
            .as_f64()
            .unwrap()
    };
    assert!(maps("keller-full") >= 250.0, "{}", maps("keller-full"));
    assert!(maps("laine") <= 16.0, "{}", maps("laine"));
    // The speedup column is the ratio of the runs' unrounded FPS, printed to one decimal (the
    // table's FPS columns are rounded too, so their ratio can be off by more than that).
    let fps = |technique: &str| run(technique)["frame"]["fps"].as_f64().unwrap();
    let row1 = gibench_row(&tmp.path().join("laine-table1.csv"));
    let speedup = fps("laine") / fps("keller-full");
    assert!(
        (speedup - row1["speedup frame"]).abs() <= 0.05 + 1e-9,
        "{speedup} printed as {}",
        row1["speedup frame"]
    );
    let row2 = gibench_row(&tmp.path().join("laine-table2.csv"));
    let steps = row2["split"] + row2["accum."] + row2["combine"] + row2["filter"];
    // Five values written to four decimals: their rounding adds up to at most 2.5e-4 ms.
    assert!(
        (steps - row2["Σ common"]).abs() <= 2.5e-4 + 1e-9,
        "{row2:?}"
    );
    assert_eq!(row1["Σ common"], row2["Σ common"]);
    for f in [
        "laine-table1.csv",
        "laine-table1.tex",
        "laine-table2.csv",
        "laine-table2.tex",
    ] {
        assert!(tmp.path().join(f).is_file(), "{f}");
    }
}

#[test]
fn laine_management_records_spot_and_omni_at_256_and_1024() {
    let tmp = tempfile::tempdir().unwrap();
    reproduce("laine-management", tmp.path());
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(tmp.path().join("laine-management.json")).unwrap())
            .unwrap();
    // Statistics of every frame after the fill frame (wall and CPU time) over the passes, each
    // pass's median, and the fill frame, for each light and VPL count. (Which is dearer is a
    // benchmark's question: on a loaded machine four frames can say either.)
    let passes = v["passes"].as_u64().unwrap();
    assert!(passes >= 2, "{v}");
    for light in ["spot", "omni"] {
        for vpls in [256, 1024] {
            let rec = &v["per_frame_ms"][format!("{light}-{vpls}")];
            for clock in ["wall_ms", "cpu_ms"] {
                let stats = &rec[clock];
                let get = |k: &str| stats[k].as_f64().unwrap_or(f64::NAN);
                assert_eq!(
                    stats["count"].as_u64(),
                    Some(4 * passes),
                    "{light}-{vpls}: {rec}"
                );
                assert!(get("median") > 0.0, "{light}-{vpls}: {rec}");
            }
            // One median per pass, the pooled median between the lowest and the highest.
            let medians: Vec<f64> = (rec["pass_median_wall_ms"].as_array().unwrap())
                .iter()
                .map(|m| m.as_f64().unwrap())
                .collect();
            assert_eq!(medians.len() as u64, passes, "{rec}");
            let pooled = rec["wall_ms"]["median"].as_f64().unwrap();
            let lo = medians.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = medians.iter().copied().fold(0.0, f64::max);
            assert!(lo <= pooled && pooled <= hi, "{rec}");
            assert!(
                rec["fill_frame_wall_ms"].as_f64().unwrap_or(0.0) > 0.0,
                "{rec}"
            );
            // The VPLs each timed frame managed: at most `vpls`, and most of them (the spot
            // light's count drains as its rim points are invalidated: about 0.8 of the slots on
            // the Cornell box after four frames; a sampling point whose ray misses makes no
            // VPL), so each row times the VPL count it names.
            let used = &rec["vpls_used"];
            let (mean, min) = (
                used["mean"].as_f64().unwrap(),
                used["min"].as_f64().unwrap(),
            );
            assert_eq!(used["count"].as_u64(), Some(4 * passes), "{rec}");
            // How the triangulation followed the points: frames rebuilt from scratch (at most
            // the timed ones) and sites repaired per frame.
            assert!(
                rec["frames_rebuilt"]
                    .as_u64()
                    .is_some_and(|n| n <= 4 * passes),
                "{rec}"
            );
            let repaired = rec["sites_repaired_per_frame"].as_f64().unwrap_or(f64::NAN);
            assert!(repaired >= 0.0 && repaired <= vpls as f64, "{rec}");
            // The step's parts, each over the same frames; per frame they lie inside the step,
            // so their means add up to at most the step's mean wall time.
            let parts = &rec["part_wall_ms"];
            let mut sum = 0.0;
            for name in gibench_laine::StepTimes::NAMES {
                assert_eq!(
                    parts[name]["count"].as_u64(),
                    Some(4 * passes),
                    "{light}-{vpls} {name}: {rec}"
                );
                sum += parts[name]["mean"].as_f64().unwrap_or(f64::NAN);
            }
            let wall = rec["wall_ms"]["mean"].as_f64().unwrap();
            assert!(
                sum > 0.0 && sum <= wall * (1.0 + 1e-9),
                "{light}-{vpls}: {rec}"
            );
            assert!(
                mean <= vpls as f64 && min >= 0.6 * vpls as f64,
                "{light}-{vpls}: {used}"
            );
        }
    }
    assert_eq!(v["frames"].as_u64(), Some(4));
}

#[test]
fn ism_breakdown_has_the_stages_the_published_figures_and_the_ratios() {
    let tmp = tempfile::tempdir().unwrap();
    reproduce("ism-breakdown", tmp.path());
    let md = std::fs::read_to_string(tmp.path().join("ism-breakdown.md")).unwrap();
    for col in [
        "RSM",
        "VPL sampling",
        "VPL maps",
        "point splat",
        "pull-push",
        "gathering",
        "filter",
        "FPS",
        "maps ÷ ISM maps",
        "FPS ism ÷ FPS",
    ] {
        assert!(md.contains(col), "the breakdown lacks '{col}'");
    }
    // The published figures, from results/papers/ism2008.json, labelled with their sources.
    assert!(md.contains("| Ritschel et al. 2008, course slides (NVIDIA GeForce 8800 GTX, 2008) | ISM | Christo's Sponza (70k) | not stated | 1024 | 256² | 8192 |"), "{md}");
    assert!(
        md.contains("| 440–660 |")
            && md.contains("| 10–15 |")
            && md.contains("| ~10 |")
            && md.contains("| > 11 |"),
        "{md}"
    );
    assert!(
        md.contains("| Linke, master's thesis (GTX 980 at base clock) |")
            && md.contains("| 0.39 + 0.85 |")
            && md.contains("| 2.70 |"),
        "{md}"
    );
    // Our three rows at equal terms, their maps counted, and the ratios computed from the
    // rows' own columns.
    let rows = technique_rows(&tmp.path().join("ism-breakdown.csv"));
    let num = |t: &str, c: &str| -> f64 { rows[t][c].parse().unwrap_or(f64::NAN) };
    for t in ["ism", "ism-classic", "keller-full"] {
        assert_eq!(rows[t]["VPLs (mean / min)"], "256.0 / 256", "{t}");
        let r: serde_json::Value = serde_json::from_slice(
            &std::fs::read(tmp.path().join(format!("runs/cornell-{t}-256x192.json"))).unwrap(),
        )
        .unwrap();
        assert_eq!(
            r["counters"]["shadow-maps"]["mean"].as_f64(),
            Some(256.0),
            "{t}"
        );
    }
    let ism_maps = num("ism", "VPL maps");
    // (The CSV rounds milliseconds to 4 decimals, ratios to 2, FPS to 1.)
    assert!((num("ism", "point splat") + num("ism", "pull-push") - ism_maps).abs() <= 2e-4);
    for t in ["ism-classic", "keller-full"] {
        let ratio = num(t, "VPL maps") / ism_maps;
        assert!(
            (num(t, "maps ÷ ISM maps") - ratio).abs() <= 0.006,
            "{t}: {ratio}"
        );
        let fps = num("ism", "FPS") / num(t, "FPS");
        let spread = fps * (0.05 / num("ism", "FPS") + 0.05 / num(t, "FPS")) + 0.006;
        assert!(
            (num(t, "FPS ism ÷ FPS") - fps).abs() <= spread,
            "{t}: {fps}"
        );
    }
    assert!(rows["ism"]["maps ÷ ISM maps"].is_empty());
    for f in ["ism-breakdown.csv", "ism-breakdown.tex"] {
        assert!(tmp.path().join(f).is_file(), "{f}");
    }
}

#[test]
fn gaitatzes_table1_has_the_papers_rows_and_the_scaling_figure() {
    let tmp = tempfile::tempdir().unwrap();
    reproduce_in("gaitatzes-table1", "gaitatzes-test", 2, tmp.path());
    let md = std::fs::read_to_string(tmp.path().join("gaitatzes-table1.md")).unwrap();
    for col in [
        "triangles",
        "grid",
        "iterations",
        "voxelization",
        "propagation",
        "total (frame)",
    ] {
        assert!(md.contains(col), "the table lacks '{col}'");
    }
    // The paper's row for the test scene, from results/papers/gaitatzes2010.json, and ours at
    // the paper's grid and iteration count with the scene's triangle count.
    assert!(
        md.contains("| Gaitatzes et al. 2010, Table 1 (NVIDIA GeForce GTX 285, 2010) | test scene | 48 | 32³ | 11 | 10.00 | 12.00 | – | 22.00 |"),
        "{md}"
    );
    assert!(
        md.contains("| gibench | gaitatzes-test | 48 | 32³ | 11 |"),
        "{md}"
    );
    let r: serde_json::Value = serde_json::from_slice(
        &std::fs::read(
            tmp.path()
                .join("runs/gaitatzes-test-gaitatzes-256x192.json"),
        )
        .unwrap(),
    )
    .unwrap();
    assert_eq!(r["counters"]["iterations"]["mean"].as_f64(), Some(11.0));
    assert_eq!(r["counters"]["grid"]["mean"].as_f64(), Some(32.0));
    let svg = std::fs::read_to_string(tmp.path().join("gaitatzes-scaling.svg")).unwrap();
    assert!(svg.contains("<svg") && svg.contains("propagation per iteration"));
    for f in ["gaitatzes-table1.csv", "gaitatzes-table1.tex"] {
        assert!(tmp.path().join(f).is_file(), "{f}");
    }
}

/// The `gibench` rows of a table's CSV by their `technique` column, as column name → text.
fn technique_rows(
    csv: &std::path::Path,
) -> std::collections::HashMap<String, std::collections::HashMap<String, String>> {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    lines
        .filter(|l| l.starts_with("gibench,"))
        .map(|l| {
            let row: std::collections::HashMap<String, String> = header
                .iter()
                .zip(l.split(','))
                .map(|(h, v)| (h.to_string(), v.to_string()))
                .collect();
            (row["technique"].clone(), row)
        })
        .collect()
}

/// The first `gibench` row of a table's CSV, as column name → number.
fn gibench_row(csv: &std::path::Path) -> std::collections::HashMap<String, f64> {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let row = lines.find(|l| l.starts_with("gibench,")).unwrap();
    header
        .iter()
        .zip(row.split(','))
        .filter_map(|(h, v)| v.parse::<f64>().ok().map(|v| (h.to_string(), v)))
        .collect()
}
