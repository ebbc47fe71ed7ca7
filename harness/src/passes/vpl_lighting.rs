//! VPL shadow maps and interleaved VPL accumulation, shared by every instant-radiosity
//! technique (Keller, Laine, and later Barczak and ISM's accumulation).
//!
//! **Shadow maps** — reads: the static shadow-caster mesh (the tessellated copy where the scene
//! has one), object uniforms, the VPL views; writes: one depth atlas holding every VPL's map in
//! its slot: a paraboloid map (Brabec et al. 2002; Laine et al. 2007 §4.6) of `size`² texels, or
//! a cube map as 3×2 faces of `size`². Depth is 16- or 32-bit, reversed (1 near, 0 empty). Laine
//! keeps the maps in a texture array; gibench uses an atlas because depth texture arrays read
//! back as zero on wgpu's GL backend. Only static geometry is rendered: maps are reused across
//! frames and indirect light bounces off static geometry only (Laine §7).
//!
//! **Accumulation** — reads: the split G-buffer ([`Interleave`]), the VPL list, the atlas;
//! writes: the split irradiance. The VPL in shadow-map slot k is assigned to tile k mod T
//! (T = n·m tiles; Laine §5.1, §7), which stays the same while the VPL lives, and each VPL's
//! contribution is E = Φ/π · cos θ_v cos θ_r / max(r², d²) · V
//! with d the clamp distance against the 1/r² singularity.

use bytemuck::Zeroable;
use glam::{Mat4, Vec3};

use crate::gpu::GpuContext;
use crate::vpl::{frame_from_normal, Vpl};
use crate::{Error, Result};

use super::{
    shader_module, texture_entry, uniform_entry, FrameUniforms, GpuScene, Interleave, Vertex,
    INTERLEAVE_WGSL,
};

/// How VPL depth maps are parameterised.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VplMapKind {
    /// One paraboloid map over the VPL's hemisphere (Laine et al. 2007).
    Paraboloid,
    /// Six cube faces (faces behind the VPL are left empty).
    Cube,
}

impl VplMapKind {
    pub fn parse(s: &str) -> Result<VplMapKind> {
        match s {
            "paraboloid" => Ok(VplMapKind::Paraboloid),
            "cube" => Ok(VplMapKind::Cube),
            _ => Err(Error::param(
                "shadow-map",
                format!("expected paraboloid or cube (got '{s}')"),
            )),
        }
    }
}

/// Settings of the VPL shadow maps.
#[derive(Clone, Copy, Debug)]
pub struct VplShadowSettings {
    pub kind: VplMapKind,
    /// Edge of one map (cube: of one face), texels.
    pub size: u32,
    /// 16-bit (Laine) or 32-bit depth.
    pub depth_bits: u32,
    /// Most VPLs (slots) held at once.
    pub capacity: u32,
    /// Minimum VPL–receiver distance used in 1/r² (scene units).
    pub clamp_distance: f32,
    /// Depth bias as a fraction of the VPL–receiver distance.
    pub bias: f32,
}

/// GPU layout of `VplView` in vpl_shadow.wgsl.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ViewData {
    view_proj: [f32; 16],
    position: [f32; 4],
    tangent: [f32; 4],
    bitangent: [f32; 4],
    normal: [f32; 4],
}

/// GPU layout of `GpuVpl` in vpl_common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuVpl {
    position: [f32; 4],
    normal: [f32; 4],
    flux: [f32; 4],
    tangent: [f32; 4],
    bitangent: [f32; 4],
}

/// GPU layout of `VplParams` in vpl_common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ParamsData {
    counts: [u32; 4],
    distances: [f32; 4],
    cube_faces: [[f32; 16]; 6],
}

const VIEW_STRIDE: u64 = 256;

/// WGSL every VPL accumulation shader starts with (after [`INTERLEAVE_WGSL`]).
pub const VPL_COMMON_WGSL: &str = include_str!("shaders/vpl_common.wgsl");

/// The VPL depth atlas and the accumulation pass.
pub struct VplLighting {
    pub settings: VplShadowSettings,
    pub atlas: wgpu::Texture,
    atlas_view: wgpu::TextureView,
    /// Slots per atlas row.
    columns: u32,
    /// Size of one slot's block in the atlas (texels).
    block: (u32, u32),
    far: f32,
    near: f32,
    /// Maps are rendered from the VPL moved this far along its normal, so the surface the VPL
    /// lies on is behind the map and cannot occlude it.
    lift: f32,
    view_buffer: wgpu::Buffer,
    view_group: wgpu::BindGroup,
    map_pipeline: wgpu::RenderPipeline,
    clear_pipeline: wgpu::RenderPipeline,
    vpl_buffer: wgpu::Buffer,
    params_buffer: wgpu::Buffer,
    vpl_group: wgpu::BindGroup,
    accumulate_pipeline: wgpu::ComputePipeline,
}

fn depth_format(bits: u32) -> Result<wgpu::TextureFormat> {
    match bits {
        16 => Ok(wgpu::TextureFormat::Depth16Unorm),
        32 => Ok(wgpu::TextureFormat::Depth32Float),
        _ => Err(Error::param(
            "depth-bits",
            format!("expected 16 or 32 (got {bits})"),
        )),
    }
}

/// Projection × rotation of cube face `f` for an eye at the origin.
fn cube_face_rotation(f: usize, near: f32) -> Mat4 {
    super::cube_face_matrix(Vec3::ZERO, f, near)
}

impl VplLighting {
    pub fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        uniforms: &FrameUniforms,
        interleave: &Interleave,
        settings: VplShadowSettings,
    ) -> Result<VplLighting> {
        let device = &gpu.device;
        let format = depth_format(settings.depth_bits)?;
        if settings.capacity == 0 {
            return Err(Error::param("vpls", "at least one VPL is needed"));
        }
        if !(8..=4096).contains(&settings.size) {
            return Err(Error::param(
                "shadow-size",
                format!("expected 8..=4096 (got {})", settings.size),
            ));
        }
        let block = match settings.kind {
            VplMapKind::Paraboloid => (settings.size, settings.size),
            VplMapKind::Cube => (3 * settings.size, 2 * settings.size),
        };
        let max = gpu.max_texture_2d();
        let columns = (max / block.0).max(1).min(settings.capacity);
        let rows = settings.capacity.div_ceil(columns);
        if block.0 > max || rows * block.1 > max {
            return Err(Error::param(
                "shadow-size",
                format!(
                    "{} VPL maps of {}² do not fit in one {max}×{max} atlas (the adapter's limit); use fewer VPLs or smaller maps",
                    settings.capacity, settings.size
                ),
            ));
        }
        let atlas = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("vpl depth atlas"),
            size: wgpu::Extent3d {
                width: columns * block.0,
                height: rows * block.1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let atlas_view = atlas.create_view(&Default::default());
        let faces = if settings.kind == VplMapKind::Cube {
            6
        } else {
            1
        };
        let view_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("vpl views"),
            size: settings.capacity as u64 * faces * VIEW_STRIDE,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let view_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("vpl view"),
            entries: &[uniform_entry(0, wgpu::ShaderStages::VERTEX_FRAGMENT, true)],
        });
        let view_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("vpl views"),
            layout: &view_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &view_buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new(std::mem::size_of::<ViewData>() as u64),
                }),
            }],
        });
        let module = shader_module(
            device,
            "vpl shadow maps",
            include_str!("shaders/vpl_shadow.wgsl"),
        );
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("vpl shadow maps"),
            bind_group_layouts: &[Some(&view_layout), Some(&uniforms.object_layout)],
            immediate_size: 0,
        });
        let position_only = wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Vertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x3],
        };
        let depth_state = |compare| wgpu::DepthStencilState {
            format,
            depth_write_enabled: Some(true),
            depth_compare: Some(compare),
            stencil: Default::default(),
            bias: Default::default(),
        };
        let (vs, fs) = match settings.kind {
            VplMapKind::Paraboloid => ("vs_paraboloid", Some("fs_paraboloid")),
            VplMapKind::Cube => ("vs_cube", None),
        };
        let map_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("vpl shadow map"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some(vs),
                compilation_options: Default::default(),
                buffers: &[Some(position_only.clone())],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(depth_state(wgpu::CompareFunction::Greater)),
            multisample: Default::default(),
            fragment: fs.map(|entry| wgpu::FragmentState {
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                targets: &[],
            }),
            multiview_mask: None,
            cache: None,
        });
        let clear_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("vpl tile clear"),
            bind_group_layouts: &[],
            immediate_size: 0,
        });
        let clear_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("vpl tile clear"),
            layout: Some(&clear_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_clear"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(depth_state(wgpu::CompareFunction::Always)),
            multisample: Default::default(),
            fragment: None,
            multiview_mask: None,
            cache: None,
        });

        let vpl_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("vpls"),
            size: settings.capacity as u64 * std::mem::size_of::<GpuVpl>() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let params_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("vpl params"),
            size: std::mem::size_of::<ParamsData>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let cs = wgpu::ShaderStages::COMPUTE;
        let vpl_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("vpl lighting"),
            entries: &[
                uniform_entry(0, cs, false),
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: cs,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: true },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                texture_entry(
                    2,
                    cs,
                    wgpu::TextureSampleType::Float { filterable: false },
                    wgpu::TextureViewDimension::D2,
                ),
            ],
        });
        let vpl_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("vpl lighting"),
            layout: &vpl_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: params_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: vpl_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&atlas_view),
                },
            ],
        });
        let source = format!(
            "{INTERLEAVE_WGSL}\n{VPL_COMMON_WGSL}\n{}",
            include_str!("shaders/vpl_accumulate.wgsl")
        );
        let accumulate_module = shader_module(device, "vpl accumulate", &source);
        let accumulate_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("vpl accumulate"),
            bind_group_layouts: &[Some(interleave.split_layout()), Some(&vpl_layout)],
            immediate_size: 0,
        });
        let accumulate_pipeline =
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("vpl accumulate"),
                layout: Some(&accumulate_layout),
                module: &accumulate_module,
                entry_point: Some("accumulate"),
                compilation_options: Default::default(),
                cache: None,
            });
        let far = scene.diagonal() * 1.5;
        let near = scene.diagonal() * 1e-4;
        let lift = scene.diagonal() * 1e-3;
        gpu.check_errors()?;
        Ok(VplLighting {
            settings,
            atlas,
            atlas_view,
            columns,
            block,
            far,
            near,
            lift,
            view_buffer,
            view_group,
            map_pipeline,
            clear_pipeline,
            vpl_buffer,
            params_buffer,
            vpl_group,
            accumulate_pipeline,
        })
    }

    fn faces(&self) -> usize {
        if self.settings.kind == VplMapKind::Cube {
            6
        } else {
            1
        }
    }

    /// Uploads the view(s) of the VPL that will render into `slot`.
    pub fn write_view(&self, queue: &wgpu::Queue, slot: u32, vpl: &Vpl) {
        let (t, b) = frame_from_normal(vpl.normal);
        let eye = vpl.position + vpl.normal * self.lift;
        let faces = self.faces();
        let mut bytes = vec![0u8; faces * VIEW_STRIDE as usize];
        for f in 0..faces {
            let view_proj = if self.settings.kind == VplMapKind::Cube {
                super::cube_face_matrix(eye, f, self.near)
            } else {
                Mat4::IDENTITY
            };
            let d = ViewData {
                view_proj: view_proj.to_cols_array(),
                position: eye.extend(self.far).to_array(),
                tangent: t.extend(0.0).to_array(),
                bitangent: b.extend(0.0).to_array(),
                normal: vpl.normal.extend(0.0).to_array(),
            };
            let o = f * VIEW_STRIDE as usize;
            bytes[o..o + std::mem::size_of::<ViewData>()].copy_from_slice(bytemuck::bytes_of(&d));
        }
        queue.write_buffer(
            &self.view_buffer,
            slot as u64 * faces as u64 * VIEW_STRIDE,
            &bytes,
        );
    }

    /// Uploads the VPLs to accumulate, each with its shadow-map slot. The GPU list is indexed by
    /// slot (slots without a VPL get a zero-flux entry, skipped by the shader), so a VPL's tile
    /// is `slot mod T` for its whole life: incremental techniques do not reshuffle the
    /// interleaving pattern when other VPLs come and go.
    pub fn write_vpls(&self, queue: &wgpu::Queue, vpls: &[(u32, Vpl)]) {
        let n = vpls
            .iter()
            .map(|(slot, _)| *slot as usize + 1)
            .max()
            .unwrap_or(0)
            .min(self.settings.capacity as usize);
        let mut data = vec![GpuVpl::zeroed(); n];
        for (slot, v) in vpls.iter().filter(|(slot, _)| (*slot as usize) < n) {
            let (t, b) = frame_from_normal(v.normal);
            data[*slot as usize] = GpuVpl {
                position: v.position.extend(*slot as f32).to_array(),
                normal: v.normal.extend(0.0).to_array(),
                flux: v.flux.extend(0.0).to_array(),
                tangent: t.extend(self.lift).to_array(),
                bitangent: b.extend(0.0).to_array(),
            };
        }
        if !data.is_empty() {
            queue.write_buffer(&self.vpl_buffer, 0, bytemuck::cast_slice(&data));
        }
        let mut cube_faces = [[0f32; 16]; 6];
        for (f, m) in cube_faces.iter_mut().enumerate() {
            *m = cube_face_rotation(f, self.near).to_cols_array();
        }
        let params = ParamsData {
            counts: [
                n as u32,
                self.columns,
                self.settings.size,
                (self.settings.kind == VplMapKind::Cube) as u32,
            ],
            distances: [
                self.far,
                self.settings.clamp_distance,
                self.settings.bias,
                self.near,
            ],
            cube_faces,
        };
        queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&params));
    }

    /// Renders the maps of `slots` (their views must have been written). `clear_all` clears the
    /// whole atlas first; otherwise each rendered slot's block is cleared on its own and the
    /// other maps are kept. Returns the number of maps rendered.
    pub fn encode_shadow_maps(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        uniforms: &FrameUniforms,
        slots: &[u32],
        clear_all: bool,
    ) -> u32 {
        let load = if clear_all {
            wgpu::LoadOp::Clear(0.0)
        } else {
            wgpu::LoadOp::Load
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("vpl shadow maps"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.atlas_view,
                depth_ops: Some(wgpu::Operations {
                    load,
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let s = self.settings.size;
        let faces = self.faces() as u32;
        for &slot in slots {
            let origin = (
                (slot % self.columns) * self.block.0,
                (slot / self.columns) * self.block.1,
            );
            if !clear_all {
                pass.set_viewport(
                    origin.0 as f32,
                    origin.1 as f32,
                    self.block.0 as f32,
                    self.block.1 as f32,
                    0.0,
                    1.0,
                );
                pass.set_scissor_rect(origin.0, origin.1, self.block.0, self.block.1);
                pass.set_pipeline(&self.clear_pipeline);
                pass.draw(0..3, 0..1);
            }
            pass.set_pipeline(&self.map_pipeline);
            for f in 0..faces {
                let (x, y) = (origin.0 + (f % 3) * s, origin.1 + (f / 3) * s);
                pass.set_viewport(x as f32, y as f32, s as f32, s as f32, 0.0, 1.0);
                pass.set_scissor_rect(x, y, s, s);
                let offset = ((slot * faces + f) as u64 * VIEW_STRIDE) as u32;
                pass.set_bind_group(0, &self.view_group, &[offset]);
                scene.draw_static_casters(&mut pass, uniforms, 1);
            }
        }
        slots.len() as u32
    }

    /// Records the accumulation over the split G-buffer.
    pub fn encode_accumulate(&self, encoder: &mut wgpu::CommandEncoder, interleave: &Interleave) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("accumulate"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.accumulate_pipeline);
        pass.set_bind_group(0, interleave.split_group(), &[]);
        pass.set_bind_group(1, &self.vpl_group, &[]);
        interleave.dispatch_split_size(&mut pass);
    }
}
