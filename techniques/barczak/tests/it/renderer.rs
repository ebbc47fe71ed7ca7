//! The renderer over frames with a moving object (pillar room, the torus circling, Vulkan and
//! GL): frame after frame, with every out-of-date shadow map re-rendered, its image equals that
//! of a renderer prepared from scratch at that frame — the database, light-map, shadow-map and
//! PRT updates together. And face culling (§4.2.2) changes no pixel while skipping faces.

use gibench_barczak::light_draws::Submission;
use gibench_barczak::renderer::{Optimisation, Renderer, RendererSettings};
use gibench_barczak::samples::SampleSettings;

use crate::support;

const SETTINGS: RendererSettings = RendererSettings {
    samples: SampleSettings {
        direct: 8,
        indirect: 40,
        bounces: 2,
    },
    light_map_res: 4,
    lights_per_draw: 7,
    submission: Submission::Merged,
    level: Optimisation::Full,
    lowres: 2,
    edge_step: 3,
    map_size: 64,
    updates: 1000,
    prt_directions: 256,
    face_cull: true,
    max_charts: gibench_barczak::setup::MAX_CHARTS,
};

#[test]
fn updated_frames_equal_frames_prepared_from_scratch() {
    let scene = gibench_test_support::load("barczak-pillars");
    gibench_test_support::each_backend("barczak", &scene, [96, 72], 64, |backend, gpu, harness| {
        let render = |r: &mut Renderer, f: u32| support::render_frame(gpu, harness, r, f);
        let start = harness.clock.frame(0);
        let mut running = Renderer::new(
            gpu,
            &scene,
            &harness.bvh,
            &harness.uniforms,
            &harness.gbuffer,
            &start,
            SETTINGS,
        )
        .unwrap();
        let mut changes = 0;
        for f in [0u32, 12, 24, 36] {
            let (image, counts) = render(&mut running, f);
            changes += counts.light_map_changes;
            let frame = harness.clock.frame(f);
            let mut fresh = Renderer::new(
                gpu,
                &scene,
                &harness.bvh,
                &harness.uniforms,
                &harness.gbuffer,
                &frame,
                SETTINGS,
            )
            .unwrap();
            let (want, _) = render(&mut fresh, f);
            let top = want
                .iter()
                .flat_map(|p| p.iter().copied())
                .fold(0f32, f32::max);
            let same = image
                .iter()
                .zip(&want)
                .filter(|(a, b)| {
                    (0..3).all(|c| (a[c] - b[c]).abs() <= 0.02 * b[c].abs() + 4e-3 * top)
                })
                .count();
            eprintln!(
                "{backend} frame {f}: {same} of {} pixels agree; {counts:?}",
                image.len()
            );
            assert!(
                same * 1000 >= image.len() * 995,
                "{backend} frame {f}: {same} of {} pixels agree",
                image.len()
            );
            assert!(counts.light_draws > 0);
        }
        assert!(changes > 0, "{backend}: the torus changed no light map");
    });
}

/// §4.2.2 on the table room (the bunny moving on the table): drawing each shadow map only into
/// the octahedral faces that hold an occluder gives the same image, bit for bit, as drawing all
/// four, frame after frame, while skipping faces. A face culled wrongly (another face's
/// numbering, an occluder missed) leaves a shadow out of its map and changes pixels.
#[test]
fn face_culling_skips_faces_and_changes_no_pixel() {
    let scene = gibench_test_support::load("barczak-table");
    gibench_test_support::each_backend("barczak", &scene, [96, 72], 64, |backend, gpu, harness| {
        let start = harness.clock.frame(0);
        let new = |face_cull| {
            let settings = RendererSettings {
                face_cull,
                updates: 16,
                ..SETTINGS
            };
            (Renderer::new(
                gpu,
                &scene,
                &harness.bvh,
                &harness.uniforms,
                &harness.gbuffer,
                &start,
                settings,
            ))
            .unwrap()
        };
        let (mut culled, mut all) = (new(true), new(false));
        let (mut faces, mut maps) = (0, 0);
        for f in [0u32, 1, 2, 3, 10, 20] {
            let (a, ca) = support::render_frame(gpu, harness, &mut culled, f);
            let (b, cb) = support::render_frame(gpu, harness, &mut all, f);
            assert_eq!(ca.maps_rendered, cb.maps_rendered);
            assert_eq!(cb.map_faces, 4 * cb.maps_rendered);
            (faces, maps) = (faces + ca.map_faces, maps + ca.maps_rendered);
            let differ = a.iter().zip(&b).filter(|(p, q)| p != q).count();
            assert_eq!(differ, 0, "{backend} frame {f}: {differ} pixels differ");
        }
        eprintln!("{backend}: {faces} faces for {maps} maps");
        assert!(
            maps > 0 && faces < 3 * maps,
            "{backend}: {faces} faces for {maps} maps"
        );
    });
}
