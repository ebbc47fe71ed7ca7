//! The device's bounds for the roofline ([`crate::measure::roofline`]): a copy kernel and an FMA kernel
//! of gibench's own, timed once per process before the frames of its first stage-timed run ([`measure_bounds`]).

use std::time::Instant;

use bytemuck::{Pod, Zeroable};

use crate::gpu::GpuContext;
use crate::kit::passes::{
    bind_buffer, compute_pipeline, params_buffer, params_entry, storage_entry,
};
use crate::measure::roofline::{BoundTimer, DeviceBounds};
use crate::{Error, Result};

/// Timed runs of each bound kernel after its untimed one; the fastest is the bound.
pub const REPEATS: usize = 3;

/// The copy's buffer on an adapter that is a CPU (lavapipe, llvmpipe): its host memory is the
/// process's, so it is kept small (two buffers of this size are resident while measuring).
const CPU_COPY_BYTES: u64 = 32 << 20;
/// The copy's buffer on a GPU: larger than any GPU's last-level cache today.
const GPU_COPY_BYTES: u64 = 256 << 20;

/// Invocations per workgroup of both kernels.
const WORKGROUP: u32 = 64;
/// Independent FMA chains per invocation, each on a `vec4<f32>`.
pub const FMA_CHAINS: u32 = 8;
/// Operations of one chain step on one invocation: `FMA_CHAINS` chains × 4 lanes × 2.
const OPS_PER_STEP: u64 = FMA_CHAINS as u64 * 4 * 2;
/// Most FMA workgroups per dispatch; beyond, the chains get longer.
const FMA_MAX_WORKGROUPS: u32 = 4096;
/// Longest chain: the chain values stay integers below 2^24 (exact in `f32`).
const FMA_MAX_ITERATIONS: u32 = 1 << 16;
/// The FMA kernel is grown until one run takes this long (so that the timer's resolution and a
/// submission's overhead are small beside it).
const FMA_TARGET_MS: f64 = 8.0;
/// Workgroups of the copy kernel at most (each invocation then copies several elements).
const COPY_MAX_WORKGROUPS: u32 = 8192;

/// The copy and FMA kernels, their buffers and a timer (see the module docs).
pub struct BoundKernels {
    copy_pipeline: wgpu::ComputePipeline,
    fill_pipeline: wgpu::ComputePipeline,
    /// Binds the source and the target (and keeps them alive).
    copy_group: wgpu::BindGroup,
    dst: wgpu::Buffer,
    fma_pipeline: wgpu::ComputePipeline,
    fma_layout: wgpu::BindGroupLayout,
    fma_out: wgpu::Buffer,
    timestamps: Option<(wgpu::QuerySet, wgpu::Buffer, wgpu::Buffer, f64)>,
}

/// The chain's parameters: `x ← fma(x, a, b)`, `iterations` times.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FmaParams {
    pub a: f32,
    pub b: f32,
    pub iterations: u32,
    pub pad: u32,
}

/// The copy and its source's fill.
const COPY_WGSL: &str = r#"
@group(0) @binding(0) var<storage, read_write> src: array<vec4<u32>>;
@group(0) @binding(1) var<storage, read_write> dst: array<vec4<u32>>;

// The source's pattern: element i holds (i, i * 2654435761, ~i, i ^ 0xa5a5a5a5).
@compute @workgroup_size(64)
fn fill(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    let stride = n.x * 64u;
    for (var i = id.x; i < arrayLength(&src); i += stride) {
        src[i] = vec4<u32>(i, i * 2654435761u, ~i, i ^ 0xa5a5a5a5u);
    }
}

// Each element read once and written once (a grid-stride loop).
@compute @workgroup_size(64)
fn copy(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    let stride = n.x * 64u;
    for (var i = id.x; i < arrayLength(&dst); i += stride) {
        dst[i] = src[i];
    }
}
"#;

/// The FMA chains.
const FMA_WGSL: &str = r#"
struct FmaParams { a: f32, b: f32, iterations: u32, pad: u32 }
@group(0) @binding(0) var<storage, read> fma_params: FmaParams;
@group(0) @binding(1) var<storage, read_write> fma_out: array<vec4<f32>>;

// Eight independent chains of x <- fma(x, a, b) on vec4s, started from the invocation's index
// (mod 256); their sum is written.
@compute @workgroup_size(64)
fn fma_chain(@builtin(global_invocation_id) id: vec3<u32>) {
    let a = vec4<f32>(fma_params.a);
    let b = vec4<f32>(fma_params.b);
    let s = f32(id.x & 255u);
    var x0 = vec4<f32>(s, s + 1.0, s + 2.0, s + 3.0);
    var x1 = x0 + 4.0;
    var x2 = x0 + 8.0;
    var x3 = x0 + 12.0;
    var x4 = x0 + 16.0;
    var x5 = x0 + 20.0;
    var x6 = x0 + 24.0;
    var x7 = x0 + 28.0;
    for (var i = 0u; i < fma_params.iterations; i++) {
        x0 = fma(x0, a, b);
        x1 = fma(x1, a, b);
        x2 = fma(x2, a, b);
        x3 = fma(x3, a, b);
        x4 = fma(x4, a, b);
        x5 = fma(x5, a, b);
        x6 = fma(x6, a, b);
        x7 = fma(x7, a, b);
    }
    fma_out[id.x] = ((x0 + x1) + (x2 + x3)) + ((x4 + x5) + (x6 + x7));
}
"#;

/// The FMA kernel's output for invocation `index` after `iterations` steps of
/// `x ← fma(x, a, b)`: the same chains on the CPU (`f32::mul_add`), summed in the kernel's
/// order.
pub fn fma_model(index: u32, params: &FmaParams) -> [f32; 4] {
    let s = (index & 255) as f32;
    let mut out = [0.0f32; 4];
    for (lane, o) in out.iter_mut().enumerate() {
        let mut x: Vec<f32> = (0..FMA_CHAINS)
            .map(|c| (s + lane as f32) + (4 * c) as f32)
            .collect();
        for _ in 0..params.iterations {
            for v in x.iter_mut() {
                *v = v.mul_add(params.a, params.b);
            }
        }
        *o = ((x[0] + x[1]) + (x[2] + x[3])) + ((x[4] + x[5]) + (x[6] + x[7]));
    }
    out
}

/// The copy source's element `i` (what the fill kernel writes).
pub fn copy_pattern(i: u32) -> [u32; 4] {
    [i, i.wrapping_mul(2654435761), !i, i ^ 0xa5a5_a5a5]
}

/// One timed run of a bound kernel.
#[derive(Clone, Copy, Debug)]
pub struct Timed {
    /// The kernel's time by the [`BoundTimer`] the kernels use.
    pub ms: f64,
    /// Wall time of the flushed submission, milliseconds (≥ `ms` with timestamps).
    pub wall_ms: f64,
}

impl BoundKernels {
    /// The kernels with a copy of `copy_bytes` (a multiple of 16, at most the device's storage
    /// buffer limit) and room for the largest FMA dispatch.
    pub fn new(gpu: &GpuContext, copy_bytes: u64) -> Result<BoundKernels> {
        if copy_bytes == 0
            || !copy_bytes.is_multiple_of(16)
            || copy_bytes > gpu.max_storage_buffer()
        {
            return Err(Error::Invalid(format!(
                "bound kernels: a copy of {copy_bytes} bytes (expected a multiple of 16 above 0, \
                 at most the device's {} bytes)",
                gpu.max_storage_buffer()
            )));
        }
        let device = &gpu.device;
        let storage = |label: &str, size: u64, extra: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE | extra,
                mapped_at_creation: false,
            })
        };
        let src = storage("bound copy source", copy_bytes, wgpu::BufferUsages::empty());
        let dst = storage(
            "bound copy target",
            copy_bytes,
            wgpu::BufferUsages::COPY_SRC,
        );
        let fma_out = storage(
            "bound fma output",
            FMA_MAX_WORKGROUPS as u64 * WORKGROUP as u64 * 16,
            wgpu::BufferUsages::COPY_SRC,
        );
        let copy_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bound copy"),
            entries: &[storage_entry(0, false), storage_entry(1, false)],
        });
        let copy_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("bound copy"),
            layout: &copy_layout,
            entries: &[bind_buffer(0, &src), bind_buffer(1, &dst)],
        });
        let fma_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bound fma"),
            entries: &[
                params_entry(0, wgpu::ShaderStages::COMPUTE),
                storage_entry(1, false),
            ],
        });
        let pipeline = |source: &str, layout: &wgpu::BindGroupLayout, entry: &str| {
            compute_pipeline(device, "bound kernels", source, &[layout], entry)
        };
        let timestamps = gpu.timestamps.then(|| {
            let set = device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("bound timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            });
            let resolve = storage(
                "bound resolve",
                16,
                wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            );
            let readback = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("bound readback"),
                size: 16,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            (
                set,
                resolve,
                readback,
                gpu.queue.get_timestamp_period() as f64,
            )
        });
        let kernels = BoundKernels {
            copy_pipeline: pipeline(COPY_WGSL, &copy_layout, "copy"),
            fill_pipeline: pipeline(COPY_WGSL, &copy_layout, "fill"),
            copy_group,
            dst,
            fma_pipeline: pipeline(FMA_WGSL, &fma_layout, "fma_chain"),
            fma_layout,
            fma_out,
            timestamps,
        };
        // The source's pattern, written once (untimed).
        let mut enc = device.create_command_encoder(&Default::default());
        kernels.dispatch(
            &mut enc,
            &kernels.fill_pipeline,
            &kernels.copy_group,
            kernels.copy_workgroups(),
            None,
        );
        gpu.queue.submit([enc.finish()]);
        gpu.flush()?;
        Ok(kernels)
    }

    /// The timer these kernels use.
    pub fn timer(&self) -> BoundTimer {
        match self.timestamps {
            Some(_) => BoundTimer::Timestamps,
            None => BoundTimer::Wall,
        }
    }

    /// Bytes one copy reads plus writes.
    pub fn copy_bytes(&self) -> f64 {
        2.0 * self.dst.size() as f64
    }

    fn copy_workgroups(&self) -> u32 {
        (self.dst.size() / 16)
            .div_ceil(WORKGROUP as u64)
            .min(COPY_MAX_WORKGROUPS as u64) as u32
    }

    fn dispatch(
        &self,
        enc: &mut wgpu::CommandEncoder,
        pipeline: &wgpu::ComputePipeline,
        group: &wgpu::BindGroup,
        workgroups: u32,
        timestamps: Option<&wgpu::QuerySet>,
    ) {
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("bound kernel"),
            timestamp_writes: timestamps.map(|set| wgpu::ComputePassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: Some(0),
                end_of_pass_write_index: Some(1),
            }),
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.dispatch_workgroups(workgroups, 1, 1);
    }

    /// Submits one kernel alone, the queue flushed before and after, and times it.
    fn timed(
        &self,
        gpu: &GpuContext,
        pipeline: &wgpu::ComputePipeline,
        group: &wgpu::BindGroup,
        workgroups: u32,
    ) -> Result<Timed> {
        gpu.flush()?;
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        let t0 = Instant::now();
        self.dispatch(
            &mut enc,
            pipeline,
            group,
            workgroups,
            self.timestamps.as_ref().map(|t| &t.0),
        );
        gpu.queue.submit([enc.finish()]);
        gpu.flush()?;
        let wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        let Some((set, resolve, readback, period_ns)) = &self.timestamps else {
            return Ok(Timed {
                ms: wall_ms,
                wall_ms,
            });
        };
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.resolve_query_set(set, 0..2, resolve, 0);
        enc.copy_buffer_to_buffer(resolve, 0, readback, 0, 16);
        gpu.queue.submit([enc.finish()]);
        let slice = readback.slice(..);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        gpu.flush()?;
        let ticks: Vec<u64> =
            bytemuck::pod_collect_to_vec(&gpu.mapped(&slice, "a readback buffer")?[..]);
        readback.unmap();
        let ms = ticks[1].saturating_sub(ticks[0]) as f64 * period_ns * 1e-6;
        Ok(Timed { ms, wall_ms })
    }

    /// One timed copy of the whole source into the target.
    pub fn copy(&self, gpu: &GpuContext) -> Result<Timed> {
        self.timed(
            gpu,
            &self.copy_pipeline,
            &self.copy_group,
            self.copy_workgroups(),
        )
    }

    /// The copy's target, read back (tests).
    pub fn read_copy(&self, gpu: &GpuContext) -> Result<Vec<[u32; 4]>> {
        Ok(bytemuck::pod_collect_to_vec(
            &crate::gpu::image_io::read_buffer(gpu, &self.dst)?,
        ))
    }

    /// Operations of one FMA run of `workgroups` workgroups and `params`.
    pub fn fma_ops(workgroups: u32, params: &FmaParams) -> f64 {
        (workgroups as u64 * WORKGROUP as u64 * params.iterations as u64 * OPS_PER_STEP) as f64
    }

    /// One timed FMA run (`workgroups` at most [`FMA_MAX_WORKGROUPS`]).
    pub fn fma(&self, gpu: &GpuContext, workgroups: u32, params: &FmaParams) -> Result<Timed> {
        if workgroups == 0 || workgroups > FMA_MAX_WORKGROUPS {
            return Err(Error::Invalid(format!(
                "bound kernels: {workgroups} FMA workgroups (expected 1 to {FMA_MAX_WORKGROUPS})"
            )));
        }
        let params_buf = params_buffer(gpu, "bound fma params", params);
        let group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("bound fma"),
            layout: &self.fma_layout,
            entries: &[bind_buffer(0, &params_buf), bind_buffer(1, &self.fma_out)],
        });
        self.timed(gpu, &self.fma_pipeline, &group, workgroups)
    }

    /// The FMA kernel's output of its first `invocations` invocations, read back (tests).
    pub fn read_fma(&self, gpu: &GpuContext, invocations: usize) -> Result<Vec<[f32; 4]>> {
        let all: Vec<[f32; 4]> =
            bytemuck::pod_collect_to_vec(&crate::gpu::image_io::read_buffer(gpu, &self.fma_out)?);
        Ok(all[..invocations].to_vec())
    }
}

/// Invocations per FMA workgroup (tests size their reads by it).
pub const FMA_WORKGROUP: u32 = WORKGROUP;

/// Measures the device's bounds (see the module docs): a copy of 32 MiB (CPU adapters) or
/// 256 MiB (GPUs), at most the device's storage-buffer limit; FMA chains grown until one run
/// takes [`FMA_TARGET_MS`]. Never inside measured frames: the runner calls it once before a
/// run's frames.
pub fn measure_bounds(gpu: &GpuContext) -> Result<DeviceBounds> {
    let start = Instant::now();
    let wanted = if gpu.info.device_type == format!("{:?}", wgpu::DeviceType::Cpu) {
        CPU_COPY_BYTES
    } else {
        GPU_COPY_BYTES
    };
    let copy_bytes = wanted.min(gpu.max_storage_buffer() / 16 * 16);
    let kernels = BoundKernels::new(gpu, copy_bytes)?;
    kernels.copy(gpu)?;
    let mut copy_ms = f64::INFINITY;
    for _ in 0..REPEATS {
        copy_ms = copy_ms.min(kernels.copy(gpu)?.ms);
    }

    let mut params = FmaParams {
        a: 1.0,
        b: 1.0,
        iterations: 1024,
        pad: 0,
    };
    let mut workgroups = 8;
    kernels.fma(gpu, workgroups, &params)?;
    // The first run compiles and warms up; then grown (more workgroups, then longer chains) until a run is long enough to time.
    loop {
        let t = kernels.fma(gpu, workgroups, &params)?;
        // The wall time stops the growth too: a timer that reads too little (a timestamp pair
        // read as equal) must not grow the kernel to minutes; the check below then refuses it.
        if t.ms >= FMA_TARGET_MS || t.wall_ms >= 4.0 * FMA_TARGET_MS {
            break;
        }
        if workgroups < FMA_MAX_WORKGROUPS {
            workgroups = (workgroups * 2).min(FMA_MAX_WORKGROUPS);
        } else if params.iterations < FMA_MAX_ITERATIONS {
            params.iterations *= 2;
        } else {
            break;
        }
    }
    let mut fma_ms = f64::INFINITY;
    for _ in 0..REPEATS {
        fma_ms = fma_ms.min(kernels.fma(gpu, workgroups, &params)?.ms);
    }
    let bounds = DeviceBounds {
        copy_bytes: kernels.copy_bytes(),
        copy_ms,
        fma_ops: BoundKernels::fma_ops(workgroups, &params),
        fma_ms,
        timer: kernels.timer(),
        measure_ms: start.elapsed().as_secs_f64() * 1e3,
    };
    if !(bounds.copy_ms > 0.0 && bounds.fma_ms > 0.0) {
        return Err(Error::Gpu(format!(
            "measuring the device's bounds: a kernel timed at zero ({} ms copy, {} ms FMA by {:?})",
            bounds.copy_ms, bounds.fma_ms, bounds.timer
        )));
    }
    Ok(bounds)
}
