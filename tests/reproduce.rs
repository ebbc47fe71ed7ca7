//! `gibench reproduce` writes the paper tables with every column of the paper's and the
//! paper's figures beside ours, and its numbers say what the paper's say where a CPU adapter
//! must agree (a small run: Cornell only, a few frames).

use std::process::Command;

fn reproduce(target: &str, out: &std::path::Path) {
    let o = Command::new(env!("CARGO_BIN_EXE_gibench"))
        .args([
            "reproduce",
            target,
            "--quick",
            "--scenes",
            "cornell",
            "--frames",
            "4",
            "--out",
        ])
        .arg(out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
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
    // Our numbers: `laine` renders a few new maps per frame where `keller-full` renders all 256,
    // so its shadow-map time is far lower and its frame rate higher; Table 2's Σ common is the
    // sum of its four steps.
    let row1 = gibench_row(&tmp.path().join("laine-table1.csv"));
    assert!(
        row1["SM comp."] > 3.0 * row1["SM ours"],
        "SM ours {} vs SM comp. {}",
        row1["SM ours"],
        row1["SM comp."]
    );
    assert!(row1["speedup frame"] > 1.0, "{row1:?}");
    assert!((row1["FPS ours"] / row1["FPS comp."] - row1["speedup frame"]).abs() < 0.2);
    let row2 = gibench_row(&tmp.path().join("laine-table2.csv"));
    let steps = row2["split"] + row2["accum."] + row2["combine"] + row2["filter"];
    assert!((steps - row2["Σ common"]).abs() < 1e-3 * steps, "{row2:?}");
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
    let median = |key: &str| v["per_frame_ms"][key]["median"].as_f64().unwrap();
    for light in ["spot", "omni"] {
        // Four times the VPLs is more work per frame (Delaunay updates, rays, Voronoi areas).
        assert!(
            median(&format!("{light}-1024")) > median(&format!("{light}-256")),
            "{light}: 1024 VPLs not dearer than 256"
        );
        assert!(median(&format!("{light}-256")) > 0.0);
    }
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
