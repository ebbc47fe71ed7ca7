//! `gibench report` over results from several devices: `--speedup`.

use crate::support;

use std::path::{Path, PathBuf};

use serde_json::Value;

/// The committed baseline's first repeat, copied to `to` with its adapter renamed and every
/// stage and frame time divided by `faster` when `rename` is given.
fn copy_runs(to: &Path, rename: Option<(&str, f64)>) {
    let from = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("results/baseline/r1");
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "json") {
            continue;
        }
        let mut v: Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
        if let Some((adapter, faster)) = rename {
            v["device"]["adapter"] = adapter.into();
            let scale = |stats: &mut Value| {
                if let Some(o) = stats.as_object_mut() {
                    for (k, x) in o.iter_mut() {
                        if k != "count" {
                            *x = (x.as_f64().unwrap() / faster).into();
                        }
                    }
                }
            };
            for s in v["stages"].as_array_mut().unwrap() {
                for clock in ["gpu_ms", "wall_ms"] {
                    scale(&mut s[clock]);
                }
            }
            if v["frame"].is_object() {
                scale(&mut v["frame"]["frame_ms"]);
            }
        }
        std::fs::write(
            to.join(p.file_name().unwrap()),
            serde_json::to_vec(&v).unwrap(),
        )
        .unwrap();
    }
}

/// Catches: a speedup taken the wrong way round (device over reference), runs of different
/// settings matched, a device left unnamed, and `--speedup` over one device passing silently.
/// Two devices' copies of the same runs, the second twice as fast: every stage's speedup is
/// 2.00 and the table names both devices; from one device, an error naming `speedup` and no
/// folder written.
#[test]
fn speedup_gives_each_stage_the_ratio_between_two_devices() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    copy_runs(&a, None);
    copy_runs(&b, Some(("Other GPU 9000", 2.0)));
    let out = tmp.path().join("out");
    let o = support::GIBENCH
        .command()
        .args(["report", "--speedup", "--out"])
        .arg(&out)
        .arg(&a)
        .arg(&b)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    let md = std::fs::read_to_string(out.join("report-speedup.md")).unwrap();
    assert!(md.contains("Speedup against llvmpipe"), "{md}");
    let rows: Vec<&str> = md.lines().filter(|l| l.starts_with("| cornell/")).collect();
    assert!(rows.len() > 20, "{md}");
    for row in &rows {
        assert!(row.contains("Other GPU 9000"), "{row}");
        let speedup = row.trim_end_matches(" |").rsplit("| ").next().unwrap();
        assert!(speedup == "2.00" || speedup == "–", "{row}");
    }
    assert!(rows.iter().any(|r| r.contains("| frame |")), "{md}");
    let lone = tmp.path().join("lone");
    let o = support::GIBENCH
        .command()
        .args(["report", "--speedup", "--out"])
        .arg(&lone)
        .arg(&a)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success()
            && stderr.contains("parameter 'speedup'")
            && stderr.contains("two devices"),
        "{stderr}"
    );
    assert!(!lone.exists());
}
