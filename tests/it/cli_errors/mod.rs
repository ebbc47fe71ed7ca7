//! Bad input gets a clear error, a non-zero exit and no results file.
//!
//! This file holds the helpers; the tests are in its submodules, one per kind of input (scenes, run options, limits, outputs, results files, reference and
//! reproduce).

mod limits;
mod outputs;
mod reference_and_reproduce;
mod results;
mod run_options;
mod scenes;
use crate::support;

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs `gibench run ARGS --out <tmp>/out`, expects failure whose stderr contains `expect`, and
/// checks nothing was written.
fn fails(args: &[&str], expect: &str) {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let o = support::GIBENCH
        .command()
        .arg("run")
        .args(args)
        .arg("--out")
        .arg(&out)
        .arg("--quiet")
        .arg("--frames=2")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success(),
        "expected failure for {args:?}, stderr: {stderr}"
    );
    assert!(
        stderr.contains(expect),
        "stderr for {args:?} does not mention '{expect}':\n{stderr}"
    );
    assert!(
        !stderr.contains("panicked"),
        "panic for {args:?}:\n{stderr}"
    );
    let leftovers: Vec<_> = std::fs::read_dir(&out)
        .map(|d| d.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    assert!(
        leftovers.is_empty(),
        "files left behind for {args:?}: {leftovers:?}"
    );
}

/// The Cornell descriptor with `edit` applied, written to `dir/name`.
fn descriptor(dir: &Path, name: &str, edit: impl FnOnce(&mut serde_json::Value)) -> PathBuf {
    let text = std::fs::read_to_string(root().join("scenes/cornell-gltf.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    edit(&mut v);
    let p = dir.join(name);
    std::fs::write(&p, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    p
}

/// One `direct` frame (stage timing, no warm-up) at `resolution` into `out`, on `scene` or the
/// default Cornell box.
fn one_direct_frame(
    resolution: &str,
    scene: Option<&Path>,
    out: impl AsRef<std::ffi::OsStr>,
) -> std::process::Output {
    let mut c = support::GIBENCH.command();
    c.args([
        "run",
        "--technique",
        "direct",
        "--frames",
        "1",
        "--warmup",
        "0",
    ])
    .args(["--timing", "stages", "--quiet", "--resolution", resolution]);
    if let Some(scene) = scene {
        c.arg("--scene").arg(scene);
    }
    c.arg("--out").arg(out).output().unwrap()
}

fn shared_scene(name: &str) -> PathBuf {
    root().join("../shared/scenes").join(name)
}

/// A one-triangle `.gltf` in `dir` whose buffer is the file `uri` names (written by the caller,
/// or not at all); the descriptor that loads it is returned.
fn one_triangle_gltf(dir: &Path, uri: &str) -> PathBuf {
    let gltf = serde_json::json!({
        "asset": {"version": "2.0"},
        "buffers": [{"uri": uri, "byteLength": 36}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0.0, 0.0, 0.0], "max": [3.0e38, 1.0, 0.0]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    });
    let file = dir.join("tri.gltf");
    std::fs::write(&file, serde_json::to_string(&gltf).unwrap()).unwrap();
    descriptor(dir, "tri.json", |v| {
        v["mesh"] = serde_json::json!({"file": file.to_str().unwrap()});
        v.as_object_mut().unwrap().remove("shadow_mesh");
    })
}

/// Triangle corners as the little-endian f32 bytes of a glTF buffer.
fn corners(p: [[f32; 3]; 3]) -> Vec<u8> {
    p.iter().flatten().flat_map(|c| c.to_le_bytes()).collect()
}

/// Runs `gibench ARGS` in folder `dir` with `env` set, expects failure whose stderr contains
/// every string of `expect` and no panic, and returns the stderr.
fn command_fails(dir: &Path, env: &[(&str, &str)], args: &[&str], expect: &[&str]) -> String {
    let o = support::GIBENCH
        .command()
        .current_dir(dir)
        .env_remove("GIBENCH_BACKEND")
        .envs(env.iter().copied())
        .args(args)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(
        !o.status.success(),
        "expected failure for {args:?}, stderr: {stderr}"
    );
    for e in expect {
        assert!(
            stderr.contains(e),
            "stderr for {args:?} does not mention '{e}':\n{stderr}"
        );
    }
    assert!(
        !stderr.contains("panicked"),
        "panic for {args:?}:\n{stderr}"
    );
    stderr
}

/// Copies the committed baseline runs (three repeats) to `to`.
fn copy_baseline(to: &Path) {
    for r in ["r1", "r2", "r3"] {
        std::fs::create_dir_all(to.join(r)).unwrap();
        for e in std::fs::read_dir(root().join("results/baseline").join(r)).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "json") {
                std::fs::copy(&p, to.join(r).join(p.file_name().unwrap())).unwrap();
            }
        }
    }
}
