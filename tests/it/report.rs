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

/// `pdflatex` (TeX Live; `.ci/run` installs it); `None` only when the user skips LaTeX checks
/// knowingly with `GIBENCH_NO_LATEX=1`.
fn pdflatex() -> Option<PathBuf> {
    let found = std::env::var_os("PATH").and_then(|path| {
        std::env::split_paths(&path)
            .map(|d| d.join("pdflatex"))
            .find(|p| p.is_file())
    });
    if found.is_none() && std::env::var_os("GIBENCH_NO_LATEX").is_some_and(|v| v == "1") {
        eprintln!(
            "SKIPPED: pdflatex is missing and GIBENCH_NO_LATEX=1: the LaTeX table was not compiled"
        );
        return None;
    }
    Some(found.expect(
        "pdflatex is missing: the LaTeX tables are compiled in a test. Install TeX Live \
         (Debian: apt-get install texlive-latex-recommended); GIBENCH_NO_LATEX=1 skips it knowingly",
    ))
}

/// `report --format latex --columns frame,relmse,flip,sum` over committed quality runs (Laine's
/// clamp sweep on Sibenik against one-bounce, gaitatzes' modes against multi-bounce) writes only
/// the `.tex`, with the identifying columns (scene, technique, resolution, and the setting that
/// tells a technique's runs apart), then exactly those asked for (`relmse`: against each
/// component); it compiles with pdflatex in
/// a document with booktabs. An unknown column is refused by name, listing those there are,
/// and nothing is written. Catches a table with every column, rows that read the same (no
/// setting), and a header LaTeX cannot set ("Σ stages" unescaped fails it: tried).
#[test]
fn latex_with_chosen_columns_compiles() {
    let Some(pdflatex) = pdflatex() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("results");
    let runs = tmp.path().join("runs");
    std::fs::create_dir_all(&runs).unwrap();
    for f in [
        "clamp/sibenik-laine/sibenik-laine-clamp-1.json",
        "clamp/sibenik-laine/sibenik-laine-clamp-30.json",
        "gaitatzes/quality/runs/gaitatzes-room-gaitatzes-pyramid-256x192.json",
        "gaitatzes/quality/runs/gaitatzes-room-gaitatzes-256x192.json",
    ] {
        let p = root.join(f);
        std::fs::copy(&p, runs.join(p.file_name().unwrap())).unwrap();
    }
    let out = tmp.path().join("out");
    let report = |columns: &str| {
        support::GIBENCH.run(&[
            "report".as_ref(),
            runs.as_os_str(),
            "--format".as_ref(),
            "latex".as_ref(),
            "--columns".as_ref(),
            columns.as_ref(),
            "--stem".as_ref(),
            "t".as_ref(),
            "--out".as_ref(),
            out.as_os_str(),
        ])
    };
    let o = report("frame,nonsense");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        stderr.contains("parameter 'columns'")
            && stderr.contains("'nonsense'")
            && stderr.contains("relmse"),
        "{stderr}"
    );
    assert!(!out.join("t.tex").exists());
    let o = report("frame,relmse,flip,sum");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!out.join("t.md").exists() && !out.join("t.csv").exists());
    let tex = std::fs::read_to_string(out.join("t.tex")).unwrap();
    assert!(
        tex.contains(
            "scene & technique & resolution & setting & frame (median ms) & relMSE one-bounce & \
             relMSE multi-bounce & FLIP one-bounce & FLIP multi-bounce & $\\Sigma$ stages \\\\"
        ),
        "{tex}"
    );
    assert!(
        tex.contains("clamp=30") && tex.contains("transport=pyramid"),
        "{tex}"
    );
    std::fs::write(
        out.join("doc.tex"),
        "\\documentclass{article}\n\\usepackage{booktabs}\n\\begin{document}\n\\input{t.tex}\n\\end{document}\n",
    )
    .unwrap();
    let o = std::process::Command::new(pdflatex)
        .args(["-interaction=nonstopmode", "-halt-on-error", "doc.tex"])
        .current_dir(&out)
        .output()
        .unwrap();
    assert!(
        o.status.success() && out.join("doc.pdf").is_file(),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
}
