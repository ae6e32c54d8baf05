//! §4.4: visual masking — the detection threshold t_d of a difference given the signal already
//! there: local masking from the point's own coefficients, global masking from renders of the
//! whole model (`global.rs`), combined as a_m = max(a_g(f), min(a₁, a₂)) and turned into t_d by
//! Daly's masking function.
//!
//! Based on: Menzel & Guthe 2010, §4.4; Scott Daly. The Visible Differences Predictor. 1993 — the
//! threshold elevation T_e = (1 + (k₁·(k₂·m)^s)^b)^(1/b) with b = 4 and slope s = 0.7 (Legge &
//! Foley 1980), the masker m in threshold units (here: its amplitude in JND times the CSF at its
//! frequency, the normalisation k₁·k₂^s = 1 the VDP uses, `metric::vdp::masking`); "the highest
//! masker contrast determines the level of masking", so the masker is the larger of the global
//! masker and the smaller of the two signals (a difference cannot mask itself: Daly's mutual
//! masking).
//!
//! Decision: "facilitation allowed". Daly's function is never below 1, so with it t_d ≥ 1: there is
//! no dip to allow. The threshold is used as the function gives it (not clamped), so a masking
//! function with a facilitation dip would lower t_d below 1 unchanged.

use crate::metric::vdp::masking::SLOPE;

/// Daly's transition exponent b.
const B: f64 = 4.0;

/// The masking function.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Masking {
    /// Whether masking is on (off: t_d = 1 always, the unmasked threshold).
    on: bool,
}

impl Masking {
    /// Daly's masking function (the paper's).
    pub fn daly() -> Masking {
        Masking { on: true }
    }

    /// No masking: t_d = 1.
    pub fn none() -> Masking {
        Masking { on: false }
    }

    /// Whether masking is on.
    pub fn is_on(&self) -> bool {
        self.on
    }

    /// T_e(x) and dT_e/dx for a masker of `x` threshold units.
    #[inline]
    pub fn elevation(&self, x: f64) -> (f64, f64) {
        if !self.on || x <= 0.0 {
            return (1.0, 0.0);
        }
        let e = SLOPE as f64 * B;
        let xe = x.powf(e);
        let base = 1.0 + xe;
        let te = base.powf(1.0 / B);
        // d/dx (1 + x^e)^(1/b) = (1/b)·(1 + x^e)^(1/b − 1)·e·x^(e − 1)
        let dte = te / base / B * e * xe / x;
        (te, dte)
    }
}

impl Masking {
    /// The least contrast sensitivity C at which a difference of `delta` JND against a masker of
    /// `m` JND can be visible: the threshold is at least 1 and at least (m·C)^s (s = 0.7), so
    /// δ·C ≥ t_d needs C ≥ 1/δ and C ≥ (m^s/δ)^(1/(1−s)). A cheap bound before the Newton
    /// iteration.
    pub fn least_sensitivity(&self, delta: f64, m: f64) -> f64 {
        self.ln_least_sensitivity(delta.ln(), m).exp()
    }

    /// ln of [`Masking::least_sensitivity`], from ln δ (two logarithms, no power).
    pub fn ln_least_sensitivity(&self, ln_delta: f64, m: f64) -> f64 {
        let unmasked = -ln_delta;
        if !self.on || m <= 0.0 {
            return unmasked;
        }
        let s = SLOPE as f64;
        unmasked.max((s * m.ln() - ln_delta) / (1.0 - s))
    }
}

/// The masker amplitude a_m of a slot: the global masker at the slot's frequency against the
/// smaller of the two signals' amplitudes.
#[inline]
pub fn masker(global: f32, a1: f32, a2: f32) -> f32 {
    global.max(a1.min(a2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_elevation_matches_the_vdp_and_its_derivative() {
        let m = Masking::daly();
        for x in [0.1f64, 1.0, 7.0, 100.0] {
            let (te, dte) = m.elevation(x);
            let vdp = crate::metric::vdp::masking::threshold_elevation(x as f32) as f64;
            assert!((te - vdp).abs() < 1e-4 * vdp, "{x}");
            let h = 1e-6 * x;
            let numeric = (m.elevation(x + h).0 - m.elevation(x - h).0) / (2.0 * h);
            assert!(
                (dte - numeric).abs() < 1e-5 * numeric.abs().max(1e-3),
                "{x}"
            );
        }
        assert_eq!(Masking::none().elevation(50.0), (1.0, 0.0));
        assert_eq!(masker(0.0, 3.0, 2.0), 2.0);
        assert_eq!(masker(5.0, 3.0, 2.0), 5.0);
    }
}
