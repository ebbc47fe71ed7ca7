//! The scene as Barczak's technique sees it, prepared once (§4.1, §4.3, §4.5): receivers and
//! blockers from the scene's patches and movers, the light samples, the visibility database
//! and the light maps.
//!
//! Reads: the scene's patches (generated scenes record them: the `barczak-*` rooms), its movers
//! and their poses at the first frame, the light's pose, the static BVH.
//! Writes: [`BarczakScene`].
//!
//! * The patches are the scene's recorded ones, or, where it records none, its planar charts
//!   (`Scene::receiver_patches`: the Cornell boxes, Sibenik, Sponza, …): each chart's smallest
//!   rectangle, standing for the chart's triangles ([`PatchTree::surface`]).
//! * Every patch is a receiver, split `levels` times; a patch that casts shadows is also a
//!   blocker: its rectangle, or a chart's convex hull — a polygon blocker when the triangles
//!   fill the hull, otherwise a [`Shape::Chart`], which blocks only partially. Patches of one
//!   object never shadow each other.
//! * Every mover is a complex object: its bounding sphere (about its origin, posed) is both a
//!   receiver (lit by PRT) and a sphere blocker; mover k is object `first_mover_object + k`.
//! * The light samples are oriented point lights at the sample positions.

use gibench_harness::cpu::bvh::SceneBvh;
use gibench_harness::scene::anim::{FrameState, LightPose};
use gibench_harness::scene::Scene;
use gibench_harness::Result;
use glam::{Mat4, Vec3};

use crate::database::{Receiver, ReceiverShape, VisibilityDatabase};
use crate::lightmap::LightMaps;
use crate::samples::{self, LightSamples, SampleSettings};
use crate::visibility::{Blocker, PatchTree, PointLight, Shape};

/// A mover's bounding sphere in its own space (centre, radius).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MoverBounds {
    pub center: Vec3,
    pub radius: f32,
}

impl MoverBounds {
    /// The sphere posed by `model` (rigid, uniformly scaled).
    pub fn posed(&self, model: Mat4) -> (Vec3, f32) {
        let scale = model.x_axis.truncate().length();
        (model.transform_point3(self.center), self.radius * scale)
    }
}

/// See the module docs.
#[derive(Clone, Debug)]
pub struct BarczakScene {
    pub samples: LightSamples,
    /// Each light's flux, in database order (direct samples first).
    pub flux: Vec<Vec3>,
    pub db: VisibilityDatabase,
    pub light_maps: LightMaps,
    pub movers: Vec<MoverBounds>,
    /// The object number of mover 0.
    pub first_mover_object: u32,
}

impl BarczakScene {
    /// The patch receivers (recorded patches or generated charts) and their leaves.
    pub fn patches_and_leaves(&self) -> (usize, usize) {
        let trees = self.db.receivers.iter().filter_map(|r| match &r.shape {
            ReceiverShape::Patch(t) => Some(t),
            ReceiverShape::Object { .. } => None,
        });
        trees.fold((0, 0), |(p, l), t| (p + 1, l + t.leaves().count()))
    }
}

/// Subdivision levels at most of the chart patches of a scene that records none.
pub const CHART_LEVELS: u32 = 2;
/// Charts a scene without recorded patches may make by default (the `max-charts` parameter):
/// Sibenik (25,010), Sponza (26,414), Maze (53,219) and the conference room (115,302) fit; the
/// conference room's preparation takes about a minute and 2.4 GB on a 2-core machine
/// (results/barczak-scenes/).
pub const MAX_CHARTS: usize = 200_000;

/// The light maps' size: `res`² texels a leaf, in a buffer of at most `max_bytes`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightMapSize {
    pub res: u32,
    pub max_bytes: u64,
}

/// Prepares `scene` at `frame` (the movers' poses) with light `light` (see the module docs).
/// Errors name the scene when it records no patches and makes more than `max_charts` charts,
/// before any work per chart, and `light-map-res` when the light maps would not fit in
/// `light_maps.max_bytes`, before the visibility database is built.
pub fn prepare(
    scene: &Scene,
    bvh: &SceneBvh,
    frame: &FrameState,
    light: &LightPose,
    settings: SampleSettings,
    light_maps: LightMapSize,
    max_charts: usize,
) -> Result<BarczakScene> {
    let patches = scene.receiver_patches(CHART_LEVELS, max_charts)?;
    let leaves: usize = patches.iter().map(|p| 4usize.pow(p.levels)).sum();
    crate::lightmap_pass::buffer_size(leaves, light_maps.res, light_maps.max_bytes)?;
    let samples = samples::generate(scene, bvh, light, settings)?;
    let lights: Vec<PointLight> = samples
        .all()
        .map(|v| PointLight {
            position: v.position,
            normal: Some(v.normal),
        })
        .collect();
    let flux: Vec<Vec3> = samples.all().map(|v| v.flux).collect();
    let mut receivers = Vec::new();
    let mut blockers = Vec::new();
    for p in &patches {
        let tree = PatchTree::new(p.object, p.corners, p.normal, p.levels);
        receivers.push(Receiver {
            object: p.object,
            shape: ReceiverShape::Patch(match &p.chart {
                Some(c) => tree.with_surface(c.triangles.clone()),
                None => tree,
            }),
        });
        if p.casts_shadows {
            let shape = match &p.chart {
                None => Shape::Polygon(p.corners.to_vec()),
                Some(c) if c.convex => Shape::Polygon(c.hull.clone()),
                Some(c) => Shape::Chart {
                    hull: c.hull.clone(),
                    triangles: c.triangles.clone(),
                },
            };
            blockers.push(Blocker {
                object: p.object,
                shape,
            });
        }
    }
    let first_mover_object = patches.iter().map(|p| p.object).max().unwrap_or(0) + 1;
    let mut movers = Vec::new();
    for (k, m) in scene.movers.iter().enumerate() {
        let (lo, hi) = m.mesh.bounds();
        let center = (lo + hi) * 0.5;
        let radius = m
            .mesh
            .positions
            .iter()
            .map(|p| (*p - center).length())
            .fold(0f32, f32::max);
        let bounds = MoverBounds { center, radius };
        let (c, r) = bounds.posed(frame.movers.get(k).copied().unwrap_or(Mat4::IDENTITY));
        let object = first_mover_object + k as u32;
        receivers.push(Receiver {
            object,
            shape: ReceiverShape::Object {
                center: c,
                radius: r,
            },
        });
        blockers.push(Blocker {
            object,
            shape: Shape::Sphere {
                center: c,
                radius: r,
            },
        });
        movers.push(bounds);
    }
    // Only the movers' blockers are listed per entry (the static ones folded into a summary):
    // what a motion revisits, and a fraction of the memory on a scene of tens of thousands of
    // charts.
    let movable: Vec<u32> = (0..scene.movers.len() as u32)
        .map(|k| first_mover_object + k)
        .collect();
    let (db, _) = VisibilityDatabase::build_keeping_movers(lights, receivers, blockers, &movable);
    let light_maps = LightMaps::bake(&db, &flux, light_maps.res);
    Ok(BarczakScene {
        samples,
        flux,
        db,
        light_maps,
        movers,
        first_mover_object,
    })
}
