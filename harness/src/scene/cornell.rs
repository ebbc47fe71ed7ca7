//! The Cornell box, generated in code from the measured data published by the Cornell
//! University Program of Computer Graphics (millimetres, +Y up; seen from the classic camera at
//! (278, 273, −800) looking towards +Z, the red wall (x ≈ 556) is on the left).
//!
//! It has the classic 32 triangles: floor, ceiling, back wall, red and green walls, the
//! luminaire patch (as a non-emitting white quad 0.1 mm below the ceiling, facing down; the
//! benchmark's light comes from the descriptor) and the short and tall blocks (5 quads each,
//! no bottoms). Every quad has one flat normal: walls, floor, ceiling and the luminaire face the
//! inside of the box, block faces face away from their block. Triangles are wound
//! counter-clockwise seen from the side their normal points to.

use glam::{Vec2, Vec3};

use super::{Material, Mesh};

/// Material indices of [`cornell_box`]'s materials.
pub const WHITE: u32 = 0;
/// The blocks' material (same colour as [`WHITE`], separate so techniques can tell them apart).
pub const BOX: u32 = 1;
/// The red wall (x ≈ 556).
pub const RED: u32 = 2;
/// The green wall (x = 0).
pub const GREEN: u32 = 3;

/// The largest number of cells along one edge of a quad when tessellating; keeps a tiny cell
/// size from exhausting memory (at most 2 · 256² triangles per quad). A scene that asks for
/// finer cells is refused when it loads (the descriptor's validation, against the generated
/// mesh's bounding-box diagonal); the generators' own cap only guards direct callers.
pub const MAX_CELLS_PER_EDGE: u32 = 256;

/// Which way a quad's normal must point.
#[derive(Clone, Copy)]
enum Facing {
    /// Roughly along this direction (walls: towards the inside of the box).
    Along(Vec3),
    /// Away from this point (block faces: away from the block's centre).
    AwayFrom(Vec3),
}

/// A quad: its corners in the published order, its material and which way it faces.
type Quad = ([Vec3; 4], u32, Facing);

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

/// (corners, material, facing) for every quad, corners in the published order: the room, the
/// short block, the tall block.
fn quads() -> Vec<Quad> {
    let mut quads = room();
    quads.extend(short_block());
    quads.extend(tall_block());
    quads
}

/// Floor, luminaire patch, ceiling, back, right and left walls, all facing the inside.
fn room() -> Vec<Quad> {
    vec![
        // Floor.
        (
            [
                v(552.8, 0.0, 0.0),
                v(0.0, 0.0, 0.0),
                v(0.0, 0.0, 559.2),
                v(549.6, 0.0, 559.2),
            ],
            WHITE,
            Facing::Along(Vec3::Y),
        ),
        // Luminaire patch, just below the ceiling, facing down.
        (
            [
                v(343.0, 548.7, 227.0),
                v(343.0, 548.7, 332.0),
                v(213.0, 548.7, 332.0),
                v(213.0, 548.7, 227.0),
            ],
            WHITE,
            Facing::Along(Vec3::NEG_Y),
        ),
        // Ceiling.
        (
            [
                v(556.0, 548.8, 0.0),
                v(556.0, 548.8, 559.2),
                v(0.0, 548.8, 559.2),
                v(0.0, 548.8, 0.0),
            ],
            WHITE,
            Facing::Along(Vec3::NEG_Y),
        ),
        // Back wall.
        (
            [
                v(549.6, 0.0, 559.2),
                v(0.0, 0.0, 559.2),
                v(0.0, 548.8, 559.2),
                v(556.0, 548.8, 559.2),
            ],
            WHITE,
            Facing::Along(Vec3::NEG_Z),
        ),
        // Right wall (green, x = 0).
        (
            [
                v(0.0, 0.0, 559.2),
                v(0.0, 0.0, 0.0),
                v(0.0, 548.8, 0.0),
                v(0.0, 548.8, 559.2),
            ],
            GREEN,
            Facing::Along(Vec3::X),
        ),
        // Left wall (red, x ≈ 556).
        (
            [
                v(552.8, 0.0, 0.0),
                v(549.6, 0.0, 559.2),
                v(556.0, 548.8, 559.2),
                v(556.0, 548.8, 0.0),
            ],
            RED,
            Facing::Along(Vec3::NEG_X),
        ),
    ]
}

/// The short block's top and four sides, facing away from its centre.
fn short_block() -> Vec<Quad> {
    let short_centre = v(186.0, 82.5, 168.5);
    vec![
        (
            [
                v(130.0, 165.0, 65.0),
                v(82.0, 165.0, 225.0),
                v(240.0, 165.0, 272.0),
                v(290.0, 165.0, 114.0),
            ],
            BOX,
            Facing::AwayFrom(short_centre),
        ),
        (
            [
                v(290.0, 0.0, 114.0),
                v(290.0, 165.0, 114.0),
                v(240.0, 165.0, 272.0),
                v(240.0, 0.0, 272.0),
            ],
            BOX,
            Facing::AwayFrom(short_centre),
        ),
        (
            [
                v(130.0, 0.0, 65.0),
                v(130.0, 165.0, 65.0),
                v(290.0, 165.0, 114.0),
                v(290.0, 0.0, 114.0),
            ],
            BOX,
            Facing::AwayFrom(short_centre),
        ),
        (
            [
                v(82.0, 0.0, 225.0),
                v(82.0, 165.0, 225.0),
                v(130.0, 165.0, 65.0),
                v(130.0, 0.0, 65.0),
            ],
            BOX,
            Facing::AwayFrom(short_centre),
        ),
        (
            [
                v(240.0, 0.0, 272.0),
                v(240.0, 165.0, 272.0),
                v(82.0, 165.0, 225.0),
                v(82.0, 0.0, 225.0),
            ],
            BOX,
            Facing::AwayFrom(short_centre),
        ),
    ]
}

/// The tall block's top and four sides, facing away from its centre.
fn tall_block() -> Vec<Quad> {
    let tall_centre = v(368.5, 165.0, 351.5);
    vec![
        (
            [
                v(423.0, 330.0, 247.0),
                v(265.0, 330.0, 296.0),
                v(314.0, 330.0, 456.0),
                v(472.0, 330.0, 406.0),
            ],
            BOX,
            Facing::AwayFrom(tall_centre),
        ),
        (
            [
                v(423.0, 0.0, 247.0),
                v(423.0, 330.0, 247.0),
                v(472.0, 330.0, 406.0),
                v(472.0, 0.0, 406.0),
            ],
            BOX,
            Facing::AwayFrom(tall_centre),
        ),
        (
            [
                v(472.0, 0.0, 406.0),
                v(472.0, 330.0, 406.0),
                v(314.0, 330.0, 456.0),
                v(314.0, 0.0, 456.0),
            ],
            BOX,
            Facing::AwayFrom(tall_centre),
        ),
        (
            [
                v(314.0, 0.0, 456.0),
                v(314.0, 330.0, 456.0),
                v(265.0, 330.0, 296.0),
                v(265.0, 0.0, 296.0),
            ],
            BOX,
            Facing::AwayFrom(tall_centre),
        ),
        (
            [
                v(265.0, 0.0, 296.0),
                v(265.0, 330.0, 296.0),
                v(423.0, 330.0, 247.0),
                v(423.0, 0.0, 247.0),
            ],
            BOX,
            Facing::AwayFrom(tall_centre),
        ),
    ]
}

/// The four materials, in the order of [`WHITE`], [`BOX`], [`RED`], [`GREEN`]. Colours are the
/// standard RGB values for the measured spectra; `average_color` equals `base_color`.
pub fn cornell_materials() -> Vec<Material> {
    let m = |name: &str, c: Vec3| Material {
        name: name.into(),
        base_color: c,
        texture: None,
        average_color: c,
    };
    vec![
        m("white", Vec3::new(0.725, 0.71, 0.68)),
        m("box", Vec3::new(0.725, 0.71, 0.68)),
        m("red", Vec3::new(0.63, 0.065, 0.05)),
        m("green", Vec3::new(0.14, 0.45, 0.091)),
    ]
}

/// Number of cells along an edge pair of mean length `len` for cell size `cell`:
/// `max(1, round(len / cell))`, capped at [`MAX_CELLS_PER_EDGE`].
fn cells(len: f32, cell: Option<f32>) -> u32 {
    match cell {
        Some(c) if c.is_finite() && c > 0.0 => {
            let n = (len / c).round();
            if n.is_finite() {
                (n as u32).clamp(1, MAX_CELLS_PER_EDGE)
            } else {
                MAX_CELLS_PER_EDGE
            }
        }
        _ => 1,
    }
}

/// The Cornell box mesh and its materials (see the module docs).
///
/// `tessellate: Some(cell)` splits every quad into an `nu × nv` grid of bilinearly
/// interpolated cells (two triangles each), where `n = max(1, round(edge_length / cell))` per
/// direction and `edge_length` is the mean length of the two opposite edges along that
/// direction (capped at [`MAX_CELLS_PER_EDGE`]; a non-positive or non-finite cell size means no
/// tessellation). `None` gives the classic 32 triangles. Vertices are not shared between quads;
/// texture coordinates are the quad's bilinear (s, t) in [0, 1].
pub fn cornell_box(tessellate: Option<f32>) -> (Mesh, Vec<Material>) {
    let mut mesh = Mesh::default();
    for (corners, material, facing) in quads() {
        // Orient so that the corners run counter-clockwise around the wanted normal.
        let centre = corners.iter().copied().sum::<Vec3>() / 4.0;
        let wanted = match facing {
            Facing::Along(d) => d,
            Facing::AwayFrom(p) => centre - p,
        };
        let mut c = corners;
        if (c[2] - c[0]).cross(c[3] - c[1]).dot(wanted) < 0.0 {
            c = [c[0], c[3], c[2], c[1]];
        }
        let normal = (c[2] - c[0]).cross(c[3] - c[1]).normalize();
        let nu = cells(
            0.5 * ((c[1] - c[0]).length() + (c[2] - c[3]).length()),
            tessellate,
        );
        let nv = cells(
            0.5 * ((c[3] - c[0]).length() + (c[2] - c[1]).length()),
            tessellate,
        );

        let base = mesh.positions.len() as u32;
        for j in 0..=nv {
            let t = j as f32 / nv as f32;
            for i in 0..=nu {
                let s = i as f32 / nu as f32;
                let p = (1.0 - s) * (1.0 - t) * c[0]
                    + s * (1.0 - t) * c[1]
                    + s * t * c[2]
                    + (1.0 - s) * t * c[3];
                mesh.positions.push(p);
                mesh.normals.push(normal);
                mesh.uvs.push(Vec2::new(s, t));
                mesh.materials.push(material);
            }
        }
        let row = nu + 1;
        for j in 0..nv {
            for i in 0..nu {
                let a = base + j * row + i;
                let (b, d) = (a + 1, a + row);
                let e = d + 1;
                // Cell corners a (s0,t0), b (s1,t0), e (s1,t1), d (s0,t1): same turning sense
                // as c[0..4].
                mesh.indices.extend_from_slice(&[a, b, e, a, e, d]);
            }
        }
    }
    (mesh, cornell_materials())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn total_area(mesh: &Mesh) -> f64 {
        (0..mesh.triangle_count())
            .map(|t| {
                let [a, b, c] = mesh.triangle(t);
                0.5 * (b - a).cross(c - a).length() as f64
            })
            .sum()
    }

    #[test]
    fn cornell_classic_counts_and_bounds() {
        let (mesh, materials) = cornell_box(None);
        assert_eq!(mesh.triangle_count(), 32);
        assert_eq!(materials.len(), 4);
        let n = mesh.positions.len();
        assert!(mesh.normals.len() == n && mesh.uvs.len() == n && mesh.materials.len() == n);
        assert!(mesh.indices.iter().all(|&i| (i as usize) < n));
        let (lo, hi) = mesh.bounds();
        assert!(lo.abs_diff_eq(Vec3::ZERO, 1e-4), "{lo}");
        assert!(hi.abs_diff_eq(Vec3::new(556.0, 548.8, 559.2), 1e-3), "{hi}");
        for m in &materials {
            assert_eq!(m.base_color, m.average_color);
        }
    }

    #[test]
    fn cornell_normals_unit_facing_and_ccw() {
        let (mesh, _) = cornell_box(None);
        let centre = Vec3::new(278.0, 274.4, 279.6);
        for t in 0..mesh.triangle_count() {
            let [a, b, c] = mesh.triangle(t);
            let i = mesh.indices[3 * t] as usize;
            let n = mesh.normals[i];
            assert!((n.length() - 1.0).abs() < 1e-5);
            // Counter-clockwise seen from the normal side.
            assert!(
                (b - a).cross(c - a).dot(n) > 0.0,
                "triangle {t} is wound clockwise"
            );
            if matches!(mesh.materials[i], WHITE | RED | GREEN) {
                assert!(n.dot(centre - a) > 0.0, "wall triangle {t} faces outward");
            } else {
                // Block faces face away from the box's vertical axis through their block, and
                // the floor under them is never in front of a side face.
                assert!(n.y >= -1e-6, "block face {t} faces down");
            }
        }
    }

    #[test]
    fn cornell_tessellated_same_area() {
        let (coarse, _) = cornell_box(None);
        let (fine, materials) = cornell_box(Some(30.0));
        assert!(fine.triangle_count() > 4000, "{}", fine.triangle_count());
        assert_eq!(materials.len(), 4);
        let (a0, a1) = (total_area(&coarse), total_area(&fine));
        assert!(((a1 - a0) / a0).abs() < 1e-3, "area {a0} vs {a1}");
        let ((lo0, hi0), (lo1, hi1)) = (coarse.bounds(), fine.bounds());
        assert!(lo0.abs_diff_eq(lo1, 1e-3) && hi0.abs_diff_eq(hi1, 1e-3));
        // Per-material areas agree too.
        for m in 0..4u32 {
            let area = |mesh: &Mesh| -> f64 {
                (0..mesh.triangle_count())
                    .filter(|&t| mesh.triangle_material(t) == m)
                    .map(|t| {
                        let [a, b, c] = mesh.triangle(t);
                        0.5 * (b - a).cross(c - a).length() as f64
                    })
                    .sum()
            };
            let (x, y) = (area(&coarse), area(&fine));
            assert!(((x - y) / x).abs() < 1e-3, "material {m}: {x} vs {y}");
        }
    }

    #[test]
    fn cornell_tessellation_is_capped_and_safe() {
        for cell in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            assert_eq!(
                cornell_box(Some(cell)).0.triangle_count(),
                32,
                "cell {cell}"
            );
        }
        let (mesh, _) = cornell_box(Some(1e-3));
        assert!(
            mesh.triangle_count() <= 16 * 2 * (MAX_CELLS_PER_EDGE * MAX_CELLS_PER_EDGE) as usize
        );
    }
}
