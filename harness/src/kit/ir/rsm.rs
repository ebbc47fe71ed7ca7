//! **Reflective shadow map**: the scene seen from the primary light — surface positions,
//! normals and the flux each texel's patch reflects — as the texels the
//! [`super::vpl_sample::VplSampler`] reads (imperfect shadow maps' first step, Ritschel et al.
//! 2008; reflective shadow maps, Dachsbacher and Stamminger 2005).
//!
//! Reads: the scene (static meshes and movers, through [`scene_pipeline`] with the G-buffer's
//! fragment shader: textured albedo, normal facing the viewer), the light's views (slots
//! 1..=6 of the frame's [`crate::kit::passes::ViewSet`]: the cube faces around a spot, omni or area
//! light, or the sun's one orthographic map), the `Light` block.
//! Writes (owns): a 3×2 atlas of `size`² faces (depth, normal, albedo), and three storage
//! buffers of 6·`size`² texels: position (w = 1 where a surface was seen), normal, reflected
//! flux = albedo × the light's flux through the texel (I(ω)·Ω for a light at a point, E⊥·A for
//! the sun). The texels of all faces together carry the flux the first bounce reflects, which
//! is what the VPLs sampled from them share.
//!
//! An area light is seen from its centre with its cosine intensity, as the harness's direct
//! pass treats it (README, deviations).

use super::splat::texel_buffer_size;
use crate::gpu::GpuContext;
use crate::kit::passes::{
    begin_gbuffer_pass, compute_pipeline, draw_light_faces, render_target, scene_pipeline,
    Bindings, FrameUniforms, GpuScene, ALBEDO_FORMAT, DEPTH_FORMAT, NORMAL_FORMAT, PARAMS_USAGE,
};
use crate::kit::technique::FrameContext;
use crate::measure::roofline::StageCost;
use crate::Result;

/// The stage name the map is timed under ([`ReflectiveShadowMap::record`]).
pub const STAGE: &str = "rsm";

/// The map, its render pipeline and its export pass (see the module docs).
pub struct ReflectiveShadowMap {
    /// The declared minimum cost of one face ([`ReflectiveShadowMap::cost`]).
    face_cost: StageCost,
    size: u32,
    depth_view: wgpu::TextureView,
    normal_view: wgpu::TextureView,
    albedo_view: wgpu::TextureView,
    pipeline: wgpu::RenderPipeline,
    export: wgpu::ComputePipeline,
    group: wgpu::BindGroup,
    faces_group: wgpu::BindGroup,
    params: wgpu::Buffer,
    buffers: [wgpu::Buffer; 3],
    _textures: [wgpu::Texture; 3],
}

impl ReflectiveShadowMap {
    /// A map of `size`² per face for the scene drawn by `scene` with `uniforms`' light views.
    pub fn new(
        gpu: &GpuContext,
        scene: &GpuScene,
        uniforms: &FrameUniforms,
        size: u32,
    ) -> Result<ReflectiveShadowMap> {
        let device = &gpu.device;
        let extent = [3 * size, 2 * size];
        let depth = render_target(device, "rsm depth", extent, DEPTH_FORMAT);
        let normal = render_target(device, "rsm normal", extent, NORMAL_FORMAT);
        let albedo = render_target(device, "rsm albedo", extent, ALBEDO_FORMAT);
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (depth_view, normal_view, albedo_view) = (view(&depth), view(&normal), view(&albedo));
        let pipeline = scene_pipeline(
            device,
            "rsm",
            scene,
            uniforms,
            "vs_main",
            Some(("fs_gbuffer", &[NORMAL_FORMAT, ALBEDO_FORMAT])),
        );
        let texels = 6 * size as u64 * size as u64;
        let bytes = texel_buffer_size(
            gpu,
            texels * 4,
            "the reflective shadow map's texels",
            "rsm-size",
        )?;
        let buffer = |label: &str| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            })
        };
        let buffers = [
            buffer("rsm position"),
            buffer("rsm normal"),
            buffer("rsm flux"),
        ];
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("rsm params"),
            size: 16,
            usage: PARAMS_USAGE,
            mapped_at_creation: false,
        });
        let c = wgpu::ShaderStages::COMPUTE;
        let export_group = Bindings::new("rsm export", c)
            .params(&params)
            .params(&uniforms.light_buffer)
            .texture(&depth_view)
            .texture(&normal_view)
            .texture(&albedo_view)
            .write(&buffers[0])
            .write(&buffers[1])
            .write(&buffers[2])
            .build(device);
        let faces = (1..=6).fold(Bindings::new("rsm faces", c), |g, f| {
            g.uniform(uniforms.views.binding(f))
        });
        let faces = faces.build(device);
        let export = compute_pipeline(
            device,
            "rsm export",
            include_str!("shaders/rsm_export.wgsl"),
            &[&export_group.layout, &faces.layout],
            "export_texels",
        );
        gpu.check_errors()?;
        // Per face: the scene drawn once, every vertex with its normal, texture coordinates and
        // material ([`GpuScene::draw_cost`]), and every texel's position, normal and reflected
        // flux (three vec4<f32>, 48 bytes) written once — straight from the rasteriser: the
        // depth, normal and albedo textures this pass goes through are not part of the
        // minimum. Per texel the flux: the direction to the light and its length (8), the
        // light's intensity that way (about 10), the texel's solid angle (6) and the albedo
        // times it (6): 30 operations. Texture reads and hidden fragments are not counted.
        let face = size as u64 * size as u64;
        let face_cost = scene
            .draw_cost()
            .plus(StageCost::per_element(face, 0, 48, 30));
        Ok(ReflectiveShadowMap {
            face_cost,
            size,
            depth_view,
            normal_view,
            albedo_view,
            pipeline,
            export,
            group: export_group.group,
            faces_group: faces.group,
            params,
            buffers,
            _textures: [depth, normal, albedo],
        })
    }

    /// The declared minimum cost ([`crate::measure::roofline`]) of a frame whose light reaches
    /// `faces` faces ([`crate::kit::passes::needed_cube_faces`]: a spot light fewer than six,
    /// the sun one). The faces it cannot reach stay empty, so their texels need no writing.
    pub fn cost(&self, faces: u32) -> StageCost {
        self.face_cost.scaled(faces as f64)
    }

    /// Edge of each face, texels (the texel buffers' rows are this long).
    pub fn size(&self) -> u32 {
        self.size
    }

    /// Texels of all faces (6 · size²).
    pub fn texels(&self) -> u32 {
        6 * self.size * self.size
    }

    /// Position, normal and reflected-flux buffers (see the module docs).
    pub fn buffers(&self) -> [&wgpu::Buffer; 3] {
        [&self.buffers[0], &self.buffers[1], &self.buffers[2]]
    }

    /// Records this frame's map as the GPU stage [`STAGE`] with its declared cost (the faces
    /// the frame's light reaches).
    pub fn record(&self, ctx: &mut FrameContext) -> Result<()> {
        let gpu = ctx.gpu;
        let (scene, uniforms) = (ctx.gpu_scene, ctx.uniforms);
        let directional = ctx.frame.light.is_directional();
        ctx.profiler.gpu_stage(gpu, STAGE, |enc| {
            self.encode(gpu, enc, scene, uniforms, directional)
        })?;
        let reached = (crate::kit::passes::needed_cube_faces(&ctx.frame.light).iter())
            .filter(|f| **f)
            .count();
        ctx.profiler.stage_cost(STAGE, self.cost(reached as u32));
        Ok(())
    }

    /// Records the faces `faces` lists (the sun: face 0 only) and the export of every texel.
    /// `directional`: whether the light is the sun (one orthographic map).
    pub fn encode(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        uniforms: &FrameUniforms,
        directional: bool,
    ) {
        let faces = if directional { 1u32 } else { 6 };
        gpu.queue.write_buffer(
            &self.params,
            0,
            bytemuck::bytes_of(&[self.size, faces, 0, 0]),
        );
        {
            let mut pass = begin_gbuffer_pass(
                encoder,
                "rsm",
                &self.normal_view,
                &self.albedo_view,
                &self.depth_view,
            );
            pass.set_pipeline(&self.pipeline);
            draw_light_faces(&mut pass, scene, uniforms, self.size, 0..faces as usize);
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("rsm export"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.export);
        pass.set_bind_group(0, &self.group, &[]);
        pass.set_bind_group(1, &self.faces_group, &[]);
        pass.dispatch_workgroups((self.size * self.size).div_ceil(64), 6, 1);
    }
}
