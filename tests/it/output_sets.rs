//! A command's files appear in `--out` complete or not at all (`gibench_harness::output`): runs
//! killed at several points leave the folder as it was, a later command clears what they left
//! (staging folder, lock, temporary cache files), and a second command into a folder in use is
//! refused.

use crate::support;

use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn gibench() -> Command {
    let mut c = support::GIBENCH.command();
    c.stdout(Stdio::null()).stderr(Stdio::piped());
    c
}

const SMALL: [&str; 8] = [
    "--resolution",
    "64x48",
    "--frames",
    "4",
    "--warmup",
    "3",
    "--shadow-size",
    "64",
];

/// A small `direct` run into `out`.
fn small_direct(out: &Path) -> std::process::Output {
    gibench()
        .args(["run", "--technique", "direct", "--quiet"])
        .args(SMALL)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap()
}

/// `gibench ARGS` at the small size into `out`, which must succeed.
fn small_ok(args: &[&str], out: &Path) {
    let o = gibench()
        .args(args)
        .args(SMALL)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Every file under `dir` (relative path → bytes), hidden ones too.
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().to_string_lossy().into_owned();
                out.insert(rel, std::fs::read(&p).unwrap_or_default());
            }
        }
    }
    out
}

/// Every results JSON in `dir` names images that exist: complete sets only.
fn complete_sets(dir: &Path) {
    for (name, bytes) in files(dir) {
        if name.ends_with(".json") && !name.starts_with('.') {
            let v: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
            for img in v["images"].as_array().into_iter().flatten() {
                let img = img.as_str().unwrap();
                assert!(
                    dir.join(img).exists(),
                    "{name} names {img}, which is missing"
                );
            }
        }
    }
}

fn spawn_long(out: &Path, cache: &Path) -> Child {
    gibench()
        .args([
            "run",
            "--technique",
            "direct,keller-full,laine",
            "--quality",
        ])
        .args(["--spp", "4", "--quiet", "--timing", "stages"])
        .args(SMALL)
        .arg("--out")
        .arg(out)
        .arg("--cache")
        .arg(cache)
        .spawn()
        .unwrap()
}

#[test]
fn killed_runs_leave_only_complete_sets() {
    let tmp = tempfile::tempdir().unwrap();
    let (out, cache) = (tmp.path().join("out"), tmp.path().join("cache"));
    // A complete earlier run: a killed one must leave it exactly as it was.
    let o = small_direct(&out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let before = files(&out);
    assert!(before.keys().any(|k| k.ends_with("cornell-direct.json")));
    assert!(!before.keys().any(|k| k.starts_with('.')), "{before:?}");
    for delay_ms in [150, 600, 1500, 3000] {
        let mut child = spawn_long(&out, &cache);
        std::thread::sleep(Duration::from_millis(delay_ms));
        let _ = child.kill();
        // Exited by itself (the kill came too late) or killed.
        let finished = child.wait().unwrap().success();
        let visible: BTreeMap<_, _> = files(&out)
            .into_iter()
            .filter(|(k, _)| !k.starts_with('.'))
            .collect();
        // Killed while moving its files into place (the journal is left: the next command
        // finishes the move, checked below) or after it had published them all (before it
        // exited: every run's results are there, complete).
        let publishing = out.join(".gibench-publish").exists();
        let published = !publishing
            && ["direct", "keller-full", "laine"].iter().all(|t| {
                (visible.get(&format!("cornell-{t}.json")))
                    .is_some_and(|new| before.get(&format!("cornell-{t}.json")) != Some(new))
            });
        if !finished && !publishing && !published {
            assert_eq!(
                visible.keys().collect::<Vec<_>>(),
                before.keys().collect::<Vec<_>>(),
                "killed after {delay_ms} ms: the folder changed"
            );
            assert!(
                visible == before,
                "killed after {delay_ms} ms: a file changed"
            );
        }
        complete_sets(&out);
    }
    // The next command takes over the dead run's lock and clears what it left.
    let o = gibench()
        .args([
            "run",
            "--technique",
            "direct",
            "--quality",
            "--spp",
            "4",
            "--quiet",
        ])
        .args(SMALL)
        .arg("--out")
        .arg(&out)
        .arg("--cache")
        .arg(&cache)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let hidden: Vec<String> = files(&out)
        .into_keys()
        .filter(|k| k.starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "left in --out: {hidden:?}");
    let temporaries: Vec<String> = files(&cache)
        .into_keys()
        .filter(|k| k.starts_with(".gibench-tmp"))
        .collect();
    assert!(temporaries.is_empty(), "left in the cache: {temporaries:?}");
    complete_sets(&out);
}

#[test]
fn a_second_command_into_a_folder_in_use_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let (out, cache) = (tmp.path().join("out"), tmp.path().join("cache"));
    let mut first = spawn_long(&out, &cache);
    let start = Instant::now();
    while !out.join(".gibench.lock").exists() && start.elapsed() < Duration::from_secs(20) {
        std::thread::sleep(Duration::from_millis(20));
    }
    let o = small_direct(&out);
    let _ = first.kill();
    let _ = first.wait();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{stderr}");
    assert!(
        stderr.contains("'out'") && stderr.contains("in use"),
        "{stderr}"
    );
}

/// `--out` through a symbolic link and `..` publishes where the OS resolves it; a folder in the
/// place of a file the command writes fails the command before anything is moved, leaving the
/// earlier set whole.
#[cfg(unix)]
#[test]
fn symlinked_out_and_a_folder_in_the_way() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(tmp.path().join("real/sub")).unwrap();
    std::os::unix::fs::symlink(tmp.path().join("real/sub"), tmp.path().join("link")).unwrap();
    let o = gibench()
        .current_dir(tmp.path())
        .args(["run", "--technique", "direct", "--quiet"])
        .args(SMALL)
        .args(["--out", "link/.."])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(tmp.path().join("real/cornell-direct.json").exists());
    assert!(!tmp.path().join(".gibench-staging").exists());

    let out = tmp.path().join("real");
    let before = files(&out);
    std::fs::remove_file(out.join("cornell-summary.md")).unwrap();
    std::fs::create_dir(out.join("cornell-summary.md")).unwrap();
    let o = small_direct(&out);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && stderr.contains("is a folder"),
        "{stderr}"
    );
    let after = files(&out);
    for (name, bytes) in &before {
        if name != "cornell-summary.md" {
            assert!(after.get(name) == Some(bytes), "{name} changed");
        }
    }
    assert!(!after.keys().any(|k| k.starts_with('.')), "{after:?}");
}

/// A run replaces its stem's images: run again with `--no-images`, it leaves none of the first
/// run's beside its results (they were of another resolution), while another stem's files in
/// the same folder stay.
#[test]
fn a_rerun_without_images_removes_the_stems_old_images() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let o = small_direct(&out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.join("cornell-direct.png").exists());
    std::fs::write(out.join("cornell-other.png"), b"another stem's image").unwrap();
    small_ok(
        &["run", "--technique", "direct", "--quiet", "--no-images"],
        &out,
    );
    let names: Vec<String> = files(&out).into_keys().collect();
    let stems: Vec<&String> = (names.iter())
        .filter(|n| n.starts_with("cornell-direct") || n.starts_with("cornell-other"))
        .collect();
    assert_eq!(
        stems,
        ["cornell-direct.json", "cornell-other.png"],
        "{names:?}"
    );
}

/// A sweep into a folder holding an earlier sweep of the same parameter leaves only its own
/// points there (the earlier sweep's extra value is gone); other files, among them the points
/// of a parameter whose name extends the swept one's (`vpl-map-size` beside `vpl-map`), stay.
#[test]
fn a_sweep_replaces_an_earlier_sweeps_points() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let sweep = |values: &str| {
        small_ok(
            &[
                "sweep",
                "--technique",
                "keller-full",
                "--quiet",
                "--no-images",
                "--sweep",
                values,
            ],
            &out,
        );
    };
    sweep("vpls=8,16");
    assert!(out.join("cornell-keller-full-vpls-16.json").exists());
    let others = [
        "cornell-keller-full.json",
        "cornell-keller-full-tiles-2x2.json",
        "cornell-keller-full-vpl-map-size-64.json",
    ];
    for f in others {
        std::fs::write(out.join(f), b"another command's").unwrap();
    }
    std::fs::write(
        out.join("cornell-keller-full-vpl-map-cube.json"),
        b"an earlier point",
    )
    .unwrap();
    sweep("vpls=8");
    sweep("vpl-map=paraboloid");
    let names: Vec<String> = files(&out).into_keys().collect();
    let mut kept: Vec<&str> = (names.iter())
        .filter(|n| n.starts_with("cornell-keller-full") && n.ends_with(".json"))
        .map(String::as_str)
        .collect();
    kept.sort_unstable();
    let mut want = vec![
        "cornell-keller-full-vpl-map-paraboloid.json",
        "cornell-keller-full-vpls-8.json",
    ];
    want.extend(others);
    want.sort_unstable();
    assert_eq!(kept, want, "{names:?}");
}

/// A run killed and not yet reaped (a zombie, which keeps its `/proc` entry) holds no folder:
/// the operating system released its lock when it died, so the next command runs. With the
/// process-id lock this replaced, the zombie's entry kept the folder locked.
#[cfg(unix)]
#[test]
fn a_killed_unreaped_run_does_not_hold_the_folder() {
    let tmp = tempfile::tempdir().unwrap();
    let (out, cache) = (tmp.path().join("out"), tmp.path().join("cache"));
    let mut first = spawn_long(&out, &cache);
    let start = Instant::now();
    while !out.join(".gibench.lock").exists() && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(20));
    }
    // SIGKILL without waiting: the child stays a zombie until `wait` below.
    let pid = first.id();
    std::process::Command::new("kill")
        .args(["-KILL", &pid.to_string()])
        .status()
        .unwrap();
    // The first thread to show `Z` may be the leader while the process's other threads (the
    // driver's workers) are still exiting, and they hold the open files (and so the lock) until
    // the last of them is gone: wait until the leader is a zombie and is the only thread left.
    let zombie_alone = || {
        let z = std::fs::read_to_string(format!("/proc/{pid}/stat"))
            .is_ok_and(|s| s.split(") ").nth(1).unwrap_or("").starts_with('Z'));
        let threads = std::fs::read_dir(format!("/proc/{pid}/task")).map_or(0, |d| d.count());
        z && threads <= 1
    };
    let start = Instant::now();
    while !zombie_alone() && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(10));
    }
    assert!(
        zombie_alone(),
        "process {pid} did not become a lone zombie in 60 s"
    );
    let o = small_direct(&out);
    let _ = first.wait();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    complete_sets(&out);
}

/// A folder below `--out` that is a symbolic link is refused by name before any work, and
/// nothing in the link's target changes — before, `reproduce … --only keller-tiles` with
/// `keller/tiles` a link deleted every file in its target, and `laine-dispersion` with `laine`
/// a link wrote outside the staging folder.
#[cfg(unix)]
#[test]
fn a_link_below_out_is_refused_and_its_target_untouched() {
    let tmp = tempfile::tempdir().unwrap();
    let outside = tmp.path().join("outside");
    std::fs::create_dir_all(&outside).unwrap();
    std::fs::write(outside.join("precious.txt"), b"a user's file").unwrap();
    for (link, only) in [
        ("keller/tiles", "keller-tiles"),
        ("laine", "laine-dispersion"),
    ] {
        let out = tmp.path().join(format!("out-{only}"));
        let at = out.join(link);
        std::fs::create_dir_all(at.parent().unwrap()).unwrap();
        std::os::unix::fs::symlink(&outside, &at).unwrap();
        let o = gibench()
            .args(["reproduce", "all", "--quick", "--quiet", "--only", only])
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{only}: {stderr}");
        assert!(
            stderr.contains("symbolic link") && stderr.contains(link) && stderr.contains("'out'"),
            "{only}: {stderr}"
        );
        let names: Vec<String> = files(&outside).into_keys().collect();
        assert_eq!(names, ["precious.txt"], "{only}");
    }
}

/// A run leaves no page, error plot or skipped list of an earlier run on the same scene: after
/// `run --quality --html`, a plain run into the same folder removes `cornell-report.html` and
/// the error plots and their PDFs (they described the earlier runs, the page over the new
/// images), says so, and leaves another scene's page alone. Catches the page kept with old numbers (issue 56).
#[test]
fn a_later_run_removes_the_earlier_runs_page_and_error_plots() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let direct = ["run", "--technique", "direct", "--quiet"];
    small_ok(&[&direct[..], &["--quality", "--html"]].concat(), &out);
    let earlier = [
        "cornell-report.html",
        "cornell-time-vs-error.svg",
        "cornell-time-vs-error.pdf",
        "cornell-rmse-per-frame.svg",
    ];
    for f in earlier {
        assert!(out.join(f).is_file(), "{f} not written");
    }
    std::fs::write(out.join("sibenik-report.html"), b"another scene's page").unwrap();
    let o = gibench()
        .args(direct)
        .args(SMALL)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    for f in earlier {
        assert!(!out.join(f).exists(), "{f} left behind");
        assert!(stderr.contains(f), "{f} not named: {stderr}");
    }
    assert!(stderr.contains("note: removed"), "{stderr}");
    assert!(out.join("sibenik-report.html").is_file());
    assert!(out.join("cornell-summary.md").is_file());
}

/// A sweep likewise: after `sweep --html`, the same sweep without it removes the earlier page
/// (`{stem}.html`) and says so. Catches a sweep's page left over new points.
#[test]
fn a_later_sweep_removes_the_earlier_sweeps_page() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let sweep = [
        "sweep",
        "--technique",
        "keller-full",
        "--quiet",
        "--no-images",
    ];
    let values = ["--sweep", "vpls=8,16"];
    small_ok(&[&sweep[..], &values, &["--html"]].concat(), &out);
    let page = "cornell-keller-full-sweep-vpls.html";
    assert!(out.join(page).is_file());
    let o = gibench()
        .args(sweep)
        .args(values)
        .args(SMALL)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(!out.join(page).exists(), "{page} left behind");
    assert!(
        stderr.contains(&format!("note: removed {page}")),
        "{stderr}"
    );
    assert!(out.join("cornell-keller-full-sweep-vpls.md").is_file());
}
