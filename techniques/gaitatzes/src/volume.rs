//! The voxel grid and its passes: voxelization with injection, propagation, reconstruction.
//!
//! * [`Grid`] — the cubic grid around the scene and the WGSL constants every pass shares.
//! * [`Volumes`] — Reads: nothing. Writes (owns): the voxel buffer (normal and occupancy,
//!   albedo, direct radiosity per cell), two propagation buffers and the accumulation buffer
//!   (second-order SH per colour channel per cell).
//! * [`Voxelizer`] — Reads: the scene (static mesh and movers), materials and textures, the
//!   direct light (its shadow map). Writes: three per-axis slice atlases (its own), then the
//!   voxel buffer, the first propagation buffer (the injected direct radiosity) and the
//!   accumulation (cleared). (`mode=lpv` injects and propagates with [`crate::lpv`] instead.)
//! * [`Propagation`] — Reads: the voxel buffer. Writes: its two senders buffers (its own: per
//!   cell the flux it sends through each face), the propagation buffers (ping-pong) and the
//!   accumulation.
//! * [`Reconstruction`] — Reads: the G-buffer, the voxel buffer, the accumulation. Writes: the
//!   technique's indirect-irradiance output.

use gibench_harness::glam::{Mat4, Vec3, Vec4};
use gibench_harness::gpu::GpuContext;
use gibench_harness::kit::passes::{
    compute_pipeline, shader_module, Bindings, Bound, DirectLight, DrawSet, FrameUniforms, GBuffer,
    GpuScene, Vertex, HDR_FORMAT,
};
use gibench_harness::scene::SceneExtent;
use gibench_harness::{wgpu, Error, Result};

use crate::sh;

/// How radiance moves through the grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Gaitatzes et al. 2010: through void cells only, reflected at occupied ones (secondary
    /// bounces), accumulated where it arrives at occupied cells.
    Occluded,
    /// Kaplanyan's light propagation volumes ([`crate::lpv`]): through every cell, no reflection,
    /// accumulated everywhere.
    Lpv,
}

/// What a void cell passes on of the flux it sends through a face (the flux itself, the share
/// of the cell's radiance integral over that face's pyramid, is the same in both).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transport {
    /// The paper's scheme as this crate reads it (and light propagation volumes'): the flux
    /// arrives as a clamped-cosine lobe along the face's axis. A lobe sends 40 % of its flux on,
    /// 15 % through each side face, and side lobes send 15 % back: light diffuses, and between
    /// two walls most of it returns to where it came from.
    Cosine,
    /// The flux arrives with the sending cell's own angular distribution (its SH, rescaled to
    /// the flux): a lobe keeps its direction however it is split among faces, so light moving
    /// away from a wall never turns back. Occupied cells still receive (and reflect) the flux as
    /// a cosine lobe along the face's axis.
    Carry,
    /// The flux arrives with the angular distribution of the light that crossed the face: the
    /// sender's radiance restricted to the face's pyramid, re-projected (its integral and first
    /// moment). Light through the front face stays forward, light through a side face leans
    /// forward too, so less of it turns back than with `Cosine`, and it still spreads. Occupied
    /// cells receive and reflect cosine lobes, as with `Carry`.
    Pyramid,
}

impl Transport {
    /// The parameter's values, in the order of the variants.
    pub const NAMES: [&'static str; 3] = ["cosine", "carry", "pyramid"];

    /// Parses a value of the `transport` parameter.
    pub fn parse(name: &str) -> Result<Transport> {
        match name {
            "cosine" => Ok(Transport::Cosine),
            "carry" => Ok(Transport::Carry),
            "pyramid" => Ok(Transport::Pyramid),
            other => Err(Error::param(
                "transport",
                format!(
                    "unknown transport '{other}' (expected one of {})",
                    Transport::NAMES.join(", ")
                ),
            )),
        }
    }

    pub fn name(self) -> &'static str {
        Transport::NAMES[self as usize]
    }
}

/// The grid (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// Cells per axis.
    pub n: u32,
    /// The min corner.
    pub origin: Vec3,
    /// Cell edge.
    pub cell: f32,
    pub mode: Mode,
    /// Secondary bounces with the voxel's albedo instead of the paper's constant 0.5.
    pub stored_albedo: bool,
    /// What void cells pass on.
    pub transport: Transport,
}

/// Bytes of one cell of the voxel buffer (`Voxel`), of an SH buffer (`Sh3`) and of each of the
/// propagation's two senders buffers (`Sender`: the flux through three of its faces).
pub const CELL_BYTES: u64 = 48;

impl Grid {
    /// A cubic grid of `n`³ cells around `extent`: its largest side plus half a cell on each
    /// side, so that walls on the bounding box fall inside cells, not on their boundaries.
    pub fn around(
        extent: &SceneExtent,
        n: u32,
        mode: Mode,
        stored_albedo: bool,
        transport: Transport,
    ) -> Grid {
        let side = (extent.max - extent.min).max_element().max(1e-6) * n as f32 / (n as f32 - 1.0);
        Grid {
            n,
            origin: extent.centre - Vec3::splat(side / 2.0),
            cell: side / n as f32,
            mode,
            stored_albedo,
            transport,
        }
    }

    /// Cells in the grid.
    pub fn cells(&self) -> u64 {
        (self.n as u64).pow(3)
    }

    /// Slice tiles per row of a voxelization atlas.
    pub fn cols(&self) -> u32 {
        (self.n as f32).sqrt().ceil() as u32
    }

    /// The atlas of one axis: `cols` × `rows` tiles of `n`² texels.
    pub fn atlas_size(&self) -> [u32; 2] {
        let cols = self.cols();
        [cols * self.n, self.n.div_ceil(cols) * self.n]
    }

    /// The grid's constants, the SH convention ([`sh::wgsl`]) and `grid.wgsl`.
    pub fn wgsl(&self) -> String {
        format!(
            "const N: u32 = {}u;\nconst COLS: u32 = {}u;\nconst ORIGIN: vec3<f32> = vec3<f32>({:.9e}, {:.9e}, {:.9e});\n\
             const CELL: f32 = {:.9e};\nconst MODE: u32 = {}u;\nconst STORED_ALBEDO: u32 = {}u;\n\
             const TRANSPORT: u32 = {}u;\n{}\n{}",
            self.n,
            self.cols(),
            self.origin.x,
            self.origin.y,
            self.origin.z,
            self.cell,
            (self.mode == Mode::Lpv) as u32,
            self.stored_albedo as u32,
            self.transport as u32,
            sh::wgsl(),
            include_str!("shaders/grid.wgsl")
        )
    }

    /// World → clip of slice `s` along `axis` (0 x, 1 y, 2 z): x and y over the slice's tile
    /// (the other two axes, in the order the combine pass reads), z the position along the axis
    /// in cells minus `s`, so that clipping to [0, 1] keeps the slice.
    pub fn slice_matrix(&self, axis: usize, s: u32) -> Mat4 {
        let (iu, iv, iw) = [(1, 2, 0), (2, 0, 1), (0, 1, 2)][axis];
        let scale = 2.0 / (self.n as f32 * self.cell);
        let unit = |i: usize| Vec3::AXES[i];
        let row_x = (unit(iu) * scale).extend(-self.origin[iu] * scale - 1.0);
        let row_y = (-unit(iv) * scale).extend(self.origin[iv] * scale + 1.0);
        let row_z = (unit(iw) / self.cell).extend(-self.origin[iw] / self.cell - s as f32);
        Mat4::from_cols(row_x, row_y, row_z, Vec4::W).transpose()
    }

    /// Checks the grid's buffers and atlases against the adapter's limits.
    pub fn check_limits(&self, gpu: &GpuContext) -> Result<()> {
        let limits = gpu.device.limits();
        let bytes = self.cells() * CELL_BYTES;
        let max = gpu.max_storage_buffer();
        if bytes > max {
            return Err(Error::param(
                "grid",
                format!(
                    "a {0}³ grid needs {bytes}-byte buffers; this adapter allows {max} bytes",
                    self.n
                ),
            ));
        }
        let [w, h] = self.atlas_size();
        if w.max(h) > limits.max_texture_dimension_2d {
            return Err(Error::param(
                "grid",
                format!(
                    "a {0}³ grid's slice atlas is {w}x{h}; this adapter allows {1}",
                    self.n, limits.max_texture_dimension_2d
                ),
            ));
        }
        Ok(())
    }
}

/// The grid's buffers (see the module docs). All are STORAGE, COPY_SRC and COPY_DST (tests
/// read and write them).
pub struct Volumes {
    pub voxels: wgpu::Buffer,
    pub propagation: [wgpu::Buffer; 2],
    pub accumulation: wgpu::Buffer,
}

impl Volumes {
    pub fn new(gpu: &GpuContext, grid: &Grid) -> Result<Volumes> {
        grid.check_limits(gpu)?;
        let buffer = |label: &str| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: grid.cells() * CELL_BYTES,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        Ok(Volumes {
            voxels: buffer("voxels"),
            propagation: [buffer("propagation a"), buffer("propagation b")],
            accumulation: buffer("accumulation"),
        })
    }
}

/// Uniform slots of the slice matrices are this far apart.
const SLICE_STRIDE: u64 = 256;

/// Voxelization, combine and injection (see the module docs).
pub struct Voxelizer {
    n: u32,
    cols: u32,
    /// Per axis: radiosity, normal, albedo targets (views).
    targets: Vec<[wgpu::TextureView; 3]>,
    slice_group: wgpu::BindGroup,
    pipeline: wgpu::RenderPipeline,
    combine: wgpu::ComputePipeline,
    combine_group: wgpu::BindGroup,
    _slices: wgpu::Buffer,
    _textures: Vec<wgpu::Texture>,
}

/// Format of the voxelization atlases (blendable and renderable on Vulkan and GL).
const ATLAS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

impl Voxelizer {
    pub fn new(
        gpu: &GpuContext,
        grid: &Grid,
        scene: &GpuScene,
        uniforms: &FrameUniforms,
        direct: &DirectLight,
        volumes: &Volumes,
    ) -> Result<Voxelizer> {
        let device = &gpu.device;
        let (textures, targets) = atlas_targets(device, grid);
        let (slices, slice_layout, slice_group) = slice_matrices(gpu, grid);
        let pipeline = voxelize_pipeline(device, &slice_layout, scene, uniforms, direct);
        let (combine, combine_group) = combine_pass(device, grid, &targets, volumes);
        gpu.check_errors()?;
        Ok(Voxelizer {
            n: grid.n,
            cols: grid.cols(),
            targets,
            slice_group,
            pipeline,
            combine,
            combine_group,
            _slices: slices,
            _textures: textures,
        })
    }

    /// Records the three axes' slice passes (every slice draws the static mesh and the
    /// movers), then the combine and injection pass.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        uniforms: &FrameUniforms,
        direct: &DirectLight,
    ) {
        let n = self.n;
        for (axis, targets) in self.targets.iter().enumerate() {
            let attachment = |view| {
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("voxelize"),
                color_attachments: &[
                    attachment(&targets[0]),
                    attachment(&targets[1]),
                    attachment(&targets[2]),
                ],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(2, &scene.material_group, &[]);
            pass.set_bind_group(3, &direct.light_group, &[]);
            for s in 0..n {
                let (x, y) = ((s % self.cols) * n, (s / self.cols) * n);
                pass.set_viewport(x as f32, y as f32, n as f32, n as f32, 0.0, 1.0);
                pass.set_scissor_rect(x, y, n, n);
                let offset = ((axis as u64 * n as u64 + s as u64) * SLICE_STRIDE) as u32;
                pass.set_bind_group(0, &self.slice_group, &[offset]);
                scene.draw(&mut pass, uniforms, 1, DrawSet::StaticAndMovers);
            }
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("voxel combine"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.combine);
        pass.set_bind_group(0, &self.combine_group, &[]);
        let g = n.div_ceil(4);
        pass.dispatch_workgroups(g, g, g);
    }
}

/// The voxelization atlases, per axis radiosity, normal and albedo (`grid`'s slices side by
/// side), and their views.
fn atlas_targets(
    device: &wgpu::Device,
    grid: &Grid,
) -> (Vec<wgpu::Texture>, Vec<[wgpu::TextureView; 3]>) {
    let [w, h] = grid.atlas_size();
    let mut textures = Vec::new();
    let mut targets = Vec::new();
    for axis in ["x", "y", "z"] {
        let make = |what: &str| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(&format!("voxel atlas {axis} {what}")),
                size: wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: ATLAS_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
        };
        let t = [make("radiosity"), make("normal"), make("albedo")];
        targets.push(t.each_ref().map(|t| t.create_view(&Default::default())));
        textures.extend(t);
    }
    (textures, targets)
}

/// One world → clip matrix per (axis, slice), written once, and the bind group that picks
/// one of them at a dynamic offset.
fn slice_matrices(
    gpu: &GpuContext,
    grid: &Grid,
) -> (wgpu::Buffer, wgpu::BindGroupLayout, wgpu::BindGroup) {
    let device = &gpu.device;
    let slices = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("voxel slices"),
        size: 3 * grid.n as u64 * SLICE_STRIDE,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut bytes = vec![0u8; slices.size() as usize];
    for axis in 0..3 {
        for s in 0..grid.n {
            let m = grid.slice_matrix(axis, s).to_cols_array();
            let o = (axis as u64 * grid.n as u64 + s as u64) * SLICE_STRIDE;
            bytes[o as usize..o as usize + 64].copy_from_slice(bytemuck::cast_slice(&m));
        }
    }
    gpu.queue.write_buffer(&slices, 0, &bytes);
    let first_slice = wgpu::BindingResource::Buffer(wgpu::BufferBinding {
        buffer: &slices,
        offset: 0,
        size: wgpu::BufferSize::new(64),
    });
    let slice = Bindings::new("voxel slice", wgpu::ShaderStages::VERTEX)
        .dynamic_uniform(first_slice)
        .build(device);
    let (slice_layout, slice_group) = (slice.layout, slice.group);
    (slices, slice_layout, slice_group)
}

/// The slice pass: every triangle scan-converted into a slice's three targets, blended by
/// addition.
fn voxelize_pipeline(
    device: &wgpu::Device,
    slice_layout: &wgpu::BindGroupLayout,
    scene: &GpuScene,
    uniforms: &FrameUniforms,
    direct: &DirectLight,
) -> wgpu::RenderPipeline {
    let source = format!(
        "{}\n{}",
        DirectLight::wgsl(3),
        include_str!("shaders/voxelize.wgsl")
    );
    let module = shader_module(device, "voxelize", &source);
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("voxelize"),
        bind_group_layouts: &[
            Some(slice_layout),
            Some(&uniforms.object_layout),
            Some(&scene.material_layout),
            Some(&direct.light_layout),
        ],
        immediate_size: 0,
    });
    let add = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    };
    let target = Some(wgpu::ColorTargetState {
        format: ATLAS_FORMAT,
        blend: Some(wgpu::BlendState {
            color: add,
            alpha: add,
        }),
        write_mask: wgpu::ColorWrites::ALL,
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("voxelize"),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_voxel"),
            compilation_options: Default::default(),
            buffers: &[Some(Vertex::LAYOUT)],
        },
        primitive: wgpu::PrimitiveState {
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_voxel"),
            compilation_options: Default::default(),
            targets: &[target.clone(), target.clone(), target],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// The combine and injection pass: the three axes' atlases (`targets`) read, the voxels and
/// the first propagation and accumulation volumes written.
fn combine_pass(
    device: &wgpu::Device,
    grid: &Grid,
    targets: &[[wgpu::TextureView; 3]],
    volumes: &Volumes,
) -> (wgpu::ComputePipeline, wgpu::BindGroup) {
    // The slices' nine targets (three per axis), then the volumes written.
    let targets = (targets.iter().flatten()).fold(
        Bindings::new("voxel combine", wgpu::ShaderStages::COMPUTE),
        |g, view| g.texture(view),
    );
    let Bound {
        layout: combine_layout,
        group: combine_group,
    } = targets
        .write(&volumes.voxels)
        .write(&volumes.propagation[0])
        .write(&volumes.accumulation)
        .build(device);
    let combine = compute_pipeline(
        device,
        "voxel combine",
        &format!("{}\n{}", grid.wgsl(), include_str!("shaders/combine.wgsl")),
        &[&combine_layout],
        "combine",
    );
    (combine, combine_group)
}

/// The propagation iterations (see the module docs). Each iteration is two dispatches
/// (`propagate.wgsl`): `faces` writes, per cell, the flux it sends through each of its six
/// faces (its own two buffers, [`CELL_BYTES`] per cell each); `propagate` gathers from the six
/// neighbours. The sender's work (its occupancy, open faces, face integrals and their
/// normalisation) is thus done once per cell and iteration, not once per receiving neighbour.
pub struct Propagation {
    n: u32,
    faces: wgpu::ComputePipeline,
    gather: wgpu::ComputePipeline,
    /// Per iteration parity [a → b, b → a]: (faces, gather).
    groups: [(wgpu::BindGroup, wgpu::BindGroup); 2],
    _senders: [wgpu::Buffer; 2],
}

impl Propagation {
    /// Cells per workgroup along x, y, z: `@workgroup_size` of both entry points of
    /// `propagate.wgsl`. The downlevel limit's 256 invocations; on llvmpipe (Cornell, 32³,
    /// vulkan) 4x4x4 took about 1.4 times as long, 32x8x1 about 1.3 times.
    const WORKGROUP: [u32; 3] = [8, 8, 4];

    pub fn new(gpu: &GpuContext, grid: &Grid, volumes: &Volumes) -> Result<Propagation> {
        let device = &gpu.device;
        // With `transport=carry` or `pyramid` the gather also reads the senders' SH: a fifth
        // storage buffer (the downlevel limit is four).
        let carries = grid.transport != Transport::Cosine;
        let have = device.limits().max_storage_buffers_per_shader_stage;
        if carries && have < 5 {
            return Err(Error::param(
                "transport",
                format!(
                    "transport={} needs 5 storage buffers per shader stage; this adapter allows {have} (transport=cosine needs 4)",
                    grid.transport.name()
                ),
            ));
        }
        // Their size (that of an SH buffer) is checked by `Grid::check_limits`.
        let sender = |label: &str| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: grid.cells() * CELL_BYTES,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            })
        };
        let senders = [
            sender("propagation senders +"),
            sender("propagation senders -"),
        ];
        let c = wgpu::ShaderStages::COMPUTE;
        // From the volume `from` to the other: `faces` reads the voxels and the source and
        // writes the senders; the gather (bindings 4.. of the same shader) reads the senders and
        // writes the other volume and the accumulation (and with `carry`, reads the source).
        let faces_of = |from: usize| {
            Bindings::new("propagation faces", c)
                .read(&volumes.voxels)
                .read(&volumes.propagation[from])
                .write(&senders[0])
                .write(&senders[1])
        };
        let gather_of = |from: usize| {
            let gather = Bindings::new("propagation", c)
                .first_binding(4)
                .read(&senders[0])
                .read(&senders[1])
                .write(&volumes.propagation[1 - from])
                .write(&volumes.accumulation);
            match carries {
                true => gather.read(&volumes.propagation[from]),
                false => gather,
            }
        };
        let (faces_layout, gather_layout) =
            (faces_of(0).layout(device), gather_of(0).layout(device));
        let groups = |from: usize| {
            (
                faces_of(from).group(device, &faces_layout),
                gather_of(from).group(device, &gather_layout),
            )
        };
        // The senders' SH, read by the gather with `transport=carry` and `pyramid` only (with
        // `cosine` the binding is left out of the shader and its layout).
        let sender_sh = if carries {
            "@group(0) @binding(8) var<storage, read> source: array<Sh3>;\n\
             fn sender_sh(i: u32) -> Sh3 { return source[i]; }"
        } else {
            "fn sender_sh(i: u32) -> Sh3 { return Sh3(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0)); }"
        };
        let source = format!(
            "{}\n{sender_sh}\n{}",
            grid.wgsl(),
            include_str!("shaders/propagate.wgsl")
        );
        let faces = compute_pipeline(
            device,
            "propagation faces",
            &source,
            &[&faces_layout],
            "faces",
        );
        let gather = compute_pipeline(
            device,
            "propagation",
            &source,
            &[&gather_layout],
            "propagate",
        );
        gpu.check_errors()?;
        Ok(Propagation {
            n: grid.n,
            faces,
            gather,
            groups: [groups(0), groups(1)],
            _senders: senders,
        })
    }

    /// Records `iterations` iterations starting from propagation buffer 0. The field after
    /// them is in buffer `iterations % 2`.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, iterations: u32) {
        self.encode_from(encoder, 0, iterations);
    }

    /// Records `iterations` iterations starting from propagation buffer `from` (0 or 1). The
    /// field after them is in buffer `(from + iterations) % 2`.
    pub fn encode_from(&self, encoder: &mut wgpu::CommandEncoder, from: u32, iterations: u32) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("propagation"),
            timestamp_writes: None,
        });
        let g = Propagation::WORKGROUP.map(|w| self.n.div_ceil(w));
        for k in from..from + iterations {
            let (faces, gather) = &self.groups[k as usize % 2];
            pass.set_pipeline(&self.faces);
            pass.set_bind_group(0, faces, &[]);
            pass.dispatch_workgroups(g[0], g[1], g[2]);
            pass.set_pipeline(&self.gather);
            pass.set_bind_group(0, gather, &[]);
            pass.dispatch_workgroups(g[0], g[1], g[2]);
        }
    }
}

/// The per-pixel reconstruction (see the module docs).
pub struct Reconstruction {
    size: [u32; 2],
    pipeline: wgpu::ComputePipeline,
    group: wgpu::BindGroup,
}

impl Reconstruction {
    pub fn new(
        gpu: &GpuContext,
        grid: &Grid,
        gbuffer: &GBuffer,
        volumes: &Volumes,
        output: &wgpu::TextureView,
    ) -> Result<Reconstruction> {
        let device = &gpu.device;
        let Bound { layout, group } = Bindings::new("reconstruction", wgpu::ShaderStages::COMPUTE)
            .read(&volumes.voxels)
            .read(&volumes.accumulation)
            .storage_texture(output, HDR_FORMAT)
            .build(device);
        let pipeline = compute_pipeline(
            device,
            "reconstruction",
            &format!(
                "{}\n{}",
                grid.wgsl(),
                include_str!("shaders/reconstruct.wgsl")
            ),
            &[&gbuffer.read_layout, &layout],
            "reconstruct",
        );
        gpu.check_errors()?;
        Ok(Reconstruction {
            size: gbuffer.size,
            pipeline,
            group,
        })
    }

    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, gbuffer: &GBuffer) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("reconstruction"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &gbuffer.read_group, &[]);
        pass.set_bind_group(1, &self.group, &[]);
        pass.dispatch_workgroups(self.size[0].div_ceil(8), self.size[1].div_ceil(8), 1);
    }
}
