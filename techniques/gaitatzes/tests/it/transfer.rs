//! What the propagation carries between two parallel walls of voxels ([`gibench_gaitatzes::slab`]),
//! on the GPU (every portable backend present), against the model of the propagation's rules
//! in `slab::model` — not against earlier output. The walls' irradiance is read through
//! `sh::irradiance`, the reconstruction's formula, so these tests fail when its
//! flux-to-irradiance constant is wrong (without it every value is 7/12 of the model's).
//!
//! Tolerance: 1 % of the emitted radiosity. The model is of infinite walls; the grid's walls
//! end at its sides, where light leaves, and that loss reaches the central column only after
//! it has diffused half the grid across. Measured: in the two-plane scene (64 iterations) a 32³
//! grid's centre lacks 3 % of the model's floor irradiance, a 64³ grid's less than 1 %; the
//! tests use 32³ for walls at most 5 cells apart (48 iterations) and 48³ for the two planes.
//! Single-precision rounding is orders of magnitude below.

use gibench_gaitatzes::slab::{measure, model, Irradiance, Slabs};
use gibench_gaitatzes::volume::Transport;
use gibench_test_support::gpus;

const N: u32 = 32;
/// The two-plane scene's grid: its walls are 16 cells apart and 64 iterations long, and light
/// diffuses further towards the grid's sides.
const N_WIDE: u32 = 48;
/// `transport=pyramid` moves light sideways nearly straight (its side lobes keep their
/// direction), so the grid's sides are felt sooner: 64³ for it.
const N_PYRAMID: u32 = 64;

fn cells(transport: Transport, n: u32) -> u32 {
    match transport {
        Transport::Pyramid => N_PYRAMID,
        _ => n,
    }
}
const TOLERANCE: f64 = 0.01;
/// `transport=pyramid` in the two-plane scene: its floor lacks, from the grid's sides, 0.093 of
/// the model's at 48³ and 0.021 at 64³ (measured; the loss shrinks with the grid and is never a
/// gain); 0.03 at 64³.
const TOLERANCE_PYRAMID_PLANES: f64 = 0.03;

fn check(backend: &str, what: &str, got: Irradiance, want: Irradiance, tolerance: f64) {
    assert!(
        (got.receiver - want.receiver).abs() <= tolerance
            && (got.emitter - want.emitter).abs() <= tolerance,
        "{backend} {what}: measured {got:?}, the model {want:?}"
    );
}

/// One lit layer of voxels (radiosity 1) facing a black receiving layer with 1, 2 and 4 void
/// cells between them (2, 3 and 5 cells apart), each transport, 48 iterations: the receiver's
/// and the emitter's irradiance are the model's. With `transport=cosine` the model's receiver
/// gets 0.70, 0.55 and 0.39 of the emitted flux once converged (the rest returns to the
/// emitter); with `transport=carry` all of it, so the receiver's irradiance is exactly the
/// emitter's radiosity, as between two infinite planes; `transport=pyramid` between the two
/// (0.84, 0.75, 0.63).
#[test]
fn a_lit_layer_gives_the_facing_layer_the_modelled_irradiance() {
    for (backend, gpu) in gpus("transfer") {
        for transport in [Transport::Cosine, Transport::Carry, Transport::Pyramid] {
            for apart in [2, 3, 5] {
                let s = Slabs {
                    apart,
                    radiosity: 1.0,
                    emitter_albedo: 0.0,
                    receiver_albedo: 0.0,
                    transport,
                };
                let got = measure(&gpu, &s, cells(transport, N), 48).expect("propagation runs");
                let want = model(&s, 48);
                assert!(want.receiver > 0.3, "{want:?}");
                check(
                    backend,
                    &format!("{transport:?} {apart} apart"),
                    got,
                    want,
                    TOLERANCE,
                );
                let limit = model(&s, 4000);
                match transport {
                    Transport::Carry => assert!(
                        (limit.receiver - 1.0).abs() < 1e-4,
                        "carry, {apart} apart: {limit:?}"
                    ),
                    Transport::Cosine => assert!(
                        limit.receiver < 0.71 && limit.emitter > 0.29,
                        "cosine, {apart} apart: {limit:?}"
                    ),
                    Transport::Pyramid => {
                        let cosine = model(
                            &Slabs {
                                transport: Transport::Cosine,
                                ..s
                            },
                            4000,
                        );
                        assert!(
                            limit.receiver > cosine.receiver + 0.1 && limit.receiver < 0.9,
                            "pyramid, {apart} apart: {limit:?} (cosine {cosine:?})"
                        );
                    }
                }
            }
        }
    }
}

/// The two-plane scene: a lit floor (albedo 0.8, radiosity 1) and a black ceiling 16 cells
/// above (2 m at the room's cell of 1/8 m), 64 iterations (the paper's room count). The
/// reference (infinite planes): the ceiling's indirect irradiance is the floor's radiosity, 1;
/// the floor's is 0 (it sees only the black ceiling). Each transport measures what the model
/// predicts — with `transport=cosine` the ceiling 0.09 and the floor a spurious 1.34 (its own
/// light returned and re-reflected), with `transport=pyramid` 0.58 and 0.55 — and
/// `transport=carry` meets the reference: the ceiling within 15 %, the floor below 0.01.
#[test]
fn lit_floor_and_black_ceiling_match_the_model() {
    for (backend, gpu) in gpus("transfer") {
        for transport in [Transport::Cosine, Transport::Carry, Transport::Pyramid] {
            let s = Slabs {
                apart: 16,
                radiosity: 1.0,
                emitter_albedo: 0.8,
                receiver_albedo: 0.0,
                transport,
            };
            let got = measure(&gpu, &s, cells(transport, N_WIDE), 64).expect("propagation runs");
            let want = model(&s, 64);
            let tolerance = match transport {
                Transport::Pyramid => TOLERANCE_PYRAMID_PLANES,
                _ => TOLERANCE,
            };
            check(backend, &format!("{transport:?}"), got, want, tolerance);
            match transport {
                Transport::Cosine => assert!(
                    want.receiver < 0.15 && want.emitter > 1.0,
                    "cosine: {want:?}"
                ),
                Transport::Carry => assert!(
                    (got.receiver - 1.0).abs() < 0.15 && got.emitter < 0.01,
                    "{backend} carry: {got:?}"
                ),
                // Between the two: more reaches the ceiling, less returns, not all.
                Transport::Pyramid => assert!(
                    want.receiver > 0.5 && want.emitter < 0.6,
                    "pyramid: {want:?}"
                ),
            }
        }
    }
}
