//! The compose pass.
//!
//! Reads: G-buffer albedo, direct irradiance, the technique's indirect irradiance.
//! Writes: `radiance` (Rgba16Float, L = ρ/π (E_direct + E_indirect)) and `display`
//! (Rgba8UnormSrgb, clamp(exposure · L), what the PNG shows).

use wgpu::util::DeviceExt;

use crate::gpu::GpuContext;
use crate::measure::roofline::StageCost;

use super::{
    bind_buffer, draw_fullscreen, fullscreen_pipeline, params_entry, render_target, shader_module,
    texture_entry,
};
use super::{GBuffer, HDR_FORMAT};

pub const DISPLAY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

pub struct Compose {
    /// The pass's declared minimum cost per frame ([`crate::measure::roofline`]), from the
    /// image's size.
    pub cost: StageCost,
    pipeline: wgpu::RenderPipeline,
    group: wgpu::BindGroup,
    pub radiance: wgpu::Texture,
    pub radiance_view: wgpu::TextureView,
    pub display: wgpu::Texture,
    pub display_view: wgpu::TextureView,
}

impl Compose {
    /// `indirect` must stay the same texture for the whole run (bound once here).
    pub fn new(
        gpu: &GpuContext,
        gbuffer: &GBuffer,
        direct: &wgpu::TextureView,
        indirect: &wgpu::TextureView,
        exposure: f32,
    ) -> Compose {
        let device = &gpu.device;
        let fs = wgpu::ShaderStages::FRAGMENT;
        let unfilterable = wgpu::TextureSampleType::Float { filterable: false };
        let d2 = wgpu::TextureViewDimension::D2;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("compose"),
            entries: &[
                texture_entry(0, fs, unfilterable, d2),
                texture_entry(1, fs, unfilterable, d2),
                params_entry(2, fs),
            ],
        });
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("compose params"),
            contents: bytemuck::cast_slice(&[exposure, 0.0, 0.0, 0.0]),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("compose"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(direct),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(indirect),
                },
                bind_buffer(2, &params),
            ],
        });
        let module = shader_module(device, "compose", include_str!("shaders/compose.wgsl"));
        let pipeline = fullscreen_pipeline(
            device,
            "compose",
            &module,
            &[&gbuffer.read_layout, &layout],
            &[HDR_FORMAT, DISPLAY_FORMAT],
        );
        let radiance = render_target(device, "radiance", gbuffer.size, HDR_FORMAT);
        let display = render_target(device, "display", gbuffer.size, DISPLAY_FORMAT);
        // Per pixel: the albedo (Rgba8, 4 bytes), the direct and the indirect irradiance
        // (Rgba16Float, 8 each) read once, the radiance (Rgba16Float, 8) and the display
        // value (Rgba8, 4) written once; per channel the indirect clamped at zero and added
        // (2), times the albedo and 1/π (2), times the exposure and clamped to [0, 1] (3):
        // 21 operations (the sRGB encoding is the target format's, on write).
        let [w, h] = gbuffer.size;
        let cost = StageCost::per_element(w as u64 * h as u64, 20, 12, 21);
        Compose {
            cost,
            pipeline,
            group,
            radiance_view: radiance.create_view(&Default::default()),
            display_view: display.create_view(&Default::default()),
            radiance,
            display,
        }
    }

    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, gbuffer: &GBuffer) {
        draw_fullscreen(
            encoder,
            "compose",
            &self.pipeline,
            &[&gbuffer.read_group, &self.group],
            &[&self.radiance_view, &self.display_view],
        );
    }
}
