//! Scene loading end to end: glTF files from the shared asset directory, built-in descriptors,
//! error reporting for bad files, and the BVH and animation over real scenes.
//!
//! Tests that need an asset which is not on the search path print a note and pass, so the
//! suite still runs on a machine without the shared scenes.

use std::path::Path;

use gibench_harness::cpu::bvh::SceneBvh;
use gibench_harness::glam::Vec3;
use gibench_harness::scene::anim::FrameClock;
use gibench_harness::scene::assets::AssetPaths;
use gibench_harness::scene::gltf_load::{load_gltf, load_gltf_with_offsets};
use gibench_harness::scene::{descriptor::builtin_names, PunctualKind, Scene, SceneDescriptor};
use gibench_harness::Error;

fn asset(name: &str) -> Option<std::path::PathBuf> {
    match AssetPaths::standard(None).find(name) {
        Ok(p) => Some(p),
        Err(e) => {
            eprintln!("skipping: {e}");
            None
        }
    }
}

fn bad_file_message(e: Error, path: &Path) -> String {
    match e {
        Error::BadFile { path: p, message } => {
            assert_eq!(p, path);
            message
        }
        other => panic!("expected BadFile for {}, got {other:?}", path.display()),
    }
}

#[test]
fn gltf_cornell_glb() {
    let Some(path) = asset("cornell.glb") else {
        return;
    };
    let g = load_gltf(&path, 0).unwrap();
    assert_eq!(g.mesh.triangle_count(), 34);
    assert_eq!(g.materials.len(), 4);
    assert!(g.textures.is_empty() && g.lights.is_empty());
    let (lo, hi) = g.mesh.bounds();
    assert!(
        lo.abs_diff_eq(Vec3::ZERO, 1e-3) && hi.abs_diff_eq(Vec3::new(556.0, 548.8, 559.2), 1e-2),
        "{lo} {hi}"
    );
    let n = g.mesh.positions.len();
    assert!(g.mesh.normals.len() == n && g.mesh.uvs.len() == n && g.mesh.materials.len() == n);
    assert!(g
        .mesh
        .normals
        .iter()
        .all(|v| (v.length() - 1.0).abs() < 1e-4));
    let names: Vec<&str> = g.materials.iter().map(|m| m.name.as_str()).collect();
    for want in ["white", "box", "red", "green"] {
        assert!(names.contains(&want), "{names:?}");
    }
    // Offsets apply to every per-vertex material index and to texture indices.
    let shifted = load_gltf_with_offsets(&path, 7, 3).unwrap();
    assert!(shifted.mesh.materials.iter().all(|&m| (7..11).contains(&m)));
    assert_eq!(shifted.materials, g.materials);
}

#[test]
fn gltf_punctual_light() {
    let Some(path) = asset("lights-punctual-cubes.glb") else {
        return;
    };
    let g = load_gltf(&path, 0).unwrap();
    assert_eq!(g.mesh.triangle_count(), 36);
    assert_eq!(g.lights.len(), 1);
    let l = &g.lights[0];
    assert_eq!(l.kind, PunctualKind::Point);
    assert!((l.intensity - 79.577).abs() < 1e-2, "{}", l.intensity);
    assert_eq!(l.color, Vec3::ONE);
    assert!(l.position.is_finite() && (l.direction.length() - 1.0).abs() < 1e-5);
    // World-space bounds from the README (node transforms applied).
    let (lo, hi) = g.mesh.bounds();
    assert!(
        lo.abs_diff_eq(Vec3::new(-4.284, -1.938, -2.994), 2e-3),
        "{lo}"
    );
    assert!(hi.abs_diff_eq(Vec3::new(4.603, 3.591, 3.639), 2e-3), "{hi}");
}

#[test]
fn gltf_sponza_textures() {
    let Some(path) = asset("sponza.glb") else {
        return;
    };
    let g = load_gltf(&path, 0).unwrap();
    assert_eq!(g.mesh.triangle_count(), 66_445);
    assert_eq!(g.materials.len(), 19);
    assert_eq!(g.textures.len(), 10);
    for t in &g.textures {
        assert_eq!(
            t.rgba8.len(),
            t.width as usize * t.height as usize * 4,
            "{}",
            t.name
        );
    }
    let textured: Vec<_> = g.materials.iter().filter(|m| m.texture.is_some()).collect();
    assert_eq!(textured.len(), 17);
    for m in textured {
        assert!(m.texture.unwrap() < g.textures.len());
        assert_ne!(m.average_color, m.base_color, "{}", m.name);
        assert!(
            m.average_color.cmple(m.base_color).all() && m.average_color.cmpgt(Vec3::ZERO).all(),
            "{}",
            m.name
        );
    }
    assert!(g
        .mesh
        .uvs
        .iter()
        .any(|uv| *uv != gibench_harness::glam::Vec2::ZERO));
}

#[test]
fn gltf_bad_files_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let garbage = dir.path().join("garbage.glb");
    let mut x = 0x1234_5678u32;
    let bytes: Vec<u8> = (0..4096)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x as u8
        })
        .collect();
    std::fs::write(&garbage, &bytes).unwrap();
    let m = bad_file_message(load_gltf(&garbage, 0).unwrap_err(), &garbage);
    assert!(m.starts_with("not a valid glTF binary: "), "{m}");
    let shown = load_gltf(&garbage, 0).unwrap_err().to_string();
    assert!(shown.contains("garbage.glb"), "{shown}");

    let empty = dir.path().join("empty.glb");
    std::fs::write(&empty, b"").unwrap();
    bad_file_message(load_gltf(&empty, 0).unwrap_err(), &empty);

    // A glTF header followed by garbage.
    let mut header = b"glTF\x02\x00\x00\x00\x00\x10\x00\x00".to_vec();
    header.extend_from_slice(&bytes[..64]);
    let fake = dir.path().join("fake.glb");
    std::fs::write(&fake, &header).unwrap();
    bad_file_message(load_gltf(&fake, 0).unwrap_err(), &fake);

    // A file with no triangles.
    let no_tris = dir.path().join("empty-scene.gltf");
    std::fs::write(
        &no_tris,
        r#"{"asset":{"version":"2.0"},"scenes":[{"nodes":[]}],"scene":0}"#,
    )
    .unwrap();
    let m = bad_file_message(load_gltf(&no_tris, 0).unwrap_err(), &no_tris);
    assert!(m.contains("no triangles"), "{m}");

    // A missing file.
    assert!(matches!(
        load_gltf(&dir.path().join("nope.glb"), 0),
        Err(Error::Io { .. })
    ));

    let Some(cornell) = asset("cornell.glb") else {
        return;
    };
    let full = std::fs::read(&cornell).unwrap();
    for keep in [full.len() - 1, full.len() / 2, full.len() - 100, 20, 12] {
        let truncated = dir.path().join(format!("truncated-{keep}.glb"));
        std::fs::write(&truncated, &full[..keep]).unwrap();
        let m = bad_file_message(load_gltf(&truncated, 0).unwrap_err(), &truncated);
        assert!(m.starts_with("not a valid glTF binary: "), "{keep}: {m}");
    }
}

/// Standard base64 (with padding), for embedding buffers in test glTF files.
fn base64(data: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in data.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                s.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

#[test]
fn gltf_transforms_flat_normals_and_default_material() {
    // One non-indexed triangle without normals, UVs or material, used by a translated node and
    // by a mirrored child of it; plus a line primitive that is skipped.
    let tri: Vec<u8> = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
        .iter()
        .flat_map(|f| f.to_le_bytes())
        .collect();
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
        "nodes":[{{"mesh":0,"translation":[10,0,0],"children":[1]}},{{"mesh":0,"scale":[-1,1,1]}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}},{{"attributes":{{"POSITION":0}},"mode":1}}]}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}}],
        "buffers":[{{"byteLength":36,"uri":"data:application/octet-stream;base64,{}"}}]}}"#,
        base64(&tri)
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tri.gltf");
    std::fs::write(&path, json).unwrap();
    let g = load_gltf(&path, 5).unwrap();
    assert_eq!(g.mesh.triangle_count(), 2);
    assert_eq!(g.materials.len(), 1);
    assert_eq!(g.materials[0].base_color, Vec3::splat(0.8));
    assert!(g.mesh.materials.iter().all(|&m| m == 5));
    assert_eq!(
        g.mesh.triangle(0),
        [
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::new(11.0, 0.0, 0.0),
            Vec3::new(10.0, 1.0, 0.0)
        ]
    );
    let mirrored = g.mesh.triangle(1);
    for p in [
        Vec3::new(10.0, 0.0, 0.0),
        Vec3::new(9.0, 0.0, 0.0),
        Vec3::new(10.0, 1.0, 0.0),
    ] {
        assert!(mirrored.contains(&p), "{mirrored:?}");
    }
    for t in 0..2 {
        // Flat normals, and the winding stays counter-clockwise around them (also when mirrored).
        let [a, b, c] = g.mesh.triangle(t);
        let n = g.mesh.normals[g.mesh.indices[3 * t] as usize];
        assert!(n.abs_diff_eq(Vec3::Z, 1e-6), "{n}");
        assert!((b - a).cross(c - a).dot(n) > 0.0);
    }
    assert!(g
        .mesh
        .uvs
        .iter()
        .all(|uv| *uv == gibench_harness::glam::Vec2::ZERO));
}

#[test]
fn missing_asset_lists_searched_dirs() {
    let assets = AssetPaths::standard(Some(Path::new("/tmp/gibench-extra-assets")));
    match assets.find("no-such-scene.glb") {
        Err(Error::AssetNotFound { name, searched }) => {
            assert_eq!(name, "no-such-scene.glb");
            assert!(
                searched.contains("/tmp/gibench-extra-assets")
                    && searched.contains("shared/scenes"),
                "{searched}"
            );
        }
        other => panic!("{other:?}"),
    }
    let mut desc = SceneDescriptor::resolve("cornell-gltf").unwrap();
    desc.mesh.file = Some("no-such-scene.glb".into());
    assert!(matches!(
        Scene::load(&desc, &assets),
        Err(Error::AssetNotFound { .. })
    ));
}

#[test]
fn scene_load_cornell_variants() {
    let assets = AssetPaths::standard(None);
    let s = Scene::load_named("cornell", &assets).unwrap();
    assert_eq!(s.mesh.triangle_count(), 32);
    assert_eq!(s.materials.len(), 4);
    assert!(s.shadow_caster_mesh().triangle_count() > 4000);
    let rho = s.average_reflectance();
    assert!(rho.x > 0.5 && rho.x < 0.73, "{rho}");

    if asset("cornell.glb").is_some() && asset("cornell-tess.glb").is_some() {
        let g = Scene::load_named("cornell-gltf", &assets).unwrap();
        assert_eq!(g.mesh.triangle_count(), 34);
        assert_eq!(g.shadow_caster_mesh().triangle_count(), 4408);
        // The shadow mesh shares the static mesh's materials (matched by name).
        assert_eq!(g.materials.len(), 4);
        let shadow = g.shadow_mesh.as_ref().unwrap();
        assert!(shadow
            .materials
            .iter()
            .all(|&m| (m as usize) < g.materials.len()));
    }

    if asset("bunny-low.glb").is_some() {
        let b = Scene::load_named("cornell-bunny", &assets).unwrap();
        assert_eq!(b.movers.len(), 1);
        let bunny = &b.movers[0];
        assert_eq!(bunny.mesh.triangle_count(), 3674);
        let (lo, hi) = bunny.mesh.bounds();
        let height = hi.y - lo.y;
        assert!((140.0..160.0).contains(&height), "bunny height {height}");
        assert!(
            bunny.mesh.materials.iter().all(|&m| m == 4),
            "mover materials follow the static ones"
        );
        assert_eq!(b.materials.len(), 5);
        // The bunny stands on the floor inside the box in every frame, clear of the blocks.
        let clock = FrameClock::new(&b.descriptor);
        let bvh = SceneBvh::new(&b.mesh);
        for i in (0..300).step_by(10) {
            let m = clock.frame(i).movers[0];
            for p in bunny.mesh.positions.iter().step_by(37) {
                let w = m.transform_point3(*p);
                assert!(
                    w.x > 0.0 && w.x < 549.0 && w.z > 0.0 && w.z < 559.0 && w.y >= -1e-3,
                    "frame {i}: {w}"
                );
                // Nothing of the static mesh between the bunny's centre and its vertices.
                let centre = m.transform_point3(Vec3::new(0.0, 75.0, 0.0));
                assert!(
                    !bvh.occluded(centre, w, 1e-4),
                    "frame {i}: bunny intersects the box at {w}"
                );
            }
        }
    }
}

#[test]
fn builtin_scenes_load_and_are_sensible() {
    let assets = AssetPaths::standard(None);
    for name in builtin_names() {
        let desc = SceneDescriptor::resolve(name).unwrap();
        let files: Vec<&String> = std::iter::once(&desc.mesh)
            .chain(desc.shadow_mesh.iter())
            .chain(desc.movers.iter().map(|m| &m.mesh))
            .filter_map(|m| m.file.as_ref())
            .collect();
        if files.iter().any(|f| asset(f).is_none()) {
            continue;
        }
        let scene = Scene::load(&desc, &assets).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(scene.mesh.triangle_count() > 0);
        for t in 0..scene.mesh.triangle_count() {
            assert!((scene.mesh.triangle_material(t) as usize) < scene.materials.len());
        }
        let bvh = SceneBvh::new(&scene.mesh);
        let (lo, hi) = scene.mesh.bounds();
        let clock = FrameClock::new(&desc);
        for i in (0..600).step_by(15) {
            let f = clock.frame(i);
            // The camera sees geometry straight ahead; the light is inside the bounds and not
            // embedded in a surface; a spot lights the scene along its axis (or through a hole:
            // allow a few misses).
            assert!(
                bvh.closest_hit(f.camera.position, f.camera.forward(), 0.0, f32::INFINITY)
                    .is_some(),
                "{name} frame {i}: camera looks at nothing"
            );
            if f.light.is_directional() {
                // The sun: only its direction counts; it reaches into the scene.
                let (centre, _) = f.light.sun_disc(&scene.extent);
                let into = (scene.extent.centre - centre).normalize();
                assert!(into.dot(f.light.axis()) > 0.99, "{name} frame {i}");
                continue;
            }
            assert!(
                f.light.position.cmpge(lo).all() && f.light.position.cmple(hi).all(),
                "{name} frame {i}"
            );
            for d in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
                if let Some(h) = bvh.closest_hit(f.light.position, d, 0.0, f32::INFINITY) {
                    assert!(
                        h.t > 1e-3 * (hi - lo).max_element(),
                        "{name} frame {i}: light touches a surface"
                    );
                }
            }
        }
    }
}

#[test]
fn tessellated_mesh_keeps_area_and_bounds_edges() {
    let (mesh, _) = gibench_harness::scene::cornell::cornell_box(None);
    let area = |m: &gibench_harness::scene::Mesh| -> f64 {
        (0..m.triangle_count())
            .map(|t| {
                let [a, b, c] = m.triangle(t);
                0.5 * (b - a).cross(c - a).length() as f64
            })
            .sum()
    };
    let t = mesh.tessellated(40.0);
    assert!(t.triangle_count() > 10 * mesh.triangle_count());
    assert!((area(&t) - area(&mesh)).abs() < 1e-4 * area(&mesh));
    for k in 0..t.triangle_count() {
        let [a, b, c] = t.triangle(k);
        for e in [(b - a).length(), (c - b).length(), (a - c).length()] {
            assert!(e <= 40.0 + 1e-3, "edge {e}");
        }
        // Same orientation as the source: normals still face the box's interior side.
        let n = (b - a).cross(c - a);
        let i = t.indices[3 * k] as usize;
        assert!(n.dot(t.normals[i]) > 0.0);
    }
    // Already small triangles are kept as they are.
    assert_eq!(
        mesh.tessellated(1e6).triangle_count(),
        mesh.triangle_count()
    );
}

#[test]
#[ignore = "prints triangle counts of Sibenik tessellations; used to choose sibenik.json's shadow_mesh"]
fn sibenik_tessellation_counts() {
    let scene = Scene::load_named("sibenik", &AssetPaths::standard(None)).unwrap();
    for edge in [1.5f32, 1.9, 2.0] {
        eprintln!(
            "edge {edge}: {} triangles",
            scene.mesh.tessellated(edge).triangle_count()
        );
    }
}

/// Barczak's rooms are exactly covered by their recorded patches: every patch a rectangle facing
/// its normal (corners counter-clockwise from the front), patch areas summing to the mesh's,
/// every triangle inside one patch — also when the mesh is split finely for paraboloid maps;
/// the room's shell casts no shadows, everything in it does.
#[test]
fn barczak_rooms_are_covered_by_their_patches() {
    use gibench_harness::scene::barczak;
    for (name, build) in [
        ("area", barczak::area_room as fn(Option<f32>) -> _),
        ("table", barczak::table_room),
        ("pillars", barczak::pillar_room),
    ] {
        for tessellate in [None, Some(0.25)] {
            let (mesh, materials, patches) = build(tessellate);
            let mut patch_area = 0.0f64;
            for (i, p) in patches.iter().enumerate() {
                let [a, b, c, d] = p.corners;
                let (u, v) = (b - a, d - a);
                assert!(
                    u.dot(v).abs() < 1e-5 * u.length() * v.length(),
                    "{name} patch {i}: not a rectangle"
                );
                assert!(
                    (a + u + v - c).length() < 1e-5,
                    "{name} patch {i}: not a rectangle"
                );
                assert!(
                    u.cross(v).normalize().dot(p.normal) > 0.9999,
                    "{name} patch {i}: faces away from its normal"
                );
                assert!((p.material as usize) < materials.len());
                assert_eq!(p.casts_shadows, p.object >= 6, "{name} patch {i}");
                patch_area += u.cross(v).length() as f64;
            }
            let mut mesh_area = 0.0f64;
            for t in 0..mesh.triangle_count() {
                let [p0, p1, p2] = mesh.triangle(t);
                mesh_area += 0.5 * (p1 - p0).cross(p2 - p0).length() as f64;
                let centre = (p0 + p1 + p2) / 3.0;
                let inside = patches.iter().any(|p| {
                    let [a, b, _, d] = p.corners;
                    let (u, v, w) = (b - a, d - a, centre - a);
                    let (s, t) = (w.dot(u) / u.length_squared(), w.dot(v) / v.length_squared());
                    p.normal.dot(w).abs() < 1e-5
                        && (0.0..=1.0).contains(&s)
                        && (0.0..=1.0).contains(&t)
                });
                assert!(inside, "{name}: triangle {t} lies in no patch");
            }
            assert!(
                (patch_area - mesh_area).abs() < 1e-5 * mesh_area,
                "{name}: patches {patch_area} m², mesh {mesh_area} m²"
            );
            let objects: std::collections::BTreeSet<u32> =
                patches.iter().map(|p| p.object).collect();
            assert_eq!(
                objects,
                (0..objects.len() as u32).collect(),
                "{name}: object ids not contiguous"
            );
        }
    }
    // Loaded through the descriptor, the static patches come along (the pillar room's mover is
    // generated, so no asset is needed).
    let scene = Scene::load_named("barczak-pillars", &AssetPaths::standard(None)).unwrap();
    assert_eq!(scene.patches.len(), 6 + 4 * 4);
    assert_eq!(scene.movers[0].mesh.positions.len(), 820);
}

/// The torus mover: 820 vertices (41 × 20, as the thesis'), closed, its triangles facing along
/// its normals.
#[test]
fn torus_mover_is_closed_with_820_vertices() {
    let (mesh, _) = gibench_harness::scene::barczak::torus();
    assert_eq!(mesh.positions.len(), 820);
    assert_eq!(mesh.triangle_count(), 1640);
    let mut edges = std::collections::HashMap::new();
    for t in 0..mesh.triangle_count() {
        let i = &mesh.indices[3 * t..3 * t + 3];
        for k in 0..3 {
            let (a, b) = (i[k].min(i[(k + 1) % 3]), i[k].max(i[(k + 1) % 3]));
            *edges.entry((a, b)).or_insert(0) += 1;
        }
        let [p0, p1, p2] = mesh.triangle(t);
        let n = (p1 - p0).cross(p2 - p0);
        assert!(
            n.dot(mesh.normals[i[0] as usize]) > 0.0,
            "triangle {t} faces inwards"
        );
    }
    assert!(edges.values().all(|n| *n == 2), "the torus has open edges");
}

#[test]
#[ignore = "prints chart counts and times of the glTF scenes; used to size Barczak on any mesh"]
fn chart_counts() {
    use gibench_harness::scene::charts::{charts, ChartSettings};
    for name in ["sibenik", "sponza", "maze", "conference", "cornell-gltf"] {
        let Ok(scene) = Scene::load_named(name, &AssetPaths::standard(None)) else {
            println!("{name}: not found");
            continue;
        };
        let t = std::time::Instant::now();
        let c = charts(&scene.mesh, ChartSettings::for_mesh(&scene.mesh));
        let convex = c.iter().filter(|c| c.convex).count();
        let single = c.iter().filter(|c| c.triangles.len() == 1).count();
        let rect: f32 = c
            .iter()
            .map(|c| {
                (c.rectangle[1] - c.rectangle[0]).length()
                    * (c.rectangle[3] - c.rectangle[0]).length()
            })
            .sum();
        let area: f32 = c.iter().map(|c| c.area).sum();
        println!(
            "{name}: {} triangles, {} charts ({convex} convex, {single} of one triangle), rectangles/area {:.2}, {:.2} s",
            scene.mesh.triangle_count(),
            c.len(),
            rect / area,
            t.elapsed().as_secs_f64()
        );
    }
}
