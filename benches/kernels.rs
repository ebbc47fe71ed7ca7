//! Criterion benches: CPU kernels the techniques lean on — BVH closest-hit and shadow rays on
//! Cornell and Sibenik; Laine's sampling domains (disc and sphere, 256 and 1024 points): one
//! delete + insert, the largest empty circle, the Voronoi areas; Laine's whole VPL management
//! per frame, spot and omni; VPL generation (Keller's light paths); the reference path tracer
//! (one path per pixel); ISM's point pool — and one whole frame of each registered technique on the Cornell box
//! (GPU, flushed per frame). Laine's management and the reference, whose work runs across cores,
//! are also measured by CPU time (every thread of the process: `…-cpu/…`), beside wall time.
//!
//! `cargo bench` runs them; `cargo bench -- rays` runs a subset; `cargo test --benches` (CI)
//! runs each once as a test.

use criterion::measurement::{Measurement, ValueFormatter};
use criterion::{criterion_group, Criterion, Throughput};
use gibench_harness::glam::Vec3;
use gibench_harness::gpu::profiler::{ProfileMode, Profiler};
use gibench_harness::gpu::{GpuContext, GpuOptions};
use gibench_harness::run::runner::Harness;
use gibench_harness::scene::assets::AssetPaths;
use gibench_harness::scene::Scene;

use gibench_papers::registry;

/// A criterion measurement: the CPU time of every thread of the process, in nanoseconds (where
/// the platform has no such clock it reads 0 and the bench says so).
/// The groups measured with it end in `-cpu`: `gibench export --criterion` exports those as
/// the `cpu-time` measure, the others as `latency`.
struct ProcessCpuTime;

impl Measurement for ProcessCpuTime {
    type Intermediate = f64;
    type Value = f64;

    fn start(&self) -> f64 {
        gibench_harness::measure::calibrate::process_cpu_ms().unwrap_or(0.0)
    }

    fn end(&self, start: f64) -> f64 {
        (self.start() - start) * 1e6
    }

    fn add(&self, a: &f64, b: &f64) -> f64 {
        a + b
    }

    fn zero(&self) -> f64 {
        0.0
    }

    fn to_f64(&self, v: &f64) -> f64 {
        *v
    }

    fn formatter(&self) -> &dyn ValueFormatter {
        &CpuFormatter
    }
}

/// Formats CPU nanoseconds as "ns/µs/ms/s (CPU)".
struct CpuFormatter;

impl ValueFormatter for CpuFormatter {
    fn scale_values(&self, typical: f64, values: &mut [f64]) -> &'static str {
        let (factor, unit) = if typical < 1e3 {
            (1.0, "ns CPU")
        } else if typical < 1e6 {
            (1e-3, "µs CPU")
        } else if typical < 1e9 {
            (1e-6, "ms CPU")
        } else {
            (1e-9, "s CPU")
        };
        for v in values {
            *v *= factor;
        }
        unit
    }

    fn scale_throughputs(
        &self,
        _: f64,
        throughput: &Throughput,
        values: &mut [f64],
    ) -> &'static str {
        let per = match *throughput {
            Throughput::Bytes(n) | Throughput::BytesDecimal(n) | Throughput::Bits(n) => n as f64,
            Throughput::Elements(n) => n as f64,
            Throughput::ElementsAndBytes { elements, .. } => elements as f64,
        };
        for v in values {
            *v = per * 1e9 / *v;
        }
        "per CPU-second"
    }

    fn scale_for_machines(&self, _: &mut [f64]) -> &'static str {
        "ns CPU"
    }
}

fn rays(c: &mut Criterion) {
    let assets = AssetPaths::standard(None);
    for name in ["cornell", "sibenik"] {
        let Ok(scene) = Scene::load_named(name, &assets) else {
            eprintln!("skipping rays/{name}: scene not found");
            continue;
        };
        let bvh = gibench_harness::cpu::bvh::SceneBvh::new(&scene.mesh);
        let origin = gibench_harness::scene::anim::FrameClock::new(&scene.descriptor)
            .frame(0)
            .light
            .position;
        let dirs = gibench_harness::cpu::vpl::fibonacci_sphere(1024);
        c.bench_function(&format!("rays/closest-hit-1024/{name}"), |b| {
            b.iter(|| {
                dirs.iter()
                    .filter(|d| bvh.closest_hit(origin, **d, 0.0, f32::INFINITY).is_some())
                    .count()
            })
        });
        // Shadow rays from the light to where the closest-hit rays land.
        let targets: Vec<Vec3> = dirs
            .iter()
            .filter_map(|d| bvh.closest_hit(origin, *d, 0.0, f32::INFINITY))
            .map(|h| h.position + h.geometric_normal * scene.extent.ray_epsilon)
            .collect();
        c.bench_function(&format!("rays/shadow-1024/{name}"), |b| {
            b.iter(|| {
                targets
                    .iter()
                    .filter(|t| bvh.occluded(origin, **t, 1e-4))
                    .count()
            })
        });
    }
}

/// Laine's sampling domains with n points: one delete + insert (the steady state of a frame's
/// changes), the largest empty circle and the Voronoi areas.
fn domains(c: &mut Criterion) {
    use gibench_laine::domain::{DomainKind, SamplingDomain};
    for kind in [DomainKind::Disc, DomainKind::Sphere] {
        for n in [256u64, 1024] {
            let mut d = SamplingDomain::spiral(kind, n);
            let tag = format!("{}-{n}", format!("{kind:?}").to_lowercase());
            let mut next = n;
            c.bench_function(&format!("domain/delete-insert/{tag}"), |b| {
                b.iter(|| {
                    let victim = next - n;
                    let p = d.remove(victim).expect("present");
                    d.insert(next, p).expect("reinserted");
                    next += 1;
                })
            });
            c.bench_function(&format!("domain/largest-empty-circle/{tag}"), |b| {
                b.iter(|| d.largest_empty_circle())
            });
            c.bench_function(&format!("domain/voronoi-areas/{tag}"), |b| {
                b.iter(|| d.voronoi_areas())
            });
        }
    }
}

/// Keller's light paths: 256 VPLs (one bounce) and 256 paths of up to four bounces on Cornell
/// and Sibenik.
fn vpl_generation(c: &mut Criterion) {
    let assets = AssetPaths::standard(None);
    for name in ["cornell", "sibenik"] {
        let Ok(scene) = Scene::load_named(name, &assets) else {
            eprintln!("skipping vpl-generation/{name}: scene not found");
            continue;
        };
        let bvh = gibench_harness::cpu::bvh::SceneBvh::new(&scene.mesh);
        let light = gibench_harness::scene::anim::FrameClock::new(&scene.descriptor)
            .frame(0)
            .light;
        let rho = scene.average_reflectance().max_element();
        for bounces in [1u32, 4] {
            c.bench_function(
                &format!("vpl-generation/256-bounces-{bounces}/{name}"),
                |b| {
                    b.iter(|| {
                        gibench_harness::cpu::vpl::generate_at_least(
                            &scene, &bvh, &light, 256, bounces, rho,
                        )
                        .1
                        .len()
                    })
                },
            );
        }
    }
}

/// ISM's point pool (`ir::points`): 65,536 points on the surfaces of Cornell and Sibenik,
/// uniform by area, shuffled — `ism`'s preparation step.
fn point_pool(c: &mut Criterion) {
    let assets = AssetPaths::standard(None);
    for name in ["cornell", "sibenik"] {
        let Ok(scene) = Scene::load_named(name, &assets) else {
            eprintln!("skipping point-pool/{name}: scene not found");
            continue;
        };
        c.bench_function(&format!("point-pool/65536/{name}"), |b| {
            b.iter(|| {
                gibench_harness::kit::ir::points::sample_scene(&scene, 65_536, 1)
                    .expect("surfaces")
                    .len()
            })
        });
    }
}

/// The reference path tracer: one path per pixel (8 bounces) over a 64x48 image of Cornell.
fn reference_paths(c: &mut Criterion) {
    reference_paths_by(c, "reference");
}

fn reference_paths_cpu(c: &mut Criterion<ProcessCpuTime>) {
    reference_paths_by(c, "reference-cpu");
}

/// The reference path tracer, one 8-bounce path per pixel of a 64x48 Cornell frame, as bench
/// group `group` under measurement `M`.
fn reference_paths_by<M: Measurement + 'static>(c: &mut Criterion<M>, group: &str) {
    let scene =
        Scene::load_named("cornell", &AssetPaths::standard(None)).expect("cornell is generated");
    let frame = gibench_harness::scene::anim::FrameClock::new(&scene.descriptor).frame(0);
    let settings = gibench_harness::cpu::reference::ReferenceSettings {
        spp: 1,
        bounces: 8,
        seed: 0,
    };
    c.bench_function(&format!("{group}/1-path-per-pixel-64x48/cornell"), |b| {
        b.iter(|| {
            gibench_harness::cpu::reference::render_reference(&scene, &frame, [64, 48], &settings)
        })
    });
}

/// Laine's VPL management per frame (validity, deletion, creation, Voronoi intensities), spot
/// and omni, at 256 and 1024 VPLs, with the light moving along Sibenik's path (Cornell if
/// Sibenik is not on the asset path).
fn laine_management(c: &mut Criterion) {
    laine_management_by(c, "laine-management");
}

fn laine_management_cpu(c: &mut Criterion<ProcessCpuTime>) {
    laine_management_by(c, "laine-management-cpu");
}

/// [`laine_management`] as bench group `group` under measurement `M`.
fn laine_management_by<M: Measurement + 'static>(c: &mut Criterion<M>, group: &str) {
    use gibench_harness::scene::descriptor::LightKind;
    let assets = AssetPaths::standard(None);
    let scene = Scene::load_named("sibenik", &assets)
        .or_else(|e| {
            eprintln!("{group}: sibenik not loaded ({e}); on cornell instead");
            Scene::load_named("cornell", &assets)
        })
        .expect("cornell is generated");
    let bvh = gibench_harness::cpu::bvh::SceneBvh::new(&scene.mesh);
    for kind in [LightKind::Spot, LightKind::Omni] {
        let mut desc = scene.descriptor.clone();
        desc.light.kind = kind;
        let clock = gibench_harness::scene::anim::FrameClock::new(&desc);
        for vpls in [256, 1024] {
            let mut m = gibench_laine::Manager::new(vpls, 4, 8);
            m.step(&scene, &bvh, clock.frame(0).light);
            let mut frame = 1;
            let name = format!(
                "{group}/{}-{vpls}/{}",
                format!("{kind:?}").to_lowercase(),
                desc.name
            );
            c.bench_function(&name, |b| {
                b.iter(|| {
                    m.step(&scene, &bvh, clock.frame(frame).light);
                    frame += 1;
                })
            });
        }
    }
}

fn frames(c: &mut Criterion) {
    let Ok(gpu) = GpuContext::new(&GpuOptions::default()) else {
        eprintln!("skipping frame benches: no GPU adapter");
        return;
    };
    let scene =
        Scene::load_named("cornell", &AssetPaths::standard(None)).expect("cornell is generated");
    let config = gibench_test_support::one_frame([256, 192]).build();
    let h = Harness::new(&gpu, &scene, &config).expect("harness");
    for info in registry::all() {
        let params = info.parse_params(&[]).expect("defaults");
        let prepared = h.prepare(info, &params, &config).expect("preparation");
        let (mut technique, compose) = h
            .build(info, &params, &config, &prepared)
            .expect("technique");
        let mut profiler = Profiler::new(&gpu, ProfileMode::Frame);
        let mut i = 0;
        c.bench_function(&format!("frame/cornell-256x192/{}", info.name), |b| {
            b.iter(|| {
                let frame = h.clock.frame(i);
                i += 1;
                h.render_frame(technique.as_mut(), &compose, &mut profiler, &frame, true)
                    .expect("frame");
                gpu.flush().expect("flush");
            })
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = rays, domains, laine_management, vpl_generation, point_pool, reference_paths, frames
}
criterion_group! {
    name = cpu_benches;
    config = Criterion::default().with_measurement(ProcessCpuTime).sample_size(20);
    targets = laine_management_cpu, reference_paths_cpu
}
// `criterion_main!`'s `main`, with this thread made a worker of the CPU pool first (as the
// gibench binary does: see `gibench_harness::cpu::threads`).
fn main() {
    gibench_harness::cpu::threads::join_global_pool();
    benches();
    cpu_benches();
    Criterion::default().configure_from_args().final_summary();
}
