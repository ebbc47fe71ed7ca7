//! PRT: an orthonormal 25-coefficient basis, the unshadowed transfer reproducing the clamped
//! cosine within the band limit, self-shadowing that darkens a cavity, and a light sample's
//! irradiance through lighting · transfer.

use gibench_barczak::prt::{basis, irradiance, lighting, transfer, COEFFS};
use gibench_harness::cpu::bvh::SceneBvh;
use gibench_harness::cpu::vpl::{fibonacci_sphere, Vpl};
use gibench_harness::glam::{Mat3, Vec3};
use gibench_harness::scene::Mesh;

use gibench_test_support::quad;

#[test]
fn basis_is_orthonormal() {
    let n = 40_000;
    let dirs = fibonacci_sphere(n);
    let mut gram = [[0f64; COEFFS]; COEFFS];
    for d in &dirs {
        let y = basis(*d);
        for (row, yi) in gram.iter_mut().zip(&y) {
            for (g, yj) in row.iter_mut().zip(&y) {
                *g += (yi * yj) as f64 * 4.0 * std::f64::consts::PI / n as f64;
            }
        }
    }
    for (i, row) in gram.iter().enumerate() {
        for (j, g) in row.iter().enumerate() {
            let want = (i == j) as u8 as f64;
            assert!((g - want).abs() < 2e-3, "<Y{i}, Y{j}> = {g}");
        }
    }
    // The band-0 and band-1 terms in closed form (z polar, x for m = 1, y for m = −1).
    let c0 = 0.5 / std::f32::consts::PI.sqrt();
    let c1 = (3.0f32).sqrt() * c0;
    let d = Vec3::new(0.36, 0.48, 0.8);
    let y = basis(d);
    assert!((y[0] - c0).abs() < 1e-6 && (y[1] - c1 * d.y).abs() < 1e-6);
    assert!((y[2] - c1 * d.z).abs() < 1e-6 && (y[3] - c1 * d.x).abs() < 1e-6);
}

/// A 2 × 2 quad in y = 0 facing +Y, and an open-top unit box (floor and four walls facing in).
fn plane() -> Mesh {
    let mut m = Mesh::default();
    let v = |x, z| Vec3::new(x, 0.0, z);
    quad(
        &mut m,
        [v(-1., -1.), v(-1., 1.), v(1., 1.), v(1., -1.)],
        Vec3::Y,
        0,
    );
    m
}

fn cavity() -> Mesh {
    let mut m = plane();
    let h = 2.0;
    let v = Vec3::new;
    quad(
        &mut m,
        [
            v(-1., 0., -1.),
            v(1., 0., -1.),
            v(1., h, -1.),
            v(-1., h, -1.),
        ],
        Vec3::Z,
        0,
    );
    quad(
        &mut m,
        [v(-1., 0., 1.), v(-1., h, 1.), v(1., h, 1.), v(1., 0., 1.)],
        Vec3::NEG_Z,
        0,
    );
    quad(
        &mut m,
        [
            v(-1., 0., -1.),
            v(-1., h, -1.),
            v(-1., h, 1.),
            v(-1., 0., 1.),
        ],
        Vec3::X,
        0,
    );
    quad(
        &mut m,
        [v(1., 0., -1.), v(1., 0., 1.), v(1., h, 1.), v(1., h, -1.)],
        Vec3::NEG_X,
        0,
    );
    m
}

/// The transfer of a vertex at the floor's centre.
fn centre_transfer(mut mesh: Mesh) -> [f32; COEFFS] {
    mesh.positions.push(Vec3::ZERO);
    mesh.normals.push(Vec3::Y);
    mesh.uvs.push(Default::default());
    mesh.materials.push(0);
    let bvh = SceneBvh::new(&mesh);
    *transfer(&mesh, &bvh, 4096, 1e-4).last().unwrap()
}

fn eval(t: &[f32; COEFFS], d: Vec3) -> f32 {
    basis(d).iter().zip(t).map(|(a, b)| a * b).sum()
}

/// Unshadowed, Σ Tₖ Yₖ(ω) is the clamped cosine max(0, n·ω) cut at band 4, whose Legendre
/// series is 1/4 + x/2 + 5/16 P₂(x) − 3/32 P₄(x) (x = n·ω): within 0.002 of it everywhere
/// (the cut itself is up to 0.059 off the clamped cosine, at the horizon).
#[test]
fn unshadowed_transfer_is_the_band_limited_clamped_cosine() {
    let t = centre_transfer(plane());
    let p2 = |x: f32| 0.5 * (3.0 * x * x - 1.0);
    let p4 = |x: f32| (35.0 * x.powi(4) - 30.0 * x * x + 3.0) / 8.0;
    let mut worst = 0f32;
    for d in fibonacci_sphere(2000) {
        let x = d.y;
        let series = 0.25 + 0.5 * x + 5.0 / 16.0 * p2(x) - 3.0 / 32.0 * p4(x);
        worst = worst.max((eval(&t, d) - series).abs());
    }
    assert!(worst < 2e-3, "{worst} off the band-4 clamped cosine");
}

/// At the bottom of a 2-deep, 2-wide open box the sky is visible only within about 35° of the
/// zenith: light from 60° off the zenith is mostly shadowed and the transfer's ambient term is
/// far below the open plane's.
#[test]
fn self_shadowing_darkens_a_cavity() {
    let open = centre_transfer(plane());
    let deep = centre_transfer(cavity());
    let oblique = Vec3::new(60f32.to_radians().sin(), 60f32.to_radians().cos(), 0.0);
    let zenith = Vec3::Y;
    eprintln!(
        "zenith {} vs {}, 60° {} vs {}, ambient {} vs {}",
        eval(&deep, zenith),
        eval(&open, zenith),
        eval(&deep, oblique),
        eval(&open, oblique),
        deep[0],
        open[0]
    );
    assert!(eval(&deep, oblique) < 0.3 * eval(&open, oblique));
    assert!(eval(&deep, zenith) > 0.5 * eval(&open, zenith));
    assert!(deep[0] < 0.5 * open[0]);
}

/// One light sample 2 m above the vertex, facing it: irradiance Φ/π / 4, within the band
/// limit's 4 %; invisible or facing away, nothing.
#[test]
fn a_light_sample_lights_through_lighting_dot_transfer() {
    let t = centre_transfer(plane());
    let sample = Vpl {
        position: Vec3::new(0.0, 2.0, 0.0),
        normal: Vec3::NEG_Y,
        flux: Vec3::new(10.0, 20.0, 30.0),
        color: Vec3::ONE,
        bounce: 1,
        path: 0,
        sample: Vec3::ZERO,
    };
    let l = lighting(Vec3::ZERO, Mat3::IDENTITY, &[sample], |_| true);
    let e = irradiance(&t, &l);
    let exact = sample.flux / std::f32::consts::PI / 4.0;
    assert!(
        ((e - exact).abs() / exact).max_element() < 0.04,
        "{e} vs {exact}"
    );
    assert_eq!(
        irradiance(
            &t,
            &lighting(Vec3::ZERO, Mat3::IDENTITY, &[sample], |_| false)
        ),
        Vec3::ZERO
    );
    let away = Vpl {
        normal: Vec3::Y,
        ..sample
    };
    assert_eq!(
        irradiance(&t, &lighting(Vec3::ZERO, Mat3::IDENTITY, &[away], |_| true)),
        Vec3::ZERO
    );
}

/// The lighting meets object-space transfer through the object's rotation: the plane turned
/// 90° about z (its normal now −x in the world) is lit by a sample on the world's −x side as the
/// unturned plane is by one above it (without the rotation that sample would be at the plane's
/// horizon: 6 % of it, the band limit's ringing).
#[test]
fn lighting_is_taken_into_the_objects_frame() {
    let t = centre_transfer(plane());
    let turn = Mat3::from_rotation_z(std::f32::consts::FRAC_PI_2);
    let to_object = turn.transpose();
    let world_normal = turn * Vec3::Y;
    let sample = |at: Vec3| Vpl {
        position: at,
        normal: -at.normalize(),
        flux: Vec3::splat(10.0),
        color: Vec3::ONE,
        bounce: 1,
        path: 0,
        sample: Vec3::ZERO,
    };
    let beside = sample(world_normal * 2.0);
    let above = sample(Vec3::Y * 2.0);
    let lit = irradiance(&t, &lighting(Vec3::ZERO, to_object, &[beside], |_| true));
    let unturned = irradiance(
        &t,
        &lighting(Vec3::ZERO, Mat3::IDENTITY, &[above], |_| true),
    );
    assert!(
        (lit - unturned).abs().max_element() < 1e-4 * unturned.max_element(),
        "{lit} vs {unturned}"
    );
}
