//! Light samples (Barczak 2006 §4.1): the oriented point lights the whole scene is lit by,
//! computed once from the static geometry (movers are assumed not to change where light goes).
//!
//! Reads: the light (its pose at the frame the set is made for), the static mesh and its BVH.
//! Writes: two sets of [`Vpl`]s, each emitting I(θ) = flux/π · cos θ about its normal:
//!
//! * **direct** — `direct` points on an area light's rectangle (Halton-stratified), each
//!   carrying Φ/`direct` with the light's normal: the area light itself, point-sampled, so its
//!   shadows come out soft;
//! * **indirect** — random walks from the light (the first ray from a point on the emitter in a
//!   cosine direction, then cosine directions about each hit's normal), a sample at every hit up
//!   to `bounces`, each carrying Φ times the albedos along its path; walks are started until
//!   there are `indirect` samples (the last walk's extra hits are dropped) and every sample is
//!   divided by the number of walks started. This is the shared Keller path tracer
//!   (`gibench_harness::cpu::vpl::generate_at_least`) with no fractional absorption (ρ̄ = 1: every
//!   walk runs to the bounce limit, as the thesis' do), on Halton numbers as Keller's.
//!
//! The VPL count in the shared sense (the VPLs lighting the frame) is `direct + indirect`.

use gibench_harness::cpu::bvh::SceneBvh;
use gibench_harness::cpu::vpl::{self, halton, Vpl};
use gibench_harness::scene::anim::LightPose;
use gibench_harness::scene::descriptor::LightKind;
use gibench_harness::scene::Scene;
use gibench_harness::{Error, Result};
use glam::Vec3;

/// How many samples of each set, and how deep the walks go.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SampleSettings {
    /// Points on the area light (0 for none, or for a point light).
    pub direct: u32,
    /// Hits of the random walks.
    pub indirect: u32,
    /// Hits per walk at most (the thesis' Figure 5-10: 5).
    pub bounces: u32,
}

/// The two sets (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct LightSamples {
    pub direct: Vec<Vpl>,
    pub indirect: Vec<Vpl>,
    /// Walks started for the indirect set (its normalisation).
    pub walks: u32,
}

impl LightSamples {
    /// Both sets, direct first.
    pub fn all(&self) -> impl Iterator<Item = &Vpl> {
        self.direct.iter().chain(&self.indirect)
    }

    /// Both sets with their store slots (slot = light index, as the database numbers them).
    pub fn slotted(&self) -> Vec<(u32, Vpl)> {
        self.all()
            .enumerate()
            .map(|(i, v)| (i as u32, *v))
            .collect()
    }
}

/// The light samples of `light` in `scene` (see the module docs). Errors name the parameter:
/// direct samples need an area light; a set must not be empty of both.
pub fn generate(
    scene: &Scene,
    bvh: &SceneBvh,
    light: &LightPose,
    settings: SampleSettings,
) -> Result<LightSamples> {
    if settings.direct + settings.indirect == 0 {
        return Err(Error::param(
            "vpls",
            "no direct and no indirect samples: nothing would light the scene",
        ));
    }
    if settings.indirect > 0 && settings.bounces == 0 {
        return Err(Error::param(
            "bounces",
            "expected at least 1 for indirect samples",
        ));
    }
    let direct = if settings.direct == 0 {
        Vec::new()
    } else {
        let Some((half_u, half_v)) = light.area_half_extents() else {
            return Err(Error::param(
                "set",
                format!(
                    "direct light samples (set=direct) are points on an area light; the scene's light is {:?} (use set=indirect)",
                    light.kind
                ),
            ));
        };
        debug_assert_eq!(light.kind, LightKind::Area);
        let n = settings.direct;
        let flux = light.emitted_flux(&scene.extent) / n as f32;
        let normal = light.axis();
        (0..n as u64)
            .map(|i| {
                let (u, v) = (halton(i, 2) as f32, halton(i, 3) as f32);
                Vpl {
                    position: light.position + (2.0 * u - 1.0) * half_u + (2.0 * v - 1.0) * half_v,
                    normal,
                    flux,
                    color: Vec3::ONE,
                    bounce: 0,
                    path: i,
                    sample: Vec3::new(2.0 * u - 1.0, 2.0 * v - 1.0, 0.0),
                }
            })
            .collect()
    };
    let (walks, indirect) = if settings.indirect == 0 {
        (0, Vec::new())
    } else {
        let (used, mut v) =
            vpl::generate_at_least(scene, bvh, light, settings.indirect, settings.bounces, 1.0);
        if v.is_empty() {
            // Not the parameters' fault: the light's walks left the scene (a light far larger
            // than the scene, or outside it facing away).
            return Err(Error::Invalid(format!(
                "scene '{}': none of {} random walks from its light ({:?}, at {:?}) hit the scene, so there are no indirect light samples; check the light's position, direction and size in the scene file (field 'light')",
                scene.descriptor.name, used.paths, light.kind, light.position
            )));
        }
        v.truncate(settings.indirect as usize);
        (used.paths, v)
    };
    Ok(LightSamples {
        direct,
        indirect,
        walks,
    })
}
