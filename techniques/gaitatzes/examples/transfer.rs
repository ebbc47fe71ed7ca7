//! The transfer sweep behind the README's *what the propagation loses* paragraph: two parallel
//! walls of voxels ([`gibench_gaitatzes::slab`]), a lit one (radiosity 1) and a black one
//! `apart` cells away, each transport; the share of the emitted flux that reaches the facing
//! wall and the share that returns to the emitter, in the model (converged: 4000 iterations,
//! and after 64) and measured on the GPU after 64 iterations in a 64³ grid; and the two-plane
//! scene (a floor of albedo 0.8, a black ceiling 16 cells above).
//!
//! `cargo run --release -p gibench-gaitatzes --example transfer -- results/gaitatzes/transfer`
//! writes `transfer.csv` and `transfer.md` there.

use std::fmt::Write as _;

use gibench_gaitatzes::slab::{forward_share, kaplanyan_weights, measure, model, Slabs};
use gibench_gaitatzes::volume::Transport;
use gibench_harness::gpu::{GpuContext, GpuOptions};

const GRID: u32 = 64;
const ITERATIONS: u32 = 64;

fn main() {
    let out = std::path::PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "results/gaitatzes/transfer".into()),
    );
    std::fs::create_dir_all(&out).expect("the output folder");
    let gpu = GpuContext::new(&GpuOptions::default()).expect("a GPU adapter (Vulkan or GL)");
    let adapter = gpu.adapter.get_info();
    let mut csv = String::from(
        "scene,apart,transport,emitter_albedo,model_receiver_converged,model_emitter_converged,model_receiver_64,model_emitter_64,gpu_receiver_64,gpu_emitter_64\n",
    );
    let mut md = format!(
        "# gaitatzes: transfer between two parallel walls of voxels\n\n\
         Radiosity 1 on the emitting wall; receiver black. `model`: the propagation's rules on \
         infinite walls (`slab::model`), converged (4000 iterations) and after {ITERATIONS}; \
         `GPU`: measured after {ITERATIONS} iterations at the central column of a {GRID}³ grid \
         ({}, {:?}; git {}). Values are irradiance over the emitter's radiosity (the share of the \
         emitted flux); the exact answer for infinite planes is receiver 1, emitter 0.\n\n\
         | scene | apart (cells) | transport | receiver, converged (model) | emitter, converged (model) | receiver, {ITERATIONS} it. (model) | receiver, {ITERATIONS} it. (GPU) | emitter, {ITERATIONS} it. (model) | emitter, {ITERATIONS} it. (GPU) |\n\
         |---|---|---|---|---|---|---|---|---|\n",
        adapter.name,
        adapter.backend,
        gibench_harness::run::runner::git_commit()
    );
    let mut row = |scene: &str, s: Slabs| {
        let converged = model(&s, 4000);
        let m = model(&s, ITERATIONS);
        let g = measure(&gpu, &s, GRID, ITERATIONS).expect("propagation runs");
        let t = s.transport.name();
        writeln!(
            csv,
            "{scene},{},{t},{},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4}",
            s.apart,
            s.emitter_albedo,
            converged.receiver,
            converged.emitter,
            m.receiver,
            m.emitter,
            g.receiver,
            g.emitter
        )
        .unwrap();
        writeln!(
            md,
            "| {scene} | {} | {t} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} |",
            s.apart,
            converged.receiver,
            converged.emitter,
            m.receiver,
            g.receiver,
            m.emitter,
            g.emitter
        )
        .unwrap();
        eprintln!("{scene} {} {t}: model {converged:?}, GPU {g:?}", s.apart);
    };
    for transport in [Transport::Cosine, Transport::Carry, Transport::Pyramid] {
        for apart in [2, 3, 4, 5, 8, 16, 30] {
            row(
                "black walls",
                Slabs {
                    apart,
                    radiosity: 1.0,
                    emitter_albedo: 0.0,
                    receiver_albedo: 0.0,
                    transport,
                },
            );
        }
    }
    for transport in [Transport::Cosine, Transport::Carry, Transport::Pyramid] {
        row(
            "lit floor (0.8), black ceiling",
            Slabs {
                apart: 16,
                radiosity: 1.0,
                emitter_albedo: 0.8,
                receiver_albedo: 0.0,
                transport,
            },
        );
    }
    // Kaplanyan's face weights beside ours, for one clamped-cosine lobe along +z.
    let k = kaplanyan_weights();
    let f = forward_share();
    write!(
        md,
        "\n## Face weights: Kaplanyan (2009) beside ours\n\n\
         One unit-integral clamped-cosine lobe along +z, propagated one step. Kaplanyan: the five \
         faces of each of the six neighbours, weighted by their solid angles from the sending \
         cell's centre (far face {:.4} sr, side face {:.4} sr; 6 × (far + 4 side) = 4π) times \
         the radiance towards each face's centre, re-emitted as cosine lobes along the faces' \
         normals. Ours: the integral over each of the sending cell's six face pyramids, \
         renormalised to the flux, re-emitted along the face's axis.\n\n\
         | | flux sent (1 conserves) | into the forward cell | re-emitted forward (+z) | re-emitted backward (−z) |\n\
         |---|---|---|---|---|\n\
         | Kaplanyan | {:.3} | {:.3} | {:.3} | {:.3} |\n\
         | ours (`transport=cosine`) | 1.000 | {f:.3} | {f:.3} | 0.000 |\n\
         | ours (`transport=carry`) | 1.000 | {f:.3} | 1.000 (every lobe keeps +z) | 0.000 |\n",
        k.front, k.side, k.total, k.into_forward_cell, k.forward, k.backward
    )
    .unwrap();
    std::fs::write(out.join("transfer.csv"), csv).unwrap();
    std::fs::write(out.join("transfer.md"), md).unwrap();
    eprintln!("wrote {}", out.display());
}
