//! The VDP's fitted constants: the only numbers in the model that were not taken from a paper.
//! They are compiled in: nothing is fitted at run time. `lodeval calibrate all` checks them.
//!
//! Three sets of human thresholds, fitted jointly in the one way each can constrain:
//! - **ModelFest** (Carney et al. 1999; Watson & Ahumada 2005; 43 stimuli at 30 cd/m², the mean of
//!   16 observers, `reference/oracles/modelfest/`) fixes the CSF's shape and scale: Daly's
//!   absolute peak sensitivity P and frequency scale ε (published 250 and 0.9) and his
//!   oblique-effect bandwidth ob (0.78), by Nelder–Mead on the RMSE of log10 sensitivity, for a
//!   given β (`cargo run --release --example fit_vdp -- --beta B --check`).
//! - **castleCSF's achromatic subset** (264 scored thresholds from nine datasets, areas from
//!   0.003 to 980 deg², `reference/oracles/castlecsf/`) fixes β, the Minkowski exponent of spatial
//!   summation (also the psychometric slope), which ModelFest's small patches barely constrain:
//!   refitting P, ε and ob on ModelFest at β = 2.863 (ModelFest's own optimum), 3.5 and 4.5 gave
//!   castleCSF 2.89, **2.79** and 2.87 dB after a per-dataset factor (ModelFest 0.060, 0.068,
//!   0.087 log10): β = 3.5, which is also Daly's published value. castleCSF also fixes the
//!   high-luminance loss (`adaptation.rs`), fitted on its residuals (exact: its stimuli sit on
//!   uniform backgrounds, so the loss scales each threshold by the inverse of its factor).
//! - **Foley 1994** (masking, `reference/oracles/foley1994/`) checks the masking stage, whose
//!   slope keeps its published value: 1.88 dB after a factor with these constants.
//!
//! Result: ModelFest 0.068 log10, castleCSF 2.72 dB (castleCSF's own model: 2.76), Foley 1.88 dB.

/// Daly's P: absolute peak contrast sensitivity. Published 250; fitted 196.41 (at β = 3.5).
pub const PEAK_SENSITIVITY: f64 = 196.41;
/// Daly's ε: frequency scale of the CSF. Published 0.9; fitted 0.9837.
pub const FREQUENCY_SCALE: f64 = 0.9837;
/// Daly's ob: bandwidth on the diagonals relative to the cardinal axes. Published 0.78; fitted
/// 0.4036.
pub const OBLIQUE: f64 = 0.4036;
/// β: Minkowski exponent of spatial summation and psychometric slope. Daly 3.5; chosen 3.5 on
/// castleCSF's range of sizes (ModelFest alone preferred 2.863).
pub const BETA: f64 = 3.5;
/// The luminance, cd/m², above which sensitivity falls off Weber's law (halved there), fitted on
/// the castleCSF subset's residuals (`fit_vdp --check`); `adaptation.rs`'s [`HighLuminanceLoss`].
///
/// [`HighLuminanceLoss`]: super::HighLuminanceLoss
pub const HIGH_LUMINANCE_KNEE: f64 = 6309.6;
/// The steepness of that fall-off (fitted on a 0.1 grid).
pub const HIGH_LUMINANCE_EXPONENT: f64 = 0.7;
/// Adaptation luminance of the CSF filter, cd/m²: ModelFest's background, so that the fit sees no
/// luminance correction (`adaptation.rs`).
pub const REFERENCE_LUMINANCE: f64 = 30.0;
