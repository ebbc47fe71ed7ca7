//! End to end: `gibench run` writes a complete results file, images and tables.

use std::process::Command;

use gibench_harness::results::RunResult;

fn run_ok(args: &[&str], out: &std::path::Path) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_gibench"))
        .arg("run")
        .args(args)
        .arg("--out")
        .arg(out)
        .arg("--quiet")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "gibench run {args:?} failed:\n{stderr}");
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn cornell_run_writes_results_images_and_tables() {
    let tmp = tempfile::tempdir().unwrap();
    let stdout = run_ok(&["--frames", "4", "--warmup", "1"], tmp.path());
    for col in [
        "gbuffer",
        "direct-shadow-map",
        "direct-light",
        "compose",
        "FPS",
    ] {
        assert!(stdout.contains(col), "table lacks '{col}':\n{stdout}");
    }
    let r = RunResult::read(&tmp.path().join("cornell-direct.json")).unwrap();
    assert_eq!(r.scene, "cornell");
    assert_eq!(r.technique, "direct");
    assert_eq!(r.frames.measured, 4);
    assert_eq!(r.frames.warmup, 1);
    for s in &r.stages {
        let wall = s.wall_ms.expect("flushed wall time");
        assert_eq!(wall.count, 4, "stage {}", s.name);
        if r.device.timestamp_queries {
            assert_eq!(s.gpu_ms.expect("timestamps").count, 4);
        }
    }
    assert_eq!(r.frame.as_ref().expect("frame timing").frame_ms.count, 4);
    for f in [
        "cornell-direct.png",
        "cornell-direct-indirect.exr",
        "cornell-direct-direct.exr",
        "cornell-summary.md",
        "cornell-summary.csv",
        "cornell-summary.tex",
        "cornell-summary.svg",
    ] {
        assert!(tmp.path().join(f).is_file(), "{f} missing");
    }
    let png = image::open(tmp.path().join("cornell-direct.png"))
        .unwrap()
        .to_rgba8();
    assert_eq!(png.dimensions(), (256, 192));
    // The spot light lights the floor: the image is not black.
    assert!(png.pixels().any(|p| p[0] > 64), "image is black");
}

#[test]
fn sibenik_loads_through_the_asset_search_path() {
    let tmp = tempfile::tempdir().unwrap();
    run_ok(
        &[
            "--scene",
            "sibenik",
            "--frames",
            "5",
            "--warmup",
            "0",
            "--timing",
            "stages",
            "--no-images",
        ],
        tmp.path(),
    );
    let r = RunResult::read(&tmp.path().join("sibenik-direct.json")).unwrap();
    assert_eq!(r.scene, "sibenik");
}
