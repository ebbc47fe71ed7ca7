//! `mode=lpv`'s passes on the GPU, on every portable backend present: the injection writes
//! Kaplanyan's clamped-cosine coefficients (√π/2 and √(π/3) times Φ/π, per cell face area)
//! into the cell half a cell in front of each texel (a surface at a cell's centre: the next
//! cell), ignores texels that saw no surface, and
//! starts afresh each frame; one propagation step sends a lobe's flux through the neighbours'
//! faces in the shares of Kaplanyan's solid angles (`slab::kaplanyan_weights`).

use gibench_gaitatzes::lpv::{Injection, LpvPropagation};
use gibench_gaitatzes::slab::kaplanyan_weights;
use gibench_gaitatzes::volume::{Grid, Mode, Transport, Volumes, CELL_BYTES};
use gibench_harness::glam::Vec3;
use gibench_harness::gpu::GpuContext;
use gibench_harness::wgpu;
use gibench_harness::wgpu::util::DeviceExt;
use gibench_test_support::{gpus, read_f32};

const N: u32 = 16;
/// 12 floats per cell: r, g, b × four SH coefficients.
const CELL: usize = (CELL_BYTES / 4) as usize;

fn grid(cell: f32) -> Grid {
    Grid {
        n: N,
        origin: Vec3::ZERO,
        cell,
        mode: Mode::Lpv,
        stored_albedo: false,
        transport: Transport::Cosine,
    }
}

fn index(x: u32, y: u32, z: u32) -> usize {
    (x + N * (y + N * z)) as usize * CELL
}

fn storage(gpu: &GpuContext, data: &[[f32; 4]]) -> wgpu::Buffer {
    gpu.device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("texels"),
            contents: bytemuck::cast_slice(data),
            usage: wgpu::BufferUsages::STORAGE,
        })
}

/// Catches: the lobe's coefficients (a missing 1/π or cell area, the l = 1 term on the wrong
/// axis or with the wrong sign), the half-cell shift (the texel lands in the cell below), a
/// texel without a surface injected (or setting the fixed-point range), sums not cleared
/// between frames (the second frame doubles).
#[test]
fn injection_writes_kaplanyans_coefficients_in_front_of_each_texel() {
    // √π/2 and √(π/3): the clamped cosine's projection, as Kaplanyan's notes give it.
    const COS0: f32 = 0.886_226_9;
    const COS1: f32 = 1.023_326_7;
    let pi = std::f32::consts::PI;
    for (backend, gpu) in gpus("lpv") {
        let cell = 0.5;
        let g = grid(cell);
        let volumes = Volumes::new(&gpu, &g).unwrap();
        // Texel a: on a floor at z = 2.4 (in cell 4), normal +z: half a cell up, in cell
        // (5, 5, 5). Texel b: a thousandth of the flux at x = 2.1 (cell 4), normal −x: in
        // cell (3, 6, 7).
        // Texel c: no surface seen (w = 0), a hundred times the flux.
        let positions = [
            [2.75, 2.75, 2.4, 1.0],
            [2.1, 3.25, 3.75, 1.0],
            [4.0, 4.0, 4.0, 0.0],
        ];
        let normals = [
            [0.0, 0.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
        ];
        let fluxes = [
            [1.0, 2.0, 3.0, 0.0],
            [0.001, 0.002, 0.003, 0.0],
            [100.0, 100.0, 100.0, 0.0],
        ];
        let bufs = [
            storage(&gpu, &positions),
            storage(&gpu, &normals),
            storage(&gpu, &fluxes),
        ];
        let injection = Injection::new(&gpu, &g, [&bufs[0], &bufs[1], &bufs[2]], 3, &volumes)
            .expect("the injection builds");
        for frame in 0..2 {
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            injection.encode(&mut enc);
            gpu.queue.submit([enc.finish()]);
            let field = read_f32(&gpu, &volumes.propagation[0]);
            let accumulation = read_f32(&gpu, &volumes.accumulation);
            assert_eq!(
                field, accumulation,
                "{backend}: the accumulation starts with it"
            );
            let area = cell * cell;
            // Order [Y00, y, z, x] per channel (sh.rs).
            let expect = |at: usize, flux: [f32; 4], axis: usize, sign: f32| {
                for ch in 0..3 {
                    let mut want = [COS0 * flux[ch] / pi / area, 0.0, 0.0, 0.0];
                    want[axis] = sign * COS1 * flux[ch] / pi / area;
                    let got = &field[at + 4 * ch..][..4];
                    for k in 0..4 {
                        // The fixed-point quantum: the largest texel flux (3) × 3 texels ×
                        // the largest coefficient over 2³⁰, far below this.
                        assert!(
                            (got[k] - want[k]).abs() <= 1e-5 * want[0].abs().max(1e-3),
                            "{backend} frame {frame} channel {ch}: {got:?}, want {want:?}"
                        );
                    }
                }
            };
            expect(index(5, 5, 5), fluxes[0], 2, 1.0);
            expect(index(3, 6, 7), fluxes[1], 3, -1.0);
            let lit: usize = (field.chunks(CELL))
                .filter(|c| c.iter().any(|v| *v != 0.0))
                .count();
            assert_eq!(lit, 2, "{backend} frame {frame}: cells injected");
        }
        // A surface at a cell's centre (where the grid puts the walls on the scene's bounds)
        // goes to the next cell along its normal, not to whichever side of the boundary the
        // last bits of half a cell take it: with cells of 0.3, (0.75 + 0.15) / 0.3 is
        // 2.9999998 in f32.
        let g = grid(0.3);
        let volumes = Volumes::new(&gpu, &g).unwrap();
        let bufs = [
            storage(&gpu, &[[0.75, 0.75, 0.75, 1.0]]),
            storage(&gpu, &[[0.0, 0.0, 1.0, 0.0]]),
            storage(&gpu, &[[1.0, 1.0, 1.0, 0.0]]),
        ];
        let injection = Injection::new(&gpu, &g, [&bufs[0], &bufs[1], &bufs[2]], 1, &volumes)
            .expect("the injection builds");
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        injection.encode(&mut enc);
        gpu.queue.submit([enc.finish()]);
        let field = read_f32(&gpu, &volumes.propagation[0]);
        assert!(
            field[index(2, 2, 3)] > 0.0,
            "{backend}: a surface at a cell's centre lands in the next cell"
        );
    }
}

/// Catches: a face's solid angle or direction wrong (front and side swapped, a side face seen
/// from the wrong point), the shared face not skipped, re-emission along the wrong axis, a
/// neighbour's flux sent back into the source cell, the accumulation not added to.
#[test]
fn one_step_sends_a_lobe_through_kaplanyans_faces() {
    let w = kaplanyan_weights();
    let c = N / 2;
    for (backend, gpu) in gpus("lpv") {
        let g = grid(1.0);
        let volumes = Volumes::new(&gpu, &g).unwrap();
        let propagation = LpvPropagation::new(&gpu, &g, &volumes).unwrap();
        let mut field = vec![0f32; N.pow(3) as usize * CELL];
        let lobe = gibench_gaitatzes::sh::cosine_unit(Vec3::Z);
        for ch in 0..3 {
            field[index(c, c, c) + 4 * ch..][..4].copy_from_slice(&lobe);
        }
        gpu.queue
            .write_buffer(&volumes.propagation[0], 0, bytemuck::cast_slice(&field));
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        propagation.encode(&mut enc, 1);
        gpu.queue.submit([enc.finish()]);
        let next = read_f32(&gpu, &volumes.propagation[1]);
        assert_eq!(
            next,
            read_f32(&gpu, &volumes.accumulation),
            "{backend}: the step is accumulated"
        );
        // A cell's radiance integral: 2√π × its DC term (one channel; all three are equal).
        let integral = |x: u32, y: u32, z: u32| {
            next[index(x, y, z)] as f64 * 2.0 * std::f64::consts::PI.sqrt()
        };
        let total: f64 = (next.chunks(CELL))
            .map(|v| v[0] as f64 * 2.0 * std::f64::consts::PI.sqrt())
            .sum();
        assert!(
            (total - w.total).abs() <= 1e-4 * w.total,
            "{backend}: sent {total}, Kaplanyan's faces {}",
            w.total
        );
        let forward = integral(c, c, c + 1) / total;
        assert!(
            (forward - w.into_forward_cell).abs() <= 1e-4,
            "{backend}: forward share {forward}, want {}",
            w.into_forward_cell
        );
        assert_eq!(
            integral(c, c, c),
            0.0,
            "{backend}: nothing back into the source"
        );
        let sides =
            [(c + 1, c), (c - 1, c), (c, c + 1), (c, c - 1)].map(|(x, y)| integral(x, y, c));
        for s in sides {
            assert!(
                (s - sides[0]).abs() <= 1e-5 * total,
                "{backend}: sides {sides:?}"
            );
        }
        // The forward neighbour's lobe leans forward (its z term positive).
        assert!(
            next[index(c, c, c + 1) + 2] > 0.0,
            "{backend}: forward lobe"
        );
    }
}
