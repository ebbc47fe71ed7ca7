//! A submission that runs longer than wgpu's GL backend lets one fence wait last (`u32::MAX`
//! nanoseconds, about 4.3 s, even for `wait_indefinitely`) completes: `GpuContext::flush` keeps
//! waiting instead of failing with "The requested Wait timed out" (seen on llvmpipe with a
//! Sibenik frame of `keller-full`). A `--gpu-timeout` shorter than the work fails, naming it.
//!
//! A test binary of its own, not a module of `tests/it/`: it needs its own process, since it
//! sizes the work by timing a short run and then times the waits, which other tests' GPU work
//! beside it (on the same llvmpipe threads) would throw off.

use std::time::{Duration, Instant};

use gibench_harness::gpu::{GpuContext, GpuOptions};
use gibench_harness::kit::passes::{
    draw_fullscreen, fullscreen_pipeline, render_target, shader_module,
};
use gibench_harness::wgpu;
use gibench_test_support::{available_backends, say_uncaptured};

/// Each pixel of a fullscreen draw steps a linear congruential generator [`STEPS`] times from
/// the seed plus its index (work that cannot be folded away) and stores the result; the work is
/// sized by the target's height. A draw, not a dispatch: llvmpipe runs a compute dispatch inside
/// `submit` (so the wait after it is short) but a draw on its own threads, which the fence wait
/// then waits for. One pixel stays under 65,535 loop iterations: llvmpipe ends a shader's loops
/// after that many (found here: a loop of 2^20 steps, and two nested ones, returned the
/// generator's 65,535th value).
const SPIN: &str = "
@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(i);
}

@fragment
fn fs_main(@builtin(position) frag: vec4<f32>) -> @location(0) u32 {
    let pix = vec2<u32>(frag.xy);
    var x = SEED + pix.y * 256u + pix.x;
    for (var i = 0u; i < 50000u; i = i + 1u) {
        x = x * 1664525u + 1013904223u;
    }
    return x;
}
";

/// The target's width.
const WIDTH: u32 = 256;

/// Steps per pixel (the shader's loop bound).
const STEPS: u64 = 50_000;

/// The generator's value after `k` steps from `seed`, on the CPU: the step x -> ax + c composed
/// with itself by squaring.
fn lcg(k: u64, seed: u32) -> u32 {
    let (mut a, mut c) = (1664525u32, 1013904223u32);
    let (mut total_a, mut total_c) = (1u32, 0u32);
    let mut k = k;
    while k > 0 {
        if k & 1 == 1 {
            total_a = a.wrapping_mul(total_a);
            total_c = a.wrapping_mul(total_c).wrapping_add(c);
        }
        c = a.wrapping_mul(c).wrapping_add(c);
        a = a.wrapping_mul(a);
        k >>= 1;
    }
    total_a.wrapping_mul(seed).wrapping_add(total_c)
}

/// What `rows` rows of the draw compute from `seed`.
fn expected(rows: u32, seed: u32) -> Vec<u32> {
    (0..rows * WIDTH)
        .map(|i| lcg(STEPS, seed.wrapping_add(i)))
        .collect()
}

#[test]
fn the_jump_matches_stepping() {
    let stepped = (0..3 * STEPS).fold(9u32, |x, _| {
        x.wrapping_mul(1664525).wrapping_add(1013904223)
    });
    assert_eq!(lcg(3 * STEPS, 9), stepped);
}

/// Draws `rows` rows from `seed` in one submission, waits with `flush`, and returns how long
/// the submission and the wait took and what the GPU computed (or the wait's error).
fn spin(gpu: &GpuContext, rows: u32, seed: u32) -> (Duration, Result<Vec<u32>, String>) {
    let source = SPIN.replace("SEED", &format!("{seed}u"));
    let module = shader_module(&gpu.device, "spin", &source);
    let pipeline = fullscreen_pipeline(
        &gpu.device,
        "spin",
        &module,
        &[],
        &[wgpu::TextureFormat::R32Uint],
    );
    let target = render_target(
        &gpu.device,
        "spin",
        [WIDTH, rows],
        wgpu::TextureFormat::R32Uint,
    );
    let view = target.create_view(&Default::default());
    let size = 4 * WIDTH as u64 * rows as u64;
    let readback = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("spin readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    draw_fullscreen(&mut enc, "spin", &pipeline, &[], &[&view]);
    let start = Instant::now();
    gpu.queue.submit([enc.finish()]);
    let waited = gpu.flush();
    let took = start.elapsed();
    if let Err(e) = waited {
        return (took, Err(e.to_string()));
    }
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    enc.copy_texture_to_buffer(
        target.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &readback,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * WIDTH),
                rows_per_image: Some(rows),
            },
        },
        wgpu::Extent3d {
            width: WIDTH,
            height: rows,
            depth_or_array_layers: 1,
        },
    );
    gpu.queue.submit([enc.finish()]);
    let slice = readback.slice(..);
    slice.map_async(wgpu::MapMode::Read, |_| {});
    if let Err(e) = gpu.flush() {
        return (took, Err(e.to_string()));
    }
    let values = {
        let mapped = slice.get_mapped_range().unwrap();
        bytemuck::cast_slice::<u8, u32>(&mapped).to_vec()
    };
    readback.unmap();
    (took, Ok(values))
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

/// Rows that take about `seconds` here, from a short timed run (checked too).
fn sized(gpu: &GpuContext, seconds: f64) -> u32 {
    let r0 = 16u32;
    // Twice: the first run's time includes the shader's compilation.
    let _ = spin(gpu, r0, 7);
    let (t0, v0) = spin(gpu, r0, 7);
    assert!(v0 == Ok(expected(r0, 7)), "the short run: {:?}", v0.err());
    ((r0 as f64) * seconds / t0.as_secs_f64().max(1e-3)).clamp(1.0, MAX_ROWS as f64) as u32
}

/// The tallest target (the smallest 2D texture limit among the backends).
const MAX_ROWS: u32 = 8192;

#[test]
fn a_submission_longer_than_the_gl_wait_cap_completes() {
    let backend = backend();
    let gpu = open(backend, None);
    // About 7 s of work; if the machine sped up since the sizing run and it took under 5 s,
    // again with twice the work.
    let mut rows = sized(&gpu, 7.0);
    for _ in 0..3 {
        let (took, values) = spin(&gpu, rows, 11);
        let values =
            values.unwrap_or_else(|e| panic!("{backend}: {rows} rows, waited {took:?}: {e}"));
        assert!(
            values == expected(rows, 11),
            "{backend}: {rows} rows computed other values"
        );
        if took > Duration::from_secs(5) {
            return;
        }
        if rows == MAX_ROWS {
            break;
        }
        rows = rows.saturating_mul(2).min(MAX_ROWS);
    }
    panic!("{backend}: could not make a submission last 5 s (the test did not test the wait)");
}

#[test]
fn a_gpu_timeout_shorter_than_the_work_fails_naming_it() {
    let backend = backend();
    // About 4 s of work, sized without a limit (on a busy machine the short sizing run alone
    // can last longer than 0.5 s), against a limit of 0.5 s. Waits are renewed every second,
    // so work shorter than a second can end before the limit is ever looked at: a submission
    // that completes must have lasted under 2 s, and is then run again with four times the
    // work (the machine's load changes between the sizing and the run).
    let mut rows = sized(&open(backend, None), 4.0);
    let gpu = open(backend, Some(0.5));
    let mut error = None;
    for _ in 0..4 {
        let (took, values) = spin(&gpu, rows, 5);
        match values {
            Err(e) => {
                error = Some(e);
                break;
            }
            Ok(_) => assert!(
                took < Duration::from_secs(2),
                "{backend}: {rows} rows completed in {took:?} under a 0.5 s limit"
            ),
        }
        rows = (rows * 4).min(MAX_ROWS);
    }
    let e = error.expect("no submission lasted long enough to meet the limit");
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
