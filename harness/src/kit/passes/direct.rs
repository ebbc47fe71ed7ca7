//! Direct illumination from the primary light: a cube shadow map around the light (as Laine et
//! al. 2007 use for both spot and omni lights) and a fullscreen pass computing direct irradiance
//! with a 16-tap percentage-closer filter.
//!
//! Shadow-map stage — reads: scene meshes, cube-face views, object transforms; writes: the
//! shadow map (one Depth32Float atlas of 3×2 faces, reversed Z; an atlas rather than a cube or
//! array texture because depth arrays read back as zero on GL). Faces a spot light cannot reach
//! (entirely behind its hemisphere) are skipped.
//!
//! Lighting stage — reads: G-buffer, light uniform, shadow map; writes: `irradiance`
//! (Rgba16Float, direct irradiance E = I(ω) cos θ / r² × visibility).

use glam::Vec3;

use crate::gpu::GpuContext;
use crate::scene::anim::LightPose;
use crate::scene::descriptor::LightKind;

use super::gbuffer::{scene_pipeline, DEPTH_FORMAT};
use super::{
    bind_buffer, draw_fullscreen, fullscreen_pipeline, params_entry, render_target, shader_module,
    texture_entry,
};
use super::{FrameUniforms, GBuffer, GpuScene, HDR_FORMAT};

/// Cube faces as (view direction, up), in the order +X, −X, +Y, −Y, +Z, −Z.
pub const CUBE_FACES: [(Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::NEG_Y),
    (Vec3::NEG_X, Vec3::NEG_Y),
    (Vec3::Y, Vec3::Z),
    (Vec3::NEG_Y, Vec3::NEG_Z),
    (Vec3::Z, Vec3::NEG_Y),
    (Vec3::NEG_Z, Vec3::NEG_Y),
];

/// Which cube faces can receive light: all six for omni lights; for spot and area lights only
/// those whose frustum reaches into the lit hemisphere (a corner direction with a positive
/// component along the light's axis).
pub fn needed_cube_faces(light: &LightPose) -> [bool; 6] {
    match light.kind {
        LightKind::Omni => return [true; 6],
        // The sun's one orthographic map sits in face 0's place.
        LightKind::Sun => return [true, false, false, false, false, false],
        _ => {}
    }
    let mut out = [false; 6];
    for (f, (dir, up)) in CUBE_FACES.iter().enumerate() {
        let right = dir.cross(*up);
        out[f] = [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)]
            .iter()
            .any(|(a, b)| (*dir + right * *a + *up * *b).dot(light.direction) > 1e-6);
    }
    out
}

/// The direct-light passes and their targets.
pub struct DirectLight {
    pub shadow_map: wgpu::Texture,
    atlas_view: wgpu::TextureView,
    face_size: u32,
    depth_pipeline: wgpu::RenderPipeline,
    light_pipeline: wgpu::RenderPipeline,
    /// Binding 0: the `Light` uniform; binding 1: the shadow atlas (unfilterable float, 2D);
    /// visible to fragment and compute shaders. Bind [`DirectLight::light_group`] with it.
    pub light_layout: wgpu::BindGroupLayout,
    pub light_group: wgpu::BindGroup,
    /// Direct irradiance (Rgba16Float).
    pub irradiance: wgpu::Texture,
    pub irradiance_view: wgpu::TextureView,
}

/// Draws the scene (static meshes and movers) into faces `faces` of a 3x2 atlas of
/// `size`² faces, each with the light's view for that face (view slots 1..=6; the sun's one
/// map is face 0), with the pass's pipeline already set. Returns the faces drawn. The direct
/// shadow map and the reflective shadow map share it.
pub fn draw_light_faces(
    pass: &mut wgpu::RenderPass,
    scene: &GpuScene,
    uniforms: &FrameUniforms,
    size: u32,
    faces: impl Iterator<Item = usize>,
) -> u32 {
    pass.set_bind_group(2, &scene.material_group, &[]);
    let mut rendered = 0;
    for f in faces {
        let (x, y) = ((f as u32 % 3) * size, (f as u32 / 3) * size);
        pass.set_viewport(x as f32, y as f32, size as f32, size as f32, 0.0, 1.0);
        pass.set_scissor_rect(x, y, size, size);
        pass.set_bind_group(0, uniforms.views.group(), &[uniforms.views.offset(1 + f)]);
        scene.draw(pass, uniforms, 1, super::DrawSet::StaticAndMovers);
        rendered += 1;
    }
    rendered
}

impl DirectLight {
    pub fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        uniforms: &FrameUniforms,
        gbuffer: &GBuffer,
    ) -> DirectLight {
        let device = &gpu.device;
        let s = uniforms.shadow_size;
        let shadow_map = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("direct shadow cube"),
            size: wgpu::Extent3d {
                width: 3 * s,
                height: 2 * s,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let atlas_view = shadow_map.create_view(&Default::default());
        let depth_pipeline = scene_pipeline(
            device,
            "direct shadow map",
            scene,
            uniforms,
            "vs_depth",
            None,
        );
        let fs = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let light_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("light"),
            entries: &[
                params_entry(0, fs),
                texture_entry(
                    1,
                    fs,
                    wgpu::TextureSampleType::Float { filterable: false },
                    wgpu::TextureViewDimension::D2,
                ),
            ],
        });
        let light_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("light"),
            layout: &light_layout,
            entries: &[
                bind_buffer(0, &uniforms.light_buffer),
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&atlas_view),
                },
            ],
        });
        let source = format!(
            "{}\n{}",
            DirectLight::wgsl(1),
            include_str!("shaders/direct.wgsl")
        );
        let module = shader_module(device, "direct light", &source);
        let light_pipeline = fullscreen_pipeline(
            device,
            "direct light",
            &module,
            &[&gbuffer.read_layout, &light_layout],
            &[HDR_FORMAT],
        );
        let irradiance = render_target(device, "direct irradiance", gbuffer.size, HDR_FORMAT);
        let irradiance_view = irradiance.create_view(&Default::default());
        DirectLight {
            shadow_map,
            atlas_view,
            face_size: s,
            depth_pipeline,
            light_pipeline,
            light_layout,
            light_group,
            irradiance,
            irradiance_view,
        }
    }

    /// The direct light for a technique's shader that binds [`DirectLight::light_group`] at
    /// `group`: the bindings `light` and `direct_shadow_map` beside the import of `gibench::direct_light`
    /// (`direct_shadow(p, n)`, `direct_irradiance(p, n)`); composed anywhere in the shader.
    pub fn wgsl(group: u32) -> String {
        format!(
            "#import gibench::direct_light\n\
             @group({group}) @binding(0) var<storage, read> light: Light;\n\
             @group({group}) @binding(1) var direct_shadow_map: texture_2d<f32>;\n"
        )
    }

    /// Records the shadow-map faces the light needs; returns how many were rendered.
    pub fn encode_shadow_map(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        uniforms: &FrameUniforms,
        light: &LightPose,
    ) -> u32 {
        let needed = needed_cube_faces(light);
        // The whole atlas is cleared; a face that is not needed stays at depth 0 (nothing in
        // front: lit, but no receiver there gets light anyway).
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("direct shadow map"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.atlas_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.depth_pipeline);
        draw_light_faces(
            &mut pass,
            scene,
            uniforms,
            self.face_size,
            (0..6).filter(|f| needed[*f]),
        )
    }

    /// Records the direct-lighting pass.
    pub fn encode_lighting(&self, encoder: &mut wgpu::CommandEncoder, gbuffer: &GBuffer) {
        draw_fullscreen(
            encoder,
            "direct light",
            &self.light_pipeline,
            &[&gbuffer.read_group, &self.light_group],
            &[&self.irradiance_view],
        );
    }
}
