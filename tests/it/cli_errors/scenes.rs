//! Scenes that cannot be loaded: missing or damaged glTF files and buffers, descriptors with
//! unknown fields or impossible geometry, tessellation past its limits, lights that miss.

use super::*;

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
    let o = support::GIBENCH
        .command()
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

/// `--scene` given a glTF file says what it takes, naming the file.
#[test]
fn scene_given_a_gltf_file() {
    let glb = shared_scene("cornell.glb");
    fails(
        &["--scene", glb.to_str().unwrap()],
        "cornell.glb: a glTF file, not a scene descriptor: --scene takes a built-in scene name",
    );
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
