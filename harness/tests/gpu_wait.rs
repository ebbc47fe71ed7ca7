//! A submission that runs longer than wgpu's GL backend lets one fence wait last (`u32::MAX`
//! nanoseconds, about 4.3 s, even for `wait_indefinitely`) completes: `GpuContext::flush` keeps
//! waiting instead of failing with "The requested Wait timed out" (seen on llvmpipe with a
//! Sibenik frame of `keller-full`). A `--gpu-timeout` shorter than the work fails, naming it.

use std::time::{Duration, Instant};

use gibench_harness::gpu::{available_backends, say_uncaptured, GpuContext, GpuOptions};
use gibench_harness::passes::{compute_pipeline, storage_entry};
use gibench_harness::wgpu;

/// One invocation steps a linear congruential generator `n` times (work that cannot be folded
/// away or spread over threads) and stores the result.
const SPIN: &str = "
@group(0) @binding(0) var<storage, read_write> state: array<u32>;
@compute @workgroup_size(1)
fn spin() {
    let n = state[0];
    var x = state[1];
    for (var i = 0u; i < n; i = i + 1u) {
        x = x * 1664525u + 1013904223u;
    }
    state[2] = x;
}
";

fn lcg(n: u32, seed: u32) -> u32 {
    (0..n).fold(seed, |x, _| x.wrapping_mul(1664525).wrapping_add(1013904223))
}

struct Spin {
    pipeline: wgpu::ComputePipeline,
    group: wgpu::BindGroup,
    state: wgpu::Buffer,
    readback: wgpu::Buffer,
}

impl Spin {
    fn new(gpu: &GpuContext) -> Spin {
        let layout = gpu
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("spin"),
                entries: &[storage_entry(0, false)],
            });
        let pipeline = compute_pipeline(&gpu.device, "spin", SPIN, &[&layout], "spin");
        let state = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("spin state"),
            size: 16,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("spin readback"),
            size: 16,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("spin"),
            layout: &layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: state.as_entire_binding(),
            }],
        });
        Spin {
            pipeline,
            group,
            state,
            readback,
        }
    }

    /// Submits `n` steps from `seed`, waits with `flush`, and returns how long the wait took
    /// and the value the GPU computed (or the wait's error).
    fn run(&self, gpu: &GpuContext, n: u32, seed: u32) -> (Duration, Result<u32, String>) {
        gpu.queue
            .write_buffer(&self.state, 0, bytemuck::cast_slice(&[n, seed, 0, 0]));
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.group, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        enc.copy_buffer_to_buffer(&self.state, 0, &self.readback, 0, 16);
        gpu.queue.submit([enc.finish()]);
        let start = Instant::now();
        let waited = gpu.flush();
        let took = start.elapsed();
        if let Err(e) = waited {
            return (took, Err(e.to_string()));
        }
        let slice = self.readback.slice(..);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        if let Err(e) = gpu.flush() {
            return (took, Err(e.to_string()));
        }
        let value = {
            let mapped = slice.get_mapped_range().unwrap();
            bytemuck::cast_slice::<u8, u32>(&mapped)[2]
        };
        self.readback.unmap();
        (took, Ok(value))
    }
}

fn open(backend: &str, gpu_timeout: Option<f64>) -> GpuContext {
    GpuContext::new(&GpuOptions {
        backend: Some(backend.into()),
        gpu_timeout,
        ..Default::default()
    })
    .expect("a GPU adapter")
}

/// The backend to test on: GL, whose fence waits are capped, where present.
fn backend() -> &'static str {
    let present = available_backends();
    if present.contains(&"gl") {
        "gl"
    } else {
        say_uncaptured(
            "gpu_wait: no GL adapter here; the long wait is tested on Vulkan, whose waits are not capped",
        );
        present.first().copied().expect("a GPU adapter")
    }
}

#[test]
fn a_submission_longer_than_the_gl_wait_cap_completes() {
    let backend = backend();
    let gpu = open(backend, None);
    let spin = Spin::new(&gpu);
    // Size the work from a short run so that the long one lasts about 7 s here; if the machine
    // sped up in between and it was shorter than 5 s, it is run again, longer.
    let n0 = 1u32 << 20;
    let (t0, v0) = spin.run(&gpu, n0, 7);
    assert_eq!(v0, Ok(lcg(n0, 7)));
    let mut n = ((n0 as f64) * 7.0 / t0.as_secs_f64().max(1e-3)).min(u32::MAX as f64) as u32;
    for _ in 0..3 {
        let (took, value) = spin.run(&gpu, n, 11);
        assert_eq!(
            value,
            Ok(lcg(n, 11)),
            "{backend}: {n} steps, waited {took:?}"
        );
        if took > Duration::from_secs(5) {
            return;
        }
        n = n.saturating_mul(2);
    }
    panic!("{backend}: could not make a submission last 5 s (the test did not test the wait)");
}

#[test]
fn a_gpu_timeout_shorter_than_the_work_fails_naming_it() {
    let backend = backend();
    let gpu = open(backend, Some(0.5));
    let spin = Spin::new(&gpu);
    let n0 = 1u32 << 20;
    let (t0, v0) = spin.run(&gpu, n0, 3);
    assert_eq!(v0, Ok(lcg(n0, 3)));
    // About 4 s of work against a limit of 0.5 s (waits are renewed every second, so the
    // error comes after one or two of them).
    let n = ((n0 as f64) * 4.0 / t0.as_secs_f64().max(1e-3)).min(u32::MAX as f64) as u32;
    let (_, value) = spin.run(&gpu, n, 5);
    let e = value.expect_err("a 4 s submission under a 0.5 s limit");
    assert!(e.contains("gpu-timeout") && e.contains("0.5 s"), "{e}");
    // Nonsense limits are refused before any adapter is opened.
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = GpuContext::new(&GpuOptions {
            gpu_timeout: Some(bad),
            ..Default::default()
        })
        .err()
        .expect("refused")
        .to_string();
        assert!(e.contains("gpu-timeout"), "{bad}: {e}");
    }
}
