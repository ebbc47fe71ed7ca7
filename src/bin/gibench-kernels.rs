//! `gibench-kernels`: runs one CPU kernel a fixed number of times on the generated Cornell box,
//! for counting its instructions under callgrind (`gibench instructions`). Setup (scene, BVH,
//! a filled sampling domain) happens outside [`gibench_kernel_body`], the only function
//! callgrind collects in (`--toggle-collect=*gibench_kernel_body*`), so the count is the
//! kernel's alone. Everything is single-threaded and deterministic.
//!
//! `gibench-kernels list` prints the kernel names; `gibench-kernels run NAME` runs one.
//! `GIBENCH_TEST_SLOW_KERNEL=NAME` runs that kernel's body twice: a deliberate regression for
//! testing the gate, never set otherwise.

use gibench_harness::cpu::bvh::SceneBvh;
use gibench_harness::glam::{DVec3, Vec3};
use gibench_harness::scene::assets::AssetPaths;
use gibench_harness::scene::Scene;
use gibench_laine::domain::{DomainKind, SamplingDomain};

/// The kernels, in the order `list` prints them.
const KERNELS: [&str; 8] = [
    "bvh-closest-hit-cornell",
    "bvh-shadow-cornell",
    "domain-delete-insert-disc-256",
    "domain-fill-at-largest-empty-circle-sphere-256",
    "domain-frame-disc-1024",
    "domain-frame-sphere-1024",
    "domain-voronoi-areas-disc-256",
    "vpl-generation-cornell",
];

/// Everything a kernel needs, made before collection starts.
pub struct Setup {
    scene: Scene,
    bvh: SceneBvh,
    dirs: Vec<Vec3>,
    targets: Vec<Vec3>,
    disc: SamplingDomain,
    sphere: SamplingDomain,
    disc_1024: SamplingDomain,
    sphere_1024: SamplingDomain,
}

fn setup() -> Setup {
    let scene = Scene::load_named("cornell", &AssetPaths::standard(None)).expect("cornell");
    let bvh = SceneBvh::new(&scene.mesh);
    let light = gibench_harness::scene::anim::FrameClock::new(&scene.descriptor)
        .frame(0)
        .light;
    let dirs = gibench_harness::cpu::vpl::fibonacci_sphere(1024);
    let targets = dirs
        .iter()
        .filter_map(|d| bvh.closest_hit(light.position, *d, 0.0, f32::INFINITY))
        .map(|h| h.position + h.geometric_normal * scene.extent.ray_epsilon)
        .collect();
    // One frame before the counted ones, as the management's frames follow others: buffers
    // sized, candidates kept.
    let [mut disc_1024, mut sphere_1024] =
        [DomainKind::Disc, DomainKind::Sphere].map(|k| SamplingDomain::spiral(k, 1024));
    domain_frame(&mut disc_1024, 0);
    domain_frame(&mut sphere_1024, 0);
    Setup {
        scene,
        bvh,
        dirs,
        targets,
        disc: SamplingDomain::spiral(DomainKind::Disc, 256),
        sphere: SamplingDomain::spiral(DomainKind::Sphere, 256),
        disc_1024,
        sphere_1024,
    }
}

/// The domain's share of one frame of Laine's management at 1024 VPLs, without its rays: every
/// site moved as a moving light moves them (a turn of 0.002 rad, and on the disc a shear and a
/// shrink of 0.05 %: a few sites repaired per frame, as on Sibenik), four redundant sites
/// deleted, eight created at the largest empty circle, the Voronoi areas.
fn domain_frame(d: &mut SamplingDomain, round: u64) -> f64 {
    let (s, c) = 0.002f64.sin_cos();
    let mut sites: Vec<(u64, DVec3)> = d
        .points()
        .into_iter()
        .map(|(id, q)| {
            let p = match d.kind() {
                DomainKind::Disc => {
                    DVec3::new(c * q.x - s * q.y + 0.001 * q.y, s * q.x + c * q.y, 0.0) * 0.9995
                }
                DomainKind::Sphere => DVec3::new(c * q.x - s * q.z, q.y, s * q.x + c * q.z),
            };
            (id, p)
        })
        .collect();
    // The sphere's projection pole (listed last) first, as the management lists it.
    if d.kind() == DomainKind::Sphere {
        sites.rotate_right(1);
    }
    let moved = d.update_sites(&sites);
    let mut queue = d.redundancy_queue();
    for _ in 0..4 {
        d.remove_redundant(&mut queue).expect("sites to delete");
    }
    for k in 0..8 {
        let (centre, _, near) = d.largest_empty_circle_near().expect("sites");
        d.insert_near(1_000_000 + 8 * round + k, centre, near)
            .expect("inserted");
    }
    let areas: f64 = d.voronoi_areas().iter().map(|(_, a)| a).sum();
    areas + moved.reinserted as f64 + if moved.rebuilt { 1e6 } else { 0.0 }
}

/// The kernel `name` once; what it returns keeps the work from being optimised away.
#[inline(never)]
#[no_mangle]
pub extern "Rust" fn gibench_kernel_body(name: &str, s: &mut Setup, round: u64) -> f64 {
    let light = gibench_harness::scene::anim::FrameClock::new(&s.scene.descriptor)
        .frame(0)
        .light;
    match name {
        "bvh-closest-hit-cornell" => s
            .dirs
            .iter()
            .filter_map(|d| s.bvh.closest_hit(light.position, *d, 0.0, f32::INFINITY))
            .map(|h| h.t as f64)
            .sum(),
        "bvh-shadow-cornell" => s
            .targets
            .iter()
            .filter(|t| s.bvh.occluded(light.position, **t, 1e-4))
            .count() as f64,
        // Sixteen deletions, each followed by the point's insertion under a new id. (One pair
        // was 13k instructions, of which a few hundred moved with the heap's state alone —
        // where an allocation landed after the scene's load —: up to 3 % between builds of
        // the same domain code, past the gate's threshold. Over sixteen it is a fraction.)
        "domain-delete-insert-disc-256" => {
            let mut sum = 0.0;
            for k in 0..16 {
                let victim = 16 * round + k;
                let p = s.disc.remove(victim).expect("present");
                s.disc.insert(256 + victim, p).expect("reinserted");
                sum += p.x;
            }
            sum
        }
        // As the management creates points: 16 times, the largest empty circle and an insertion
        // at its centre (the first query fills the kept candidates, the later ones update them).
        "domain-fill-at-largest-empty-circle-sphere-256" => {
            let mut sum = 0.0;
            for k in 0..16 {
                let (c, r, site) = s.sphere.largest_empty_circle_near().expect("sites");
                s.sphere
                    .insert_near(1_000 + 16 * round + k, c, site)
                    .expect("inserted");
                sum += r;
            }
            sum
        }
        "domain-frame-disc-1024" => domain_frame(&mut s.disc_1024, round + 1),
        "domain-frame-sphere-1024" => domain_frame(&mut s.sphere_1024, round + 1),
        "domain-voronoi-areas-disc-256" => s.disc.voronoi_areas().iter().map(|(_, a)| a).sum(),
        "vpl-generation-cornell" => {
            let rho = s.scene.average_reflectance().max_element();
            gibench_harness::cpu::vpl::generate_at_least(&s.scene, &s.bvh, &light, 256, 1, rho)
                .1
                .len() as f64
        }
        other => panic!("unknown kernel {other}"),
    }
}

fn main() -> std::process::ExitCode {
    gibench_harness::cpu::threads::join_global_pool();
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args
        .iter()
        .map(String::as_str)
        .collect::<Vec<_>>()
        .as_slice()
    {
        ["list"] => {
            for k in KERNELS {
                println!("{k}");
            }
            std::process::ExitCode::SUCCESS
        }
        ["run", name] if KERNELS.contains(name) => {
            let mut s = setup();
            let slow = std::env::var("GIBENCH_TEST_SLOW_KERNEL").is_ok_and(|v| v == *name);
            let mut acc = 0.0;
            for round in 0..if slow { 2 } else { 1 } {
                acc += gibench_kernel_body(name, &mut s, round);
            }
            println!("{acc}");
            std::process::ExitCode::SUCCESS
        }
        _ => {
            eprintln!(
                "usage: gibench-kernels list | run NAME (one of: {})",
                KERNELS.join(", ")
            );
            std::process::ExitCode::FAILURE
        }
    }
}
