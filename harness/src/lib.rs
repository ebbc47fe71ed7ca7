//! # gibench-harness
//!
//! Everything the techniques share, written once: the GPU context ([`gpu`]), the scene model and
//! its loaders ([`scene`]), the deterministic animation clock ([`anim`]), CPU ray casting over the
//! static geometry ([`bvh`]), the one light model ([`light`]), the shared GPU passes
//! ([`passes`]), the instant-radiosity kit ([`ir`]), the profiler ([`profiler`]), the
//! technique interface ([`technique`]), the frame loop ([`runner`]), results ([`results`]) and
//! their tables and plots ([`report`]).
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

pub mod anim;
pub mod assets;
pub mod bounds;
pub mod bvh;
pub mod calibrate;
pub mod compare;
pub mod error;
pub mod gpu;
pub mod html;
pub mod image_io;
pub mod ir;
pub mod light;
pub mod metrics;
pub mod output;
pub mod passes;
pub mod profiler;
pub mod quality;
pub mod reference;
pub mod report;
pub mod results;
pub mod rng;
pub mod roofline;
pub mod runner;
pub mod scene;
pub mod session;
pub mod stats;
pub mod technique;
pub mod threads;
pub mod vpl;

pub use error::{Error, Result};
pub use glam;
pub use wgpu;
