//! The scene on the GPU and the per-frame uniforms every pass shares.

use glam::{Mat4, Vec3, Vec4};
use wgpu::util::DeviceExt;

use crate::scene::anim::{FrameState, LightPose};
use crate::scene::{Mesh, Scene, SceneExtent, Texture};
use crate::{Error, Result};

use super::{bind_buffer, sampler_entry, texture_entry, uniform_entry};

/// Most materials a scene may have (they live in one uniform array).
pub const MAX_MATERIALS: usize = 1024;
/// Uniform slots are this far apart (the largest minimum dynamic-offset alignment in practice).
const SLOT: u64 = 256;
/// Edge length every texture is resampled to in the texture array.
const TEXTURE_SIZE: u32 = 512;

/// One vertex as the GPU sees it.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub uv: [f32; 2],
    pub material: u32,
}

impl Vertex {
    /// The vertex buffer layout matching `geometry.wgsl`.
    pub const LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Uint32],
    };
}

/// A mesh's vertex and index buffers.
pub struct GpuMesh {
    pub vertices: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub index_count: u32,
}

impl GpuMesh {
    pub fn new(device: &wgpu::Device, label: &str, mesh: &Mesh) -> GpuMesh {
        let verts: Vec<Vertex> = (0..mesh.positions.len())
            .map(|i| Vertex {
                position: mesh.positions[i].to_array(),
                normal: mesh.normals[i].to_array(),
                uv: mesh.uvs.get(i).map(|u| u.to_array()).unwrap_or([0.0; 2]),
                material: mesh.materials[i],
            })
            .collect();
        GpuMesh {
            vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytemuck::cast_slice(&verts),
                usage: wgpu::BufferUsages::VERTEX,
            }),
            indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytemuck::cast_slice(&mesh.indices),
                usage: wgpu::BufferUsages::INDEX,
            }),
            index_count: mesh.indices.len() as u32,
        }
    }
}

/// Meshes, materials and textures of a scene, uploaded once.
pub struct GpuScene {
    /// The static mesh (object slot 0).
    pub static_mesh: GpuMesh,
    /// The shadow-caster copy of the static mesh (tessellated when the scene has one).
    pub shadow_mesh: Option<GpuMesh>,
    /// Movers (object slot i + 1).
    pub movers: Vec<GpuMesh>,
    pub material_layout: wgpu::BindGroupLayout,
    pub material_group: wgpu::BindGroup,
    /// Bounds, diagonal and bounding sphere of the static mesh.
    pub extent: SceneExtent,
}

fn srgb_texel_bilinear(t: &Texture, u: f32, v: f32) -> [f32; 4] {
    let x = (u * t.width as f32 - 0.5).clamp(0.0, (t.width - 1) as f32);
    let y = (v * t.height as f32 - 0.5).clamp(0.0, (t.height - 1) as f32);
    let (x0, y0) = (x.floor() as u32, y.floor() as u32);
    let (x1, y1) = ((x0 + 1).min(t.width - 1), (y0 + 1).min(t.height - 1));
    let (fx, fy) = (x - x0 as f32, y - y0 as f32);
    let at = |x: u32, y: u32, c: usize| t.rgba8[((y * t.width + x) * 4) as usize + c] as f32;
    let mut out = [0.0; 4];
    for (c, o) in out.iter_mut().enumerate() {
        let top = at(x0, y0, c) * (1.0 - fx) + at(x1, y0, c) * fx;
        let bottom = at(x0, y1, c) * (1.0 - fx) + at(x1, y1, c) * fx;
        *o = top * (1.0 - fy) + bottom * fy;
    }
    out
}

/// Resamples every texture to `TEXTURE_SIZE`² and builds the full mip chain (box filter).
fn texture_array_data(textures: &[Texture]) -> (u32, u32, Vec<u8>) {
    let size = TEXTURE_SIZE;
    let mips = size.ilog2() + 1;
    let layers = textures.len().max(1) as u32;
    let mut data = Vec::new();
    for layer in 0..layers as usize {
        let mut level: Vec<u8> = match textures.get(layer) {
            Some(t)
                if t.width > 0
                    && t.height > 0
                    && t.rgba8.len() >= (t.width * t.height * 4) as usize =>
            {
                (0..size * size)
                    .flat_map(|i| {
                        let (x, y) = (i % size, i / size);
                        let c = srgb_texel_bilinear(
                            t,
                            (x as f32 + 0.5) / size as f32,
                            (y as f32 + 0.5) / size as f32,
                        );
                        c.map(|v| v.round().clamp(0.0, 255.0) as u8)
                    })
                    .collect()
            }
            _ => vec![255; (size * size * 4) as usize],
        };
        let mut s = size;
        loop {
            data.extend_from_slice(&level);
            if s == 1 {
                break;
            }
            let n = s / 2;
            let mut next = vec![0u8; (n * n * 4) as usize];
            for y in 0..n {
                for x in 0..n {
                    for c in 0..4 {
                        let at = |xx: u32, yy: u32| level[((yy * s + xx) * 4 + c) as usize] as u32;
                        let sum = at(2 * x, 2 * y)
                            + at(2 * x + 1, 2 * y)
                            + at(2 * x, 2 * y + 1)
                            + at(2 * x + 1, 2 * y + 1);
                        next[((y * n + x) * 4 + c) as usize] = ((sum + 2) / 4) as u8;
                    }
                }
            }
            level = next;
            s = n;
        }
    }
    (layers, mips, data)
}

impl GpuScene {
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, scene: &Scene) -> Result<GpuScene> {
        if scene.materials.len() > MAX_MATERIALS {
            return Err(Error::Invalid(format!(
                "scene '{}' has {} materials; gibench supports at most {MAX_MATERIALS}",
                scene.descriptor.name,
                scene.materials.len()
            )));
        }
        let mut mats = vec![[0f32; 4]; MAX_MATERIALS];
        for (i, m) in scene.materials.iter().enumerate() {
            let layer = m.texture.map(|t| t as f32).unwrap_or(-1.0);
            mats[i] = [m.base_color.x, m.base_color.y, m.base_color.z, layer];
        }
        let material_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("materials"),
            contents: bytemuck::cast_slice(&mats),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let (layers, mips, data) = texture_array_data(&scene.textures);
        let texture = device.create_texture_with_data(
            queue,
            &wgpu::TextureDescriptor {
                label: Some("scene textures"),
                size: wgpu::Extent3d {
                    width: TEXTURE_SIZE,
                    height: TEXTURE_SIZE,
                    depth_or_array_layers: layers,
                },
                mip_level_count: mips,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba8UnormSrgb,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            &data,
        );
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("scene textures"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let fs = wgpu::ShaderStages::FRAGMENT;
        let material_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("materials"),
            entries: &[
                uniform_entry(0, fs, false),
                texture_entry(
                    1,
                    fs,
                    wgpu::TextureSampleType::Float { filterable: true },
                    wgpu::TextureViewDimension::D2Array,
                ),
                sampler_entry(2, fs, wgpu::SamplerBindingType::Filtering),
            ],
        });
        let material_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("materials"),
            layout: &material_layout,
            entries: &[
                bind_buffer(0, &material_buffer),
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(&sampler),
                },
            ],
        });
        Ok(GpuScene {
            static_mesh: GpuMesh::new(device, "static mesh", &scene.mesh),
            shadow_mesh: scene
                .shadow_mesh
                .as_ref()
                .map(|m| GpuMesh::new(device, "shadow mesh", m)),
            movers: scene
                .movers
                .iter()
                .map(|m| GpuMesh::new(device, &m.name, &m.mesh))
                .collect(),
            material_layout,
            material_group,
            extent: scene.extent,
        })
    }

    /// Number of object slots (static mesh + movers).
    pub fn object_count(&self) -> usize {
        1 + self.movers.len()
    }

    /// Length of the scene's bounding-box diagonal.
    pub fn diagonal(&self) -> f32 {
        self.extent.diagonal
    }

    /// Draws `set` (see [`DrawSet`]), binding each object's uniforms (from `uniforms`) at bind
    /// group `object_group_index` with its dynamic offset; the caller binds everything else.
    pub fn draw(
        &self,
        pass: &mut wgpu::RenderPass,
        uniforms: &FrameUniforms,
        object_group_index: u32,
        set: DrawSet,
    ) {
        for (slot, mesh) in self.meshes(set).enumerate() {
            pass.set_bind_group(
                object_group_index,
                &uniforms.object_group,
                &[uniforms.object_offset(slot)],
            );
            pass.set_vertex_buffer(0, mesh.vertices.slice(..));
            pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..mesh.index_count, 0, 0..1);
        }
    }
}

/// What a scene draw includes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DrawSet {
    /// The static mesh's shadow-caster copy (tessellated where the scene has one) only: what VPL
    /// maps reused across frames hold (indirect light bounces off static geometry only; Laine
    /// et al. 2007 §7).
    StaticCasters,
    /// The static mesh only.
    Static,
    /// The static mesh and every mover (the camera view, the direct light's shadow map).
    StaticAndMovers,
    /// The shadow-caster copy and every mover: VPL maps rendered anew every frame with the
    /// movers in them (`ism-classic`).
    CastersAndMovers,
}

/// A view for drawing the scene: the `View` uniform of `common.wgsl`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// World → clip (reversed Z).
    pub view_proj: Mat4,
    /// Eye position.
    pub eye: Vec3,
    /// Target size in pixels.
    pub size: [f32; 2],
    /// Near plane (0 for orthographic views).
    pub near: f32,
}

/// A set of [`View`] uniforms in one buffer, each bound with a dynamic offset; the harness's
/// camera and light views are one, and a technique may own others (e.g. orthographic views).
/// Written with `queue.write_buffer`; never re-created.
pub struct ViewSet {
    buffer: wgpu::Buffer,
    group: wgpu::BindGroup,
    count: usize,
}

impl ViewSet {
    /// `count` views bound through `layout` ([`FrameUniforms::view_layout`], which every
    /// scene pipeline uses at group 0).
    pub fn new(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        count: usize,
        label: &str,
    ) -> ViewSet {
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: count.max(1) as u64 * SLOT,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new(std::mem::size_of::<ViewData>() as u64),
                }),
            }],
        });
        ViewSet {
            buffer,
            group,
            count,
        }
    }

    /// Number of views.
    pub fn len(&self) -> usize {
        self.count
    }
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Uploads `views` into slots 0.. (at most [`ViewSet::len`]).
    pub fn write(&self, queue: &wgpu::Queue, views: &[View]) {
        let n = views.len().min(self.count);
        let mut bytes = vec![0u8; n * SLOT as usize];
        for (slot, v) in views[..n].iter().enumerate() {
            let d = ViewData {
                view_proj: v.view_proj.to_cols_array(),
                inv_view_proj: v.view_proj.inverse().to_cols_array(),
                eye: v.eye.extend(1.0).to_array(),
                params: [v.size[0], v.size[1], v.near, 0.0],
            };
            let o = slot * SLOT as usize;
            bytes[o..o + std::mem::size_of::<ViewData>()].copy_from_slice(bytemuck::bytes_of(&d));
        }
        queue.write_buffer(&self.buffer, 0, &bytes);
    }

    /// The bind group; bind it with [`ViewSet::offset`] of the view to use.
    pub fn group(&self) -> &wgpu::BindGroup {
        &self.group
    }

    /// Dynamic offset of view `slot`.
    pub fn offset(&self, slot: usize) -> u32 {
        (slot as u64 * SLOT) as u32
    }

    /// View `slot`'s uniform range, for bind groups that take it without a dynamic offset.
    pub fn binding(&self, slot: usize) -> wgpu::BindingResource<'_> {
        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer: &self.buffer,
            offset: slot as u64 * SLOT,
            size: wgpu::BufferSize::new(std::mem::size_of::<ViewData>() as u64),
        })
    }
}

/// GPU layout of `View` in `common.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ViewData {
    view_proj: [f32; 16],
    inv_view_proj: [f32; 16],
    eye: [f32; 4],
    params: [f32; 4],
}

/// GPU layout of `Light` in `common.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct LightData {
    position: [f32; 4],
    direction: [f32; 4],
    intensity: [f32; 4],
    shadow: [f32; 4],
    faces: [[f32; 16]; 6],
}

/// View slots: 0 = camera, 1..=6 = the primary light's cube faces.
pub const CAMERA_SLOT: usize = 0;

/// Per-frame uniforms shared by all passes: views (camera and cube faces), object transforms
/// and the primary light. Written with `queue.write_buffer` each frame; never re-created.
pub struct FrameUniforms {
    /// Layout of a [`ViewSet`] (one `View` uniform, dynamic offset): group 0 of every scene
    /// pipeline.
    pub view_layout: wgpu::BindGroupLayout,
    /// Slot [`CAMERA_SLOT`]: the camera; 1..=6: the primary light's cube faces (the sun: its
    /// orthographic view in slot 1).
    pub views: ViewSet,
    pub object_buffer: wgpu::Buffer,
    pub object_layout: wgpu::BindGroupLayout,
    pub object_group: wgpu::BindGroup,
    pub light_buffer: wgpu::Buffer,
    pub resolution: [u32; 2],
    objects: usize,
    /// Near plane of the cube shadow-map faces.
    pub shadow_near: f32,
    /// Shadow-map size and PCF settings written into the light uniform.
    pub shadow_size: u32,
    pub shadow_bias: f32,
    /// The scene's extent (the sun's orthographic map covers its bounding sphere).
    extent: SceneExtent,
}

/// View-projection of cube face `face` (+X, −X, +Y, −Y, +Z, −Z) around `eye`, reversed-Z.
pub fn cube_face_matrix(eye: Vec3, face: usize, near: f32) -> Mat4 {
    let (dir, up) = super::CUBE_FACES[face];
    crate::scene::anim::perspective_reverse_z(std::f32::consts::FRAC_PI_2, 1.0, near)
        * crate::scene::anim::look_at(eye, eye + dir, up)
}

/// The sun's shadow view: an orthographic, reversed-Z view-projection along the light's axis
/// that covers the scene's bounding sphere (depth 1 at the sun's disc, 0 a diameter further).
pub fn sun_view_matrix(light: &LightPose, extent: &SceneExtent) -> Mat4 {
    let (eye, r) = light.sun_disc(extent);
    let axis = light.axis();
    let up = if axis.y.abs() > 0.999 {
        Vec3::Z
    } else {
        Vec3::Y
    };
    // The disc sits 2r upstream of the centre; depth covers [r, 3r] along the axis.
    let proj = Mat4::from_cols(
        Vec4::new(1.0 / r, 0.0, 0.0, 0.0),
        Vec4::new(0.0, 1.0 / r, 0.0, 0.0),
        Vec4::new(0.0, 0.0, 0.5 / r, 0.0),
        Vec4::new(0.0, 0.0, 1.5, 1.0),
    );
    proj * crate::scene::anim::look_at(eye, eye + axis, up)
}

impl FrameUniforms {
    pub fn new(
        device: &wgpu::Device,
        scene: &GpuScene,
        resolution: [u32; 2],
        shadow_size: u32,
        shadow_bias: f32,
    ) -> FrameUniforms {
        let objects = scene.object_count();
        let all = wgpu::ShaderStages::VERTEX_FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let view_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("view"),
            entries: &[uniform_entry(0, all, true)],
        });
        let views = ViewSet::new(device, &view_layout, 7, "views");
        let object_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("objects"),
            size: objects as u64 * SLOT,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let object_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("object"),
            entries: &[uniform_entry(0, wgpu::ShaderStages::VERTEX, true)],
        });
        let object_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("objects"),
            layout: &object_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &object_buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new(128),
                }),
            }],
        });
        let light_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("light"),
            size: std::mem::size_of::<LightData>() as u64,
            usage: super::PARAMS_USAGE,
            mapped_at_creation: false,
        });
        FrameUniforms {
            view_layout,
            views,
            object_buffer,
            object_layout,
            object_group,
            light_buffer,
            resolution,
            objects,
            shadow_near: scene.diagonal() * 1e-3,
            shadow_size,
            shadow_bias,
            extent: scene.extent,
        }
    }

    /// Dynamic offset of object slot `slot` (0 static mesh, 1 + i mover i).
    pub fn object_offset(&self, slot: usize) -> u32 {
        (slot as u64 * SLOT) as u32
    }
    /// The camera's uniform range, for bind groups that take it without a dynamic offset.
    pub fn camera_binding(&self) -> wgpu::BindingResource<'_> {
        self.views.binding(CAMERA_SLOT)
    }

    /// The camera's view-projection for `frame`.
    pub fn camera_view_proj(&self, frame: &FrameState) -> Mat4 {
        let aspect = self.resolution[0] as f32 / self.resolution[1] as f32;
        frame.camera.projection(aspect) * frame.camera.view()
    }

    /// Uploads this frame's camera, cube faces, object transforms and light.
    pub fn write(&self, queue: &wgpu::Queue, frame: &FrameState) {
        let [w, h] = self.resolution;
        let mut views = vec![View {
            view_proj: self.camera_view_proj(frame),
            eye: frame.camera.position,
            size: [w as f32, h as f32],
            near: frame.camera.near,
        }];
        let light = &frame.light;
        let mut faces = [[0f32; 16]; 6];
        let s = self.shadow_size as f32;
        if light.is_directional() {
            // The sun: one orthographic map in face 0's place.
            let m = sun_view_matrix(light, &self.extent);
            faces[0] = m.to_cols_array();
            views.push(View {
                view_proj: m,
                eye: light.sun_disc(&self.extent).0,
                size: [s, s],
                near: 0.0,
            });
        } else {
            for (f, face) in faces.iter_mut().enumerate() {
                let m = cube_face_matrix(light.position, f, self.shadow_near);
                *face = m.to_cols_array();
                views.push(View {
                    view_proj: m,
                    eye: light.position,
                    size: [s, s],
                    near: self.shadow_near,
                });
            }
        }
        self.views.write(queue, &views);

        let mut objects = vec![0u8; self.objects * SLOT as usize];
        for slot in 0..self.objects {
            let model = if slot == 0 {
                Mat4::IDENTITY
            } else {
                frame
                    .movers
                    .get(slot - 1)
                    .copied()
                    .unwrap_or(Mat4::IDENTITY)
            };
            let normal = model.inverse().transpose();
            let o = slot * SLOT as usize;
            objects[o..o + 64].copy_from_slice(bytemuck::cast_slice(&model.to_cols_array()));
            objects[o + 64..o + 128].copy_from_slice(bytemuck::cast_slice(&normal.to_cols_array()));
        }
        queue.write_buffer(&self.object_buffer, 0, &objects);

        let position = if light.is_directional() {
            light.sun_disc(&self.extent).0
        } else {
            light.position
        };
        let data = LightData {
            position: position
                .extend(crate::cpu::light::gpu_kind(light.kind))
                .to_array(),
            direction: light
                .axis()
                .extend(light.sun_disc(&self.extent).1)
                .to_array(),
            intensity: light.axis_intensity().extend(0.0).to_array(),
            shadow: Vec4::new(
                self.shadow_size as f32,
                self.shadow_bias,
                self.shadow_near,
                4.0,
            )
            .to_array(),
            faces,
        };
        queue.write_buffer(&self.light_buffer, 0, bytemuck::bytes_of(&data));
    }
}

impl GpuScene {
    /// The meshes `set` draws, in object-slot order: the static mesh (or its shadow-caster
    /// copy), then the movers if the set has them.
    pub fn meshes(&self, set: DrawSet) -> impl Iterator<Item = &GpuMesh> {
        let statics = match set {
            DrawSet::StaticCasters | DrawSet::CastersAndMovers => {
                self.shadow_mesh.as_ref().unwrap_or(&self.static_mesh)
            }
            DrawSet::Static | DrawSet::StaticAndMovers => &self.static_mesh,
        };
        let movers = if matches!(set, DrawSet::StaticAndMovers | DrawSet::CastersAndMovers) {
            &self.movers[..]
        } else {
            &[]
        };
        std::iter::once(statics).chain(movers.iter())
    }

    /// The least cost of drawing `set` once into a depth-only map (a shadow map), for the
    /// roofline ([`crate::measure::roofline`]): every vertex's position (12 bytes; the normal,
    /// texture coordinates and material a depth map does not need are not counted) and every
    /// index read once, and every vertex moved into the map's space, a 4×4 matrix times a point
    /// (16 FMAs, 32 operations). The caller adds the depth texels it writes.
    pub fn depth_draw_cost(&self, set: DrawSet) -> crate::measure::roofline::StageCost {
        let vertex = std::mem::size_of::<Vertex>() as u64;
        let (mut indices, mut vertices) = (0, 0);
        for m in self.meshes(set) {
            indices += m.indices.size();
            vertices += m.vertices.size() / vertex;
        }
        crate::measure::roofline::StageCost {
            bytes_read: (indices + vertices * 12) as f64,
            bytes_written: 0.0,
            ops: (vertices * 32) as f64,
        }
    }

    /// The least cost of drawing the scene's meshes (static and movers) once, for the roofline
    /// ([`crate::measure::roofline`]): every vertex and index read once (the meshes' buffers, bytes), and
    /// every vertex moved to clip space, a 4×4 matrix times a point (16 FMAs, 32 operations).
    /// What a rasterising stage must do at least; it adds what it writes.
    pub fn draw_cost(&self) -> crate::measure::roofline::StageCost {
        let vertex = std::mem::size_of::<Vertex>() as u64;
        let (mut bytes, mut vertices) = (0, 0);
        for m in std::iter::once(&self.static_mesh).chain(&self.movers) {
            bytes += m.vertices.size() + m.indices.size();
            vertices += m.vertices.size() / vertex;
        }
        crate::measure::roofline::StageCost {
            bytes_read: bytes as f64,
            bytes_written: 0.0,
            ops: (vertices * 32) as f64,
        }
    }
}
