//! `gibench export-scene --rays N` and `gibench raycast`: the ray files hold what the docs say
//! (shadow rays end at the light, closest-hit rays are unit directions from the same origins),
//! raycast's answers are consistent with the files, and bad ray folders are refused by name.

use crate::support;

use std::path::Path;

/// Runs `gibench ARGS` to the end.
fn gibench<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> std::process::Output {
    support::GIBENCH.run(args)
}

fn ok(args: &[&str]) {
    support::GIBENCH.run_ok(args);
}

/// Seven little-endian f32 per ray.
fn rays(path: &Path) -> Vec<[f32; 7]> {
    let b = std::fs::read(path).unwrap();
    assert_eq!(b.len() % 28, 0, "{}", path.display());
    b.chunks_exact(28)
        .map(|r| {
            std::array::from_fn(|i| f32::from_le_bytes(r[4 * i..4 * i + 4].try_into().unwrap()))
        })
        .collect()
}

/// `export-scene --scene cornell --rays n --out dir`.
fn export_cornell(dir: &Path, n: usize) {
    ok(&[
        "export-scene",
        "--scene",
        "cornell",
        "--rays",
        &n.to_string(),
        "--out",
        dir.to_str().unwrap(),
    ]);
}

#[test]
fn exported_rays_are_what_the_docs_say_and_raycast_answers_them() {
    let tmp = tempfile::tempdir().unwrap();
    let (export, cast) = (tmp.path().join("export"), tmp.path().join("cast"));
    let n = 2000;
    let e = export.to_str().unwrap();
    export_cornell(&export, n);
    let meta: serde_json::Value =
        serde_json::from_slice(&std::fs::read(export.join("scene.json")).unwrap()).unwrap();
    let light: Vec<f32> = meta["light"]["position"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap() as f32)
        .collect();
    let closest = rays(&export.join("rays-closest.bin"));
    let shadow = rays(&export.join("rays-shadow.bin"));
    assert_eq!((closest.len(), shadow.len()), (n, n));
    for (c, s) in closest.iter().zip(&shadow) {
        // Same origin; a unit closest-hit direction with an unbounded interval; a shadow ray
        // whose segment ends at the light, stopping just short of it.
        assert_eq!(c[..3], s[..3]);
        let len = (c[3] * c[3] + c[4] * c[4] + c[5] * c[5]).sqrt();
        assert!(
            (len - 1.0).abs() < 1e-4,
            "closest-hit direction of length {len}"
        );
        assert!(c[6].is_infinite());
        for k in 0..3 {
            assert!(
                (s[k] + s[3 + k] - light[k]).abs() < 1e-2,
                "shadow ray {s:?} misses the light {light:?}"
            );
        }
        assert!(s[6] > 0.999 && s[6] < 1.0);
        // Origins on the box's surfaces (the Cornell box spans about 0..556 x 0..549 x 0..560).
        assert!(
            c[0] > -1.0
                && c[0] < 557.0
                && c[1] > -1.0
                && c[1] < 550.0
                && c[2] > -1.0
                && c[2] < 561.0,
            "{c:?}"
        );
    }
    let c = cast.to_str().unwrap();
    ok(&["raycast", "--rays", e, "--repeats", "2", "--out", c]);
    let r: serde_json::Value =
        serde_json::from_slice(&std::fs::read(cast.join("raycast.json")).unwrap()).unwrap();
    assert_eq!(r["scene"], "cornell");
    assert_eq!(r["passes"].as_array().unwrap().len(), 2);
    let t: Vec<f32> = std::fs::read(cast.join("closest-t.bin"))
        .unwrap()
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    let blocked = std::fs::read(cast.join("shadow-hit.bin")).unwrap();
    assert_eq!((t.len(), blocked.len()), (n, n));
    let hits = t.iter().filter(|x| x.is_finite()).count();
    let nblocked = blocked.iter().filter(|&&b| b == 1).count();
    assert_eq!(r["closest_hits"].as_u64(), Some(hits as u64));
    assert_eq!(r["shadow_blocked"].as_u64(), Some(nblocked as u64));
    // Rays from the inside of an open-fronted box mostly hit it; the blocks shadow some of the
    // floor from the light, not all of the box.
    assert!(hits > n / 2, "{hits} of {n} closest-hit rays hit");
    assert!(
        nblocked > 0 && nblocked < n / 2,
        "{nblocked} of {n} shadow rays blocked"
    );
    for (ray, &t) in closest.iter().zip(&t) {
        if t.is_finite() {
            let p: Vec<f32> = (0..3).map(|k| ray[k] + t * ray[3 + k]).collect();
            assert!(
                t > 0.0 && p[0] > -1.0 && p[0] < 557.0 && p[1] > -1.0 && p[1] < 550.0,
                "{p:?}"
            );
        }
    }
}

#[test]
fn bad_ray_folders_are_refused_by_name_and_write_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let export = tmp.path().join("export");
    let e = export.to_str().unwrap();
    export_cornell(&export, 10);
    let fails = |args: &[&str], expect: &[&str]| {
        let out = tmp.path().join("cast");
        let mut all = args.to_vec();
        all.extend(["--out", out.to_str().unwrap()]);
        let o = gibench(&all);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} succeeded");
        for x in expect {
            assert!(err.contains(x), "{args:?}: '{x}' not in: {err}");
        }
        assert!(!err.contains("panicked"), "{err}");
        assert!(!out.join("raycast.json").exists());
    };
    fails(&["raycast", "--rays", e, "--repeats", "0"], &["repeats"]);
    fails(
        &["raycast", "--rays", e, "--repeats", "1001"],
        &["repeats", "1000"],
    );
    let none = tmp.path().join("nothing");
    fails(
        &["raycast", "--rays", none.to_str().unwrap()],
        &["rays", "scene.json"],
    );
    // A ray file cut mid-ray.
    let f = export.join("rays-shadow.bin");
    let b = std::fs::read(&f).unwrap();
    std::fs::write(&f, &b[..b.len() - 5]).unwrap();
    fails(
        &["raycast", "--rays", e],
        &["rays", "rays-shadow.bin", "28 bytes"],
    );
    // Links to a device that never ends: refused without reading (before, each grew until
    // the address space ran out).
    #[cfg(unix)]
    for name in ["rays-shadow.bin", "scene.json"] {
        let f = export.join(name);
        let _ = std::fs::remove_file(&f);
        std::os::unix::fs::symlink("/dev/zero", &f).unwrap();
        fails(
            &["raycast", "--rays", e],
            &["rays", name, "not a regular file"],
        );
    }
}

/// A second export into a folder replaces the first one's meshes and rays (a scene of fewer
/// materials, an export without rays), `raycast` refuses ray files that are not the export's
/// (none recorded, or another count than `scene.json` records), and export-scene refuses a
/// ray count past its limit and an empty image before writing anything.
#[test]
fn a_second_export_replaces_the_first_and_stale_rays_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let export = tmp.path().join("export");
    let e = export.to_str().unwrap();
    let files = |dir: &Path| {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|f| f.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    };
    ok(&[
        "export-scene",
        "--scene",
        "barczak-area",
        "--rays",
        "10",
        "--out",
        e,
    ]);
    let first = files(&export);
    export_cornell(&export, 0);
    // Exactly scene.json and the meshes it lists.
    let meta: serde_json::Value =
        serde_json::from_slice(&std::fs::read(export.join("scene.json")).unwrap()).unwrap();
    let mut want: Vec<String> = (meta["materials"].as_array().unwrap().iter())
        .map(|m| m["file"].as_str().unwrap().to_string())
        .chain(["scene.json".to_string()])
        .collect();
    want.sort();
    assert_eq!(files(&export), want, "after {first:?}");
    let cast = tmp.path().join("cast");
    let refused = |expect: &[&str]| {
        let o = gibench(&["raycast", "--rays", e, "--out", cast.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success());
        for x in expect {
            assert!(err.contains(x), "'{x}' not in: {err}");
        }
        assert!(!cast.join("raycast.json").exists());
    };
    refused(&["scene.json", "records no rays", "--rays N"]);
    // Rays of another export (20) beside a scene.json that records 10.
    let other = tmp.path().join("other");
    export_cornell(&other, 20);
    export_cornell(&export, 10);
    std::fs::copy(
        other.join("rays-shadow.bin"),
        export.join("rays-shadow.bin"),
    )
    .unwrap();
    refused(&["rays-shadow.bin", "holds 20 rays", "records 10"]);
    for (args, expect) in [
        (&["--rays", "16777217"][..], &["rays", "limit"][..]),
        (
            &["--resolution", "0x1"][..],
            &["resolution", "at least 1"][..],
        ),
        (&["--frame", "10000001"][..], &["frame", "limit"][..]),
    ] {
        let out = tmp.path().join("refused");
        let mut all = vec!["export-scene", "--out", out.to_str().unwrap()];
        all.extend(args);
        let o = gibench(&all);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} succeeded");
        for x in expect {
            assert!(err.contains(x), "{args:?}: '{x}' not in: {err}");
        }
        assert!(!out.exists(), "{args:?} created {out:?}");
    }
}
