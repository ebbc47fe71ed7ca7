//! CPU ray casting over the static geometry with an eight-wide BVH (`wide`, collapsed from an
//! `obvhs` PLOC tree): closest-hit (triangle, barycentrics, position, normals, material) and
//! any-hit (occlusion) queries. The techniques use it to place and validate VPLs; the reference
//! renderer traces paths with it, over a scene's static tree built once and its movers' trees
//! per frame (`frame`).

use std::time::Duration;

use glam::{Vec2, Vec3, Vec3A};
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;

mod frame;
mod wide;
pub use frame::{mover_mesh, FrameBvh, SceneTrees, TreeBuilds};
use wide::WideBvh;

use crate::scene::Mesh;

/// A closest-hit result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter (distance when the direction is unit length).
    pub t: f32,
    pub triangle: u32,
    /// Barycentrics (u, v) of corners 1 and 2; corner 0 has 1 − u − v.
    pub barycentrics: Vec2,
    pub position: Vec3,
    /// Unit geometric normal, facing against the ray (towards the ray origin).
    pub geometric_normal: Vec3,
    /// Unit interpolated shading normal, flipped to the same side as `geometric_normal`.
    pub shading_normal: Vec3,
    pub uv: Vec2,
    pub material: u32,
}

/// A BVH over one mesh (the scene's static mesh). It keeps its own copies of the triangles,
/// normals, texture coordinates and per-triangle materials, so it does not borrow the mesh.
/// Triangles with no area are never hit, and they and exact duplicates of another triangle
/// (the same three corners) are left out of the tree: a pile of coincident triangles cannot be
/// split and made the build quadratic (40k of them took 48 s). An empty mesh gives a BVH that
/// never hits.
pub struct SceneBvh {
    /// `None` for a mesh without triangles.
    bvh: Option<WideBvh>,
    /// The mesh triangle of each triangle built into the tree.
    built: Vec<u32>,
    /// What a hit record reads, per triangle in mesh order (one place: a hit touches one
    /// triangle's record, not four arrays).
    corners: Vec<Corners>,
}

/// A triangle's unit geometric normal (from its corners, in their order), the shading normals
/// and texture coordinates of its corners, and its material.
#[derive(Clone, Copy, Debug)]
struct Corners {
    ng: Vec3,
    n: [Vec3; 3],
    uv: [Vec2; 3],
    material: u32,
}

/// A triangle as the scalar intersection test reads it: the first corner and the edges to the
/// other two. The tree stores the same values eight to a group.
#[cfg(test)]
#[derive(Clone, Copy, Debug)]
struct Leaf {
    v0: Vec3,
    e1: Vec3,
    e2: Vec3,
}

#[cfg(test)]
impl Leaf {
    fn new(t: &[Vec3; 3]) -> Leaf {
        Leaf {
            v0: t[0],
            e1: t[1] - t[0],
            e2: t[2] - t[0],
        }
    }
}

/// Möller–Trumbore: `(t, u, v)` of the hit of `origin + t·dir` with triangle `tri` for `t` in
/// the open interval `(t_min, t_max)`, where `(u, v)` weight corners 1 and 2. Both sides hit.
/// The tree's lane tests (`wide::intersect4` and the AVX one) do these operations in this
/// order; the tests compare the tree against this one.
#[cfg(test)]
fn intersect(
    tri: &Leaf,
    origin: Vec3,
    dir: Vec3,
    t_min: f32,
    t_max: f32,
) -> Option<(f32, f32, f32)> {
    let (e1, e2) = (tri.e1, tri.e2);
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv_det = 1.0 / det;
    let s = origin - tri.v0;
    let u = s.dot(p) * inv_det;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = dir.dot(q) * inv_det;
    if !(v >= 0.0 && u + v <= 1.0) {
        return None;
    }
    let t = e2.dot(q) * inv_det;
    (t > t_min && t < t_max).then_some((t, u, v))
}

impl SceneBvh {
    /// Builds the BVH over `mesh` (copied; the BVH does not borrow it). Indices out of range
    /// are treated as degenerate triangles at the origin, which are never hit.
    pub fn new(mesh: &Mesh) -> Self {
        let count = mesh.triangle_count();
        let mut corners = Vec::with_capacity(count);
        let mut positions = Vec::with_capacity(count);
        for t in 0..count {
            let idx = &mesh.indices[3 * t..3 * t + 3];
            let in_range = idx.iter().all(|&i| (i as usize) < mesh.positions.len());
            let at = |k: usize| idx[k] as usize;
            let p = if in_range {
                [0, 1, 2].map(|k| mesh.positions[at(k)])
            } else {
                [Vec3::ZERO; 3]
            };
            let p = if p.iter().all(|v| v.is_finite()) {
                p
            } else {
                [Vec3::ZERO; 3]
            };
            // Also the hit record's geometric normal (computed here once, not per hit).
            let face = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or(Vec3::Y);
            let n = [0, 1, 2].map(|k| {
                mesh.normals
                    .get(at(k))
                    .copied()
                    .filter(|n| n.is_finite())
                    .unwrap_or(face)
            });
            let uv = [0, 1, 2].map(|k| mesh.uvs.get(at(k)).copied().unwrap_or(Vec2::ZERO));
            positions.push(p);
            corners.push(Corners {
                ng: face,
                n,
                uv,
                material: mesh.materials.get(at(0)).copied().unwrap_or(0),
            });
        }
        let mut seen = std::collections::HashSet::with_capacity(corners.len());
        let built: Vec<u32> = (0..corners.len() as u32)
            .filter(|&t| {
                let p = positions[t as usize];
                let area = (p[1] - p[0]).cross(p[2] - p[0]).length_squared();
                let mut key = p.map(|v| v.to_array().map(f32::to_bits));
                key.sort_unstable();
                area > 0.0 && area.is_finite() && seen.insert(key)
            })
            .collect();
        let bvh = (!built.is_empty()).then(|| {
            let obvhs_tris: Vec<Triangle> = built
                .iter()
                .map(|&i| {
                    let t = &positions[i as usize];
                    Triangle {
                        v0: Vec3A::from(t[0]),
                        v1: Vec3A::from(t[1]),
                        v2: Vec3A::from(t[2]),
                    }
                })
                .collect();
            // One triangle per BVH2 leaf: the wide tree groups them eight to a leaf itself.
            // obvhs's slowest preset's reinsertion (every node considered, twice), without its
            // pre-splitting: on Sibenik's 80k triangles the build takes 0.27 s instead of
            // 0.06 s and closest-hit rays run 10 % faster, shadow rays 7 % (262,144 of each,
            // alternating runs); pre-splitting made both 3-5 % slower, and the lighter
            // presets' reinsertion gained less.
            let params = BvhBuildParams {
                max_prims_per_leaf: 1,
                pre_split: false,
                ..BvhBuildParams::very_slow_build()
            };
            let mut build_time = Duration::ZERO;
            let bvh2 = build_bvh2_from_tris(&obvhs_tris, params, &mut build_time);
            WideBvh::from_bvh2(&bvh2, &obvhs_tris, &built)
        });
        SceneBvh {
            bvh,
            built,
            corners,
        }
    }

    /// The same tree with box and triangle tests in four-lane halves even where the CPU has
    /// AVX2 (the tests check both).
    #[cfg(test)]
    fn without_avx2(mut self) -> Self {
        self.bvh = self.bvh.map(WideBvh::without_avx2);
        self
    }

    /// Number of triangles in the BVH.
    pub fn triangle_count(&self) -> usize {
        self.corners.len()
    }

    /// Number of triangles in the tree itself: those with area, duplicates counted once.
    pub fn tree_triangle_count(&self) -> usize {
        self.built.len()
    }

    /// Whether the ray's values can be traced (finite origin, finite non-zero direction and a
    /// non-empty, non-NaN interval).
    #[inline(always)]
    fn usable(origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> bool {
        // x · 0 is ±0 for a finite x and NaN for ±∞ and NaN, so the six products sum to zero
        // exactly when every coordinate is finite (a few operations instead of a test per
        // coordinate); a NaN bound fails the last comparison.
        let z = origin * 0.0 + dir * 0.0;
        z.x + z.y + z.z == 0.0 && dir != Vec3::ZERO && t_max > t_min
    }

    /// Closest hit along `origin + t·dir` for `t` in `(t_min, t_max)` (a negative `t_min` acts
    /// as 0). Both sides of every triangle are hit. Non-finite or zero rays hit nothing.
    pub fn closest_hit(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Option<Hit> {
        let bvh = self.bvh.as_ref()?;
        let t_min = t_min.max(0.0);
        if !Self::usable(origin, dir, t_min, t_max) {
            return None;
        }
        let (tri, t, u, v) = bvh.closest(origin, dir, t_min, t_max)?;
        let i = tri as usize;
        let w = 1.0 - u - v;
        let c = &self.corners[i];
        let ([n0, n1, n2], [uv0, uv1, uv2]) = (c.n, c.uv);
        let mut geometric_normal = c.ng;
        if geometric_normal.dot(dir) > 0.0 {
            geometric_normal = -geometric_normal;
        }
        let mut shading_normal = (w * n0 + u * n1 + v * n2).normalize_or(geometric_normal);
        if shading_normal.dot(geometric_normal) < 0.0 {
            shading_normal = -shading_normal;
        }
        Some(Hit {
            t,
            triangle: tri,
            barycentrics: Vec2::new(u, v),
            position: origin + t * dir,
            geometric_normal,
            shading_normal,
            uv: w * uv0 + u * uv1 + v * uv2,
            material: c.material,
        })
    }

    /// Whether anything blocks the open segment from `a` to `b` (both ends shrunk by `eps`
    /// relative to the segment length, to avoid self-intersection at the endpoints).
    pub fn occluded(&self, a: Vec3, b: Vec3, eps: f32) -> bool {
        let eps = if eps.is_finite() {
            eps.clamp(0.0, 0.5)
        } else {
            0.0
        };
        self.any_hit(a, b - a, eps, 1.0 - eps)
    }

    /// Whether any triangle is hit along the ray for `t` in `(t_min, t_max)` (a negative
    /// `t_min` acts as 0).
    pub fn any_hit(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> bool {
        let Some(bvh) = self.bvh.as_ref() else {
            return false;
        };
        let t_min = t_min.max(0.0);
        if !Self::usable(origin, dir, t_min, t_max) {
            return false;
        }
        bvh.any(origin, dir, t_min, t_max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 40k copies of one triangle (they took 48 s to build when the tree held them all) and
    /// 1000 zero-area ones join the tree as one triangle; rays still hit it.
    #[test]
    fn coincident_and_degenerate_triangles_stay_out_of_the_tree() {
        let mut mesh = Mesh::default();
        let corners = [Vec3::ZERO, Vec3::X, Vec3::Y];
        for _ in 0..40_000 {
            let base = mesh.positions.len() as u32;
            mesh.positions.extend(corners);
            mesh.normals.extend([Vec3::Z; 3]);
            mesh.materials.extend([0; 3]);
            mesh.indices.extend([base, base + 1, base + 2]);
        }
        for i in 0..1000 {
            let base = mesh.positions.len() as u32;
            let p = Vec3::splat(i as f32);
            mesh.positions.extend([p, p, p + Vec3::X]);
            mesh.normals.extend([Vec3::Z; 3]);
            mesh.materials.extend([0; 3]);
            mesh.indices.extend([base, base + 1, base + 2]);
        }
        let bvh = SceneBvh::new(&mesh);
        assert_eq!(bvh.triangle_count(), 41_000);
        assert_eq!(bvh.tree_triangle_count(), 1);
        let hit = bvh
            .closest_hit(Vec3::new(0.2, 0.2, 1.0), Vec3::NEG_Z, 0.0, 10.0)
            .expect("the triangle is hit");
        assert!((hit.t - 1.0).abs() < 1e-6 && hit.triangle < 40_000);
    }
    use crate::scene::cornell::{cornell_box, BOX};

    use crate::rng::SplitMix64 as Rng;

    /// A uniform unit vector (rejection from the cube).
    fn unit_vector(rng: &mut Rng) -> Vec3 {
        loop {
            let v = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
            if v.length_squared() > 1e-4 && v.length_squared() <= 1.0 {
                return v.normalize();
            }
        }
    }

    fn brute_force(mesh: &Mesh, origin: Vec3, dir: Vec3) -> Option<(f32, u32)> {
        (0..mesh.triangle_count())
            .filter_map(|t| {
                intersect(
                    &Leaf::new(&mesh.triangle(t)),
                    origin,
                    dir,
                    0.0,
                    f32::INFINITY,
                )
                .map(|(d, _, _)| (d, t as u32))
            })
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }

    #[test]
    fn bvh_camera_ray_hits_block_with_consistent_barycentrics() {
        let (mesh, _) = cornell_box(None);
        let bvh = SceneBvh::new(&mesh);
        assert_eq!(bvh.triangle_count(), 32);
        let origin = Vec3::new(278.0, 273.0, -800.0);
        let dir = (Vec3::new(278.0, 273.0, 280.0) - origin).normalize();
        let hit = bvh
            .closest_hit(origin, dir, 0.0, f32::INFINITY)
            .expect("the camera sees the box");
        // Straight ahead is the front face of the tall block (z ≈ 292 at x = 278).
        assert_eq!(hit.material, BOX);
        assert!((hit.position.z - 292.0).abs() < 1.0, "{}", hit.position);
        assert!(hit.position.abs_diff_eq(origin + hit.t * dir, 1e-3));
        let [a, b, c] = mesh.triangle(hit.triangle as usize);
        let (u, v) = (hit.barycentrics.x, hit.barycentrics.y);
        let p = (1.0 - u - v) * a + u * b + v * c;
        assert!(p.abs_diff_eq(hit.position, 1e-3), "{p} vs {}", hit.position);
        assert!(hit.geometric_normal.dot(dir) < 0.0);
        assert!(hit.shading_normal.dot(hit.geometric_normal) > 0.99);
        assert!((hit.geometric_normal.length() - 1.0).abs() < 1e-5);
        // t_max before the block: nothing.
        assert!(bvh.closest_hit(origin, dir, 0.0, hit.t * 0.99).is_none());
        // The back wall is behind it.
        let back = bvh.closest_hit(origin, dir, hit.t * 1.01, f32::INFINITY);
        assert!(back.is_some());
    }

    #[test]
    fn bvh_occlusion() {
        let (mesh, _) = cornell_box(Some(30.0));
        let bvh = SceneBvh::new(&mesh);
        // Through the short block.
        assert!(bvh.occluded(
            Vec3::new(186.0, 80.0, 10.0),
            Vec3::new(186.0, 80.0, 400.0),
            1e-4
        ));
        // Across open space above the blocks.
        assert!(!bvh.occluded(
            Vec3::new(278.0, 400.0, 100.0),
            Vec3::new(278.0, 400.0, 500.0),
            1e-4
        ));
        // Endpoints on surfaces do not occlude themselves: floor to ceiling, straight up in the open.
        assert!(!bvh.occluded(
            Vec3::new(500.0, 0.0, 100.0),
            Vec3::new(500.0, 548.8, 100.0),
            1e-4
        ));
        assert!(bvh.any_hit(Vec3::new(278.0, 273.0, 279.0), Vec3::Y, 0.0, 1000.0));
        assert!(!bvh.any_hit(Vec3::new(278.0, 273.0, 279.0), Vec3::Y, 0.0, 200.0));
        // Axis directions, including ones with negative-zero components such as `-Vec3::Y`
        // (not −Z: the front of the box is open).
        let centre = Vec3::new(278.0, 273.0, 279.0);
        for d in [
            Vec3::X,
            -Vec3::X,
            Vec3::Y,
            -Vec3::Y,
            Vec3::Z,
            Vec3::NEG_Y,
            Vec3::new(-0.0, -1.0, -0.0),
        ] {
            let hit = bvh.closest_hit(centre, d, 0.0, f32::INFINITY);
            assert!(hit.is_some(), "{d:?} misses");
            assert!(
                bvh.any_hit(centre, d, 0.0, f32::INFINITY),
                "{d:?} any-hit misses"
            );
        }
    }

    #[test]
    fn bvh_matches_brute_force() {
        let (mesh, _) = cornell_box(Some(30.0));
        let bvh = SceneBvh::new(&mesh);
        let mut rng = Rng::from_state(0x9e37_79b9_7f4a_7c15);
        let mut hits = 0;
        for _ in 0..1000 {
            let origin = Vec3::new(
                rng.next_f32() * 556.0,
                rng.next_f32() * 548.0,
                rng.next_f32() * 900.0 - 300.0,
            );
            let dir = unit_vector(&mut rng);
            let expected = brute_force(&mesh, origin, dir);
            let got = bvh.closest_hit(origin, dir, 0.0, f32::INFINITY);
            match (expected, got) {
                (None, None) => {}
                (Some((t, _)), Some(h)) => {
                    hits += 1;
                    assert!(
                        (h.t - t).abs() <= 1e-3 * t.max(1.0),
                        "t {} vs brute force {t}",
                        h.t
                    );
                }
                (e, g) => panic!("origin {origin} dir {dir}: brute force {e:?}, bvh {g:?}"),
            }
            assert_eq!(
                expected.is_some(),
                bvh.any_hit(origin, dir, 0.0, f32::INFINITY)
            );
        }
        assert!(hits > 500, "{hits}");
    }

    /// Brute force over every triangle: the smallest `t` in `(t_min, t_max)` with the
    /// triangles hit at exactly that `t`, and `(u, v)` of the first of them.
    fn brute_force_all(
        mesh: &Mesh,
        origin: Vec3,
        dir: Vec3,
        t_min: f32,
        t_max: f32,
    ) -> Option<(f32, Vec<u32>)> {
        let hits: Vec<(f32, u32)> = (0..mesh.triangle_count())
            .filter_map(|t| {
                intersect(&Leaf::new(&mesh.triangle(t)), origin, dir, t_min, t_max)
                    .map(|(d, _, _)| (d, t as u32))
            })
            .collect();
        let t = hits.iter().map(|h| h.0).min_by(f32::total_cmp)?;
        Some((t, hits.iter().filter(|h| h.0 == t).map(|h| h.1).collect()))
    }

    /// A soup of triangles of every size and orientation (some axis-aligned, so boxes of zero
    /// thickness): the tree's closest hit is bit for bit the smallest `t` of the scalar test over
    /// every triangle, with that triangle's barycentrics, for rays with random intervals; its
    /// any-hit agrees. Catches a traversal that culls a box it enters (a wrong near/far plane,
    /// a stack entry dropped while still nearer than the best hit) or a lane test that rounds
    /// differently from the scalar one.
    fn check_against_brute_force(
        mesh: &Mesh,
        rays: usize,
        rng: &mut Rng,
        mut ray: impl FnMut(&mut Rng) -> (Vec3, Vec3),
    ) -> usize {
        // The tree as the CPU runs it (eight lanes per step with AVX2) and in four-lane halves.
        let (wide, halves) = (SceneBvh::new(mesh), SceneBvh::new(mesh).without_avx2());
        let mut hits = 0;
        for i in 0..rays {
            let (origin, mut dir) = ray(rng);
            if i % 7 == 0 {
                // Axis-parallel rays (zero direction components, some negative zero).
                dir = [Vec3::X, -Vec3::Y, Vec3::new(-0.0, 0.0, 1.0)][i % 3];
            }
            let (t_min, t_max) = if i % 3 == 0 {
                (rng.next_f32() * 20.0, 20.0 + rng.next_f32() * 80.0)
            } else {
                (0.0, f32::INFINITY)
            };
            let expected = brute_force_all(mesh, origin, dir, t_min, t_max);
            for bvh in [&wide, &halves] {
                let got = bvh.closest_hit(origin, dir, t_min, t_max);
                match (&expected, got) {
                    (None, None) => {}
                    (Some((t, tris)), Some(h)) => {
                        hits += 1;
                        assert_eq!(h.t, *t, "ray {i}: t");
                        assert!(
                            tris.contains(&h.triangle),
                            "ray {i}: {} not in {tris:?}",
                            h.triangle
                        );
                        let (_, u, v) = intersect(
                            &Leaf::new(&mesh.triangle(h.triangle as usize)),
                            origin,
                            dir,
                            t_min,
                            t_max,
                        )
                        .unwrap();
                        assert_eq!(h.barycentrics, Vec2::new(u, v), "ray {i}: barycentrics");
                    }
                    (e, g) => panic!("ray {i} {origin} {dir}: brute force {e:?}, tree {g:?}"),
                }
                assert_eq!(
                    expected.is_some(),
                    bvh.any_hit(origin, dir, t_min, t_max),
                    "ray {i}: any-hit"
                );
            }
        }
        hits / 2
    }

    fn push_triangle(mesh: &mut Mesh, corners: [Vec3; 3]) {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(corners);
        mesh.normals.extend([Vec3::Z; 3]);
        mesh.materials.extend([0; 3]);
        mesh.indices.extend([base, base + 1, base + 2]);
    }

    #[test]
    fn tree_matches_brute_force_on_a_triangle_soup() {
        let mut rng = Rng::from_state(0x2545_f491_4f6c_dd1d);
        let mut mesh = Mesh::default();
        for i in 0..3000 {
            let size = [0.3, 3.0, 30.0][i % 3] * rng.next_f32();
            let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 100.0;
            let mut corners = [0, 1, 2].map(|_| c + unit_vector(&mut rng) * size);
            if i % 5 == 0 {
                // Flat in one axis: a box of zero thickness.
                let axis = i % 3;
                for p in &mut corners {
                    p[axis] = c[axis];
                }
            }
            push_triangle(&mut mesh, corners);
        }
        let hits = check_against_brute_force(&mesh, 4000, &mut rng, |rng| {
            let origin = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 120.0 - 10.0;
            (origin, unit_vector(rng))
        });
        assert!(hits > 1500, "{hits}");
    }

    /// Rays aimed exactly at corners and edge points of a soup's triangles: where a corner is
    /// extreme in its leaf group, the ray meets the group's box on its boundary, in two or three
    /// axes at once, and rounding can put the computed entry past the computed exit. The
    /// traversal's widened exit (`wide::ROBUST`) keeps those boxes entered: without it, the
    /// tree misses hits the scalar test finds.
    #[test]
    fn rays_through_corners_and_edges_find_what_brute_force_finds() {
        let mut rng = Rng::from_state(0x9e37_79b9_7f4a_7c15);
        let mut mesh = Mesh::default();
        for _ in 0..2000 {
            let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 100.0;
            let size = 0.5 + 5.0 * rng.next_f32();
            push_triangle(
                &mut mesh,
                [0, 1, 2].map(|_| c + unit_vector(&mut rng) * size),
            );
        }
        let corners: Vec<[Vec3; 3]> = (0..mesh.triangle_count())
            .map(|t| mesh.triangle(t))
            .collect();
        let hits = check_against_brute_force(&mesh, 6000, &mut rng, |rng| {
            let tri = corners[(rng.next_f32() * corners.len() as f32) as usize % corners.len()];
            let k = (rng.next_f32() * 3.0) as usize % 3;
            let target = if rng.next_f32() < 0.5 {
                tri[k]
            } else {
                tri[k].lerp(tri[(k + 1) % 3], rng.next_f32())
            };
            let origin = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 140.0 - 20.0;
            (origin, (target - origin).normalize())
        });
        assert!(hits > 3000, "{hits}");
    }

    /// Triangles across the x axis at distances growing geometrically (up to 2¹²⁵) nest each
    /// box in the next: a tree deeper than the scenes' (a ray along the axis needs 115 stack
    /// entries), whose traversal outgrows the stack's fixed part and must still find every hit.
    #[test]
    fn deep_trees_are_traversed_completely() {
        let mut mesh = Mesh::default();
        for i in 0..1000 {
            let x = 2f32.powf(0.125 * i as f32);
            push_triangle(
                &mut mesh,
                [
                    Vec3::new(x, -1.0, -1.0),
                    Vec3::new(x, 1.0, -1.0),
                    Vec3::new(x, 0.0, 1.0),
                ],
            );
        }
        let bvh = SceneBvh::new(&mesh);
        let stack = bvh.bvh.as_ref().unwrap().stack_len();
        assert!(
            stack > wide::FIXED_STACK,
            "the tree is not deep: {stack} entries"
        );
        let mut rng = Rng::from_state(7);
        let hits = check_against_brute_force(&mesh, 600, &mut rng, |rng| {
            let origin = Vec3::new(-1.0, rng.next_f32() - 0.5, rng.next_f32() - 0.5);
            // Along the axis, so that the ray enters every box on the way.
            (origin, Vec3::X)
        });
        assert!(hits > 300, "{hits}");
    }

    #[test]
    fn bvh_degenerate_inputs_never_panic() {
        let empty = SceneBvh::new(&Mesh::default());
        assert!(empty
            .closest_hit(Vec3::ZERO, Vec3::X, 0.0, f32::INFINITY)
            .is_none());
        assert!(!empty.any_hit(Vec3::ZERO, Vec3::X, 0.0, f32::INFINITY));
        assert!(!empty.occluded(Vec3::ZERO, Vec3::ONE, 1e-3));

        let (mesh, _) = cornell_box(None);
        let bvh = SceneBvh::new(&mesh);
        let o = Vec3::new(278.0, 273.0, 279.0);
        assert!(bvh.closest_hit(o, Vec3::ZERO, 0.0, f32::INFINITY).is_none());
        assert!(bvh
            .closest_hit(o, Vec3::new(f32::NAN, 0.0, 1.0), 0.0, f32::INFINITY)
            .is_none());
        assert!(bvh
            .closest_hit(Vec3::splat(f32::INFINITY), Vec3::X, 0.0, f32::INFINITY)
            .is_none());
        assert!(bvh.closest_hit(o, Vec3::X, 10.0, 5.0).is_none());
        assert!(!bvh.occluded(o, o, 1e-3));
        // Non-finite coordinates and a NaN far bound hit nothing; a direction whose squared
        // length overflows is still finite and traced (a guard built on its length, or on a
        // sum that overflows, would refuse it).
        let inf_z = Vec3::new(0.0, 0.0, f32::INFINITY);
        assert!(bvh.closest_hit(o + inf_z, Vec3::X, 0.0, 1e9).is_none());
        assert!(bvh.closest_hit(o, Vec3::X + inf_z, 0.0, 1e9).is_none());
        assert!(!bvh.any_hit(o, Vec3::X + inf_z, 0.0, 1e9));
        assert!(bvh.closest_hit(o, Vec3::X, 0.0, f32::NAN).is_none());
        assert!(!bvh.any_hit(o, Vec3::X, 0.0, f32::NAN));
        assert!(bvh.closest_hit(o, Vec3::X * 1e30, 0.0, 1.0).is_some());
        assert!(bvh.any_hit(o, Vec3::X * 1e30, 0.0, 1.0));

        // Bad indices and a zero-area triangle.
        let mut broken = mesh.clone();
        broken.indices.extend_from_slice(&[0, 1, 9999, 0, 0, 0]);
        broken.normals.truncate(3);
        let bvh = SceneBvh::new(&broken);
        assert!(bvh.closest_hit(o, Vec3::X, 0.0, f32::INFINITY).is_some());
    }
}
