//! The low-resolution pass (Barczak 2006 §4.3.3): the lights drawn at 1/`factor` of the
//! resolution, interpolated to full resolution, and drawn again at full resolution only at
//! edges, where interpolation would leak across surfaces.
//!
//! Reads: the G-buffer (the kit's [`EdgeMask`] finds the edges from its positions and normals,
//! stepping `edge_step` pixels), the low-resolution image the light draws made
//! ([`crate::light_draws::LightDraws::encode_low`]).
//! Writes (owns): the low-resolution image (Rgba16Float, cleared by the low draws); the edge
//! mask as depth, as the thesis does (reversed Z here: 0 at edge pixels, 1 elsewhere), so the
//! full-resolution light draws, depth-tested Greater, run at edges only; and, in the caller's
//! pass, the interpolated image added to (or, after light maps, subtracted from) the target off
//! the edges, on pixels that show a surface.
//!
//! Low-resolution pixel p samples the full-resolution pixel `factor·p + ⌊factor/2⌋`: the low
//! draws shift the projection by [`LowRes::ndc_offset`] so that their pixel centres fall on
//! those pixels' centres, where they test the G-buffer's depth as the full-resolution draws do.
//! The resolution must be a multiple of `factor`.

use bytemuck::{Pod, Zeroable};
use gibench_harness::gpu::GpuContext;
use gibench_harness::kit::ir::edges::{EdgeMask, EdgeSettings};
use gibench_harness::kit::passes::{
    fullscreen_pipeline_with, params_buffer, render_target, shader_module, Bindings, Bound,
    GBuffer, HDR_FORMAT,
};
use gibench_harness::{wgpu, Error, Result};

/// The edge mask's depth format.
pub const MASK_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Params {
    counts: [u32; 4],
    full: [u32; 4],
}

/// See the module docs.
pub struct LowRes {
    pub factor: u32,
    /// The low resolution.
    pub size: [u32; 2],
    full: [u32; 2],
    edges: EdgeMask,
    low: wgpu::Texture,
    low_view: wgpu::TextureView,
    _mask: wgpu::Texture,
    mask_view: wgpu::TextureView,
    group: wgpu::BindGroup,
    gbuffer_group: wgpu::BindGroup,
    mask_pipeline: wgpu::RenderPipeline,
    composite_add: wgpu::RenderPipeline,
    composite_subtract: wgpu::RenderPipeline,
}

impl LowRes {
    /// The pass at 1/`factor` of `gbuffer`'s resolution with edges found by `edges`. Errors
    /// name `lowres` when the resolution is not a multiple of it.
    pub fn new(
        gpu: &GpuContext,
        gbuffer: &GBuffer,
        factor: u32,
        edges: EdgeSettings,
    ) -> Result<LowRes> {
        let [w, h] = gbuffer.size;
        if !(2..=16).contains(&factor) {
            return Err(Error::param(
                "lowres",
                format!("expected a factor in 2..=16 (got {factor})"),
            ));
        }
        if w % factor != 0 || h % factor != 0 {
            return Err(Error::param(
                "lowres",
                format!("the resolution {w}x{h} is not a multiple of the factor {factor}"),
            ));
        }
        let edges = EdgeMask::new(gpu, gbuffer, edges)?;
        let device = &gpu.device;
        let size = [w / factor, h / factor];
        let low = render_target(device, "barczak low resolution", size, HDR_FORMAT);
        let low_view = low.create_view(&Default::default());
        let mask = render_target(device, "barczak edge depth", gbuffer.size, MASK_FORMAT);
        let mask_view = mask.create_view(&Default::default());
        let params = params_buffer(
            gpu,
            "barczak low resolution",
            &Params {
                counts: [factor, factor / 2, size[0], size[1]],
                full: [w, h, 0, 0],
            },
        );
        let frag = wgpu::ShaderStages::FRAGMENT;
        let Bound { layout, group } = Bindings::new("barczak low resolution", frag)
            .params(&params)
            .params(edges.mask())
            .texture(&low_view)
            .build(device);
        let module = shader_module(
            device,
            "barczak low resolution",
            include_str!("shaders/lowres.wgsl"),
        );
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("barczak low resolution"),
            bind_group_layouts: &[Some(&layout), Some(&gbuffer.read_layout)],
            immediate_size: 0,
        });
        let pipeline = |entry: &str,
                        depth: wgpu::DepthStencilState,
                        targets: &[Option<wgpu::ColorTargetState>]| {
            fullscreen_pipeline_with(
                device,
                "barczak low resolution",
                &module,
                &pipeline_layout,
                entry,
                targets,
                Some(depth),
            )
        };
        let mask_pipeline = pipeline(
            "fs_mask",
            mask_depth(true, wgpu::CompareFunction::Always),
            &[],
        );
        let composite = |operation| {
            pipeline(
                "fs_composite",
                mask_depth(false, wgpu::CompareFunction::Less),
                &[Some(accumulate(operation))],
            )
        };
        let composite_add = composite(wgpu::BlendOperation::Add);
        let composite_subtract = composite(wgpu::BlendOperation::ReverseSubtract);
        gpu.check_errors()?;
        Ok(LowRes {
            factor,
            size,
            full: gbuffer.size,
            edges,
            low,
            low_view,
            _mask: mask,
            mask_view,
            group,
            gbuffer_group: gbuffer.read_group.clone(),
            mask_pipeline,
            composite_add,
            composite_subtract,
        })
    }

    /// The NDC shift that puts low-resolution pixel centres on their samples' centres.
    pub fn ndc_offset(&self) -> [f32; 2] {
        // Low pixel p's centre is at full-resolution x = factor·p + factor/2; its sample's
        // centre at factor·p + ⌊factor/2⌋ + 0.5.
        let d = self.factor as f32 / 2.0 - ((self.factor / 2) as f32 + 0.5);
        [
            2.0 * d / self.full[0] as f32,
            -2.0 * d / self.full[1] as f32,
        ]
    }

    /// The low-resolution image's texture (for tests and inspection).
    pub fn low_texture(&self) -> &wgpu::Texture {
        &self.low
    }

    /// The low-resolution image.
    pub fn low_view(&self) -> &wgpu::TextureView {
        &self.low_view
    }

    /// The edge mask as depth.
    pub fn mask_view(&self) -> &wgpu::TextureView {
        &self.mask_view
    }

    /// The kit's edge mask (for tests and inspection).
    pub fn edges(&self) -> &EdgeMask {
        &self.edges
    }

    /// Records the edge detection and its depth mask.
    pub fn encode_mask(&self, encoder: &mut wgpu::CommandEncoder) {
        self.edges.encode(encoder);
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("barczak edge depth"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.mask_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.mask_pipeline);
        pass.set_bind_group(0, &self.group, &[]);
        pass.set_bind_group(1, &self.gbuffer_group, &[]);
        pass.draw(0..3, 0..1);
    }

    /// Draws the interpolated image into `pass` (whose depth attachment is [`Self::mask_view`])
    /// off the edges: added, or subtracted when `subtract`.
    pub fn composite(&self, pass: &mut wgpu::RenderPass, subtract: bool) {
        pass.set_pipeline(if subtract {
            &self.composite_subtract
        } else {
            &self.composite_add
        });
        pass.set_bind_group(0, &self.group, &[]);
        pass.set_bind_group(1, &self.gbuffer_group, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// The edge mask's depth state: written (by the mask) or only tested with `compare`.
pub(crate) fn mask_depth(write: bool, compare: wgpu::CompareFunction) -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: MASK_FORMAT,
        depth_write_enabled: Some(write),
        depth_compare: Some(compare),
        stencil: Default::default(),
        bias: Default::default(),
    }
}

/// An Rgba16Float target blended `dst op src` on colour, alpha kept.
pub(crate) fn accumulate(operation: wgpu::BlendOperation) -> wgpu::ColorTargetState {
    wgpu::ColorTargetState {
        format: HDR_FORMAT,
        blend: Some(wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::One,
                dst_factor: wgpu::BlendFactor::One,
                operation,
            },
            alpha: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::Zero,
                dst_factor: wgpu::BlendFactor::One,
                operation: wgpu::BlendOperation::Add,
            },
        }),
        write_mask: wgpu::ColorWrites::ALL,
    }
}
