//! **Accumulation**: the irradiance of a [`VplStore`]'s VPLs, with visibility from a
//! [`ShadowAtlas`], gathered into the interleaved split G-buffer.
//!
//! Reads: [`Interleave`]'s split position and normal, the VPL store, the atlas (any format:
//! rasterised depth or a float atlas written by another pass).
//! Writes: `split_irradiance`. The VPL in slot k lights the split tile `k mod T` (T = n·m
//! tiles; Laine et al. 2007 §5.1), scaled by T; its contribution to a receiver is
//! E = Φ/π · cos θ_v cos θ_r / r² · V.
//!
//! One compute pass of two dispatches: the first computes once per VPL what does not depend on
//! the receiver (its map's eye point and tile origin in the atlas, Φ/π, the largest geometric
//! term the clamp lets through) into a buffer of the store's capacity; the second, one
//! invocation per split texel, loops over its tile's VPLs with only the receiver-dependent
//! work (the geometric term, the map lookup). The images equal those of the direct per-pair
//! formulation (`harness/tests/it/accumulate_per_pair.wgsl`, compared by a test).
//!
//! **Clamp** (Laine et al. 2007 §5.2, after Keller): the irradiance a single VPL may give a
//! receiver is bounded — against the 1/r² singularity — by E_max = k · Ē, where Ē = ΣΦ / A
//! is the mean irradiance all the store's VPLs together would give if their flux were spread
//! evenly over the scene's surfaces (A, [`SceneExtent::surface_area`]; per channel) and k is
//! the technique's `clamp` parameter (0: no clamp). A contribution over the bound in any
//! channel is scaled as a whole down to it, keeping its colour. E_max does not depend on the
//! scene's units or the light's power, and with more VPLs each carries less flux and fewer
//! are clamped, so the bias shrinks with the VPL count as with the paper's fixed bound.
//!
//! [`SceneExtent::surface_area`]: crate::scene::SceneExtent::surface_area

use bytemuck::{Pod, Zeroable};

use super::atlas::ShadowAtlas;
use super::interleave::{Interleave, INTERLEAVE_WGSL};
use super::store::VplStore;
use crate::gpu::GpuContext;
use crate::kit::passes::{compute_pipeline, params_buffer, Bindings};
use crate::Result;

/// GPU layout of `AccumulateParams` in `accumulate.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ParamsData {
    /// x: k / A (0: no clamp).
    clamp: [f32; 4],
}

/// The clamp of one VPL's irradiance (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IrradianceClamp {
    /// k: E_max in units of the mean irradiance ΣΦ / A; 0 (or less) turns the clamp off.
    pub factor: f32,
    /// A: the scene's surface area.
    pub surface_area: f32,
}

impl IrradianceClamp {
    /// No clamp.
    pub const OFF: IrradianceClamp = IrradianceClamp {
        factor: 0.0,
        surface_area: 1.0,
    };

    /// E_max per channel for VPLs whose summed flux is `flux` (`None` with no clamp).
    pub fn max_irradiance(&self, flux: glam::Vec3) -> Option<glam::Vec3> {
        (self.factor > 0.0).then(|| self.per_flux() * flux)
    }

    /// k / A, what the shader multiplies the store's summed flux by (0 with no clamp).
    fn per_flux(&self) -> f32 {
        if self.factor > 0.0 && self.surface_area > 0.0 {
            self.factor / self.surface_area
        } else {
            0.0
        }
    }
}

/// Bytes of one `PreparedVpl` (`prepared_vpl.wgsl`).
const PREPARED_BYTES: u64 = 80;
/// Invocations per workgroup of the prepare dispatch (`accumulate_prepare.wgsl`).
const PREPARE_WG: u32 = 64;

/// The accumulate pass over one store and one atlas (see the module docs).
pub struct Accumulation {
    prepare: wgpu::ComputePipeline,
    prepare_group: wgpu::BindGroup,
    pipeline: wgpu::ComputePipeline,
    group: wgpu::BindGroup,
    /// Slots of the store (the prepare dispatch covers them all; those past the header's
    /// count return at once).
    capacity: u32,
    /// Kept alive for the bind groups.
    _buffers: [wgpu::Buffer; 2],
}

impl Accumulation {
    /// Builds the pass for `store` and `atlas` over `interleave`'s split buffers, with `clamp`
    /// on each VPL's irradiance.
    pub fn new(
        gpu: &GpuContext,
        interleave: &Interleave,
        store: &VplStore,
        atlas: &ShadowAtlas,
        clamp: IrradianceClamp,
    ) -> Result<Accumulation> {
        let device = &gpu.device;
        let params = params_buffer(
            gpu,
            "accumulate params",
            &ParamsData {
                clamp: [clamp.per_flux(), 0.0, 0.0, 0.0],
            },
        );
        // Its size is that of the store's items (80 bytes each, as GpuVpl), which the store
        // checked against the adapter's limits.
        let prepared = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("accumulate prepared vpls"),
            size: store.capacity() as u64 * PREPARED_BYTES,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let prepare = Bindings::new("accumulate prepare", wgpu::ShaderStages::COMPUTE)
            .read(store.buffer())
            .params(&params)
            .write(&prepared)
            .build(device);
        let source = format!(
            "{}\n{}\n{}",
            VplStore::wgsl(0, 0, false),
            ShadowAtlas::wgsl(1),
            include_str!("shaders/accumulate_prepare.wgsl")
        );
        let prepare_pipeline = compute_pipeline(
            device,
            "vpl accumulate prepare",
            &source,
            &[&prepare.layout, atlas.layout()],
            "prepare",
        );
        let gather = Bindings::new("accumulate", wgpu::ShaderStages::COMPUTE)
            .read(&prepared)
            .read(store.buffer())
            .build(device);
        let source = format!(
            "{INTERLEAVE_WGSL}\n{}\n{}\n{}",
            VplStore::wgsl(1, 1, false),
            ShadowAtlas::wgsl(2),
            include_str!("shaders/accumulate.wgsl")
        );
        let pipeline = compute_pipeline(
            device,
            "vpl accumulate",
            &source,
            &[interleave.split_layout(), &gather.layout, atlas.layout()],
            "accumulate",
        );
        gpu.check_errors()?;
        Ok(Accumulation {
            prepare: prepare_pipeline,
            prepare_group: prepare.group,
            pipeline,
            group: gather.group,
            capacity: store.capacity(),
            _buffers: [params, prepared],
        })
    }

    /// Records the accumulation (the atlas must be the one this pass was built with).
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        interleave: &Interleave,
        atlas: &ShadowAtlas,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("accumulate"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.prepare);
        pass.set_bind_group(0, &self.prepare_group, &[]);
        pass.set_bind_group(1, atlas.group(), &[]);
        pass.dispatch_workgroups(self.capacity.div_ceil(PREPARE_WG), 1, 1);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, interleave.split_group(), &[]);
        pass.set_bind_group(1, &self.group, &[]);
        pass.set_bind_group(2, atlas.group(), &[]);
        interleave.dispatch_split_size(&mut pass);
    }
}
