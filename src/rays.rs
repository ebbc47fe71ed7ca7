//! Raw ray throughput of the reference's BVH on a fixed set of rays that another ray caster can
//! trace too (`scripts/compare_mitsuba.py --rays`: Mitsuba 3, i.e. Embree).
//!
//! `gibench export-scene --rays N` writes two ray files beside the scene: `rays-closest.bin`,
//! N rays like the reference's path segments (from a primary hit, offset by the reference's ε
//! along the geometric normal, cosine-distributed about the shading normal; closest hit), and
//! `rays-shadow.bin`, N segments from those origins to the light (any hit). Each ray is seven
//! little-endian `f32`: origin xyz, direction xyz, t_max (t_min is 0; a shadow ray's direction
//! is the whole segment, t_max just below 1; a closest-hit ray's t_max is +∞).
//!
//! `gibench raycast --rays DIR` loads the same frame (scene and frame from `DIR/scene.json`),
//! builds the reference's BVH and casts both sets `--repeats` times across all cores, timing
//! each pass by wall clock and by the CPU time of every thread; it writes `raycast.json` and,
//! for checking agreement with the other caster, `closest-t.bin` (one `f32` distance per
//! closest-hit ray, +∞ for a miss) and `shadow-hit.bin` (one byte per shadow ray, 1 = blocked).
//!
//! This module holds the ray files (writing and reading them); the two commands are
//! [`crate::cli::export_scene`] and [`crate::cli::raycast`].

use std::path::Path;

use gibench_harness::cpu::reference::{camera_ray, cosine_direction, ReferenceTracer};
use gibench_harness::glam::{Vec2, Vec3};
use gibench_harness::scene::descriptor::LightKind;
use gibench_harness::scene::Scene;
use gibench_harness::{Error, Result};
use rayon::prelude::*;

/// File of the closest-hit rays.
pub(crate) const CLOSEST: &str = "rays-closest.bin";
/// File of the shadow rays.
pub(crate) const SHADOW: &str = "rays-shadow.bin";
/// Bytes per ray: seven `f32`.
pub(crate) const RAY_BYTES: usize = 28;
/// Rays per set `export-scene --rays` takes at most (a set is built in memory: 470 MB).
pub(crate) const MAX_RAYS: u32 = 1 << 24;

/// One ray as stored.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Ray {
    pub(crate) origin: Vec3,
    pub(crate) dir: Vec3,
    pub(crate) t_max: f32,
}

/// A uniform number in [0, 1) from `k` (SplitMix64's finaliser; the rays need only be fixed
/// and well spread, not the reference's sampler).
fn uniform(k: u64) -> f32 {
    gibench_harness::rng::SplitMix64::from_state(k).next_f32()
}

/// The two ray sets of `count` rays each for `frame` of `scene` seen at `resolution`: the
/// reference's BVH and ε, its camera rays and its cosine sampling (see the module docs).
pub(crate) fn make_rays(
    scene: &Scene,
    frame: &gibench_harness::scene::anim::FrameState,
    resolution: [u32; 2],
    count: u32,
) -> Result<(Vec<u8>, Vec<u8>)> {
    let tracer = ReferenceTracer::new(scene, frame);
    let (bvh, eps) = (tracer.bvh(), tracer.epsilon());
    let [w, h] = resolution;
    // The primary hits, in pixel order: (point, geometric normal, shading normal).
    let hits: Vec<(Vec3, Vec3, Vec3)> = (0..w * h)
        .into_par_iter()
        .filter_map(|i| {
            let (origin, dir) = camera_ray(frame, resolution, i % w, i / w);
            let hit = bvh.closest_hit(origin, dir, 0.0, f32::INFINITY)?;
            Some((hit.position, hit.geometric_normal, hit.shading_normal))
        })
        .collect();
    if hits.is_empty() {
        return Err(Error::param(
            "rays",
            "no pixel of the frame sees the scene, so there is nowhere to start rays from",
        ));
    }
    let light = &frame.light;
    let far = 2.0 * scene.extent.diagonal;
    let mut closest = Vec::with_capacity(count as usize * RAY_BYTES);
    let mut shadow = Vec::with_capacity(count as usize * RAY_BYTES);
    for k in 0..count as u64 {
        let (p, ng, ns) = hits[(uniform(3 * k) * hits.len() as f32) as usize % hits.len()];
        let u = Vec2::new(uniform(3 * k + 1), uniform(3 * k + 2));
        let mut dir = cosine_direction(ns, u);
        if dir.dot(ng) <= 0.0 {
            dir = cosine_direction(ng, u);
        }
        let origin = p + ng * eps;
        let to_light = match light.kind {
            LightKind::Sun => -light.direction.normalize_or(Vec3::NEG_Y) * far,
            _ => light.position - origin,
        };
        for (out, ray) in [
            (
                &mut closest,
                Ray {
                    origin,
                    dir,
                    t_max: f32::INFINITY,
                },
            ),
            (
                &mut shadow,
                Ray {
                    origin,
                    dir: to_light,
                    t_max: 1.0 - 1e-4,
                },
            ),
        ] {
            for c in ray.origin.to_array().into_iter().chain(ray.dir.to_array()) {
                out.extend_from_slice(&c.to_le_bytes());
            }
            out.extend_from_slice(&ray.t_max.to_le_bytes());
        }
    }
    Ok((closest, shadow))
}

/// Reads a ray file, refusing one whose size is not a whole, non-zero number of rays.
pub(crate) fn read_rays(path: &Path) -> Result<Vec<Ray>> {
    let bytes = gibench_harness::error::read_bounded(path, MAX_RAYS as u64 * RAY_BYTES as u64)
        .map_err(|e| Error::param("rays", format!("cannot read {}: {e}", path.display())))?;
    if bytes.is_empty() || bytes.len() % RAY_BYTES != 0 {
        return Err(Error::param(
            "rays",
            format!(
                "{}: {} bytes is not a whole number of rays ({RAY_BYTES} bytes each, at least one)",
                path.display(),
                bytes.len()
            ),
        ));
    }
    let f = |b: &[u8], i: usize| {
        f32::from_le_bytes([b[4 * i], b[4 * i + 1], b[4 * i + 2], b[4 * i + 3]])
    };
    Ok(bytes
        .chunks_exact(RAY_BYTES)
        .map(|b| Ray {
            origin: Vec3::new(f(b, 0), f(b, 1), f(b, 2)),
            dir: Vec3::new(f(b, 3), f(b, 4), f(b, 5)),
            t_max: f(b, 6),
        })
        .collect())
}
