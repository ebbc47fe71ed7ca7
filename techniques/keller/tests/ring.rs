//! Keller's light paths on the CPU: the incremental ring holds the same distribution as
//! `keller-full`'s paths (fractional absorption by the path's place among the N, weights
//! N / ⌊ρ̄^(j−1) N⌋ by the actual count), and `keller-full` traces until it has its VPL count.

use gibench_harness::cpu::bvh::SceneBvh;
use gibench_harness::cpu::vpl::{self, Vpl, VplSettings};
use gibench_harness::glam::Vec3;
use gibench_harness::scene::anim::{FrameClock, LightPose};
use gibench_harness::scene::descriptor::{LightKind, SceneDescriptor};
use gibench_harness::scene::{Material, Mesh, Scene};
use gibench_keller::PathRing;
use gibench_test_support::{load, quad, scene_with};

/// Flux per bounce (1-based; index 0 unused), red channel.
fn per_bounce(vpls: &[Vpl], bounces: u32) -> Vec<f64> {
    let mut out = vec![0.0; bounces as usize + 1];
    for v in vpls {
        out[v.bounce as usize] += v.flux.x as f64;
    }
    out
}

fn cornell() -> (Scene, SceneBvh, LightPose) {
    let scene = load("cornell");
    let bvh = SceneBvh::new(&scene.mesh);
    let light = FrameClock::new(&scene.descriptor).frame(0).light;
    (scene, bvh, light)
}

/// A still light, 4 bounces: once every path of the ring has been replaced, the ring's flux per
/// bounce is within 5 % of `keller-full`'s with the same N, whatever the per-frame budget.
/// (Before the fix, absorption was applied within each replaced batch: with budget 1 no second
/// bounce survived.)
#[test]
fn ring_matches_full_per_bounce_once_full() {
    let (scene, bvh, light) = cornell();
    let (n, bounces) = (4096u32, 4u32);
    let rho = vpl::mean_reflectance(&scene);
    let full = vpl::generate(
        &scene,
        &bvh,
        &light,
        &VplSettings {
            paths: n,
            bounces,
            first_path: 0,
            normalisation_paths: n,
            average_reflectance: Some(rho),
        },
    );
    let want = per_bounce(&full, bounces);
    for budget in [1u32, 2, 4] {
        let mut ring = PathRing::new(n, bounces, rho);
        ring.advance(&scene, &bvh, &light, n);
        // Replace every path at least once (a still light: the same distribution).
        for _ in 0..n.div_ceil(budget) {
            ring.advance(&scene, &bvh, &light, budget);
        }
        let got = per_bounce(
            &ring.vpls().into_iter().map(|(_, v)| v).collect::<Vec<_>>(),
            bounces,
        );
        for j in 1..=bounces as usize {
            let rel = (got[j] - want[j]).abs() / want[j];
            assert!(
                rel < 0.05,
                "budget {budget}, bounce {j}: ring {:.1} vs full {:.1} ({:.1} %)",
                got[j],
                want[j],
                100.0 * rel
            );
        }
    }
}

/// A closed box of uniform albedo ρ: with N = 64 paths, bounce j carries Φ ρ^j within 1 %
/// (every path hits; ⌊ρ^(j−1) N⌋ paths continue, each weighted by N over that count).
#[test]
fn closed_box_bounce_flux_is_exact_at_n_64() {
    let rho = 0.6f32;
    let size = 10.0f32;
    let mut mesh = Mesh::default();
    let c = |x: f32, y: f32, z: f32| Vec3::new(x, y, z) * size;
    let faces = [
        (
            [c(0., 0., 0.), c(1., 0., 0.), c(1., 0., 1.), c(0., 0., 1.)],
            Vec3::Y,
        ),
        (
            [c(0., 1., 0.), c(0., 1., 1.), c(1., 1., 1.), c(1., 1., 0.)],
            Vec3::NEG_Y,
        ),
        (
            [c(0., 0., 0.), c(0., 0., 1.), c(0., 1., 1.), c(0., 1., 0.)],
            Vec3::X,
        ),
        (
            [c(1., 0., 0.), c(1., 1., 0.), c(1., 1., 1.), c(1., 0., 1.)],
            Vec3::NEG_X,
        ),
        (
            [c(0., 0., 0.), c(0., 1., 0.), c(1., 1., 0.), c(1., 0., 0.)],
            Vec3::Z,
        ),
        (
            [c(0., 0., 1.), c(1., 0., 1.), c(1., 1., 1.), c(0., 1., 1.)],
            Vec3::NEG_Z,
        ),
    ];
    for (corners, n) in faces {
        quad(&mut mesh, corners, n, 0);
    }
    let mut descriptor = SceneDescriptor::resolve("cornell").unwrap();
    descriptor.light.kind = LightKind::Omni;
    let scene = scene_with(
        descriptor,
        mesh,
        vec![Material::plain("grey", Vec3::splat(rho))],
    );
    let bvh = SceneBvh::new(&scene.mesh);
    let light = LightPose {
        kind: LightKind::Omni,
        // Off-centre, so that no ray runs exactly along a quad's diagonal.
        position: Vec3::new(0.37, 0.41, 0.53) * size,
        direction: Vec3::NEG_Y,
        power: Vec3::splat(100.0),
        size: [0.0; 2],
    };
    let bounces = 4;
    let vpls = vpl::generate(
        &scene,
        &bvh,
        &light,
        &VplSettings {
            paths: 64,
            bounces,
            first_path: 0,
            normalisation_paths: 64,
            average_reflectance: Some(rho),
        },
    );
    let got = per_bounce(&vpls, bounces);
    for (j, got) in got.iter().enumerate().skip(1) {
        let want = 100.0 * (rho as f64).powi(j as i32);
        assert!(
            (got - want).abs() < 0.01 * want,
            "bounce {j}: {got:.4} vs Φρ^j = {want:.4}"
        );
    }
    // The same through the ring, filled in batches of 3 (a still light).
    let mut ring = PathRing::new(64, bounces, rho);
    ring.advance(&scene, &bvh, &light, 64);
    for _ in 0..30 {
        ring.advance(&scene, &bvh, &light, 3);
    }
    let got = per_bounce(
        &ring.vpls().into_iter().map(|(_, v)| v).collect::<Vec<_>>(),
        bounces,
    );
    for (j, got) in got.iter().enumerate().skip(1) {
        let want = 100.0 * (rho as f64).powi(j as i32);
        assert!(
            (got - want).abs() < 0.01 * want,
            "ring, bounce {j}: {got:.4} vs Φρ^j = {want:.4}"
        );
    }
}

/// `keller-full` traces the fewest paths that give at least its VPL count (here on the Cornell
/// box, where some paths leave through the open front): exactly the count with one bounce, and
/// the flux is normalised by the paths traced.
#[test]
fn full_traces_until_it_has_its_vpl_count() {
    let (scene, bvh, light) = cornell();
    let rho = vpl::mean_reflectance(&scene);
    for (target, bounces) in [(64u32, 1u32), (256, 1), (256, 3)] {
        let (settings, vpls) = vpl::generate_at_least(&scene, &bvh, &light, target, bounces, rho);
        assert!(vpls.len() as u32 >= target, "{target}: {} VPLs", vpls.len());
        if bounces == 1 {
            assert_eq!(vpls.len() as u32, target);
        }
        eprintln!(
            "{target} VPLs, {bounces} bounces: {} paths, {} VPLs",
            settings.paths,
            vpls.len()
        );
        assert!(settings.paths >= target.div_ceil(bounces));
        if bounces == 1 {
            assert!(settings.paths > target, "some paths leave the box");
        }
        // The fewest: one path fewer gives fewer VPLs.
        let fewer = vpl::generate(
            &scene,
            &bvh,
            &light,
            &VplSettings {
                paths: settings.paths - 1,
                normalisation_paths: settings.paths - 1,
                ..settings
            },
        );
        assert!((fewer.len() as u32) < target);
        let first: f32 = vpls
            .iter()
            .filter(|v| v.bounce == 1)
            .map(|v| v.flux.x / v.color.x)
            .sum();
        let want = light.power.x * vpls.iter().filter(|v| v.bounce == 1).count() as f32
            / settings.paths as f32;
        assert!((first - want).abs() < 1e-3 * want);
    }
}
