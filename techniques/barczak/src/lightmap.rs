//! Light maps (Barczak 2006 §4.3.2, §4.5.2).
//!
//! Reads: the visibility database (which lights light each leaf: unblocked or partial), each
//! light's flux, the leaves' geometry.
//! Writes: per leaf (sub-patch) of every patch receiver, a `res` × `res` light map: at each
//! texel centre the irradiance of the leaf's lit lights *without* visibility; and, per motion,
//! the maps updated by adding or removing single lights' contributions (a light becoming fully
//! blocked or lit again; unblocked ⇄ partial needs no change).
//!
//! At render time the light map gives every light's irradiance; the shadow maps then subtract
//! the contributions of the lights that are partial on the leaf and occluded at the pixel. That
//! equals summing every light with its visibility (tested on the CPU with ray casts in place of
//! shadow maps). A separate map per sub-patch, as the thesis found necessary to keep
//! interpolation from crossing sub-patches with different lights.
//!
//! A light's irradiance at x with normal n: a light sample with normal N emits Φ/π · cos θ
//! (an omni light Φ/4π), so E = I(θ) · max(0, n·ω) / r², ω the unit direction to the light.

use gibench_harness::cpu::light::point_irradiance;
use glam::Vec3;

use crate::database::{LightMapChange, ReceiverShape, VisibilityDatabase};
use crate::visibility::{LightState, PatchTree, PointLight};

/// The irradiance at `x` (normal `n`) from `light` of flux `flux`, without visibility (the
/// harness's [`point_irradiance`]).
pub fn contribution(light: &PointLight, flux: Vec3, x: Vec3, n: Vec3) -> Vec3 {
    point_irradiance(light.position, light.normal, flux, x, n)
}

/// The centre of texel (i, j) of a `res`² map on `node` of `tree` (i along the first edge).
pub fn texel_position(tree: &PatchTree, node: usize, res: u32, i: u32, j: u32) -> Vec3 {
    let [a, b, c, d] = tree.nodes[node].corners;
    let (s, t) = ((i as f32 + 0.5) / res as f32, (j as f32 + 0.5) / res as f32);
    a.lerp(b, s).lerp(d.lerp(c, s), t)
}

/// Every leaf's light map (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct LightMaps {
    pub res: u32,
    /// `[receiver][node]`: the texels (row j, column i) of a patch leaf; empty otherwise.
    maps: Vec<Vec<Vec<Vec3>>>,
}

fn lit(state: LightState) -> bool {
    matches!(state, LightState::Unblocked | LightState::Partial)
}

impl LightMaps {
    /// The maps of every patch leaf of `db` at `res`² texels, lights of `flux`.
    pub fn bake(db: &VisibilityDatabase, flux: &[Vec3], res: u32) -> LightMaps {
        let mut maps = LightMaps {
            res,
            maps: db
                .receivers
                .iter()
                .map(|r| vec![Vec::new(); r.node_count()])
                .collect(),
        };
        for (r, receiver) in db.receivers.iter().enumerate() {
            let ReceiverShape::Patch(tree) = &receiver.shape else {
                continue;
            };
            for n in tree.leaves() {
                maps.maps[r][n] = vec![Vec3::ZERO; (res * res) as usize];
                for l in 0..db.lights.len() {
                    if lit(db.state(r, n, l)) {
                        maps.add(db, flux, r, n, l, 1.0);
                    }
                }
            }
        }
        maps
    }

    /// Adds `sign` × light `l`'s contribution to leaf `n` of receiver `r`.
    fn add(
        &mut self,
        db: &VisibilityDatabase,
        flux: &[Vec3],
        r: usize,
        n: usize,
        l: usize,
        sign: f32,
    ) {
        let ReceiverShape::Patch(tree) = &db.receivers[r].shape else {
            return;
        };
        let res = self.res;
        let map = &mut self.maps[r][n];
        for j in 0..res {
            for i in 0..res {
                let x = texel_position(tree, n, res, i, j);
                map[(j * res + i) as usize] +=
                    sign * contribution(&db.lights[l], flux[l], x, tree.normal);
            }
        }
    }

    /// Applies a motion's light-map changes (after [`VisibilityDatabase::move_object`]). The
    /// mover's own patches moved: rebake them.
    pub fn apply(
        &mut self,
        db: &VisibilityDatabase,
        flux: &[Vec3],
        changes: &[LightMapChange],
        moved: u32,
    ) {
        for c in changes {
            if db.receivers[c.receiver as usize].object == moved {
                continue;
            }
            let sign = if c.add { 1.0 } else { -1.0 };
            self.add(
                db,
                flux,
                c.receiver as usize,
                c.node as usize,
                c.light as usize,
                sign,
            );
        }
        for (r, receiver) in db.receivers.iter().enumerate() {
            if receiver.object != moved {
                continue;
            }
            if let ReceiverShape::Patch(tree) = &receiver.shape {
                for n in tree.leaves() {
                    self.maps[r][n].iter_mut().for_each(|t| *t = Vec3::ZERO);
                    for l in 0..db.lights.len() {
                        if lit(db.state(r, n, l)) {
                            self.add(db, flux, r, n, l, 1.0);
                        }
                    }
                }
            }
        }
    }

    /// The texels of leaf `node` of receiver `receiver` (row by row; empty if not a patch leaf).
    pub fn texels(&self, receiver: usize, node: usize) -> &[Vec3] {
        &self.maps[receiver][node]
    }
}
