//! Two parallel walls of voxels: the analytic scene that measures what the propagation carries
//! from one surface to another, on the GPU ([`measure`]) and in a model ([`model`]).
//!
//! The emitting wall is a layer of occupied cells at z = [`EMITTER_Z`] with normal +z and
//! radiosity B (injected, as the combine pass does, as B times the unit-integral clamped-cosine
//! lobe about +z); the receiving wall the layer `apart` cells above it, normal −z. Both fill the
//! grid's whole x–y extent; each reflects what reaches it with its own albedo (the voxel's, as
//! with `albedo=stored`). The irradiance of each wall is read at the grid's central column from
//! the accumulation by [`sh::irradiance`], the reconstruction's formula.
//!
//! **The model.** Between two infinite walls every cell of a layer holds the same radiance, and
//! by the mirror symmetries in x and y its l = 1 terms along x and y vanish: a layer is two
//! numbers, its DC and z coefficients. One iteration of the propagation's rules (each open
//! face's share of the cell's radiance integral by its pyramid's SH integral, negative ones
//! dropped; void cells open on all six faces, occupied ones only towards the void on their
//! normal's side) on that state: the flux through the +z and −z faces moves to the next layer;
//! the flux through the four side faces arrives in the four side neighbours, which by the
//! symmetry is the same as staying in the layer (as four cosine lobes along ±x and ±y, whose
//! l = 1 terms cancel, for [`Transport::Cosine`]; as the cell's own lobe for
//! [`Transport::Carry`]; as four lobes of the side pyramids' first moments, whose x and y parts
//! cancel, for [`Transport::Pyramid`]). Occupied cells accumulate the flux arriving head-on and send their
//! albedo times its mirror image on. With the exact flux-to-irradiance constant a wall's
//! irradiance is the flux per unit area that has arrived at it. The model owes nothing to the
//! shaders beyond those rules; at one void cell between black walls ([`Transport::Cosine`]) it
//! reduces to a closed form: a fraction f = (Ω/4 + X/2) / (5Ω/4 + X/2) ≈ 0.3996 of the emitted
//! flux goes straight on (Ω = 2π/3 the pyramid's solid angle, X = 2√2 atan(1/√2) its cosine
//! integral; the lobe is (1/4 + cos θ/2)/π, its backward integral negative), 1 − f to the sides
//! of the void layer, whose (isotropic) light sends 1/6 on, 1/6 back and 4/6 to the sides
//! again, so the receiver gets f + (1 − f)/2 = (1 + f)/2 ≈ 0.6998 of it and the emitter the
//! rest.

use gibench_harness::glam::Vec3;
use gibench_harness::gpu::GpuContext;
use gibench_harness::{wgpu, Result};

use crate::sh;
use crate::volume::{Grid, Mode, Propagation, Transport, Volumes, CELL_BYTES};

/// The emitting wall's layer.
pub const EMITTER_Z: u32 = 1;

/// Two walls `apart` cells apart (the receiver at z = [`EMITTER_Z`] + `apart`; at 1 they touch
/// and nothing passes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slabs {
    pub apart: u32,
    /// The emitter's direct radiosity B.
    pub radiosity: f32,
    pub emitter_albedo: f32,
    pub receiver_albedo: f32,
    pub transport: Transport,
}

/// The walls' indirect irradiance after some iterations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Irradiance {
    pub receiver: f64,
    /// The emitter's spurious self-irradiance: light it emitted that came back (its own
    /// reflections included).
    pub emitter: f64,
}

/// The model (see the module docs): the walls' irradiance after `iterations` iterations.
pub fn model(s: &Slabs, iterations: u32) -> Irradiance {
    let pi = std::f64::consts::PI;
    let c0 = sh::C0 as f64;
    let c1 = sh::C1 as f64;
    // The face pyramid's coefficients and the unit-integral cosine lobe's.
    let x = 2.0 * 2f64.sqrt() * (1.0 / 2f64.sqrt()).atan();
    let face0 = 4.0 * pi / 6.0 * c0;
    let face1 = x * c1;
    // The pyramid's second moments along and across its axis.
    let axial = sh::FACE_MOMENT_AXIAL as f64;
    let across = (4.0 * pi / 6.0 - axial) / 2.0;
    let (cos0, cos1) = (c0, 2.0 / 3.0 * c1);
    let whole = |st: [f64; 2]| st[0] * 4.0 * pi * c0;
    let top = s.apart as usize;
    let layers = top + 1;
    let mut state = vec![[0.0f64; 2]; layers];
    state[0] = [s.radiosity as f64 * cos0, s.radiosity as f64 * cos1];
    let (mut at_emitter, mut at_receiver) = (0.0, 0.0);
    for _ in 0..iterations {
        let mut next = vec![[0.0f64; 2]; layers];
        for z in 0..layers {
            let st = state[z];
            let w = whole(st);
            if w <= 0.0 {
                continue;
            }
            // Faces +z, −z, and one side; which are open.
            let integral = [
                st[0] * face0 + st[1] * face1,
                st[0] * face0 - st[1] * face1,
                st[0] * face0,
            ];
            let open = match z {
                0 => [top > 1, false, false],
                z if z == top => [false, top > 1, false],
                _ => [true, true, true],
            };
            let weights = [1.0, 1.0, 4.0];
            let positive: f64 = (0..3)
                .filter(|&k| open[k])
                .map(|k| integral[k].max(0.0) * weights[k])
                .sum();
            if positive <= 0.0 {
                continue;
            }
            let share = |k: usize| {
                if open[k] {
                    integral[k].max(0.0) * w / positive
                } else {
                    0.0
                }
            };
            for (k, dz) in [(0usize, 1i64), (1, -1)] {
                let f = share(k);
                let t = z as i64 + dz;
                if f <= 0.0 || t < 0 || t >= layers as i64 {
                    continue;
                }
                let t = t as usize;
                let wall = t == 0 || t == top;
                match s.transport {
                    _ if wall => {
                        next[t][0] += f * cos0;
                        next[t][1] += f * cos1 * dz as f64;
                    }
                    Transport::Cosine => {
                        next[t][0] += f * cos0;
                        next[t][1] += f * cos1 * dz as f64;
                    }
                    Transport::Carry => {
                        next[t][0] += f * st[0] / w;
                        next[t][1] += f * st[1] / w;
                    }
                    Transport::Pyramid => {
                        // The first moment's z part over the ±z pyramid.
                        let m = dz as f64 * c0 * st[0] * x + c1 * axial * st[1];
                        next[t][0] += f * c0;
                        next[t][1] += f * c1 * m / integral[k];
                    }
                }
                if t == 0 {
                    at_emitter += f;
                } else if t == top {
                    at_receiver += f;
                }
            }
            let side = 4.0 * share(2);
            if side > 0.0 {
                match s.transport {
                    Transport::Cosine => next[z][0] += side * cos0,
                    Transport::Carry => {
                        next[z][0] += side * st[0] / w;
                        next[z][1] += side * st[1] / w;
                    }
                    Transport::Pyramid => {
                        // The side pyramids' first moments: their x and y parts cancel among
                        // the four, their z parts are c1 · across · c_z each.
                        next[z][0] += side * c0;
                        next[z][1] += side * c1 * (c1 * across * st[1]) / integral[2];
                    }
                }
            }
        }
        // The walls reflect: albedo times the mirror image in z.
        for (z, rho) in [(0, s.emitter_albedo), (top, s.receiver_albedo)] {
            next[z] = [rho as f64 * next[z][0], -(rho as f64) * next[z][1]];
        }
        state = next;
    }
    Irradiance {
        receiver: at_receiver,
        emitter: at_emitter,
    }
}

/// Kaplanyan's (2009) face weights beside ours, for one unit-integral clamped-cosine lobe along
/// +z in a cell of unit edge. Light propagation volumes send a cell's light to each of its six
/// neighbours through that neighbour's five faces other than the shared one, each weighted by
/// the solid angle the face subtends from the sending cell's centre (the far face `front`, the
/// four adjoining ones `side`) times the radiance towards the face's centre, and re-emit it as a
/// cosine lobe along the face's normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceWeights {
    /// Solid angle of the far face of the forward neighbour (sr).
    pub front: f64,
    /// Solid angle of one of its side faces (sr).
    pub side: f64,
    /// Flux sent, all faces of all neighbours (1 would conserve energy).
    pub total: f64,
    /// Of it, the share re-emitted along +z (still moving forward).
    pub forward: f64,
    /// The share re-emitted along −z (turned back).
    pub backward: f64,
    /// The share that lands in the forward neighbour (whatever its new direction).
    pub into_forward_cell: f64,
}

/// The share of a clamped-cosine lobe's flux that our propagation sends through the face it
/// points at (the rest through the four side faces; none back): f = (Ω/4 + X/2) / (5Ω/4 + X/2)
/// with Ω = 2π/3 a face pyramid's solid angle and X = 2√2 atan(1/√2) its cosine integral.
pub fn forward_share() -> f64 {
    let omega = 2.0 * std::f64::consts::PI / 3.0;
    let x = 2.0 * 2f64.sqrt() * (1.0 / 2f64.sqrt()).atan();
    (omega / 4.0 + x / 2.0) / (5.0 * omega / 4.0 + x / 2.0)
}

/// The solid angle of the rectangle [0, a] × [0, b] at distance `d` seen from above its corner.
fn corner_rectangle(a: f64, b: f64, d: f64) -> f64 {
    (a * b / (d * (a * a + b * b + d * d).sqrt())).atan()
}

/// Kaplanyan's weights ([`FaceWeights`]) for a clamped-cosine lobe along +z.
pub fn kaplanyan_weights() -> FaceWeights {
    use std::f64::consts::PI;
    // Far face: centred, half-edges 1/2, at 3/2. Side face of the forward neighbour: the plane
    // x = 1/2, y in [-1/2, 1/2], z in [1/2, 3/2], seen from the origin.
    let front = 4.0 * corner_rectangle(0.5, 0.5, 1.5);
    let side = 2.0 * (corner_rectangle(1.5, 0.5, 0.5) - corner_rectangle(0.5, 0.5, 0.5));
    let radiance = |d: [f64; 3]| {
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        ((0.25 + 0.5 * d[2] / len) / PI).max(0.0)
    };
    let (mut total, mut forward, mut backward, mut into_forward_cell) = (0.0, 0.0, 0.0, 0.0);
    let axes: [[f64; 3]; 6] = [
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    for n in axes {
        // The neighbour's centre is n; its faces other than the shared one: n + f/2.
        for f in axes {
            if f == n.map(|v| -v) {
                continue;
            }
            let centre = [n[0] + f[0] / 2.0, n[1] + f[1] / 2.0, n[2] + f[2] / 2.0];
            let omega = if f == n { front } else { side };
            let flux = omega * radiance(centre);
            total += flux;
            if f[2] > 0.5 {
                forward += flux;
            } else if f[2] < -0.5 {
                backward += flux;
            }
            if n[2] > 0.5 {
                into_forward_cell += flux;
            }
        }
    }
    FaceWeights {
        front,
        side,
        total,
        forward: forward / total,
        backward: backward / total,
        into_forward_cell: into_forward_cell / total,
    }
}

/// The walls' voxels in an `n`³ grid (12 floats per cell: normal and occupancy, albedo,
/// radiosity).
fn voxels(s: &Slabs, n: u32) -> Vec<f32> {
    let floats = (CELL_BYTES / 4) as usize;
    let mut v = vec![0f32; n.pow(3) as usize * floats];
    for (z, normal, albedo, b) in [
        (EMITTER_Z, 1.0, s.emitter_albedo, s.radiosity),
        (EMITTER_Z + s.apart, -1.0, s.receiver_albedo, 0.0),
    ] {
        for y in 0..n {
            for x in 0..n {
                let i = (x + n * (y + n * z)) as usize * floats;
                v[i..i + 12].copy_from_slice(&[
                    0.0, 0.0, normal, 1.0, albedo, albedo, albedo, 0.0, b, b, b, 0.0,
                ]);
            }
        }
    }
    v
}

/// The propagation on the GPU: the walls in an `n`³ grid of unit cells (`apart` +
/// [`EMITTER_Z`] < `n`), the emitter's radiance injected, `iterations` iterations, the walls'
/// irradiance at the central column (red channel; the three are equal).
pub fn measure(gpu: &GpuContext, s: &Slabs, n: u32, iterations: u32) -> Result<Irradiance> {
    assert!(EMITTER_Z + s.apart < n, "the walls must fit in the grid");
    let grid = Grid {
        n,
        origin: Vec3::ZERO,
        cell: 1.0,
        mode: Mode::Occluded,
        stored_albedo: true,
        transport: s.transport,
    };
    let volumes = Volumes::new(gpu, &grid)?;
    let propagation = Propagation::new(gpu, &grid, &volumes)?;
    let floats = (CELL_BYTES / 4) as usize;
    let cells = n.pow(3) as usize;
    let mut field = vec![0f32; cells * floats];
    let lobe = sh::cosine_unit(Vec3::Z).map(|c| c * s.radiosity);
    for y in 0..n {
        for x in 0..n {
            let i = (x + n * (y + n * EMITTER_Z)) as usize * floats;
            for channel in 0..3 {
                field[i + 4 * channel..i + 4 * channel + 4].copy_from_slice(&lobe);
            }
        }
    }
    let zero = vec![0f32; cells * floats];
    gpu.queue
        .write_buffer(&volumes.voxels, 0, bytemuck::cast_slice(&voxels(s, n)));
    gpu.queue
        .write_buffer(&volumes.propagation[0], 0, bytemuck::cast_slice(&field));
    gpu.queue
        .write_buffer(&volumes.accumulation, 0, bytemuck::cast_slice(&zero));
    // In chunks, so that no one submission runs for long.
    let mut done = 0;
    while done < iterations {
        let k = (iterations - done).min(16);
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        propagation.encode_from(&mut enc, done % 2, k);
        gpu.queue.submit([enc.finish()]);
        gpu.flush()?;
        done += k;
    }
    let acc = read(gpu, &volumes.accumulation)?;
    let at = |z: u32, normal: Vec3| {
        let i = ((n / 2) + n * ((n / 2) + n * z)) as usize * floats;
        let c: [f32; 4] = acc[i..i + 4].try_into().unwrap();
        sh::irradiance(&c, normal) as f64
    };
    Ok(Irradiance {
        receiver: at(EMITTER_Z + s.apart, Vec3::NEG_Z),
        emitter: at(EMITTER_Z, Vec3::Z),
    })
}

fn read(gpu: &GpuContext, buffer: &wgpu::Buffer) -> Result<Vec<f32>> {
    Ok(bytemuck::pod_collect_to_vec(
        &gibench_harness::gpu::image_io::read_buffer(gpu, buffer)?,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn slabs(apart: u32, transport: Transport) -> Slabs {
        Slabs {
            apart,
            radiosity: 1.0,
            emitter_albedo: 0.0,
            receiver_albedo: 0.0,
            transport,
        }
    }

    /// The model against its closed form at one void cell between black walls: (1 + f)/2
    /// reaches the receiver and the rest returns (the module docs derive it).
    #[test]
    fn the_model_matches_its_closed_form_at_one_void_cell() {
        let want = (1.0 + forward_share()) / 2.0;
        let r = model(&slabs(2, Transport::Cosine), 400);
        assert!((r.receiver - want).abs() < 1e-6, "{r:?} vs {want}");
        assert!((r.emitter - (1.0 - want)).abs() < 1e-6, "{r:?}");
        // Carry: the lobe keeps pointing at the receiver; nothing returns.
        let r = model(&slabs(2, Transport::Carry), 400);
        assert!(
            (r.receiver - 1.0).abs() < 1e-6 && r.emitter.abs() < 1e-9,
            "{r:?}"
        );
    }

    /// Kaplanyan's solid angles are the ones his course notes give (0.4006 and 0.4234 sr), and
    /// the five faces of the six neighbours tile the sphere (6 × (front + 4 side) = 4π).
    #[test]
    fn kaplanyan_solid_angles_match_the_published_ones() {
        let w = kaplanyan_weights();
        assert!((w.front - 0.4006).abs() < 1e-4, "{w:?}");
        assert!((w.side - 0.4234).abs() < 1e-4, "{w:?}");
        let sphere = 6.0 * (w.front + 4.0 * w.side);
        assert!(
            (sphere - 4.0 * std::f64::consts::PI).abs() < 1e-9,
            "{sphere}"
        );
    }

    /// Energy: between black walls, what reaches the two adds up to what was emitted once the
    /// propagation has converged (every iteration passes on exactly the flux it holds).
    #[test]
    fn the_model_conserves_the_emitted_flux() {
        for transport in [Transport::Cosine, Transport::Carry, Transport::Pyramid] {
            for apart in [2, 3, 5, 9] {
                let r = model(&slabs(apart, transport), 4000);
                assert!(
                    (r.receiver + r.emitter - 1.0).abs() < 1e-4,
                    "{transport:?} {apart}: {r:?}"
                );
            }
        }
    }
}
