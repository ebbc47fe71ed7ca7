//! The PRT draw on the GPU (pillar room, the torus mover, Vulkan and GL): at every pixel of the
//! torus the irradiance is the CPU's per-vertex Σ Tₖ Lₖ interpolated over the triangle the pixel
//! shows, the lighting rotated into the torus' frame.

use gibench_barczak::prt::{self, COEFFS};
use gibench_barczak::prt_pass::PrtPass;
use gibench_barczak::samples::SampleSettings;
use gibench_harness::cpu::bvh::SceneBvh;
use gibench_harness::glam::{Mat3, Vec3};
use gibench_harness::kit::passes::{render_target, HDR_FORMAT};
use gibench_harness::wgpu;

use crate::support;

const W: u32 = 160;
const H: u32 = 120;

/// The closest point of triangle (a, b, c) to p, as barycentric weights, and its distance.
fn barycentric(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> (Vec3, f32) {
    let n = (b - a).cross(c - a);
    let q = p - n * (n.dot(p - a) / n.length_squared());
    let area = |x: Vec3, y: Vec3, z: Vec3| (y - x).cross(z - x).dot(n);
    let (wa, wb, wc) = (area(q, b, c), area(a, q, c), area(a, b, q));
    let total = n.length_squared();
    let w = Vec3::new(wa, wb, wc) / total;
    if w.min_element() >= -1e-3 {
        return (w, (p - q).length());
    }
    (w, f32::MAX)
}

#[test]
fn prt_draw_interpolates_the_cpu_vertex_irradiance() {
    let scene = gibench_test_support::load("barczak-pillars");
    let mesh = &scene.movers[0].mesh;
    let transfer = prt::transfer(mesh, &SceneBvh::new(mesh), 512, 1e-4);
    gibench_test_support::each_backend("barczak", &scene, [W, H], 64, |backend, gpu, harness| {
        let frame = harness.clock.frame(40);
        harness.uniforms.write(&gpu.queue, &frame);
        let settings = SampleSettings {
            direct: 16,
            indirect: 48,
            bounces: 2,
        };
        let bz = support::prepared(&scene, &harness.bvh, &frame, settings, 2);
        let model = frame.movers[0];
        let (centre, _) = bz.movers[0].posed(model);
        let rotation = Mat3::from_mat4(model);
        let to_object = Mat3::from_cols(
            rotation.x_axis.normalize(),
            rotation.y_axis.normalize(),
            rotation.z_axis.normalize(),
        )
        .transpose();
        let eps = 1e-4 * scene.extent.diagonal;
        let samples: Vec<_> = bz.samples.all().copied().collect();
        let lighting = prt::lighting(centre, to_object, &samples, |v| {
            !harness
                .bvh
                .occluded(centre, v.position + v.normal * eps, eps)
        });
        let pass = PrtPass::new(
            gpu,
            &harness.uniforms,
            &harness.gbuffer,
            std::slice::from_ref(&transfer),
        )
        .unwrap();
        pass.set_lighting(gpu, 0, &lighting);
        let target = render_target(&gpu.device, "test irradiance", [W, H], HDR_FORMAT);
        let view = target.create_view(&Default::default());
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        harness
            .gbuffer
            .encode(&mut enc, &harness.gpu_scene, &harness.uniforms);
        {
            // Cleared first, as the light-map pass would.
            enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: None,
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
        }
        assert_eq!(
            pass.encode(&mut enc, &harness.gpu_scene, &harness.uniforms, &view),
            1
        );
        gpu.queue.submit([enc.finish()]);
        let gpu_e = gibench_harness::gpu::image_io::read_rgb_f32(gpu, &target).unwrap();
        let g = harness.gbuffer.export(gpu).unwrap();
        // Per vertex, posed.
        let vertex_e: Vec<Vec3> = transfer
            .iter()
            .map(|t| prt::irradiance(t, &lighting).max(Vec3::ZERO))
            .collect();
        let posed: Vec<Vec3> = mesh
            .positions
            .iter()
            .map(|p| model.transform_point3(*p))
            .collect();
        let (mut torus, mut agree) = (0, 0);
        let top = vertex_e
            .iter()
            .map(|e| e.max_element())
            .fold(0f32, f32::max);
        for (i, p) in g.positions.iter().enumerate() {
            let Some(p) = p else { continue };
            let mut best = (Vec3::ZERO, f32::MAX, 0usize);
            for t in 0..mesh.triangle_count() {
                let idx = &mesh.indices[3 * t..3 * t + 3];
                let (w, d) = barycentric(
                    *p,
                    posed[idx[0] as usize],
                    posed[idx[1] as usize],
                    posed[idx[2] as usize],
                );
                if d < best.1 {
                    best = (w, d, t);
                }
            }
            if best.1 > 2e-3 {
                continue; // not the torus
            }
            let idx = &mesh.indices[3 * best.2..3 * best.2 + 3];
            let want = vertex_e[idx[0] as usize] * best.0.x
                + vertex_e[idx[1] as usize] * best.0.y
                + vertex_e[idx[2] as usize] * best.0.z;
            let got = Vec3::from(gpu_e[i]);
            torus += 1;
            agree += ((got - want).abs().max_element() <= 0.02 * want.max_element() + 2e-3 * top)
                as usize;
        }
        eprintln!("{backend}: {agree} of {torus} torus pixels agree");
        assert!(torus > 100, "{backend}: {torus} torus pixels");
        assert!(
            agree * 100 >= torus * 98,
            "{backend}: {agree} of {torus} torus pixels agree with the CPU"
        );
        // The coefficients' count is the thesis' 5th order.
        assert_eq!(transfer[0].len(), COEFFS);
    });
}
