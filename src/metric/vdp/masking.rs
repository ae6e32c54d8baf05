//! Stage 5 of the VDP: visual masking — how much a signal already in the image raises the
//! threshold for seeing a change.
//!
//! Based on: Scott Daly. The Visible Differences Predictor. 1993 — threshold elevation
//! T_e = (1 + (k1·(k2·m)^s)^b)^(1/b) with b = 4 and learning slope s between 0.65 and 1; and his
//! *mutual* masking, where the masker is the smaller of the two images' band contrasts, so a
//! difference cannot mask itself. Gordon Legge, John Foley. Contrast Masking in Human Vision.
//! JOSA 1980 — the slope of about 0.7 above threshold for similar frequency and orientation.
//!
//! Band contrasts arrive CSF-weighted (`filter.rs`): one unit is one threshold contrast, which is
//! the normalisation k1·k2^s = 1 of Daly's form, leaving T_e = (1 + m^(s·b))^(1/b) with s = 0.7,
//! b = 4: no elevation far below threshold, a slope of 0.7 far above it. Masking is phase
//! insensitive, so the masker magnitude is |band| averaged over a 3×3 neighbourhood of the band's
//! samples. ModelFest cannot calibrate this stage (its stimuli are shown on a uniform field, where
//! the masker is 0); its constants are the published ones.

/// Masking slope s (Legge & Foley 1980; Daly 1993).
pub const SLOPE: f32 = 0.7;
/// Daly's transition exponent b.
const B: f32 = 4.0;

/// Threshold elevation for a masker of `m` JND (≥ 1; 1 means no masking).
pub fn threshold_elevation(m: f32) -> f32 {
    let m = m.abs();
    // At or below this masker m^(s·b) < 2^-24, so 1 + m^(s·b) rounds to 1 and the formula gives
    // exactly 1 (tested): most of a flat background, without the two powers.
    if m <= NO_ELEVATION {
        return 1.0;
    }
    (1.0 + m.powf(SLOPE * B)).powf(1.0 / B)
}

/// The largest masker [`threshold_elevation`] takes as no masking at all: 0.002^2.8 ≈ 2.8e-8 <
/// 2^-24 ≈ 6.0e-8.
const NO_ELEVATION: f32 = 0.002;

/// 3×3 mean of |v| (phase-insensitive masker magnitude), borders clamped.
pub(crate) fn local_magnitude(v: &[f32], w: usize, h: usize) -> Vec<f32> {
    use rayon::prelude::*;
    // Horizontal 3-sums of |v|, then vertical 3-sums of those.
    let mut row3 = vec![0.0f32; w * h];
    row3.par_chunks_mut(w).enumerate().for_each(|(y, out)| {
        let r = &v[y * w..(y + 1) * w];
        for (x, o) in out.iter_mut().enumerate() {
            let (a, c) = (x.saturating_sub(1), (x + 1).min(w - 1));
            *o = r[a].abs() + r[x].abs() + r[c].abs();
        }
    });
    let mut out = vec![0.0f32; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, o)| {
        let (a, c) = (y.saturating_sub(1), (y + 1).min(h - 1));
        let (ra, rb, rc) = (
            &row3[a * w..][..w],
            &row3[y * w..][..w],
            &row3[c * w..][..w],
        );
        for x in 0..w {
            o[x] = (ra[x] + rb[x] + rc[x]) * (1.0 / 9.0);
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shortcut_gives_what_the_formula_gives() {
        let formula = |m: f32| (1.0 + m.abs().powf(SLOPE * B)).powf(1.0 / B);
        // Every float from 0 to just past the shortcut's bound, in steps of 97 ulps, and the
        // bound's neighbours.
        let top = (NO_ELEVATION * 1.01).to_bits();
        for bits in (0..top).step_by(97).chain(NO_ELEVATION.to_bits() - 8..top) {
            let m = f32::from_bits(bits);
            assert_eq!(threshold_elevation(m), formula(m), "{m}");
            assert_eq!(threshold_elevation(-m), formula(-m), "{m}");
        }
        assert!(threshold_elevation(f32::NAN).is_nan());
    }

    #[test]
    fn elevation_is_one_below_threshold_and_follows_the_slope_above() {
        assert!((threshold_elevation(0.0) - 1.0).abs() < 1e-6);
        // A masker at a fifth of threshold: (1 + 0.2^2.8)^(1/4) = 1.0027, under 0.5 % elevation.
        assert!((threshold_elevation(0.2) - 1.0).abs() < 5e-3);
        // Far above threshold T_e ≈ m^0.7: a 100-JND masker raises the threshold about 25×.
        let t = threshold_elevation(100.0);
        assert!((t / 100f32.powf(SLOPE) - 1.0).abs() < 1e-3, "{t}");
    }
}
