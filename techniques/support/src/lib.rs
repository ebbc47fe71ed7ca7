//! Helpers the harness's and the technique crates' integration tests share (a dev-dependency only): every GPU
//! test runs on each portable backend present ([`gpus`], [`each_backend`]), reads its results
//! back ([`read_f32`], [`read_rgb`]), draws its random numbers from a fixed sequence ([`Lcg`]),
//! builds small scenes in code ([`scene`]) and runs registered techniques frame by frame
//! ([`technique`]).

pub mod gpu;
pub mod readback;
pub mod rng;
pub mod scene;
pub mod technique;

pub use gpu::{each_backend, gpus, run_config};
pub use readback::{read_f32, read_rgb};
pub use rng::Lcg;
pub use scene::{
    closed_box_mesh, descriptor, load, material, quad, scene, scene_from_json, scene_with,
};
pub use technique::{kv, Rendered};
