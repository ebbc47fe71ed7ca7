//! Virtual point light (VPL) generation for instant radiosity (Keller 1997), shared by the
//! Keller, Laine, Barczak and ISM techniques.
//!
//! ## What a VPL is
//!
//! A [`Vpl`] follows the crate's radiometric convention (see the crate docs): it sits on a
//! surface point with a unit normal facing the side the light came from and carries the RGB
//! radiant flux `Φ_vpl` *leaving* the surface, emitting like a cosine spot around its normal:
//! I(θ) = (Φ_vpl / π) cos θ. The albedo is already folded into the flux (a VPL on a red wall
//! carries red light); [`Vpl::color`] keeps the albedo for techniques that need it.
//!
//! ## Light paths
//!
//! [`generate`] traces `paths` quasi-random light paths. Path `i` of a call uses the Halton
//! point with index `h = first_path + i` ([`halton`]), so incremental techniques continue the
//! sequence by advancing `first_path`:
//!
//! * **First ray**: [`LightPose::emit`] (the one light model, [`crate::cpu::light`]) for Halton
//!   index `h`: spot lights lift a disc point to the hemisphere (Nusselt analog, Laine et al.
//!   2007 §4.1, Figure 3a/b); omni lights take a uniform direction (Figure 3c); area lights a
//!   uniform point on the rectangle and a cosine direction about its normal; the sun a uniform
//!   point on the disc covering the scene's bounding sphere, along its direction.
//!   [`Vpl::sample`] is the ray's point in the light's sampling domain (the unit disc, or the
//!   unit sphere for omni lights).
//!
//!   Every path carries [`LightPose::emitted_flux`]` / normalisation_paths` from the light (Φ,
//!   or the sun's E⊥ · πR²). A path whose first ray leaves the scene gives no VPL and its
//!   energy is *not* redistributed (it left the scene).
//! * **First hit** y₁: a VPL with flux `Φ / normalisation_paths · ρ(y₁)`, where ρ is the hit
//!   material's [`Material::average_color`](crate::scene::Material::average_color).
//! * **Further bounces** (Keller's fractional absorption, with the scene's average reflectance
//!   ρ̄, the mean of the RGB channels of
//!   [`Scene::average_reflectance`](crate::scene::Scene::average_reflectance)): of the N =
//!   `normalisation_paths` paths, C_j = ⌊ρ̄^(j−1) · N⌋ reach vertex j ([`continuing_paths`]):
//!   the path with Halton index h continues to vertex j iff `h mod N < C_j`. A call with
//!   `first_path = 0` and `paths = N` therefore continues its first C_j paths, and any N
//!   consecutive Halton indices (the ring of `keller-incremental`, however it is refilled) hold
//!   exactly the same counts. The new direction is cosine-weighted about the previous VPL's
//!   normal (Halton dims `4 + 2(j−2)`, `5 + 2(j−2)`), and the VPL at y_j carries
//!   Φ / C_j · ρ(y₁)…ρ(y_j) — Keller's weight N / C_j by the actual count — so bounce j carries
//!   exactly Φ ρ^j in a closed scene of uniform albedo. A continuation ray that misses the scene
//!   or points below the geometric surface (possible with interpolated normals) ends the path.
//!
//! Rays start `ε` = 10⁻⁴ × the static mesh's bounding-box diagonal
//! ([`SceneExtent::ray_epsilon`](crate::scene::SceneExtent), computed once at load; the same
//! rule as the reference's) off their origin: light rays ignore hits closer than ε to the light,
//! continuation rays start ε off the surface along the geometric normal.
//!
//! Everything is deterministic (no random numbers) and never panics: an empty mesh, zero paths
//! or zero bounces give an empty `Vec`. A zero (or non-finite, treated as zero) power still
//! places the VPLs, with zero flux, so positions never depend on the power. A hit on a
//! material index outside [`Scene::materials`](crate::scene::Scene::materials) counts as black
//! (a zero-flux VPL is still emitted, so VPL counts depend on geometry only).

use std::f64::consts::PI;

use glam::{Vec2, Vec3};

use crate::cpu::bvh::{Hit, SceneBvh};
use crate::scene::anim::LightPose;
use crate::scene::Scene;

/// The first 64 primes: the Halton bases of dims 0..64. Higher dims compute their prime.
const PRIMES: [u32; 64] = [
    2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53, 59, 61, 67, 71, 73, 79, 83, 89, 97,
    101, 103, 107, 109, 113, 127, 131, 137, 139, 149, 151, 157, 163, 167, 173, 179, 181, 191, 193,
    197, 199, 211, 223, 227, 229, 233, 239, 241, 251, 257, 263, 269, 271, 277, 281, 283, 293, 307,
    311,
];

/// The largest `f64` below 1.
const ONE_MINUS_EPSILON: f64 = 1.0 - f64::EPSILON / 2.0;

/// The `dim`-th prime (0-based: 2, 3, 5, 7, …).
fn nth_prime(dim: usize) -> u32 {
    if let Some(&p) = PRIMES.get(dim) {
        return p;
    }
    let mut count = PRIMES.len() - 1;
    let mut candidate = PRIMES[PRIMES.len() - 1];
    loop {
        candidate += 2;
        let is_prime = (3..)
            .step_by(2)
            .take_while(|d| d * d <= candidate)
            .all(|d| !candidate.is_multiple_of(d));
        if is_prime {
            count += 1;
            if count == dim {
                return candidate;
            }
        }
    }
}

/// The radical inverse of `index` in `base` (van der Corput): the digits of `index` mirrored
/// about the radix point, in [0, 1). `radical_inverse(2, 1..=4)` = 0.5, 0.25, 0.75, 0.125.
/// Bases below 2 give 0.
pub fn radical_inverse(base: u32, index: u64) -> f64 {
    if base < 2 {
        return 0.0;
    }
    let b = base as u64;
    let inv_base = 1.0 / base as f64;
    let mut n = index;
    let mut reversed = 0u64;
    let mut inv_base_n = 1.0f64;
    // Accumulate the mirrored digits as an integer while it cannot overflow (exact), then
    // continue in floating point.
    while n > 0 && reversed <= (u64::MAX - b) / b {
        reversed = reversed * b + n % b;
        n /= b;
        inv_base_n *= inv_base;
    }
    let mut value = reversed as f64 * inv_base_n;
    while n > 0 {
        inv_base_n *= inv_base;
        value += (n % b) as f64 * inv_base_n;
        n /= b;
    }
    value.min(ONE_MINUS_EPSILON)
}

/// Coordinate `dim` of Halton point `index`: [`radical_inverse`] in the `dim`-th prime base
/// (dims 0, 1, 2, … use 2, 3, 5, 7, 11, 13, 17, 19, 23, 29, …; any dim works, the first 64
/// bases are tabulated). Index 0 is the origin in every dim.
pub fn halton(index: u64, dim: usize) -> f64 {
    radical_inverse(nth_prime(dim), index)
}

/// Maps `(u, v)` in [0, 1)² uniformly onto the closed unit disc with the Shirley–Chiu
/// concentric mapping (area preserving, keeps strata compact; the square's border maps to the
/// circle).
pub fn square_to_disc(u: f64, v: f64) -> Vec2 {
    let a = 2.0 * u - 1.0;
    let b = 2.0 * v - 1.0;
    if a == 0.0 && b == 0.0 || !a.is_finite() || !b.is_finite() {
        return Vec2::ZERO;
    }
    let (r, phi) = if a.abs() > b.abs() {
        (a, PI / 4.0 * (b / a))
    } else {
        (b, PI / 2.0 - PI / 4.0 * (a / b))
    };
    Vec2::new((r * phi.cos()) as f32, (r * phi.sin()) as f32)
}

/// Lifts a unit-disc point `(x, y)` to the upper unit hemisphere around +Z:
/// `(x, y, √(1 − x² − y²))`. By the Nusselt analog, points uniform on the disc become
/// directions with density cos θ / π on the hemisphere (Laine et al. 2007, Figure 3a/b).
/// Points outside the disc are first projected radially onto its circle.
pub fn disc_to_hemisphere(p: Vec2) -> Vec3 {
    let len2 = p.length_squared();
    let p = if len2 > 1.0 { p / len2.sqrt() } else { p };
    let z = (1.0 - p.length_squared()).max(0.0).sqrt();
    p.extend(z)
}

/// The inverse of [`disc_to_hemisphere`]: drops z, mapping a direction of the hemisphere
/// around +Z to its point on the unit disc (Laine et al. 2007, Figure 3a).
pub fn hemisphere_to_disc(d: Vec3) -> Vec2 {
    d.truncate()
}

/// `n` deterministic unit directions spread evenly over the sphere (a Fibonacci lattice): ray
/// sets for benchmarks and instruction counts.
pub fn fibonacci_sphere(n: usize) -> Vec<Vec3> {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
            let r = (1.0 - z * z).sqrt();
            let phi = golden * i as f32;
            Vec3::new(r * phi.cos(), z, r * phi.sin())
        })
        .collect()
}

/// Maps `(u, v)` in [0, 1)² uniformly onto the unit sphere: z = 1 − 2u, azimuth 2πv (the
/// cylindrical, Archimedes projection, which preserves area).
pub fn square_to_sphere(u: f64, v: f64) -> Vec3 {
    let z = (1.0 - 2.0 * u).clamp(-1.0, 1.0);
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * v;
    Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32)
}

/// A deterministic right-handed orthonormal basis `(t, b)` for unit `n` (t × b = n), with the
/// branchless construction of Duff et al. 2017, "Building an Orthonormal Basis, Revisited".
/// For n = +Z it is (+X, +Y). A zero or non-finite `n` is treated as +Z.
pub fn frame_from_normal(n: Vec3) -> (Vec3, Vec3) {
    let n = n.normalize_or(Vec3::Z);
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// Transforms `local` from the frame `(t, b, n)` of [`frame_from_normal`] (z along `n`) to
/// world space.
pub fn to_world(local: Vec3, n: Vec3) -> Vec3 {
    let (t, b) = frame_from_normal(n);
    local.x * t + local.y * b + local.z * n.normalize_or(Vec3::Z)
}

/// Transforms world-space `v` into the frame `(t, b, n)` of [`frame_from_normal`]; the inverse
/// of [`to_world`].
pub fn to_local(v: Vec3, n: Vec3) -> Vec3 {
    let (t, b) = frame_from_normal(n);
    Vec3::new(v.dot(t), v.dot(b), v.dot(n.normalize_or(Vec3::Z)))
}

/// A unit direction with density cos θ / π about unit `n`, from `(u, v)` in [0, 1)²:
/// [`square_to_disc`] → [`disc_to_hemisphere`] → [`to_world`].
pub fn cosine_direction(n: Vec3, u: f64, v: f64) -> Vec3 {
    let n = n.normalize_or(Vec3::Z);
    to_world(disc_to_hemisphere(square_to_disc(u, v)), n).normalize_or(n)
}

/// A virtual point light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vpl {
    /// World-space position on the static mesh.
    pub position: Vec3,
    /// Unit shading normal, facing the side the light came from.
    pub normal: Vec3,
    /// RGB radiant flux leaving the surface: the VPL emits I(θ) = flux/π · cos θ around
    /// `normal`.
    pub flux: Vec3,
    /// Albedo at the hit (the material's `average_color`), already folded into `flux`.
    pub color: Vec3,
    /// Vertex number on its light path: 1 = first hit (single bounce of indirect light).
    pub bounce: u32,
    /// The light path's Halton index (`first_path + i`).
    pub path: u64,
    /// The path's first ray as a point of the light's sampling domain (Laine et al. 2007,
    /// Figure 3; see [`crate::cpu::light`]): `(x, y, 0)` on the unit disc for spot, area and sun
    /// lights, the unit direction for omni lights. Convert with
    /// [`LightPose::ray_of_sample`] / [`LightPose::sample_of_point`].
    pub sample: Vec3,
}

/// How many light paths to trace and how deep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VplSettings {
    /// Number N of light paths in this call (each gives at most `bounces` VPLs).
    pub paths: u32,
    /// Maximum vertices per path: 1 = single bounce (as in Laine et al. 2007).
    pub bounces: u32,
    /// Halton index of the first path; incremental techniques continue the sequence.
    pub first_path: u64,
    /// Every path carries Φ / `normalisation_paths` from the light; usually = `paths`.
    /// 0 means `paths`.
    pub normalisation_paths: u32,
    /// Keller's average reflectance ρ̄; `None` computes it from the scene (the mean of the
    /// channels of [`Scene::average_reflectance`], one pass over the static mesh). Values
    /// above 1 act as 1; zero, negative or non-finite values stop every path after its first
    /// hit.
    pub average_reflectance: Option<f32>,
}

impl VplSettings {
    /// `paths` single-bounce paths from Halton index 0, normalised by `paths`, with ρ̄ from the
    /// scene.
    pub fn new(paths: u32) -> Self {
        VplSettings {
            paths,
            bounces: 1,
            first_path: 0,
            normalisation_paths: paths,
            average_reflectance: None,
        }
    }
    /// The same settings with `bounces` vertices per path.
    pub fn with_bounces(self, bounces: u32) -> Self {
        VplSettings { bounces, ..self }
    }
}

impl Default for VplSettings {
    /// 256 single-bounce paths (Laine et al. 2007's VPL count).
    fn default() -> Self {
        VplSettings::new(256)
    }
}

/// Keller's ρ̄ for `scene`: the mean of the RGB channels of [`Scene::average_reflectance`].
pub fn mean_reflectance(scene: &Scene) -> f32 {
    let r = scene.average_reflectance();
    (r.x + r.y + r.z) / 3.0
}

/// ρ̄ clamped to the continuation probability in [0, 1] (non-finite → 0).
fn continuation_probability(average_reflectance: f32) -> f32 {
    if average_reflectance.is_finite() {
        average_reflectance.clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// Keller's fractional absorption: how many of a call's `paths` paths reach vertex `vertex`
/// (1-based): `⌊ρ̄^(vertex−1) · paths⌋` with ρ̄ clamped to [0, 1] (all paths reach vertex 1).
/// Paths `0 .. continuing_paths(…)` of the call continue.
pub fn continuing_paths(average_reflectance: f32, paths: u32, vertex: u32) -> u32 {
    if vertex <= 1 {
        return paths;
    }
    let q = continuation_probability(average_reflectance) as f64;
    let n = (q.powi((vertex - 1).min(i32::MAX as u32) as i32) * paths as f64).floor();
    (n.max(0.0) as u32).min(paths)
}

/// The albedo ρ a VPL uses for `material` (black when unknown).
fn albedo(scene: &Scene, material: u32) -> Vec3 {
    scene
        .materials
        .get(material as usize)
        .map_or(Vec3::ZERO, |m| m.average_color)
}

fn make_vpl(scene: &Scene, hit: &Hit, incoming: Vec3, bounce: u32, path: u64, sample: Vec3) -> Vpl {
    let color = albedo(scene, hit.material);
    Vpl {
        position: hit.position,
        normal: hit.shading_normal,
        flux: incoming * color,
        color,
        bounce,
        path,
        sample,
    }
}

/// A single first-bounce VPL from the light through the sampling point `sample` of the light's
/// [`SampleDomain`](crate::cpu::light::SampleDomain) ([`LightPose::ray_of_sample`]), carrying
/// `path_flux` · ρ; `None` if the ray leaves the scene. For area lights the ray starts at the
/// rectangle's centre. Laine's incremental method uses this to place a VPL at a chosen
/// sampling point; `path` is only recorded.
pub fn vpl_from_sample(
    scene: &Scene,
    bvh: &SceneBvh,
    light: &LightPose,
    sample: Vec3,
    path_flux: Vec3,
    path: u64,
) -> Option<Vpl> {
    let (origin, dir) = light.ray_of_sample(sample, &scene.extent);
    let hit = bvh.closest_hit(origin, dir, scene.extent.ray_epsilon, f32::INFINITY)?;
    Some(make_vpl(scene, &hit, path_flux, 1, path, sample))
}

/// Traces `settings.paths` light paths from `light` through the static geometry in `bvh` and
/// returns their VPLs, path by path (each path's VPLs in bounce order). See the module docs
/// for the sampling, the flux of each VPL and the fractional absorption. Costs one pass over
/// the mesh's triangles (ρ̄) unless `settings.average_reflectance` is given.
pub fn generate(
    scene: &Scene,
    bvh: &SceneBvh,
    light: &LightPose,
    settings: &VplSettings,
) -> Vec<Vpl> {
    let paths = settings.paths;
    if paths == 0 || settings.bounces == 0 || bvh.triangle_count() == 0 {
        return Vec::new();
    }
    let normalisation = if settings.normalisation_paths == 0 {
        paths
    } else {
        settings.normalisation_paths
    };
    let path_flux = light.emitted_flux(&scene.extent) / normalisation as f32;
    let eps = scene.extent.ray_epsilon;
    // Keller's ρ̄ as the continuation probability (only needed for more than one bounce).
    let q = if settings.bounces > 1 {
        continuation_probability(
            settings
                .average_reflectance
                .unwrap_or_else(|| mean_reflectance(scene)),
        )
    } else {
        0.0
    };
    let mut vpls = Vec::with_capacity(paths as usize);
    for i in 0..paths {
        let h = settings.first_path.wrapping_add(i as u64);
        let ray = light.emit(h, &scene.extent);
        let (origin, dir, sample) = (ray.origin, ray.direction, ray.sample);
        let Some(mut hit) = bvh.closest_hit(origin, dir, eps, f32::INFINITY) else {
            continue;
        };
        let mut vpl = make_vpl(scene, &hit, path_flux, 1, h, sample);
        vpls.push(vpl);
        // The path's place among the N, and how many of the N reached the previous vertex.
        let residue = h % normalisation as u64;
        let mut reaching = normalisation;
        for j in 2..=settings.bounces {
            // Keller's fractional absorption: ⌊ρ̄^(j−1) N⌋ of the N paths reach vertex j
            // (so q > 0 below).
            let continuing = continuing_paths(q, normalisation, j);
            if residue >= continuing as u64 {
                break;
            }
            let dim = 4 + 2 * (j as usize - 2);
            let d = cosine_direction(vpl.normal, halton(h, dim), halton(h, dim + 1));
            if d.dot(hit.geometric_normal) <= 0.0 {
                break;
            }
            let start = hit.position + eps * hit.geometric_normal;
            let Some(next) = bvh.closest_hit(start, d, 0.0, f32::INFINITY) else {
                break;
            };
            hit = next;
            // Φ / C_j · ρ₁…ρ_j: the previous vertex's flux re-weighted from C_{j−1} to C_j.
            let weight = reaching as f32 / continuing as f32;
            vpl = make_vpl(scene, &hit, vpl.flux * weight, j, h, sample);
            vpls.push(vpl);
            reaching = continuing;
        }
    }
    vpls
}

/// `keller-full`'s VPL count: the fewest light paths from Halton index 0 (each carrying
/// Φ / paths, `bounces` vertices, Keller's ρ̄ = `average_reflectance`) that give at least
/// `target` VPLs, and their VPLs. With one bounce the count is exactly `target` unless the
/// scene is (nearly) missed: at most 64 × `target` paths are traced. The VPL count grows with
/// the path count (each path's first hit is fixed by its Halton index), so the search is an
/// estimate from the hit rate followed by bisection.
pub fn generate_at_least(
    scene: &Scene,
    bvh: &SceneBvh,
    light: &LightPose,
    target: u32,
    bounces: u32,
    average_reflectance: f32,
) -> (VplSettings, Vec<Vpl>) {
    let settings = |paths: u32| VplSettings {
        paths,
        bounces,
        first_path: 0,
        normalisation_paths: paths,
        average_reflectance: Some(average_reflectance),
    };
    let run = |paths: u32| generate(scene, bvh, light, &settings(paths));
    let target = target.max(1);
    let cap = target.saturating_mul(64);
    // Grow from `target` paths by the observed yield until there are enough VPLs.
    let (mut lo, mut hi) = (0u32, target);
    let mut best = run(hi);
    while (best.len() as u32) < target && hi < cap {
        lo = hi;
        let yield_per_path = best.len().max(1) as f64 / hi as f64;
        let guess = (target as f64 / yield_per_path * 1.02).ceil() as u32;
        hi = guess.clamp(hi + 1, cap);
        best = run(hi);
    }
    if (best.len() as u32) < target {
        return (settings(hi), best);
    }
    // The fewest paths in (lo, hi] with enough VPLs.
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        let v = run(mid);
        if v.len() as u32 >= target {
            hi = mid;
            best = v;
        } else {
            lo = mid;
        }
    }
    (settings(hi), best)
}

/// The sum of the VPLs' fluxes.
pub fn total_flux(vpls: &[Vpl]) -> Vec3 {
    vpls.iter().map(|v| v.flux).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primes_beyond_the_table() {
        assert_eq!(nth_prime(0), 2);
        assert_eq!(nth_prime(9), 29);
        assert_eq!(nth_prime(63), 311);
        assert_eq!(nth_prime(64), 313);
        assert_eq!(nth_prime(65), 317);
        assert_eq!(nth_prime(99), 541);
    }

    #[test]
    fn radical_inverse_large_indices_stay_below_one() {
        for base in [2, 3, 5, 7, 311] {
            for index in [u64::MAX, u64::MAX - 1, 1 << 63, 123_456_789_012_345] {
                let x = radical_inverse(base, index);
                assert!((0.0..1.0).contains(&x), "base {base} index {index}: {x}");
            }
        }
        assert_eq!(radical_inverse(0, 5), 0.0);
        assert_eq!(radical_inverse(1, 5), 0.0);
    }

    #[test]
    fn frame_is_orthonormal_and_right_handed() {
        for n in [
            Vec3::Z,
            Vec3::NEG_Z,
            Vec3::X,
            Vec3::NEG_Y,
            Vec3::new(0.3, -0.5, 0.8).normalize(),
            Vec3::new(-1e-4, 1e-4, -1.0).normalize(),
        ] {
            let (t, b) = frame_from_normal(n);
            assert!((t.length() - 1.0).abs() < 1e-5);
            assert!((b.length() - 1.0).abs() < 1e-5);
            assert!(t.dot(b).abs() < 1e-5 && t.dot(n).abs() < 1e-5 && b.dot(n).abs() < 1e-5);
            assert!((t.cross(b) - n).length() < 1e-5, "n = {n}");
            let v = Vec3::new(0.2, -0.7, 0.4);
            assert!((to_local(to_world(v, n), n) - v).length() < 1e-5);
        }
        assert_eq!(frame_from_normal(Vec3::Z), (Vec3::X, Vec3::Y));
    }

    #[test]
    fn continuing_paths_edge_cases() {
        assert_eq!(continuing_paths(0.6, 1024, 1), 1024);
        assert_eq!(continuing_paths(0.5, 1024, 2), 512);
        assert_eq!(continuing_paths(0.5, 1024, 3), 256);
        assert_eq!(continuing_paths(1.5, 100, 4), 100);
        assert_eq!(continuing_paths(0.0, 100, 2), 0);
        assert_eq!(continuing_paths(f32::NAN, 100, 2), 0);
        assert_eq!(continuing_paths(0.9, 100, u32::MAX), 0);
    }
}
