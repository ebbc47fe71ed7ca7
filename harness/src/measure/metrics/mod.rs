//! Image-quality metrics: how far a technique's image is from the reference, per frame and over
//! time.
//!
//! All metrics compare two images of the same size given as `&[Vec3]` (linear RGB, row-major,
//! top row first) together with a `mask` of the pixels to include (the pixels where geometry was
//! hit, so the background does not dilute the error). Each metric averages over the masked pixels
//! *and* the three channels, in `f64`.
//!
//! Robustness conventions shared by the pixel metrics (they return a plain `f64`, never panic):
//!
//! * only the first `min(test.len(), reference.len(), mask.len())` pixels are looked at; pixels
//!   past the end of any of the slices are treated as masked out;
//! * when no pixel is masked in, the metric is `0.0` (there is nothing to be wrong about), never
//!   NaN, so that results stay serialisable as JSON numbers.
//!
//! Perceptual error uses NVIDIA's LDR-ꟻLIP ([`flip`]) on the tone-mapped sRGB8 images that the
//! display target would show ([`tonemap_srgb8`]); [`flip_error_png`] turns its error map into a
//! picture. Temporal stability (flicker) is measured by [`temporal_instability`] and
//! [`relative_temporal_instability`]. [`summarize`] turns per-frame [`FrameQuality`] records into
//! a [`QualitySummary`].

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::measure::stats::Stats;
use crate::{Error, Result};

mod temporal;
pub use temporal::{flicker_floor, relative_temporal_instability, temporal_instability};

/// Visits every masked-in pixel (see the module conventions) with its test and reference value.
fn for_each_masked(
    test: &[Vec3],
    reference: &[Vec3],
    mask: &[bool],
    mut f: impl FnMut(Vec3, Vec3),
) {
    for ((t, r), m) in test.iter().zip(reference).zip(mask) {
        if *m {
            f(*t, *r);
        }
    }
}

/// Mean over the masked pixels and the three channels of `g(t_c, r_c)`; 0 when none is masked.
fn channel_mean(
    test: &[Vec3],
    reference: &[Vec3],
    mask: &[bool],
    mut g: impl FnMut(f64, f64) -> f64,
) -> f64 {
    let mut sum = 0.0f64;
    let mut n = 0usize;
    for_each_masked(test, reference, mask, |t, r| {
        for c in 0..3 {
            sum += g(t[c] as f64, r[c] as f64);
        }
        n += 3;
    });
    if n == 0 {
        0.0
    } else {
        sum / n as f64
    }
}

/// Root-mean-square error: `sqrt(mean over masked pixels p and channels c of (t_pc − r_pc)²)`.
///
/// Same units as the images (so a constant offset `d` gives exactly `d`). 0 when no pixel is
/// masked in.
pub fn rmse(test: &[Vec3], reference: &[Vec3], mask: &[bool]) -> f64 {
    channel_mean(test, reference, mask, |t, r| (t - r) * (t - r)).sqrt()
}

/// Mean absolute error: `mean over masked pixels p and channels c of |t_pc − r_pc|`.
///
/// Same units as the images. 0 when no pixel is masked in.
pub fn mae(test: &[Vec3], reference: &[Vec3], mask: &[bool]) -> f64 {
    channel_mean(test, reference, mask, |t, r| (t - r).abs())
}

/// Relative mean squared error (Rousselle, Knaus and Zwicker 2011, "Adaptive sampling and
/// reconstruction using greedy error minimization"), in its scale-invariant form:
///
/// ```text
/// relMSE = mean over masked pixels p and channels c of (t_pc − r_pc)² / (r_pc² + ε)
/// ε      = 1e-2 · m²,   m = mean over masked pixels p and channels c of |r_pc|
/// ```
///
/// (`|r|` = `r` for the non-negative images the harness produces.) Because ε scales with the
/// square of the image's mean, multiplying both images by the same factor `k > 0` leaves the
/// value unchanged, so scenes with different light power or exposure are comparable; the ε term
/// keeps nearly black reference pixels from dominating. Dimensionless.
///
/// Edge cases: 0 for identical images and when no pixel is masked in. If the reference is black
/// over the whole mask (`m = 0`), `m` is taken from the test image instead (mean of `|t_pc|`), so
/// the value stays finite and still scale-invariant; it is then 0 only if the test is black too.
pub fn relative_mse(test: &[Vec3], reference: &[Vec3], mask: &[bool]) -> f64 {
    let mut m = channel_mean(test, reference, mask, |_, r| r.abs());
    if m == 0.0 {
        m = channel_mean(test, reference, mask, |t, _| t.abs());
    }
    if m == 0.0 {
        // Both images black over the mask (or nothing masked in): no error.
        return 0.0;
    }
    let eps = 1e-2 * m * m;
    channel_mean(test, reference, mask, |t, r| {
        (t - r) * (t - r) / (r * r + eps)
    })
}

/// `clamp(x, 0, 1)` with NaN mapped to 0 (like a GPU's saturate).
fn saturate(x: f32) -> f32 {
    if x > 0.0 {
        x.min(1.0)
    } else {
        0.0
    }
}

/// The exact sRGB transfer function (IEC 61966-2-1 OETF) for a linear value in `[0, 1]`.
fn srgb_encode(linear: f64) -> f64 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// Tone-maps linear radiance to sRGB8, 3 bytes per pixel (RGB, same pixel order).
///
/// Per channel: `x = clamp(exposure · L, 0, 1)` (computed in `f32` as on the GPU; NaN becomes 0
/// like the GPU's saturate), then the exact sRGB transfer function, then rounding to the nearest
/// of the 256 levels. This is what the GPU display pass produces when it writes
/// `clamp(radiance * exposure)` into an `Rgba8UnormSrgb` target (the hardware encodes with the
/// same function and rounds to nearest), and what the PNG convention in the crate docs means.
pub fn tonemap_srgb8(radiance: &[Vec3], exposure: f32) -> Vec<u8> {
    let mut out = Vec::with_capacity(radiance.len() * 3);
    for l in radiance {
        for c in 0..3 {
            let x = exposure * l[c];
            let x = saturate(x);
            let v = (srgb_encode(x as f64) * 255.0 + 0.5).floor();
            out.push(v.clamp(0.0, 255.0) as u8);
        }
    }
    out
}

/// Result of an LDR-ꟻLIP comparison.
#[derive(Clone, Debug, PartialEq)]
pub struct FlipResult {
    /// Mean of the per-pixel FLIP error over the pixels considered (the single number the FLIP
    /// authors recommend reporting). In `[0, 1]`.
    pub mean: f64,
    /// Median of the per-pixel error over the pixels considered (plain, unweighted percentile with
    /// linear interpolation as in [`Stats::of`]; not the FLIP tool's value-weighted median).
    pub median: f64,
    /// 95th percentile of the per-pixel error over the pixels considered (same definition).
    pub p95: f64,
    /// The per-pixel FLIP error of the *whole* image (all pixels, masked or not), row-major, top
    /// row first, values in `[0, 1]`.
    pub error_map: Vec<f32>,
}

/// Checks `size` and both buffer lengths; returns the pixel count.
fn check_flip_input(test: &[u8], reference: &[u8], size: [u32; 2]) -> Result<usize> {
    let [w, h] = size;
    if w == 0 || h == 0 {
        return Err(Error::Invalid(format!("FLIP: image size {w}x{h} is empty")));
    }
    let pixels = w as u64 * h as u64;
    // nv-flip computes `width * height * 3` in u32.
    if pixels * 3 > u32::MAX as u64 {
        return Err(Error::Invalid(format!(
            "FLIP: image size {w}x{h} is too large"
        )));
    }
    let expected = pixels as usize * 3;
    let size_of = |len: usize| -> String {
        if len.is_multiple_of(3) {
            format!("{len} bytes ({} RGB8 pixels)", len / 3)
        } else {
            format!("{len} bytes (not a whole number of RGB8 pixels)")
        }
    };
    if test.len() != expected || reference.len() != expected {
        return Err(Error::Invalid(format!(
            "FLIP: image sizes differ: test image has {}, reference image has {}, \
             expected {expected} bytes for {w}x{h} RGB8",
            size_of(test.len()),
            size_of(reference.len())
        )));
    }
    Ok(pixels as usize)
}

/// Runs nv-flip and returns the error map (lengths already checked).
fn flip_error_map(test: &[u8], reference: &[u8], size: [u32; 2]) -> Vec<f32> {
    let [w, h] = size;
    let ref_img = nv_flip::FlipImageRgb8::with_data(w, h, reference);
    let test_img = nv_flip::FlipImageRgb8::with_data(w, h, test);
    nv_flip::flip(ref_img, test_img, nv_flip::DEFAULT_PIXELS_PER_DEGREE).to_vec()
}

/// Mean / median / p95 of the error values selected by `keep`.
fn flip_stats(error_map: Vec<f32>, keep: impl Fn(usize) -> bool) -> FlipResult {
    let values: Vec<f64> = error_map
        .iter()
        .enumerate()
        .filter(|(i, _)| keep(*i))
        .map(|(_, e)| *e as f64)
        .collect();
    let s = Stats::of(&values);
    FlipResult {
        mean: s.mean,
        median: s.median,
        p95: s.p95,
        error_map,
    }
}

/// LDR-ꟻLIP (Andersson et al. 2020) between a test and a reference image, both sRGB8 RGB
/// (3 bytes per pixel, row-major, top row first, e.g. from [`tonemap_srgb8`]) of `size`
/// `[width, height]`, with the `nv-flip` crate's default of 67 pixels per degree (a 0.7 m wide
/// 4K monitor at 0.7 m).
///
/// The statistics cover every pixel of the image; background pixels that are identical in both
/// images add (almost) zero error and so dilute the mean: use [`flip_masked`] to restrict the
/// statistics to the geometry.
///
/// Errors with [`Error::Invalid`] naming both sizes when a buffer's length is not
/// `width · height · 3`, and when the size is empty; never panics.
pub fn flip(test_srgb8: &[u8], reference_srgb8: &[u8], size: [u32; 2]) -> Result<FlipResult> {
    check_flip_input(test_srgb8, reference_srgb8, size)?;
    let map = flip_error_map(test_srgb8, reference_srgb8, size);
    Ok(flip_stats(map, |_| true))
}

/// [`flip`] with its mean, median and p95 taken over the pixels where `mask` is true only (the
/// error map itself is still computed on, and covers, the whole image, so the errors at geometry
/// edges see their neighbourhood). All statistics are 0 when no pixel is masked in; a `mask`
/// shorter than the image counts the missing pixels as masked out.
pub fn flip_masked(
    test_srgb8: &[u8],
    reference_srgb8: &[u8],
    size: [u32; 2],
    mask: &[bool],
) -> Result<FlipResult> {
    check_flip_input(test_srgb8, reference_srgb8, size)?;
    let map = flip_error_map(test_srgb8, reference_srgb8, size);
    Ok(flip_stats(map, |i| mask.get(i).copied().unwrap_or(false)))
}

/// RGBA8 picture (4 bytes per pixel, opaque) of a FLIP error map of `size`, coloured with ꟻLIP's
/// magma colour map (`nv_flip::magma_lut`, indexed exactly as nv-flip's `apply_color_lut`:
/// entry `round(255 · error)`), ready for [`crate::gpu::image_io::write_png`].
///
/// Always returns `width · height · 4` bytes: error values outside `[0, 1]` or NaN are clamped
/// (NaN as 0), and if `result.error_map` is shorter than the image the missing pixels are drawn
/// as error 0.
pub fn flip_error_png(result: &FlipResult, size: [u32; 2]) -> Vec<u8> {
    let lut = nv_flip::magma_lut().to_vec(); // 256 RGB8 entries
    let n = size[0] as usize * size[1] as usize;
    let mut out = Vec::with_capacity(n * 4);
    for i in 0..n {
        let e = result.error_map.get(i).copied().unwrap_or(0.0);
        let e = saturate(e);
        let k = ((e * 255.0 + 0.5) as usize).min(255) * 3;
        out.extend_from_slice(&[lut[k], lut[k + 1], lut[k + 2], 255]);
    }
    out
}

/// Quality of one frame of a technique against the reference.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct FrameQuality {
    /// Frame index.
    pub frame: u32,
    /// [`rmse`] of the technique's image.
    #[serde(with = "crate::measure::stats::nullable")]
    pub rmse: f64,
    /// [`relative_mse`].
    #[serde(with = "crate::measure::stats::nullable")]
    pub rel_mse: f64,
    /// [`mae`].
    #[serde(with = "crate::measure::stats::nullable")]
    pub mae: f64,
    /// Mean LDR-ꟻLIP error ([`FlipResult::mean`]) of the tone-mapped images.
    #[serde(with = "crate::measure::stats::nullable")]
    pub flip_mean: f64,
    /// [`relative_bias`]: signed relative error of the mean (negative = too dark).
    #[serde(default, with = "crate::measure::stats::nullable")]
    pub bias: f64,
    /// [`temporal_instability`] (or its relative form, as the caller documents) against the
    /// previous frame; absent for the first frame or when not measured.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub temporal: Option<f64>,
}

/// Per-frame quality records of one run and statistics over them.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct QualitySummary {
    /// What the technique was compared against, e.g. "one-bounce, 256 spp, 8 bounces, seed 1".
    pub reference: String,
    /// The per-frame records, in the order given.
    pub frames: Vec<FrameQuality>,
    /// Statistics of [`FrameQuality::rmse`] over the frames.
    pub rmse: Stats,
    /// Statistics of [`FrameQuality::rel_mse`].
    pub rel_mse: Stats,
    /// Statistics of [`FrameQuality::mae`].
    pub mae: Stats,
    /// Statistics of [`FrameQuality::flip_mean`].
    pub flip_mean: Stats,
    /// Statistics of [`FrameQuality::bias`].
    #[serde(default)]
    pub bias: Stats,
    /// Statistics of [`FrameQuality::temporal`] over the frames that have it; `None` when no
    /// frame has it.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub temporal: Option<Stats>,
    /// The reference's own flicker floor ([`flicker_floor`]), the mean over up to three of the
    /// compared pairs (spread over them, the last included), in [`FrameQuality::temporal`]'s
    /// units; `None` when no pair was compared (and in files
    /// written before it was recorded).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub flicker_floor: Option<f64>,
    /// How the reference images were come by; absent in files written before it was recorded.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub reference_work: Option<ReferenceWork>,
    /// The run's errors against each indirect component ([`ComponentErrors::NAMES`]: one-bounce
    /// and multi-bounce), its own among them, so that runs of techniques that compute different
    /// components compare on one; empty in files written before they were recorded.
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub components: Vec<ComponentErrors>,
}

impl QualitySummary {
    /// The component the run's own errors (`rmse`, `rel_mse`, ...) are against: the first item
    /// of [`QualitySummary::reference`] ("one-bounce", "multi-bounce" or "direct").
    pub fn own_component(&self) -> &str {
        self.reference.split(',').next().unwrap_or_default().trim()
    }

    /// The run's errors against `component` ("one-bounce" or "multi-bounce"): from
    /// [`QualitySummary::components`], else (a file written before they were recorded) its own
    /// errors where they are against that component.
    pub fn against(&self, component: &str) -> Option<ComponentErrors> {
        (self
            .components
            .iter()
            .find(|c| c.component == component)
            .cloned())
        .or_else(|| (self.own_component() == component).then(|| ComponentErrors::own(self)))
    }
}

/// A run's errors against one indirect component of the reference (one entry of
/// [`QualitySummary::components`]): of indirect irradiance, relative MSE and bias; of the
/// tonemapped composed image (direct plus that component), mean FLIP. Means over the same
/// compared frames as the run's own errors.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct ComponentErrors {
    /// One of [`ComponentErrors::NAMES`].
    pub component: String,
    /// The reference compared with, as [`QualitySummary::reference`].
    pub reference: String,
    pub rel_mse: Stats,
    pub bias: Stats,
    pub flip_mean: Stats,
}

impl ComponentErrors {
    /// The components every run with quality data is scored against.
    pub const NAMES: [&'static str; 2] = ["one-bounce", "multi-bounce"];

    /// The run's own errors, as the entry of its own component.
    pub fn own(q: &QualitySummary) -> ComponentErrors {
        ComponentErrors {
            component: q.own_component().to_string(),
            reference: q.reference.clone(),
            rel_mse: q.rel_mse,
            bias: q.bias,
            flip_mean: q.flip_mean,
        }
    }
}

/// How a quality pass came by its reference images: how many it rendered and how many it read
/// from the reference cache, and the trees the run has built for the scene so far (the static
/// mesh's, shared by every frame, every technique's CPU rays and the reference; the movers',
/// one per mover per rendered frame).
#[derive(Serialize, Deserialize, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ReferenceWork {
    /// Reference frames rendered by this pass.
    pub rendered: u32,
    /// Reference frames this pass read from the cache.
    pub cached: u32,
    /// Builds of the static mesh's tree in the run so far: 1.
    pub static_tree_builds: u32,
    /// Builds of movers' trees in the run so far.
    pub mover_tree_builds: u32,
}

/// Signed relative error of the image's mean over masked pixels and channels:
/// Σ(t − r) / Σ r (0 when the reference is black). Negative means the technique is too dark —
/// e.g. the energy that VPL clamping removes.
pub fn relative_bias(test: &[Vec3], reference: &[Vec3], mask: &[bool]) -> f64 {
    let (mut t, mut r) = (0.0f64, 0.0f64);
    for ((a, b), m) in test.iter().zip(reference).zip(mask) {
        if *m {
            t += a.element_sum() as f64;
            r += b.element_sum() as f64;
        }
    }
    if r > 0.0 {
        (t - r) / r
    } else {
        0.0
    }
}

/// Summarises per-frame quality records ([`Stats::of`] of each metric over the frames).
pub fn summarize(reference: String, frames: Vec<FrameQuality>) -> QualitySummary {
    let of = |f: fn(&FrameQuality) -> f64| Stats::of(&frames.iter().map(f).collect::<Vec<_>>());
    let temporal: Vec<f64> = frames.iter().filter_map(|f| f.temporal).collect();
    QualitySummary {
        reference,
        rmse: of(|f| f.rmse),
        rel_mse: of(|f| f.rel_mse),
        mae: of(|f| f.mae),
        flip_mean: of(|f| f.flip_mean),
        bias: of(|f| f.bias),
        temporal: (!temporal.is_empty()).then(|| Stats::of(&temporal)),
        flicker_floor: None,
        frames,
        reference_work: None,
        components: Vec::new(),
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A deterministic, varied test image of `n` pixels.
    pub(crate) fn image(n: usize) -> Vec<Vec3> {
        (0..n)
            .map(|i| {
                let x = i as f32;
                Vec3::new(
                    0.5 + 0.4 * (x * 0.37).sin(),
                    0.3 + 0.25 * (x * 0.11).cos(),
                    0.05 * (i % 7) as f32,
                )
            })
            .collect()
    }

    pub(crate) fn all(n: usize) -> Vec<bool> {
        vec![true; n]
    }

    #[test]
    fn metrics_identical_images_are_zero() {
        let a = image(64);
        let m = all(64);
        assert_eq!(rmse(&a, &a, &m), 0.0);
        assert_eq!(mae(&a, &a, &m), 0.0);
        assert_eq!(relative_mse(&a, &a, &m), 0.0);
        // Black images too (relative MSE's ε falls back, no NaN).
        let black = vec![Vec3::ZERO; 64];
        assert_eq!(relative_mse(&black, &black, &m), 0.0);
    }

    #[test]
    fn metrics_constant_offset_is_exact() {
        // Values exactly representable so the offset is exact in f32 too.
        let r: Vec<Vec3> = (0..50).map(|i| Vec3::splat(i as f32 * 0.125)).collect();
        let d = 0.25f32;
        let t: Vec<Vec3> = r.iter().map(|v| *v + Vec3::splat(d)).collect();
        let m = all(50);
        assert_eq!(rmse(&t, &r, &m), d as f64);
        assert_eq!(mae(&t, &r, &m), d as f64);
        assert_eq!(rmse(&r, &t, &m), d as f64);
    }

    #[test]
    fn metrics_rel_mse_scale_invariant() {
        let r = image(100);
        let t: Vec<Vec3> = image(100)
            .iter()
            .enumerate()
            .map(|(i, v)| *v * (1.0 + 0.1 * (i % 3) as f32))
            .collect();
        let m = all(100);
        let base = relative_mse(&t, &r, &m);
        assert!(base > 0.0);
        for k in [1e-3f32, 0.5, 4.0, 1e4] {
            let tk: Vec<Vec3> = t.iter().map(|v| *v * k).collect();
            let rk: Vec<Vec3> = r.iter().map(|v| *v * k).collect();
            let v = relative_mse(&tk, &rk, &m);
            assert!((v - base).abs() <= 1e-5 * base, "k = {k}: {v} vs {base}");
        }
        // Black reference: finite and scale-invariant too.
        let black = vec![Vec3::ZERO; 100];
        let v1 = relative_mse(&t, &black, &m);
        let t2: Vec<Vec3> = t.iter().map(|v| *v * 3.0).collect();
        let v2 = relative_mse(&t2, &black, &m);
        assert!(v1.is_finite() && v1 > 0.0);
        assert!((v1 - v2).abs() <= 1e-6 * v1);
    }

    #[test]
    fn metrics_mask_excludes_pixels() {
        let r = vec![Vec3::splat(0.5); 4];
        let mut t = r.clone();
        t[1] = Vec3::splat(1000.0);
        t[3] = Vec3::splat(f32::NAN);
        let m = vec![true, false, true, false];
        assert_eq!(rmse(&t, &r, &m), 0.0);
        assert_eq!(mae(&t, &r, &m), 0.0);
        assert_eq!(relative_mse(&t, &r, &m), 0.0);
        // Pixels 0 and 2 masked in, offset 0.5 at pixel 0 only.
        t[0] = Vec3::splat(1.0);
        assert_eq!(rmse(&t, &r, &m), 0.125f64.sqrt());
        assert_eq!(mae(&t, &r, &m), 0.25);
        // Empty mask, mismatched lengths: 0, no panic.
        assert_eq!(rmse(&t, &r, &[false; 4]), 0.0);
        assert_eq!(relative_mse(&t, &r, &[]), 0.0);
        assert_eq!(mae(&t[..2], &r, &m), 0.5);
    }

    #[test]
    fn metrics_tonemap_srgb() {
        let px = [
            Vec3::new(0.0, 1.0, 0.5),
            Vec3::new(-1.0, 7.0, f32::NAN),
            Vec3::new(0.25, f32::INFINITY, 0.002),
        ];
        let out = tonemap_srgb8(&px, 1.0);
        assert_eq!(out.len(), 9);
        assert_eq!(&out[0..3], &[0, 255, 188]);
        assert_eq!(&out[3..6], &[0, 255, 0]);
        // 0.25 → 0.5371 → 137; 0.002 → 12.92·0.002 = 0.02584 → 7.
        assert_eq!(&out[6..9], &[137, 255, 7]);
        // Exposure scales before the clamp.
        assert_eq!(tonemap_srgb8(&[Vec3::splat(0.25)], 2.0), vec![188; 3]);
        assert!(tonemap_srgb8(&[], 1.0).is_empty());
    }

    /// `w`×`h` RGB8 image of one colour.
    fn flat(w: u32, h: u32, rgb: [u8; 3]) -> Vec<u8> {
        rgb.repeat((w * h) as usize)
    }

    /// A gradient-and-stripes RGB8 test picture.
    fn picture(w: u32, h: u32) -> Vec<u8> {
        let mut v = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let stripe = if (x / 4) % 2 == 0 { 40 } else { 0 };
                v.extend_from_slice(&[
                    (x * 200 / w) as u8 + stripe,
                    (y * 200 / h) as u8,
                    100 + stripe,
                ]);
            }
        }
        v
    }

    #[test]
    fn metrics_flip_identical_is_zero() {
        let a = picture(48, 32);
        let r = flip(&a, &a, [48, 32]).unwrap();
        assert!(r.mean.abs() < 1e-6, "{}", r.mean);
        assert!(r.median.abs() < 1e-6 && r.p95.abs() < 1e-6);
        assert_eq!(r.error_map.len(), 48 * 32);
    }

    #[test]
    fn metrics_flip_black_vs_white_is_large() {
        let black = flat(32, 32, [0, 0, 0]);
        let white = flat(32, 32, [255, 255, 255]);
        let r = flip(&black, &white, [32, 32]).unwrap();
        assert!(r.mean > 0.5, "{}", r.mean);
        assert!(r.median > 0.5 && r.p95 > 0.5);
        // Swapped roles: also works, also large, no panic.
        let s = flip(&white, &black, [32, 32]).unwrap();
        assert!(s.mean > 0.5 && s.mean <= 1.0, "{}", s.mean);
    }

    #[test]
    fn metrics_flip_one_level_is_small() {
        let a = picture(64, 48);
        let b: Vec<u8> = a.iter().map(|v| v + 1).collect();
        let r = flip(&b, &a, [64, 48]).unwrap();
        assert!(r.mean > 0.0 && r.mean < 0.05, "{}", r.mean);
        let g = flat(16, 16, [128, 128, 128]);
        let g1 = flat(16, 16, [129, 129, 129]);
        let r = flip(&g1, &g, [16, 16]).unwrap();
        assert!(r.mean < 0.05, "{}", r.mean);
    }

    #[test]
    fn metrics_flip_not_symmetric_but_sane() {
        let a = picture(40, 30);
        let b: Vec<u8> = a
            .iter()
            .enumerate()
            .map(|(i, v)| if i % 11 == 0 { 255 - v } else { *v })
            .collect();
        let ab = flip(&a, &b, [40, 30]).unwrap();
        let ba = flip(&b, &a, [40, 30]).unwrap();
        for r in [&ab, &ba] {
            assert!(r.mean > 0.0 && r.mean <= 1.0);
            assert!(r.median <= r.p95);
            assert!(r.error_map.iter().all(|e| (0.0..=1.0).contains(e)));
        }
        // Tiny images work too.
        let one = flip(&[1, 2, 3], &[200, 100, 50], [1, 1]).unwrap();
        assert!(one.mean > 0.0 && one.mean <= 1.0);
    }

    #[test]
    fn metrics_flip_mean_matches_flip_pool() {
        let a = picture(40, 30);
        let b: Vec<u8> = a.iter().map(|v| v.saturating_add(30)).collect();
        let r = flip(&b, &a, [40, 30]).unwrap();
        let map = nv_flip::FlipImageFloat::with_data(40, 30, &r.error_map);
        let pool = nv_flip::FlipPool::from_image(&map);
        assert!((pool.mean() as f64 - r.mean).abs() < 1e-5);
        assert!(r.mean > 0.0);
    }

    #[test]
    fn metrics_flip_size_mismatch_is_error() {
        let a = flat(8, 8, [10, 20, 30]);
        let b = flat(8, 7, [10, 20, 30]);
        let e = flip(&a, &b, [8, 8]).unwrap_err();
        let msg = e.to_string();
        assert!(matches!(e, Error::Invalid(_)));
        assert!(
            msg.contains("64 RGB8 pixels") && msg.contains("56 RGB8 pixels"),
            "{msg}"
        );
        assert!(flip(&a, &a, [8, 9]).is_err());
        assert!(flip(&a[..10], &a, [8, 8]).is_err());
        assert!(flip(&[], &[], [0, 0]).is_err());
        assert!(flip(&a, &a, [u32::MAX, u32::MAX]).is_err());
        assert!(flip_masked(&a, &b, [8, 8], &[true; 64]).is_err());
    }

    #[test]
    fn metrics_flip_masked_restricts_statistics() {
        let (w, h) = (32u32, 32u32);
        let a = flat(w, h, [100, 100, 100]);
        let mut b = a.clone();
        // Right half differs.
        for y in 0..h {
            for x in w / 2..w {
                let i = ((y * w + x) * 3) as usize;
                b[i..i + 3].copy_from_slice(&[230, 40, 40]);
            }
        }
        let full = flip(&b, &a, [w, h]).unwrap();
        let right: Vec<bool> = (0..w * h).map(|i| i % w >= w / 2).collect();
        let m = flip_masked(&b, &a, [w, h], &right).unwrap();
        assert_eq!(m.error_map, full.error_map);
        assert!(m.mean > full.mean * 1.5, "{} vs {}", m.mean, full.mean);
        let none = flip_masked(&b, &a, [w, h], &[]).unwrap();
        assert_eq!((none.mean, none.median, none.p95), (0.0, 0.0, 0.0));
    }

    #[test]
    fn metrics_flip_error_png_uses_magma() {
        let a = picture(20, 10);
        let b: Vec<u8> = a.iter().map(|v| v / 2).collect();
        let r = flip(&b, &a, [20, 10]).unwrap();
        let png = flip_error_png(&r, [20, 10]);
        assert_eq!(png.len(), 20 * 10 * 4);
        // Same colours as nv-flip's own LUT application.
        let map = nv_flip::FlipImageFloat::with_data(20, 10, &r.error_map);
        let rgb = map.apply_color_lut(&nv_flip::magma_lut()).to_vec();
        for (p, q) in png.chunks_exact(4).zip(rgb.chunks_exact(3)) {
            assert_eq!(&p[..3], q);
            assert_eq!(p[3], 255);
        }
        // Short or odd error maps never panic.
        let odd = FlipResult {
            mean: 0.0,
            median: 0.0,
            p95: 0.0,
            error_map: vec![f32::NAN, 2.0, -1.0],
        };
        assert_eq!(flip_error_png(&odd, [3, 3]).len(), 36);
    }

    fn fq(frame: u32, temporal: Option<f64>) -> FrameQuality {
        FrameQuality {
            frame,
            rmse: frame as f64,
            rel_mse: 0.1 * frame as f64,
            mae: 0.5 * frame as f64,
            flip_mean: 0.01 * frame as f64,
            bias: -0.01 * frame as f64,
            temporal,
        }
    }

    #[test]
    fn metrics_relative_bias_is_signed() {
        let r = vec![Vec3::ONE; 4];
        let dark = vec![Vec3::splat(0.9); 4];
        let mask = [true, true, true, false];
        assert!((relative_bias(&dark, &r, &mask) + 0.1).abs() < 1e-6);
        assert_eq!(relative_bias(&r, &r, &mask), 0.0);
        assert_eq!(relative_bias(&r, &[Vec3::ZERO; 4], &mask), 0.0);
    }

    #[test]
    fn metrics_summarize_counts_and_temporal() {
        let frames: Vec<FrameQuality> = (0..5).map(|i| fq(i, None)).collect();
        let s = summarize(
            "one-bounce, 256 spp, 8 bounces, seed 1".into(),
            frames.clone(),
        );
        assert_eq!(s.frames, frames);
        assert_eq!(s.rmse.count, 5);
        assert_eq!(s.rel_mse.count, 5);
        assert_eq!(s.mae.count, 5);
        assert_eq!(s.flip_mean.count, 5);
        assert_eq!(s.rmse.mean, 2.0);
        assert_eq!(s.mae.max, 2.0);
        assert!(s.temporal.is_none());
        let json = serde_json::to_string(&s).unwrap();
        assert!(!json.contains("temporal"), "{json}");
        let back: QualitySummary = serde_json::from_str(&json).unwrap();
        assert_eq!(back, s);

        let frames: Vec<FrameQuality> =
            (0..5).map(|i| fq(i, (i > 0).then_some(i as f64))).collect();
        let s = summarize(String::new(), frames);
        let t = s.temporal.unwrap();
        assert_eq!(t.count, 4);
        assert_eq!(t.min, 1.0);
        let json = serde_json::to_string(&s).unwrap();
        let back: QualitySummary = serde_json::from_str(&json).unwrap();
        // serde_json's default float parsing may be off by one ulp.
        assert_eq!(back.frames, s.frames);
        assert_eq!(back.temporal.unwrap().count, 4);
        assert!((back.temporal.unwrap().p95 - t.p95).abs() < 1e-12);
        assert_eq!(summarize(String::new(), vec![]).rmse.count, 0);
    }
}
