//! [`PathRing`]: the light paths `keller-incremental` keeps, refilled oldest first, and the
//! VPLs they hold with their shadow-map slots.

use gibench_harness::cpu::bvh::SceneBvh;
use gibench_harness::cpu::vpl::{self, Vpl, VplSettings};
use gibench_harness::scene::anim::LightPose;
use gibench_harness::scene::Scene;

/// The ring of `keller-incremental`: N path slots, each holding the VPLs of one light path; the
/// path with Halton index h lives in slot h mod N. Refilled oldest first with consecutive
/// Halton indices, the ring always holds N consecutive indices, one per residue mod N, so
/// Keller's fractional absorption ([`vpl::generate`]: ⌊ρ̄^(j−1) N⌋ paths reach vertex j,
/// weighted by N over that count) gives it exactly `keller-full`'s counts and weights whatever
/// the per-frame budget. The VPL of slot p's vertex b lives in shadow-map slot p · bounces + b.
pub struct PathRing {
    paths: u32,
    bounces: u32,
    average_reflectance: f32,
    ring: Vec<Vec<Vpl>>,
    /// Halton index of the next path (its slot is `next_path mod paths`: the oldest).
    next_path: u64,
}

impl PathRing {
    /// An empty ring of `paths` light paths of up to `bounces` vertices.
    pub fn new(paths: u32, bounces: u32, average_reflectance: f32) -> PathRing {
        PathRing {
            paths: paths.max(1),
            bounces: bounces.max(1),
            average_reflectance,
            ring: vec![Vec::new(); paths.max(1) as usize],
            next_path: 0,
        }
    }

    /// N.
    pub fn paths(&self) -> u32 {
        self.paths
    }

    /// Replaces the oldest `count` paths (at most N) by new ones traced from `light`; returns
    /// the new VPLs with their shadow-map slots.
    pub fn advance(
        &mut self,
        scene: &Scene,
        bvh: &SceneBvh,
        light: &LightPose,
        count: u32,
    ) -> Vec<(u32, Vpl)> {
        let count = count.min(self.paths);
        let settings = VplSettings {
            paths: count,
            bounces: self.bounces,
            first_path: self.next_path,
            normalisation_paths: self.paths,
            average_reflectance: Some(self.average_reflectance),
        };
        let batch = vpl::generate(scene, bvh, light, &settings);
        let mut new_vpls = Vec::new();
        for k in 0..count as u64 {
            let h = self.next_path + k;
            let p = (h % self.paths as u64) as u32;
            let path: Vec<Vpl> = batch.iter().filter(|v| v.path == h).copied().collect();
            for (b, v) in path.iter().enumerate() {
                new_vpls.push((p * self.bounces + b as u32, *v));
            }
            self.ring[p as usize] = path;
        }
        self.next_path += count as u64;
        new_vpls
    }

    /// Every VPL in the ring with its shadow-map slot.
    pub fn vpls(&self) -> Vec<(u32, Vpl)> {
        let bounces = self.bounces;
        self.ring
            .iter()
            .enumerate()
            .flat_map(|(p, path)| {
                path.iter()
                    .enumerate()
                    .map(move |(b, v)| (p as u32 * bounces + b as u32, *v))
            })
            .collect()
    }
}
