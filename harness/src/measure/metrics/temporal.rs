//! Temporal stability (flicker): a technique's frame-to-frame change against the reference's
//! ([`temporal_instability`], [`relative_temporal_instability`]), and the reference's own
//! floor of it ([`flicker_floor`]). The conventions on lengths and empty masks are the parent
//! module's.

use glam::Vec3;

/// Temporal instability (flicker) of a technique between two consecutive frames, relative to
/// the reference's own change:
///
/// ```text
/// sqrt(mean over masked pixels p and channels c of
///      ((t_cur − t_prev) − (r_cur − r_prev))²)
/// ```
///
/// i.e. the RMSE of the technique's frame-to-frame change against the reference's
/// frame-to-frame change. Genuine changes (moving light or objects) appear in both and cancel;
/// what remains is change the technique makes that it should not (flicker, popping, VPLs jumping
/// around), plus change it fails to make (lag). Same units as the images.
///
/// This is the measure that checks Laine et al. 2007's claim that incremental instant radiosity
/// flickers less than recomputing all VPLs every frame, and the imperfect-shadow-maps paper's
/// claim of temporally coherent ("no flicker") indirect light: a technique that is temporally
/// stable scores close to the reference's own value.
///
/// `mask` must select the pixels that are valid in *both* frames (the caller ANDs the two hit
/// masks; a pixel that is background in either frame is not comparable). Conventions on lengths
/// and empty masks are the module's. Note that Monte Carlo noise in the reference that differs
/// between the frames adds to the value (variances add); render the reference with a per-frame
/// fixed seed, or with enough samples that this floor is negligible.
pub fn temporal_instability(
    test_prev: &[Vec3],
    test_cur: &[Vec3],
    ref_prev: &[Vec3],
    ref_cur: &[Vec3],
    mask: &[bool],
) -> f64 {
    let (sum, n) = temporal_sums(
        test_prev,
        test_cur,
        ref_prev,
        ref_cur,
        mask,
        |tp, tc, rp, rc| {
            let d = (tc - tp) - (rc - rp);
            d * d
        },
    );
    if n == 0 {
        0.0
    } else {
        (sum / n as f64).sqrt()
    }
}

/// The reference's own flicker floor: the RMS of its frame-to-frame change that is Monte Carlo
/// noise, which [`temporal_instability`] counts against every technique (its note). Estimated
/// from the same two frames rendered with two seeds (`r0_*`, the reference compared with, and
/// `r1_*`, another seed): their changes' noise parts are independent with the same variance, so
/// the RMS of the difference of the changes is √2 times the floor. A technique that matched the
/// noiseless truth would score about this; a flicker at or below it is at the floor.
pub fn flicker_floor(
    r1_prev: &[Vec3],
    r1_cur: &[Vec3],
    r0_prev: &[Vec3],
    r0_cur: &[Vec3],
    mask: &[bool],
) -> f64 {
    temporal_instability(r1_prev, r1_cur, r0_prev, r0_cur, mask) / std::f64::consts::SQRT_2
}

/// [`temporal_instability`] divided by the RMS of the reference's values in the two frames,
/// `sqrt(mean over masked p, c of (r_prev² + r_cur²) / 2)`, so that it is dimensionless and
/// comparable across scenes, light powers and exposures (scaling all four images by `k > 0`
/// leaves it unchanged). A value of 0.05 means the unexplained frame-to-frame change is 5 % of
/// the typical reference value.
///
/// If the reference is black over the whole mask, the RMS of the test's values in the two frames
/// is used instead (so the value stays finite); 0 when that is 0 too or no pixel is masked in.
pub fn relative_temporal_instability(
    test_prev: &[Vec3],
    test_cur: &[Vec3],
    ref_prev: &[Vec3],
    ref_cur: &[Vec3],
    mask: &[bool],
) -> f64 {
    let abs = temporal_instability(test_prev, test_cur, ref_prev, ref_cur, mask);
    if abs == 0.0 {
        return 0.0;
    }
    let rms = |prev: &[Vec3], cur: &[Vec3]| {
        let (sum, n) = temporal_sums(test_prev, test_cur, prev, cur, mask, |_, _, p, c| {
            (p * p + c * c) / 2.0
        });
        if n == 0 {
            0.0
        } else {
            (sum / n as f64).sqrt()
        }
    };
    let mut norm = rms(ref_prev, ref_cur);
    if norm == 0.0 {
        norm = rms(test_prev, test_cur);
    }
    if norm == 0.0 {
        0.0
    } else {
        abs / norm
    }
}

/// Sum over the masked pixels (pixels present in all four images and the mask) and channels of
/// `g(t_prev, t_cur, r_prev, r_cur)`, and the number of terms.
fn temporal_sums(
    test_prev: &[Vec3],
    test_cur: &[Vec3],
    ref_prev: &[Vec3],
    ref_cur: &[Vec3],
    mask: &[bool],
    g: impl Fn(f64, f64, f64, f64) -> f64,
) -> (f64, usize) {
    let mut sum = 0.0f64;
    let mut n = 0usize;
    let it = test_prev
        .iter()
        .zip(test_cur)
        .zip(ref_prev.iter().zip(ref_cur))
        .zip(mask);
    for (((tp, tc), (rp, rc)), m) in it {
        if !*m {
            continue;
        }
        for c in 0..3 {
            sum += g(tp[c] as f64, tc[c] as f64, rp[c] as f64, rc[c] as f64);
        }
        n += 3;
    }
    (sum, n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::metrics::tests::{all, image};

    /// Two renderings of the same two frames whose noise is independent between seeds and
    /// frames, of known size (±0.03 in the first frame and ±0.04 in the second, per channel,
    /// uniform): the floor is the RMS of one rendering's change's noise, sqrt((0.03² + 0.04²) / 3)
    /// ≈ 0.0289 (uniform ±a has variance a²/3), and it equals that measured on the first
    /// rendering alone, within the sampling error of 30k terms (2 %). Catches the √2 left out (41 % high) and a floor taken
    /// from one seed against itself (0).
    #[test]
    fn the_flicker_floor_is_one_renderings_noise_change() {
        let n = 10_000;
        let truth = image(n);
        let mut state = 12345u64;
        let mut noise = |a: f32| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let u = (state >> 40) as f32 / (1u64 << 24) as f32;
            a * (2.0 * u - 1.0)
        };
        let mut render = |a: f32| -> Vec<Vec3> {
            truth
                .iter()
                .map(|t| *t + Vec3::new(noise(a), noise(a), noise(a)))
                .collect()
        };
        let (r0p, r0c, r1p, r1c) = (render(0.03), render(0.04), render(0.03), render(0.04));
        let mask = all(n);
        let floor = flicker_floor(&r1p, &r1c, &r0p, &r0c, &mask);
        let model = ((0.03f64.powi(2) + 0.04f64.powi(2)) / 3.0).sqrt();
        let measured = temporal_instability(&truth, &truth, &r0p, &r0c, &mask);
        assert!(
            (floor - model).abs() < 0.02 * model,
            "{floor} against {model}"
        );
        assert!(
            (floor - measured).abs() < 0.02 * measured,
            "{floor} against {measured}"
        );
        assert_eq!(flicker_floor(&r0p, &r0c, &r0p, &r0c, &mask), 0.0);
    }

    #[test]
    fn metrics_temporal_instability() {
        let n = 30;
        let m = all(n);
        let t = image(n);
        let r_prev = image(n);
        let d = 0.125f32;
        let r_cur: Vec<Vec3> = r_prev.iter().map(|v| *v + Vec3::splat(d)).collect();
        // Static technique, reference changes by d → d.
        let v = temporal_instability(&t, &t, &r_prev, &r_cur, &m);
        assert!((v - d as f64).abs() < 1e-6, "{v}");
        // Identical changes → 0.
        assert_eq!(
            temporal_instability(&r_prev, &r_cur, &r_prev, &r_cur, &m),
            0.0
        );
        // Same change on a biased image → 0 up to f32 rounding of the inputs.
        let t_prev: Vec<Vec3> = r_prev.iter().map(|v| *v * 0.5).collect();
        let t_cur: Vec<Vec3> = t_prev.iter().map(|v| *v + Vec3::splat(d)).collect();
        assert!(temporal_instability(&t_prev, &t_cur, &r_prev, &r_cur, &m) < 1e-6);
        let (t_prev, t_cur) = (r_prev.clone(), r_cur.clone());
        assert_eq!(
            temporal_instability(&t_prev, &t_cur, &r_prev, &r_cur, &m),
            0.0
        );
        assert_eq!(
            relative_temporal_instability(&t_prev, &t_cur, &r_prev, &r_cur, &m),
            0.0
        );
        // Masked-out pixels don't count.
        let mut t_flicker = t_cur.clone();
        t_flicker[0] = Vec3::splat(99.0);
        let mut m0 = m.clone();
        m0[0] = false;
        assert_eq!(
            temporal_instability(&t_prev, &t_flicker, &r_prev, &r_cur, &m0),
            0.0
        );
        assert!(temporal_instability(&t_prev, &t_flicker, &r_prev, &r_cur, &m) > 1.0);
    }

    #[test]
    fn metrics_relative_temporal_instability_normalised() {
        let n = 20;
        let m = all(n);
        let r = vec![Vec3::splat(2.0); n];
        let t_prev = r.clone();
        let t_cur: Vec<Vec3> = r.iter().map(|v| *v + Vec3::splat(0.5)).collect();
        // Static reference of RMS 2, technique jumps by 0.5 → 0.25.
        let v = relative_temporal_instability(&t_prev, &t_cur, &r, &r, &m);
        assert!((v - 0.25).abs() < 1e-12, "{v}");
        // Scale-invariant.
        let s = |x: &[Vec3]| x.iter().map(|v| *v * 7.0).collect::<Vec<_>>();
        let v7 = relative_temporal_instability(&s(&t_prev), &s(&t_cur), &s(&r), &s(&r), &m);
        assert!((v7 - v).abs() < 1e-9);
        // Black reference: finite.
        let black = vec![Vec3::ZERO; n];
        let vb = relative_temporal_instability(&t_prev, &t_cur, &black, &black, &m);
        assert!(vb.is_finite() && vb > 0.0);
        assert_eq!(
            relative_temporal_instability(&t_prev, &t_cur, &r, &r, &[]),
            0.0
        );
    }
}
