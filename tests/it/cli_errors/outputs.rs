//! Output folders: unwritable ones found before any work, none left behind by a failed run,
//! bad `--stem`s refused, every staged file published.

use super::*;

/// An output folder that cannot be written is found before any GPU work, naming `--out`.
#[test]
fn unwritable_output_folder() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("a-file");
    std::fs::write(&file, b"not a folder").unwrap();
    let o = support::GIBENCH
        .command()
        .args(["run", "--frames", "2", "--quiet", "--out"])
        .arg(file.join("sub"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{stderr}");
    assert!(
        stderr.contains("out") && stderr.contains("not a writable folder"),
        "{stderr}"
    );
    assert!(
        !stderr.contains("gibench: scene"),
        "failed only after opening the GPU: {stderr}"
    );
}

/// `--out` naming a missing folder with a trailing `.` is created; a `report --stem` that is not
/// a plain file name is refused before any work, naming `--stem`.
#[test]
fn out_with_a_dot_and_a_bad_stem() {
    let tmp = tempfile::tempdir().unwrap();
    let o = one_direct_frame("32x24", None, tmp.path().join("new/."));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(tmp.path().join("new/cornell-direct.json").exists());
    let o = support::GIBENCH
        .command()
        .arg("report")
        .arg(tmp.path().join("new"))
        .args(["--stem", "../x", "--out"])
        .arg(tmp.path().join("rep"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && stderr.contains("parameter 'stem'"),
        "{stderr}"
    );
    assert!(o.stdout.is_empty() && !tmp.path().join("rep").exists());
}

/// A command that fails after its checks (an atlas that does not fit) leaves no `--out`
/// folder behind when it created it.
#[test]
fn a_failed_run_leaves_no_new_folder() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("a/b");
    let o = support::GIBENCH
        .command()
        .args(["run", "--technique", "laine", "--frames", "1", "--quiet"])
        .args([
            "--param",
            "vpl-map-size=4096",
            "--param",
            "vpls=1024",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(!tmp.path().join("a").exists(), "{:?}", out);
}

/// Files whose names start like the publication journal's directives ("replace…") are
/// published like any other (a broader test of the journal's lines once kept them staged).
#[test]
fn files_named_like_journal_directives_are_published() {
    let tmp = tempfile::tempdir().unwrap();
    copy_baseline(tmp.path());
    let o = support::GIBENCH
        .command()
        .current_dir(tmp.path())
        .args(["report", "r1", "--stem", "replaced", "--out", "o"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(tmp.path().join("o/replaced.md").is_file());
}
