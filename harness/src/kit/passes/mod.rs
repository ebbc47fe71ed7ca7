//! Shared GPU passes, written once and used by every technique (Falcor-style: each pass says
//! what it reads and writes in its docs, and the runner scopes each one as a profiler stage).
//!
//! * [`GpuScene`]: the scene's meshes, materials and textures on the GPU, and how to draw them.
//! * [`FrameUniforms`]: per-frame camera, cube-face, object and light uniforms; [`ViewSet`]:
//!   a set of [`View`]s (the harness's, or a technique's own); [`DrawSet`]: what a draw includes;
//!   [`scene_pipeline`]: a pipeline drawing the scene with any vertex/fragment entry.
//! * [`GBuffer`]: reversed-Z depth, normal and albedo of the camera view; world positions are
//!   reconstructed from depth (Rgba32Float is not renderable on GL).
//! * [`DirectLight`]: the primary light's shadow map (cube, or the sun's orthographic map) and
//!   direct irradiance with 16-tap PCF; [`DirectLight::wgsl`] gives any shader the same lookup.
//! * [`Compose`]: outgoing radiance and its display encoding.
//! * Bind-group entries: [`uniform_entry`], [`storage_entry`], [`params_entry`],
//!   [`texture_entry`], [`storage_texture_entry`], [`sampler_entry`] and the like for layouts;
//!   [`bind_buffer`] for a whole buffer in a bind group.

mod bind;
mod compose;
mod direct;
mod gbuffer;
mod scene_gpu;

pub use bind::{
    bind_buffer, dynamic_storage_entry, params_entry, read_storage_entry, sampler_entry,
    storage_entry, storage_texture_entry, texture_entry, uniform_entry, Bindings, Bound,
    PARAMS_USAGE,
};
pub use compose::Compose;
pub use direct::{draw_light_faces, needed_cube_faces, DirectLight, CUBE_FACES};
pub use gbuffer::{
    begin_gbuffer_pass, scene_pipeline, GBuffer, GBufferTexels, ALBEDO_FORMAT, DEPTH_FORMAT,
    NORMAL_FORMAT,
};
pub use scene_gpu::{
    cube_face_matrix, sun_view_matrix, DrawSet, FrameUniforms, GpuScene, Vertex, View, ViewSet,
    CAMERA_SLOT, MAX_MATERIALS,
};

/// Creates a shader module from `source`, its `#import`s and the prelude resolved
/// ([`crate::kit::wgsl::compose`]). An unknown import is a bug of ours: it panics, naming it
/// (the test over every shader finds it first).
pub fn shader_module(device: &wgpu::Device, label: &str, source: &str) -> wgpu::ShaderModule {
    let full = crate::kit::wgsl::compose(source).unwrap_or_else(|e| panic!("{label}: {e}"));
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(full.into()),
    })
}

/// A compute pipeline: `entry` of `source` (imports resolved, [`shader_module`]) over `layouts`
/// (bind groups 0, 1, ... in order).
pub fn compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    source: &str,
    layouts: &[&wgpu::BindGroupLayout],
    entry: &str,
) -> wgpu::ComputePipeline {
    let module = shader_module(device, label, source);
    let layouts: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().copied().map(Some).collect();
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &layouts,
        immediate_size: 0,
    });
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(&layout),
        module: &module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// Format of every irradiance and radiance buffer (renderable on Vulkan and GL).
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The full-resolution indirect-irradiance texture a technique returns (HDR_FORMAT; sampled by
/// compose, copied out for images and quality). `storage` adds STORAGE_BINDING for compute
/// writes. wgpu zero-initialises it, so a technique that never writes it outputs zero.
pub fn indirect_target(device: &wgpu::Device, size: [u32; 2], storage: bool) -> wgpu::Texture {
    let mut usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC;
    if storage {
        usage |= wgpu::TextureUsages::STORAGE_BINDING;
    }
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("indirect irradiance"),
        size: wgpu::Extent3d {
            width: size[0],
            height: size[1],
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: HDR_FORMAT,
        usage,
        view_formats: &[],
    })
}

/// A full-resolution 2D render target.
pub fn render_target(
    device: &wgpu::Device,
    label: &str,
    size: [u32; 2],
    format: wgpu::TextureFormat,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: size[0],
            height: size[1],
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

/// A parameter block for a binding made with [`params_entry`]: a buffer of `data`'s size with
/// [`PARAMS_USAGE`], `data` queued into it.
pub fn params_buffer<T: bytemuck::Pod>(
    gpu: &crate::gpu::GpuContext,
    label: &str,
    data: &T,
) -> wgpu::Buffer {
    let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: std::mem::size_of::<T>() as u64,
        usage: PARAMS_USAGE,
        mapped_at_creation: false,
    });
    gpu.queue.write_buffer(&buffer, 0, bytemuck::bytes_of(data));
    buffer
}

/// A fullscreen-triangle render pipeline (vertex `vs_main`, fragment `fs_main`).
pub fn fullscreen_pipeline(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    layouts: &[&wgpu::BindGroupLayout],
    targets: &[wgpu::TextureFormat],
) -> wgpu::RenderPipeline {
    let layouts: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().map(|l| Some(*l)).collect();
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &layouts,
        immediate_size: 0,
    });
    let targets: Vec<Option<wgpu::ColorTargetState>> = targets
        .iter()
        .map(|f| {
            Some(wgpu::ColorTargetState {
                format: *f,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })
        })
        .collect();
    fullscreen_pipeline_with(device, label, module, &layout, "fs_main", &targets, None)
}

/// A fullscreen-triangle render pipeline over `layout` (vertex `vs_main`): fragment `entry`
/// writing `targets` as given (blending included; none for a depth-only pass), with an optional
/// depth state.
pub fn fullscreen_pipeline_with(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    entry: &str,
    targets: &[Option<wgpu::ColorTargetState>],
    depth: Option<wgpu::DepthStencilState>,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: depth,
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// Runs a fullscreen pass writing `targets` (cleared to zero first).
pub fn draw_fullscreen(
    encoder: &mut wgpu::CommandEncoder,
    label: &str,
    pipeline: &wgpu::RenderPipeline,
    bind_groups: &[&wgpu::BindGroup],
    targets: &[&wgpu::TextureView],
) {
    let attachments: Vec<Option<wgpu::RenderPassColorAttachment>> = targets
        .iter()
        .map(|view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })
        })
        .collect();
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &attachments,
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(pipeline);
    for (i, bg) in bind_groups.iter().enumerate() {
        pass.set_bind_group(i as u32, *bg, &[]);
    }
    pass.draw(0..3, 0..1);
}
