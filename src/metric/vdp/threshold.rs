//! The VDP's threshold for a pattern: the contrast at which its detection probability is the
//! observers' criterion ([`THRESHOLD_PROBABILITY`]: 2AFC 84 % correct corrected for guessing,
//! pooled sum S = 1), against a reference image — a uniform field for a detection threshold
//! (ModelFest, castleCSF), a masker for a masking threshold (Foley 1994).
//!
//! The search is a bracketed secant (Illinois) on ln c: S grows about as c^β, so ln S is nearly
//! linear in ln c and a few steps reach |ln S| < 10⁻⁶. The bracket is contrast 10⁻⁶ to 1 (above
//! 100 % is not a stimulus); a pattern that stays invisible at 1, or is already visible at 10⁻⁶,
//! is reported as that bound ([`Threshold::bound`]), never as a measured threshold.

use super::{THRESHOLD_PROBABILITY, Vdp, VdpPrepared};

/// Lowest contrast searched.
pub const MIN_CONTRAST: f64 = 1e-6;
/// Highest contrast searched.
pub const MAX_CONTRAST: f64 = 1.0;

/// Which end of the bracket a threshold stopped at.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Bound {
    /// Not seen even at contrast [`MAX_CONTRAST`]: the threshold is above it.
    AboveMax,
    /// Seen already at [`MAX_CONTRAST`]'s floor [`MIN_CONTRAST`]: the threshold is below it.
    BelowMin,
}

/// A threshold contrast.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Threshold {
    /// The contrast at which S = 1 (or the bracket's end, see `bound`).
    pub contrast: f64,
    /// Set when the search stopped at an end of its bracket.
    pub bound: Option<Bound>,
}

/// The threshold of `test(c)` against `reference` (both `w × h` luminance images in cd/m²).
/// The criterion is [`THRESHOLD_PROBABILITY`].
pub fn threshold(vdp: &Vdp, reference: &VdpPrepared, test: impl Fn(f64) -> Vec<f32>) -> Threshold {
    let (w, h) = (reference.width, reference.height);
    let f = |ln_c: f64| {
        let prepared = vdp.prepare_luminance(w, h, test(ln_c.exp()));
        let score = vdp
            .compare_prepared(reference, &prepared)
            .expect("the test image has the reference's size");
        score.jnd.powf(vdp.params().beta).max(1e-300).ln()
    };
    debug_assert!((super::psychometric::probability(1.0) - THRESHOLD_PROBABILITY).abs() < 1e-9);
    let (mut a, mut b) = (MIN_CONTRAST.ln(), MAX_CONTRAST.ln());
    let (mut fa, mut fb) = (f(a), f(b));
    if fb < 0.0 {
        return Threshold {
            contrast: MAX_CONTRAST,
            bound: Some(Bound::AboveMax),
        };
    }
    if fa > 0.0 {
        return Threshold {
            contrast: MIN_CONTRAST,
            bound: Some(Bound::BelowMin),
        };
    }
    // Illinois false position: the side that stays keeps half its weight.
    let mut side = 0i8;
    let mut found = None;
    for _ in 0..60 {
        let c = (a * fb - b * fa) / (fb - fa);
        let fc = f(c);
        if fc.abs() < 1e-6 || (b - a).abs() < 1e-9 {
            found = Some(c);
            break;
        }
        if fc < 0.0 {
            (a, fa) = (c, fc);
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        } else {
            (b, fb) = (c, fc);
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        }
    }
    Threshold {
        contrast: found.unwrap_or(0.5 * (a + b)).exp(),
        bound: None,
    }
}
