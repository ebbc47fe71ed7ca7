//! The voxel passes of `gaitatzes` on the GPU, on every portable backend present: one lit voxel
//! in an empty grid propagates symmetrically and loses no more than a stated fraction of its
//! energy per iteration (and never gains); an occupied wall blocks propagation; iterations in
//! one pass match iterations one at a time, and reflect with the albedo; voxelizing a
//! tilted triangle leaves no hole along any axis and marks no voxel the triangle's plane misses.

use gibench_gaitatzes::sh;
use gibench_gaitatzes::volume::{
    Grid, Mode, Propagation, Transport, Volumes, Voxelizer, CELL_BYTES,
};
use gibench_harness::glam::{Vec2, Vec3};
use gibench_harness::gpu::{GpuContext, GpuOptions};
use gibench_harness::run::runner::Harness;
use gibench_harness::scene::{Material, Mesh};
use gibench_test_support::{gpus, read_f32, run_config, scene_from_json};

const N: u32 = 16;

fn grid(mode: Mode) -> Grid {
    Grid {
        n: N,
        origin: Vec3::ZERO,
        cell: 1.0,
        mode,
        stored_albedo: false,
        transport: Transport::Cosine,
    }
}

fn index(x: u32, y: u32, z: u32) -> usize {
    (x + N * (y + N * z)) as usize
}

/// 12 floats per cell: three SH vectors (r, g, b), or normal / albedo / radiosity.
const CELL: usize = (CELL_BYTES / 4) as usize;

/// The radiance integral ∫ L dω of each channel summed over the cells (√(4π) × the DC terms).
fn energy(field: &[f32]) -> f64 {
    let k = (4.0 * std::f64::consts::PI).sqrt();
    field
        .chunks(CELL)
        .map(|c| (c[0] + c[4] + c[8]) as f64 * k)
        .sum()
}

/// A propagation setup: `voxels` (12 floats per cell) and one source cell with SH `lobe` in
/// every channel; returns the propagation field after each of `iterations` iterations and the
/// final accumulation.
fn propagate(
    gpu: &GpuContext,
    mode: Mode,
    voxels: &[f32],
    source: (u32, u32, u32),
    lobe: [f32; 4],
    iterations: u32,
) -> (Vec<Vec<f32>>, Vec<f32>) {
    propagate_in(gpu, &grid(mode), voxels, source, lobe, iterations, false)
}

/// [`propagate`] in grid `g`; with `one_pass`, the iterations are encoded at once (one compute
/// pass, as a frame does) and only the last field is returned.
fn propagate_in(
    gpu: &GpuContext,
    g: &Grid,
    voxels: &[f32],
    source: (u32, u32, u32),
    lobe: [f32; 4],
    iterations: u32,
    one_pass: bool,
) -> (Vec<Vec<f32>>, Vec<f32>) {
    let g = *g;
    let volumes = Volumes::new(gpu, &g).unwrap();
    let propagation = Propagation::new(gpu, &g, &volumes).unwrap();
    let mut field = vec![0f32; N.pow(3) as usize * CELL];
    let i = index(source.0, source.1, source.2) * CELL;
    for channel in 0..3 {
        field[i + 4 * channel..i + 4 * channel + 4].copy_from_slice(&lobe);
    }
    gpu.queue
        .write_buffer(&volumes.voxels, 0, bytemuck::cast_slice(voxels));
    gpu.queue.write_buffer(
        &volumes.accumulation,
        0,
        bytemuck::cast_slice(&vec![0f32; field.len()]),
    );
    let mut fields = Vec::new();
    if one_pass {
        gpu.queue
            .write_buffer(&volumes.propagation[0], 0, bytemuck::cast_slice(&field));
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        propagation.encode(&mut enc, iterations);
        gpu.queue.submit([enc.finish()]);
        fields.push(read_f32(gpu, &volumes.propagation[iterations as usize % 2]));
        return (fields, read_f32(gpu, &volumes.accumulation));
    }
    for k in 0..iterations {
        gpu.queue
            .write_buffer(&volumes.propagation[0], 0, bytemuck::cast_slice(&field));
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        propagation.encode(&mut enc, 1);
        gpu.queue.submit([enc.finish()]);
        field = read_f32(gpu, &volumes.propagation[1]);
        fields.push(field.clone());
        let _ = k;
    }
    (fields, read_f32(gpu, &volumes.accumulation))
}

/// An isotropic lit voxel in the middle of an empty grid: after every iteration the field is
/// symmetric under the grid's mirror symmetries about the source and the swaps of the axes
/// (to 1e-5 relative), and until the light reaches the grid's edge no iteration loses or gains
/// more than 10⁻⁴ of the energy (the faces' pyramids tile the sphere and each cell passes on
/// exactly its radiance integral). A clamped-cosine lobe keeps its energy too, and sends
/// 40 % of it forward and 15 % through each side face.
#[test]
fn one_lit_voxel_propagates_symmetrically_and_loses_no_energy() {
    let c = N / 2;
    for (backend, gpu) in gpus("volume") {
        let empty = vec![0f32; N.pow(3) as usize * CELL];
        let iso = [1.0, 0.0, 0.0, 0.0];
        let (fields, _) = propagate(&gpu, Mode::Occluded, &empty, (c, c, c), iso, 6);
        let mut before = energy(&{
            let mut f = vec![0f32; empty.len()];
            f[index(c, c, c) * CELL] = 1.0;
            f[index(c, c, c) * CELL + 4] = 1.0;
            f[index(c, c, c) * CELL + 8] = 1.0;
            f
        });
        for (k, f) in fields.iter().enumerate() {
            let scale = f.iter().fold(0f32, |m, v| m.max(v.abs()));
            for z in 1..N {
                for y in 1..N {
                    for x in 1..N {
                        let a = &f[index(x, y, z) * CELL..][..CELL];
                        // DC terms under every mirror and axis swap; l = 1 terms flip sign
                        // with their mirror.
                        for (x2, y2, z2) in [
                            (2 * c - x, y, z),
                            (x, 2 * c - y, z),
                            (x, y, 2 * c - z),
                            (y, x, z),
                            (z, y, x),
                        ] {
                            if x2 == 0 || y2 == 0 || z2 == 0 {
                                continue;
                            }
                            let b = &f[index(x2, y2, z2) * CELL..][..CELL];
                            assert!(
                                (a[0] - b[0]).abs() <= 1e-5 * scale,
                                "{backend} iteration {k}: ({x},{y},{z}) {} vs ({x2},{y2},{z2}) {}",
                                a[0],
                                b[0]
                            );
                        }
                        let m = &f[index(2 * c - x, y, z) * CELL..][..CELL];
                        assert!((a[3] + m[3]).abs() <= 1e-5 * scale, "{backend}: x mirror");
                    }
                }
            }
            let e = energy(f);
            let ratio = e / before;
            assert!(
                (ratio - 1.0).abs() <= 1e-4,
                "{backend} iteration {k}: energy ratio {ratio}"
            );
            before = e;
        }
        let lobe = sh::clamped_cosine(Vec3::X).map(|v| v / std::f32::consts::PI);
        let (fields, _) = propagate(&gpu, Mode::Occluded, &empty, (c, c, c), lobe, 1);
        let k = (4.0 * std::f64::consts::PI).sqrt();
        let unit = 3.0 * k * lobe[0] as f64;
        let ratio = energy(&fields[0]) / unit;
        assert!(
            (ratio - 1.0).abs() <= 1e-4,
            "{backend}: a cosine lobe keeps {ratio} of its energy"
        );
        let at = |x: u32, y: u32| {
            let i = index(x, y, c) * CELL;
            fields[0][i] as f64 * 3.0 * k / unit
        };
        assert!(
            (at(c + 1, c) - 0.40).abs() < 0.01,
            "{backend}: forward {}",
            at(c + 1, c)
        );
        assert!(
            (at(c, c + 1) - 0.15).abs() < 0.01,
            "{backend}: side {}",
            at(c, c + 1)
        );
        assert!(
            at(c - 1, c).abs() < 1e-6,
            "{backend}: backward {}",
            at(c - 1, c)
        );
    }
}

/// Voxels with a wall of occupied cells across the grid at x = `wall` (normal −x, towards the
/// source), if any.
fn wall_voxels(wall: Option<u32>) -> Vec<f32> {
    let mut v = vec![0f32; N.pow(3) as usize * CELL];
    if let Some(x) = wall {
        for z in 0..N {
            for y in 0..N {
                let i = index(x, y, z) * CELL;
                v[i..i + 4].copy_from_slice(&[-1.0, 0.0, 0.0, 1.0]);
                v[i + 4..i + 8].copy_from_slice(&[0.5, 0.5, 0.5, 0.0]);
            }
        }
    }
    v
}

/// An isotropic source at x = 5 and an occupied wall at x = 10: no radiance ever reaches the
/// cells behind the wall (at most 1e-6 of what reaches them without the wall, which is more
/// than 5 % of the source), and the wall accumulates the light that arrives.
#[test]
fn an_occluding_wall_blocks_propagation() {
    let behind = |f: &[f32]| -> f64 {
        let k = (4.0 * std::f64::consts::PI).sqrt();
        let mut e = 0.0;
        for z in 0..N {
            for y in 0..N {
                for x in 11..N {
                    let i = index(x, y, z) * CELL;
                    e += (f[i] + f[i + 4] + f[i + 8]).abs() as f64 * k;
                }
            }
        }
        e
    };
    for (backend, gpu) in gpus("volume") {
        let iso = [1.0, 0.0, 0.0, 0.0];
        let source = 3.0 * (4.0 * std::f64::consts::PI).sqrt();
        let run = |wall| propagate(&gpu, Mode::Occluded, &wall_voxels(wall), (5, 8, 8), iso, 12);
        let (open, _) = run(None);
        let (walled, accumulated) = run(Some(10));
        let through: f64 = open.iter().map(|f| behind(f)).sum();
        let leaked: f64 = walled.iter().map(|f| behind(f)).sum();
        assert!(
            through > 0.05 * source,
            "{backend}: without the wall {through}"
        );
        assert!(
            leaked <= 1e-6 * through,
            "{backend}: {leaked} behind the wall (without it: {through})"
        );
        let on_wall: f32 = (0..N * N)
            .map(|i| accumulated[index(10, i % N, i / N) * CELL])
            .sum();
        assert!(on_wall > 0.0, "{backend}: nothing accumulated on the wall");
    }
}

/// A wall (as in [`an_occluding_wall_blocks_propagation`]) of albedo (0.2, 0.5, 0.8), with the
/// voxels' albedo for the bounces (`albedo=stored`): 8 iterations encoded in one compute pass
/// give exactly (bit for bit: the same shaders on the same data) the field and accumulation of
/// 8 iterations encoded one at a time. Catches an iteration that gathers what the cells sent in
/// an earlier iteration (the per-face fluxes not recomputed from each iteration's field, or
/// computed from the other ping-pong buffer). And the light the wall reflects in the first
/// iteration that reaches it (the same in every channel before) is scaled by each channel's
/// albedo (to 10⁻⁵): catches the albedo read from the wrong place or channel.
#[test]
fn iterations_in_one_pass_match_one_at_a_time_and_reflect_with_the_albedo() {
    let rho = [0.2f32, 0.5, 0.8];
    let mut voxels = wall_voxels(Some(10));
    for c in voxels.chunks_mut(CELL).filter(|c| c[3] > 0.0) {
        c[4..7].copy_from_slice(&rho);
    }
    let g = Grid {
        stored_albedo: true,
        ..grid(Mode::Occluded)
    };
    let iso = [1.0, 0.0, 0.0, 0.0];
    for (backend, gpu) in gpus("volume") {
        let (steps, accumulated) = propagate_in(&gpu, &g, &voxels, (5, 8, 8), iso, 8, false);
        let (once, accumulated_once) = propagate_in(&gpu, &g, &voxels, (5, 8, 8), iso, 8, true);
        assert!(
            steps[7] == once[0] && accumulated == accumulated_once,
            "{backend}: 8 iterations in one pass differ from 8 one at a time"
        );
        // The source is 5 cells from the wall: the light reaches it in the 5th iteration.
        let wall = &steps[4][index(10, 8, 8) * CELL..][..CELL];
        assert!(wall[0] > 0.0, "{backend}: nothing reflected at the wall");
        for c in 1..3 {
            let ratio = wall[4 * c] / wall[0];
            let expected = rho[c] / rho[0];
            assert!(
                (ratio - expected).abs() <= 1e-5 * expected,
                "{backend}: channel {c} reflected {ratio} × red, expected {expected}"
            );
        }
    }
}

/// Voxelizing one tilted triangle into a 32³ grid (the paper's default): along every axis, every
/// grid line through cell centres that crosses the triangle (away from its edges) finds the
/// crossed cell occupied; and every occupied cell touches the triangle's plane.
#[test]
fn voxelizing_a_tilted_triangle_leaves_no_hole_along_any_axis() {
    // The same triangle with its coordinates permuted cyclically: its normal's largest
    // component along x, y and z in turn (a single slicing axis leaves holes in two of them).
    let tri = [
        Vec3::new(0.3, 0.2, 0.9),
        Vec3::new(9.7, 3.1, 0.4),
        Vec3::new(2.6, 9.8, 8.7),
    ];
    for shift in 0..3 {
        let p = |v: Vec3| match shift {
            0 => v,
            1 => Vec3::new(v.z, v.x, v.y),
            _ => Vec3::new(v.y, v.z, v.x),
        };
        voxelize_triangle(p(tri[0]), p(tri[1]), p(tri[2]));
    }
}

fn voxelize_triangle(a: Vec3, b: Vec3, c: Vec3) {
    let n = (b - a).cross(c - a).normalize();
    let mut mesh = Mesh::default();
    for p in [a, b, c] {
        mesh.positions.push(p);
        mesh.normals.push(n);
        mesh.uvs.push(Vec2::ZERO);
        mesh.materials.push(0);
    }
    mesh.indices.extend([0, 1, 2]);
    let json = r#"{
        "name": "triangle",
        "mesh": { "generated": "cornell-box" },
        "camera": { "fov_y_deg": 60, "near": 0.1,
                    "path": { "keys": [ { "time": 0, "position": [5, 5, -20], "target": [5, 5, 5] } ] } },
        "light": { "kind": "omni", "power": [1, 1, 1],
                   "path": { "keys": [ { "time": 0, "position": [5, 5, 5] } ] } },
        "settings": { "filter_distance": 1 }
    }"#;
    let scene = scene_from_json(json, mesh, vec![Material::plain("grey", Vec3::splat(0.5))]);
    for (backend, gpu) in gpus("volume") {
        let config = run_config([32, 24], 64);
        let harness = Harness::new(&gpu, &scene, &config).unwrap();
        harness.uniforms.write(&gpu.queue, &harness.clock.frame(0));
        let g = Grid::around(&scene.extent, 32, Mode::Occluded, false, Transport::Cosine);
        let volumes = Volumes::new(&gpu, &g).unwrap();
        let voxelizer = Voxelizer::new(
            &gpu,
            &g,
            &harness.gpu_scene,
            &harness.uniforms,
            &harness.direct,
            &volumes,
        )
        .unwrap();
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        voxelizer.encode(
            &mut enc,
            &harness.gpu_scene,
            &harness.uniforms,
            &harness.direct,
        );
        gpu.queue.submit([enc.finish()]);
        let voxels = read_f32(&gpu, &volumes.voxels);
        let cells = g.n as i32;
        let occupied = |c: [i32; 3]| -> bool {
            c.iter().all(|v| (0..cells).contains(v))
                && voxels[((c[0] + cells * (c[1] + cells * c[2])) as usize) * CELL + 3] > 0.0
        };
        let centre = |c: [i32; 3]| {
            g.origin + (Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32) + 0.5) * g.cell
        };
        let (mut lines, mut total) = (0, 0);
        for axis in 0..3 {
            let (iu, iv) = [(1, 2), (2, 0), (0, 1)][axis];
            for u in 0..cells {
                for v in 0..cells {
                    let mut cell = [0; 3];
                    cell[iu] = u;
                    cell[iv] = v;
                    let o = centre(cell);
                    let d = Vec3::AXES[axis];
                    if n.dot(d).abs() < 1e-3 {
                        continue;
                    }
                    let t = (a - o).dot(n) / n.dot(d);
                    let q = o + d * t;
                    // Barycentric coordinates of q; skip lines within 2 % of an edge.
                    let (v0, v1, v2) = (b - a, c - a, q - a);
                    let (d00, d01, d11) = (v0.dot(v0), v0.dot(v1), v1.dot(v1));
                    let (d20, d21) = (v2.dot(v0), v2.dot(v1));
                    let den = d00 * d11 - d01 * d01;
                    let (s, r) = ((d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den);
                    if s < 0.02 || r < 0.02 || s + r > 0.98 {
                        continue;
                    }
                    total += 1;
                    let mut hit = cell;
                    let w = (q[axis] - g.origin[axis]) / g.cell;
                    hit[axis] = w.floor() as i32;
                    // On a slice boundary (within 10⁻³ cell) either side may take it.
                    let mut below = hit;
                    below[axis] -= 1;
                    let boundary = w - w.floor() < 1e-3;
                    if occupied(hit) || (boundary && occupied(below)) {
                        lines += 1;
                    } else {
                        panic!("{backend}: axis {axis} line ({u}, {v}) crosses the triangle in cell {hit:?} (at {w}), which is empty");
                    }
                }
            }
        }
        assert!(
            total > 500 && lines == total,
            "{backend}: {lines} of {total}"
        );
        // No occupied cell off the plane: the cell's box must touch it.
        let reach = 0.5 * g.cell * (n.x.abs() + n.y.abs() + n.z.abs()) + 1e-3 * g.cell;
        for z in 0..cells {
            for y in 0..cells {
                for x in 0..cells {
                    if occupied([x, y, z]) {
                        let dist = (centre([x, y, z]) - a).dot(n).abs();
                        assert!(
                            dist <= reach,
                            "{backend}: cell ({x},{y},{z}) is {dist} off the plane"
                        );
                    }
                }
            }
        }
    }
}

/// On an adapter with the downlevel four storage buffers per shader stage, `transport=carry`
/// and `pyramid` (a fifth: the senders' SH) are refused by name before any pipeline is made,
/// and `transport=cosine` still builds. Caught by: the check dropped (pipeline creation then
/// fails inside wgpu, an uncaptured validation error instead of the parameter's name) or
/// counting the cosine transport's buffers as five.
#[test]
fn transports_needing_a_fifth_storage_buffer_are_refused_with_four() {
    for (backend, full) in gpus("transports_needing_a_fifth_storage_buffer_are_refused_with_four") {
        let limits = gibench_harness::wgpu::Limits {
            max_storage_buffers_per_shader_stage: 4,
            ..full.device.limits()
        };
        let gpu = GpuContext::new(&GpuOptions {
            backend: Some(backend.into()),
            limits: Some(limits),
            ..Default::default()
        })
        .unwrap_or_else(|e| panic!("{backend}: a device with 4 storage buffers: {e}"));
        for transport in [Transport::Carry, Transport::Pyramid, Transport::Cosine] {
            let g = Grid {
                transport,
                ..grid(Mode::Occluded)
            };
            let volumes = Volumes::new(&gpu, &g).unwrap();
            let made = Propagation::new(&gpu, &g, &volumes);
            if transport == Transport::Cosine {
                assert!(made.is_ok(), "{backend}: cosine with 4 buffers");
                continue;
            }
            let err = made.err().unwrap().to_string();
            assert!(
                err.contains("transport")
                    && err.contains(
                        "needs 5 storage buffers per shader stage; this adapter allows 4"
                    ),
                "{backend} {}: {err}",
                transport.name()
            );
        }
        gpu.check_errors()
            .unwrap_or_else(|e| panic!("{backend}: no validation error: {e}"));
    }
}
