//! VPL generation for instant radiosity: Halton points, the domain mappings (unit disc,
//! cosine hemisphere, unit sphere), flux conservation in a closed box, Keller's fractional
//! absorption, the spot's sampling distribution, incremental continuation and determinism.
//! Scenes are built in code, plus the Cornell box. No GPU needed.

use gibench_harness::cpu::bvh::SceneBvh;
use gibench_harness::cpu::vpl::{
    continuing_paths, disc_to_hemisphere, generate, halton, hemisphere_to_disc, mean_reflectance,
    radical_inverse, square_to_disc, square_to_sphere, to_local, total_flux, Vpl, VplSettings,
};
use gibench_harness::glam::{Vec2, Vec3};
use gibench_harness::scene::anim::{FrameClock, LightPose};
use gibench_harness::scene::assets::AssetPaths;
use gibench_harness::scene::descriptor::LightKind;
use gibench_harness::scene::{Mesh, Scene};

use gibench_test_support::scene::{closed_box_mesh, material, quad, scene};

const ALBEDO: Vec3 = Vec3::new(0.5, 0.6, 0.7);
const BOX: Vec3 = Vec3::new(4.0, 3.0, 5.0);

/// A closed 4 × 3 × 5 box of six inward-facing quads, all of albedo [`ALBEDO`].
fn closed_box() -> Scene {
    scene(closed_box_mesh(BOX, 0), vec![material("box", ALBEDO)])
}

/// The square [−h, h]² in the y = 0 plane, facing +Y, albedo [`ALBEDO`].
fn plane(h: f32) -> Scene {
    let mut m = Mesh::default();
    let v = |x, z| Vec3::new(x, 0.0, z);
    quad(&mut m, [v(-h, -h), v(-h, h), v(h, h), v(h, -h)], Vec3::Y, 0);
    scene(m, vec![material("plane", ALBEDO)])
}

fn light(kind: LightKind, position: Vec3, direction: Vec3, power: Vec3) -> LightPose {
    LightPose {
        kind,
        position,
        direction: direction.normalize(),
        power,
        size: [0.0, 0.0],
    }
}

/// An omni light off the box's centre (no ray runs along a quad's diagonal).
fn box_light() -> LightPose {
    light(
        LightKind::Omni,
        Vec3::new(0.37, 0.41, 0.53) * BOX,
        Vec3::NEG_Y,
        Vec3::new(100.0, 200.0, 50.0),
    )
}

fn settings(paths: u32, bounces: u32, first_path: u64) -> VplSettings {
    VplSettings {
        paths,
        bounces,
        first_path,
        normalisation_paths: paths,
        average_reflectance: None,
    }
}

fn assert_rel(actual: Vec3, expected: Vec3, tol: f32, what: &str) {
    for c in 0..3 {
        let rel = (actual[c] - expected[c]).abs() / expected[c].abs();
        assert!(
            rel <= tol,
            "{what}: channel {c}: {} vs {} (relative {rel})",
            actual[c],
            expected[c]
        );
    }
}

/// Halton points `1..=n` in dims 0, 1.
fn points(n: u64) -> impl Iterator<Item = (f64, f64)> {
    (1..=n).map(|i| (halton(i, 0), halton(i, 1)))
}

#[test]
fn vpl_halton_values() {
    let base2: Vec<f64> = (1..=4).map(|i| radical_inverse(2, i)).collect();
    assert_eq!(base2, [0.5, 0.25, 0.75, 0.125]);
    let base3: Vec<f64> = (1..=6).map(|i| radical_inverse(3, i)).collect();
    let expected = [
        1.0 / 3.0,
        2.0 / 3.0,
        1.0 / 9.0,
        4.0 / 9.0,
        7.0 / 9.0,
        2.0 / 9.0,
    ];
    for (a, e) in base3.iter().zip(expected) {
        assert!((a - e).abs() < 1e-15, "{base3:?}");
    }
    assert_eq!(radical_inverse(2, 0), 0.0);
    // Dims use the primes 2, 3, 5, 7, …: index 1 is 1/p in every dim.
    let primes = [2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53];
    for (dim, p) in primes.into_iter().enumerate() {
        assert!((halton(1, dim) - 1.0 / p as f64).abs() < 1e-15, "dim {dim}");
        assert_eq!(halton(12345, dim), radical_inverse(p, 12345));
    }
    for dim in 0..32 {
        for i in 0..2000u64 {
            let x = halton(i, dim);
            assert!((0.0..1.0).contains(&x), "halton({i}, {dim}) = {x}");
        }
    }
}

#[test]
fn vpl_disc_to_hemisphere_is_cosine_distributed() {
    let n = 4096;
    let (mut sum_cos, mut above_60) = (0.0f64, 0usize);
    for (u, v) in points(n) {
        let p = square_to_disc(u, v);
        let d = disc_to_hemisphere(p);
        assert!((d.length() - 1.0).abs() < 1e-5, "{d}");
        assert!(d.z >= 0.0);
        assert_eq!(hemisphere_to_disc(d), p);
        sum_cos += d.z as f64;
        if d.z as f64 > 60f64.to_radians().cos() {
            above_60 += 1;
        }
    }
    let mean_cos = sum_cos / n as f64;
    assert!(
        (mean_cos - 2.0 / 3.0).abs() < 0.01,
        "mean cos θ = {mean_cos}"
    );
    let frac = above_60 as f64 / n as f64;
    assert!((frac - 0.75).abs() < 0.01, "fraction within 60° = {frac}");
}

#[test]
fn vpl_square_to_disc_is_uniform() {
    let n = 4096;
    let mut inner = 0usize;
    let mut quadrants = [0usize; 4];
    for (u, v) in points(n) {
        let p = square_to_disc(u, v);
        assert!(p.length() <= 1.0 + 1e-6, "{p}");
        if p.length() < 0.5 {
            inner += 1;
        }
        quadrants[(p.x < 0.0) as usize + 2 * (p.y < 0.0) as usize] += 1;
    }
    let frac = inner as f64 / n as f64;
    assert!(
        (frac - 0.25).abs() < 0.01,
        "fraction within r = 0.5: {frac}"
    );
    for q in quadrants {
        assert!((q as f64 / n as f64 - 0.25).abs() < 0.01, "{quadrants:?}");
    }
    assert_eq!(square_to_disc(0.5, 0.5), Vec2::ZERO);
}

#[test]
fn vpl_square_to_sphere_is_uniform() {
    let n = 4096;
    let mut mean = Vec3::ZERO;
    let mut octants = [0usize; 8];
    for (u, v) in points(n) {
        let d = square_to_sphere(u, v);
        assert!((d.length() - 1.0).abs() < 1e-5, "{d}");
        mean += d;
        octants[(d.x < 0.0) as usize + 2 * (d.y < 0.0) as usize + 4 * (d.z < 0.0) as usize] += 1;
    }
    mean /= n as f32;
    assert!(mean.length() < 0.01, "mean direction {mean}");
    for o in octants {
        assert!((o as f64 / n as f64 - 0.125).abs() < 0.01, "{octants:?}");
    }
}

#[test]
fn vpl_closed_box_flux_is_power_times_albedo() {
    let s = closed_box();
    let bvh = SceneBvh::new(&s.mesh);
    let l = box_light();
    let vpls = generate(&s, &bvh, &l, &settings(1024, 1, 0));
    assert_eq!(vpls.len(), 1024, "every path hits the closed box");
    assert_rel(total_flux(&vpls), l.power * ALBEDO, 1e-4, "total flux");
    for (i, v) in vpls.iter().enumerate() {
        assert_eq!(v.bounce, 1);
        assert_eq!(v.path, i as u64);
        assert_eq!(v.color, ALBEDO);
        assert!((v.normal.length() - 1.0).abs() < 1e-5);
        assert!(v.normal.dot(l.position - v.position) > 0.0);
        // Omni samples are the world direction of the first ray.
        let dir = (v.position - l.position).normalize();
        assert!((dir - v.sample).length() < 1e-3, "{dir} vs {}", v.sample);
    }
    // Zero power still places the VPLs, with zero flux.
    let dark = LightPose {
        power: Vec3::ZERO,
        ..l
    };
    let dark_vpls = generate(&s, &bvh, &dark, &settings(1024, 1, 0));
    assert_eq!(dark_vpls.len(), 1024);
    assert_eq!(total_flux(&dark_vpls), Vec3::ZERO);
    for (a, b) in vpls.iter().zip(&dark_vpls) {
        assert_eq!(a.position, b.position);
    }
}

#[test]
fn vpl_closed_box_area_light_flux() {
    let s = closed_box();
    let bvh = SceneBvh::new(&s.mesh);
    let l = LightPose {
        kind: LightKind::Area,
        position: Vec3::new(0.5, 0.99, 0.45) * BOX,
        direction: Vec3::NEG_Y,
        power: Vec3::splat(10.0),
        size: [1.0, 0.5],
    };
    let vpls = generate(&s, &bvh, &l, &settings(512, 1, 0));
    assert_eq!(vpls.len(), 512);
    assert_rel(total_flux(&vpls), l.power * ALBEDO, 1e-4, "area light flux");
    for v in &vpls {
        // Samples live on the unit disc (the light's domain) and map to cosine directions
        // about −Y: every ray goes down from the rectangle.
        assert_eq!(v.sample.z, 0.0);
        assert!(v.sample.truncate().length() <= 1.0 + 1e-6);
        let (_, d) = l.ray_of_sample(v.sample, &s.extent);
        assert!(d.y < 0.0, "{d}");
        assert!(v.position.y < l.position.y);
    }
}

#[test]
fn vpl_closed_box_multi_bounce_fractional_absorption() {
    let s = closed_box();
    let bvh = SceneBvh::new(&s.mesh);
    let l = box_light();
    let paths = 1024;
    let rho_bar = mean_reflectance(&s);
    assert!((rho_bar - 0.6).abs() < 1e-5);
    let vpls = generate(&s, &bvh, &l, &settings(paths, 3, 0));
    let mut expected_albedo = Vec3::ONE;
    for j in 1..=3u32 {
        expected_albedo *= ALBEDO;
        let bounce: Vec<Vpl> = vpls.iter().copied().filter(|v| v.bounce == j).collect();
        let count = continuing_paths(rho_bar, paths, j);
        assert_eq!(
            count,
            (rho_bar.powi(j as i32 - 1) as f64 * paths as f64).floor() as u32
        );
        assert_eq!(bounce.len() as u32, count, "bounce {j}");
        // The first paths continue.
        for (i, v) in bounce.iter().enumerate() {
            assert_eq!(v.path, i as u64);
        }
        // ⌊ρ̄^(j−1) N⌋ paths reach bounce j, each weighted by N over that count: exact.
        assert_rel(
            total_flux(&bounce),
            l.power * expected_albedo,
            2e-3,
            &format!("bounce {j} flux"),
        );
    }
    // Paths are listed path by path, bounces in order.
    let first_path: Vec<u32> = vpls
        .iter()
        .filter(|v| v.path == 0)
        .map(|v| v.bounce)
        .collect();
    assert_eq!(first_path, [1, 2, 3]);
    // Continued vertices are seen from the previous one along its normal's side.
    for w in vpls.windows(2) {
        if w[1].bounce == w[0].bounce + 1 {
            let d = w[1].position - w[0].position;
            assert!(d.dot(w[0].normal) > 0.0 && w[1].normal.dot(-d) > 0.0);
        }
    }
    // A given ρ̄ overrides the scene's.
    let half = VplSettings {
        average_reflectance: Some(0.5),
        ..settings(paths, 3, 0)
    };
    let vpls = generate(&s, &bvh, &l, &half);
    assert_eq!(vpls.iter().filter(|v| v.bounce == 2).count(), 512);
    assert_eq!(vpls.iter().filter(|v| v.bounce == 3).count(), 256);
}

#[test]
fn vpl_cornell_spot_vpls_lie_on_the_mesh_and_face_the_light() {
    let s = Scene::load_named("cornell", &AssetPaths::standard(None)).unwrap();
    let l = FrameClock::new(&s.descriptor).frame(0).light;
    assert_eq!(l.kind, LightKind::Spot);
    let bvh = SceneBvh::new(&s.mesh);
    let eps = s.extent.ray_epsilon;
    let vpls = generate(&s, &bvh, &l, &settings(256, 1, 0));
    assert!(vpls.len() > 200, "{} VPLs", vpls.len());
    let max_albedo = s
        .materials
        .iter()
        .map(|m| m.average_color.max_element())
        .fold(0.0f32, f32::max);
    let total = total_flux(&vpls);
    for c in 0..3 {
        assert!(
            total[c] <= l.power[c] * max_albedo * (1.0 + 1e-5),
            "{total}"
        );
        assert!(total[c] > 0.0);
    }
    for v in &vpls {
        let to_vpl = v.position - l.position;
        let hit = bvh
            .closest_hit(l.position, to_vpl.normalize(), eps, f32::INFINITY)
            .expect("the ray towards a VPL hits");
        assert!(
            (hit.position - v.position).length() < 10.0 * eps,
            "VPL {} vs hit {}",
            v.position,
            hit.position
        );
        assert!(
            v.normal.dot(-to_vpl) > 0.0,
            "normal {} faces away",
            v.normal
        );
        assert!(v.flux.cmple(l.power / 256.0 * max_albedo * 1.00001).all());
        // The spot's sample is the disc point of the direction in the spot's frame.
        assert_eq!(v.sample.z, 0.0);
        assert!(v.sample.truncate().length() <= 1.0 + 1e-6);
        let local = to_local(to_vpl.normalize(), l.direction);
        assert!(local.z >= -1e-4);
        assert!(
            (local.truncate() - v.sample.truncate()).length() < 1e-3,
            "{local} vs {}",
            v.sample
        );
        assert!((l.sample_of_point(v.position, &s.extent) - v.sample).length() < 1e-3);
    }
}

#[test]
fn vpl_spot_sampling_matches_the_cosine_distribution() {
    // ε = 10⁻⁴ × the diagonal (0.028) stays well below the light's height.
    let s = plane(100.0);
    let bvh = SceneBvh::new(&s.mesh);
    let l = light(
        LightKind::Spot,
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::NEG_Y,
        Vec3::splat(1000.0),
    );
    let vpls = generate(&s, &bvh, &l, &settings(1024, 1, 0));
    assert!(vpls.len() >= 1020, "{} VPLs", vpls.len());
    let expected = l.power * ALBEDO;
    let inner: Vec3 = vpls
        .iter()
        .filter(|v| v.sample.truncate().length() < 0.5)
        .map(|v| v.flux)
        .sum();
    let frac = inner.x / expected.x;
    assert!((frac - 0.25).abs() < 0.01, "flux within r = 0.5: {frac}");
    // Directions within 60° of the axis carry 3/4 of the flux (I ∝ cos θ).
    let within_60: Vec3 = vpls
        .iter()
        .filter(|v| (v.position - l.position).normalize().dot(l.direction) > 0.5)
        .map(|v| v.flux)
        .sum();
    let frac = within_60.x / expected.x;
    assert!((frac - 0.75).abs() < 0.01, "flux within 60°: {frac}");
    // Nothing lands behind the spot, and the flux sums to Φ ρ (up to the grazing misses).
    assert!(vpls.iter().all(|v| v.position.y.abs() < 1e-3));
    assert_rel(total_flux(&vpls), expected, 0.005, "spot flux");
}

#[test]
fn vpl_incremental_continuation_matches_one_call() {
    let s = closed_box();
    let bvh = SceneBvh::new(&s.mesh);
    let l = box_light();
    let all = generate(&s, &bvh, &l, &settings(128, 1, 0));
    let first = VplSettings {
        normalisation_paths: 128,
        ..settings(64, 1, 0)
    };
    let second = VplSettings {
        first_path: 64,
        ..first
    };
    let mut joined = generate(&s, &bvh, &l, &first);
    joined.extend(generate(&s, &bvh, &l, &second));
    assert_eq!(joined, all);
    // Same positions whatever the normalisation; the flux scales with it.
    let unnormalised = generate(&s, &bvh, &l, &settings(64, 1, 64));
    for (a, b) in unnormalised.iter().zip(&all[64..]) {
        assert_eq!(a.position, b.position);
        assert_eq!(a.path, b.path);
        assert!((a.flux - 2.0 * b.flux).length() <= 1e-5 * a.flux.length());
    }
}

#[test]
fn vpl_generation_is_deterministic_and_total() {
    let s = closed_box();
    let bvh = SceneBvh::new(&s.mesh);
    let l = box_light();
    let a = generate(&s, &bvh, &l, &settings(300, 4, 17));
    let b = generate(&s, &bvh, &l, &settings(300, 4, 17));
    assert_eq!(a, b);
    assert!(a
        .iter()
        .all(|v| v.flux.is_finite() && v.position.is_finite()));
    // Degenerate inputs give nothing, without panicking.
    assert!(generate(&s, &bvh, &l, &settings(0, 1, 0)).is_empty());
    assert!(generate(&s, &bvh, &l, &settings(16, 0, 0)).is_empty());
    let empty = scene(Mesh::default(), Vec::new());
    let empty_bvh = SceneBvh::new(&empty.mesh);
    assert!(generate(&empty, &empty_bvh, &l, &settings(16, 3, 0)).is_empty());
    // A light outside a plane facing away from it: every ray misses.
    let p = plane(1.0);
    let away = light(
        LightKind::Spot,
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::Y,
        Vec3::ONE,
    );
    assert!(generate(&p, &SceneBvh::new(&p.mesh), &away, &settings(64, 2, 1)).is_empty());
}
