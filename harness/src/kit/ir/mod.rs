//! # The instant-radiosity kit
//!
//! The parts every VPL technique composes, each owning what it reads and writes (documented at
//! the top of its file), wired by a few lines in the technique — no render graph:
//!
//! ```text
//!  VPLs (CPU list, or a GPU pass)        scene meshes (DrawSet)
//!        │                                     │
//!        ▼                                     ▼
//!   ┌──────────┐   slot, VPL views     ┌────────────────┐
//!   │ VplStore │ ───────────────────▶  │ AtlasRasteriser│ ──▶ ┌─────────────┐
//!   └──────────┘                       └────────────────┘     │ ShadowAtlas │ ◀── other writers
//!        │                                                    └─────────────┘     (point splats,
//!        │             G-buffer ──▶ Interleave::split               │              pull-push)
//!        │                               │                          │
//!        └──────────────▶  Accumulation  ◀──────────────────────────┘
//!                               │ split irradiance
//!                               ▼
//!                 Interleave::combine ──▶ Interleave::filter ──▶ indirect irradiance
//! ```
//!
//! * [`store::VplStore`] — slot-indexed VPLs on the GPU, written by the CPU or a GPU pass.
//! * [`atlas::ShadowAtlas`] — one visibility map per slot (paraboloid, cube or octahedral; 16/32-bit depth
//!   or a 32-bit float texture), its parameters and its WGSL lookup.
//! * [`raster::AtlasRasteriser`] — renders chosen slots of a depth atlas from a
//!   [`DrawSet`](crate::kit::passes::DrawSet), uploading its own views; octahedral maps only into
//!   the faces [`face_cull::Occluders`] finds occluders in, where the technique asks.
//! * [`interleave::Interleave`] — split, combine and the geometry-aware filter (Laine et al.
//!   2007 §5).
//! * [`accumulate::Accumulation`] — a store and an atlas through the interleaving.
//! * [`rsm::ReflectiveShadowMap`] — the scene seen from the primary light: positions, normals
//!   and reflected flux per texel, for the VPL sampler.
//! * [`vpl_sample::VplSampler`] — VPLs importance-sampled by brightness from reflective
//!   shadow-map texels into the store, on the GPU.
//! * [`points`] — the scene's surfaces as a shuffled pool of points, uniform by area.
//! * [`splat::PointSplat`] — imperfect shadow maps' depth: each VPL's own subset of a point
//!   pool splatted into its paraboloid map, one dispatch for all VPLs (Ritschel et al. 2008).
//! * [`pullpush::PullPush`] — fills the splats' holes in every map at once and writes them
//!   into a float atlas.
//! * [`edges::EdgeMask`] — pixels where the G-buffer's surface plane changes within a few
//!   pixels, for a low-resolution illumination pass (Barczak 2006 §4.3.3).
//! * [`gather::VplGather`] — the common case wired: CPU list, rasterised static casters,
//!   interleaved gathering, with the shared parameters and stage names.

pub mod accumulate;
pub mod atlas;
pub mod edges;
pub mod face_cull;
pub mod gather;
pub mod interleave;
pub mod points;
pub mod pullpush;
pub mod raster;
pub mod rsm;
pub mod splat;
pub mod store;
pub mod vpl_sample;
