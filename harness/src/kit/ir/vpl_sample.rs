//! **VPL sampling**: N VPLs importance-sampled by brightness from the texels of a reflective
//! shadow map, on the GPU (imperfect shadow maps' first step, Ritschel et al. 2008; reflective
//! shadow maps, Dachsbacher and Stamminger 2005). No CPU readback.
//!
//! Reads: per texel, the surface position (w = 1 where the texel saw a surface), its normal
//! and the flux its patch reflects (storage buffers of `vec4<f32>`, written by the pass that
//! renders the map).
//! Writes: the [`VplStore`] — slots 0..N, and its header (N, and the texels' total flux as the
//! summed flux the accumulation's clamp is relative to); its own CDF and totals buffers.
//!
//! One workgroup scans the texels' luminance into a CDF (and sums their flux). VPL i has a
//! fixed point of the unit square, (uᵢ, vᵢ) = ((i + ξᵢ)/N, φ₂(i) ⊕ η): ξᵢ ∈ [0, 1) a fixed hash
//! of i, φ₂ the base-2 radical inverse, η one fixed shift (a jittered Hammersley set: stratified,
//! so the estimate is unbiased, and the same texels while the map does not change). The point
//! picks a texel with probability its luminance / the total, by one of two warps
//! ([`VplWarp`]): the texel where the CDF over the flattened map crosses uᵢ, or a row (face
//! row) by its luminance at uᵢ, then a texel in that row at vᵢ. The VPL carries that texel's
//! flux × total luminance / (its luminance · N): every VPL has luminance total / N, so the
//! VPLs' luminance sums to the texels' exactly and their flux per channel is an unbiased
//! estimate of the texels'.
//!
//! The warps differ in how far a VPL moves when the map changes a little (a moving light or
//! mover): along the flattened order a small shift of the CDF carries VPLs past the ends of
//! rows, to the other side of the face; the row-then-column warp moves them to a neighbouring
//! row or texel (the flicker this causes is measured by `gibench reproduce ism-sampling`).

use bytemuck::{Pod, Zeroable};

use super::store::VplStore;
use crate::gpu::GpuContext;
use crate::kit::passes::{compute_pipeline, params_buffer, Bindings};
use crate::measure::roofline::StageCost;
use crate::{Error, Result};

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ParamsData {
    counts: [u32; 4],
}

/// The scan and sample passes (see the module docs).
pub struct VplSampler {
    /// The pass's declared minimum cost per frame, from the map's texels and the VPL count.
    pub cost: StageCost,
    scan: wgpu::ComputePipeline,
    sample: wgpu::ComputePipeline,
    group: wgpu::BindGroup,
    _buffers: [wgpu::Buffer; 3],
    count: u32,
}

/// How a VPL's point of the unit square picks its texel (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VplWarp {
    /// The luminance CDF over the flattened map (rows one after another) at u.
    Flattened,
    /// A row by the rows' luminance at u, then a texel of that row by its CDF at v.
    RowColumn,
}

impl VplWarp {
    /// The names a parameter gives them.
    pub const NAMES: &'static [&'static str] = &["flat", "row-column"];

    /// The warp a parameter value names.
    pub fn from_name(name: &str) -> Result<VplWarp> {
        match name {
            "flat" => Ok(VplWarp::Flattened),
            "row-column" => Ok(VplWarp::RowColumn),
            other => Err(Error::Invalid(format!(
                "unknown VPL warp '{other}': expected one of {}",
                Self::NAMES.join(", ")
            ))),
        }
    }
}

/// The texels' buffers the sampler reads.
pub struct RsmTexels<'a> {
    pub position: &'a wgpu::Buffer,
    pub normal: &'a wgpu::Buffer,
    pub flux: &'a wgpu::Buffer,
    /// Texels in each buffer.
    pub texels: u32,
    /// Texels in a row (the buffers hold `texels / row` rows, one after another).
    pub row: u32,
}

impl VplSampler {
    /// Sampling `count` VPLs (at most the store's capacity) from `rsm` into `store` through
    /// `warp`.
    pub fn new(
        gpu: &GpuContext,
        store: &VplStore,
        rsm: &RsmTexels,
        count: u32,
        warp: VplWarp,
    ) -> Result<VplSampler> {
        if count == 0 || count > store.capacity() {
            return Err(Error::param(
                "vpls",
                format!(
                    "expected 1..={} VPLs (the store's capacity), got {count}",
                    store.capacity()
                ),
            ));
        }
        if rsm.texels == 0 || rsm.row == 0 || !rsm.texels.is_multiple_of(rsm.row) {
            return Err(Error::Invalid(format!(
                "the reflective shadow map's {} texels are not whole rows of {}",
                rsm.texels, rsm.row
            )));
        }
        let device = &gpu.device;
        let params = params_buffer(
            gpu,
            "vpl sample params",
            &ParamsData {
                counts: [
                    rsm.texels,
                    count,
                    rsm.row,
                    (warp == VplWarp::RowColumn) as u32,
                ],
            },
        );
        let buffer = |label: &str, size: u64| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            })
        };
        let cdf = buffer("vpl sample cdf", rsm.texels as u64 * 4);
        let totals = buffer("vpl sample totals", 16);
        // The store is written (VplStore::layout_entry(_, true)); the map's texels are read.
        let bound = Bindings::new("vpl sample", wgpu::ShaderStages::COMPUTE)
            .write(store.buffer())
            .params(&params)
            .read(rsm.position)
            .read(rsm.normal)
            .read(rsm.flux)
            .write(&cdf)
            .write(&totals)
            .build(device);
        let (layout, group) = (bound.layout, bound.group);
        let source = format!(
            "{}\n{}",
            VplStore::wgsl(0, 0, true),
            include_str!("shaders/vpl_sample.wgsl")
        );
        let scan = compute_pipeline(device, "vpl sample scan", &source, &[&layout], "scan");
        let sample = compute_pipeline(device, "vpl sample", &source, &[&layout], "sample");
        gpu.check_errors()?;
        // The declared minimum cost ([`crate::measure::roofline`]): every texel's flux read
        // once (a vec4<f32>, 16 bytes) with its luminance (5 operations) added to a running sum
        // (1) — the VPLs' points are sorted along u, so one sweep over that sum places them all
        // and the CDF need not be stored; per VPL its texel's position, normal and flux read
        // (48 bytes), the VPL written (`GpuVpl`), its flux scaled by the total over its texel's
        // luminance (5 with that luminance, 3 more for the channels) and its frame about the
        // normal built (about 17): 25 operations. The search for its texel is comparisons, not
        // counted.
        let vpl_bytes = std::mem::size_of::<super::store::GpuVpl>() as u64;
        let cost = StageCost::per_element(rsm.texels as u64, 16, 0, 6)
            .plus(StageCost::per_element(count as u64, 48, vpl_bytes, 25));
        Ok(VplSampler {
            cost,
            scan,
            sample,
            group,
            _buffers: [params, cdf, totals],
            count,
        })
    }

    /// Records the scan and the sampling.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("vpl sample"),
            timestamp_writes: None,
        });
        pass.set_bind_group(0, &self.group, &[]);
        pass.set_pipeline(&self.scan);
        pass.dispatch_workgroups(1, 1, 1);
        pass.set_pipeline(&self.sample);
        pass.dispatch_workgroups(self.count.div_ceil(64), 1, 1);
    }
}
