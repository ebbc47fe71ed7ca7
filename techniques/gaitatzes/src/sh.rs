//! Second-order spherical harmonics (bands l = 0 and 1: four coefficients per colour channel),
//! the convention every `gaitatzes` shader uses (Gaitatzes et al. 2010, Eq. 1–2). Public light
//! propagation volume code disagrees on the sign and order of the l = 1 terms; this is the one
//! place gibench fixes them, and [`wgsl`] hands the same constants to the shaders.
//!
//! * Order: `[Y₀⁰, Y₁⁻¹, Y₁⁰, Y₁¹]`.
//! * Basis (real SH, no Condon–Shortley phase, z the polar axis): Y₀⁰ = 1 / (2√π),
//!   Y₁⁻¹ = √3 / (2√π) · y, Y₁⁰ = √3 / (2√π) · z, Y₁¹ = √3 / (2√π) · x.
//! * The projection of f is ∫ f(ω) Yₖ(ω) dω; by orthonormality the integral of a product of two
//!   projected functions is the dot product of their coefficients (Eq. 4).
//! * Radiance L(ω) is stored as the direction light *travels*; the irradiance of a surface with
//!   normal n is ∫ L(ω) max(0, −n·ω) dω = L · [`clamped_cosine`]`(−n)` (Eq. 9–12).

use glam::Vec3;

/// Y₀⁰.
pub const C0: f32 = 0.282_094_8;
/// The factor of the l = 1 functions.
pub const C1: f32 = 0.488_602_5;

/// The basis functions at unit direction `d`.
pub fn basis(d: Vec3) -> [f32; 4] {
    [C0, C1 * d.y, C1 * d.z, C1 * d.x]
}

/// Coefficients of a band-0 + band-1 lobe with DC factor `a` and axis factor `b` along `d`.
fn lobe(a: f32, b: f32, d: Vec3) -> [f32; 4] {
    [a, b * d.y, b * d.z, b * d.x]
}

/// The projection of the clamped cosine max(0, d·ω) about unit `d`: ∫ max(0, d·ω) Y(ω) dω =
/// (π Y₀⁰, 2π/3 · √3/(2√π) · d) — exact for bands 0 and 1.
pub fn clamped_cosine(d: Vec3) -> [f32; 4] {
    lobe(
        std::f32::consts::PI * C0,
        2.0 * std::f32::consts::PI / 3.0 * C1,
        d,
    )
}

/// The projection of the indicator of the "90-degree cone" through one face of a voxel: the
/// pyramid from the voxel's centre through the face whose axis is unit `d` (apex angle 90°).
/// The six tile the sphere, so the six faces' integrals of any function add up to its
/// integral. (Ω Y₀⁰, X · √3/(2√π) · d) with Ω = 4π/6 and X = ∫ cos θ dω over the face =
/// 2√2 · atan(1/√2).
pub fn face(d: Vec3) -> [f32; 4] {
    let solid = 4.0 * std::f32::consts::PI / 6.0;
    let axis = 2.0 * std::f32::consts::SQRT_2 * (1.0 / std::f32::consts::SQRT_2).atan();
    lobe(solid * C0, axis * C1, d)
}

/// The clamped-cosine lobe of unit integral about unit `d`: [`clamped_cosine`]`(d) / π`. The
/// propagation stores the flux Φ crossing a face towards `d` (per face area s², in the units of
/// the radiance integral ∫ L dω) as Φ times this lobe.
pub fn cosine_unit(d: Vec3) -> [f32; 4] {
    clamped_cosine(d).map(|c| c / std::f32::consts::PI)
}

/// What turns the reconstruction's SH dot product into irradiance. A unit-integral
/// clamped-cosine lobe arriving head-on at a surface (travelling along −n) stands for a flux
/// density of 1 through the surface, which is its irradiance; its dot product with the clamped
/// cosine about −n is not 1 but π(Y₀⁰)² + (2π/3)²(√3/(2√π))²/π = 1/4 + 1/3 = 7/12 (the
/// band-limited lobe 1/4 + cos θ/2 spreads part of its flux sideways, and the cosine weighting
/// of that spread loses it). The reconstruction multiplies by the reciprocal, 12/7, so that the
/// flux that the propagation delivers into an occupied cell through the face its surface faces
/// becomes exactly that surface's irradiance. (A lobe arriving sideways, through a face
/// perpendicular to the surface, is weighted 12/7 · 1/4 = 3/7; occupied cells receive flux only
/// from the void in front of them, so that arises only at edges and corners.)
pub fn flux_to_irradiance() -> f32 {
    // A lobe travelling along z onto the surface with normal −z: the cosine about −n = z.
    1.0 / dot(&cosine_unit(Vec3::Z), &clamped_cosine(Vec3::Z))
}

/// The irradiance of a surface with unit normal `n` from accumulated incident radiance `c`
/// (travel-direction convention): [`flux_to_irradiance`] · `c` · [`clamped_cosine`]`(−n)`,
/// floored at 0.
pub fn irradiance(c: &[f32; 4], n: Vec3) -> f32 {
    (flux_to_irradiance() * dot(c, &clamped_cosine(-n))).max(0.0)
}

/// ∫ (ω·d)² dω over the face pyramid about `d` (its second moment along its axis); across the
/// axis each of the two other directions gets (4π/6 − this) / 2. By quadrature of
/// ∫∫ (1 + u² + v²)^(−5/2) du dv over [−1, 1]² (the face at distance 1).
pub const FACE_MOMENT_AXIAL: f32 = 1.467_932_1;

/// The first moment ∫ L(ω) ω dω of band-limited radiance `c` over the face pyramid about unit
/// axis `d`: (Y₀⁰ c₀) X d + (√3/(2√π)) M (c_x, c_y, c_z), with X = ∫ ω·d dω over the pyramid and
/// M its second-moment matrix (axial [`FACE_MOMENT_AXIAL`], the rest across).
pub fn face_moment(c: &[f32; 4], d: Vec3) -> Vec3 {
    let x = 2.0 * std::f32::consts::SQRT_2 * (1.0 / std::f32::consts::SQRT_2).atan();
    let across = (4.0 * std::f32::consts::PI / 6.0 - FACE_MOMENT_AXIAL) / 2.0;
    let v = Vec3::new(c[3], c[1], c[2]);
    C0 * c[0] * x * d + C1 * (across * v + (FACE_MOMENT_AXIAL - across) * v.dot(d) * d)
}

/// Dot product of two coefficient vectors (the integral of the product of the functions).
pub fn dot(a: &[f32; 4], b: &[f32; 4]) -> f32 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Value at unit `d` of the function with coefficients `c`.
pub fn eval(c: &[f32; 4], d: Vec3) -> f32 {
    dot(c, &basis(d))
}

/// The convention as WGSL constants (`SH_C0`, `SH_C1`, the face pyramid's
/// `SH_FACE0`/`SH_FACE1`, the clamped cosine's `SH_COS0`/`SH_COS1`, [`flux_to_irradiance`] as
/// `SH_FLUX_TO_IRRADIANCE`) and functions: `sh_lobe(a, b, d)`, `sh_face(d)`, `sh_cosine(d)`
/// (the clamped cosine about `d`), `sh_cosine_unit(d)` (the same divided by π: a lobe of unit
/// integral) and `sh_irradiance(c, n)` ([`irradiance`]).
pub fn wgsl() -> String {
    let c = face(Vec3::Z);
    let k = clamped_cosine(Vec3::Z);
    format!(
        "const SH_C0: f32 = {:.9e};\nconst SH_C1: f32 = {:.9e};\n\
         const SH_FACE0: f32 = {:.9e};\nconst SH_FACE1: f32 = {:.9e};\n\
         const SH_COS0: f32 = {:.9e};\nconst SH_COS1: f32 = {:.9e};\n\
         fn sh_lobe(a: f32, b: f32, d: vec3<f32>) -> vec4<f32> {{ return vec4<f32>(a, b * d.y, b * d.z, b * d.x); }}\n\
         fn sh_face(d: vec3<f32>) -> vec4<f32> {{ return sh_lobe(SH_FACE0, SH_FACE1, d); }}\n\
         fn sh_cosine(d: vec3<f32>) -> vec4<f32> {{ return sh_lobe(SH_COS0, SH_COS1, d); }}\n\
         fn sh_cosine_unit(d: vec3<f32>) -> vec4<f32> {{ return sh_lobe(SH_COS0 / 3.14159265, SH_COS1 / 3.14159265, d); }}\n\
         const SH_FLUX_TO_IRRADIANCE: f32 = {:.9e};\n\
         const SH_MOMENT_AXIAL: f32 = {:.9e};\n\
         fn sh_face_moment(c: vec4<f32>, d: vec3<f32>) -> vec3<f32> {{ let across = (4.0 * 3.14159265 / 6.0 - SH_MOMENT_AXIAL) / 2.0; let v = vec3<f32>(c.w, c.y, c.z); return SH_C0 * c.x * (SH_FACE1 / SH_C1) * d + SH_C1 * (across * v + (SH_MOMENT_AXIAL - across) * dot(v, d) * d); }}\n\
         fn sh_irradiance(c: vec4<f32>, n: vec3<f32>) -> f32 {{ return max(SH_FLUX_TO_IRRADIANCE * dot(c, sh_cosine(-n)), 0.0); }}\n",
        C0,
        C1,
        c[0],
        c[2],
        k[0],
        k[2],
        flux_to_irradiance(),
        FACE_MOMENT_AXIAL
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫ f(ω) g(ω) dω over the sphere by a fine midpoint rule in (cos θ, φ) (exact measure).
    fn integrate(f: impl Fn(Vec3) -> f32) -> f64 {
        let (nu, nphi) = (800, 1600);
        let mut sum = 0.0f64;
        for i in 0..nu {
            let z = -1.0 + (i as f64 + 0.5) * 2.0 / nu as f64;
            let r = (1.0 - z * z).sqrt();
            for j in 0..nphi {
                let phi = (j as f64 + 0.5) * std::f64::consts::TAU / nphi as f64;
                let d = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
                sum += f(d) as f64;
            }
        }
        sum * 4.0 * std::f64::consts::PI / (nu * nphi) as f64
    }

    fn dirs() -> [Vec3; 3] {
        [
            Vec3::Z,
            Vec3::new(0.3, -0.5, 0.8).normalize(),
            Vec3::new(-0.9, 0.1, -0.2).normalize(),
        ]
    }

    /// The basis is orthonormal under the sphere's measure.
    #[test]
    fn the_basis_is_orthonormal() {
        for a in 0..4 {
            for b in 0..4 {
                let v = integrate(|d| basis(d)[a] * basis(d)[b]);
                let want = if a == b { 1.0 } else { 0.0 };
                assert!((v - want).abs() < 1e-3, "<Y{a}, Y{b}> = {v}");
            }
        }
    }

    /// The clamped cosine's coefficients are its numerical projection, its band-limited
    /// reconstruction is the closed form 1/4 + cos θ / 2, and the irradiance of a uniform field
    /// of radiance 1 through it is π (exact in bands 0 and 1).
    #[test]
    fn clamped_cosine_projection_and_reconstruction_match_the_closed_form() {
        for n in dirs() {
            let c = clamped_cosine(n);
            for (k, ck) in c.iter().enumerate() {
                let v = integrate(|d| n.dot(d).max(0.0) * basis(d)[k]);
                assert!(
                    (v - *ck as f64).abs() < 1e-3,
                    "{n}: coefficient {k}: {v} vs {ck}"
                );
            }
            for d in dirs() {
                let want = 0.25 + 0.5 * n.dot(d);
                assert!((eval(&c, d) - want).abs() < 1e-5, "{n} at {d}");
            }
            // A uniform radiance of 1 has coefficients (√(4π), 0, 0, 0).
            let uniform = [(4.0 * std::f32::consts::PI).sqrt(), 0.0, 0.0, 0.0];
            assert!((dot(&uniform, &c) - std::f32::consts::PI).abs() < 1e-5);
        }
    }

    /// The flux-to-irradiance constant is the closed form 12/7, and with it a unit-integral
    /// clamped-cosine lobe gives a surface it meets head-on irradiance 1 and one it passes
    /// sideways 3/7; numerically, the lobe's band-limited radiance integrated against the
    /// clamped cosine is the 7/12 it corrects.
    #[test]
    fn flux_to_irradiance_is_twelve_sevenths() {
        assert!((flux_to_irradiance() - 12.0 / 7.0).abs() < 1e-5);
        for d in dirs() {
            let lobe = cosine_unit(d);
            assert!((irradiance(&lobe, -d) - 1.0).abs() < 1e-5, "head-on {d}");
            let side = d.any_orthonormal_vector();
            assert!(
                (irradiance(&lobe, side) - 3.0 / 7.0).abs() < 1e-5,
                "side {d}"
            );
            let v = integrate(|w| eval(&lobe, w) * d.dot(w).max(0.0));
            assert!((v - 7.0 / 12.0).abs() < 1e-3, "{d}: {v}");
        }
    }

    /// The pyramid's first moment of a band-limited function is its numerical integral (which
    /// checks the axial second moment too).
    #[test]
    fn face_moment_matches_its_integral() {
        let in_face = |n: Vec3, d: Vec3| {
            let m = d.abs().max_element();
            n.dot(d) > 0.0 && n.dot(d) >= m - 1e-7
        };
        let f = [0.7, -0.2, 0.3, 0.5];
        for n in [Vec3::X, Vec3::NEG_Y, Vec3::Z] {
            let m = face_moment(&f, n);
            for k in 0..3 {
                let v = integrate(|d| {
                    if in_face(n, d) {
                        eval(&f, d) * d[k]
                    } else {
                        0.0
                    }
                });
                assert!(
                    (v - m[k] as f64).abs() < 2e-3,
                    "{n}: component {k}: {v} vs {m}"
                );
            }
        }
    }

    /// The face pyramid's coefficients are its numerical projection, and the six faces'
    /// integrals of any band-limited function add up to its integral.
    #[test]
    fn face_projection_matches_its_integral_and_the_faces_tile_the_sphere() {
        let in_face = |n: Vec3, d: Vec3| {
            // d lies in the pyramid of face n when n's axis is its largest component.
            let a = d.abs();
            let m = a.max_element();
            n.dot(d) > 0.0 && (n.dot(d)).abs() >= m - 1e-7
        };
        for n in [Vec3::X, Vec3::NEG_Y, Vec3::Z] {
            let c = face(n);
            for (k, ck) in c.iter().enumerate() {
                let v = integrate(|d| if in_face(n, d) { basis(d)[k] } else { 0.0 });
                assert!(
                    (v - *ck as f64).abs() < 2e-3,
                    "{n}: coefficient {k}: {v} vs {ck}"
                );
            }
        }
        let f = [0.7, -0.2, 0.3, 0.5];
        let faces = [
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::NEG_Z,
        ];
        let sum: f32 = faces.iter().map(|d| dot(&f, &face(*d))).sum();
        // ∫ f = f₀ ∫ Y₀⁰ = f₀ · 4π Y₀⁰.
        let whole = f[0] * 4.0 * std::f32::consts::PI * C0;
        assert!((sum - whole).abs() < 1e-5, "{sum} vs {whole}");
    }
}
