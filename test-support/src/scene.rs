//! Scenes for tests: a named scene of `scenes/`, or one built in code (quads, closed boxes) with
//! a descriptor's camera, light and settings.

use gibench_harness::glam::{Vec2, Vec3};
use gibench_harness::scene::assets::AssetPaths;
use gibench_harness::scene::descriptor::SceneDescriptor;
use gibench_harness::scene::{Material, Mesh, Scene, SceneExtent};

/// The scene `name` of `scenes/`.
pub fn load(name: &str) -> Scene {
    Scene::load_named(name, &AssetPaths::standard(None)).unwrap()
}

/// A minimal valid descriptor: camera at (0, 5, 5) looking at the origin, an omni light of
/// unit power at (0, 3, 0) (its mesh source is unused: the scenes below are built in code).
pub fn descriptor() -> SceneDescriptor {
    let json = r#"{
        "name": "test",
        "mesh": { "generated": "cornell-box" },
        "camera": { "fov_y_deg": 60, "near": 0.1,
                    "path": { "keys": [ { "time": 0, "position": [0, 5, 5], "target": [0, 0, 0] } ] } },
        "light": { "kind": "omni", "power": [1, 1, 1],
                   "path": { "keys": [ { "time": 0, "position": [0, 3, 0] } ] } },
        "settings": { "filter_distance": 1 }
    }"#;
    SceneDescriptor::from_json(std::path::Path::new("test.json"), json).unwrap()
}

/// An untextured material of colour `color`.
pub fn material(name: &str, color: Vec3) -> Material {
    Material::plain(name, color)
}

/// A scene of `mesh` (static, no movers) with `materials` under `descriptor`'s camera, light
/// and settings (its mesh source is not used).
pub fn scene_with(descriptor: SceneDescriptor, mesh: Mesh, materials: Vec<Material>) -> Scene {
    Scene {
        descriptor,
        extent: SceneExtent::of(&mesh),
        mesh,
        shadow_mesh: None,
        materials,
        textures: Vec::new(),
        movers: Vec::new(),
        gltf_lights: Vec::new(),
        patches: Vec::new(),
    }
}

/// [`scene_with`] the minimal [`descriptor`].
pub fn scene(mesh: Mesh, materials: Vec<Material>) -> Scene {
    scene_with(descriptor(), mesh, materials)
}

/// [`scene_with`] the descriptor `json`.
pub fn scene_from_json(json: &str, mesh: Mesh, materials: Vec<Material>) -> Scene {
    let descriptor = SceneDescriptor::from_json(std::path::Path::new("test.json"), json).unwrap();
    scene_with(descriptor, mesh, materials)
}

/// A face: four corners (x, y, z) and its normal.
pub type Face = ([(f32, f32, f32); 4], Vec3);

/// The unit cube's six faces as (corners, inward normal), corners counter-clockwise seen from
/// inside.
pub fn unit_box_faces() -> [Face; 6] {
    [
        (
            [(0., 0., 0.), (1., 0., 0.), (1., 0., 1.), (0., 0., 1.)],
            Vec3::Y,
        ),
        (
            [(0., 1., 0.), (0., 1., 1.), (1., 1., 1.), (1., 1., 0.)],
            Vec3::NEG_Y,
        ),
        (
            [(0., 0., 0.), (0., 0., 1.), (0., 1., 1.), (0., 1., 0.)],
            Vec3::X,
        ),
        (
            [(1., 0., 0.), (1., 1., 0.), (1., 1., 1.), (1., 0., 1.)],
            Vec3::NEG_X,
        ),
        (
            [(0., 0., 0.), (0., 1., 0.), (1., 1., 0.), (1., 0., 0.)],
            Vec3::Z,
        ),
        (
            [(0., 0., 1.), (1., 0., 1.), (1., 1., 1.), (0., 1., 1.)],
            Vec3::NEG_Z,
        ),
    ]
}

/// A closed box of `size` from the origin: six inward-facing quads of `material`.
pub fn closed_box_mesh(size: Vec3, material: u32) -> Mesh {
    let mut m = Mesh::default();
    let corner = |(x, y, z): (f32, f32, f32)| Vec3::new(x, y, z) * size;
    for (c, n) in unit_box_faces() {
        quad(&mut m, c.map(corner), n, material);
    }
    m
}

/// Appends quad `c` (corners in order) as two triangles with flat normal `n` and `material`.
pub fn quad(mesh: &mut Mesh, c: [Vec3; 4], n: Vec3, material: u32) {
    let base = mesh.positions.len() as u32;
    for (p, uv) in c.iter().zip([Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y]) {
        mesh.positions.push(*p);
        mesh.normals.push(n);
        mesh.uvs.push(uv);
        mesh.materials.push(material);
    }
    mesh.indices
        .extend([0, 1, 2, 0, 2, 3].into_iter().map(|i| base + i));
}
