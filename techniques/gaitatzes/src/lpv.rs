//! `mode=lpv`: light propagation volumes (Kaplanyan 2009; Kaplanyan and Dachsbacher 2010), the
//! contrast of Gaitatzes et al.'s Figure 6 (`shaders/lpv.wgsl` has the algorithm).
//!
//! * [`Injection`] — Reads: a reflective shadow map's texels (the kit's
//!   [`gibench_harness::kit::ir::rsm::ReflectiveShadowMap`]: position, normal, flux). Writes:
//!   the first propagation buffer and the accumulation (the VPLs' intensity lobes per cell),
//!   and its own fixed-point sums.
//! * [`LpvPropagation`] — Reads: the propagation buffers (ping-pong). Writes: the other one and
//!   the accumulation.
//!
//! What we took as the description: Kaplanyan's SIGGRAPH 2009 course notes and the I3D 2010
//! paper as public implementations and Kirsch's annotations (2010) read them: RSM texels as
//! VPLs moved half a cell along their normals (and 1/64 of a cell more: `lpv.wgsl`), clamped-cosine intensity lobes in two SH bands,
//! flux through the five faces of each neighbour weighted by their solid angles from the
//! sending cell's centre (0.4006696846 sr for the far face, 0.4234413544 sr for a side face:
//! [`crate::slab::kaplanyan_weights`] computes them), re-emitted as cosine lobes along the
//! faces' normals, every step accumulated. Not implemented: the geometry volume (occlusion) and
//! cascades.

use gibench_harness::gpu::GpuContext;
use gibench_harness::kit::passes::{compute_pipeline, Bindings};
use gibench_harness::measure::roofline::StageCost;
use gibench_harness::{wgpu, Result};

use crate::volume::{Grid, Volumes, CELL_BYTES};

/// The reflective shadow map's face edge, texels: the `ism` technique's default `rsm-size`.
pub const RSM_SIZE: u32 = 64;

/// The fixed-point range of the injection's sums: no cell's sum can exceed it (each texel adds
/// at most `FIXED / texels` units), and it stays below i32's 2³¹.
const FIXED: f64 = (1u64 << 30) as f64;

/// The WGSL of both passes: the grid's constants, the texel count, Kaplanyan's solid angles.
fn source(grid: &Grid, texels: u32) -> String {
    let w = crate::slab::kaplanyan_weights();
    format!(
        "{}\nconst TEXELS: u32 = {texels}u;\nconst FIXED: f32 = {FIXED:.1};\n\
         const LPV_FRONT: f32 = {:.9e};\nconst LPV_SIDE: f32 = {:.9e};\n{}",
        grid.wgsl(),
        w.front,
        w.side,
        include_str!("shaders/lpv.wgsl")
    )
}

/// The injection (see the module docs).
pub struct Injection {
    n: u32,
    texels: u32,
    clear: wgpu::ComputePipeline,
    largest: wgpu::ComputePipeline,
    inject: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
    texel_group: wgpu::BindGroup,
    cell_group: wgpu::BindGroup,
    _sums: wgpu::Buffer,
    /// The declared minimum cost of the injection ([`StageCost`]).
    pub cost: StageCost,
}

impl Injection {
    /// The injection of the `texels` texels in `rsm` (position, normal, flux: `vec4<f32>`
    /// each; position w = 1 where a surface was seen) into `volumes`.
    pub fn new(
        gpu: &GpuContext,
        grid: &Grid,
        rsm: [&wgpu::Buffer; 3],
        texels: u32,
        volumes: &Volumes,
    ) -> Result<Injection> {
        let device = &gpu.device;
        let sums = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("lpv injection sums"),
            size: (12 * grid.cells() + 1) * 4,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let c = wgpu::ShaderStages::COMPUTE;
        let [position, normal, flux] = rsm;
        let texel = Bindings::new("lpv injection", c)
            .read(position)
            .read(normal)
            .read(flux)
            .write(&sums)
            .build(device);
        let cell = Bindings::new("lpv resolve", c)
            .first_binding(3)
            .write(&sums)
            .write(&volumes.propagation[0])
            .write(&volumes.accumulation)
            .build(device);
        let source = source(grid, texels);
        let pipeline = |entry: &str, layout: &wgpu::BindGroupLayout| {
            compute_pipeline(device, "lpv injection", &source, &[layout], entry)
        };
        let clear = pipeline("clear", &cell.layout);
        let largest = pipeline("largest", &texel.layout);
        let inject = pipeline("inject", &texel.layout);
        let resolve = pipeline("resolve", &cell.layout);
        gpu.check_errors()?;
        // Per texel its position, normal and flux read (48 bytes); per cell the injected SH and
        // the accumulation's start written (2 × 48). Operations per texel: the cell (about
        // 10) and 12 coefficients scaled (12).
        let cost = StageCost::per_element(texels as u64, 48, 0, 22).plus(StageCost::per_element(
            grid.cells(),
            0,
            2 * CELL_BYTES,
            0,
        ));
        Ok(Injection {
            n: grid.n,
            texels,
            clear,
            largest,
            inject,
            resolve,
            texel_group: texel.group,
            cell_group: cell.group,
            _sums: sums,
            cost,
        })
    }

    /// Records the injection of the texels (made before it in the frame).
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("lpv injection"),
            timestamp_writes: None,
        });
        let texels = self.texels.div_ceil(64);
        pass.set_pipeline(&self.clear);
        pass.set_bind_group(0, &self.cell_group, &[]);
        pass.dispatch_workgroups(1, 1, 1);
        pass.set_pipeline(&self.largest);
        pass.set_bind_group(0, &self.texel_group, &[]);
        pass.dispatch_workgroups(texels, 1, 1);
        pass.set_pipeline(&self.inject);
        pass.dispatch_workgroups(texels, 1, 1);
        pass.set_pipeline(&self.resolve);
        pass.set_bind_group(0, &self.cell_group, &[]);
        let g = self.n.div_ceil(4);
        pass.dispatch_workgroups(g, g, g);
    }
}

/// The propagation iterations of `mode=lpv` (see the module docs): one dispatch each.
pub struct LpvPropagation {
    n: u32,
    pipeline: wgpu::ComputePipeline,
    /// Per iteration parity: a → b, b → a.
    groups: [wgpu::BindGroup; 2],
}

impl LpvPropagation {
    /// Cells per workgroup (`lpv_propagate`'s `@workgroup_size`).
    const WORKGROUP: [u32; 3] = [8, 8, 4];

    pub fn new(gpu: &GpuContext, grid: &Grid, volumes: &Volumes) -> Result<LpvPropagation> {
        let device = &gpu.device;
        let of = |from: usize| {
            Bindings::new("lpv propagation", wgpu::ShaderStages::COMPUTE)
                .first_binding(6)
                .read(&volumes.propagation[from])
                .write(&volumes.propagation[1 - from])
                .write(&volumes.accumulation)
        };
        let layout = of(0).layout(device);
        let groups = [of(0).group(device, &layout), of(1).group(device, &layout)];
        let pipeline = compute_pipeline(
            device,
            "lpv propagation",
            &source(grid, 0),
            &[&layout],
            "lpv_propagate",
        );
        gpu.check_errors()?;
        Ok(LpvPropagation {
            n: grid.n,
            pipeline,
            groups,
        })
    }

    /// The declared minimum cost of `iterations` iterations over `cells` cells: per iteration
    /// and cell its SH read once (48 bytes: every neighbour reads it, once is the minimum), the
    /// next SH written (48) and the accumulation read and written (2 × 48); operations: six
    /// neighbours × five faces × three channels × (a 4-term dot product and a 4-term lobe
    /// added), 720.
    pub fn cost(cells: u64, iterations: u32) -> StageCost {
        StageCost::per_element(
            cells * iterations as u64,
            2 * CELL_BYTES,
            2 * CELL_BYTES,
            720,
        )
    }

    /// Records `iterations` iterations from propagation buffer 0.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, iterations: u32) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("lpv propagation"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        let g = LpvPropagation::WORKGROUP.map(|w| self.n.div_ceil(w));
        for k in 0..iterations as usize {
            pass.set_bind_group(0, &self.groups[k % 2], &[]);
            pass.dispatch_workgroups(g[0], g[1], g[2]);
        }
    }
}
