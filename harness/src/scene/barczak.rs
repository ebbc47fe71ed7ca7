//! The test scenes of Barczak 2006 (§5, Figure 5-1) generated in code: the thesis shows them
//! (a room with large area lights, a room with a table and the bunny, a room with four pillars)
//! but gives no geometry, so these are rooms of the same kind. Every surface is a planar
//! rectangle recorded as a [`Patch`] with the object it belongs to, as the light-mapped,
//! visibility-culled technique needs (§4.3): the room's shell (six objects that cannot shadow
//! each other, so not shadow casters, as the thesis leaves outer walls out of its occluders),
//! blocks, the table (one object: top and legs) and the pillars (one object each).
//!
//! * [`area_room`] — 6 × 3 × 6 m, two blocks on the floor to cast soft shadows from the area
//!   light (the descriptor's; the thesis has two).
//! * [`table_room`] — the room with a 1.6 × 1.0 m table, 0.9 m high, for the bunny to walk on.
//! * [`pillar_room`] — the room with four 0.4 m square pillars from floor to ceiling.
//! * [`casters`] — a room's shadow casters alone (its shadow mesh: the shell left out).
//! * [`torus`] — the thesis' 820-vertex torus mover (41 × 20 vertices), 0.3 m ring, 0.1 m tube.
//!
//! Units are metres, +Y up. Walls: red at x = 0, blue at x = 6 (the thesis' colour bleeding),
//! the rest light grey.

use glam::{Vec2, Vec3};

use super::maze::quad;
use super::{Material, Mesh, Patch};

const W: f32 = 6.0;
const H: f32 = 3.0;

/// A mesh with its patches being built.
struct Builder {
    mesh: Mesh,
    patches: Vec<Patch>,
    cell: Option<f32>,
}

impl Builder {
    /// A rectangle (corners counter-clockwise seen from `normal`'s side) of `object`.
    fn rect(
        &mut self,
        c: [Vec3; 4],
        normal: Vec3,
        material: u32,
        object: u32,
        levels: u32,
        casts: bool,
    ) {
        quad(&mut self.mesh, c, normal, material, self.cell);
        self.patches.push(Patch {
            corners: c,
            normal,
            object,
            material,
            levels,
            casts_shadows: casts,
            chart: None,
        });
    }

    /// An axis-aligned box from `lo` to `hi` of `object`; `bottom` whether its underside is a
    /// surface (not when it stands on the floor or reaches the ceiling: `top` likewise).
    #[allow(clippy::too_many_arguments)]
    fn cuboid(
        &mut self,
        lo: Vec3,
        hi: Vec3,
        material: u32,
        object: u32,
        levels: u32,
        top: bool,
        bottom: bool,
    ) {
        let v = Vec3::new;
        let (x0, y0, z0, x1, y1, z1) = (lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
        if top {
            self.rect(
                [v(x0, y1, z0), v(x0, y1, z1), v(x1, y1, z1), v(x1, y1, z0)],
                Vec3::Y,
                material,
                object,
                levels,
                true,
            );
        }
        if bottom {
            self.rect(
                [v(x0, y0, z0), v(x1, y0, z0), v(x1, y0, z1), v(x0, y0, z1)],
                Vec3::NEG_Y,
                material,
                object,
                levels,
                true,
            );
        }
        self.rect(
            [v(x0, y0, z0), v(x0, y1, z0), v(x1, y1, z0), v(x1, y0, z0)],
            Vec3::NEG_Z,
            material,
            object,
            levels,
            true,
        );
        self.rect(
            [v(x1, y0, z1), v(x1, y1, z1), v(x0, y1, z1), v(x0, y0, z1)],
            Vec3::Z,
            material,
            object,
            levels,
            true,
        );
        self.rect(
            [v(x0, y0, z1), v(x0, y1, z1), v(x0, y1, z0), v(x0, y0, z0)],
            Vec3::NEG_X,
            material,
            object,
            levels,
            true,
        );
        self.rect(
            [v(x1, y0, z0), v(x1, y1, z0), v(x1, y1, z1), v(x1, y0, z1)],
            Vec3::X,
            material,
            object,
            levels,
            true,
        );
    }
}

/// Materials: 0 floor, 1 ceiling, 2 wall, 3 red wall, 4 blue wall, 5 objects.
fn materials() -> Vec<Material> {
    vec![
        Material::plain("floor", Vec3::splat(0.6)),
        Material::plain("ceiling", Vec3::splat(0.75)),
        Material::plain("wall", Vec3::splat(0.7)),
        Material::plain("red wall", Vec3::new(0.63, 0.065, 0.05)),
        Material::plain("blue wall", Vec3::new(0.1, 0.15, 0.6)),
        Material::plain("grey", Vec3::splat(0.5)),
    ]
}

/// The room's shell, objects 0–5: floor (split three times), ceiling (once), walls (twice).
fn shell(tessellate: Option<f32>) -> Builder {
    let mut b = Builder {
        mesh: Mesh::default(),
        patches: Vec::new(),
        cell: tessellate,
    };
    let v = Vec3::new;
    b.rect(
        [v(0., 0., 0.), v(0., 0., W), v(W, 0., W), v(W, 0., 0.)],
        Vec3::Y,
        0,
        0,
        3,
        false,
    );
    b.rect(
        [v(0., H, 0.), v(W, H, 0.), v(W, H, W), v(0., H, W)],
        Vec3::NEG_Y,
        1,
        1,
        1,
        false,
    );
    b.rect(
        [v(0., 0., 0.), v(0., H, 0.), v(0., H, W), v(0., 0., W)],
        Vec3::X,
        3,
        2,
        2,
        false,
    );
    b.rect(
        [v(W, 0., 0.), v(W, 0., W), v(W, H, W), v(W, H, 0.)],
        Vec3::NEG_X,
        4,
        3,
        2,
        false,
    );
    b.rect(
        [v(0., 0., 0.), v(W, 0., 0.), v(W, H, 0.), v(0., H, 0.)],
        Vec3::Z,
        2,
        4,
        2,
        false,
    );
    b.rect(
        [v(0., 0., W), v(0., H, W), v(W, H, W), v(W, 0., W)],
        Vec3::NEG_Z,
        2,
        5,
        2,
        false,
    );
    b
}

/// A generated room: its mesh, materials and patches.
pub type Room = (Mesh, Vec<Material>, Vec<Patch>);

fn finish(b: Builder) -> Room {
    (b.mesh, materials(), b.patches)
}

/// The room with large area lights: two blocks on the floor (objects 6, 7).
pub fn area_room(tessellate: Option<f32>) -> Room {
    let mut b = shell(tessellate);
    let v = Vec3::new;
    b.cuboid(v(1.2, 0., 1.8), v(2.2, 0.8, 2.8), 5, 6, 1, true, false);
    b.cuboid(v(3.8, 0., 3.4), v(4.5, 1.6, 4.1), 5, 7, 1, true, false);
    finish(b)
}

/// The room with a table (object 6: a 1.6 × 1.0 × 0.06 m top at 0.9 m on four 6 cm legs).
pub fn table_room(tessellate: Option<f32>) -> Room {
    let mut b = shell(tessellate);
    let v = Vec3::new;
    let (x0, z0, x1, z1) = (2.2, 2.5, 3.8, 3.5);
    b.cuboid(v(x0, 0.84, z0), v(x1, 0.9, z1), 5, 6, 2, true, true);
    for (x, z) in [
        (x0, z0),
        (x1 - 0.06, z0),
        (x0, z1 - 0.06),
        (x1 - 0.06, z1 - 0.06),
    ] {
        b.cuboid(
            v(x, 0., z),
            v(x + 0.06, 0.84, z + 0.06),
            5,
            6,
            0,
            false,
            false,
        );
    }
    finish(b)
}

/// The room with four pillars (objects 6–9), floor to ceiling.
pub fn pillar_room(tessellate: Option<f32>) -> Room {
    let mut b = shell(tessellate);
    let v = Vec3::new;
    for (i, (x, z)) in [(1.6, 1.6), (4.4, 1.6), (1.6, 4.4), (4.4, 4.4)]
        .into_iter()
        .enumerate()
    {
        b.cuboid(
            v(x - 0.2, 0., z - 0.2),
            v(x + 0.2, H, z + 0.2),
            5,
            6 + i as u32,
            1,
            false,
            false,
        );
    }
    finish(b)
}

/// The shadow casters of a room built by `room`: only its patches that cast shadows (split
/// into cells of about `tessellate`), as the thesis leaves the outer walls, which cannot block
/// other surfaces, out of its occluders (§4.2.2). The shell of a room is convex, so leaving it
/// out of a shadow map changes no lookup inside the room; it lets a map's octahedral faces
/// without a caster go undrawn.
pub fn casters(room: fn(Option<f32>) -> Room, tessellate: Option<f32>) -> Room {
    let (_, materials, patches) = room(None);
    let kept: Vec<Patch> = patches.into_iter().filter(|p| p.casts_shadows).collect();
    let mut mesh = Mesh::default();
    for p in &kept {
        quad(&mut mesh, p.corners, p.normal, p.material, tessellate);
    }
    (mesh, materials, kept)
}

/// Vertices around the ring and around the tube of [`torus`].
pub const TORUS_SEGMENTS: (u32, u32) = (41, 20);

/// The 820-vertex torus (41 × 20, ring radius 0.3 m, tube 0.1 m) around +Y at the origin.
pub fn torus() -> (Mesh, Vec<Material>) {
    let (n_ring, n_tube) = TORUS_SEGMENTS;
    let (big, small) = (0.3f32, 0.1f32);
    let mut mesh = Mesh::default();
    for i in 0..n_ring {
        let a = i as f32 / n_ring as f32 * std::f32::consts::TAU;
        let centre = Vec3::new(a.cos(), 0.0, a.sin()) * big;
        let out = Vec3::new(a.cos(), 0.0, a.sin());
        for j in 0..n_tube {
            let b = j as f32 / n_tube as f32 * std::f32::consts::TAU;
            let n = out * b.cos() + Vec3::Y * b.sin();
            mesh.positions.push(centre + n * small);
            mesh.normals.push(n);
            mesh.uvs.push(Vec2::new(
                i as f32 / n_ring as f32,
                j as f32 / n_tube as f32,
            ));
            mesh.materials.push(0);
        }
    }
    for i in 0..n_ring {
        for j in 0..n_tube {
            let at = |i: u32, j: u32| (i % n_ring) * n_tube + (j % n_tube);
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            mesh.indices.extend([a, c, b, a, d, c]);
        }
    }
    (
        mesh,
        vec![Material::plain("torus", Vec3::new(0.8, 0.7, 0.2))],
    )
}
