//! `reference` and `reproduce` limits: the frame number, a dispersion run of one frame.

use super::*;

#[test]
fn dispersion_needs_two_frames() {
    let tmp = tempfile::tempdir().unwrap();
    let o = support::GIBENCH
        .command()
        .args(["reproduce", "laine-dispersion", "--frames", "1", "--out"])
        .arg(tmp.path().join("d"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && stderr.contains("at least 2 frames"),
        "{stderr}"
    );
    let left: Vec<_> = std::fs::read_dir(tmp.path().join("d"))
        .map(|d| d.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    assert!(left.is_empty(), "{left:?}");
}

/// `reference --frame` past the limit names `frame`, the option it has, not `first-frame`.
#[test]
fn reference_frame_limit_names_frame() {
    let tmp = tempfile::tempdir().unwrap();
    let err = command_fails(
        tmp.path(),
        &[],
        &["reference", "--frame", "20000000", "--out", "out"],
        &["parameter 'frame'"],
    );
    assert!(!err.contains("first-frame"), "{err}");
}
