//! Stage 5 of the VDP: from normalised differences to detection probabilities.
//!
//! Based on: Scott Daly 1993 — the Weibull psychometric function P(d) = 1 − exp(−|d|^β) with
//! β = 3.5, d the difference in threshold units; and probability summation over channels and
//! locations, which for this function is 1 − exp(−Σ|d|^β): the Minkowski sum of the differences
//! with exponent β, turned into a probability. The pooled JND score is that Minkowski sum, so
//! P = 1 − exp(−JND^β): 1 JND means a 63 % chance of detection, P = 0.5 at JND = (ln 2)^(1/β) ≈ 0.90.

/// Psychometric slope β.
pub const BETA: f32 = 3.5;

/// Detection probability of a summed |d|^β.
pub fn probability(sum_d_beta: f64) -> f64 {
    1.0 - (-sum_d_beta).exp()
}

/// JND score of a summed |d|^β.
pub fn jnd(sum_d_beta: f64) -> f64 {
    sum_d_beta.powf(1.0 / BETA as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_jnd_is_63_percent() {
        assert!((probability(1.0) - (1.0 - (-1.0f64).exp())).abs() < 1e-12);
        assert!((jnd(2f64.ln()) - 2f64.ln().powf(1.0 / 3.5)).abs() < 1e-12);
        assert!((probability(jnd(2f64.ln()).powf(3.5)) - 0.5).abs() < 1e-12);
    }
}
