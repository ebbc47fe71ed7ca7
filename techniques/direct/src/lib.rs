//! `direct`: the baseline. Direct light only (the harness's shared shadow-mapped direct pass);
//! the indirect irradiance it returns is zero everywhere. Every other technique's cost and
//! error is measured against this floor.
//!
//! Needs: no optional GPU features, WebGL2-level limits.

mod params;

use gibench_harness::kit::technique::{
    cornell_boxes, prepare_nothing, Conformance, Converged, FrameContext, Params, PrepareContext,
    Prepared, Technique, TechniqueInfo,
};
use gibench_harness::wgpu;
use gibench_harness::Result;

use params::PARAMS;

/// Registry entry.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "direct",
    paper: "—",
    summary: "baseline: direct light only",
    description: "direct light only (shadow-mapped primary light); indirect irradiance is zero",
    stages: &[],
    params: &[PARAMS],
    required_features: wgpu::Features::empty(),
    required_limits: wgpu::Limits::downlevel_webgl2_defaults,
    reference: gibench_harness::kit::technique::one_bounce,
    // No indirect light at all: the mean ratio must be exactly zero.
    // No indirect light at all: a mean ratio of exactly 0 and the all-zero image's relative L1.
    conformance: Conformance {
        defaults: &cornell_boxes([(0.0, 1.0); 4]),
        converged: Converged {
            params: &[],
            why: "nothing to converge: the baseline computes no indirect light at any setting",
            boxes: &cornell_boxes([(0.0, 1.0); 4]),
        },
    },
    knob: None,
    prepare: prepare_nothing,
    create,
};

/// The technique: one zero texture, made once.
pub struct Direct {
    view: wgpu::TextureView,
}

fn create(_params: &Params, ctx: &PrepareContext, _: &Prepared) -> Result<Box<dyn Technique>> {
    // Zero-initialised by wgpu and never written: the indirect irradiance is zero.
    let texture =
        gibench_harness::kit::passes::indirect_target(&ctx.gpu.device, ctx.resolution, false);
    Ok(Box::new(Direct {
        view: texture.create_view(&Default::default()),
    }))
}

impl Technique for Direct {
    fn render(&mut self, _ctx: &mut FrameContext) -> Result<()> {
        Ok(())
    }
    fn output(&self) -> &wgpu::TextureView {
        &self.view
    }
}
