//! The low-resolution pass (pillar room, Vulkan and GL) against the same level at full
//! resolution (VD+LP against VD):
//!
//! 1. each low-resolution pixel p equals the full-resolution image at its sample pixel
//!    2p + 1 (catches a wrong projection shift or sample pixel: the low draws would light or
//!    test another point);
//! 2. off the edges, VD+LP's image is the bilinear interpolation of the low image between the
//!    samples (catches a wrong interpolation footprint or mapping), and zero on background;
//! 3. on the edges it equals VD's full-resolution image (catches edge draws not restricted to,
//!    or missing from, the edge mask);
//! 4. the low-resolution pass draws every planned draw twice;
//! 5. and Full, with its low-resolution subtraction, agrees with VD+LP within 10 % on 95 % of
//!    the pixels (they differ by the light maps' interpolation).

use gibench_barczak::light_draws::Submission;
use gibench_barczak::renderer::{FrameCounts, Optimisation, Renderer, RendererSettings};
use gibench_barczak::samples::SampleSettings;

use crate::support;

const W: u32 = 96;
const H: u32 = 72;

fn settings(level: Optimisation) -> RendererSettings {
    RendererSettings {
        samples: SampleSettings {
            direct: 8,
            indirect: 40,
            bounces: 2,
        },
        light_map_res: 4,
        lights_per_draw: 7,
        submission: Submission::Merged,
        level,
        lowres: 2,
        edge_step: 3,
        map_size: 64,
        updates: 1000,
        prt_directions: 64,
        face_cull: true,
        max_charts: gibench_barczak::setup::MAX_CHARTS,
    }
}

#[test]
fn the_low_resolution_pass_interpolates_off_edges_and_redraws_them() {
    let scene = gibench_test_support::load("barczak-pillars");
    gibench_test_support::each_backend("barczak", &scene, [W, H], 64, |backend, gpu, harness| {
        let frame = harness.clock.frame(0);
        let render = |level| -> (Renderer, Vec<[f32; 3]>, FrameCounts) {
            let mut r = Renderer::new(
                gpu,
                &scene,
                &harness.bvh,
                &harness.uniforms,
                &harness.gbuffer,
                &frame,
                settings(level),
            )
            .unwrap();
            let (image, counts) = support::render_frame(gpu, harness, &mut r, 0);
            (r, image, counts)
        };
        let (lp, lp_image, lp_counts) = render(Optimisation::VdLp);
        let (_, vd_image, vd_counts) = render(Optimisation::Vd);
        let (_, full_image, _) = render(Optimisation::Full);
        let lowres = lp.lowres().expect("VD+LP has the low-resolution pass");
        let low = gibench_harness::gpu::image_io::read_rgb_f32(gpu, lowres.low_texture()).unwrap();
        let mask = lowres.edges().read(gpu).unwrap();
        let top = vd_image
            .iter()
            .flat_map(|p| p.iter().copied())
            .fold(0f32, f32::max);
        let close = |a: [f32; 3], b: [f32; 3], rel: f32| {
            (0..3).all(|c| (a[c] - b[c]).abs() <= rel * a[c].abs().max(b[c].abs()) + 1e-3 * top)
        };
        let [lw, lh] = lowres.size;
        assert_eq!([lw, lh], [W / 2, H / 2]);

        // 1. Low pixels against their sample pixels (those showing a patch: movers are drawn by
        // PRT, after).
        let g = harness.gbuffer.export(gpu).unwrap();
        let db = &lp.scene().db;
        let on_patch = |i: usize| {
            g.positions[i].is_some_and(|p| {
                support::leaf_at(db, p, g.normals[i], 1e-3 * scene.extent.diagonal, 0.02).is_some()
            })
        };
        let (mut lit, mut same) = (0, 0);
        for y in 0..lh {
            for x in 0..lw {
                let s = ((2 * y + 1) * W + 2 * x + 1) as usize;
                let want = vd_image[s];
                if !on_patch(s) {
                    continue;
                }
                lit += 1;
                same += close(low[(y * lw + x) as usize], want, 0.01) as usize;
            }
        }
        eprintln!("{backend}: {same} of {lit} low pixels equal their samples");
        assert!(lit > 1000, "{backend}: {lit} low pixels lit");
        assert!(
            same * 100 >= lit * 99,
            "{backend}: {same} of {lit} low pixels equal their sample pixels"
        );

        // 2, 3. Off the edges the interpolation, on them the full-resolution draws.
        let at = |x: i64, y: i64| {
            let (x, y) = (x.clamp(0, lw as i64 - 1), y.clamp(0, lh as i64 - 1));
            low[(y as u32 * lw + x as u32) as usize]
        };
        let (mut off, mut off_same, mut on, mut on_same) = (0, 0, 0, 0);
        for y in 0..H {
            for x in 0..W {
                let i = (y * W + x) as usize;
                if g.positions[i].is_none() {
                    assert_eq!(lp_image[i], [0.0; 3], "{backend}: background at ({x}, {y})");
                    continue;
                }
                if mask[i] != 0 {
                    on += 1;
                    on_same += close(lp_image[i], vd_image[i], 0.01) as usize;
                    continue;
                }
                // Low pixel p samples full pixel 2p + 1.
                let (u, v) = (
                    ((x as f32 - 1.0) / 2.0).clamp(0.0, (lw - 1) as f32),
                    ((y as f32 - 1.0) / 2.0).clamp(0.0, (lh - 1) as f32),
                );
                let (x0, y0) = (u.floor() as i64, v.floor() as i64);
                let (tx, ty) = (u - u.floor(), v - v.floor());
                let mut want = [0f32; 3];
                for (c, w) in want.iter_mut().enumerate() {
                    let a = at(x0, y0)[c] * (1.0 - tx) + at(x0 + 1, y0)[c] * tx;
                    let b = at(x0, y0 + 1)[c] * (1.0 - tx) + at(x0 + 1, y0 + 1)[c] * tx;
                    *w = a * (1.0 - ty) + b * ty;
                }
                off += 1;
                off_same += close(lp_image[i], want, 0.01) as usize;
            }
        }
        eprintln!(
            "{backend}: off the edges {off_same} of {off} interpolated; on them {on_same} of {on} as at full resolution"
        );
        assert!(
            off > 2000 && on > 300,
            "{backend}: {off} off, {on} on edges"
        );
        assert!(
            off_same * 1000 >= off * 995,
            "{backend}: {off_same} of {off} pixels off the edges are the interpolation"
        );
        assert!(
            on_same * 100 >= on * 99,
            "{backend}: {on_same} of {on} edge pixels equal the full-resolution image"
        );

        // 4. Two draws per planned draw.
        assert_eq!(lp_counts.light_draws, 2 * vd_counts.light_draws);

        // 5. Full (light maps, subtraction at low resolution) against VD+LP.
        let shown = lp_image
            .iter()
            .filter(|p| p.iter().any(|v| *v != 0.0))
            .count();
        let agree = lp_image
            .iter()
            .zip(&full_image)
            .filter(|(a, b)| a.iter().any(|v| *v != 0.0) && close(**a, **b, 0.1))
            .count();
        eprintln!("{backend}: Full agrees with VD+LP on {agree} of {shown} pixels");
        assert!(
            agree * 100 >= shown * 95,
            "{backend}: Full agrees with VD+LP on {agree} of {shown} pixels"
        );
    });
}
