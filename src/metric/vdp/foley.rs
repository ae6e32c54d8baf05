//! The VDP against Foley 1994's contrast masking thresholds: a Gabor target's threshold on Gabor
//! maskers of rising contrast at 0°, 45° and 90° to it (the dipper, then the rise).
//!
//! Based on: John M. Foley. Human luminance pattern-vision mechanisms: masking experiments require
//! a new model. JOSA A 11(6) 1994 (30 thresholds digitised from its figure, in
//! `reference/oracles/foley1994/`: masker orientation, masker contrast in dB of Michelson contrast,
//! target threshold in dB; a masker contrast of 0 dB marks the unmasked threshold, no masker).
//!
//! Assumed, because the digitised table does not carry them (a per-dataset sensitivity factor, as
//! in `agreement.rs`, absorbs a different mean luminance or presentation time in the unmasked
//! threshold; what it cannot absorb is the masking curve's shape, which is the point): target and
//! masker are Gabors of [`FREQUENCY`] c/deg and σ = [`SIGMA`]° in cosine phase, centred on each
//! other, on a [`LUMINANCE`] cd/m² field. The reference image is the masker alone, the test the
//! masker plus the target; the threshold is found as for ModelFest (`threshold.rs`).

use std::path::Path;

use rayon::prelude::*;

use super::agreement::{DatasetAgreement, per_dataset};
use super::stimuli::{Aperture, Grating, raster_for};
use super::threshold::{Bound, threshold};
use super::{Display, Vdp, VdpParams};
use crate::error::Result;

/// Target and masker frequency, cycles per degree (assumed).
pub const FREQUENCY: f64 = 2.0;
/// Target and masker Gaussian σ, degrees (assumed).
pub const SIGMA: f64 = 0.5;
/// Mean luminance, cd/m² (assumed).
pub const LUMINANCE: f64 = 40.0;

/// One measured threshold.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Point {
    /// Masker orientation relative to the target, degrees.
    pub orientation: f64,
    /// Masker contrast, dB (20·log10 Michelson); `None`: no masker.
    pub mask_db: Option<f64>,
    /// Target threshold contrast, dB.
    pub target_db: f64,
}

/// The dataset as loaded.
#[derive(Debug, Clone)]
pub struct Foley {
    /// The thresholds in file order.
    pub points: Vec<Point>,
}

impl Foley {
    /// Load `foley1994_masking.csv` from `dir`, checking every value.
    pub fn load(dir: &Path) -> Result<Foley> {
        let fix = "copy foley1994_masking.csv (orientation,c_mask,c_target) back from the \
                   repository, or pass --data with the folder that holds it";
        let path = dir.join("foley1994_masking.csv");
        let table = super::table::Table::read(&path, &["orientation", "c_mask", "c_target"], fix)?;
        let points = table
            .rows
            .iter()
            .map(|row| {
                let orientation = table.number(row, 0, "orientation", 0.0, 90.0)?;
                let mask = table.number(row, 1, "c_mask", -120.0, 0.0)?;
                let target_db = table.number(row, 2, "c_target", -120.0, 0.0)?;
                Ok(Point {
                    orientation,
                    mask_db: (mask != 0.0).then_some(mask),
                    target_db,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Foley { points })
    }
}

/// One threshold's result.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FoleyRow {
    /// Masker orientation relative to the target, degrees.
    pub orientation: f64,
    /// Masker contrast, dB; empty: no masker.
    pub mask_db: Option<f64>,
    /// Observed target threshold, dB.
    pub observed_db: f64,
    /// The VDP's target threshold, dB.
    pub predicted_db: f64,
    /// Set where the prediction is a bound of the search, not a threshold.
    pub bound: Option<Bound>,
    /// Sensitivity residual, dB: observed − predicted threshold (as castleCSF's sign).
    pub residual_db: Option<f64>,
}

/// The whole check.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FoleyCalibration {
    /// The agreement (one dataset).
    pub agreement: DatasetAgreement,
    /// Per threshold, in file order.
    pub points: Vec<FoleyRow>,
}

/// Run the check with `params`.
pub fn calibrate(data: &Foley, params: VdpParams) -> Result<FoleyCalibration> {
    let gabor = |orientation: f64| Grating {
        frequency: FREQUENCY,
        orientation,
        aperture: Aperture::Gauss { sigma: SIGMA },
    };
    let (ppd, side) =
        raster_for(gabor(0.0).extent(), FREQUENCY).expect("a 2 c/deg Gabor fits the raster");
    let vdp = Vdp::with_params(ppd, Display::DEFAULT, params);
    let target = gabor(0.0).raster(ppd, side);
    let l0 = LUMINANCE as f32;
    let points = data
        .points
        .par_iter()
        .map(|p| {
            let cm = p.mask_db.map_or(0.0, |db| 10f64.powf(db / 20.0)) as f32;
            let masker: Vec<f32> = gabor(p.orientation)
                .raster(ppd, side)
                .iter()
                .map(|&m| l0 * (1.0 + cm * m))
                .collect();
            let reference = vdp.prepare_luminance(side, side, masker.clone());
            let t = threshold(&vdp, &reference, |c| {
                masker
                    .iter()
                    .zip(&target)
                    .map(|(&m, &s)| m + l0 * c as f32 * s)
                    .collect()
            });
            let predicted_db = 20.0 * t.contrast.log10();
            FoleyRow {
                orientation: p.orientation,
                mask_db: p.mask_db,
                observed_db: p.target_db,
                predicted_db,
                bound: t.bound,
                residual_db: t.bound.is_none().then_some(p.target_db - predicted_db),
            }
        })
        .collect::<Vec<_>>();
    let agreement = per_dataset(points.iter().map(|r| ("foley1994", r.residual_db)))
        .pop()
        .expect("one dataset");
    Ok(FoleyCalibration { agreement, points })
}
