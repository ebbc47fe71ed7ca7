//! Complex meshes by precomputed radiance transfer (Barczak 2006 §4.4, after Sloan et al. 2002).
//!
//! Reads: a complex object's mesh (object space) and its BVH; at run time the light samples, a
//! visibility query from the object's bounding-sphere centre, and the centre.
//! Writes: per vertex, 25 transfer coefficients (5th-order real spherical harmonics, bands
//! l = 0…4, not wavelength dependent: white objects, as the thesis'); per frame, the object's
//! lighting environment as 25 RGB coefficients; per vertex, irradiance as their dot product.
//!
//! * **Transfer** (prepared once, on the CPU by ray casts): Tₖ = ∫ V(x, ω) max(0, n·ω) Yₖ(ω) dω
//!   over `directions` Fibonacci-sphere directions, V the object's own self-shadowing (a ray
//!   from the vertex, lifted off its surface, that hits the mesh). Irradiance under a lighting
//!   environment L is then Σₖ Lₖ Tₖ (orthonormal basis).
//! * **Lighting** (every frame): each visible light sample i, seen from the centre C in
//!   direction ωᵢ = (Pᵢ − C)/|Pᵢ − C|, is a directional light of radiant intensity towards C over
//!   distance², Iᵢ = Φᵢ/π · max(0, −Nᵢ·ωᵢ) / |Pᵢ − C|² (the thesis' Lᵢ with the sample's flux),
//!   projected onto the basis, Lₖ += Iᵢ Yₖ(ωᵢ), and summed.
//!
//! The lighting is valid at the centre only (the thesis' §4.4.2: shadows cast *onto* the
//! object are blurred); the basis truncation smooths a point light's cosine (tested bounds).
//! The thesis used the DirectX SDK's PRT simulator and D3DX's projection; these are our own.

use gibench_harness::cpu::bvh::SceneBvh;
use gibench_harness::cpu::vpl::{fibonacci_sphere, Vpl};
use gibench_harness::scene::Mesh;
use glam::Vec3;

/// Coefficients of 5th-order SH: (4 + 1)².
pub const COEFFS: usize = 25;

/// The real orthonormal SH basis Y_l^m (l ≤ 4, m = −l…l, index l² + l + m) at unit `d`, z the
/// polar axis: Y_l^m = K_l^m P_l^|m|(z) · (√2 cos mφ | 1 | √2 sin |m|φ) for m > 0 | 0 | < 0,
/// with P the associated Legendre functions without the Condon–Shortley phase.
pub fn basis(d: Vec3) -> [f32; COEFFS] {
    let d = d.normalize_or(Vec3::Z).as_dvec3();
    let (x, y, z) = (d.x, d.y, d.z);
    // P_l^m(z) by the standard recurrences, for l, m ≤ 4 (no (−1)^m phase).
    let s = (1.0 - z * z).max(0.0).sqrt();
    let mut p = [[0f64; 5]; 5];
    p[0][0] = 1.0;
    for m in 1..5 {
        p[m][m] = p[m - 1][m - 1] * (2 * m - 1) as f64 * s;
    }
    for m in 0..4 {
        p[m + 1][m] = z * (2 * m + 1) as f64 * p[m][m];
    }
    #[allow(clippy::needless_range_loop)]
    for m in 0..5 {
        for l in m + 2..5 {
            p[l][m] = ((2 * l - 1) as f64 * z * p[l - 1][m] - (l + m - 1) as f64 * p[l - 2][m])
                / (l - m) as f64;
        }
    }
    let phi = y.atan2(x);
    let fact = |n: usize| (1..=n).map(|k| k as f64).product::<f64>();
    let mut out = [0f32; COEFFS];
    for l in 0..5usize {
        for m in -(l as i64)..=(l as i64) {
            let am = m.unsigned_abs() as usize;
            let k = ((2 * l + 1) as f64 / (4.0 * std::f64::consts::PI) * fact(l - am)
                / fact(l + am))
            .sqrt();
            let v = match m.cmp(&0) {
                std::cmp::Ordering::Greater => {
                    std::f64::consts::SQRT_2 * k * (m as f64 * phi).cos() * p[l][am]
                }
                std::cmp::Ordering::Equal => k * p[l][0],
                std::cmp::Ordering::Less => {
                    std::f64::consts::SQRT_2 * k * (am as f64 * phi).sin() * p[l][am]
                }
            };
            out[l * l + (l as i64 + m) as usize] = v as f32;
        }
    }
    out
}

/// Per-vertex transfer of `mesh` (see the module docs), self-shadowed against `bvh` (the same
/// mesh's), from `directions` directions; rays start `lift` off the surface.
pub fn transfer(mesh: &Mesh, bvh: &SceneBvh, directions: usize, lift: f32) -> Vec<[f32; COEFFS]> {
    let dirs = fibonacci_sphere(directions);
    let basis: Vec<[f32; COEFFS]> = dirs.iter().map(|d| basis(*d)).collect();
    let weight = 4.0 * std::f32::consts::PI / directions as f32;
    mesh.positions
        .iter()
        .zip(&mesh.normals)
        .map(|(&p, &n)| {
            let mut t = [0f32; COEFFS];
            for (d, y) in dirs.iter().zip(&basis) {
                let cos = n.dot(*d);
                if cos <= 0.0 || bvh.any_hit(p + n * lift, *d, 0.0, f32::INFINITY) {
                    continue;
                }
                for k in 0..COEFFS {
                    t[k] += weight * cos * y[k];
                }
            }
            t
        })
        .collect()
}

/// The lighting environment at `center` from the light samples `lights`, of which `visible`
/// says which reach the centre (the thesis ray-traces this), in the object's frame:
/// `to_object` turns world directions into the object's (the inverse of its rotation), so that
/// it meets transfer computed in object space.
pub fn lighting(
    center: Vec3,
    to_object: glam::Mat3,
    lights: &[Vpl],
    visible: impl Fn(&Vpl) -> bool,
) -> [Vec3; COEFFS] {
    let mut l = [Vec3::ZERO; COEFFS];
    for v in lights {
        let d = v.position - center;
        let r2 = d.length_squared();
        if r2 <= 0.0 {
            continue;
        }
        let w = d / r2.sqrt();
        let cos = (-v.normal.dot(w)).max(0.0);
        if cos <= 0.0 || !visible(v) {
            continue;
        }
        let intensity = v.flux / std::f32::consts::PI * cos / r2;
        let y = basis(to_object * w);
        for k in 0..COEFFS {
            l[k] += intensity * y[k];
        }
    }
    l
}

/// A vertex's irradiance: Σₖ Lₖ Tₖ.
pub fn irradiance(transfer: &[f32; COEFFS], lighting: &[Vec3; COEFFS]) -> Vec3 {
    transfer.iter().zip(lighting).map(|(t, l)| *t * *l).sum()
}
