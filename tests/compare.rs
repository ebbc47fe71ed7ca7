//! `gibench compare` on real runs: three repeats of `direct` each for BASE, SAME (the same
//! build) and SLOW (the same build with 3 ms added to `compose`'s recorded times through the
//! test hook `GIBENCH_TEST_SLOW_STAGE`, which leaves the other stages' execution untouched),
//! run alternating. SAME against BASE is "unchanged" for every stage; SLOW against BASE is
//! "slower" for `compose` and for nothing else, and SLOW's results carry the hook's warning.
//! Two repeats are refused.

use std::path::Path;
use std::process::Command;

fn run_into(out: &Path, slow: bool) {
    let mut c = Command::new(env!("CARGO_BIN_EXE_gibench"));
    c.args([
        "run",
        "--technique",
        "direct",
        "--frames",
        "30",
        "--warmup",
        "3",
    ])
    .args([
        "--timing",
        "stages",
        "--resolution",
        "96x72",
        "--quiet",
        "--no-images",
    ])
    .arg("--out")
    .arg(out);
    if slow {
        c.env("GIBENCH_TEST_SLOW_STAGE", "compose:3");
    } else {
        c.env_remove("GIBENCH_TEST_SLOW_STAGE");
    }
    let o = c.output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn compare(dir: &Path, base: &str, current: &str) -> (bool, serde_json::Value, String) {
    let out = dir.join(format!("cmp-{current}"));
    let o = Command::new(env!("CARGO_BIN_EXE_gibench"))
        .arg("compare")
        .arg(dir.join(base))
        .arg(dir.join(current))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
    let json = std::fs::read(out.join("compare.json"))
        .ok()
        .and_then(|b| serde_json::from_slice(&b).ok())
        .unwrap_or(serde_json::Value::Null);
    (o.status.success(), json, stderr)
}

#[test]
fn compare_finds_the_slowed_stage_and_only_it() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    for i in 0..3 {
        run_into(&dir.join(format!("base/r{i}")), false);
        run_into(&dir.join(format!("same/r{i}")), false);
        run_into(&dir.join(format!("slow/r{i}")), true);
    }
    let verdicts = |json: &serde_json::Value| -> Vec<(String, String)> {
        json.as_array()
            .unwrap()
            .iter()
            .map(|r| {
                (
                    r["stage"].as_str().unwrap().to_string(),
                    r["verdict"].as_str().unwrap().to_string(),
                )
            })
            .collect()
    };
    let (ok, same, stderr) = compare(dir, "base", "same");
    assert!(ok, "{stderr}");
    let same = verdicts(&same);
    assert_eq!(same.len(), 4, "{same:?}");
    assert!(same.iter().all(|(_, v)| v == "unchanged"), "{same:?}");
    let (ok, slow, stderr) = compare(dir, "base", "slow");
    assert!(ok, "{stderr}");
    for (stage, verdict) in verdicts(&slow) {
        let want = if stage == "compose" {
            "slower"
        } else {
            "unchanged"
        };
        assert_eq!(verdict, want, "{stage}");
    }
    let warned = |side: &str| {
        let f = std::fs::read_dir(dir.join(side).join("r0"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| p.extension().is_some_and(|e| e == "json"))
            .unwrap();
        let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&f).unwrap()).unwrap();
        v["warnings"].as_array().is_some_and(|w| {
            w.iter()
                .any(|w| w.as_str().unwrap().contains("GIBENCH_TEST_SLOW_STAGE"))
        })
    };
    assert!(warned("slow") && !warned("base"));
    std::fs::remove_dir_all(dir.join("same/r2")).unwrap();
    let (ok, _, stderr) = compare(dir, "base", "same");
    assert!(
        !ok && stderr.contains("CURRENT has 2 repeat(s) of cornell/direct/96x72"),
        "{stderr}"
    );
}
