//! `laine`: Laine, Saransaari, Kontkanen, Lehtinen and Aila 2007, "Incremental Instant
//! Radiosity for Real-Time Indirect Illumination".
//!
//! VPLs are reused across frames; every frame the CPU manages them (§4), then only the shadow
//! maps of new VPLs are rendered and all VPLs are gathered with the harness's interleaved
//! sampling (§5), exactly as the comparison method (`keller-full`) does:
//!
//! 1. **Validity** (§4.4): a VPL is invalid when a shadow ray from the new light position to it
//!    is blocked by static geometry, when its surface now faces away from the light, or, for spot
//!    lights, when it has left the illuminated hemisphere.
//! 2. **Deletion** (§4.5): invalid VPLs are removed; then, while fewer than `recalc-min` slots
//!    are free, the shortest Delaunay edge is found and the endpoint whose distance to its
//!    second-closest neighbour is smaller is deleted.
//! 3. **Creation** (§4.6): a new sampling point goes to the centre of the largest empty circle
//!    of the domain (unit disc for spot lights, unit sphere for omni lights; [`domain`]); a ray
//!    is cast; a hit creates a VPL and its paraboloid map, a miss creates none. Repeated until
//!    `recalc-max` new points or `vpls` VPLs (the paper's maxLights).
//! 4. **Intensities** (§4.7): each VPL's flux is the light's power times its sampling point's
//!    Voronoi area over the domain's area (π or 4π), times the albedo at the VPL.
//!
//! Deviations (also in the README): the sphere is triangulated on its surface (stereographic
//! projection into `spade`) instead of with a 3D tetrahedralisation, as the paper's §6 asks for;
//! the sampling points are re-derived from the VPLs' positions each frame and last frame's
//! triangulation is moved with them, the few sites whose motion breaks it taken out and put
//! back (`SamplingDomain::update_sites`; the paper does not say how its triangulation follows
//! the moving points — the result is their Delaunay triangulation either way); the first
//! frame fills all `vpls` slots (the paper does not describe start-up); intensities are
//! normalised by the domain's area, and a sampling point whose ray left the scene stays in the
//! domain (fixed relative to the light, re-tested each frame) so that its share of the power
//! leaves the scene instead of being handed to its neighbours (with every ray hitting, this is
//! the paper's "scaled so that their sum equals the total power"); VPL management runs on the frame's critical path
//! and is timed as its own CPU stage (the paper overlapped it with GPU work with a one-frame
//! delay; the `vpl-management` stage shows what that overlap hides). Area lights are managed as
//! spot lights at their centre.
//!
//! Layout: `params` (the parameters), `manager` (the per-frame management, one phase per
//! step), [`domain`] (the sampling points and their triangulation), `lec` (the kept
//! largest-empty-circle candidates); this file holds the registry entry and the technique.

pub mod domain;
mod lec;
mod manager;
mod params;

pub use manager::{Manager, Step, StepTimes};
pub use params::LaineParams;

use domain::SamplingDomain;
use gibench_harness::cpu::vpl::Vpl;
use gibench_harness::glam::Vec3;
use gibench_harness::kit::ir::gather::{VplGather, GATHER_PARAMS};
use gibench_harness::kit::ir::raster::AtlasClear;
use gibench_harness::kit::passes::DrawSet;
use gibench_harness::kit::technique::{
    cornell_boxes, prepare_nothing, Conformance, Converged, FrameContext, Knob, Params,
    PrepareContext, Prepared, Technique, TechniqueInfo,
};
use gibench_harness::scene::anim::LightPose;
use gibench_harness::{wgpu, Result};
use manager::domain_kind;
use params::OWN_PARAMS;

/// Stage: the CPU VPL management of §4 (validity, deletion, creation, intensities).
pub const STAGE_VPL_MANAGEMENT: &str = "vpl-management";
/// Laine's own stage, declared.
const OWN_STAGES: &[gibench_harness::kit::technique::Stage] =
    &[gibench_harness::kit::technique::Stage::cpu(
        STAGE_VPL_MANAGEMENT,
    )];

/// `laine` registry entry.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "laine",
    paper: "Laine et al. 2007",
    summary: "incremental instant radiosity",
    description: "Laine et al. 2007 incremental instant radiosity: reuse valid VPLs, recompute a few per frame",
    stages: &[OWN_STAGES, gibench_harness::kit::ir::gather::SHADOW_MAP_STAGES, gibench_harness::kit::ir::gather::GATHER_STAGES],
    params: &[OWN_PARAMS, GATHER_PARAMS],
    required_features: wgpu::Features::empty(),
    required_limits: wgpu::Limits::downlevel_defaults,
    reference: gibench_harness::kit::technique::one_bounce,
    // On the Cornell boxes against the one-bounce reference (64 VPLs, 4x4 tiles; measured on
    // lavapipe, 96x72, after three frames): the same VPL count as keller-*, the mean within 6 %.
    conformance: Conformance {
        defaults: &cornell_boxes([
            (1.039, 0.383),
            (0.941, 0.332),
            (0.966, 0.711),
            (0.964, 0.596),
        ]),
        converged: Converged {
            params: &["vpls=1024"],
            why: "1024 VPLs (16x the defaults; 64 per pixel under the 4x4 tiles): the VPLs' noise and hot spots shrink; left: the clamp (k = 10), the shadow maps' depth bias and VPLs kept from earlier frames",
            boxes: &cornell_boxes([(1.027, 0.150), (1.008, 0.128), (0.996, 0.648), (0.947, 0.207)]),
        },
    },
    knob: Some(Knob::VPLS),
    prepare: prepare_nothing,
    create,
};

/// The technique: management plus the shared gathering.
pub struct Laine {
    gather: VplGather,
    manager: Manager,
}

fn create(params: &Params, ctx: &PrepareContext, _: &Prepared) -> Result<Box<dyn Technique>> {
    let p = LaineParams::from_params(params)?;
    let gather = VplGather::new(&p.gather, ctx, p.max_lights, Some(DrawSet::StaticCasters))?;
    let manager = Manager::new(p.max_lights, p.recalc_min, p.recalc_max);
    Ok(Box::new(Laine { gather, manager }))
}

impl Technique for Laine {
    fn render(&mut self, ctx: &mut FrameContext) -> Result<()> {
        let (scene, bvh, light) = (ctx.scene, ctx.bvh, ctx.frame.light);
        let manager = &mut self.manager;
        let (step, list) = ctx.profiler.cpu_stage(STAGE_VPL_MANAGEMENT, || {
            let step = manager.step(scene, bvh, light);
            (step, manager.vpls())
        });
        ctx.profiler
            .count("new-sampling-points", step.created as f64);
        ctx.profiler.count("deleted-vpls", step.deleted as f64);
        ctx.profiler
            .count("rim-sampling-points", step.on_rim as f64);
        ctx.profiler.count("dispersion", self.manager.dispersion());
        let new: Vec<(u32, Vpl)> = list
            .iter()
            .filter(|(slot, _)| step.new_slots.contains(slot))
            .copied()
            .collect();
        // Only the new VPLs' maps are rendered; every other map is kept.
        self.gather
            .render_maps(ctx, &new, AtlasClear::RenderedSlots)?;
        self.gather.gather(ctx, &list)
    }

    fn output(&self) -> &wgpu::TextureView {
        self.gather.output()
    }
}

/// Sampling-point dispersion helper for tests and plots: the largest empty circle's radius of
/// the given points in the light's domain.
pub fn dispersion_of(light: &LightPose, samples: &[Vec3]) -> f64 {
    let mut d = SamplingDomain::new(domain_kind(light));
    for (i, s) in samples.iter().enumerate() {
        let _ = d.insert(i as u64, s.as_dvec3());
    }
    d.dispersion()
}
