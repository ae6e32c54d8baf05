//! Stage 7 of the VDP: from the pooled difference to a detection probability.
//!
//! Based on: Scott Daly 1993 and John Robson, Norma Graham. Probability summation and regional
//! variation in contrast sensitivity across the visual field. Vision Research 21 1981 — the
//! Weibull psychometric function, and probability summation over independent detectors, which for
//! that function is 1 − exp(−Σ|d|^β): the Minkowski sum of the differences with exponent β
//! (`pooling.rs`), turned into a probability.
//!
//! The JND scale is anchored on the observers: ModelFest's thresholds are the 84 %-correct points
//! of a two-interval forced choice (its methods page), which after the correction for guessing,
//! P_c = ½ + ½·P_det, is a detection probability of 0.68. The pooled sum S is scaled (by the
//! fitted CSF peak) so that S = 1 there: **1 JND is the observers' detection threshold**, and
//! P_det = 1 − exp(−k·J^β) with J = S^(1/β) and k = −ln(1 − 0.68) = 1.139. So P_det = 0.5 at
//! J = (ln 2 / k)^(1/β) ≈ 0.84 JND, and 0.95 at ≈ 1.4 JND.

/// Detection probability at the observers' threshold: 2AFC 84 % correct, corrected for guessing.
pub const THRESHOLD_PROBABILITY: f64 = 0.68;

/// k in P = 1 − exp(−k·S): −ln(1 − [`THRESHOLD_PROBABILITY`]).
fn k() -> f64 {
    -(1.0 - THRESHOLD_PROBABILITY).ln()
}

/// Detection probability of a pooled sum S = J^β (S = 1 at threshold).
pub fn probability(sum: f64) -> f64 {
    1.0 - (-k() * sum.max(0.0)).exp()
}

/// JND of a pooled sum S with exponent `beta`.
pub fn jnd(sum: f64, beta: f64) -> f64 {
    sum.max(0.0).powf(1.0 / beta)
}

/// The pooled sum S at which the detection probability is `p` (in (0, 1)).
pub fn sum_for_probability(p: f64) -> f64 {
    -(1.0 - p).ln() / k()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_jnd_is_the_observers_threshold() {
        // S = 1 is 2AFC 84 % correct: P_det = 0.68, P_c = 0.5 + 0.5 · 0.68 = 0.84.
        assert!((probability(1.0) - 0.68).abs() < 1e-12);
        assert!((0.5 + 0.5 * probability(1.0) - 0.84).abs() < 1e-12);
        assert!((probability(sum_for_probability(0.5)) - 0.5).abs() < 1e-12);
        assert_eq!(probability(0.0), 0.0);
        assert!((jnd(8.0, 3.0) - 2.0).abs() < 1e-12);
    }
}
