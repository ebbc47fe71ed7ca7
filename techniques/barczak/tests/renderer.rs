//! The renderer over frames with a moving object (pillar room, the torus circling, Vulkan and
//! GL): frame after frame, with every out-of-date shadow map re-rendered, its image equals that
//! of a renderer prepared from scratch at that frame — the database, light-map, shadow-map and
//! PRT updates together.

use gibench_barczak::renderer::{Optimisation, Renderer, RendererSettings};
use gibench_barczak::samples::SampleSettings;
use gibench_harness::assets::AssetPaths;
use gibench_harness::scene::Scene;

mod support;

const SETTINGS: RendererSettings = RendererSettings {
    samples: SampleSettings {
        direct: 8,
        indirect: 40,
        bounces: 2,
    },
    light_map_res: 4,
    lights_per_draw: 7,
    level: Optimisation::Full,
    lowres: 2,
    edge_step: 3,
    map_size: 64,
    updates: 1000,
    prt_directions: 256,
};

#[test]
fn updated_frames_equal_frames_prepared_from_scratch() {
    let scene = Scene::load_named("barczak-pillars", &AssetPaths::standard(None)).unwrap();
    support::each_backend(&scene, [96, 72], |backend, gpu, harness| {
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
