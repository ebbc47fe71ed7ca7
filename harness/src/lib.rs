//! # gibench-harness
//!
//! Everything the techniques share, written once, in folders by concern. Each folder uses only
//! the ones above it in this list (`harness/tests/it/layers.rs` checks it):
//!
//! * [`error`], [`interrupt`], [`output`] and [`rng`]: errors; polite stops (SIGTERM, SIGINT);
//!   atomic files and output sets; random numbers;
//! * [`measure`]: statistics, image metrics, the timer calibration, the results file model,
//!   the roofline's costs and bounds;
//! * [`scene`]: the scene model and its loaders, the asset search path, the animation clock;
//! * [`cpu`]: the BVH over the static geometry, the one light model, VPL paths, the reference
//!   path tracer;
//! * [`gpu`]: the GPU context, the profiler, image read-back and image files;
//! * [`kit`]: the technique interface, the shared GPU passes, the instant-radiosity kit;
//! * [`run`]: the frame loop, the quality pass, a session of runs, the bounds' kernels;
//! * [`report`]: tables, plots, comparisons of results and the HTML page.
//!
//! ## Radiometric convention
//!
//! All techniques and the reference use one convention (RGB, linear, scene length units):
//!
//! * The primary light's `power` Φ (descriptor field `light.power`) is its total emitted flux.
//!   * omni point light: radiant intensity I = Φ / 4π in every direction;
//!   * spot light (180° cone, cosine falloff, as in Laine et al. 2007): I(θ) = (Φ / π) cos θ
//!     for θ < 90° from the spot direction, 0 behind it;
//!   * area light (one-sided Lambertian rectangle): radiance L = Φ / (π A). The GPU direct pass
//!     treats it as a cosine spot at its centre (same Φ, same far field); see the README's
//!     deviations table.
//! * A surface point receives irradiance E = I(ω) cos θ_r / r² from a point light (times
//!   visibility).
//! * Every technique outputs *indirect irradiance* E_ind (W/m² in scene units) per pixel, not
//!   multiplied by the receiver's albedo. A VPL carries flux Φ_vpl and emits like a cosine spot
//!   around its surface normal: I(θ) = (Φ_vpl / π) cos θ.
//! * The composed outgoing radiance of a diffuse pixel is L = (ρ / π)(E_direct + E_ind).
//! * PNG images are `clamp(exposure · L)` encoded as sRGB; the exposure is a scene setting.

pub mod cpu;
pub mod error;
pub mod gpu;
pub mod interrupt;
pub mod kit;
pub mod measure;
pub mod output;
pub mod report;
pub mod rng;
pub mod run;
pub mod scene;

pub use error::{Error, Result};
pub use glam;
pub use wgpu;
