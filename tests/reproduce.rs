//! `gibench reproduce` writes the paper tables with every column of the paper's and the
//! paper's figures beside ours (a small smoke run: Cornell only, two frames).

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
            "2",
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
    assert!(t1.contains("Laine et al. 2007, Table 1 (GeForce 8800 GTX) | CORNELL | 1024x768 | 4.4 | 1.1 | 12.1 | 0.7 | 30.8"), "{t1}");
    assert!(t1.contains("| gibench | cornell | 256x192 |"), "{t1}");
    let t2 = std::fs::read_to_string(tmp.path().join("laine-table2.md")).unwrap();
    for col in ["split", "accum.", "combine", "filter", "Σ common"] {
        assert!(t2.contains(col), "table 2 lacks '{col}'");
    }
    assert!(t2.contains("| 2.1 | 5.7 | 0.7 | 3.6 | 12.1 |"), "{t2}");
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
    for key in ["spot-256", "spot-1024", "omni-256", "omni-1024"] {
        let s = &v["per_frame_ms"][key];
        assert!(
            s["median"].as_f64().unwrap() > 0.0
                && s["p99"].as_f64().unwrap() >= s["median"].as_f64().unwrap(),
            "{key}"
        );
    }
}
