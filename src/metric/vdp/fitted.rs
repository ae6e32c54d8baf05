//! The VDP's fitted constants: the only numbers in the model that were not taken from a paper.
//!
//! Source: ModelFest (Carney et al. 1999; Watson & Ahumada 2005), 43 stimuli, the mean of 16
//! observers' log10 contrast sensitivities (`reference/oracles/modelfest/`). Fitted by
//! `cargo run --release --example fit_vdp` (Nelder–Mead on the RMSE of predicted against observed
//! log10 sensitivity, the prediction being the contrast at which this model's detection
//! probability reaches the observers' 2AFC threshold); `lodeval calibrate modelfest` checks them.
//! They are compiled in: nothing is fitted at run time.
//!
//! Free parameters, four for 43 thresholds: Daly's CSF's absolute peak sensitivity P and frequency
//! scale ε (his published 250 and 0.9), his oblique-effect bandwidth ob (0.78), and the Minkowski
//! exponent β of spatial summation, which is also the psychometric slope (probability summation;
//! Daly used 3.5, Watson & Ahumada 2005 fit values between 2 and 4 depending on the aperture).
//! Everything else — the CSF's luminance dependence, the masking slope, the display — keeps its
//! published value, because ModelFest (one luminance, no masker) cannot constrain it.

/// Daly's P: absolute peak contrast sensitivity. Published 250; fitted 212.38.
pub const PEAK_SENSITIVITY: f64 = 212.38;
/// Daly's ε: frequency scale of the CSF. Published 0.9; fitted 0.9730.
pub const FREQUENCY_SCALE: f64 = 0.9730;
/// Daly's ob: bandwidth on the diagonals relative to the cardinal axes. Published 0.78; fitted
/// 0.5591.
pub const OBLIQUE: f64 = 0.5591;
/// β: Minkowski exponent of spatial summation and psychometric slope. Daly 3.5; fitted 2.863.
pub const BETA: f64 = 2.863;
/// Adaptation luminance of the CSF filter, cd/m²: ModelFest's background, so that the fit sees no
/// luminance correction (`adaptation.rs`).
pub const REFERENCE_LUMINANCE: f64 = 30.0;
