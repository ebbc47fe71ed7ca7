//! A scene's trees across frames: the static mesh's tree, built once per scene and shared by
//! every frame (and by the techniques' CPU rays), and each mover's tree, built per frame over
//! the mover in that frame's pose. [`FrameBvh`] is one frame's two levels: the static tree and
//! the movers' trees, queried in that order.
//!
//! Why the movers' trees are rebuilt per frame in world space rather than built once in object
//! space with each ray transformed into it: a ray transformed into object space gives other
//! roundings of `t`, `u` and `v` than the same ray against the world-space triangles, and the
//! reference's images must stay bit for bit those of one tree over the frame's whole mesh
//! ([`crate::cpu::reference::frame_mesh`]). Movers are small (the bunny: 3,674 triangles), so their
//! trees cost about 10 CPU-ms a frame; the static mesh's (Sibenik: 80k triangles, 0.28 CPU-s)
//! is the one worth keeping.
//!
//! The top level is the list itself (static tree, then movers in descriptor order): scenes have
//! one or two movers, and each tree's root boxes cull the rays that miss it.

use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, OnceLock};

use glam::{Mat3, Mat4, Vec3};

use super::{Hit, SceneBvh};
use crate::scene::anim::FrameState;
use crate::scene::{Mesh, Mover, Scene};

/// `mover`'s mesh in world space under the object → world transform `model`: positions
/// transformed, normals by the inverse transpose and renormalised (zero where they vanish).
/// [`crate::cpu::reference::frame_mesh`] appends exactly these values.
pub fn mover_mesh(mover: &Mover, model: Mat4) -> Mesh {
    let normal_matrix = Mat3::from_mat4(model).inverse().transpose();
    let mut mesh = mover.mesh.clone();
    for p in &mut mesh.positions {
        *p = model.transform_point3(*p);
    }
    for n in &mut mesh.normals {
        *n = (normal_matrix * *n).normalize_or_zero();
    }
    mesh
}

/// One frame's geometry for ray queries: the static tree and the movers' trees.
///
/// Its answers are those of one [`SceneBvh`] over the frame's whole mesh (static mesh, then the
/// movers appended in order, triangle ids numbered the same way), bit for bit, except where a
/// ray's closest hit is an exact tie in `t` between two different triangles: one tree returns
/// whichever of them its traversal meets first, which depends on the tree's shape; here a tie
/// between trees goes to the earlier tree (the static one first), and a tie within the static
/// tree is resolved by the static tree's shape, not the combined tree's. Any-hit answers are
/// the same without exception. A static scene's frame is its static tree alone: the same tree
/// as one built over the frame's mesh, so the same answers with no exception.
pub struct FrameBvh {
    statics: Arc<SceneBvh>,
    /// Each mover's tree (world space, this frame) and the id of its first triangle.
    movers: Vec<(SceneBvh, u32)>,
}

impl FrameBvh {
    /// The static tree and the movers' trees, in the frame mesh's order.
    pub fn new(statics: Arc<SceneBvh>, movers: Vec<SceneBvh>) -> FrameBvh {
        let mut first = statics.triangle_count() as u32;
        let movers = movers
            .into_iter()
            .map(|m| {
                let at = first;
                first += m.triangle_count() as u32;
                (m, at)
            })
            .collect();
        FrameBvh { statics, movers }
    }

    /// Number of triangles (static and movers).
    pub fn triangle_count(&self) -> usize {
        self.statics.triangle_count()
            + self
                .movers
                .iter()
                .map(|(m, _)| m.triangle_count())
                .sum::<usize>()
    }

    /// Number of triangles in the trees themselves (see [`SceneBvh::tree_triangle_count`]).
    pub fn tree_triangle_count(&self) -> usize {
        self.statics.tree_triangle_count()
            + self
                .movers
                .iter()
                .map(|(m, _)| m.tree_triangle_count())
                .sum::<usize>()
    }

    /// [`SceneBvh::closest_hit`] over every tree: each later tree is asked only for hits nearer
    /// than the best so far, so a tie stays with the earlier tree.
    #[inline]
    pub fn closest_hit(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Option<Hit> {
        let mut best = self.statics.closest_hit(origin, dir, t_min, t_max);
        for (tree, first) in &self.movers {
            let limit = best.map_or(t_max, |h| h.t);
            if let Some(mut hit) = tree.closest_hit(origin, dir, t_min, limit) {
                hit.triangle += first;
                best = Some(hit);
            }
        }
        best
    }

    /// [`SceneBvh::any_hit`] over every tree.
    #[inline]
    pub fn any_hit(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> bool {
        self.statics.any_hit(origin, dir, t_min, t_max)
            || self
                .movers
                .iter()
                .any(|(tree, _)| tree.any_hit(origin, dir, t_min, t_max))
    }

    /// [`SceneBvh::occluded`] over every tree.
    pub fn occluded(&self, a: Vec3, b: Vec3, eps: f32) -> bool {
        self.statics.occluded(a, b, eps)
            || self.movers.iter().any(|(tree, _)| tree.occluded(a, b, eps))
    }
}

/// How many trees a [`SceneTrees`] has built.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TreeBuilds {
    /// Builds of the static mesh's tree: at most one per scene.
    pub static_tree: u32,
    /// Builds of movers' trees: one per mover per frame set up.
    pub mover_trees: u32,
}

/// One scene's trees: the static mesh's, built on first use and kept, and the movers' per
/// frame ([`SceneTrees::frame`]). Shared by reference and not copied: every frame set up from
/// it shares the one static tree. Counts what it builds ([`SceneTrees::builds`]).
pub struct SceneTrees<'a> {
    scene: &'a Scene,
    statics: OnceLock<(Arc<SceneBvh>, (Vec3, Vec3))>,
    static_builds: AtomicU32,
    mover_builds: AtomicU32,
}

/// The fold of `positions` into (min, max), starting from `acc` (glam's `min`/`max`: exact, so
/// folding the parts of a mesh in order gives the whole mesh's bits).
fn fold_bounds(acc: (Vec3, Vec3), positions: &[Vec3]) -> (Vec3, Vec3) {
    positions
        .iter()
        .fold(acc, |(lo, hi), p| (lo.min(*p), hi.max(*p)))
}

/// The start of [`fold_bounds`], as [`Mesh::bounds`] starts.
const NO_BOUNDS: (Vec3, Vec3) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));

impl<'a> SceneTrees<'a> {
    /// No tree built yet.
    pub fn new(scene: &'a Scene) -> SceneTrees<'a> {
        SceneTrees {
            scene,
            statics: OnceLock::new(),
            static_builds: AtomicU32::new(0),
            mover_builds: AtomicU32::new(0),
        }
    }

    /// The scene.
    pub fn scene(&self) -> &'a Scene {
        self.scene
    }

    fn statics(&self) -> &(Arc<SceneBvh>, (Vec3, Vec3)) {
        self.statics.get_or_init(|| {
            self.static_builds.fetch_add(1, Ordering::Relaxed);
            let mesh = &self.scene.mesh;
            (
                Arc::new(SceneBvh::new(mesh)),
                fold_bounds(NO_BOUNDS, &mesh.positions),
            )
        })
    }

    /// The static mesh's tree (built on the first call).
    pub fn static_tree(&self) -> &Arc<SceneBvh> {
        &self.statics().0
    }

    /// `frame`'s trees (the movers' built now, in `frame`'s pose; identity where the frame has
    /// no transform for a mover) and the bounds of the frame's whole mesh, bit for bit
    /// [`Mesh::bounds`] of [`crate::cpu::reference::frame_mesh`].
    pub fn frame(&self, frame: &FrameState) -> (FrameBvh, (Vec3, Vec3)) {
        let (statics, static_bounds) = self.statics();
        let mut bounds = *static_bounds;
        let mut vertices = self.scene.mesh.positions.len();
        let movers = (self.scene.movers.iter().enumerate())
            .map(|(i, mover)| {
                let model = frame.movers.get(i).copied().unwrap_or(Mat4::IDENTITY);
                let mesh = mover_mesh(mover, model);
                bounds = fold_bounds(bounds, &mesh.positions);
                vertices += mesh.positions.len();
                self.mover_builds.fetch_add(1, Ordering::Relaxed);
                SceneBvh::new(&mesh)
            })
            .collect();
        if vertices == 0 {
            bounds = (Vec3::ZERO, Vec3::ZERO);
        }
        (FrameBvh::new(statics.clone(), movers), bounds)
    }

    /// The trees built so far.
    pub fn builds(&self) -> TreeBuilds {
        TreeBuilds {
            static_tree: self.static_builds.load(Ordering::Relaxed),
            mover_trees: self.mover_builds.load(Ordering::Relaxed),
        }
    }
}
