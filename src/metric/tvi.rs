//! Threshold versus intensity: the smallest luminance step a person sees on a uniform field of
//! adaptation luminance L_a, for the cone and the rod system.
//!
//! Based on: James Ferwerda, Sumanta Pattanaik, Peter Shirley, Donald Greenberg. A Model of Visual
//! Adaptation for Realistic Image Synthesis. SIGGRAPH 1996, §4 (the piecewise fits to Blackwell's
//! and Aguilar & Stiles' data, in log10 cd/m²):
//!
//! cones: log t_p = −0.72 (log L_a ≤ −2.6); log L_a − 1.255 (log L_a ≥ 1.9);
//!        (0.249·log L_a + 0.65)^2.7 − 0.72 between.
//! rods:  log t_s = −2.86 (log L_a ≤ −3.94); log L_a − 0.395 (log L_a ≥ −1.44);
//!        (0.405·log L_a + 1.6)^2.18 − 2.86 between.
//!
//! The threshold a person has is the lower of the two (rods in the dark, cones on any display).
//! Qu & Meyer (§4.2) use it for the luminance half of their masking map: a brighter region hides a
//! larger absolute change.

/// Cone threshold t_p (cd/m²) at adaptation luminance `la` (cd/m²).
pub fn cone_threshold(la: f64) -> f64 {
    let x = la.max(1e-12).log10();
    let log_t = if x <= -2.6 {
        -0.72
    } else if x >= 1.9 {
        x - 1.255
    } else {
        (0.249 * x + 0.65).powf(2.7) - 0.72
    };
    10f64.powf(log_t)
}

/// Rod threshold t_s (cd/m²) at adaptation luminance `la` (cd/m²).
pub fn rod_threshold(la: f64) -> f64 {
    let x = la.max(1e-12).log10();
    let log_t = if x <= -3.94 {
        -2.86
    } else if x >= -1.44 {
        x - 0.395
    } else {
        (0.405 * x + 1.6).powf(2.18) - 2.86
    };
    10f64.powf(log_t)
}

/// The visible threshold (cd/m²) at adaptation luminance `la`: the lower of the two systems'.
pub fn threshold(la: f64) -> f64 {
    cone_threshold(la).min(rod_threshold(la))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pieces_meet_and_follow_weber_in_the_light() {
        // Continuity at every breakpoint: the published fits join within 3 % (the rods' upper
        // breakpoint is the widest, 2.8 %).
        for (f, x) in [
            (cone_threshold as fn(f64) -> f64, -2.6),
            (cone_threshold, 1.9),
            (rod_threshold, -3.94),
            (rod_threshold, -1.44),
        ] {
            let below = f(10f64.powf(x - 1e-9));
            let above = f(10f64.powf(x + 1e-9));
            assert!((below / above - 1.0).abs() < 0.03, "{x}: {below} {above}");
        }
        // Photopic: Weber's law with the fraction 10^−1.255 ≈ 0.056.
        for la in [100.0, 1000.0] {
            assert!((cone_threshold(la) / la - 0.0556).abs() < 0.001);
            assert_eq!(threshold(la), cone_threshold(la));
        }
        // Scotopic: the rods see far less than the cones' absolute floor.
        assert!(threshold(1e-3) < 0.01 && cone_threshold(1e-3) > 0.15);
        // Monotonic over the whole range.
        let mut last = 0.0;
        for i in -60..=40 {
            let t = threshold(10f64.powf(i as f64 / 10.0));
            assert!(t >= last);
            last = t;
        }
    }
}
