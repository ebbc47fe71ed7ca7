//! The gathering half that every instant-radiosity technique shares: the technique's output
//! texture, the interleaved-sampling passes ([`Interleave`]) and the VPL depth maps and
//! accumulation ([`VplLighting`]), built from the same named parameters, and recorded as the same
//! profiler stages (`vpl-shadow-maps`, `split`, `accumulate`, `combine`, `filter`). Techniques
//! differ only in how they manage their VPLs.

use crate::passes::{FilterSettings, Interleave, VplLighting, VplMapKind, VplShadowSettings};
use crate::technique::{FrameContext, ParamKind, ParamSpec, Params, PrepareContext};
use crate::vpl::Vpl;
use crate::Result;

/// Parameters shared by every VPL technique's gathering.
pub const GATHER_PARAMS: [ParamSpec; 5] = [
    ParamSpec {
        name: "tiles",
        kind: ParamKind::Tiles,
        default: "4x4",
        doc: "interleaved-sampling tiles NxM (Laine: 4x4); 1x1 = no interleaving",
    },
    ParamSpec {
        name: "shadow-map",
        kind: ParamKind::Choice(&["paraboloid", "cube"]),
        default: "paraboloid",
        doc: "VPL shadow-map parameterisation",
    },
    ParamSpec {
        name: "shadow-size",
        kind: ParamKind::Int { min: 8, max: 4096 },
        default: "128",
        doc: "VPL shadow-map edge in texels (Laine: 256)",
    },
    ParamSpec {
        name: "depth-bits",
        kind: ParamKind::Choice(&["16", "32"]),
        default: "16",
        doc: "VPL shadow-map depth format: 16 (Laine) or 32",
    },
    ParamSpec {
        name: "clamp",
        kind: ParamKind::Float { min: 0.0, max: 1.0 },
        default: "0.02",
        doc: "minimum VPL-receiver distance in 1/r^2, as a fraction of the scene's bounding-box diagonal",
    },
];

/// The gathering half every VPL technique shares: output texture, interleaving, VPL maps.
pub struct VplGather {
    /// Kept alive for the view and the filter's storage binding.
    _output: wgpu::Texture,
    view: wgpu::TextureView,
    pub interleave: Interleave,
    pub lighting: VplLighting,
}

impl VplGather {
    /// Builds the gather for at most `capacity` VPLs from the gather parameters in `params`.
    pub fn new(params: &Params, ctx: &PrepareContext, capacity: u32) -> Result<VplGather> {
        let device = &ctx.gpu.device;
        let output = crate::passes::indirect_target(device, ctx.resolution, true);
        let settings = &ctx.scene.descriptor.settings;
        let interleave = Interleave::new(
            ctx.gpu,
            ctx.gbuffer,
            params.tiles("tiles"),
            FilterSettings {
                alpha: settings.filter_distance,
                beta: settings.filter_normal,
            },
            &output,
        )?;
        let depth_bits = if params.choice("depth-bits") == "32" {
            32
        } else {
            16
        };
        let lighting = VplLighting::new(
            ctx.gpu,
            ctx.gpu_scene,
            ctx.uniforms,
            &interleave,
            VplShadowSettings {
                kind: VplMapKind::parse(params.choice("shadow-map"))?,
                size: params.int("shadow-size") as u32,
                depth_bits,
                capacity,
                clamp_distance: params.float("clamp") as f32 * ctx.gpu_scene.diagonal(),
                bias: settings.shadow_bias,
            },
        )?;
        let view = output.create_view(&Default::default());
        Ok(VplGather {
            _output: output,
            view,
            interleave,
            lighting,
        })
    }

    /// Records split, accumulate, combine and filter as four stages over `vpls` (slot, VPL),
    /// whose list order is the tile assignment order.
    pub fn gather(&self, ctx: &mut FrameContext, vpls: &[(u32, Vpl)]) -> Result<()> {
        self.lighting.write_vpls(&ctx.gpu.queue, vpls);
        let gpu = ctx.gpu;
        ctx.profiler
            .gpu_stage(gpu, "split", |enc| self.interleave.encode_split(enc))?;
        ctx.profiler.gpu_stage(gpu, "accumulate", |enc| {
            self.lighting.encode_accumulate(enc, &self.interleave)
        })?;
        ctx.profiler
            .gpu_stage(gpu, "combine", |enc| self.interleave.encode_combine(enc))?;
        ctx.profiler
            .gpu_stage(gpu, "filter", |enc| self.interleave.encode_filter(enc))?;
        ctx.profiler.count("vpls", vpls.len() as f64);
        Ok(())
    }

    /// Records the shadow maps of `slots` as the `vpl-shadow-maps` stage.
    pub fn render_maps(
        &self,
        ctx: &mut FrameContext,
        slots: &[u32],
        clear_all: bool,
    ) -> Result<()> {
        let gpu = ctx.gpu;
        let (scene, uniforms) = (ctx.gpu_scene, ctx.uniforms);
        let n = ctx.profiler.gpu_stage(gpu, "vpl-shadow-maps", |enc| {
            self.lighting
                .encode_shadow_maps(enc, scene, uniforms, slots, clear_all)
        })?;
        ctx.profiler.count("shadow-maps", n as f64);
        Ok(())
    }

    pub fn output(&self) -> &wgpu::TextureView {
        &self.view
    }
}
