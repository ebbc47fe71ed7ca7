//! The scene on the GPU and the per-frame uniforms every pass shares.

use glam::{Mat4, Vec3, Vec4};
use wgpu::util::DeviceExt;

use crate::anim::{FrameState, LightPose};
use crate::scene::descriptor::LightKind;
use crate::scene::{Mesh, Scene, Texture};
use crate::{Error, Result};

use super::{texture_entry, uniform_entry};

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
    /// Scene bounds (static mesh).
    pub bounds: (Vec3, Vec3),
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
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: fs,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let material_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("materials"),
            layout: &material_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: material_buffer.as_entire_binding(),
                },
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
            bounds: scene.mesh.bounds(),
        })
    }

    /// Number of object slots (static mesh + movers).
    pub fn object_count(&self) -> usize {
        1 + self.movers.len()
    }

    /// Length of the scene's bounding-box diagonal.
    pub fn diagonal(&self) -> f32 {
        (self.bounds.1 - self.bounds.0).length().max(1e-6)
    }

    /// Draws every object: the static mesh (or its shadow-caster copy when `shadow_casters`)
    /// and the movers, binding each one's object uniforms at `object_group_index`.
    /// Draws only the static geometry's shadow-caster copy (object slot 0): what VPL shadow
    /// maps hold, since they are reused across frames and indirect light bounces off static
    /// geometry only (Laine et al. 2007, Section 7).
    pub fn draw_static_casters(
        &self,
        pass: &mut wgpu::RenderPass,
        uniforms: &FrameUniforms,
        object_group_index: u32,
    ) {
        let mesh = self.shadow_mesh.as_ref().unwrap_or(&self.static_mesh);
        pass.set_bind_group(
            object_group_index,
            &uniforms.object_group,
            &[uniforms.object_offset(0)],
        );
        pass.set_vertex_buffer(0, mesh.vertices.slice(..));
        pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..mesh.index_count, 0, 0..1);
    }

    pub fn draw(
        &self,
        pass: &mut wgpu::RenderPass,
        uniforms: &FrameUniforms,
        object_group_index: u32,
        shadow_casters: bool,
    ) {
        let statics = if shadow_casters {
            self.shadow_mesh.as_ref().unwrap_or(&self.static_mesh)
        } else {
            &self.static_mesh
        };
        for (slot, mesh) in std::iter::once(statics)
            .chain(self.movers.iter())
            .enumerate()
        {
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
    pub view_buffer: wgpu::Buffer,
    pub view_layout: wgpu::BindGroupLayout,
    /// The view uniforms with a dynamic offset (`view_offset(slot)`).
    pub view_group: wgpu::BindGroup,
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
}

/// View-projection of cube face `face` (+X, −X, +Y, −Y, +Z, −Z) around `eye`, reversed-Z.
pub fn cube_face_matrix(eye: Vec3, face: usize, near: f32) -> Mat4 {
    let (dir, up) = super::CUBE_FACES[face];
    crate::anim::perspective_reverse_z(std::f32::consts::FRAC_PI_2, 1.0, near)
        * crate::anim::look_at(eye, eye + dir, up)
}

/// On-axis radiant intensity of the primary light (see the harness's radiometric convention).
pub fn light_axis_intensity(light: &LightPose) -> Vec3 {
    match light.kind {
        LightKind::Omni => light.power / (4.0 * std::f32::consts::PI),
        LightKind::Spot | LightKind::Area => light.power / std::f32::consts::PI,
    }
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
        let view_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("views"),
            size: 7 * SLOT,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let view_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("view"),
            entries: &[uniform_entry(0, all, true)],
        });
        let view_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("views"),
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
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        FrameUniforms {
            view_buffer,
            view_layout,
            view_group,
            object_buffer,
            object_layout,
            object_group,
            light_buffer,
            resolution,
            objects,
            shadow_near: scene.diagonal() * 1e-3,
            shadow_size,
            shadow_bias,
        }
    }

    /// Dynamic offset of view slot `slot` (0 camera, 1 + f cube face f).
    pub fn view_offset(&self, slot: usize) -> u32 {
        (slot as u64 * SLOT) as u32
    }
    /// Dynamic offset of object slot `slot` (0 static mesh, 1 + i mover i).
    pub fn object_offset(&self, slot: usize) -> u32 {
        (slot as u64 * SLOT) as u32
    }
    /// The camera's uniform range, for bind groups that take it without a dynamic offset.
    pub fn camera_binding(&self) -> wgpu::BindingResource<'_> {
        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer: &self.view_buffer,
            offset: 0,
            size: wgpu::BufferSize::new(std::mem::size_of::<ViewData>() as u64),
        })
    }

    /// The camera's view-projection for `frame`.
    pub fn camera_view_proj(&self, frame: &FrameState) -> Mat4 {
        let aspect = self.resolution[0] as f32 / self.resolution[1] as f32;
        frame.camera.projection(aspect) * frame.camera.view()
    }

    /// Uploads this frame's camera, cube faces, object transforms and light.
    pub fn write(&self, queue: &wgpu::Queue, frame: &FrameState) {
        let mut views = vec![0u8; 7 * SLOT as usize];
        let vp = self.camera_view_proj(frame);
        let [w, h] = self.resolution;
        let mut put_view = |slot: usize, m: Mat4, eye: Vec3, near: f32, size: [f32; 2]| {
            let d = ViewData {
                view_proj: m.to_cols_array(),
                inv_view_proj: m.inverse().to_cols_array(),
                eye: eye.extend(1.0).to_array(),
                params: [size[0], size[1], near, 0.0],
            };
            let o = slot * SLOT as usize;
            views[o..o + std::mem::size_of::<ViewData>()].copy_from_slice(bytemuck::bytes_of(&d));
        };
        put_view(
            CAMERA_SLOT,
            vp,
            frame.camera.position,
            frame.camera.near,
            [w as f32, h as f32],
        );
        let light = &frame.light;
        let mut faces = [[0f32; 16]; 6];
        for (f, face) in faces.iter_mut().enumerate() {
            let m = cube_face_matrix(light.position, f, self.shadow_near);
            *face = m.to_cols_array();
            let s = self.shadow_size as f32;
            put_view(1 + f, m, light.position, self.shadow_near, [s, s]);
        }
        queue.write_buffer(&self.view_buffer, 0, &views);

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

        let kind = match light.kind {
            LightKind::Spot => 0.0,
            LightKind::Omni => 1.0,
            LightKind::Area => 2.0,
        };
        let data = LightData {
            position: light.position.extend(kind).to_array(),
            direction: light.direction.extend(0.0).to_array(),
            intensity: light_axis_intensity(light).extend(0.0).to_array(),
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
