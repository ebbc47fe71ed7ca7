//! Interleaved sampling (Keller & Heidrich 2001) as Laine et al. 2007 §5 use it: split the
//! G-buffer into n×m tiles, accumulate each tile's share of the VPLs (the technique's own
//! shader), combine the tiles back, and filter with the geometry-aware n×m box of Figure 5.
//! Written once and used by every VPL technique.
//!
//! # Layout
//!
//! * Full resolution W×H; tiles n×m (n columns, m rows; 1×1 means no interleaving); each of
//!   `1..=64`.
//! * Tile size tw×th = ceil(W/n)×ceil(H/m); the split buffers hold (n·tw)×(m·th) texels, row-major
//!   in split coordinates (sx, sy), one `vec4<f32>` each.
//! * Split texel (sx, sy) lies in tile (i, j) = (sx / tw, sy / th) at (a, b) = (sx % tw, sy % th)
//!   and holds the original pixel (a·n + i, b·m + j): each tile is the whole image sub-sampled at
//!   one offset. Texels whose original pixel lies outside W×H are invalid.
//! * The tile index of a texel is j·n + i (`split_tile` in WGSL).
//!
//! # Stages (each its own labelled compute pass, 8×8 workgroups)
//!
//! * **split** ([`Interleave::encode_split`], label `interleave split`) — reads: the G-buffer
//!   (camera, depth, normal); writes: `split_position` (world position from `world_from_depth` at
//!   the pixel centre, w = 1 where geometry was hit, 0 for background or invalid texels) and
//!   `split_normal` (xyz unit normal, w = 0; zero for background or invalid texels).
//! * **accumulate** — the technique's: it prepends [`INTERLEAVE_WGSL`] to its shader, binds
//!   [`Interleave::split_group`] at group 0 (0 `interleave: InterleaveParams`, 1 `split_position`
//!   read, 2 `split_normal` read, 3 `split_irradiance` read_write) and its own groups after, and
//!   dispatches 8×8 workgroups over the split size ([`Interleave::dispatch_split_size`]). Each
//!   invocation returns when `!split_in_range(sx, sy)`, skips texels with
//!   `split_position[i].w == 0` (writing zero) and lights the texel with the VPLs of tile
//!   `split_tile(sx, sy)`.
//! * **combine** ([`Interleave::encode_combine`], label `interleave combine`) — reads:
//!   `split_irradiance`; writes: `combined` (W×H, row-major), the exact inverse of the split.
//! * **filter** ([`Interleave::encode_filter`], label `interleave filter`) — reads:
//!   `split_position` and `split_normal` (this frame's split: each tap's surface without
//!   rebuilding its position from depth) and `combined`; writes: the technique's `output` texture (Rgba16Float, rgb = filtered
//!   irradiance, a = 1 where geometry was hit; background pixels are 0). Per pixel p the n×m box
//!   of offsets x ∈ [0, n), y ∈ [0, m) from p − (⌊n/2⌋, ⌊m/2⌋) is averaged over pixels q with
//!   |pos(q) − pos(p)| < α and normal(q)·normal(p) > β (p itself always counts). At image borders
//!   the box is shifted to lie inside the image (so it still covers one pixel of every tile);
//!   only when the image is smaller than the box are taps dropped.

use bytemuck::{Pod, Zeroable};

use crate::gpu::GpuContext;
use crate::{Error, Result};

use crate::kit::passes::{
    bind_buffer, params_entry, shader_module, storage_entry, storage_texture_entry, GBuffer,
    HDR_FORMAT, PARAMS_USAGE,
};

/// WGSL a technique composes into its accumulate shader (its bindings, and the import of the
/// module `gibench::interleave`, resolved by [`crate::kit::passes::shader_module`]): `struct InterleaveParams { full, tiles, tile_size, split:
/// vec2<u32>, thresholds: vec4<f32> }`, the group-0 bindings `interleave`, `split_position`,
/// `split_normal`, `split_irradiance`, and the helpers `split_in_range`, `split_index`,
/// `split_tile`, `split_original_pixel`, `split_valid` and `split_texel_of_pixel`.
pub const INTERLEAVE_WGSL: &str = include_str!("shaders/interleave_bindings.wgsl");

/// Thresholds of the geometry-aware filter (Laine et al. 2007, Figure 5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterSettings {
    /// Distance threshold α in scene units (descriptor `settings.filter_distance`).
    pub alpha: f32,
    /// Normal threshold β, a cosine (descriptor `settings.filter_normal`, 0.8 by default).
    pub beta: f32,
}

/// `InterleaveParams` in WGSL.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Params {
    full: [u32; 2],
    tiles: [u32; 2],
    tile_size: [u32; 2],
    split: [u32; 2],
    thresholds: [f32; 4],
}

/// The split, combine and filter passes and their buffers (see the module docs).
pub struct Interleave {
    /// Full resolution W×H.
    pub full: [u32; 2],
    /// n×m.
    pub tiles: [u32; 2],
    /// tw×th = ceil(W/n)×ceil(H/m).
    pub tile_size: [u32; 2],
    /// (n·tw)×(m·th).
    pub split_size: [u32; 2],
    /// The filter's current thresholds.
    pub filter: FilterSettings,
    /// The `InterleaveParams` uniform.
    pub params: wgpu::Buffer,
    /// World position per split texel (w = 1 valid geometry, 0 background / outside).
    pub split_position: wgpu::Buffer,
    /// Unit normal per split texel (w = 0).
    pub split_normal: wgpu::Buffer,
    /// Irradiance per split texel, written by the technique's accumulate shader.
    pub split_irradiance: wgpu::Buffer,
    /// Combined (unfiltered) irradiance per full-resolution pixel, row-major.
    pub combined: wgpu::Buffer,
    split_layout: wgpu::BindGroupLayout,
    split_group: wgpu::BindGroup,
    pass_group: wgpu::BindGroup,
    gbuffer_group: wgpu::BindGroup,
    split_pipeline: wgpu::ComputePipeline,
    combine_pipeline: wgpu::ComputePipeline,
    filter_pipeline: wgpu::ComputePipeline,
}

const WG: u32 = Interleave::WORKGROUP_SIZE;

/// Refuses a tile grid outside `1..=MAX_TILES` per side or with more tiles along an axis than
/// the image has pixels, an output texture that is not the G-buffer's size, format and storage
/// usage, and filter thresholds out of range.
fn check_setup(
    tiles: [u32; 2],
    full: [u32; 2],
    output: &wgpu::Texture,
    filter: &FilterSettings,
) -> Result<()> {
    if tiles
        .iter()
        .any(|t| !(1..=Interleave::MAX_TILES).contains(t))
    {
        return Err(Error::param(
            "tiles",
            format!(
                "{}x{} tiles: each side must be between 1 and {}",
                tiles[0],
                tiles[1],
                Interleave::MAX_TILES
            ),
        ));
    }
    if tiles[0] > full[0] || tiles[1] > full[1] {
        // Tiles without a pixel would take their VPLs' light away (or, filtered, spread
        // others' into hot spots).
        return Err(Error::param(
            "tiles",
            format!(
                "{}x{} tiles on a {}x{} image: a tile grid cannot have more tiles along an axis than the image has pixels",
                tiles[0], tiles[1], full[0], full[1]
            ),
        ));
    }
    let out_size = [output.width(), output.height()];
    if out_size != full || output.depth_or_array_layers() != 1 {
        return Err(Error::param(
            "output",
            format!(
                "interleave output texture is {}x{}x{}; it must match the G-buffer, {}x{}",
                out_size[0],
                out_size[1],
                output.depth_or_array_layers(),
                full[0],
                full[1]
            ),
        ));
    }
    if output.format() != HDR_FORMAT {
        return Err(Error::param(
            "output",
            format!(
                "interleave output texture is {:?}; it must be {HDR_FORMAT:?}",
                output.format()
            ),
        ));
    }
    if !output
        .usage()
        .contains(wgpu::TextureUsages::STORAGE_BINDING)
    {
        return Err(Error::param(
            "output",
            "interleave output texture needs usage STORAGE_BINDING",
        ));
    }
    check_filter(filter)?;
    Ok(())
}

/// The interleave buffers: the uniform and the split, irradiance and combined storage.
struct Buffers {
    params: wgpu::Buffer,
    split_position: wgpu::Buffer,
    split_normal: wgpu::Buffer,
    split_irradiance: wgpu::Buffer,
    combined: wgpu::Buffer,
}

impl Buffers {
    /// Split buffers of `split_bytes`, the combined buffer of `full_bytes`, and the uniform.
    fn new(device: &wgpu::Device, split_bytes: u64, full_bytes: u64) -> Buffers {
        let buffer = |label: &str, size: u64| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let split_position = buffer("interleave split position", split_bytes);
        let split_normal = buffer("interleave split normal", split_bytes);
        let split_irradiance = buffer("interleave split irradiance", split_bytes);
        let combined = buffer("interleave combined", full_bytes);
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("interleave params"),
            size: std::mem::size_of::<Params>() as u64,
            usage: PARAMS_USAGE,
            mapped_at_creation: false,
        });
        Buffers {
            params,
            split_position,
            split_normal,
            split_irradiance,
            combined,
        }
    }
}

/// Group 0 of a technique's accumulate shader: the uniform, the split position and normal
/// (read) and the split irradiance (read_write).
fn split_bind_group(
    device: &wgpu::Device,
    b: &Buffers,
) -> (wgpu::BindGroupLayout, wgpu::BindGroup) {
    let compute = wgpu::ShaderStages::COMPUTE;
    let split_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("interleave split (accumulate)"),
        entries: &[
            params_entry(0, compute),
            storage_entry(1, true),
            storage_entry(2, true),
            storage_entry(3, false),
        ],
    });
    let split_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("interleave split (accumulate)"),
        layout: &split_layout,
        entries: &[
            bind_buffer(0, &b.params),
            bind_buffer(1, &b.split_position),
            bind_buffer(2, &b.split_normal),
            bind_buffer(3, &b.split_irradiance),
        ],
    });
    (split_layout, split_group)
}

/// The split, combine and filter passes' group: every buffer and the output texture.
fn pass_bind_group(
    device: &wgpu::Device,
    b: &Buffers,
    output: &wgpu::Texture,
) -> (wgpu::BindGroupLayout, wgpu::BindGroup) {
    let compute = wgpu::ShaderStages::COMPUTE;
    let pass_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("interleave passes"),
        entries: &[
            params_entry(0, compute),
            storage_entry(1, false),
            storage_entry(2, false),
            storage_entry(3, true),
            storage_entry(4, false),
            storage_texture_entry(5, HDR_FORMAT),
        ],
    });
    let output_view = output.create_view(&Default::default());
    let pass_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("interleave passes"),
        layout: &pass_layout,
        entries: &[
            bind_buffer(0, &b.params),
            bind_buffer(1, &b.split_position),
            bind_buffer(2, &b.split_normal),
            bind_buffer(3, &b.split_irradiance),
            bind_buffer(4, &b.combined),
            wgpu::BindGroupEntry {
                binding: 5,
                resource: wgpu::BindingResource::TextureView(&output_view),
            },
        ],
    });
    (pass_layout, pass_group)
}

/// The split, combine and filter pipelines, in that order, over the pass group and the
/// G-buffer's read group.
/// The passes' shader (split, combine, filter).
const PASSES_WGSL: &str = include_str!("shaders/interleave_passes.wgsl");

fn pipelines(
    device: &wgpu::Device,
    pass_layout: &wgpu::BindGroupLayout,
    gbuffer: &GBuffer,
    source: &str,
) -> [wgpu::ComputePipeline; 3] {
    let module = shader_module(device, "interleave", source);
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("interleave"),
        bind_group_layouts: &[Some(pass_layout), Some(&gbuffer.read_layout)],
        immediate_size: 0,
    });
    let pipeline = |label: &str, entry: &str| {
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        })
    };
    let split_pipeline = pipeline("interleave split", "split_main");
    let combine_pipeline = pipeline("interleave combine", "combine_main");
    let filter_pipeline = pipeline("interleave filter", "filter_main");
    [split_pipeline, combine_pipeline, filter_pipeline]
}

impl Interleave {
    /// Workgroup size (both axes) of every interleave pass; accumulate shaders use it too.
    pub const WORKGROUP_SIZE: u32 = 8;
    /// Largest number of tiles per axis.
    pub const MAX_TILES: u32 = 64;

    /// Creates the buffers, pipelines and bind groups (nothing is created per frame).
    ///
    /// `output` is the technique's full-resolution indirect-irradiance texture: Rgba16Float, the
    /// G-buffer's size, with usage STORAGE_BINDING (and typically TEXTURE_BINDING | COPY_SRC).
    pub fn new(
        gpu: &GpuContext,
        gbuffer: &GBuffer,
        tiles: (u32, u32),
        filter: FilterSettings,
        output: &wgpu::Texture,
    ) -> Result<Interleave> {
        Self::with_passes_source(gpu, gbuffer, tiles, filter, output, PASSES_WGSL)
    }

    /// [`Interleave::new`] with the split, combine and filter passes compiled from `source`
    /// (entry points and bindings as `shaders/interleave_passes.wgsl`'s) instead of the kit's:
    /// how a test runs an earlier implementation of a pass beside the current one.
    pub fn with_passes_source(
        gpu: &GpuContext,
        gbuffer: &GBuffer,
        tiles: (u32, u32),
        filter: FilterSettings,
        output: &wgpu::Texture,
        source: &str,
    ) -> Result<Interleave> {
        let device = &gpu.device;
        let tiles = [tiles.0, tiles.1];
        let full = gbuffer.size;
        check_setup(tiles, full, output, &filter)?;
        let tile_size = [full[0].div_ceil(tiles[0]), full[1].div_ceil(tiles[1])];
        let split_size = [tile_size[0] * tiles[0], tile_size[1] * tiles[1]];

        let split_bytes = split_size[0] as u64 * split_size[1] as u64 * 16;
        let full_bytes = full[0] as u64 * full[1] as u64 * 16;
        let max = gpu.max_storage_buffer();
        if split_bytes.max(full_bytes) > max {
            return Err(Error::Gpu(format!(
                "interleave buffers of {} bytes exceed the adapter's storage-buffer limit of {max}",
                split_bytes.max(full_bytes)
            )));
        }
        let buffers = Buffers::new(device, split_bytes, full_bytes);
        let (split_layout, split_group) = split_bind_group(device, &buffers);
        let (pass_layout, pass_group) = pass_bind_group(device, &buffers, output);
        let [split_pipeline, combine_pipeline, filter_pipeline] =
            pipelines(device, &pass_layout, gbuffer, source);

        let Buffers {
            params,
            split_position,
            split_normal,
            split_irradiance,
            combined,
        } = buffers;
        let me = Interleave {
            full,
            tiles,
            tile_size,
            split_size,
            filter,
            params,
            split_position,
            split_normal,
            split_irradiance,
            combined,
            split_layout,
            split_group,
            pass_group,
            gbuffer_group: gbuffer.read_group.clone(),
            split_pipeline,
            combine_pipeline,
            filter_pipeline,
        };
        me.write_params(&gpu.queue);
        Ok(me)
    }

    fn write_params(&self, queue: &wgpu::Queue) {
        let p = Params {
            full: self.full,
            tiles: self.tiles,
            tile_size: self.tile_size,
            split: self.split_size,
            thresholds: [self.filter.alpha, self.filter.beta, 0.0, 0.0],
        };
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
    }

    /// Changes the filter thresholds (takes effect for work submitted afterwards).
    pub fn set_filter(&mut self, queue: &wgpu::Queue, filter: FilterSettings) -> Result<()> {
        check_filter(&filter)?;
        self.filter = filter;
        self.write_params(queue);
        Ok(())
    }

    /// Layout of [`Interleave::split_group`], for the technique's accumulate pipeline (group 0).
    pub fn split_layout(&self) -> &wgpu::BindGroupLayout {
        &self.split_layout
    }

    /// Group 0 of the accumulate shader: 0 `InterleaveParams`, 1 `split_position` (read),
    /// 2 `split_normal` (read), 3 `split_irradiance` (read_write); compute only.
    pub fn split_group(&self) -> &wgpu::BindGroup {
        &self.split_group
    }

    /// Number of split texels (n·tw)·(m·th).
    pub fn split_texels(&self) -> u32 {
        self.split_size[0] * self.split_size[1]
    }

    /// Dispatches 8×8 workgroups covering the split size (the accumulate convention).
    pub fn dispatch_split_size(&self, pass: &mut wgpu::ComputePass) {
        pass.dispatch_workgroups(
            self.split_size[0].div_ceil(WG),
            self.split_size[1].div_ceil(WG),
            1,
        );
    }

    fn run(
        &self,
        enc: &mut wgpu::CommandEncoder,
        label: &str,
        pipeline: &wgpu::ComputePipeline,
        size: [u32; 2],
    ) {
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(label),
            timestamp_writes: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &self.pass_group, &[]);
        pass.set_bind_group(1, &self.gbuffer_group, &[]);
        pass.dispatch_workgroups(size[0].div_ceil(WG), size[1].div_ceil(WG), 1);
    }

    /// Records the split: G-buffer → `split_position`, `split_normal`.
    pub fn encode_split(&self, enc: &mut wgpu::CommandEncoder) {
        self.run(
            enc,
            "interleave split",
            &self.split_pipeline,
            self.split_size,
        );
    }

    /// Records the combine: `split_irradiance` → `combined` (the exact inverse of the split).
    pub fn encode_combine(&self, enc: &mut wgpu::CommandEncoder) {
        self.run(enc, "interleave combine", &self.combine_pipeline, self.full);
    }

    /// Records the geometry-aware n×m box filter: `split_position`, `split_normal` (the split
    /// must have run on this frame's G-buffer), `combined` → `output`.
    pub fn encode_filter(&self, enc: &mut wgpu::CommandEncoder) {
        self.run(enc, "interleave filter", &self.filter_pipeline, self.full);
    }
}

fn check_filter(f: &FilterSettings) -> Result<()> {
    if f.alpha.is_nan() || f.beta.is_nan() {
        return Err(Error::param(
            "filter",
            format!(
                "filter thresholds must be numbers, got alpha {} and beta {}",
                f.alpha, f.beta
            ),
        ));
    }
    Ok(())
}
