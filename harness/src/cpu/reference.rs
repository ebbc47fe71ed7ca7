//! The CPU reference renderer: the ground truth every technique is compared against.
//!
//! It follows the crate's radiometric convention (see the [crate docs](crate)) exactly and
//! outputs, per pixel of the GPU camera, the albedo, the direct irradiance from the primary
//! light, the indirect irradiance of exactly one bounce, the indirect irradiance summed over
//! `1..=bounces` bounces and the composed radiance ρ/π (E_direct + E_ind).
//!
//! ## Geometry and camera
//!
//! * The geometry is the static mesh **plus** the movers in this frame's pose
//!   ([`frame_mesh`]). Movers cast shadows *and* reflect light here: the reference is physically
//!   complete, even where a technique (like Laine et al. 2007) bounces light off the static mesh
//!   only. The static mesh's BVH is built once per scene and shared by every frame
//!   ([`SceneTrees`]); each mover's is built per frame in world space (see [`crate::cpu::bvh::FrameBvh`]
//!   for why, and for the one case where the two levels can answer otherwise than one tree).
//! * One ray per pixel centre ([`camera_ray`]), exactly the GPU camera: pixel (x, y) is NDC
//!   ((x + ½)/w·2 − 1, 1 − (y + ½)/h·2) unprojected with the inverse of
//!   `perspective_reverse_z(fov, w/h, near) · look_at(…)`. Rays start at the near plane (the GPU
//!   clips anything nearer). No anti-aliasing: the G-buffer is not anti-aliased either, so
//!   pixels compare 1:1.
//! * Every surface is a two-sided Lambertian reflector. At a hit, the geometric and shading
//!   normals are flipped to face the incoming ray (as the G-buffer flips its normal towards the
//!   camera). Cosines use the shading normal; new rays start `ε` off the surface along the
//!   geometric normal, with `ε` = 10⁻⁴ × the scene's bounding-box diagonal. A direction on the
//!   far side of the geometric surface (possible only where shading normals are interpolated)
//!   carries nothing.
//! * Albedo ρ at a hit: the material's `base_color` times its texture (if any) sampled at the
//!   hit's uv, bilinear between texels decoded sRGB → linear, REPEAT wrap, base level only (no
//!   mipmaps). The same albedo is used at secondary hits. The alpha channel is ignored.
//!
//! ## The primary light
//!
//! * spot: I(ω) = Φ/π · max(0, cos θ) around its direction; omni: I = Φ/4π. Direct irradiance
//!   E = I(ω) cos θ_r / r² × V with one exact shadow ray: point lights have no noise.
//! * area: a one-sided Lambertian rectangle centred at `light.position` facing
//!   `light.direction` with radiance L = Φ/(πA). Its width runs along `normalize(up × n)` and
//!   its height along `n × width`, where `up` is +Y, or +Z when the normal is within about 2.6°
//!   of ±Y. E = ∫ L cos θ_l cos θ_r / r² V dA, estimated with `spp` stratified points at the
//!   primary hit and **one** uniform point per secondary vertex (the paths average those).
//!   A rectangle with no area is treated as a spot light (its far field).
//! * sun: parallel light against its direction with irradiance E⊥ (`power`) on a surface facing
//!   it: E = E⊥ cos θ_r × V, V from one shadow ray to infinity.
//! * Every kind's geometry and intensity come from the one light model, [`crate::cpu::light`].
//! * The light itself is not geometry: rays pass through it and never see it; all light enters
//!   paths through next-event estimation (the shadow rays above).
//!
//! ## The indirect estimator
//!
//! At the primary hit x (normal n), E_ind(x) = ∫ L_in(ω) cos θ dω. With `spp` cosine-weighted
//! directions ω_j (pdf cos θ/π; 2D-stratified over a ⌊√spp⌋ × ⌊spp/⌊√spp⌋⌋ grid, the rest
//! uniform) the estimator is π × mean_j L_in(ω_j). Each ω_j starts a path y₁, y₂, … (each next
//! direction cosine-sampled around the shading normal at y_k). The radiance y₁ sends back is
//! expanded by next-event estimation at every vertex:
//!
//! L_in(ω_j) ≈ Σ_{k=1..B} β_k · ρ(y_k)/π · E_d(y_k),   β₁ = 1,   β_{k+1} = β_k ρ(y_k),
//!
//! where E_d is the direct irradiance from the primary light (above) and B = `bounces`. So
//! `multi_bounce` = mean_j Σ_k β_k ρ(y_k) E_d(y_k) (the π's cancel) and `one_bounce` is its k = 1
//! term. Paths have a fixed depth (no Russian roulette): `multi_bounce` is exactly the sum of
//! bounces 1..=B, without the light of bounces beyond B (a fraction ρ̄^B of the total in a closed
//! scene of uniform albedo ρ̄: 1.7 % for ρ̄ = 0.6 and B = 8). A ray leaving the scene contributes 0
//! from there on.
//!
//! ## Determinism and error estimates
//!
//! Every pixel (or [`ReferenceTracer::irradiance_at`] query) draws from its own random stream
//! derived from (`seed`, pixel index) with SplitMix64, so images are bit-identical for a fixed
//! seed whatever the number of threads. The error falls as 1/√spp (faster for the stratified
//! first bounce); two renders with different seeds give an estimate of it.

use glam::{Mat4, Vec2, Vec3, Vec4};
use rayon::prelude::*;

use crate::cpu::bvh::{mover_mesh, FrameBvh, SceneTrees};
use crate::cpu::light::PointEmitter;
use crate::scene::anim::{FrameState, LightPose};
use crate::scene::descriptor::LightKind;
use crate::scene::{Mesh, Scene, Texture};
use crate::{Error, Result};

/// Version of the reference's results: bumped whenever the same inputs would give different
/// images (part of the reference cache key). 2: the indirect paths' directions from a polynomial
/// sine and cosine and no longer renormalised (Cornell, 128×96, 64 spp: the multi-bounce image
/// 10⁻⁵ RMS from version 1's, where two seeds differ by 0.14).
pub const REFERENCE_VERSION: u32 = 2;

/// How much work the reference does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ReferenceSettings {
    /// Paths (cosine-weighted hemisphere samples) per pixel, and the number of stratified
    /// points on an area light at the primary hit. 0 gives zero indirect light.
    pub spp: u32,
    /// Path depth B: `multi_bounce` sums bounces 1..=B.
    pub bounces: u32,
    /// Seed of every pixel's random stream.
    pub seed: u64,
}

impl Default for ReferenceSettings {
    /// `spp` 256, `bounces` 8, `seed` 0.
    ///
    /// * 256 paths (a 16 × 16 stratified grid of first directions) render the Cornell box at
    ///   256 × 192 in about 6 s on 2 cores; two seeds then differ by a relative MSE of about
    ///   1.4 · 10⁻² in `multi_bounce` (each render about half that from the converged image:
    ///   roughly 8 % RMS per pixel and channel). Quadruple `spp` to halve the noise.
    /// * 8 bounces leave out the bounces beyond the eighth: a fraction ρ̄⁸ of the indirect
    ///   light in a closed scene of uniform albedo ρ̄ (1.7 % for ρ̄ = 0.6), less in open ones.
    fn default() -> Self {
        ReferenceSettings {
            spp: 256,
            bounces: 8,
            seed: 0,
        }
    }
}

/// Which reference component a technique's indirect irradiance is compared with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IndirectComponent {
    /// Exactly one bounce (Laine, Keller with one bounce, ISM).
    OneBounce,
    /// All bounces up to the reference's bounce count.
    MultiBounce,
    /// The primary light's direct irradiance (for a technique's direct light samples: Barczak's
    /// `set=direct`).
    Direct,
}

impl IndirectComponent {
    pub fn parse(s: &str) -> Result<IndirectComponent> {
        match s {
            "one-bounce" => Ok(IndirectComponent::OneBounce),
            "multi-bounce" => Ok(IndirectComponent::MultiBounce),
            "direct" => Ok(IndirectComponent::Direct),
            _ => Err(Error::param(
                "quality-reference",
                format!("expected one-bounce, multi-bounce or direct (got '{s}')"),
            )),
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            IndirectComponent::OneBounce => "one-bounce",
            IndirectComponent::MultiBounce => "multi-bounce",
            IndirectComponent::Direct => "direct",
        }
    }
    /// The component's image.
    pub fn of(self, r: &ReferenceImages) -> &[Vec3] {
        match self {
            IndirectComponent::OneBounce => &r.one_bounce,
            IndirectComponent::MultiBounce => &r.multi_bounce,
            IndirectComponent::Direct => &r.direct,
        }
    }
}

/// The reference's images for one frame, row-major with the top row first, one value per
/// pixel. Pixels that see no geometry (`hit` false) are zero in every image.
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceImages {
    /// Width, height.
    pub size: [u32; 2],
    pub spp: u32,
    pub bounces: u32,
    pub seed: u64,
    /// Whether the pixel's ray hits geometry.
    pub hit: Vec<bool>,
    /// Diffuse albedo ρ at the pixel's hit (linear RGB).
    pub albedo: Vec<Vec3>,
    /// Direct irradiance from the primary light.
    pub direct: Vec<Vec3>,
    /// Indirect irradiance of exactly one bounce.
    pub one_bounce: Vec<Vec3>,
    /// Indirect irradiance summed over bounces 1..=`bounces`.
    pub multi_bounce: Vec<Vec3>,
    /// Outgoing radiance ρ/π (direct + multi_bounce).
    pub radiance: Vec<Vec3>,
}

impl ReferenceImages {
    /// Number of pixels.
    pub fn pixel_count(&self) -> usize {
        self.hit.len()
    }
    /// The radiance ρ/π (direct + `indirect`) with another indirect irradiance image (e.g. a
    /// technique's), per pixel; pixels without geometry stay zero. `indirect` must have one
    /// value per pixel (missing values count as zero).
    pub fn radiance_with(&self, indirect: &[Vec3]) -> Vec<Vec3> {
        (0..self.pixel_count())
            .map(|i| {
                if !self.hit[i] {
                    return Vec3::ZERO;
                }
                let e = self.direct[i] + indirect.get(i).copied().unwrap_or(Vec3::ZERO);
                self.albedo[i] * std::f32::consts::FRAC_1_PI * e
            })
            .collect()
    }
}

/// The rays a render traced ([`TracerSetup::rays`]): counted where the tracer asks its trees,
/// one per query whatever the number of trees (static and movers) it asks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Closest-hit rays: one per pixel from the camera, one per path segment.
    pub closest: u64,
    /// Shadow rays: one per light point whose light reaches the receiver's side (a receiver
    /// facing away, or outside a spot's cone, traces none).
    pub shadow: u64,
}

impl RayCounts {
    /// Closest-hit and shadow rays together.
    pub fn total(&self) -> u64 {
        self.closest + self.shadow
    }
}

impl std::ops::AddAssign for RayCounts {
    fn add_assign(&mut self, o: RayCounts) {
        self.closest += o.closest;
        self.shadow += o.shadow;
    }
}

/// Irradiance at one surface point (see [`ReferenceTracer::irradiance_at`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointIrradiance {
    /// Direct irradiance from the primary light.
    pub direct: Vec3,
    /// Indirect irradiance of exactly one bounce.
    pub one_bounce: Vec3,
    /// Indirect irradiance of bounces 1..=`bounces`.
    pub multi_bounce: Vec3,
}

/// The camera's view-projection at `resolution`, as the GPU builds it.
fn view_projection(frame: &FrameState, resolution: [u32; 2]) -> Mat4 {
    let aspect = resolution[0] as f32 / resolution[1].max(1) as f32;
    frame.camera.projection(aspect) * frame.camera.view()
}

/// (origin, unit direction, distance to the near plane along it) of pixel (x, y)'s ray.
fn camera_ray_near(
    inv_view_proj: &Mat4,
    frame: &FrameState,
    resolution: [u32; 2],
    x: u32,
    y: u32,
) -> (Vec3, Vec3, f32) {
    let [w, h] = resolution.map(|v| v.max(1) as f32);
    let ndc = Vec4::new(
        (x as f32 + 0.5) / w * 2.0 - 1.0,
        1.0 - (y as f32 + 0.5) / h * 2.0,
        1.0,
        1.0,
    );
    let near = *inv_view_proj * ndc;
    let near = near.truncate() / near.w;
    let origin = frame.camera.position;
    let to_near = near - origin;
    let dir = to_near.normalize_or(frame.camera.forward());
    (origin, dir, to_near.length())
}

/// The ray through the centre of pixel (x, y) (top row y = 0) of a `resolution` image:
/// (camera position, unit direction). It matches the GPU camera exactly: the pixel's NDC
/// point on the near plane unprojected with the inverse of the same view-projection.
pub fn camera_ray(frame: &FrameState, resolution: [u32; 2], x: u32, y: u32) -> (Vec3, Vec3) {
    let inv = view_projection(frame, resolution).inverse();
    let (o, d, _) = camera_ray_near(&inv, frame, resolution, x, y);
    (o, d)
}

/// The static mesh plus every mover transformed by `frame.movers[i]` (identity where the frame
/// has no transform), in world space ([`crate::cpu::bvh::mover_mesh`]). Mover material indices
/// already refer to [`Scene::materials`]. The tracer does not build this mesh: its trees are the
/// scene's static tree and the movers' ([`SceneTrees`]), which answer as one tree over it.
pub fn frame_mesh(scene: &Scene, frame: &FrameState) -> Mesh {
    let mut mesh = scene.mesh.clone();
    for (i, mover) in scene.movers.iter().enumerate() {
        let model = frame.movers.get(i).copied().unwrap_or(Mat4::IDENTITY);
        mesh.append(&mover_mesh(mover, model), 0);
    }
    mesh
}

/// The reference's generator (also the point pool's, [`crate::kit::ir::points`]).
pub(crate) type Rng = crate::rng::SplitMix64;

/// Two uniform draws in [0, 1)², x first.
fn next_2d(rng: &mut Rng) -> Vec2 {
    let x = rng.next_f32();
    Vec2::new(x, rng.next_f32())
}

/// Jittered 2D samples for `n` draws: the first ⌊√n⌋ × ⌊n/⌊√n⌋⌋ fill a grid (one per cell),
/// the rest are uniform. Every draw is uniformly distributed on its own, so means stay unbiased.
struct Stratified {
    nx: u32,
    ny: u32,
}

impl Stratified {
    fn new(n: u32) -> Stratified {
        let nx = ((n as f64).sqrt() as u32).max(1);
        Stratified {
            nx,
            ny: (n / nx).max(1),
        }
    }
    fn sample(&self, j: u32, rng: &mut Rng) -> Vec2 {
        let u = next_2d(rng);
        if j < self.nx * self.ny {
            Vec2::new(
                ((j % self.nx) as f32 + u.x) / self.nx as f32,
                ((j / self.nx) as f32 + u.y) / self.ny as f32,
            )
            .min(Vec2::splat(1.0 - f32::EPSILON / 2.0))
        } else {
            u
        }
    }
}

/// An orthonormal basis (t, b) perpendicular to unit `n` (Duff et al. 2017).
fn basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// Cosine-weighted direction around unit `n` from `u` in [0, 1)² (concentric disk mapping,
/// which keeps strata compact). The disk point's angle is ±π/4 · (ratio of the coordinates)
/// off an axis, so one sine and cosine on [−π/4, π/4] (`sin_cos_quarter`) serve both halves
/// of the mapping.
pub fn cosine_direction(n: Vec3, u: Vec2) -> Vec3 {
    let a = 2.0 * u - Vec2::ONE;
    let (dx, dy) = if a.x == 0.0 && a.y == 0.0 {
        (0.0, 0.0)
    } else if a.x.abs() > a.y.abs() {
        // φ = π/4 · y/x.
        let (s, c) = sin_cos_quarter(std::f32::consts::FRAC_PI_4 * (a.y / a.x));
        (a.x * c, a.x * s)
    } else {
        // φ = π/2 − θ with θ = π/4 · x/y: cos φ = sin θ, sin φ = cos θ.
        let (s, c) = sin_cos_quarter(std::f32::consts::FRAC_PI_4 * (a.x / a.y));
        (a.y * s, a.y * c)
    };
    let dz = (1.0 - dx * dx - dy * dy).max(0.0).sqrt();
    let (t, b) = basis(n);
    // Unit up to rounding (t, b, n orthonormal, dx² + dy² + dz² = 1): not renormalised.
    dx * t + dy * b + dz * n
}

/// (sin θ, cos θ) for |θ| ≤ π/4: their Taylor polynomials to θ⁹ and θ⁸, whose first omitted
/// terms (θ¹¹/11!, θ¹⁰/10!) are below 3·10⁻⁸ there — under f32's half ulp at 1 — at a
/// fraction of libm's `sincosf`, which reduces arbitrary arguments.
fn sin_cos_quarter(theta: f32) -> (f32, f32) {
    let t2 = theta * theta;
    // The coefficients are constants (a division by a constant would be one at run time).
    const S: [f32; 4] = [-1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0, 1.0 / 362_880.0];
    const C: [f32; 4] = [-1.0 / 2.0, 1.0 / 24.0, -1.0 / 720.0, 1.0 / 40_320.0];
    let s = theta * (1.0 + t2 * (S[0] + t2 * (S[1] + t2 * (S[2] + t2 * S[3]))));
    let c = 1.0 + t2 * (C[0] + t2 * (C[1] + t2 * (C[2] + t2 * C[3])));
    (s, c)
}

/// sRGB transfer function, decoded.
fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// A point receiving light: position `p`, the shadow rays' `origin` (`p` offset along `ng`),
/// geometric and shading normals `ng` and `ns` on the receiving side.
struct Receiver {
    p: Vec3,
    origin: Vec3,
    ng: Vec3,
    ns: Vec3,
}

/// How the primary light is sampled.
enum LightShape {
    /// A point with radiant intensity [`LightPose::intensity_toward`], set up once.
    Point(PointEmitter),
    /// A rectangle: centre `position`, half-extent vectors, normal, radiance × area (Φ/π).
    Rect {
        half_u: Vec3,
        half_v: Vec3,
        normal: Vec3,
        radiance_area: Vec3,
    },
    /// Parallel rays against `direction` carrying irradiance E⊥.
    Sun,
}

/// Everything needed to trace one frame: the trees over the frame's geometry, the light, the
/// materials. Set up one per frame; queries are `&self` and thread-safe.
pub struct ReferenceTracer<'a> {
    scene: &'a Scene,
    light: LightPose,
    shape: LightShape,
    bvh: FrameBvh,
    eps: f32,
    srgb: [f32; 256],
}

impl<'a> ReferenceTracer<'a> {
    /// Builds the trees over [`frame_mesh`] (the static mesh's too) and sets up the frame's
    /// light. For several frames of a scene, [`ReferenceTracer::with_trees`] builds the static
    /// mesh's tree once.
    pub fn new(scene: &'a Scene, frame: &FrameState) -> ReferenceTracer<'a> {
        Self::with_trees(&SceneTrees::new(scene), frame)
    }

    /// Sets up `frame` over `trees`' scene: its static tree (built if not yet) and the movers'
    /// trees in `frame`'s pose, and the frame's light.
    pub fn with_trees(trees: &SceneTrees<'a>, frame: &FrameState) -> ReferenceTracer<'a> {
        let scene = trees.scene();
        let (bvh, (lo, hi)) = trees.frame(frame);
        let diagonal = (hi - lo).length();
        let eps = if diagonal.is_finite() && diagonal > 0.0 {
            1e-4 * diagonal
        } else {
            1e-6
        };
        let light = frame.light;
        let shape = match (light.kind, light.area_half_extents()) {
            (LightKind::Sun, _) => LightShape::Sun,
            (LightKind::Area, Some((half_u, half_v))) => LightShape::Rect {
                half_u,
                half_v,
                normal: light.axis(),
                radiance_area: light.power / std::f32::consts::PI,
            },
            // Spot, omni, and an area light with no area (its far field: a cosine spot).
            _ => LightShape::Point(light.emitter()),
        };
        let mut srgb = [0.0; 256];
        for (i, s) in srgb.iter_mut().enumerate() {
            *s = srgb_to_linear(i as f32 / 255.0);
        }
        ReferenceTracer {
            scene,
            light,
            shape,
            bvh,
            eps,
            srgb,
        }
    }

    /// The trees over the frame's geometry (static mesh and movers).
    pub fn bvh(&self) -> &FrameBvh {
        &self.bvh
    }

    /// The ray-origin offset ε (10⁻⁴ × the scene's bounding-box diagonal).
    pub fn epsilon(&self) -> f32 {
        self.eps
    }

    /// Linear texel of `tex` at `uv`: bilinear, REPEAT, decoded from sRGB before filtering.
    /// A texture without (enough) data is white.
    fn texel(&self, tex: &Texture, uv: Vec2) -> Vec3 {
        let (w, h) = (tex.width as usize, tex.height as usize);
        if w == 0 || h == 0 || tex.rgba8.len() < w * h * 4 {
            return Vec3::ONE;
        }
        let uv = if uv.is_finite() { uv } else { Vec2::ZERO };
        // Keep the coordinates small before converting to integers.
        let uv = uv - uv.floor();
        let x = uv.x * w as f32 - 0.5;
        let y = uv.y * h as f32 - 0.5;
        let (fx0, fy0) = (x.floor(), y.floor());
        let (fx, fy) = (x - fx0, y - fy0);
        let x0 = (fx0 as i64).rem_euclid(w as i64) as usize;
        let y0 = (fy0 as i64).rem_euclid(h as i64) as usize;
        let (x1, y1) = ((x0 + 1) % w, (y0 + 1) % h);
        let at = |x: usize, y: usize| {
            let o = (y * w + x) * 4;
            Vec3::new(
                self.srgb[tex.rgba8[o] as usize],
                self.srgb[tex.rgba8[o + 1] as usize],
                self.srgb[tex.rgba8[o + 2] as usize],
            )
        };
        let top = at(x0, y0).lerp(at(x1, y0), fx);
        let bottom = at(x0, y1).lerp(at(x1, y1), fx);
        top.lerp(bottom, fy)
    }

    /// Diffuse albedo of `material` at texture coordinate `uv`: base colour × texture texel
    /// (see the module docs). An unknown material is black.
    pub fn albedo(&self, material: u32, uv: Vec2) -> Vec3 {
        let Some(m) = self.scene.materials.get(material as usize) else {
            return Vec3::ZERO;
        };
        match m.texture.and_then(|t| self.scene.textures.get(t)) {
            Some(tex) => m.base_color * self.texel(tex, uv),
            None => m.base_color,
        }
    }

    /// Whether the segment from `from` (already offset from its surface) to the light point
    /// `to` is free; the last ε before `to` is not tested.
    fn visible(&self, from: Vec3, to: Vec3, rays: &mut RayCounts) -> bool {
        let d = to - from;
        let len = d.length();
        if len <= self.eps {
            return true;
        }
        rays.shadow += 1;
        !self.bvh.any_hit(from, d, 0.0, 1.0 - self.eps / len)
    }

    /// Irradiance from one light point `y` with emitted intensity towards `p` computed by
    /// `intensity(l)` (l: unit direction from `p` to `y`), times visibility.
    fn point_irradiance(
        &self,
        &Receiver { p, origin, ng, ns }: &Receiver,
        y: Vec3,
        intensity: impl Fn(Vec3) -> Vec3,
        rays: &mut RayCounts,
    ) -> Vec3 {
        let to = y - p;
        let r2 = to.length_squared();
        if r2 <= 0.0 || !r2.is_finite() {
            return Vec3::ZERO;
        }
        let l = to / r2.sqrt();
        let cos_r = ns.dot(l);
        if cos_r <= 0.0 || ng.dot(l) <= 0.0 {
            return Vec3::ZERO;
        }
        let i = intensity(l);
        if i == Vec3::ZERO || !self.visible(origin, y, rays) {
            return Vec3::ZERO;
        }
        i * (cos_r / r2)
    }

    /// Direct irradiance at `p` (geometric normal `ng`, shading normal `ns`, both on the
    /// receiving side). Area lights use `samples` points: stratified when `rng_strata`.
    fn direct(
        &self,
        p: Vec3,
        ng: Vec3,
        ns: Vec3,
        samples: u32,
        rng: &mut Rng,
        rays: &mut RayCounts,
    ) -> Vec3 {
        let origin = p + ng * self.eps;
        let at = Receiver { p, origin, ng, ns };
        match &self.shape {
            LightShape::Point(emitter) => {
                let position = self.light.position;
                self.point_irradiance(&at, position, |l| emitter.intensity_toward(-l), rays)
            }
            LightShape::Sun => {
                let l = -self.light.axis();
                let cos_r = ns.dot(l);
                if cos_r <= 0.0 || ng.dot(l) <= 0.0 {
                    return Vec3::ZERO;
                }
                rays.shadow += 1;
                if self.bvh.any_hit(origin, l, 0.0, f32::INFINITY) {
                    return Vec3::ZERO;
                }
                self.light.power * cos_r
            }
            LightShape::Rect {
                half_u,
                half_v,
                normal,
                radiance_area,
            } => {
                let n = samples.max(1);
                let strata = Stratified::new(n);
                let mut sum = Vec3::ZERO;
                for j in 0..n {
                    let u = 2.0 * strata.sample(j, rng) - Vec2::ONE;
                    let y = self.light.position + u.x * *half_u + u.y * *half_v;
                    // Per point: L·A · cos θ_l (the pdf 1/A cancels A).
                    sum += self.point_irradiance(
                        &at,
                        y,
                        |l| *radiance_area * (-l).dot(*normal).max(0.0),
                        rays,
                    );
                }
                sum / n as f32
            }
        }
    }

    /// Direct, one-bounce and multi-bounce irradiance at surface point `point`, on the side its
    /// `geometric_normal` faces, with cosines taken about `shading_normal` (both unit length and
    /// on the same side; pass the same vector twice for flat surfaces). Uses `settings.spp`
    /// paths of `settings.bounces` bounces, drawing from the random stream (`settings.seed`,
    /// `stream`); [`render_reference`] uses the pixel index as the stream.
    pub fn irradiance_at(
        &self,
        point: Vec3,
        geometric_normal: Vec3,
        shading_normal: Vec3,
        settings: &ReferenceSettings,
        stream: u64,
    ) -> PointIrradiance {
        let mut rays = RayCounts::default();
        self.irradiance_counted(
            point,
            geometric_normal,
            shading_normal,
            settings,
            stream,
            &mut rays,
        )
    }

    /// [`ReferenceTracer::irradiance_at`], adding the rays it traces to `rays`.
    fn irradiance_counted(
        &self,
        point: Vec3,
        geometric_normal: Vec3,
        shading_normal: Vec3,
        settings: &ReferenceSettings,
        stream: u64,
        rays: &mut RayCounts,
    ) -> PointIrradiance {
        let mut rng = Rng::new(settings.seed, stream);
        let (ng, ns) = (geometric_normal, shading_normal);
        let direct = self.direct(point, ng, ns, settings.spp, &mut rng, rays);
        let mut one = Vec3::ZERO;
        let mut multi = Vec3::ZERO;
        if settings.spp > 0 && settings.bounces > 0 {
            let strata = Stratified::new(settings.spp);
            for j in 0..settings.spp {
                let mut dir = cosine_direction(ns, strata.sample(j, &mut rng));
                if dir.dot(ng) <= 0.0 {
                    continue;
                }
                let mut origin = point + ng * self.eps;
                let mut beta = Vec3::ONE;
                for k in 1..=settings.bounces {
                    rays.closest += 1;
                    let Some(hit) = self.bvh.closest_hit(origin, dir, 0.0, f32::INFINITY) else {
                        break;
                    };
                    let rho = self.albedo(hit.material, hit.uv);
                    let e = self.direct(
                        hit.position,
                        hit.geometric_normal,
                        hit.shading_normal,
                        1,
                        &mut rng,
                        rays,
                    );
                    // β ρ/π E_d, times the estimator's π.
                    let c = beta * rho * e;
                    if k == 1 {
                        one += c;
                    }
                    multi += c;
                    beta *= rho;
                    if k == settings.bounces || beta == Vec3::ZERO {
                        break;
                    }
                    dir = cosine_direction(hit.shading_normal, next_2d(&mut rng));
                    if dir.dot(hit.geometric_normal) <= 0.0 {
                        break;
                    }
                    origin = hit.position + hit.geometric_normal * self.eps;
                }
            }
            one /= settings.spp as f32;
            multi /= settings.spp as f32;
        }
        PointIrradiance {
            direct,
            one_bounce: one,
            multi_bounce: multi,
        }
    }
}

/// Renders the reference images of `frame` at `resolution` (see the module docs): one ray per
/// pixel centre, `settings.spp` paths per hit pixel. Parallel over pixels with rayon;
/// the result depends only on the inputs, not on the number of threads.
pub fn render_reference(
    scene: &Scene,
    frame: &FrameState,
    resolution: [u32; 2],
    settings: &ReferenceSettings,
) -> ReferenceImages {
    render_reference_timed(scene, frame, resolution, settings).0
}

/// What setting up the tracer cost in a [`render_reference_timed`] call: the frame's trees
/// (the static mesh's when not built yet, and the movers'), built before any ray is traced.
/// Renderers that build their acceleration structure when the scene loads (Mitsuba, Embree)
/// leave this out of their render time; a like-for-like comparison subtracts it from the
/// render call's. With it, the rays the render then traced (for a per-ray cost).
#[derive(Clone, Copy, Debug)]
pub struct TracerSetup {
    /// Wall seconds.
    pub seconds: f64,
    /// CPU seconds of every thread of the process over the same span (`None` where the
    /// platform has no process CPU clock).
    pub cpu_seconds: Option<f64>,
    /// The rays the render traced after the set-up, summed over its pixels (each pixel counts
    /// its own, added up once the pixels are done: nothing shared in the loop).
    pub rays: RayCounts,
}

/// [`render_reference`], with what setting up the tracer cost.
pub fn render_reference_timed(
    scene: &Scene,
    frame: &FrameState,
    resolution: [u32; 2],
    settings: &ReferenceSettings,
) -> (ReferenceImages, TracerSetup) {
    render_reference_with(&SceneTrees::new(scene), frame, resolution, settings)
}

/// [`render_reference_timed`] over `trees`' scene, its static tree built once for every frame
/// rendered with the same `trees`.
pub fn render_reference_with(
    trees: &SceneTrees,
    frame: &FrameState,
    resolution: [u32; 2],
    settings: &ReferenceSettings,
) -> (ReferenceImages, TracerSetup) {
    let (tracer, seconds, cpu_seconds) =
        crate::measure::calibrate::timed(|| ReferenceTracer::with_trees(trees, frame));
    let [w, h] = resolution;
    let inv = view_projection(frame, resolution).inverse();
    let pixels: Vec<(Option<(Vec3, PointIrradiance)>, RayCounts)> = (0..w as usize * h as usize)
        .into_par_iter()
        .with_min_len(w.max(1) as usize)
        .map(|i| {
            let (x, y) = (i as u32 % w, i as u32 / w);
            let (origin, dir, near) = camera_ray_near(&inv, frame, resolution, x, y);
            let mut rays = RayCounts {
                closest: 1,
                shadow: 0,
            };
            let Some(hit) = tracer.bvh.closest_hit(origin, dir, near, f32::INFINITY) else {
                return (None, rays);
            };
            let albedo = tracer.albedo(hit.material, hit.uv);
            let e = tracer.irradiance_counted(
                hit.position,
                hit.geometric_normal,
                hit.shading_normal,
                settings,
                i as u64,
                &mut rays,
            );
            (Some((albedo, e)), rays)
        })
        .collect();
    let mut rays = RayCounts::default();
    for (_, r) in &pixels {
        rays += *r;
    }
    let setup = TracerSetup {
        seconds,
        cpu_seconds,
        rays,
    };
    let n = pixels.len();
    let mut out = ReferenceImages {
        size: resolution,
        spp: settings.spp,
        bounces: settings.bounces,
        seed: settings.seed,
        hit: Vec::with_capacity(n),
        albedo: Vec::with_capacity(n),
        direct: Vec::with_capacity(n),
        one_bounce: Vec::with_capacity(n),
        multi_bounce: Vec::with_capacity(n),
        radiance: Vec::with_capacity(n),
    };
    for (p, _) in pixels {
        let (albedo, e) = p.unwrap_or_default();
        out.hit.push(p.is_some());
        out.albedo.push(albedo);
        out.direct.push(e.direct);
        out.one_bounce.push(e.one_bounce);
        out.multi_bounce.push(e.multi_bounce);
        out.radiance
            .push(albedo * std::f32::consts::FRAC_1_PI * (e.direct + e.multi_bounce));
    }
    (out, setup)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The polynomial sine and cosine agree with libm's to within 2·10⁻⁷ on [−π/4, π/4].
    #[test]
    fn sin_cos_quarter_matches_libm() {
        for k in -1000..=1000 {
            let theta = k as f32 / 1000.0 * std::f32::consts::FRAC_PI_4;
            let (s, c) = sin_cos_quarter(theta);
            assert!((s - theta.sin()).abs() <= 2e-7, "sin {theta}: {s}");
            assert!((c - theta.cos()).abs() <= 2e-7, "cos {theta}: {c}");
        }
    }

    /// Directions are unit to within 10⁻⁶ and equal, to within 10⁻⁵, the concentric mapping
    /// written with libm's sine and cosine of φ (Shirley and Chiu: φ = π/4 · y/x where |x| > |y|,
    /// else π/2 − π/4 · x/y), over a grid that crosses both halves and every quadrant.
    #[test]
    fn cosine_directions_match_the_concentric_mapping() {
        let n = Vec3::new(0.3, -0.5, 0.8).normalize();
        let (t, b) = basis(n);
        for i in 0..64 {
            for j in 0..64 {
                let u = Vec2::new(i as f32 + 0.5, j as f32 + 0.5) / 64.0;
                let d = cosine_direction(n, u);
                assert!((d.length() - 1.0).abs() < 1e-6, "{u}: |d| = {}", d.length());
                let a = 2.0 * u - Vec2::ONE;
                let (r, phi) = if a.x.abs() > a.y.abs() {
                    (a.x, std::f32::consts::FRAC_PI_4 * (a.y / a.x))
                } else {
                    (
                        a.y,
                        std::f32::consts::FRAC_PI_2 - std::f32::consts::FRAC_PI_4 * (a.x / a.y),
                    )
                };
                let (dx, dy) = (r * phi.cos(), r * phi.sin());
                let want = dx * t + dy * b + (1.0 - dx * dx - dy * dy).max(0.0).sqrt() * n;
                assert!((d - want).length() < 1e-5, "{u}: {d} vs {want}");
            }
        }
    }
}
