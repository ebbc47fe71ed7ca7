//! Laine's VPL management (§4) on the CPU: the managed VPLs and sampling points, and each
//! frame's step (validity, domain update, deletion, creation, intensities) in named phases.

use gibench_harness::cpu::bvh::SceneBvh;
use gibench_harness::cpu::light::SampleDomain;
use gibench_harness::cpu::vpl::{self, Vpl};
use gibench_harness::glam::Vec3;
use gibench_harness::scene::anim::LightPose;
use gibench_harness::scene::{Scene, SceneExtent};
use rayon::prelude::*;

use crate::domain::{DomainKind, SamplingDomain};

/// A managed VPL.
#[derive(Clone, Copy, Debug)]
struct Managed {
    id: u64,
    slot: u32,
    vpl: Vpl,
}

/// Laine's VPL management (CPU only): the VPLs, their shadow-map slots and the sampling
/// points of rays that left the scene, updated once per frame by [`Manager::step`].
pub struct Manager {
    max_lights: u32,
    recalc_min: u32,
    recalc_max: u32,
    /// Live VPLs in creation order (the tile-assignment order).
    vpls: Vec<Managed>,
    /// Sampling points whose ray left the scene: they keep their place (and their share of the
    /// power, which leaves the scene) until their ray hits something or they are deleted.
    misses: Vec<(u64, Vec3)>,
    free_slots: Vec<u32>,
    next_id: u64,
    started: bool,
    /// Dispersion of the sampling points after this frame's management.
    last_dispersion: f64,
    /// The sampling points' domain after the last step.
    domain: Option<SamplingDomain>,
}

#[inline]
pub(crate) fn domain_kind(light: &LightPose) -> DomainKind {
    match light.domain() {
        SampleDomain::Sphere => DomainKind::Sphere,
        SampleDomain::Disc => DomainKind::Disc,
    }
}

/// Creation rays from which a batch is cast across cores (the first frame's); a frame's few
/// are cast on the calling thread.
const PARALLEL_RAYS: usize = 64;

/// Whether a VPL is still lit by the light at its new position (§4.4): in front of a spot's
/// (or area light's) plane — sampling points on the disc's boundary circle, which the
/// largest-empty-circle search produces, lie exactly in it and stay valid —, its surface
/// facing the light, and no static geometry in between.
#[inline]
fn still_valid(bvh: &SceneBvh, light: &LightPose, v: &Vpl, eps: f32) -> bool {
    if !light.in_front(v.position) {
        return false;
    }
    let (to_light, _) = light.toward_light(v.position);
    if v.normal.dot(to_light) < -1e-5 {
        return false;
    }
    light.unoccluded(bvh, v.position, eps)
}

/// What one frame's management did.
#[derive(Clone, Debug, Default)]
pub struct Step {
    /// Shadow-map slots of the VPLs created this frame (their maps must be rendered).
    pub new_slots: Vec<u32>,
    /// New sampling points (hits and misses).
    pub created: u32,
    /// Of those, how many the largest-empty-circle search put on the disc's rim (the paper's
    /// rule): their rays graze the light's plane, so any motion of the light invalidates them.
    pub on_rim: u32,
    /// VPLs deleted (invalid or redundant).
    pub deleted: u32,
    /// Whether the sampling points were triangulated from scratch (the first frame, or where
    /// moving last frame's triangulation did not apply) rather than moved.
    pub rebuilt: bool,
    /// Moved: the sampling points whose motion broke last frame's triangulation (taken out
    /// and put back).
    pub repaired: u32,
    /// Wall time of each part of the step.
    pub times: StepTimes,
}

/// Wall time of each part of one [`Manager::step`]: the paper's management steps 1–4 (§3),
/// with the update of the sampling points' triangulation (they all move with the light)
/// timed apart from step 2's deletions. Consecutive, non-overlapping intervals inside the
/// step; the dispersion the step records at its end (for reporting, not a paper step) is in
/// none.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepTimes {
    /// §4.4: the validity rays, and whether each missed sampling point still misses (across
    /// cores).
    pub validity: std::time::Duration,
    /// The surviving sampling points from the new light position, and their triangulation
    /// moved to them (or built), the invalid ones taken out.
    pub update: std::time::Duration,
    /// §4.5: redundant VPLs deleted until recalcMin slots are free.
    pub deletion: std::time::Duration,
    /// §4.6: new sampling points at the largest empty circle, and their rays.
    pub creation: std::time::Duration,
    /// §4.7: the Voronoi areas and from them the VPLs' intensities.
    pub intensities: std::time::Duration,
}

impl StepTimes {
    /// The parts' names as the reports write them, in step order.
    pub const NAMES: [&'static str; 5] =
        ["validity", "update", "deletion", "creation", "intensities"];

    /// The parts in step order (as [`NAMES`](Self::NAMES)).
    #[inline]
    pub fn parts(&self) -> [std::time::Duration; 5] {
        [
            self.validity,
            self.update,
            self.deletion,
            self.creation,
            self.intensities,
        ]
    }
}

impl Manager {
    /// At most `max_lights` VPLs; keep `recalc_min` slots free; at most `recalc_max` new
    /// sampling points per frame (the first frame fills every slot).
    pub fn new(max_lights: u32, recalc_min: u32, recalc_max: u32) -> Manager {
        Manager {
            max_lights,
            recalc_min: recalc_min.min(max_lights),
            recalc_max,
            vpls: Vec::new(),
            misses: Vec::new(),
            free_slots: (0..max_lights).rev().collect(),
            next_id: 0,
            started: false,
            last_dispersion: 0.0,
            domain: None,
        }
    }

    /// The live VPLs with their shadow-map slots, in creation order.
    #[inline]
    pub fn vpls(&self) -> Vec<(u32, Vpl)> {
        self.vpls.iter().map(|m| (m.slot, m.vpl)).collect()
    }

    /// The sampling points' domain after the last step (`None` before the first).
    #[inline]
    pub fn domain(&self) -> Option<&SamplingDomain> {
        self.domain.as_ref()
    }

    /// Dispersion (largest empty circle radius) of all sampling points after the last step.
    #[inline]
    pub fn dispersion(&self) -> f64 {
        self.last_dispersion
    }

    /// §4.4–§4.7 for one frame with the light at `light`.
    pub fn step(&mut self, scene: &Scene, bvh: &SceneBvh, light: LightPose) -> Step {
        let kind = domain_kind(&light);
        let mut clock = Clock::start();
        // 1. Validity, and the surviving VPLs' sampling points from the new light position.
        let checks = self.check_validity(scene, bvh, &light);
        let validity = clock.lap();
        let moved = self.update_domain(kind, &light, &scene.extent, checks);
        let mut domain = moved.domain;
        let update = clock.lap();
        // 2. Deletion of redundant VPLs until recalc-min slots are free.
        let deleted = moved.deleted + self.delete_redundant(&mut domain);
        let deletion = clock.lap();
        // 3. Creation at the largest empty circle's centre.
        let made = self.create(scene, bvh, &light, kind, &mut domain);
        let creation = clock.lap();
        // 4. Intensities: Voronoi areas over the domain's area.
        self.set_intensities(&light, &scene.extent, &domain);
        let intensities = clock.lap();
        self.last_dispersion = domain.dispersion();
        self.domain = Some(domain);
        Step {
            new_slots: made.new_slots,
            created: made.created,
            on_rim: made.on_rim,
            deleted,
            rebuilt: moved.rebuilt,
            repaired: moved.repaired,
            times: StepTimes {
                validity,
                update,
                deletion,
                creation,
                intensities,
            },
        }
    }

    /// Step 1's rays: per VPL whether it is still valid, and per missed sampling point
    /// whether its ray still misses.
    fn check_validity(&self, scene: &Scene, bvh: &SceneBvh, light: &LightPose) -> Validity {
        let (extent, eps) = (&scene.extent, scene.extent.ray_epsilon);
        // The validity rays, across cores (one per VPL, independent); likewise whether each
        // missed sampling point (fixed relative to the light) still misses.
        let valid: Vec<bool> = self
            .vpls
            .par_iter()
            .map(|m| still_valid(bvh, light, &m.vpl, eps))
            .collect();
        let still_missing: Vec<bool> = self
            .misses
            .par_iter()
            .map(|(_, sample)| {
                let (origin, dir) = light.ray_of_sample(*sample, extent);
                // Any hit, not the closest: only whether the ray still misses matters.
                !bvh.any_hit(origin, dir, eps, f32::INFINITY)
            })
            .collect();
        Validity {
            valid,
            still_missing,
        }
    }

    /// The rest of step 1: last frame's domain moved to the sampling points of the valid
    /// VPLs and of the misses that still miss (or built from them); the VPLs and misses it
    /// does not hold are dropped, the VPLs' slots freed.
    fn update_domain(
        &mut self,
        kind: DomainKind,
        light: &LightPose,
        extent: &SceneExtent,
        checks: Validity,
    ) -> MovedDomain {
        let Validity {
            valid,
            still_missing,
        } = checks;
        let mut deleted = 0;
        // The domain of the valid VPLs' new sampling points, then the misses that still
        // miss, in that order (the points all moved with the light).
        let samples: Vec<Vec3> = self
            .vpls
            .iter()
            .map(|m| light.sample_of_point(m.vpl.position, extent))
            .collect();
        let mut sites = Vec::with_capacity(self.vpls.len() + self.misses.len());
        // Per VPL and per miss, its index in `sites` if it is a candidate.
        let mut add = |id: u64, sample: Vec3, ok: bool| {
            ok.then(|| {
                sites.push((id, sample.as_dvec3()));
                sites.len() - 1
            })
        };
        let site_of_vpl: Vec<Option<usize>> = (self.vpls.iter().zip(&samples).zip(&valid))
            .map(|((m, s), ok)| add(m.id, *s, *ok))
            .collect();
        let site_of_miss: Vec<Option<usize>> = (self.misses.iter().zip(&still_missing))
            .map(|((id, s), ok)| add(*id, *s, *ok))
            .collect();
        let (mut rebuilt, mut repaired) = (true, 0);
        // Last frame's domain moved to the new points (kinetic, see `update_sites`), or built.
        let (domain, accepted) = match self.domain.take() {
            Some(mut d) if d.kind() == kind => {
                let u = d.update_sites(&sites);
                rebuilt = u.rebuilt;
                repaired = u.reinserted as u32;
                (d, u.accepted)
            }
            _ => SamplingDomain::from_sites(kind, &sites),
        };
        let mut kept = Vec::with_capacity(self.vpls.len());
        for ((m, sample), site) in self.vpls.drain(..).zip(samples).zip(site_of_vpl) {
            if site.is_some_and(|k| accepted[k]) {
                kept.push(Managed {
                    vpl: Vpl { sample, ..m.vpl },
                    ..m
                });
            } else {
                self.free_slots.push(m.slot);
                deleted += 1;
            }
        }
        self.vpls = kept;
        // Missed sampling points stay (fixed relative to the light) while their ray still misses.
        let mut site_of_miss = site_of_miss.into_iter();
        self.misses
            .retain(|_| site_of_miss.next().flatten().is_some_and(|k| accepted[k]));
        MovedDomain {
            domain,
            rebuilt,
            repaired,
            deleted,
        }
    }

    /// Step 2: redundant VPLs deleted until recalc-min slots are free; returns how many.
    fn delete_redundant(&mut self, domain: &mut SamplingDomain) -> u32 {
        let mut deleted = 0;
        // The VPLs are in creation order, so their ids ascend: found by binary search, and
        // taken out of the lists in one pass at the end.
        let mut queue = None;
        let mut gone = Vec::new();
        while (self.free_slots.len() as u32) < self.recalc_min {
            let q = queue.get_or_insert_with(|| domain.redundancy_queue());
            let Some(id) = domain.remove_redundant(q) else {
                break;
            };
            gone.push(id);
            if let Ok(i) = self.vpls.binary_search_by_key(&id, |m| m.id) {
                self.free_slots.push(self.vpls[i].slot);
                deleted += 1;
            }
        }
        if !gone.is_empty() {
            self.vpls.retain(|m| !gone.contains(&m.id));
            self.misses.retain(|(m, _)| !gone.contains(m));
        }
        deleted
    }

    /// Step 3: new sampling points at the largest empty circle's centre, and their rays, up
    /// to this frame's budget (every slot on the first frame).
    fn create(
        &mut self,
        scene: &Scene,
        bvh: &SceneBvh,
        light: &LightPose,
        kind: DomainKind,
        domain: &mut SamplingDomain,
    ) -> Creation {
        let budget = if self.started {
            self.recalc_max
        } else {
            self.max_lights
        };
        self.started = true;
        let mut made = Creation::default();
        // In batches: a batch of k sampling points, k = the creations left before the budget,
        // the VPL slots or the miss list could run out (each creation adds one VPL or one
        // miss), is inserted one by one as before, then its rays are cast — across cores for
        // large batches (the first frame's) — and their results taken in order. The points
        // and outcomes are the one-at-a-time loop's: the rays do not depend on the domain.
        let mut batch: Vec<(u64, Vec3)> = Vec::new();
        loop {
            let room = (budget - made.created)
                .min(self.max_lights.saturating_sub(self.vpls.len() as u32))
                .min((self.max_lights as usize).saturating_sub(self.misses.len()) as u32);
            if room == 0 {
                break;
            }
            let stopped = self.fill_batch(domain, kind, room, &mut batch, &mut made);
            let ray = |&(id, sample): &(u64, Vec3)| {
                vpl::vpl_from_sample(scene, bvh, light, sample, Vec3::ZERO, id)
            };
            let hits: Vec<Option<Vpl>> = if batch.len() >= PARALLEL_RAYS {
                batch.par_iter().map(ray).collect()
            } else {
                batch.iter().map(ray).collect()
            };
            for (&(id, sample), hit) in batch.iter().zip(hits) {
                if let Some(v) = hit {
                    let slot = self.free_slots.pop().expect("fewer VPLs than slots");
                    made.new_slots.push(slot);
                    self.vpls.push(Managed { id, slot, vpl: v });
                } else {
                    self.misses.push((id, sample));
                }
            }
            if stopped {
                break;
            }
        }
        made
    }

    /// Inserts up to `room` new sampling points into `domain`, each at the largest empty
    /// circle's centre, into `batch` (cleared first) with fresh ids, counting them in `made`;
    /// returns whether the domain stopped giving points (no circle, or a refused insertion).
    fn fill_batch(
        &mut self,
        domain: &mut SamplingDomain,
        kind: DomainKind,
        room: u32,
        batch: &mut Vec<(u64, Vec3)>,
        made: &mut Creation,
    ) -> bool {
        batch.clear();
        for _ in 0..room {
            let Some((centre, _, site)) = domain.largest_empty_circle_near() else {
                return true;
            };
            let id = self.next_id;
            self.next_id += 1;
            if domain.insert_near(id, centre, site).is_err() {
                return true;
            }
            made.created += 1;
            if kind == DomainKind::Disc && centre.truncate().length() >= 1.0 - 1e-9 {
                made.on_rim += 1;
            }
            batch.push((id, centre.as_vec3()));
        }
        false
    }

    /// Step 4: each VPL's flux from its sampling point's Voronoi area over the domain's area.
    fn set_intensities(
        &mut self,
        light: &LightPose,
        extent: &SceneExtent,
        domain: &SamplingDomain,
    ) {
        let total = light.domain().area();
        let power = light.emitted_flux(extent);
        // Each site's area sits at its index in the domain's order.
        let areas = domain.voronoi_areas();
        for m in &mut self.vpls {
            let area = match domain.site_index(m.id).and_then(|k| areas.get(k)) {
                Some(&(id, a)) if id == m.id => a,
                _ => 0.0,
            };
            let share = area / total;
            m.vpl.flux = power * share as f32 * m.vpl.color;
        }
    }
}

/// Step 1's ray results (see [`Manager::check_validity`]).
struct Validity {
    /// Per VPL, whether it is still lit.
    valid: Vec<bool>,
    /// Per missed sampling point, whether its ray still misses.
    still_missing: Vec<bool>,
}

/// What [`Manager::update_domain`] left: the moved (or built) domain and what it did.
struct MovedDomain {
    domain: SamplingDomain,
    rebuilt: bool,
    repaired: u32,
    /// VPLs dropped (invalid, or refused by the domain).
    deleted: u32,
}

/// What [`Manager::create`] made.
#[derive(Default)]
struct Creation {
    new_slots: Vec<u32>,
    created: u32,
    on_rim: u32,
}

/// Laps of a step's parts: each [`lap`](Self::lap) is the time since the previous one.
struct Clock(std::time::Instant);

impl Clock {
    #[inline]
    fn start() -> Clock {
        Clock(std::time::Instant::now())
    }

    #[inline]
    fn lap(&mut self) -> std::time::Duration {
        let now = std::time::Instant::now();
        let lap = now - self.0;
        self.0 = now;
        lap
    }
}
