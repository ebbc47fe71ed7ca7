//! The one light model: everything the primary light means, written once and used by VPL
//! generation ([`crate::cpu::vpl`]), Laine's sampling domains, the reference renderer
//! ([`crate::cpu::reference`]) and the GPU uniforms ([`crate::kit::passes::FrameUniforms`]).
//!
//! A [`LightPose`] (the light in one frame, from [`crate::scene::anim`]) owns its position and
//! direction, its radiant intensity, its emission sampling (the first ray of a light path for
//! a Halton index), its sampling domain for Laine et al. 2007's management (the unit disc or the
//! unit sphere) and the maps between that domain and rays. The only per-scene input is the
//! scene's [`SceneExtent`] (the sun needs the scene's bounding sphere; every ray needs ε).
//!
//! | kind | emits | `power` | sampling domain | a sample is |
//! |---|---|---|---|---|
//! | spot | from `position`, I(θ) = Φ/π cos θ about `direction` (180° cone) | flux Φ | unit disc | (x, y, 0): the disc point under the direction, in the spot's frame (Nusselt analog) |
//! | omni | from `position`, I = Φ/4π | flux Φ | unit sphere | the unit direction |
//! | area | one-sided Lambertian rectangle of `size` at `position`, facing `direction`, L = Φ/(πA) | flux Φ | unit disc | (x, y, 0): the disc point of the cosine direction about the normal; Laine's management starts rays at the centre |
//! | sun | parallel rays along `direction` | irradiance E⊥ on a surface facing the sun | unit disc | (x, y, 0): where the ray crosses the disc that covers the scene's bounding sphere, in units of its radius |
//!
//! The sun's flux into the scene is E⊥ · πR² through the disc of radius R (the scene's bounding
//! sphere) perpendicular to its direction; [`LightPose::emitted_flux`] gives every kind's flux,
//! so VPL generation and Laine's Voronoi intensities (Φ × area share) need no special case.

use glam::{Vec2, Vec3};

use crate::cpu::bvh::SceneBvh;
use crate::cpu::vpl::{
    cosine_direction, disc_to_hemisphere, frame_from_normal, halton, hemisphere_to_disc,
    square_to_disc, square_to_sphere, to_local, to_world,
};
use crate::scene::anim::LightPose;
use crate::scene::descriptor::LightKind;
use crate::scene::SceneExtent;

/// Where a light's sampling points live (Laine et al. 2007, Figure 3).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleDomain {
    /// The unit disc (spot, area, sun); samples are `(x, y, 0)`.
    Disc,
    /// The unit sphere (omni); samples are unit directions.
    Sphere,
}

impl SampleDomain {
    /// π for the disc, 4π for the sphere.
    pub fn area(self) -> f64 {
        match self {
            SampleDomain::Disc => std::f64::consts::PI,
            SampleDomain::Sphere => 4.0 * std::f64::consts::PI,
        }
    }
}

/// The first ray of a light path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmittedRay {
    pub origin: Vec3,
    /// Unit direction.
    pub direction: Vec3,
    /// The ray's point in the light's [`SampleDomain`].
    pub sample: Vec3,
}

/// The shader's code for a light kind (`Light.position.w` in `common.wgsl`).
pub fn gpu_kind(kind: LightKind) -> f32 {
    match kind {
        LightKind::Spot => 0.0,
        LightKind::Omni => 1.0,
        LightKind::Area => 2.0,
        LightKind::Sun => 3.0,
    }
}

/// A light's radiant intensity by direction ([`LightPose::emitter`]).
#[derive(Clone, Copy, Debug)]
pub struct PointEmitter {
    axis: Vec3,
    on_axis: Vec3,
    /// Whether it falls off as the cosine to the axis (spot, area), or not (omni, sun).
    cosine: bool,
}

impl PointEmitter {
    /// [`LightPose::intensity_toward`].
    #[inline]
    pub fn intensity_toward(&self, dir_from_light: Vec3) -> Vec3 {
        if self.cosine {
            self.on_axis * dir_from_light.dot(self.axis).max(0.0)
        } else {
            self.on_axis
        }
    }
}

impl LightPose {
    /// The light's unit axis (spot direction, area normal, sun direction), −Y if unusable.
    pub fn axis(&self) -> Vec3 {
        self.direction.normalize_or(Vec3::NEG_Y)
    }

    /// Whether the light is the sun (parallel rays, no position), as opposed to a light at a
    /// point (spot, omni, and area lights as the GPU passes and Laine's management see them).
    pub fn is_directional(&self) -> bool {
        self.kind == LightKind::Sun
    }

    /// The light's sampling domain (see the module table).
    pub fn domain(&self) -> SampleDomain {
        match self.kind {
            LightKind::Omni => SampleDomain::Sphere,
            LightKind::Spot | LightKind::Area | LightKind::Sun => SampleDomain::Disc,
        }
    }

    /// The power with non-finite channels replaced by 0.
    fn sanitized_power(&self) -> Vec3 {
        Vec3::select(self.power.is_finite_mask(), self.power, Vec3::ZERO)
    }

    /// The flux the light sends into the scene: Φ for spot, omni and area lights; E⊥ · πR² for
    /// the sun (R: the scene's bounding-sphere radius). Non-finite channels count as 0.
    pub fn emitted_flux(&self, extent: &SceneExtent) -> Vec3 {
        let p = self.sanitized_power();
        match self.kind {
            LightKind::Sun => p * (std::f32::consts::PI * extent.radius * extent.radius),
            _ => p,
        }
    }

    /// The GPU's `Light.intensity`: the on-axis radiant intensity of a point light (spot and
    /// area Φ/π, omni Φ/4π) or the sun's irradiance E⊥.
    pub fn axis_intensity(&self) -> Vec3 {
        match self.kind {
            LightKind::Omni => self.power / (4.0 * std::f32::consts::PI),
            LightKind::Spot | LightKind::Area => self.power / std::f32::consts::PI,
            LightKind::Sun => self.power,
        }
    }

    /// Radiant intensity of a point light (spot, omni; area lights as a cosine spot at their
    /// centre) towards unit `dir_from_light`; the sun's E⊥ for the sun.
    pub fn intensity_toward(&self, dir_from_light: Vec3) -> Vec3 {
        self.emitter().intensity_toward(dir_from_light)
    }

    /// [`LightPose::intensity_toward`] set up once: the axis and on-axis intensity, which it
    /// would otherwise compute (a normalisation, three divisions) at every call.
    pub fn emitter(&self) -> PointEmitter {
        PointEmitter {
            axis: self.axis(),
            on_axis: self.axis_intensity(),
            cosine: !matches!(self.kind, LightKind::Omni | LightKind::Sun),
        }
    }

    /// An area light's half-extent vectors (width, height) in its tangent frame (width along
    /// `normalize(up × n)`, up = +Y, or +Z when n is within 2.6° of ±Y), or `None` when it is
    /// not an area light or has no area.
    pub fn area_half_extents(&self) -> Option<(Vec3, Vec3)> {
        if self.kind != LightKind::Area {
            return None;
        }
        let [w, h] = self.size;
        if !(w > 0.0 && h > 0.0 && w.is_finite() && h.is_finite()) {
            return None;
        }
        let n = self.axis();
        let up = if n.y.abs() > 0.999 { Vec3::Z } else { Vec3::Y };
        let u = up.cross(n).normalize();
        let v = n.cross(u);
        Some((0.5 * w * u, 0.5 * h * v))
    }

    /// The sun's emitting disc: its centre (outside the scene's bounding sphere, upstream of
    /// it) and radius (the sphere's, plus a 1 % margin).
    pub fn sun_disc(&self, extent: &SceneExtent) -> (Vec3, f32) {
        let r = extent.radius * 1.01;
        (extent.centre - self.axis() * (2.0 * r), r)
    }

    /// The first ray of light path `h` (Halton dims 0–3): spot, a disc point lifted to the
    /// hemisphere; omni, a uniform direction; area, a uniform point on the rectangle (dims 2, 3)
    /// and a cosine direction (dims 0, 1); sun, a uniform point on its disc (dims 0, 1) and the
    /// sun's direction.
    pub fn emit(&self, h: u64, extent: &SceneExtent) -> EmittedRay {
        let (u0, u1) = (halton(h, 0), halton(h, 1));
        let axis = self.axis();
        match (self.kind, self.area_half_extents()) {
            (LightKind::Omni, _) => {
                let d = square_to_sphere(u0, u1);
                EmittedRay {
                    origin: self.position,
                    direction: d,
                    sample: d,
                }
            }
            (LightKind::Area, Some((half_u, half_v))) => {
                let (u2, u3) = (halton(h, 2) as f32, halton(h, 3) as f32);
                let origin = self.position + (2.0 * u2 - 1.0) * half_u + (2.0 * u3 - 1.0) * half_v;
                let p = square_to_disc(u0, u1);
                EmittedRay {
                    origin,
                    direction: cosine_direction(axis, u0, u1),
                    sample: p.extend(0.0),
                }
            }
            (LightKind::Sun, _) => {
                let p = square_to_disc(u0, u1);
                let (origin, direction) = self.ray_of_sample(p.extend(0.0), extent);
                EmittedRay {
                    origin,
                    direction,
                    sample: p.extend(0.0),
                }
            }
            _ => {
                let p = square_to_disc(u0, u1);
                EmittedRay {
                    origin: self.position,
                    direction: to_world(disc_to_hemisphere(p), axis).normalize_or(axis),
                    sample: p.extend(0.0),
                }
            }
        }
    }

    /// The ray through sampling point `sample` of the light's domain: (origin, unit direction).
    /// Disc points of spot and area lights are lifted to the hemisphere about the axis and start
    /// at `position` (an area light's centre); sphere points are directions from `position`;
    /// the sun's disc points start on its disc and run along its direction.
    pub fn ray_of_sample(&self, sample: Vec3, extent: &SceneExtent) -> (Vec3, Vec3) {
        let axis = self.axis();
        match self.kind {
            LightKind::Omni => (self.position, sample.normalize_or(axis)),
            LightKind::Sun => {
                let (centre, r) = self.sun_disc(extent);
                let (t, b) = frame_from_normal(axis);
                (centre + r * (sample.x * t + sample.y * b), axis)
            }
            LightKind::Spot | LightKind::Area => (
                self.position,
                to_world(disc_to_hemisphere(sample.truncate()), axis).normalize_or(axis),
            ),
        }
    }

    /// The sampling point whose ray reaches `point` (the inverse of [`Self::ray_of_sample`]):
    /// for disc lights the direction from `position` in the axis frame projected to the disc
    /// (points behind the light land on the disc too, mirrored); for omni lights the unit
    /// direction; for the sun the point's offset across the sun's direction over the disc
    /// radius.
    pub fn sample_of_point(&self, point: Vec3, extent: &SceneExtent) -> Vec3 {
        let axis = self.axis();
        match self.kind {
            LightKind::Omni => (point - self.position).normalize_or(axis),
            LightKind::Sun => {
                let (centre, r) = self.sun_disc(extent);
                let local = to_local(point - centre, axis);
                Vec2::new(local.x / r, local.y / r).extend(0.0)
            }
            LightKind::Spot | LightKind::Area => {
                let d = (point - self.position).normalize_or(axis);
                hemisphere_to_disc(to_local(d, axis)).extend(0.0)
            }
        }
    }

    /// Unit direction from `point` towards the light and the distance to it (infinite for the
    /// sun); area lights are taken at their centre.
    pub fn toward_light(&self, point: Vec3) -> (Vec3, f32) {
        if self.kind == LightKind::Sun {
            return (-self.axis(), f32::INFINITY);
        }
        let d = self.position - point;
        let len = d.length();
        (d / len.max(f32::MIN_POSITIVE), len)
    }

    /// Whether the segment from `point` to the light (its centre; for the sun, the ray against
    /// its direction) is free of static geometry in `bvh`, ignoring ε at both ends.
    pub fn unoccluded(&self, bvh: &SceneBvh, point: Vec3, eps: f32) -> bool {
        match self.kind {
            LightKind::Sun => !bvh.any_hit(point, -self.axis(), eps, f32::INFINITY),
            _ => !bvh.occluded(self.position, point, eps),
        }
    }

    /// Whether `point` is on the emitting side of the light: in front of a spot's or an area
    /// light's plane (within a relative tolerance of 10⁻⁵, so disc-rim samples in the plane
    /// count), anywhere for omni lights and the sun.
    pub fn in_front(&self, point: Vec3) -> bool {
        match self.kind {
            LightKind::Omni | LightKind::Sun => true,
            LightKind::Spot | LightKind::Area => {
                let d = point - self.position;
                d.dot(self.axis()) >= -1e-5 * d.length()
            }
        }
    }
}

/// The irradiance at `x` (unit normal `n`) from a point light at `position` of flux `flux`,
/// without visibility: E = I · max(0, n·ω) / r², ω the unit direction from `x` to the light.
/// A light on a surface of unit normal `normal` (a VPL, a light sample) emits I = Φ/π ·
/// max(0, cos θ) about it, an omnidirectional one (`None`) I = Φ/4π. Zero at the light itself.
/// The GPU's unoccluded term is `vpl_geometry` (`ir/shaders/vpl_store.wgsl`).
pub fn point_irradiance(
    position: Vec3,
    normal: Option<Vec3>,
    flux: Vec3,
    x: Vec3,
    n: Vec3,
) -> Vec3 {
    let d = position - x;
    let r2 = d.length_squared();
    if r2 <= 0.0 {
        return Vec3::ZERO;
    }
    let w = d / r2.sqrt();
    let receive = n.dot(w).max(0.0);
    let intensity = match normal {
        Some(ln) => flux / std::f32::consts::PI * (-ln.dot(w)).max(0.0),
        None => flux / (4.0 * std::f32::consts::PI),
    };
    intensity * receive / r2
}

#[cfg(test)]
mod tests {
    use super::*;

    fn extent() -> SceneExtent {
        SceneExtent::from_bounds(Vec3::new(-1.0, 0.0, -2.0), Vec3::new(3.0, 2.0, 2.0))
    }

    fn pose(kind: LightKind) -> LightPose {
        LightPose {
            kind,
            position: Vec3::new(0.5, 1.5, 0.2),
            direction: Vec3::new(0.2, -1.0, 0.1).normalize(),
            power: Vec3::ONE,
            size: if kind == LightKind::Area {
                [0.3, 0.2]
            } else {
                [0.0; 2]
            },
        }
    }

    #[test]
    fn emitted_rays_round_trip_through_their_samples() {
        let e = extent();
        for kind in [
            LightKind::Spot,
            LightKind::Omni,
            LightKind::Area,
            LightKind::Sun,
        ] {
            let l = pose(kind);
            for h in 1..64 {
                let ray = l.emit(h, &e);
                assert!((ray.direction.length() - 1.0).abs() < 1e-5, "{kind:?}");
                let target = ray.origin + ray.direction * 0.7;
                if kind != LightKind::Area {
                    let (o, d) = l.ray_of_sample(ray.sample, &e);
                    assert!((d - ray.direction).length() < 1e-4, "{kind:?} h={h}");
                    assert!((o - ray.origin).length() < 1e-4, "{kind:?} h={h}");
                    let s = l.sample_of_point(target, &e);
                    assert!(
                        (s - ray.sample).length() < 1e-4,
                        "{kind:?} h={h}: {s} vs {}",
                        ray.sample
                    );
                }
                // Every emitted ray leaves towards the lit side.
                assert!(ray.direction.dot(l.axis()) >= -1e-6 || kind == LightKind::Omni);
            }
        }
    }

    #[test]
    fn area_light_samples_live_on_the_disc_in_front_of_the_light() {
        // The bug the light model fixes: an area light's samples were world directions while
        // Laine's domain is the disc, so rays from disc samples went sideways and behind.
        let (l, e) = (pose(LightKind::Area), extent());
        assert_eq!(l.domain(), SampleDomain::Disc);
        for h in 1..200 {
            let s = l.emit(h, &e).sample;
            assert!(s.z == 0.0 && s.truncate().length() <= 1.0 + 1e-5);
            let (_, d) = l.ray_of_sample(s, &e);
            assert!(d.dot(l.axis()) >= 0.0);
        }
    }

    #[test]
    fn sun_disc_covers_the_scene_and_carries_its_flux() {
        let e = extent();
        let sun = LightPose {
            power: Vec3::splat(2.0),
            ..pose(LightKind::Sun)
        };
        let (centre, r) = sun.sun_disc(&e);
        assert!(r >= e.radius);
        assert!(
            (centre - e.centre).length() > e.radius,
            "disc starts outside the scene"
        );
        let flux = sun.emitted_flux(&e);
        let want = 2.0 * std::f32::consts::PI * e.radius * e.radius;
        assert!((flux.x - want).abs() < 1e-3 * want);
        assert_eq!(sun.toward_light(Vec3::ZERO).1, f32::INFINITY);
        assert!((sun.toward_light(Vec3::ZERO).0 + sun.axis()).length() < 1e-6);
    }

    #[test]
    fn intensities_follow_the_radiometric_convention() {
        let pi = std::f32::consts::PI;
        assert!((pose(LightKind::Omni).axis_intensity().x - 1.0 / (4.0 * pi)).abs() < 1e-7);
        let spot = pose(LightKind::Spot);
        assert!((spot.intensity_toward(spot.axis()).x - 1.0 / pi).abs() < 1e-7);
        assert_eq!(spot.intensity_toward(-spot.axis()), Vec3::ZERO);
        assert!(spot.in_front(spot.position + spot.axis()));
        assert!(!spot.in_front(spot.position - spot.axis()));
    }
}
