//! Stage 4 of the VDP: local luminance adaptation — each band's sensitivity at the luminance the
//! eye is adapted to there, not at the filter's reference luminance.
//!
//! Based on: Rafał Mantiuk et al. HDR-VDP-2. ACM TOG 30(4) 2011, §4 (the CSF applied per band at
//! the local adaptation luminance taken from the Gaussian pyramid); Scott Daly 1993 (the CSF's
//! luminance dependence, [`DalyCsf`]).
//!
//! The CSF filter (`filter.rs`) weights every frequency by S(ρ, L_ref). Band k, centred on ρ_k,
//! is then multiplied per sample by g_k(L_a) = S(ρ_k, L_a) / S(ρ_k, L_ref), L_a the luminance of
//! the Gaussian pyramid one level coarser than the band (the local mean the band's contrast sits
//! on). In the dark g < 1, most at high frequencies (de Vries–Rose behaviour, the CSF's peak
//! moving to lower frequencies); above a few tens of cd/m² g ≈ 1 (Weber's law). At L_ref the
//! correction is exactly 1, so ModelFest (30 cd/m², the reference) calibrates the filter alone.
//! g_k is tabulated over ln L_a from [`L_MIN`] to [`L_MAX`] cd/m² and interpolated linearly.
//!
//! Daly's CSF keeps Weber's law however bright the background (it even gains at high frequencies),
//! but observers lose sensitivity above a few thousand cd/m²: castleCSF's hdr_csf data (Gabors on
//! 0.02 to 10 000 cd/m²) sat 5 dB above the model at 7 000–10 000 cd/m² relative to its own mean.
//! [`HighLuminanceLoss`] multiplies sensitivity by 1/(1 + (L/L_knee)^n), normalised to 1 at the
//! reference; its two constants are fitted on the castleCSF subset (`fitted.rs`). The form is ours:
//! castleCSF's own peak-sensitivity term (Ashraf et al. 2024, after stelaCSF) also falls above a
//! high-luminance knee, which is the fact taken from it.

use super::bands::Plane;
use crate::metric::csf::DalyCsf;
use crate::metric::runs::map_runs;

/// Lowest tabulated adaptation luminance, cd/m² (darker is clamped to it).
pub const L_MIN: f64 = 1e-3;
/// Highest tabulated adaptation luminance, cd/m².
pub const L_MAX: f64 = 1e5;
const TABLE: usize = 512;

/// Sensitivity lost on very bright backgrounds: a factor 1/(1 + (L/`knee_cd_m2`)^`exponent`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HighLuminanceLoss {
    /// The luminance, cd/m², at which sensitivity is halved.
    pub knee_cd_m2: f64,
    /// How steeply it falls beyond the knee (sensitivity ∝ L^−exponent far above it).
    pub exponent: f64,
}

impl HighLuminanceLoss {
    /// The factor at `l` cd/m².
    pub fn factor(&self, l: f64) -> f64 {
        1.0 / (1.0 + (l / self.knee_cd_m2).powf(self.exponent))
    }
}

/// g_k over ln L_a for one band.
#[derive(Debug, Clone)]
pub(crate) struct BandAdaptation {
    table: Vec<f32>,
}

impl BandAdaptation {
    /// The correction for a band centred on `rho` cycles per degree, from `l_ref` cd/m², with
    /// `loss` (if any) on bright backgrounds.
    pub(crate) fn new(
        csf: &DalyCsf,
        rho: f64,
        l_ref: f64,
        loss: Option<HighLuminanceLoss>,
    ) -> BandAdaptation {
        let loss_at = |l: f64| loss.map_or(1.0, |h| h.factor(l));
        let at_ref = csf.sensitivity(rho, 1.0, l_ref) * loss_at(l_ref);
        let table = (0..TABLE)
            .map(|i| {
                let l = (L_MIN.ln() + (L_MAX / L_MIN).ln() * i as f64 / (TABLE - 1) as f64).exp();
                if at_ref > 0.0 {
                    (csf.sensitivity(rho, 1.0, l) * loss_at(l) / at_ref) as f32
                } else {
                    1.0
                }
            })
            .collect();
        BandAdaptation { table }
    }

    /// g at adaptation luminance `l` cd/m².
    pub(crate) fn gain(&self, l: f32) -> f32 {
        let lo = L_MIN.ln() as f32;
        let span = (L_MAX / L_MIN).ln() as f32;
        let t = ((l.max(L_MIN as f32).ln() - lo) / span * (TABLE - 1) as f32)
            .clamp(0.0, (TABLE - 1) as f32);
        let i = (t as usize).min(TABLE - 2);
        let u = t - i as f32;
        self.table[i] * (1.0 - u) + self.table[i + 1] * u
    }

    /// Multiply every sample of `band` by g at the luminance of `adapt`, a plane at half the
    /// band's resolution (nearest coarse sample).
    pub(crate) fn apply(&self, band: &mut Plane, adapt: &Plane) {
        use rayon::prelude::*;
        let (w, aw, ah) = (band.w, adapt.w, adapt.h);
        // The gain of every coarse sample once (each serves up to four band samples); a run of
        // equal luminances (a flat background) takes one logarithm.
        let gains: Vec<f32> = adapt
            .v
            .par_chunks(aw)
            .flat_map_iter(|row| map_runs(row.iter().copied(), |l| self.gain(l)))
            .collect();
        band.v.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            let grow = &gains[(y / 2).min(ah - 1) * aw..][..aw];
            for (x, v) in row.iter_mut().enumerate() {
                *v *= grow[(x / 2).min(aw - 1)];
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn correction_is_one_at_the_reference_and_below_one_in_the_dark() {
        let csf = DalyCsf::published();
        for rho in [0.5, 4.0, 24.0] {
            let a = BandAdaptation::new(&csf, rho, 30.0, None);
            assert!((a.gain(30.0) - 1.0).abs() < 2e-3, "{rho}: {}", a.gain(30.0));
            assert!(a.gain(0.5) < a.gain(5.0) && a.gain(5.0) < a.gain(30.0));
            // Near Weber's law above the reference at low and middle frequencies: from 30 to
            // 1000 cd/m² Daly's CSF gains at most 40 % there (26 % at 4 cpd, as his peak moves
            // up), where the square-root law of the dark would give 5.8×. High frequencies keep
            // gaining (the acuity limit rises with luminance): 2.1× at 24 cpd.
            let brighter = a.gain(1000.0) / a.gain(30.0);
            let limit = if rho <= 4.0 { 1.4 } else { 2.5 };
            assert!((1.0..limit).contains(&brighter), "{rho}: {brighter}");
        }
        // The dark costs high frequencies more than low ones.
        let (lo, hi) = (
            BandAdaptation::new(&csf, 1.0, 30.0, None),
            BandAdaptation::new(&csf, 24.0, 30.0, None),
        );
        assert!(hi.gain(0.5) < lo.gain(0.5));
    }
}
