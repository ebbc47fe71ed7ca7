//! **`gaitatzes`**: interactive volume-based indirect illumination (Gaitatzes, Mavridis and
//! Papaioannou 2010), every frame and all on the GPU — the scene is treated as fully dynamic:
//!
//! 1. **Voxelization** (§4.1, Algorithm 1; [`volume::Voxelizer`]): along each axis, every
//!    slice of the `grid`³ grid is a thin orthographic view in which the whole scene (movers
//!    included) is scan-converted; per voxel the fragments' direct radiosity (albedo × the
//!    shared direct light, shadowed), normal and albedo. The three axes are combined by MAX
//!    (radiosity) into one volume of shells; each occupied voxel's radiosity is **injected** as
//!    a VPL's clamped-cosine radiance lobe about its normal.
//! 2. **Propagation** (§4.2, Eq. 8; [`volume::Propagation`]): `iterations` times, every cell
//!    gathers from its six neighbours what each sends through the shared face (the SH integral
//!    over the face's 90° pyramid); void cells pass the radiance on, occupied cells accumulate
//!    it and reflect it (mirrored along the dominant axis of their normal, times 0.5 — the
//!    paper's constant — or the voxel's albedo): secondary bounces. Each iteration is two
//!    dispatches with the same result as the paper's one gather: every cell's flux through
//!    each of its faces, computed once, then the gather of the six fluxes that arrive.
//! 3. **Reconstruction** (§4.3, Eq. 11–12; [`volume::Reconstruction`]): per pixel, the
//!    accumulated radiance interpolated from the occupied ones of the eight nearest cells, and
//!    the irradiance as its SH dot product with the clamped cosine about the normal, times the
//!    flux-to-irradiance constant 12/7 ([`sh::flux_to_irradiance`]: without it a surface
//!    receives 7/12 of the flux that arrives at it head-on).
//!
//! **What the propagation loses** ([`slab`]): a clamped-cosine lobe sends 40 % of its flux on
//! and 15 % through each side face, and the side lobes send 15 % back, so light diffuses rather
//! than travels. Between two infinite walls the share of the emitted flux that reaches the
//! facing wall, converged, is 70 / 45 / 28 / 16 / 9 % at 2 / 4 / 8 / 16 / 30 cells apart; the
//! rest returns to the emitter as spurious self-irradiance; those shares are already the
//! converged ones, so more iterations do not raise them (between walls a given number of
//! cells apart). Where light has not yet arrived, more iterations do bring more of it: the
//! ceiling 16 cells above a lit floor gets 0.09 of its exact irradiance at 64 iterations and
//! 0.52 converged (results/gaitatzes/transfer/). This is the method class's (second-order SH propagation through cell faces,
//! as in light propagation volumes), not a missing constant. Two variants, not the paper's:
//! `transport=carry` keeps each lobe's direction through void cells: all the flux reaches the
//! facing wall (in about 2.5 iterations per cell), at the price of beams that widen too little
//! with distance; `transport=pyramid` passes on, through each face, the re-projection of the
//! light within that face's pyramid (its integral and first moment), so light that left through
//! a side face still leans forward: 84 / 68 / 53 / 37 / 25 % reach the facing wall at the
//! distances above, and light still spreads.
//!
//! `mode=lpv` is Kaplanyan's light propagation volumes (2009) for the paper's Figure 6(d)
//! ([`lpv`]): reflective-shadow-map texels injected as VPLs, his face weights, no occlusion or
//! reflection, every step accumulated, interpolated from all eight cells.
//!
//! Second-order SH per colour channel, in the convention of [`sh`]. Deviations (README): what a
//! cell sends through a face is normalised so that it passes on exactly its radiance integral
//! (negative, ringing integrals dropped) and arrives as a clamped-cosine lobe of unit integral,
//! which the reconstruction turns back into irradiance with the constant 12/7 (the paper gives
//! neither); occupied cells pass light only into void neighbours on their normal's side; the
//! volumes are storage buffers and the slices 2D atlases, not 3D textures; each occupied voxel
//! is taken to hold one cell face of surface (injected radiance B/π per unit cosine);
//! `transport=carry` and `transport=pyramid` are ours.
//!
//! Needs: compute shaders and storage buffers (Vulkan, GL ES 3.1); no optional features. Four
//! storage buffers per shader stage, five with `transport=carry` or `pyramid` (checked when the
//! technique is created).

pub mod lpv;
mod params;
pub mod sh;
pub mod slab;
pub mod volume;

pub use params::GaitatzesParams;

use gibench_harness::kit::technique::{
    cornell_boxes, prepare_nothing, Conformance, Converged, FrameContext, Knob, Params,
    PrepareContext, Prepared, Technique, TechniqueInfo,
};
use gibench_harness::{wgpu, Result};

use gibench_harness::kit::ir::rsm::ReflectiveShadowMap;
use gibench_harness::measure::roofline::StageCost;
use params::PARAMS;
use volume::{Grid, Mode, Propagation, Reconstruction, Volumes, Voxelizer, CELL_BYTES};

/// The quality knob (`gibench run --equal-time`): the propagation iterations.
const KNOB: Knob = Knob {
    param: "iterations",
    why: "each iteration carries light one cell further (more of it, and more bounces, arrive) at one more pass over the grid",
};

/// Stage: voxelization, combine and injection.
pub const STAGE_VOXELIZATION: &str = "voxelization";
/// Stage (`mode=lpv`): the reflective shadow map.
pub const STAGE_RSM: &str = gibench_harness::kit::ir::rsm::STAGE;
/// Stage (`mode=lpv`): its texels injected into the grid.
pub const STAGE_INJECTION: &str = "injection";
/// Stage: the propagation iterations.
pub const STAGE_PROPAGATION: &str = "propagation";
/// Stage: the per-pixel reconstruction.
pub const STAGE_RECONSTRUCTION: &str = "reconstruction";
/// Every stage, declared, in frame order.
const STAGES: &[gibench_harness::kit::technique::Stage] = &[
    gibench_harness::kit::technique::Stage::gpu(STAGE_VOXELIZATION),
    gibench_harness::kit::technique::Stage::gpu(STAGE_RSM),
    gibench_harness::kit::technique::Stage::gpu(STAGE_INJECTION),
    gibench_harness::kit::technique::Stage::gpu(STAGE_PROPAGATION),
    gibench_harness::kit::technique::Stage::gpu(STAGE_RECONSTRUCTION),
];

/// Registry entry.
pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "gaitatzes",
    paper: "Gaitatzes et al. 2010",
    summary: "voxel SH propagation of indirect light",
    description: "Gaitatzes et al. 2010 voxel SH light propagation with occlusion and multiple bounces (mode=lpv: Kaplanyan's light propagation volumes)",
    stages: &[STAGES],
    params: &[PARAMS],
    required_features: wgpu::Features::empty(),
    required_limits: wgpu::Limits::downlevel_defaults,
    reference: gibench_harness::kit::technique::multi_bounce,
    // On the Cornell boxes against the multi-bounce reference at the defaults (32³, 12
    // iterations, `transport=cosine`; measured on lavapipe, 96x72, after three frames): a
    // known darkness, the propagation's (README, *Voxel SH propagation*: light diffuses back to
    // its source instead of crossing the box, and 12 iterations reach a third of it).
    conformance: Conformance {
        defaults: &cornell_boxes([
            (0.315, 0.724),
            (0.322, 0.717),
            (0.321, 0.942),
            (0.570, 0.770),
        ]),
        converged: Converged {
            params: &["transport=pyramid", "iterations=256", "albedo=stored"],
            why: "the face-pyramid transport (light carried along, not diffused at every cell), 256 iterations (light crosses the 32-cell grid many times: every bounce arrives) and the voxels' stored albedo (not the paper's constant 0.5); left: the 32-cell grid's blur and the SH's low order",
            boxes: &cornell_boxes([(0.991, 0.262), (1.003, 0.262), (1.055, 0.651), (0.987, 0.323)]),
        },
    },
    knob: Some(KNOB),
    prepare: prepare_nothing,
    create,
};

/// `gaitatzes`.
pub struct Gaitatzes {
    _volumes: Volumes,
    light: Light,
    reconstruction: Reconstruction,
    iterations: u32,
    grid: u32,
    _output: wgpu::Texture,
    view: wgpu::TextureView,
    costs: Costs,
}

/// How the grid gets its light and moves it: the paper's voxelization and occluded
/// propagation, or light propagation volumes' injection and propagation (`mode=lpv`).
enum Light {
    Occluded {
        voxelizer: Box<Voxelizer>,
        propagation: Propagation,
    },
    Lpv {
        rsm: Box<ReflectiveShadowMap>,
        injection: lpv::Injection,
        propagation: lpv::LpvPropagation,
    },
}

/// The stages' declared minimum costs ([`gibench_harness::measure::roofline`]), computed once. Cells:
/// `grid`³; a cell of the voxel buffer or of an SH buffer is [`CELL_BYTES`] (three vec4s).
struct Costs {
    voxelization: StageCost,
    propagation: StageCost,
    reconstruction: StageCost,
}

impl Costs {
    fn new(grid: &Grid, iterations: u32, resolution: [u32; 2], ctx: &PrepareContext) -> Costs {
        let cells = grid.cells();
        let pixels = resolution[0] as u64 * resolution[1] as u64;
        // `voxelization` (with injection): the scene drawn once, and per cell its voxel
        // (normal, albedo, radiosity), its injected SH and its cleared accumulation written
        // once (3 × 48 bytes). Drawing the scene once per slice (3·grid times) is this
        // implementation's way, not the minimum; the injection's arithmetic, only in occupied
        // cells (not known before the frame), is not counted.
        let voxelization =
            ctx.gpu_scene
                .draw_cost()
                .plus(StageCost::per_element(cells, 0, 3 * CELL_BYTES, 0));
        // `propagation`, per iteration and cell: its voxel's normal and occupancy read (a
        // vec4, 16 bytes), its SH read once (48: every neighbour reads it, but once is the
        // minimum) and the next SH written (48); the accumulation is added to only in
        // occupied cells (not counted). Operations: each cell's six face integrals once (6
        // faces × 3 channels × a 4-term dot product, 144) and the six incoming lobes added
        // (6 × 3 × 4 FMAs, 144). `mode=lpv`: `LpvPropagation::cost`.
        let propagation = match grid.mode {
            Mode::Occluded => {
                StageCost::per_element(cells * iterations as u64, 16 + CELL_BYTES, CELL_BYTES, 288)
            }
            Mode::Lpv => lpv::LpvPropagation::cost(cells, iterations),
        };
        // `reconstruction`: per pixel the G-buffer's depth and normal read (12 bytes) and the
        // irradiance written (Rgba16Float, 8); the accumulation and the voxels' occupancy read
        // once (48 + 16 bytes per cell). Per pixel the position rebuilt from depth (32
        // operations), eight cells' SH weighted (8 × 12 FMAs, 192) and the irradiance's dot
        // product per channel (3 × 4 FMAs, 24).
        let reconstruction = StageCost::per_element(pixels, 12, 8, 248)
            .plus(StageCost::per_element(cells, CELL_BYTES + 16, 0, 0));
        Costs {
            voxelization,
            propagation,
            reconstruction,
        }
    }
}

fn create(params: &Params, ctx: &PrepareContext, _: &Prepared) -> Result<Box<dyn Technique>> {
    let p = GaitatzesParams::from_params(params)?;
    let gpu = ctx.gpu;
    let grid = Grid::around(
        &ctx.scene.extent,
        p.grid,
        p.mode,
        p.stored_albedo,
        p.transport,
    );
    let volumes = Volumes::new(gpu, &grid)?;
    let light = match p.mode {
        Mode::Occluded => Light::Occluded {
            voxelizer: Box::new(Voxelizer::new(
                gpu,
                &grid,
                ctx.gpu_scene,
                ctx.uniforms,
                ctx.direct,
                &volumes,
            )?),
            propagation: Propagation::new(gpu, &grid, &volumes)?,
        },
        Mode::Lpv => {
            let rsm = Box::new(ReflectiveShadowMap::new(
                gpu,
                ctx.gpu_scene,
                ctx.uniforms,
                lpv::RSM_SIZE,
            )?);
            let injection = lpv::Injection::new(gpu, &grid, rsm.buffers(), rsm.texels(), &volumes)?;
            Light::Lpv {
                rsm,
                injection,
                propagation: lpv::LpvPropagation::new(gpu, &grid, &volumes)?,
            }
        }
    };
    let output = gibench_harness::kit::passes::indirect_target(&gpu.device, ctx.resolution, true);
    let view = output.create_view(&Default::default());
    let reconstruction = Reconstruction::new(gpu, &grid, ctx.gbuffer, &volumes, &view)?;
    Ok(Box::new(Gaitatzes {
        _volumes: volumes,
        light,
        reconstruction,
        iterations: p.iterations,
        grid: p.grid,
        _output: output,
        view,
        costs: Costs::new(&grid, p.iterations, ctx.resolution, ctx),
    }))
}

impl Technique for Gaitatzes {
    fn render(&mut self, ctx: &mut FrameContext) -> Result<()> {
        let gpu = ctx.gpu;
        let (scene, uniforms, direct, gbuffer) =
            (ctx.gpu_scene, ctx.uniforms, ctx.direct, ctx.gbuffer);
        let iterations = self.iterations;
        match &self.light {
            Light::Occluded {
                voxelizer,
                propagation,
            } => {
                ctx.profiler.gpu_stage(gpu, STAGE_VOXELIZATION, |enc| {
                    voxelizer.encode(enc, scene, uniforms, direct)
                })?;
                ctx.profiler
                    .stage_cost(STAGE_VOXELIZATION, self.costs.voxelization);
                ctx.profiler.gpu_stage(gpu, STAGE_PROPAGATION, |enc| {
                    propagation.encode(enc, iterations)
                })?;
            }
            Light::Lpv {
                rsm,
                injection,
                propagation,
            } => {
                rsm.record(ctx)?;
                ctx.profiler
                    .gpu_stage(gpu, STAGE_INJECTION, |enc| injection.encode(enc))?;
                ctx.profiler.stage_cost(STAGE_INJECTION, injection.cost);
                ctx.profiler.gpu_stage(gpu, STAGE_PROPAGATION, |enc| {
                    propagation.encode(enc, iterations)
                })?;
            }
        }
        ctx.profiler
            .stage_cost(STAGE_PROPAGATION, self.costs.propagation);
        ctx.profiler.gpu_stage(gpu, STAGE_RECONSTRUCTION, |enc| {
            self.reconstruction.encode(enc, gbuffer)
        })?;
        ctx.profiler
            .stage_cost(STAGE_RECONSTRUCTION, self.costs.reconstruction);
        ctx.profiler.count("grid", self.grid as f64);
        ctx.profiler.count("iterations", self.iterations as f64);
        Ok(())
    }

    fn output(&self) -> &wgpu::TextureView {
        &self.view
    }
}
