//! **Point pool**: the scene's surfaces as points, sampled once, uniformly by area (the
//! prepared-once step of imperfect shadow maps, Ritschel et al. 2008: "at startup, we
//! approximate the surfaces with a set of points").
//!
//! Reads: the static mesh and every mover's mesh (in its object space).
//! Writes: a list of [`PoolPoint`]s in random order — so that any run of consecutive points,
//! which is what a VPL takes ([`super::splat`]), is itself a uniform sample of the surfaces.
//!
//! Triangles are chosen by area with stratified numbers (point i of n uses (i + ξ) / n on the
//! cumulative area), so each triangle gets its share of the points to within one; the point
//! in the triangle is uniform (the square-root warp of two more numbers). Movers' points are
//! in their object space with the mover's index: a pass moves them with the mover's transform
//! every frame. Deterministic for a seed.

use glam::Vec3;

use crate::cpu::reference::Rng;
use crate::scene::{Mesh, Scene};
use crate::{Error, Result};

/// One point of the pool.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoolPoint {
    /// World space (static mesh) or the mover's object space.
    pub position: Vec3,
    /// 0: the static mesh; k + 1: mover k.
    pub object: u32,
}

/// `count` points on the surfaces of `meshes` (object index, mesh), uniform by area, in random
/// order (see the module docs).
pub fn sample_meshes(meshes: &[(u32, &Mesh)], count: u32, seed: u64) -> Result<Vec<PoolPoint>> {
    // Cumulative area over every triangle of every mesh.
    let mut triangles: Vec<(u32, [Vec3; 3])> = Vec::new();
    let mut cumulative: Vec<f64> = Vec::new();
    let mut total = 0.0f64;
    for (object, mesh) in meshes {
        for t in 0..mesh.triangle_count() {
            let [a, b, c] = mesh.triangle(t);
            let area = 0.5 * (b - a).cross(c - a).length() as f64;
            if area > 0.0 && area.is_finite() {
                total += area;
                cumulative.push(total);
                triangles.push((*object, [a, b, c]));
            }
        }
    }
    if total <= 0.0 {
        return Err(Error::Invalid(
            "the point pool needs surfaces with area; the scene has none".into(),
        ));
    }
    let mut rng = Rng::new(seed, 0x1517);
    let mut points = Vec::with_capacity(count as usize);
    for i in 0..count {
        let u = (i as f64 + rng.next_f32() as f64) / count as f64 * total;
        let k = cumulative
            .partition_point(|c| *c <= u)
            .min(triangles.len() - 1);
        let (object, [a, b, c]) = triangles[k];
        let (r1, r2) = (rng.next_f32().sqrt(), rng.next_f32());
        let position = a * (1.0 - r1) + b * (r1 * (1.0 - r2)) + c * (r1 * r2);
        points.push(PoolPoint { position, object });
    }
    // Fisher–Yates, so any run of the pool is a uniform sample.
    for i in (1..points.len()).rev() {
        let j = (rng.next_u64() % (i as u64 + 1)) as usize;
        points.swap(i, j);
    }
    Ok(points)
}

/// `count` points on `scene`'s static mesh and movers (see the module docs).
pub fn sample_scene(scene: &Scene, count: u32, seed: u64) -> Result<Vec<PoolPoint>> {
    let mut meshes: Vec<(u32, &Mesh)> = vec![(0, &scene.mesh)];
    meshes.extend(
        scene
            .movers
            .iter()
            .enumerate()
            .map(|(k, m)| (k as u32 + 1, &m.mesh)),
    );
    sample_meshes(&meshes, count, seed)
}

/// The area of the scene's surfaces (the static mesh and the movers), what
/// [`sample_scene`] spreads its points over.
pub fn scene_area(scene: &Scene) -> f64 {
    let meshes = std::iter::once(&scene.mesh).chain(scene.movers.iter().map(|m| &m.mesh));
    meshes
        .flat_map(|mesh| (0..mesh.triangle_count()).map(move |t| mesh.triangle(t)))
        .map(|[a, b, c]| 0.5 * (b - a).cross(c - a).length() as f64)
        .filter(|a| a.is_finite())
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    /// A mesh of quads, each two triangles in the plane z = `z`.
    fn quads(rects: &[(Vec2, Vec2)], z: f32) -> Mesh {
        let mut mesh = Mesh::default();
        for (lo, hi) in rects {
            let base = mesh.positions.len() as u32;
            for p in [
                Vec3::new(lo.x, lo.y, z),
                Vec3::new(hi.x, lo.y, z),
                Vec3::new(hi.x, hi.y, z),
                Vec3::new(lo.x, hi.y, z),
            ] {
                mesh.positions.push(p);
                mesh.normals.push(Vec3::Z);
                mesh.uvs.push(Vec2::ZERO);
                mesh.materials.push(0);
            }
            mesh.indices
                .extend([0, 1, 2, 0, 2, 3].into_iter().map(|i| base + i));
        }
        mesh
    }

    /// Each surface gets its share of the points by area to within one per triangle; every
    /// point lies on its surface; a run of the shuffled pool keeps the shares; movers' points
    /// carry their object; the same seed gives the same pool.
    #[test]
    fn points_are_uniform_by_area_and_shuffled() {
        // Static: a 1x1 and a 3x1 quad (areas 1 and 3); mover: a 2x2 quad (area 4) at z = 5.
        let stat = quads(
            &[
                (Vec2::ZERO, Vec2::ONE),
                (Vec2::new(2.0, 0.0), Vec2::new(5.0, 1.0)),
            ],
            0.0,
        );
        let mover = quads(&[(Vec2::ZERO, Vec2::splat(2.0))], 5.0);
        let n = 8000;
        let pool = sample_meshes(&[(0, &stat), (1, &mover)], n, 7).unwrap();
        assert_eq!(pool.len(), n as usize);
        let share = |pts: &[PoolPoint], f: &dyn Fn(&PoolPoint) -> bool| {
            pts.iter().filter(|p| f(p)).count() as f64 / pts.len() as f64
        };
        let small = |p: &PoolPoint| p.object == 0 && p.position.x <= 1.0;
        let large = |p: &PoolPoint| p.object == 0 && p.position.x >= 2.0;
        let moved = |p: &PoolPoint| p.object == 1;
        // Stratified: within one point per triangle of the exact shares 1/8, 3/8, 4/8.
        for (f, want) in [
            (&small as &dyn Fn(&PoolPoint) -> bool, 0.125),
            (&large, 0.375),
            (&moved, 0.5),
        ] {
            assert!((share(&pool, f) - want).abs() <= 6.0 / n as f64, "{want}");
        }
        for p in &pool {
            let on = match p.object {
                0 => {
                    p.position.z == 0.0
                        && (small(p) || large(p))
                        && (0.0..=1.0).contains(&p.position.y)
                }
                _ => {
                    (p.position.z - 5.0).abs() < 1e-5 && p.position.x <= 2.0 && p.position.y <= 2.0
                }
            };
            assert!(on, "{p:?} is off its surface");
        }
        // A run of 1000 of the shuffled pool: the shares within 5 standard errors.
        let run = &pool[3000..4000];
        for (f, want) in [
            (&small as &dyn Fn(&PoolPoint) -> bool, 0.125f64),
            (&large, 0.375),
            (&moved, 0.5),
        ] {
            let se = (want * (1.0 - want) / run.len() as f64).sqrt();
            assert!((share(run, f) - want).abs() < 5.0 * se, "run share {want}");
        }
        // Unshuffled, the first points would all be on the first quad.
        assert!(share(&pool[..500], &small) < 0.3);
        assert_eq!(
            pool,
            sample_meshes(&[(0, &stat), (1, &mover)], n, 7).unwrap()
        );
        assert_ne!(
            pool,
            sample_meshes(&[(0, &stat), (1, &mover)], n, 8).unwrap()
        );
    }

    #[test]
    fn a_scene_without_area_is_refused() {
        let flat = Mesh {
            positions: vec![Vec3::ZERO; 3],
            normals: vec![Vec3::Z; 3],
            uvs: vec![Vec2::ZERO; 3],
            materials: vec![0; 3],
            indices: vec![0, 1, 2],
        };
        assert!(sample_meshes(&[(0, &flat)], 10, 1).is_err());
    }
}
