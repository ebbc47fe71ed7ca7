//! `barczak` (in progress): Barczak 2006, "Interactive Illumination Using Large Sets of Point
//! Lights" (M.S. thesis, University of Maryland) — light-mapped, visibility-culled instant
//! radiosity with moving objects.
//!
//! What exists so far, each part tested on the CPU:
//!
//! * [`visibility`] — §4.3.1: occlusion pyramids from patches (and complex objects' bounding
//!   spheres) to each light, polygon and sphere blockers, lights classified unblocked / partial /
//!   fully blocked, hierarchical patch subdivision with early termination.
//! * [`database`] — §4.5.1–4.5.2: the visibility database of every receiver node and light,
//!   updated by Table 4-1 when an object moves, with the light-map changes and the shadow
//!   maps a motion affects.
//! * [`lightmap`] — §4.3.2, §4.5.2: a light map per leaf sub-patch holding its lit lights'
//!   irradiance without visibility, updated by single lights when a motion blocks or frees
//!   them; with the partial lights' subtraction it equals summing every light with visibility.
//! * [`lightmap_pass`] — §4.3.2 on the GPU: the light maps drawn for every patch leaf the camera
//!   sees (one draw), bilinear inside each leaf.
//! * [`light_draws`] — §4.3.2's second pass drawn as §4.3.4–4.3.5 do: per optimised element,
//!   draws of up to K lights (shared octahedral atlas lookups), subtracting the occluded partial
//!   lights after the light maps (Full), or adding lights with lookups only where partial (VD)
//!   or everywhere (Naive); the draws are counted.
//! * [`passes`] — §4.3.5: the greedy render-pass optimiser of Figure 4-10 over elements (sets of
//!   objects with the lights they share), a pass drawing up to K lights.
//! * [`schedule`] — §4.5.3: shadow maps a motion made out of date re-rendered a fixed number
//!   per frame, by brightness × frames out of date.
//! * [`prt`] — §4.4: 5th-order SH transfer per vertex of a complex mesh (self-shadowed, by ray
//!   casts, prepared once), the lighting environment at its centre from the visible light
//!   samples, and irradiance as their dot product.
//! * [`setup`] — the above put together from a scene once: receivers and blockers from the
//!   scene's patches and movers (`gibench_harness::scene::Patch`; the `barczak-*` rooms record
//!   them), light samples, the database and the light maps.
//! * [`prt_pass`] — §4.4 on the GPU: each mover drawn once, per vertex its transfer dotted with
//!   the lighting environment (taken into the mover's frame).
//! * [`renderer`] — the parts wired frame after frame: movers moved in the database, light maps
//!   and shadow maps updated (by priority), the subtraction planned and drawn, movers lit by PRT.
//! * [`samples`] — §4.1: the direct light samples on area emitters and the indirect ones from
//!   random walks, computed once from the static geometry.
//!
//! The shadow maps are the shared atlas's octahedral kind (§4.2.1,
//! `gibench_harness::ir::atlas::MapKind::Octahedral`), the low-resolution pass's mask the kit's
//! `EdgeMask`. Still to come (issue 11): the low-resolution pass itself (VD+LP, and Full's),
//! the technique's registry and conformance entries (timed stages, counters) and
//! `gibench reproduce barczak2006`; until then `barczak` is not in the technique registry.

pub mod database;
pub mod light_draws;
pub mod lightmap;
pub mod lightmap_pass;
pub mod lowres;
pub mod passes;
pub mod prt;
pub mod prt_pass;
pub mod renderer;
pub mod samples;
pub mod schedule;
pub mod setup;
pub mod visibility;
