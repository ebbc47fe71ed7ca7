//! **Point splat**: imperfect shadow maps' depth (Ritschel et al. 2008) — every VPL's own
//! subset of a point pool splatted, one texel per point, into its paraboloid map.
//!
//! Reads: the point pool (`vec4<f32>` each: position in its object's space, w = the object's
//! index; in random order so that any run of it is a uniform sample of the surfaces), the
//! objects' transforms (`mat4x4<f32>` each: 0 the static mesh, k + 1 mover k, written each
//! frame by the technique), the [`VplStore`], the [`ShadowAtlas`]'s parameters (map size, far
//! distance, the lift of a map's centre off its VPL).
//! Writes (owns): the imperfect depth buffer, one `u32` per texel of every slot's map
//! (`slot · size² + y · size + x`), holding the bits of the nearest point's reversed depth
//! (1 − d / far, as the atlas stores), 0 where no point landed. [`super::pullpush::PullPush`]
//! fills its holes and writes the atlas.
//!
//! VPL slot s takes `points_per_vpl` consecutive points of the pool from a start that a hash
//! of s picks, so each VPL has its own subset (the paper: 8k points per VPL). One dispatch for
//! all VPLs: a thread per (point, slot), kept nearest-first by a storage-buffer `atomicMax` —
//! no texture atomics, so it runs on Vulkan and GL alike. Paraboloid maps only (the paper's).

use bytemuck::{Pod, Zeroable};

use super::atlas::{MapKind, ShadowAtlas};
use super::store::VplStore;
use crate::gpu::GpuContext;
use crate::kit::passes::{
    bind_buffer, compute_pipeline, params_buffer, params_entry, storage_entry,
};
use crate::{Error, Result};

/// GPU layout of `SplatParams` in `splat.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ParamsData {
    counts: [u32; 4],
}

/// The splat pass and the imperfect depth buffer it writes (see the module docs).
pub struct PointSplat {
    pipeline: wgpu::ComputePipeline,
    group: wgpu::BindGroup,
    depth: wgpu::Buffer,
    /// Kept alive for the bind group.
    _params: wgpu::Buffer,
    per_vpl: u32,
    slots: u32,
    size: u32,
}

/// Bytes of one buffer of `texels` 4-byte values, checked against the device's limits; the
/// error names `param`, the parameter that sets its size.
pub(crate) fn texel_buffer_size(
    gpu: &GpuContext,
    texels: u64,
    what: &str,
    param: &str,
) -> Result<u64> {
    let bytes = texels * 4;
    let max = gpu.max_storage_buffer();
    if bytes > max {
        let advice = if param == "vpl-map-size" {
            "use fewer VPLs or smaller maps"
        } else {
            "use a smaller value"
        };
        return Err(Error::param(
            param,
            format!(
                "{what} of {bytes} bytes exceeds this adapter's largest storage buffer ({max} bytes); {advice}"
            ),
        ));
    }
    Ok(bytes)
}

impl PointSplat {
    /// The pass for `store`'s slots into `atlas`'s maps, each VPL splatting `points_per_vpl`
    /// points of `points` (a storage buffer of `pool` `vec4<f32>`: position, object index)
    /// moved by `objects` (a storage buffer of `mat4x4<f32>`, one per object).
    pub fn new(
        gpu: &GpuContext,
        store: &VplStore,
        atlas: &ShadowAtlas,
        points: &wgpu::Buffer,
        objects: &wgpu::Buffer,
        pool: u32,
        points_per_vpl: u32,
    ) -> Result<PointSplat> {
        if atlas.settings.kind != MapKind::Paraboloid {
            return Err(Error::param(
                "vpl-map",
                "imperfect shadow maps are paraboloid maps (got cube)",
            ));
        }
        if pool == 0 || points_per_vpl == 0 {
            return Err(Error::param(
                "points",
                "at least one point per VPL and in the pool is needed",
            ));
        }
        let device = &gpu.device;
        let (slots, size) = (store.capacity(), atlas.settings.size);
        let texels = slots as u64 * size as u64 * size as u64;
        let bytes = texel_buffer_size(gpu, texels, "the imperfect depth buffer", "vpl-map-size")?;
        let depth = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ism depth"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let params = params_buffer(
            gpu,
            "splat params",
            &ParamsData {
                counts: [points_per_vpl, pool, 0, 0],
            },
        );
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("splat"),
            entries: &[
                VplStore::layout_entry(0, false),
                params_entry(1, wgpu::ShaderStages::COMPUTE),
                storage_entry(2, true),
                storage_entry(3, false),
                storage_entry(4, true),
            ],
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("splat"),
            layout: &layout,
            entries: &[
                bind_buffer(0, store.buffer()),
                bind_buffer(1, &params),
                bind_buffer(2, points),
                bind_buffer(3, &depth),
                bind_buffer(4, objects),
            ],
        });
        let source = format!(
            "{}\n{}\n{}",
            VplStore::wgsl(0, 0, false),
            ShadowAtlas::wgsl(1),
            include_str!("shaders/splat.wgsl")
        );
        let pipeline = compute_pipeline(
            device,
            "ism splat",
            &source,
            &[&layout, atlas.layout()],
            "splat",
        );
        gpu.check_errors()?;
        Ok(PointSplat {
            pipeline,
            group,
            depth,
            _params: params,
            per_vpl: points_per_vpl,
            slots,
            size,
        })
    }

    /// Records the splat: clears the depth buffer, then one dispatch for every slot.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, atlas: &ShadowAtlas) {
        encoder.clear_buffer(&self.depth, 0, None);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("ism splat"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.group, &[]);
        pass.set_bind_group(1, atlas.group(), &[]);
        pass.dispatch_workgroups(self.per_vpl.div_ceil(64), self.slots, 1);
    }

    /// The imperfect depth buffer (see the module docs).
    pub fn depth(&self) -> &wgpu::Buffer {
        &self.depth
    }

    /// The splat's declared minimum cost per frame ([`crate::measure::roofline`]): the depth buffer
    /// cleared (slots × size² texels, 4 bytes each, written) and, per (point, slot), the point
    /// read (a `vec4<f32>`, 16 bytes: every VPL has its own subset) and one texel written (a
    /// `u32`, 4 bytes — the nearest-first atomic's read of it not counted). Operations per
    /// point: the object's transform (a 4×4 matrix times a point, 32), the vector to the VPL
    /// in its frame (3 subtractions, three 3-term dot products: 18), its length and the
    /// paraboloid's projection (a square root and a division per axis: about 10) — 60.
    pub fn cost(&self) -> crate::measure::roofline::StageCost {
        let texels = self.slots as u64 * self.size as u64 * self.size as u64;
        let points = self.slots as u64 * self.per_vpl as u64;
        crate::measure::roofline::StageCost::per_element(points, 16, 4, 60).plus(
            crate::measure::roofline::StageCost::per_element(texels, 0, 4, 0),
        )
    }

    /// Slots and map edge of the depth buffer.
    pub fn layout(&self) -> (u32, u32) {
        (self.slots, self.size)
    }
}
