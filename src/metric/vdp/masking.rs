//! Stage 4 of the VDP: visual masking — how much a signal already in the image raises the
//! threshold for seeing a change.
//!
//! Based on: Scott Daly. The Visible Differences Predictor. 1993 — threshold elevation
//! T_e = (1 + (k1·(k2·m)^s)^b)^(1/b) with b = 4 and learning slope s between 0.65 and 1; and his
//! *mutual* masking, where the masker is the smaller of the two images' band contrasts, so a
//! difference cannot mask itself. Gordon Legge, John Foley. Contrast Masking in Human Vision.
//! JOSA 1980 — the slope of about 0.7 above threshold for similar frequency and orientation.
//!
//! Here band contrasts are already CSF-weighted and in JND units (1 = detection threshold), which is
//! exactly the normalisation k1·k2^s = 1 of Daly's form, leaving T_e = (1 + m^(s·b))^(1/b) with
//! s = 0.7, b = 4: no elevation far below threshold, a slope of 0.7 far above it. Masking is phase
//! insensitive, so the masker magnitude is averaged over a 3×3 neighbourhood of the band.

/// Masking slope s (Legge & Foley 1980; Daly 1993).
pub const SLOPE: f32 = 0.7;
/// Daly's transition exponent b.
const B: f32 = 4.0;

/// Threshold elevation for a masker of `m` JND (≥ 1; 1 means no masking).
pub fn threshold_elevation(m: f32) -> f32 {
    (1.0 + m.abs().powf(SLOPE * B)).powf(1.0 / B)
}

/// 3×3 mean of |v| (phase-insensitive masker magnitude), mirrored borders.
pub(crate) fn local_magnitude(v: &[f32], w: usize, h: usize) -> Vec<f32> {
    (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as isize, (i / w) as isize);
            let mut s = 0.0;
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let xx = (x + dx).clamp(0, w as isize - 1) as usize;
                    let yy = (y + dy).clamp(0, h as isize - 1) as usize;
                    s += v[yy * w + xx].abs();
                }
            }
            s / 9.0
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

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
