//! Laine's VPL management on the Cornell box (CPU only): invariants every frame, and the
//! dispersion of the sampling points under a still light.

use gibench_harness::cpu::bvh::SceneBvh;
use gibench_harness::scene::anim::FrameClock;
use gibench_harness::scene::assets::AssetPaths;
use gibench_harness::scene::descriptor::LightKind;
use gibench_harness::scene::Scene;
use gibench_laine::Manager;

fn cornell(kind: LightKind) -> (Scene, SceneBvh) {
    let mut scene = Scene::load_named("cornell", &AssetPaths::standard(None)).unwrap();
    scene.descriptor.light.kind = kind;
    if kind == LightKind::Omni {
        // Keep the omni light inside the box, below the ceiling.
        for k in &mut scene.descriptor.light.path.keys {
            k.position[1] = 400.0;
        }
    }
    let bvh = SceneBvh::new(&scene.mesh);
    (scene, bvh)
}

#[test]
fn still_light_dispersion_only_goes_down() {
    for kind in [LightKind::Spot, LightKind::Omni] {
        let (scene, bvh) = cornell(kind);
        let light = FrameClock::new(&scene.descriptor).frame(0).light;
        let mut m = Manager::new(256, 4, 8);
        m.step(&scene, &bvh, light);
        let mut previous = m.dispersion();
        let first = previous;
        for frame in 1..80 {
            m.step(&scene, &bvh, light);
            let d = m.dispersion();
            assert!(
                d <= previous + 1e-12,
                "{kind:?} frame {frame}: dispersion rose from {previous} to {d}"
            );
            previous = d;
        }
        assert!(
            previous < first,
            "{kind:?}: dispersion did not improve ({first} -> {previous})"
        );
    }
}

#[test]
fn management_invariants_while_the_light_moves() {
    for kind in [LightKind::Spot, LightKind::Omni] {
        let (scene, bvh) = cornell(kind);
        let clock = FrameClock::new(&scene.descriptor);
        let mut m = Manager::new(128, 4, 8);
        for frame in 0..60 {
            let light = clock.frame(frame).light;
            let step = m.step(&scene, &bvh, light);
            let vpls = m.vpls();
            if frame == 0 {
                // The first frame fills every slot (hits and misses).
                assert_eq!(
                    step.created, 128,
                    "{kind:?}: the first frame fills every slot"
                );
            } else {
                assert!(
                    step.created <= 8,
                    "{kind:?} frame {frame}: {} new sampling points",
                    step.created
                );
            }
            let mut slots: Vec<u32> = vpls.iter().map(|(s, _)| *s).collect();
            slots.sort();
            slots.dedup();
            assert_eq!(slots.len(), vpls.len(), "slots are unique");
            let mut flux = gibench_harness::glam::Vec3::ZERO;
            for (_, v) in &vpls {
                // Every VPL is lit by the current light (validity, §4.4).
                assert!(
                    !bvh.occluded(light.position, v.position, 1e-4),
                    "{kind:?} frame {frame}: an occluded VPL"
                );
                if kind == LightKind::Spot {
                    let d = v.position - light.position;
                    assert!(d.dot(light.direction) >= -1e-5 * d.length());
                }
                flux += v.flux;
            }
            // Intensities are Voronoi shares of the power times the albedo (§4.7): the total
            // estimates the same first-bounce flux as 1024 Halton light paths do.
            let halton: gibench_harness::glam::Vec3 =
                gibench_harness::cpu::vpl::total_flux(&gibench_harness::cpu::vpl::generate(
                    &scene,
                    &bvh,
                    &light,
                    &gibench_harness::cpu::vpl::VplSettings::new(1024),
                ));
            for c in 0..3 {
                assert!(
                    (flux[c] - halton[c]).abs() <= 0.1 * halton[c],
                    "{kind:?} frame {frame}: flux {flux} vs {halton} from light paths"
                );
            }
        }
    }
}

#[test]
fn area_light_vpls_lie_in_front_of_the_light() {
    let scene = Scene::load_named("cornell-area", &AssetPaths::standard(None)).unwrap();
    let bvh = SceneBvh::new(&scene.mesh);
    let clock = FrameClock::new(&scene.descriptor);
    let mut m = Manager::new(256, 4, 8);
    for frame in 0..30 {
        let light = clock.frame(frame).light;
        assert_eq!(light.kind, LightKind::Area);
        m.step(&scene, &bvh, light);
        let vpls = m.vpls();
        assert!(vpls.len() > 200, "frame {frame}: {} VPLs", vpls.len());
        for (_, v) in &vpls {
            // In front, or in the light's plane (Laine's largest-empty-circle search puts new
            // sampling points on the disc's rim, whose rays graze the plane).
            let d = v.position - light.position;
            assert!(
                d.dot(light.direction) >= -1e-5 * d.length(),
                "frame {frame}: a VPL at {} is behind the light",
                v.position
            );
        }
    }
}

/// Each VPL's flux is the light's flux times its own sampling point's share of the domain (its
/// Voronoi area over the domain's) times its colour: the area read for that VPL (by its id,
/// `Vpl::path`), not another site's.
#[test]
fn each_vpl_gets_its_own_voronoi_share() {
    for kind in [LightKind::Spot, LightKind::Omni] {
        let (scene, bvh) = cornell(kind);
        let clock = FrameClock::new(&scene.descriptor);
        let mut m = Manager::new(128, 4, 8);
        for frame in 0..30 {
            let light = clock.frame(frame).light;
            m.step(&scene, &bvh, light);
            let areas: std::collections::HashMap<u64, f64> = m
                .domain()
                .expect("a domain after a step")
                .voronoi_areas()
                .into_iter()
                .collect();
            let (power, total) = (light.emitted_flux(&scene.extent), light.domain().area());
            for (_, v) in m.vpls() {
                let share = areas[&v.path] / total;
                assert_eq!(
                    v.flux,
                    power * share as f32 * v.color,
                    "{kind:?} frame {frame}: VPL {}",
                    v.path
                );
            }
        }
    }
}

/// FNV-1a over 64-bit words.
fn fnv(h: &mut u64, word: u64) {
    for b in word.to_le_bytes() {
        *h = (*h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
    }
}

/// The VPL layout frame by frame — every VPL's slot, position, normal and sampling point, the
/// counts created and deleted — over 300 frames of the moving light, hashed and pinned, and the
/// dispersion's sum over the frames: the faster management (kept largest-empty-circle
/// candidates, hinted point location, rays across cores, the per-frame bulk load, then the
/// moved triangulation and the queued deletions) must give exactly the layout the rules gave
/// before it. The constants were computed with the sites inserted one by one (before the bulk
/// load); another numbering of the triangles' corners can move a circumradius in its last bits
/// (≤ 10⁻¹³ relative), hence the dispersion's tolerance. The per-frame flux (through the
/// Voronoi areas, whose last bits are not pinned) is left out. A deliberate change of the rules
/// changes these.
#[test]
fn the_vpl_layout_is_the_one_the_rules_gave_before() {
    let mut got = Vec::new();
    for kind in [LightKind::Spot, LightKind::Omni] {
        let (scene, bvh) = cornell(kind);
        let clock = FrameClock::new(&scene.descriptor);
        let mut m = Manager::new(256, 4, 8);
        let mut h = 0xcbf2_9ce4_8422_2325u64;
        let mut dispersion = 0.0;
        for frame in 0..300 {
            let s = m.step(&scene, &bvh, clock.frame(frame).light);
            dispersion += m.dispersion();
            fnv(&mut h, ((s.created as u64) << 32) | s.deleted as u64);
            for (slot, v) in m.vpls() {
                fnv(&mut h, slot as u64);
                for x in [v.position, v.normal, v.sample] {
                    for c in x.to_array() {
                        fnv(&mut h, c.to_bits() as u64);
                    }
                }
            }
        }
        got.push((format!("{h:016x}"), dispersion));
    }
    let want = [
        ("ada2acf8037b5c9b", 29.4481945802551),
        ("4f65e912274d668c", 51.617862371010986),
    ];
    for ((h, d), (wh, wd)) in got.iter().zip(want) {
        assert_eq!(h, wh);
        assert!((d - wd).abs() <= 1e-9 * wd, "dispersion sum {d} vs {wd}");
    }
}

/// `Step::times` splits the step into consecutive parts: their sum never exceeds the step's
/// wall time measured around it (an interval counted twice, or one reaching outside the step,
/// would), each part the steps run take time over a moving light's frames, and on the first
/// frame, which creates every VPL, creation is the largest part.
#[test]
fn step_times_are_consecutive_parts_of_the_step() {
    for kind in [LightKind::Spot, LightKind::Omni] {
        let (scene, bvh) = cornell(kind);
        let clock = FrameClock::new(&scene.descriptor);
        let mut m = Manager::new(256, 4, 8);
        let mut totals = [std::time::Duration::ZERO; 5];
        for frame in 0..30 {
            let start = std::time::Instant::now();
            let step = m.step(&scene, &bvh, clock.frame(frame).light);
            let elapsed = start.elapsed();
            let parts = step.times.parts();
            let sum: std::time::Duration = parts.iter().sum();
            assert!(
                sum <= elapsed,
                "{kind:?} frame {frame}: parts {parts:?} add up to more than the step ({elapsed:?})"
            );
            if frame == 0 {
                assert!(
                    parts.iter().all(|p| *p <= step.times.creation),
                    "{kind:?}: the fill frame's parts {parts:?}"
                );
            }
            for (t, p) in totals.iter_mut().zip(parts) {
                *t += p;
            }
        }
        // Every part but the deletions runs each frame; the omni light's VPLs stay valid, so
        // its frames delete redundant ones.
        for (name, t) in gibench_laine::StepTimes::NAMES.iter().zip(totals) {
            if *name != "deletion" || kind == LightKind::Omni {
                assert!(
                    t > std::time::Duration::ZERO,
                    "{kind:?}: {name} took no time"
                );
            }
        }
    }
}
