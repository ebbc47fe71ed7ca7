//! Bad input gets a clear error, a non-zero exit and no results file.

mod support;

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs `gibench run ARGS --out <tmp>/out`, expects failure whose stderr contains `expect`, and
/// checks nothing was written.
fn fails(args: &[&str], expect: &str) {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let o = support::gibench()
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
    let mut c = support::gibench();
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

#[test]
fn missing_asset() {
    let tmp = tempfile::tempdir().unwrap();
    let d = descriptor(tmp.path(), "missing.json", |v| {
        v["mesh"] = serde_json::json!({"file": "no-such-mesh.glb"})
    });
    fails(
        &["--scene", d.to_str().unwrap()],
        "asset 'no-such-mesh.glb' not found",
    );
}

#[test]
fn truncated_gltf() {
    let tmp = tempfile::tempdir().unwrap();
    let bytes = std::fs::read(shared_scene("cornell.glb")).expect("../shared/scenes/cornell.glb");
    let glb = tmp.path().join("truncated.glb");
    std::fs::write(&glb, &bytes[..bytes.len() / 2]).unwrap();
    let d = descriptor(tmp.path(), "truncated.json", |v| {
        v["mesh"] = serde_json::json!({"file": glb.to_str().unwrap()});
        v.as_object_mut().unwrap().remove("shadow_mesh");
    });
    fails(&["--scene", d.to_str().unwrap()], "truncated.glb");
}

#[test]
fn malformed_gltf() {
    let tmp = tempfile::tempdir().unwrap();
    let glb = tmp.path().join("garbage.glb");
    std::fs::write(
        &glb,
        b"glTF\x02\x00\x00\x00this is not a glTF binary at all",
    )
    .unwrap();
    let d = descriptor(tmp.path(), "garbage.json", |v| {
        v["mesh"] = serde_json::json!({"file": glb.to_str().unwrap()});
        v.as_object_mut().unwrap().remove("shadow_mesh");
    });
    fails(&["--scene", d.to_str().unwrap()], "garbage.glb");
}

#[test]
fn descriptor_with_unknown_field() {
    let tmp = tempfile::tempdir().unwrap();
    let d = descriptor(tmp.path(), "unknown.json", |v| {
        v["light"]["colour"] = serde_json::json!([1, 1, 1])
    });
    fails(&["--scene", d.to_str().unwrap()], "colour");
}

#[test]
fn unknown_scene() {
    fails(&["--scene", "atlantis"], "atlantis");
}

#[test]
fn unknown_technique() {
    fails(&["--technique", "direct,nope"], "unknown technique 'nope'");
}

#[test]
fn unknown_parameter() {
    fails(&["--technique", "direct", "--param", "vpls=64"], "vpls");
    fails(
        &["--technique", "direct", "--param", "direct.vpls=64"],
        "technique 'direct' has no such parameter",
    );
}

#[test]
fn bad_resolutions() {
    fails(&["--resolution", "0x192"], "resolution");
    fails(&["--resolution", "100000x192"], "exceeds");
    fails(&["--resolution", "256by192"], "WIDTHxHEIGHT");
}

#[test]
fn zero_frames() {
    let tmp = tempfile::tempdir().unwrap();
    let o = support::gibench()
        .args(["run", "--frames", "0", "--quiet", "--out"])
        .arg(tmp.path().join("out"))
        .output()
        .unwrap();
    assert!(!o.status.success());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("frames") && stderr.contains("got 0"),
        "{stderr}"
    );
    assert!(!tmp.path().join("out").exists());
}

#[test]
fn bad_timing_mode_and_backend() {
    fails(&["--timing", "sometimes"], "timing");
    fails(&["--backend", "glide"], "unknown backend 'glide'");
}

/// Timing whole frames with fewer warm-up frames than the frames in flight plus one would let
/// the first (fill) frame's work land in a measured interval; `laine`'s recalc-min above its
/// recalc-max would drain its VPL count. Both are refused before anything runs.
#[test]
fn short_warmup_and_draining_laine_parameters() {
    fails(&["--warmup", "1"], "warmup");
    fails(
        &[
            "--technique",
            "laine",
            "--param",
            "recalc-min=9",
            "--warmup",
            "3",
        ],
        "laine.recalc-min",
    );
}

/// Overflowing frame counts, a descriptor name that would climb out of the output folder, a
/// technique or sweep value listed twice, `--assets` that is not a folder: clear errors, nothing
/// written.
#[test]
fn overflow_names_duplicates_and_assets() {
    fails(&["--frames", "4294967295"], "frames");
    fails(&["--first-frame", "4294967295"], "first-frame");
    let tmp = tempfile::tempdir().unwrap();
    for bad in ["../../x", "", ".hidden", "a/b"] {
        let d = descriptor(tmp.path(), "named.json", |v| {
            v["name"] = serde_json::json!(bad)
        });
        fails(&["--scene", d.to_str().unwrap()], "name");
    }
    fails(&["--technique", "direct,direct"], "listed twice");
    fails(&["--assets", "/no/such/folder"], "assets");
    let file = tmp.path().join("not-a-folder");
    std::fs::write(&file, b"x").unwrap();
    fails(&["--assets", file.to_str().unwrap()], "not a folder");
    let o = support::gibench()
        .args([
            "sweep",
            "--technique",
            "keller-full",
            "--sweep",
            "vpls=8,8",
            "--frames",
            "2",
        ])
        .arg("--out")
        .arg(tmp.path().join("sweep"))
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("listed twice"));
    let o = support::gibench()
        .args(["reproduce", "laine-dispersion", "--frames", "0"])
        .arg("--out")
        .arg(tmp.path().join("repro"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && stderr.contains("frames") && !stderr.contains("panicked"));
    assert!(!tmp.path().join("repro").exists());
}

/// An output folder that cannot be written is found before any GPU work, naming `--out`.
#[test]
fn unwritable_output_folder() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("a-file");
    std::fs::write(&file, b"not a folder").unwrap();
    let o = support::gibench()
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

/// Geometry too large for f32 bounds (a vertex at 3e38, a static scaled by 1e30 or placed at
/// 3e38) is refused with the field or mesh named, instead of panicking in the BVH build.
#[test]
fn huge_coordinates() {
    let tmp = tempfile::tempdir().unwrap();
    let d = one_triangle_gltf(tmp.path(), "tri.bin");
    std::fs::write(
        tmp.path().join("tri.bin"),
        corners([[0.0, 0.0, 0.0], [3.0e38, 0.0, 0.0], [0.0, 1.0, 0.0]]),
    )
    .unwrap();
    // The glTF file is named (before: only the scene and "the static mesh").
    fails(&["--scene", d.to_str().unwrap()], "mesh: a vertex at");
    fails(&["--scene", d.to_str().unwrap()], "tri.gltf");
    let statue = |scale: f64, at: f64| {
        move |v: &mut serde_json::Value| {
            v["statics"] = serde_json::json!([{
                "mesh": {"generated": "cornell-box"},
                "scale": scale,
                "position": [at, 0.0, 0.0]
            }]);
        }
    };
    let d = descriptor(tmp.path(), "scaled.json", statue(1e30, 0.0));
    fails(&["--scene", d.to_str().unwrap()], "after its transforms");
    let d = descriptor(tmp.path(), "placed.json", statue(1.0, 3e38));
    fails(&["--scene", d.to_str().unwrap()], "statics[0]");
}

/// A buffer URI must stay inside the glTF's folder and name a regular file; a missing one is
/// named; a device (`/dev/zero`) is never read, as a URI or as `--scene`.
#[test]
fn buffer_uris_outside_the_folder_devices_and_missing_files() {
    let tmp = tempfile::tempdir().unwrap();
    for (uri, expect) in [
        ("../../../../etc/passwd", "leaves the glTF's folder"),
        ("/dev/zero", "leaves the glTF's folder"),
        ("file:///dev/zero", "has a scheme"),
        ("missing.bin", "missing.bin"),
    ] {
        let d = one_triangle_gltf(tmp.path(), uri);
        fails(&["--scene", d.to_str().unwrap()], expect);
    }
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink("/dev/zero", tmp.path().join("zero.bin")).unwrap();
        let d = one_triangle_gltf(tmp.path(), "zero.bin");
        fails(&["--scene", d.to_str().unwrap()], "through a symbolic link");
        std::fs::create_dir(tmp.path().join("folder.bin")).unwrap();
        let d = one_triangle_gltf(tmp.path(), "folder.bin");
        fails(
            &["--scene", d.to_str().unwrap()],
            "does not name a regular file",
        );
        fails(&["--scene", "/dev/zero"], "not a regular file");
    }
}

/// A `tessellate` edge that would make more than 2²³ triangles is refused before any memory is
/// asked for, naming the field.
#[test]
fn tessellation_past_the_cap() {
    let tmp = tempfile::tempdir().unwrap();
    let d = descriptor(tmp.path(), "fine.json", |v| {
        v["shadow_mesh"]["tessellate"] = serde_json::json!(0.001)
    });
    fails(&["--scene", d.to_str().unwrap()], "shadow_mesh.tessellate");
}

/// A `tessellate` length finer than the tessellation's per-edge limit (256 rows or cells) is
/// refused, naming the field and the smallest length that fits, where it used to be coarsened
/// without a word: a generated Cornell box (about 960 mm corner to corner) at 1 mm cells, and
/// one triangle (longest edge √2) at 0.005 — 283 rows, 80,089 triangles, well under the total
/// cap, so only the per-edge limit catches it.
#[test]
fn tessellation_finer_than_the_per_edge_limit() {
    let tmp = tempfile::tempdir().unwrap();
    let d = descriptor(tmp.path(), "fine-generated.json", |v| {
        v["shadow_mesh"] = serde_json::json!({"generated": "cornell-box", "tessellate": 1.0});
    });
    fails(
        &["--scene", d.to_str().unwrap()],
        "shadow_mesh.tessellate: 1 would split the generated mesh 'cornell-box'",
    );
    let d = one_triangle_gltf(tmp.path(), "tri.bin");
    std::fs::write(
        tmp.path().join("tri.bin"),
        corners([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
    )
    .unwrap();
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&d).unwrap()).unwrap();
    v["shadow_mesh"] = serde_json::json!({"file": v["mesh"]["file"].clone(), "tessellate": 0.005});
    std::fs::write(&d, serde_json::to_string(&v).unwrap()).unwrap();
    fails(
        &["--scene", d.to_str().unwrap()],
        "shadow_mesh.tessellate = 0.005 would split its longest triangle edge",
    );
}

/// Irradiance past the half-float limit of the irradiance buffers is reported, in the results
/// file and on standard error, instead of being clamped silently.
#[test]
fn half_float_saturation_is_reported() {
    let tmp = tempfile::tempdir().unwrap();
    let d = descriptor(tmp.path(), "bright.json", |v| {
        v["light"]["power"] = serde_json::json!([1e12, 1e12, 1e12])
    });
    let out = tmp.path().join("out");
    let o = one_direct_frame("64x48", Some(&d), &out);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(stderr.contains("half-float limit"), "{stderr}");
    let name = std::fs::read_dir(&out)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .find(|p| {
            p.extension().is_some_and(|x| x == "json") && !p.to_string_lossy().contains("summary")
        })
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(name).unwrap()).unwrap();
    assert!(v["warnings"][0]
        .as_str()
        .unwrap()
        .contains("direct irradiance"));
    // The ordinary scene gets no such warning.
    let o = one_direct_frame("64x48", None, tmp.path().join("plain"));
    assert!(!String::from_utf8_lossy(&o.stderr).contains("half-float"));
}

#[test]
fn dispersion_needs_two_frames() {
    let tmp = tempfile::tempdir().unwrap();
    let o = support::gibench()
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

/// What does not fit the device is found before the first technique's first frame: a VPL atlas
/// too large for the adapter fails at once even after a long `direct` run in the same command
/// (3000 frames, tens of seconds), and a cube-map atlas past the texture limit names
/// `--shadow-size`.
#[test]
fn device_limits_are_checked_before_any_frame() {
    let tmp = tempfile::tempdir().unwrap();
    let start = std::time::Instant::now();
    let o = support::gibench()
        .args([
            "run",
            "--technique",
            "direct,laine",
            "--frames",
            "3000",
            "--quiet",
        ])
        .args([
            "--param",
            "vpl-map-size=4096",
            "--param",
            "vpls=1024",
            "--out",
        ])
        .arg(tmp.path().join("out"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && stderr.contains("do not fit"),
        "{stderr}"
    );
    assert!(
        start.elapsed() < std::time::Duration::from_secs(15),
        "found only after {:?}",
        start.elapsed()
    );
    fails(&["--shadow-size", "8000"], "parameter 'shadow-size'");
}

/// What a hostile review found: a buffer URI that leaves the folder through a symbolic link,
/// a `tessellate` edge so short it would be clamped, a mover whose scale and path together
/// pass the coordinate bound, a `--cache` that is a file for `reference`, a stale lock held by
/// a pid of another program, a staging leftover that is a file — each refused or recovered.
#[test]
fn hostile_review_cases() {
    let tmp = tempfile::tempdir().unwrap();
    #[cfg(unix)]
    {
        let outside = tmp.path().join("outside");
        std::fs::create_dir(&outside).unwrap();
        std::fs::write(
            outside.join("tri.bin"),
            corners([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
        )
        .unwrap();
        let inside = tmp.path().join("inside");
        std::fs::create_dir(&inside).unwrap();
        std::os::unix::fs::symlink(outside.join("tri.bin"), inside.join("link.bin")).unwrap();
        let d = one_triangle_gltf(&inside, "link.bin");
        fails(&["--scene", d.to_str().unwrap()], "through a symbolic link");
    }
    let d = descriptor(tmp.path(), "tiny-edge.json", |v| {
        v["shadow_mesh"]["tessellate"] = serde_json::json!(1e-30)
    });
    fails(&["--scene", d.to_str().unwrap()], "shadow_mesh.tessellate");
    let d = descriptor(tmp.path(), "far-mover.json", |v| {
        v["movers"] = serde_json::json!([{
            "name": "big", "mesh": {"generated": "cornell-box"}, "scale": 1e6,
            "path": {"keys": [{"time": 0.0, "position": [9e8, 0.0, 9e8]}]}
        }]);
    });
    fails(&["--scene", d.to_str().unwrap()], "mover 'big'");
    let file = tmp.path().join("cache-file");
    std::fs::write(&file, b"x").unwrap();
    let o = support::gibench()
        .args([
            "reference",
            "--resolution",
            "16x12",
            "--spp",
            "1",
            "--cache",
        ])
        .arg(&file)
        .arg("--out")
        .arg(tmp.path().join("ref"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && stderr.contains("parameter 'cache'"),
        "{stderr}"
    );
    // A lock naming pid 1 (another program) and a staging leftover that is a file: taken over.
    let out = tmp.path().join("locked");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join(".gibench.lock"), b"1").unwrap();
    std::fs::write(out.join(".gibench-staging"), b"junk").unwrap();
    let o = one_direct_frame("32x24", None, &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.join("cornell-direct.json").exists());
    assert!(!out.join(".gibench.lock").exists() && !out.join(".gibench-staging").exists());
}

/// `--out` naming a missing folder with a trailing `.` is created; a `report --stem` that is not
/// a plain file name is refused before any work, naming `--stem`.
#[test]
fn out_with_a_dot_and_a_bad_stem() {
    let tmp = tempfile::tempdir().unwrap();
    let o = one_direct_frame("32x24", None, tmp.path().join("new/."));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(tmp.path().join("new/cornell-direct.json").exists());
    let o = support::gibench()
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
    let o = support::gibench()
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

/// Runs `gibench ARGS` in folder `dir` with `env` set, expects failure whose stderr contains
/// every string of `expect` and no panic, and returns the stderr.
fn command_fails(dir: &Path, env: &[(&str, &str)], args: &[&str], expect: &[&str]) -> String {
    let o = support::gibench()
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

/// A parameter given twice for one technique, or both with `--param` and as the swept one, is
/// refused naming it; the same name for two different techniques is fine.
#[test]
fn parameter_given_twice() {
    fails(&["-p", "vpls=8", "-p", "vpls=16"], "given twice");
    fails(
        &[
            "--technique",
            "laine,keller-full",
            "-p",
            "vpls=8",
            "-p",
            "laine.vpls=16",
        ],
        "parameter 'laine.vpls': given twice",
    );
    // Two techniques' own values pass the parameter check (and fail later, on the scene).
    fails(
        &[
            "--technique",
            "laine,keller-full",
            "-p",
            "laine.vpls=8",
            "-p",
            "keller-full.vpls=16",
            "--scene",
            "atlantis",
        ],
        "unknown scene 'atlantis'",
    );
    let tmp = tempfile::tempdir().unwrap();
    command_fails(
        tmp.path(),
        &[],
        &[
            "sweep",
            "--technique",
            "keller-full",
            "--sweep",
            "vpls=8,16",
            "-p",
            "vpls=32",
            "--out",
            "out",
        ],
        &["parameter 'vpls'", "given both as --param"],
    );
}

/// Sweep values are compared as the technique reads them: `08` and `8`, `1` and `1.0` are one
/// setting, refused naming both values.
#[test]
fn sweep_values_compared_as_parsed() {
    let tmp = tempfile::tempdir().unwrap();
    for (technique, sweep, values) in [
        ("keller-full", "vpls=08,8", ["'08'", "'8'"]),
        ("laine", "clamp=1,1.0", ["'1'", "'1.0'"]),
    ] {
        command_fails(
            tmp.path(),
            &[],
            &[
                "sweep",
                "--technique",
                technique,
                "--sweep",
                sweep,
                "--out",
                "out",
            ],
            &["listed twice", values[0], values[1]],
        );
    }
    assert!(!tmp.path().join("out").exists());
}

/// `compare` refuses runs compared with themselves: the same folder twice, the same files on
/// both sides (nested folders), byte-identical copies on both sides or within one.
#[test]
fn compare_refuses_runs_compared_with_themselves() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    copy_baseline(&dir.join("a"));
    copy_baseline(&dir.join("copy"));
    let cmp = |base: &str, current: &str, expect: &[&str]| {
        command_fails(dir, &[], &["compare", base, current, "--out", "o"], expect);
    };
    cmp(
        "a",
        "a",
        &["parameter 'current'", "the same folder as BASE"],
    );
    cmp("a", "a/r1", &["the same file as"]);
    cmp("a", "copy", &["a byte-identical copy of", "in BASE"]);
    // CURRENT made distinct from BASE (a trailing newline), then one repeat copied over another.
    for e in std::fs::read_dir(dir.join("copy")).unwrap() {
        for f in std::fs::read_dir(e.unwrap().path()).unwrap() {
            let f = f.unwrap().path();
            let mut bytes = std::fs::read(&f).unwrap();
            bytes.push(b'\n');
            std::fs::write(&f, bytes).unwrap();
        }
    }
    std::fs::copy(
        dir.join("copy/r1/cornell-direct.json"),
        dir.join("copy/r2/cornell-direct.json"),
    )
    .unwrap();
    cmp("a", "copy", &["a byte-identical copy of", "in CURRENT;"]);
    assert!(!dir.join("o").exists());
}

/// `report` and `plot-quality` refuse a results file reached twice (`F F`, `DIR DIR/F`)
/// instead of counting its run twice.
#[test]
fn report_and_plot_quality_count_each_file_once() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    copy_baseline(dir);
    let f = "r1/cornell-direct.json";
    for args in [
        ["report", f, f],
        ["report", "r1", "./r1/cornell-direct.json"],
        ["plot-quality", f, f],
    ] {
        let mut args = args.to_vec();
        args.extend(["--out", "o"]);
        command_fails(dir, &[], &args, &["cornell-direct.json", "given twice"]);
    }
    assert!(!dir.join("o").exists());
}

/// `plot-quality` on results without per-frame values names its inputs and says how to make
/// them; a bad `--out` is named; its help lists every metric it takes.
#[test]
fn plot_quality_inputs_out_and_metrics() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    copy_baseline(dir);
    let err = command_fails(
        dir,
        &[],
        &[
            "plot-quality",
            "r1/cornell-direct.json",
            "--out",
            "pq/one.svg",
        ],
        &["r1/cornell-direct.json", "run --quality --quality-all"],
    );
    assert!(!err.contains("one.svg"), "{err}");
    command_fails(
        dir,
        &[],
        &["plot-quality", "r1", "--out", "pq/x.svg"],
        &["r1: no results hold per-frame quality values"],
    );
    command_fails(
        dir,
        &[],
        &["plot-quality", "r1", "--out", "r2"],
        &["parameter 'out'", "is a folder"],
    );
    command_fails(
        dir,
        &[],
        &["plot-quality", "r1", "--out", "r1/cornell-ism.json/x.svg"],
        &["parameter 'out'", "is a file, not a folder"],
    );
    let err = command_fails(
        dir,
        &[],
        &["plot-quality", "r1", "--metric", "nope"],
        &["parameter 'metric'"],
    );
    let help = support::gibench()
        .args(["plot-quality", "--help"])
        .output()
        .unwrap();
    let help = String::from_utf8_lossy(&help.stdout);
    let listed = err.split("expected ").nth(1).unwrap().split(" (got").next();
    for metric in listed
        .unwrap()
        .split([',', ' '])
        .filter(|m| !m.is_empty() && *m != "or")
    {
        assert!(help.contains(metric), "--help lacks '{metric}':\n{help}");
    }
    assert!(!dir.join("pq").exists());
}

/// `--scene` given a glTF file says what it takes, naming the file.
#[test]
fn scene_given_a_gltf_file() {
    let glb = shared_scene("cornell.glb");
    fails(
        &["--scene", glb.to_str().unwrap()],
        "cornell.glb: a glTF file, not a scene descriptor: --scene takes a built-in scene name",
    );
}

/// An unknown backend from the environment names `GIBENCH_BACKEND` and the accepted values.
#[test]
fn backend_from_the_environment() {
    let tmp = tempfile::tempdir().unwrap();
    command_fails(
        tmp.path(),
        &[("GIBENCH_BACKEND", "bogus")],
        &["run", "--frames", "2", "--quiet", "--out", "out"],
        &["GIBENCH_BACKEND", "'bogus'", "vulkan, gl, metal, dx12"],
    );
    assert!(!tmp.path().join("out").exists());
}

/// A results file that parses but would print wrong tables is refused by `report`, naming the
/// file and the field: a negative time, an empty technique name, a stage listed twice (its
/// time would count twice in Σ).
#[test]
fn results_files_with_impossible_values_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    copy_baseline(dir);
    let file = dir.join("r1/cornell-keller-full.json");
    let good = std::fs::read(&file).unwrap();
    type Edit = (
        &'static str,
        fn(&mut serde_json::Value),
        &'static [&'static str],
    );
    let edits: [Edit; 3] = [
        (
            "negative",
            |v| v["stages"][0]["wall_ms"]["median"] = serde_json::json!(-5.0),
            &["wall_ms.median is -5", "not negative"],
        ),
        (
            "unnamed",
            |v| v["technique"] = serde_json::json!(""),
            &["'technique' is empty"],
        ),
        (
            "repeated",
            |v| {
                let first = v["stages"][0].clone();
                v["stages"].as_array_mut().unwrap().push(first);
            },
            &["listed twice"],
        ),
    ];
    for (what, edit, expect) in edits {
        let mut v: serde_json::Value = serde_json::from_slice(&good).unwrap();
        edit(&mut v);
        std::fs::write(&file, serde_json::to_vec(&v).unwrap()).unwrap();
        let mut all = vec!["cornell-keller-full.json"];
        all.extend(expect);
        let err = command_fails(dir, &[], &["report", "r1", "--out", "o"], &all);
        assert!(!dir.join("o").exists(), "{what}: {err}");
    }
}

/// Options of the error measurement given without `--quality` are refused (they used to be
/// ignored: nothing was compared), as are zero frame pairs, and reference sample and bounce
/// counts past their limits (a run that would not end in hours), before any work. The sizes
/// are tiny, so that without the checks each command would succeed at once.
#[test]
fn quality_options_need_quality_and_reference_sizes_have_limits() {
    let tmp = tempfile::tempdir().unwrap();
    let run = [
        "run",
        "--technique",
        "direct",
        "--resolution",
        "16x12",
        "--frames",
        "1",
        "--warmup",
        "0",
        "--timing",
        "stages",
        "--no-images",
        "--quiet",
        "--spp",
        "1",
        "--no-cache",
        "--out",
        "o",
    ];
    for (extra, expect) in [
        (
            &["--quality-all"][..],
            &["quality-all", "add --quality"][..],
        ),
        (
            &["--quality-pairs", "3"][..],
            &["quality-pairs", "add --quality"][..],
        ),
        (
            &["--quality-reference", "direct"][..],
            &["quality-reference", "add --quality"][..],
        ),
        (
            &["--quality", "--quality-pairs", "0"][..],
            &["quality-pairs", "at least one"][..],
        ),
    ] {
        let mut args = run.to_vec();
        args.extend(extra);
        command_fails(tmp.path(), &[], &args, expect);
    }
    let reference = [
        "reference",
        "--resolution",
        "1x1",
        "--no-cache",
        "--out",
        "r",
    ];
    for (extra, expect) in [
        (["--spp", "65537"], &["spp", "1..=65536"][..]),
        (["--bounces", "65"], &["bounces", "1..=64"][..]),
    ] {
        let mut args = reference.to_vec();
        args.extend(extra);
        command_fails(tmp.path(), &[], &args, expect);
    }
    assert!(!tmp.path().join("o").exists() && !tmp.path().join("r").exists());
}

/// Files whose names start like the publication journal's directives ("replace…") are
/// published like any other (a broader test of the journal's lines once kept them staged).
#[test]
fn files_named_like_journal_directives_are_published() {
    let tmp = tempfile::tempdir().unwrap();
    copy_baseline(tmp.path());
    let o = support::gibench()
        .current_dir(tmp.path())
        .args(["report", "r1", "--stem", "replaced", "--out", "o"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(tmp.path().join("o/replaced.md").is_file());
}

/// Parameters past what the image or the device allows are refused by name before any frame:
/// a tile grid with more tiles along an axis than the image has pixels (before: an all-zero
/// image for `laine` and `ism`, +20 % with hot spots for `keller-full`), an `ism` point pool or
/// reflective shadow map larger than the adapter's largest storage buffer (before: a raw GPU
/// validation error after seconds of sampling, or the blame put on `vpl-map-size`).
#[test]
fn parameters_past_the_image_or_the_device() {
    for t in ["laine", "ism", "keller-full"] {
        fails(
            &[
                "--technique",
                t,
                "--resolution",
                "64x48",
                "--param",
                "tiles=64x64",
            ],
            "parameter 'tiles'",
        );
    }
    fails(
        &[
            "--technique",
            "laine",
            "--resolution",
            "64x48",
            "--param",
            "tiles=8x49",
        ],
        "8x49 tiles on a 64x48 image",
    );
    let gpu = gibench_harness::gpu::GpuContext::new(&Default::default()).expect("an adapter");
    let limits = gpu.device.limits();
    let max = limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size);
    drop(gpu);
    if (1u64 << 24) * 16 > max {
        fails(
            &[
                "--technique",
                "ism",
                "--resolution",
                "32x24",
                "--param",
                "point-pool=16777216",
                "--param",
                "points-per-vpl=1",
            ],
            "parameter 'point-pool'",
        );
    } else {
        gibench_harness::gpu::say_uncaptured(&format!(
            "cli_errors: this adapter's storage buffers ({max} bytes) take ism's largest point pool; the pool's check was not tried"
        ));
    }
    if 6 * 2048u64 * 2048 * 16 > max {
        fails(
            &[
                "--technique",
                "ism",
                "--resolution",
                "32x24",
                "--param",
                "rsm-size=2048",
            ],
            "parameter 'rsm-size'",
        );
    }
}

/// An area light a billion units wide (within the corner limit) sends every one of barczak's
/// random walks past the Cornell box: the error names the scene's light, not the `vpls`
/// parameter the user never gave (as it did before: "parameter 'vpls': at least one VPL slot").
#[test]
fn a_light_whose_walks_miss_the_scene_is_named() {
    let tmp = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root().join("scenes/cornell-area.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["light"]["size"] = serde_json::json!([1e9, 1e9]);
    let p = tmp.path().join("wide-light.json");
    std::fs::write(&p, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    let scene = p.to_str().unwrap();
    fails(
        &[
            "--scene",
            scene,
            "--technique",
            "barczak",
            "--resolution",
            "64x48",
        ],
        "field 'light'",
    );
}

/// The component each run is compared with follows its parameters (`keller-full bounces=3`
/// computes several bounces, `barczak set=direct` the area light's direct light), and
/// `--quality-reference` naming another one warns, naming the technique (checked at planning:
/// an unwritable `--out` then stops the run before any work). Caught by: the component
/// declared once per technique (no warning for bounces=3 against one bounce, a false one for
/// set=direct against direct).
#[test]
fn quality_reference_other_than_the_computed_component_warns() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("file"), b"").unwrap();
    let planned = |args: &[&str]| {
        let mut all = vec!["run", "--quality", "--out", "file/out"];
        all.extend_from_slice(args);
        command_fails(tmp.path(), &[], &all, &["parameter 'out'"])
    };
    let warned = |stderr: &str, technique: &str| {
        stderr
            .lines()
            .any(|l| l.starts_with("warning: --quality-reference") && l.contains(technique))
    };
    let e = planned(&[
        "--technique",
        "keller-full",
        "--param",
        "bounces=3",
        "--quality-reference",
        "one-bounce",
    ]);
    assert!(warned(&e, "keller-full computes the multi-bounce"), "{e}");
    let e = planned(&[
        "--technique",
        "keller-full",
        "--quality-reference",
        "one-bounce",
    ]);
    assert!(!warned(&e, "keller-full"), "{e}");
    let e = planned(&[
        "--technique",
        "barczak",
        "--param",
        "set=direct",
        "--quality-reference",
        "direct",
    ]);
    assert!(!warned(&e, "barczak"), "{e}");
    let e = planned(&[
        "--technique",
        "barczak",
        "--param",
        "set=direct",
        "--quality-reference",
        "multi-bounce",
    ]);
    assert!(warned(&e, "barczak computes the direct"), "{e}");
}
