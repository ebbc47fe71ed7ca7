//! Helpers every tier's tests share (a dev-dependency only: of the root package, the harness
//! and the technique crates; the root's benches too): every GPU test runs on each portable
//! backend present ([`gpus`], [`each_backend`], [`backends_for`]; [`GpuTest`] where it needs
//! features or limits, skipping with a printed reason), with run settings built from
//! one frame ([`one_frame`]), reads its results back ([`read_f32`], [`read_rgb`]), draws its
//! random numbers from a fixed sequence ([`Lcg`]), builds small scenes in code ([`scene`]) and
//! runs registered techniques frame by frame ([`technique`]); the root's tests run the
//! `gibench` binary ([`Gibench`]).

pub mod bin;
pub mod config;
pub mod gpu;
pub mod readback;
pub mod rng;
pub mod scene;
pub mod source;
pub mod technique;

pub use bin::{reference_image, Gibench};
pub use config::{one_frame, run_config, Config};
pub use gpu::{
    available_backends, backend_context, backends_for, each_backend, gpus, say_uncaptured, GpuTest,
};
pub use readback::{read_f32, read_rgb};
pub use rng::Lcg;
pub use scene::{
    closed_box_mesh, descriptor, load, material, quad, scene, scene_from_json, scene_with,
};
pub use technique::{kv, Rendered};
