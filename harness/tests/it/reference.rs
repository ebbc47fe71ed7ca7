//! The CPU reference renderer against closed forms (point and area lights over a plane, a
//! white-furnace box), its statistics (1/√spp error, determinism) and a colour-bleeding sanity
//! check on the Cornell box. Test scenes are built in code. No GPU needed.

use std::f32::consts::PI;

use gibench_harness::cpu::reference::{
    camera_ray, render_reference, render_reference_timed, ReferenceImages, ReferenceSettings,
    ReferenceTracer,
};
use gibench_harness::glam::{Mat4, Vec2, Vec3};
use gibench_harness::scene::anim::{CameraPose, FrameClock, FrameState, LightPose};
use gibench_harness::scene::assets::AssetPaths;
use gibench_harness::scene::descriptor::LightKind;
use gibench_harness::scene::{Material, Mesh, Mover, Scene, Texture};

use gibench_test_support::scene::{self as support, material, quad, scene};

/// The square [−h, h]² in the y = 0 plane, facing +Y.
fn plane(h: f32) -> Mesh {
    let mut m = Mesh::default();
    let v = |x, z| Vec3::new(x, 0.0, z);
    quad(&mut m, [v(-h, -h), v(-h, h), v(h, h), v(h, -h)], Vec3::Y, 0);
    m
}

fn frame(eye: Vec3, target: Vec3, light: LightPose) -> FrameState {
    FrameState {
        index: 0,
        time: 0.0,
        camera: CameraPose {
            position: eye,
            target,
            up: Vec3::Y,
            fov_y_rad: 60f32.to_radians(),
            near: 0.1,
        },
        light,
        movers: Vec::new(),
    }
}

fn light(
    kind: LightKind,
    position: Vec3,
    direction: Vec3,
    power: f32,
    size: [f32; 2],
) -> LightPose {
    LightPose {
        kind,
        position,
        direction: direction.normalize(),
        power: Vec3::splat(power),
        size,
    }
}

fn cornell() -> (Scene, FrameState) {
    let scene = Scene::load_named("cornell", &AssetPaths::standard(None)).unwrap();
    let frame = FrameClock::new(&scene.descriptor).frame(0);
    (scene, frame)
}

/// Root-mean-square difference over hit pixels and channels.
fn rmse(a: &[Vec3], b: &[Vec3], mask: &[bool]) -> f64 {
    let (mut sum, mut n) = (0.0f64, 0usize);
    for i in 0..a.len() {
        if mask[i] {
            let d = a[i] - b[i];
            sum += d.length_squared() as f64;
            n += 3;
        }
    }
    (sum / n.max(1) as f64).sqrt()
}

fn bits(v: &[Vec3]) -> Vec<[u32; 3]> {
    v.iter().map(|c| c.to_array().map(f32::to_bits)).collect()
}

fn assert_bit_identical(a: &ReferenceImages, b: &ReferenceImages) {
    assert_eq!(a.hit, b.hit);
    for (x, y) in [
        (&a.albedo, &b.albedo),
        (&a.direct, &b.direct),
        (&a.one_bounce, &b.one_bounce),
        (&a.multi_bounce, &b.multi_bounce),
        (&a.radiance, &b.radiance),
    ] {
        assert!(bits(x) == bits(y), "images differ");
    }
}

#[test]
fn reference_camera_ray_goes_through_pixel_centres() {
    let f = frame(
        Vec3::new(1.0, 4.0, 6.0),
        Vec3::new(0.5, 0.0, 0.0),
        light(LightKind::Omni, Vec3::Y, Vec3::NEG_Y, 1.0, [0.0; 2]),
    );
    let res = [40, 30];
    let vp = f.camera.projection(40.0 / 30.0) * f.camera.view();
    for (x, y) in [(0, 0), (39, 29), (17, 3), (20, 15)] {
        let (o, d) = camera_ray(&f, res, x, y);
        assert_eq!(o, f.camera.position);
        assert!((d.length() - 1.0).abs() < 1e-5);
        let clip = vp * (o + 7.0 * d).extend(1.0);
        let ndc = clip.truncate() / clip.w;
        let expected = Vec2::new(
            (x as f32 + 0.5) / 40.0 * 2.0 - 1.0,
            1.0 - (y as f32 + 0.5) / 30.0 * 2.0,
        );
        assert!(
            Vec2::new(ndc.x, ndc.y).abs_diff_eq(expected, 1e-4),
            "({x}, {y}): {ndc} vs {expected}"
        );
    }
}

/// Direct irradiance over a plane from point lights equals I(ω) cos θ / r²; nothing bounces.
#[test]
fn reference_point_lights_over_a_plane_match_closed_form() {
    let s = scene(plane(50.0), vec![material("grey", Vec3::splat(0.6))]);
    let lpos = Vec3::new(0.7, 3.0, -0.4);
    let lights = [
        light(LightKind::Omni, lpos, Vec3::NEG_Y, 1000.0, [0.0; 2]),
        light(
            LightKind::Spot,
            lpos,
            Vec3::new(0.3, -1.0, 0.2),
            1000.0,
            [0.0; 2],
        ),
        // Nearly horizontal: part of the plane is behind the spot and gets nothing.
        light(
            LightKind::Spot,
            lpos,
            Vec3::new(1.0, -0.15, 0.0),
            1000.0,
            [0.0; 2],
        ),
    ];
    let res = [48, 36];
    let settings = ReferenceSettings {
        spp: 4,
        bounces: 3,
        seed: 7,
    };
    for l in lights {
        let f = frame(Vec3::new(0.0, 6.0, 7.0), Vec3::ZERO, l);
        let img = render_reference(&s, &f, res, &settings);
        let (mut checked, mut dark) = (0, 0);
        for y in 0..res[1] {
            for x in 0..res[0] {
                let i = (y * res[0] + x) as usize;
                let (o, d) = camera_ray(&f, res, x, y);
                let t = -o.y / d.y;
                assert!(
                    img.hit[i] && t > 0.0,
                    "pixel ({x}, {y}) should see the plane"
                );
                let p = o + t * d;
                let to = l.position - p;
                let r2 = to.length_squared();
                let w = to / r2.sqrt();
                let intensity = match l.kind {
                    LightKind::Omni => 1000.0 / (4.0 * PI),
                    _ => 1000.0 / PI * (-w).dot(l.direction).max(0.0),
                };
                let expected = intensity * w.y / r2;
                let got = img.direct[i];
                assert!(got.x == got.y && got.y == got.z);
                assert!(
                    (got.x - expected).abs() <= 1e-4 * expected + 1e-9,
                    "{:?} pixel ({x}, {y}): {} vs {expected}",
                    l.kind,
                    got.x
                );
                if expected == 0.0 {
                    dark += 1;
                }
                checked += 1;
                assert_eq!(img.one_bounce[i], Vec3::ZERO);
                assert_eq!(img.multi_bounce[i], Vec3::ZERO);
                assert_eq!(img.albedo[i], Vec3::splat(0.6));
                let r = img.albedo[i] / PI * got;
                assert!(img.radiance[i].abs_diff_eq(r, 1e-6 * r.x.max(1.0)));
            }
        }
        assert_eq!(checked, res[0] * res[1]);
        if l.direction.y > -0.5 {
            assert!(dark > 50, "the plane behind the spot should be dark");
        }
    }
}

/// Irradiance at a point on the axis-parallel rectangle's plane, `c` below it, from a corner
/// rectangle [0, a] × [0, b] (signed: negative extents subtract): π L F with the view factor
/// F = 1/2π [A/√(1+A²) atan(B/√(1+A²)) + B/√(1+B²) atan(A/√(1+B²))], A = a/c, B = b/c.
fn corner_irradiance(l: f64, a: f64, b: f64, c: f64) -> f64 {
    let (aa, bb) = ((a / c).abs(), (b / c).abs());
    let sa = (1.0 + aa * aa).sqrt();
    let sb = (1.0 + bb * bb).sqrt();
    let f =
        (aa / sa * (bb / sa).atan() + bb / sb * (aa / sb).atan()) / (2.0 * std::f64::consts::PI);
    a.signum() * b.signum() * std::f64::consts::PI * l * f
}

#[test]
fn reference_area_light_matches_closed_form() {
    let s = scene(plane(50.0), vec![material("grey", Vec3::splat(0.6))]);
    let (w, h, c) = (2.0f32, 1.0f32, 1.5f32);
    let centre = Vec3::new(0.3, c, -0.2);
    let power = 500.0;
    // Facing straight down: width along +X, height along +Z (see the module docs).
    let l = light(LightKind::Area, centre, Vec3::NEG_Y, power, [w, h]);
    let f = frame(Vec3::new(0.0, 6.0, 7.0), Vec3::ZERO, l);
    let tracer = ReferenceTracer::new(&s, &f);
    let settings = ReferenceSettings {
        spp: 256,
        bounces: 1,
        seed: 3,
    };
    let radiance = power as f64 / (PI as f64 * (w * h) as f64);
    for (k, p) in [
        Vec3::new(0.3, 0.0, -0.2),
        Vec3::new(1.0, 0.0, 0.1),
        Vec3::new(2.5, 0.0, -1.5),
    ]
    .into_iter()
    .enumerate()
    {
        let (x0, x1) = (
            (centre.x - w / 2.0 - p.x) as f64,
            (centre.x + w / 2.0 - p.x) as f64,
        );
        let (z0, z1) = (
            (centre.z - h / 2.0 - p.z) as f64,
            (centre.z + h / 2.0 - p.z) as f64,
        );
        let e = |a, b| corner_irradiance(radiance, a, b, c as f64);
        let expected = e(x1, z1) - e(x0, z1) - e(x1, z0) + e(x0, z0);
        let got = tracer.irradiance_at(p, Vec3::Y, Vec3::Y, &settings, k as u64);
        assert!(
            (got.direct.x as f64 - expected).abs() <= 5e-3 * expected,
            "at {p}: {} vs {expected}",
            got.direct.x
        );
        assert_eq!(got.one_bounce, Vec3::ZERO);
    }
    // Behind the one-sided light: nothing.
    let up = light(LightKind::Area, centre, Vec3::Y, power, [w, h]);
    let f = frame(Vec3::new(0.0, 6.0, 7.0), Vec3::ZERO, up);
    let got =
        ReferenceTracer::new(&s, &f).irradiance_at(Vec3::ZERO, Vec3::Y, Vec3::Y, &settings, 0);
    assert_eq!(got.direct, Vec3::ZERO);
}

/// Movers are placed by the frame's transforms, cast shadows and reflect light.
#[test]
fn reference_movers_cast_shadows() {
    let mut s = scene(plane(50.0), vec![material("grey", Vec3::splat(0.5))]);
    let mut m = Mesh::default();
    let v = |x, z| Vec3::new(x, 0.0, z);
    quad(
        &mut m,
        [v(-1.0, -1.0), v(-1.0, 1.0), v(1.0, 1.0), v(1.0, -1.0)],
        Vec3::Y,
        0,
    );
    s.movers.push(Mover {
        name: "card".into(),
        mesh: m,
    });
    let l = light(
        LightKind::Omni,
        Vec3::new(0.0, 3.0, 0.0),
        Vec3::NEG_Y,
        100.0,
        [0.0; 2],
    );
    let mut f = frame(Vec3::new(0.0, 6.0, 7.0), Vec3::ZERO, l);
    let settings = ReferenceSettings {
        spp: 64,
        bounces: 2,
        seed: 1,
    };
    f.movers = vec![Mat4::from_translation(Vec3::new(0.0, 1.5, 0.0))];
    let t = ReferenceTracer::new(&s, &f);
    let under = t.irradiance_at(Vec3::ZERO, Vec3::Y, Vec3::Y, &settings, 0);
    assert_eq!(under.direct, Vec3::ZERO);
    // Light reflected by the lit plane comes back off the card's underside (two bounces).
    assert!(under.multi_bounce.x > 0.0);
    let aside = t.irradiance_at(Vec3::new(4.0, 0.0, 0.0), Vec3::Y, Vec3::Y, &settings, 1);
    assert!(aside.direct.x > 0.0);
    // The top of the card is lit.
    let top = t.irradiance_at(Vec3::new(0.0, 1.5, 0.0), Vec3::Y, Vec3::Y, &settings, 2);
    assert!(top.direct.x > 0.0);
    // Moved away: no shadow.
    f.movers = vec![Mat4::from_translation(Vec3::new(0.0, 1.5, 30.0))];
    let t = ReferenceTracer::new(&s, &f);
    let e = t.irradiance_at(Vec3::ZERO, Vec3::Y, Vec3::Y, &settings, 0);
    assert!((e.direct.x - 100.0 / (4.0 * PI) / 9.0).abs() < 1e-4 * e.direct.x);
}

#[test]
fn reference_texture_albedo_is_bilinear_srgb_repeat() {
    let mut s = scene(plane(1.0), vec![]);
    // 2 × 2: red, green / blue, white (sRGB 255 and 0 decode to 1 and 0 exactly).
    s.textures.push(Texture {
        name: "checker".into(),
        width: 2,
        height: 2,
        rgba8: vec![
            255, 0, 0, 255, 0, 255, 0, 255, //
            0, 0, 255, 255, 255, 255, 255, 255,
        ],
    });
    s.materials.push(Material {
        texture: Some(0),
        ..material("tex", Vec3::new(0.5, 1.0, 1.0))
    });
    let l = light(LightKind::Omni, Vec3::Y, Vec3::NEG_Y, 1.0, [0.0; 2]);
    let t = ReferenceTracer::new(&s, &frame(Vec3::new(0.0, 6.0, 7.0), Vec3::ZERO, l));
    let close = |a: Vec3, b: Vec3| assert!(a.abs_diff_eq(b, 1e-6), "{a} vs {b}");
    // Texel centres.
    close(t.albedo(0, Vec2::new(0.25, 0.25)), Vec3::new(0.5, 0.0, 0.0));
    close(t.albedo(0, Vec2::new(0.75, 0.25)), Vec3::new(0.0, 1.0, 0.0));
    close(t.albedo(0, Vec2::new(0.25, 0.75)), Vec3::new(0.0, 0.0, 1.0));
    // Repeat: one period over.
    close(
        t.albedo(0, Vec2::new(-0.75, 2.75)),
        Vec3::new(0.0, 0.0, 1.0),
    );
    // The corner (0, 0) averages all four texels (wrapping), in linear space.
    close(t.albedo(0, Vec2::ZERO), Vec3::new(0.5 * 0.5, 0.5, 0.5));
    // Halfway between red and green: (0.5, 0.5, 0) before the base colour.
    close(t.albedo(0, Vec2::new(0.5, 0.25)), Vec3::new(0.25, 0.5, 0.0));
    // sRGB 128 decodes to about 0.2158.
    s.textures[0].rgba8 = vec![128; 16];
    let t = ReferenceTracer::new(&s, &frame(Vec3::new(0.0, 6.0, 7.0), Vec3::ZERO, l));
    let a = t.albedo(0, Vec2::new(0.3, 0.6));
    assert!((a.y - 0.21586).abs() < 1e-4, "{a}");
}

/// A closed box with albedo ρ everywhere and an omni light inside: every emitted watt lands on
/// the walls, so the area-mean irradiance of bounce k is (Φ/A) ρ^k. Points are drawn uniformly
/// by area; each gets a few paths.
#[test]
fn reference_white_furnace_box() {
    let rho = 0.5f32;
    let size = Vec3::new(4.0, 3.0, 5.0);
    let corner = |x: f32, y: f32, z: f32| Vec3::new(x, y, z) * size;
    // Six inward-facing faces: (corners, inward normal).
    let faces = support::unit_box_faces();
    let m = support::closed_box_mesh(size, 0);
    let s = scene(m, vec![material("grey", Vec3::splat(rho))]);
    let power = 100.0;
    let l = light(
        LightKind::Omni,
        Vec3::new(1.3, 1.7, 2.2),
        Vec3::NEG_Y,
        power,
        [0.0; 2],
    );
    let t = ReferenceTracer::new(
        &s,
        &frame(Vec3::new(2.0, 1.5, 0.5), Vec3::new(2.0, 1.5, 4.0), l),
    );
    let bounces = 5;
    let settings = ReferenceSettings {
        spp: 4,
        bounces,
        seed: 11,
    };
    let area = 2.0 * (size.x * size.y + size.y * size.z + size.x * size.z);
    // Stratified by face: each face gets points in proportion to its area (a jittered grid).
    let (mut direct, mut one, mut multi) = (0.0f64, 0.0f64, 0.0f64);
    let mut stream = 0u64;
    for (c, n) in faces {
        let [p0, p1, _, p3] = c.map(|(x, y, z)| corner(x, y, z));
        let (e1, e2) = (p1 - p0, p3 - p0);
        let face_area = e1.cross(e2).length();
        // About 6000 points over the whole box.
        let cells = ((6000.0 * face_area / area).sqrt().ceil()) as u32;
        let weight = (face_area / area) as f64 / (cells * cells) as f64;
        for i in 0..cells {
            for j in 0..cells {
                // A fixed jitter pattern (golden-ratio offsets) keeps the test deterministic.
                let h = |k: u64, a: f64| ((k as f64 * a).fract()) as f32;
                let u = (i as f32 + h(stream + 1, 0.618_033_988_7)) / cells as f32;
                let v = (j as f32 + h(stream + 1, 0.754_877_666_2)) / cells as f32;
                let p = p0 + u * e1 + v * e2;
                let e = t.irradiance_at(p, n, n, &settings, stream);
                stream += 1;
                direct += weight * e.direct.x as f64;
                one += weight * e.one_bounce.x as f64;
                multi += weight * e.multi_bounce.x as f64;
            }
        }
    }
    let e0 = (power / area) as f64;
    let rho = rho as f64;
    let expected_multi: f64 = (1..=bounces).map(|k| e0 * rho.powi(k as i32)).sum();
    let rel = |got: f64, want: f64| (got - want).abs() / want;
    eprintln!(
        "furnace: direct {direct} / {e0}, one {one} / {}, multi {multi} / {expected_multi}",
        e0 * rho
    );
    assert!(rel(direct, e0) < 0.01, "direct {direct} vs {e0}");
    assert!(
        rel(one, e0 * rho) < 0.03,
        "one bounce {one} vs {}",
        e0 * rho
    );
    assert!(
        rel(multi, expected_multi) < 0.03,
        "multi {multi} vs {expected_multi}"
    );
}

/// In a closed box lit from inside by an omni light every ray hits a wall facing the light, so
/// the rays a render traces are known exactly: per pixel one camera ray and one shadow ray,
/// per path `bounces` segments each with its shadow ray. Catches a ray traced but not counted
/// (or counted twice: the counts feed `scripts/compare_mitsuba.py`'s per-ray ratio) and pixels'
/// counts lost when they are summed.
#[test]
fn reference_counts_the_rays_it_traces() {
    let size = Vec3::new(4.0, 3.0, 5.0);
    let s = scene(
        support::closed_box_mesh(size, 0),
        vec![material("grey", Vec3::splat(0.5))],
    );
    let l = light(
        LightKind::Omni,
        Vec3::new(1.3, 1.7, 2.2),
        Vec3::NEG_Y,
        100.0,
        [0.0; 2],
    );
    let f = frame(Vec3::new(2.0, 1.5, 0.5), Vec3::new(2.0, 1.5, 4.0), l);
    let settings = ReferenceSettings {
        spp: 3,
        bounces: 4,
        seed: 5,
    };
    let (r, setup) = render_reference_timed(&s, &f, [16, 12], &settings);
    let pixels = 16 * 12u64;
    assert!(r.hit.iter().all(|&h| h), "the camera is inside the box");
    let paths = pixels * settings.spp as u64;
    let rays = setup.rays;
    assert_eq!(rays.closest, pixels + paths * settings.bounces as u64);
    assert_eq!(rays.shadow, pixels + paths * settings.bounces as u64);
    assert_eq!(rays.total(), rays.closest + rays.shadow);
}

/// The error between two seeds falls (at least) as 1/√spp: 4× the paths divide it by 2 for
/// plain Monte Carlo. The first bounce's directions are stratified, which converges faster
/// where the integrand is smooth (up to spp^(−3/4), a factor 2.83, for a 2D integrand with
/// edges such as shadow and light boundaries), so the factor may exceed 2; 3.0 is the bound.
#[test]
fn reference_error_falls_at_least_as_inverse_sqrt_spp() {
    let (scene, frame) = cornell();
    let res = [48, 36];
    let render = |spp, seed| {
        render_reference(
            &scene,
            &frame,
            res,
            &ReferenceSettings {
                spp,
                bounces: 4,
                seed,
            },
        )
    };
    let n = 16;
    let s0: u64 = std::env::var("REF_SEED")
        .ok()
        .map_or(1, |v| v.parse().unwrap());
    let (a, b) = (render(n, s0), render(n, s0 + 1));
    let (c, d) = (render(4 * n, s0), render(4 * n, s0 + 1));
    for (name, lo, hi) in [
        (
            "one_bounce",
            rmse(&a.one_bounce, &b.one_bounce, &a.hit),
            rmse(&c.one_bounce, &d.one_bounce, &a.hit),
        ),
        (
            "multi_bounce",
            rmse(&a.multi_bounce, &b.multi_bounce, &a.hit),
            rmse(&c.multi_bounce, &d.multi_bounce, &a.hit),
        ),
    ] {
        let ratio = lo / hi;
        eprintln!(
            "{name}: RMSE {lo} at {n} spp, {hi} at {} spp: ratio {ratio}",
            4 * n
        );
        assert!((1.6..=3.0).contains(&ratio), "{name}: ratio {ratio}");
    }
}

#[test]
fn reference_is_deterministic_per_seed() {
    let (scene, frame) = cornell();
    let res = [24, 18];
    let settings = ReferenceSettings {
        spp: 8,
        bounces: 3,
        seed: 5,
    };
    let a = render_reference(&scene, &frame, res, &settings);
    let b = render_reference(&scene, &frame, res, &settings);
    assert_bit_identical(&a, &b);
    // Whatever the number of threads.
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let c = one_thread.install(|| render_reference(&scene, &frame, res, &settings));
    assert_bit_identical(&a, &c);
    let three = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .unwrap();
    let d = three.install(|| render_reference(&scene, &frame, res, &settings));
    assert_bit_identical(&a, &d);

    let other = render_reference(
        &scene,
        &frame,
        res,
        &ReferenceSettings {
            seed: 6,
            ..settings
        },
    );
    assert_eq!(a.hit, other.hit);
    assert_eq!(
        bits(&a.direct),
        bits(&other.direct),
        "a spot light has no noise"
    );
    assert!(bits(&a.one_bounce) != bits(&other.one_bounce));
    assert!(bits(&a.multi_bounce) != bits(&other.multi_bounce));
    // The composed radiance is ρ/π (direct + multi_bounce), and radiance_with agrees.
    let r = a.radiance_with(&a.multi_bounce);
    assert_eq!(r.len(), a.pixel_count());
    for (x, y) in r.iter().zip(&a.radiance) {
        assert!(x.abs_diff_eq(*y, 1e-6 * y.max_element().max(1.0)));
    }
    assert!(a.hit.iter().filter(|h| **h).count() > res[0] as usize * res[1] as usize / 2);
}

/// Light bouncing off the red wall tints the floor and back wall next to it red; the green wall
/// tints its side green.
#[test]
fn reference_cornell_colour_bleeding() {
    let (scene, frame) = cornell();
    let t = ReferenceTracer::new(&scene, &frame);
    let settings = ReferenceSettings {
        spp: 1024,
        bounces: 1,
        seed: 9,
    };
    let floor_n = Vec3::Y;
    let back_n = Vec3::NEG_Z;
    // The red wall is at x ≈ 556, the green one at x = 0.
    let near_red = [
        (Vec3::new(530.0, 0.0, 300.0), floor_n),
        (Vec3::new(535.0, 300.0, 559.2), back_n),
    ];
    let near_green = [
        (Vec3::new(25.0, 0.0, 300.0), floor_n),
        (Vec3::new(20.0, 300.0, 559.2), back_n),
    ];
    for (k, (p, n)) in near_red.into_iter().enumerate() {
        let e = t.irradiance_at(p, n, n, &settings, k as u64).one_bounce;
        assert!(
            e.x > 1.3 * e.y && e.x > 1.3 * e.z,
            "near the red wall at {p}: {e}"
        );
    }
    for (k, (p, n)) in near_green.into_iter().enumerate() {
        let e = t
            .irradiance_at(p, n, n, &settings, 10 + k as u64)
            .one_bounce;
        assert!(
            e.y > 1.3 * e.x && e.y > 1.3 * e.z,
            "near the green wall at {p}: {e}"
        );
    }
    // The same in a rendered image: floor pixels near the red wall have R > G.
    let img = render_reference(
        &scene,
        &frame,
        [32, 24],
        &ReferenceSettings {
            spp: 64,
            bounces: 1,
            seed: 9,
        },
    );
    let [w, h] = img.size;
    let (mut red_pixels, mut sum) = (0, Vec3::ZERO);
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let (o, d) = camera_ray(&frame, img.size, x, y);
            let Some(hit) = t.bvh().closest_hit(o, d, 0.0, f32::INFINITY) else {
                continue;
            };
            if hit.position.y < 1.0 && hit.position.x > 480.0 {
                red_pixels += 1;
                sum += img.one_bounce[i];
            }
        }
    }
    assert!(
        red_pixels > 3,
        "{red_pixels} floor pixels near the red wall"
    );
    assert!(sum.x > 1.3 * sum.y, "floor near the red wall: {sum}");
}

/// Relative MSE over hit pixels and channels: mean of (a − b)² / (b² + 10⁻² mean(b)²).
fn relative_mse(a: &[Vec3], b: &[Vec3], mask: &[bool]) -> f64 {
    let idx: Vec<usize> = (0..a.len()).filter(|&i| mask[i]).collect();
    let mean_b = idx
        .iter()
        .map(|&i| b[i].to_array().iter().map(|&c| c as f64).sum::<f64>())
        .sum::<f64>()
        / (3 * idx.len().max(1)) as f64;
    let floor = 1e-2 * mean_b * mean_b;
    let mut sum = 0.0;
    for &i in &idx {
        for c in 0..3 {
            let (x, y) = (a[i][c] as f64, b[i][c] as f64);
            sum += (x - y).powi(2) / (y * y + floor);
        }
    }
    sum / (3 * idx.len().max(1)) as f64
}

/// Timing and noise of the default settings on the Cornell box at 256 × 192 (frame 0): run with
/// `cargo test --release -p gibench-harness --test it --
/// reference::reference_default_settings_timing_and_noise --ignored --nocapture`.
#[test]
#[ignore = "slow: measures the default settings"]
fn reference_default_settings_timing_and_noise() {
    let (scene, frame) = cornell();
    let res = [256, 192];
    let settings = ReferenceSettings::default();
    let start = std::time::Instant::now();
    let a = render_reference(&scene, &frame, res, &settings);
    let seconds = start.elapsed().as_secs_f64();
    let b = render_reference(
        &scene,
        &frame,
        res,
        &ReferenceSettings {
            seed: 1,
            ..settings
        },
    );
    eprintln!(
        "cornell 256x192, {settings:?}: {seconds:.2} s on {} threads; relMSE between seeds 0 and 1: one_bounce {:.3e}, multi_bounce {:.3e}, radiance {:.3e}",
        rayon::current_num_threads(),
        relative_mse(&a.one_bounce, &b.one_bounce, &a.hit),
        relative_mse(&a.multi_bounce, &b.multi_bounce, &a.hit),
        relative_mse(&a.radiance, &b.radiance, &a.hit),
    );
}

/// The reference's two levels (the scene's static tree, built once, and the movers' trees per
/// frame) answer as one tree over the frame's whole mesh, the way the reference traced before
/// them: on the Cornell box with the walking bunny, at three frames, every closest-hit record
/// (triangle id, `t`, barycentrics, normals, uv, material) is bit for bit the one tree's, and
/// every any-hit answer the same, for camera rays, rays aimed at the bunny and rays in random
/// directions; the frame's bounds (the ray offset ε's diagonal) are the frame mesh's. One
/// static build serves the three frames, and each frame builds the bunny's tree once. Catches
/// a mover's triangles numbered from the wrong offset, a mover tree asked for hits beyond the
/// best so far (a farther mover hit would replace a nearer static one), a mover transformed
/// otherwise than `frame_mesh` does, bounds that leave a part out, and a static tree rebuilt
/// per frame.
#[test]
fn reference_trees_answer_as_one_tree_over_the_frame_mesh() {
    use gibench_harness::cpu::bvh::{SceneBvh, SceneTrees, TreeBuilds};
    use gibench_harness::cpu::reference::frame_mesh;
    use gibench_harness::rng::SplitMix64;
    let scene = Scene::load_named("cornell-bunny", &AssetPaths::standard(None)).unwrap();
    let clock = FrameClock::new(&scene.descriptor);
    let trees = SceneTrees::new(&scene);
    let statics = scene.mesh.triangle_count() as u32;
    let mut rng = SplitMix64::new(7, 0);
    let unit = |rng: &mut SplitMix64| loop {
        let v = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
        if v.length_squared() > 1e-4 && v.length_squared() <= 1.0 {
            break v.normalize();
        }
    };
    let (mut on_mover, mut rays) = (0, 0);
    for f in [0, 40, 90] {
        let frame = clock.frame(f);
        let (two, bounds) = trees.frame(&frame);
        let mesh = frame_mesh(&scene, &frame);
        let one = SceneBvh::new(&mesh);
        assert_eq!(bounds, mesh.bounds(), "frame {f}");
        assert_eq!(two.triangle_count(), one.triangle_count());
        let bunny = frame.movers[0].transform_point3(Vec3::ZERO);
        let mut cast = |origin: Vec3, dir: Vec3| {
            let (a, b) = (
                two.closest_hit(origin, dir, 0.0, f32::INFINITY),
                one.closest_hit(origin, dir, 0.0, f32::INFINITY),
            );
            assert_eq!(a, b, "frame {f}: {origin} {dir}");
            assert_eq!(
                two.any_hit(origin, dir, 0.0, f32::INFINITY),
                one.any_hit(origin, dir, 0.0, f32::INFINITY)
            );
            rays += 1;
            on_mover += a.is_some_and(|h| h.triangle >= statics) as u32;
        };
        for y in (0..96).step_by(3) {
            for x in (0..128).step_by(3) {
                let (o, d) = camera_ray(&frame, [128, 96], x, y);
                cast(o, d);
            }
        }
        for _ in 0..3000 {
            let o = Vec3::new(20.0, 20.0, 20.0)
                + Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 510.0;
            let target = bunny + unit(&mut rng) * 40.0;
            cast(o, (target - o).normalize());
            cast(o, unit(&mut rng));
        }
    }
    assert!(on_mover > 1000, "{on_mover} of {rays} rays hit the bunny");
    assert_eq!(
        trees.builds(),
        TreeBuilds {
            static_tree: 1,
            mover_trees: 3
        }
    );
}
