//! The test scenes of Gaitatzes, Mavridis and Papaioannou 2010 (Table 1) that have no public
//! asset, generated in code: the paper gives their triangle counts and what they show, not their
//! geometry, so these are scenes of the same kind and about the same size.
//!
//! * [`test_scene`] — "test scene", 48 triangles: a closed room (12 triangles) with three
//!   blocks (12 each), lit from inside.
//! * [`room`] — "room", a room lit by the sun through a row of windows in one wall, so that only
//!   a patch of the opposite wall is lit directly and the rest of the room by bounces, with a
//!   staircase along the back wall (the paper's Figure 6: 704 triangles; ours counts
//!   [`ROOM_TRIANGLES`], 616).
//! * [`arena`] — "arena", an enclosed outdoor arena (ground, a ring wall, pillars, a stand) open
//!   to the sky (the paper's Figure 1 and 9: 10,219 triangles; ours counts about as many).
//!
//! Units are metres, +Y up; every surface is one-sided geometry shaded from both sides.

use glam::Vec3;

use super::maze::quad;
use super::{Material, Mesh};

fn material(name: &str, c: Vec3) -> Material {
    Material::plain(name, c)
}

/// An axis-aligned box from `lo` to `hi`, all six faces facing out, each face split into cells
/// of about `cell` when given.
fn cuboid(mesh: &mut Mesh, lo: Vec3, hi: Vec3, material: u32, cell: Option<f32>) {
    let v = Vec3::new;
    let (x0, y0, z0, x1, y1, z1) = (lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
    let faces = [
        (
            [v(x0, y1, z0), v(x0, y1, z1), v(x1, y1, z1), v(x1, y1, z0)],
            Vec3::Y,
        ),
        (
            [v(x0, y0, z0), v(x1, y0, z0), v(x1, y0, z1), v(x0, y0, z1)],
            Vec3::NEG_Y,
        ),
        (
            [v(x0, y0, z0), v(x0, y1, z0), v(x1, y1, z0), v(x1, y0, z0)],
            Vec3::NEG_Z,
        ),
        (
            [v(x1, y0, z1), v(x1, y1, z1), v(x0, y1, z1), v(x0, y0, z1)],
            Vec3::Z,
        ),
        (
            [v(x0, y0, z1), v(x0, y1, z1), v(x0, y1, z0), v(x0, y0, z0)],
            Vec3::NEG_X,
        ),
        (
            [v(x1, y0, z0), v(x1, y1, z0), v(x1, y1, z1), v(x1, y0, z1)],
            Vec3::X,
        ),
    ];
    for (c, n) in faces {
        quad(mesh, c, n, material, cell);
    }
}

/// The inside of an axis-aligned room from `lo` to `hi`: six faces facing in.
fn room_shell(mesh: &mut Mesh, lo: Vec3, hi: Vec3, materials: [u32; 3], cell: Option<f32>) {
    let v = Vec3::new;
    let (x0, y0, z0, x1, y1, z1) = (lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
    let [floor, ceiling, wall] = materials;
    quad(
        mesh,
        [v(x0, y0, z0), v(x0, y0, z1), v(x1, y0, z1), v(x1, y0, z0)],
        Vec3::Y,
        floor,
        cell,
    );
    quad(
        mesh,
        [v(x0, y1, z0), v(x1, y1, z0), v(x1, y1, z1), v(x0, y1, z1)],
        Vec3::NEG_Y,
        ceiling,
        cell,
    );
    quad(
        mesh,
        [v(x0, y0, z1), v(x0, y1, z1), v(x1, y1, z1), v(x1, y0, z1)],
        Vec3::NEG_Z,
        wall,
        cell,
    );
    quad(
        mesh,
        [v(x1, y0, z0), v(x1, y1, z0), v(x0, y1, z0), v(x0, y0, z0)],
        Vec3::Z,
        wall,
        cell,
    );
    quad(
        mesh,
        [v(x0, y0, z0), v(x0, y1, z0), v(x0, y1, z1), v(x0, y0, z1)],
        Vec3::X,
        wall,
        cell,
    );
    quad(
        mesh,
        [v(x1, y0, z1), v(x1, y1, z1), v(x1, y1, z0), v(x1, y0, z0)],
        Vec3::NEG_X,
        wall,
        cell,
    );
}

/// The 48-triangle test scene: a 6 × 3 × 6 m closed room and three blocks on its floor.
pub fn test_scene(tessellate: Option<f32>) -> (Mesh, Vec<Material>) {
    let mut mesh = Mesh::default();
    let v = Vec3::new;
    room_shell(
        &mut mesh,
        v(0.0, 0.0, 0.0),
        v(6.0, 3.0, 6.0),
        [0, 1, 2],
        tessellate,
    );
    cuboid(&mut mesh, v(0.8, 0.0, 3.4), v(2.2, 1.6, 4.8), 3, tessellate);
    cuboid(&mut mesh, v(3.6, 0.0, 3.8), v(5.0, 0.8, 5.2), 4, tessellate);
    cuboid(&mut mesh, v(2.6, 0.0, 1.0), v(3.4, 2.2, 1.8), 2, tessellate);
    let materials = vec![
        material("floor", v(0.6, 0.6, 0.6)),
        material("ceiling", v(0.75, 0.75, 0.75)),
        material("wall", v(0.7, 0.7, 0.7)),
        material("red", v(0.7, 0.15, 0.12)),
        material("green", v(0.15, 0.6, 0.2)),
    ];
    (mesh, materials)
}

/// Triangles of [`room`] untessellated (the paper's room has 704).
pub const ROOM_TRIANGLES: usize = 616;

/// The room: 8 × 4 × 8 m, three windows in the +X wall, a staircase of 12 steps along the +Z
/// wall up to a landing, floor and ceiling in 1 m cells (the walls' counts make up
/// [`ROOM_TRIANGLES`]).
pub fn room(tessellate: Option<f32>) -> (Mesh, Vec<Material>) {
    let mut mesh = Mesh::default();
    let v = Vec3::new;
    let (w, h, d) = (8.0f32, 4.0f32, 8.0f32);
    let cell = Some(tessellate.unwrap_or(1.0).min(1.0));
    let fine = tessellate.map(|t| t.min(1.0));
    // Floor and ceiling in 1 m cells (128 triangles each), the three plain walls in 1 m × 1 m
    // cells (64 each).
    quad(
        &mut mesh,
        [
            v(0.0, 0.0, 0.0),
            v(0.0, 0.0, d),
            v(w, 0.0, d),
            v(w, 0.0, 0.0),
        ],
        Vec3::Y,
        0,
        cell,
    );
    quad(
        &mut mesh,
        [v(0.0, h, 0.0), v(w, h, 0.0), v(w, h, d), v(0.0, h, d)],
        Vec3::NEG_Y,
        1,
        cell,
    );
    quad(
        &mut mesh,
        [v(0.0, 0.0, d), v(0.0, h, d), v(w, h, d), v(w, 0.0, d)],
        Vec3::NEG_Z,
        2,
        cell,
    );
    quad(
        &mut mesh,
        [
            v(w, 0.0, 0.0),
            v(w, h, 0.0),
            v(0.0, h, 0.0),
            v(0.0, 0.0, 0.0),
        ],
        Vec3::Z,
        2,
        cell,
    );
    quad(
        &mut mesh,
        [
            v(0.0, 0.0, 0.0),
            v(0.0, h, 0.0),
            v(0.0, h, d),
            v(0.0, 0.0, d),
        ],
        Vec3::X,
        3,
        cell,
    );
    // The window wall (x = w): three 1.2 m × 1.6 m windows, sills at 1.2 m, separated by
    // piers; the wall around them is quads: below, above and the four piers.
    let (sill, top) = (1.2f32, 2.8f32);
    let windows = [(1.2f32, 2.4f32), (3.4, 4.6), (5.6, 6.8)];
    let wall_quad = |mesh: &mut Mesh, z0: f32, z1: f32, y0: f32, y1: f32| {
        quad(
            mesh,
            [v(w, y0, z1), v(w, y1, z1), v(w, y1, z0), v(w, y0, z0)],
            Vec3::NEG_X,
            2,
            fine,
        );
    };
    wall_quad(&mut mesh, 0.0, d, 0.0, sill);
    wall_quad(&mut mesh, 0.0, d, top, h);
    let mut z = 0.0;
    for (a, b) in windows {
        wall_quad(&mut mesh, z, a, sill, top);
        z = b;
    }
    wall_quad(&mut mesh, z, d, sill, top);
    // The staircase: 12 steps of 0.25 m along the back wall (z from 6.8 to 8), rising along
    // -X from x = 7 to x = 2.2, then a landing; each step a closed box.
    let (step_w, step_h) = (0.4f32, 0.25f32);
    for i in 0..12 {
        let x1 = 7.0 - i as f32 * step_w;
        cuboid(
            &mut mesh,
            v(x1 - step_w, 0.0, 6.8),
            v(x1, (i + 1) as f32 * step_h, d),
            4,
            fine,
        );
    }
    cuboid(&mut mesh, v(0.0, 0.0, 6.8), v(2.2, 3.0, d), 4, fine);
    let materials = vec![
        material("floor", v(0.55, 0.45, 0.35)),
        material("ceiling", v(0.8, 0.8, 0.8)),
        material("wall", v(0.75, 0.72, 0.68)),
        material("left wall", v(0.7, 0.3, 0.25)),
        material("stairs", v(0.6, 0.6, 0.65)),
    ];
    (mesh, materials)
}

/// The arena: a 60 m disc of ground in 2 m cells, a ring wall of 96 segments (inner and outer
/// faces in 4 rows, and its top), 12 pillars of 16 sides inside it and a stepped stand on one
/// side; open to the sky.
pub fn arena(tessellate: Option<f32>) -> (Mesh, Vec<Material>) {
    let mut mesh = Mesh::default();
    let v = Vec3::new;
    let radius = 30.0f32;
    let ground_cell = Some(tessellate.unwrap_or(1.0).min(1.0));
    let fine = tessellate;
    // Ground: a 64 × 64 m square in 1 m cells (8192 triangles), under the ring.
    quad(
        &mut mesh,
        [
            v(-32.0, 0.0, -32.0),
            v(-32.0, 0.0, 32.0),
            v(32.0, 0.0, 32.0),
            v(32.0, 0.0, -32.0),
        ],
        Vec3::Y,
        0,
        ground_cell,
    );
    // The ring wall: 96 segments, 6 m high, 1 m thick; inner and outer faces in 3 rows of 2 m.
    let segments = 96;
    let (height, thickness) = (6.0f32, 1.0f32);
    let at = |r: f32, k: usize, y: f32| {
        let a = k as f32 / segments as f32 * std::f32::consts::TAU;
        v(r * a.cos(), y, r * a.sin())
    };
    for k in 0..segments {
        let (ri, ro) = (radius, radius + thickness);
        let mid = (k as f32 + 0.5) / segments as f32 * std::f32::consts::TAU;
        let out = v(mid.cos(), 0.0, mid.sin());
        for row in 0..3 {
            let (y0, y1) = (row as f32 * 2.0, row as f32 * 2.0 + 2.0);
            quad(
                &mut mesh,
                [
                    at(ri, k, y0),
                    at(ri, k, y1),
                    at(ri, k + 1, y1),
                    at(ri, k + 1, y0),
                ],
                -out,
                1,
                fine,
            );
            quad(
                &mut mesh,
                [
                    at(ro, k + 1, y0),
                    at(ro, k + 1, y1),
                    at(ro, k, y1),
                    at(ro, k, y0),
                ],
                out,
                1,
                fine,
            );
        }
        quad(
            &mut mesh,
            [
                at(ri, k, height),
                at(ro, k, height),
                at(ro, k + 1, height),
                at(ri, k + 1, height),
            ],
            Vec3::Y,
            1,
            fine,
        );
    }
    // Twelve pillars of 16 sides, 0.8 m in radius, 8 m high, on a circle of 20 m; sides in 2
    // rows, a fan on top.
    for p in 0..12 {
        let a = p as f32 / 12.0 * std::f32::consts::TAU;
        let c = v(20.0 * a.cos(), 0.0, 20.0 * a.sin());
        let sides = 16;
        let rim = |k: usize, y: f32| {
            let b = k as f32 / sides as f32 * std::f32::consts::TAU;
            c + v(0.8 * b.cos(), y, 0.8 * b.sin())
        };
        for k in 0..sides {
            let b = (k as f32 + 0.5) / sides as f32 * std::f32::consts::TAU;
            let n = v(b.cos(), 0.0, b.sin());
            for row in 0..2 {
                let (y0, y1) = (row as f32 * 4.0, row as f32 * 4.0 + 4.0);
                quad(
                    &mut mesh,
                    [rim(k + 1, y0), rim(k + 1, y1), rim(k, y1), rim(k, y0)],
                    n,
                    2,
                    fine,
                );
            }
            let base = mesh.positions.len() as u32;
            for q in [c + v(0.0, 8.0, 0.0), rim(k, 8.0), rim(k + 1, 8.0)] {
                mesh.positions.push(q);
                mesh.normals.push(Vec3::Y);
                mesh.uvs.push(glam::Vec2::ZERO);
                mesh.materials.push(2);
            }
            mesh.indices.extend([base, base + 2, base + 1]);
        }
    }
    // A stand of 8 steps on the -X side, inside the ring.
    for i in 0..8 {
        let x0 = -29.0 + i as f32 * 1.0;
        cuboid(
            &mut mesh,
            v(x0, 0.0, -8.0),
            v(x0 + 1.0, (8 - i) as f32 * 0.5, 8.0),
            3,
            fine,
        );
    }
    let materials = vec![
        material("ground", v(0.45, 0.4, 0.32)),
        material("ring wall", v(0.7, 0.65, 0.55)),
        material("pillars", v(0.75, 0.75, 0.78)),
        material("stand", v(0.35, 0.45, 0.6)),
    ];
    (mesh, materials)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scenes_have_the_papers_sizes() {
        assert_eq!(test_scene(None).0.triangle_count(), 48);
        assert_eq!(room(None).0.triangle_count(), ROOM_TRIANGLES);
        let arena = arena(None).0.triangle_count();
        assert!((9_000..=11_500).contains(&arena), "{arena}");
    }
}
