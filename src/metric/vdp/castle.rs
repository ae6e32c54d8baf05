//! The VDP against castleCSF's achromatic, static, foveal detection thresholds: how sensitivity
//! changes with background luminance (0.00002 to 10 000 cd/m²), stimulus size (0.003 to 980 deg²)
//! and shape (Gabors, gratings, discs) — what ModelFest, one luminance and small patches, cannot
//! pin down.
//!
//! Based on: Maliha Ashraf, Rafał Mantiuk, Alexandre Chapiro, Sophie Wuerger. castleCSF — A
//! contrast sensitivity function of color, area, spatio-temporal frequency, luminance and
//! eccentricity. Journal of Vision 24(4) 2024 (the aggregated data, MIT licence, and the figure of
//! merit: RMSE in dB of sensitivity per dataset, with a per-dataset sensitivity factor).
//!
//! The data (`reference/oracles/castlecsf/achromatic.csv`, made by `select_achromatic.py` there
//! from castleCSF's `data/`): one row per condition — dataset, stimulus (`gabor`, `grating`,
//! `disk`), aperture, background luminance, frequency, Gabor σ, area, orientation and the
//! observers' mean log10 sensitivity (1 / Michelson contrast at threshold).
//!
//! Each row's stimulus is synthesised (`stimuli.rs`) on a raster chosen for it (the VDP is given
//! that raster's pixels per degree), shown as L0·(1 + c·s) on its uniform background L0, and its
//! threshold found as for ModelFest (`threshold.rs`). Rows the raster cannot hold, and
//! predictions that stop at a bound of the search, are counted and left out of the RMSE, never
//! reported as thresholds.

use std::path::Path;

use rayon::prelude::*;

use super::agreement::{DatasetAgreement, average, per_dataset};
use super::stimuli::{Aperture, Grating, raster_for};
use super::threshold::{Bound, threshold};
use super::{Display, Vdp, VdpParams};
use crate::error::{Error, Result};

/// The table's columns.
const HEADER: [&str; 9] = [
    "dataset",
    "stimulus",
    "aperture",
    "luminance",
    "frequency",
    "sigma",
    "area",
    "orientation",
    "log_sensitivity",
];

/// One condition and what the observers saw.
#[derive(Debug, Clone, PartialEq)]
pub struct Condition {
    /// castleCSF's dataset name.
    pub dataset: String,
    /// The stimulus.
    pub grating: Grating,
    /// Background luminance, cd/m².
    pub luminance: f64,
    /// Area, deg² (as castleCSF gives it).
    pub area: f64,
    /// Observers' log10 sensitivity.
    pub observed: f64,
}

/// The dataset as loaded.
#[derive(Debug, Clone)]
pub struct CastleCsf {
    /// The conditions in file order.
    pub conditions: Vec<Condition>,
}

impl CastleCsf {
    /// Load `achromatic.csv` from `dir`, checking every value.
    pub fn load(dir: &Path) -> Result<CastleCsf> {
        let fix = "regenerate it with reference/oracles/castlecsf/select_achromatic.py from \
                   castleCSF's data folder, or pass --data with the folder that holds it";
        let path = dir.join("achromatic.csv");
        let table = super::table::Table::read(&path, &HEADER, fix)?;
        let conditions = table
            .rows
            .iter()
            .map(|row| {
                let luminance = table.number(row, 3, "luminance", 1e-6, 1e6)?;
                let frequency = table.number(row, 4, "frequency", 0.0, 120.0)?;
                let sigma = table.number(row, 5, "sigma", 1e-3, 100.0)?;
                let area = table.number(row, 6, "area", 1e-4, 1e4)?;
                let orientation = table.number(row, 7, "orientation", -360.0, 360.0)?;
                let observed = table.number(row, 8, "log_sensitivity", -1.0, 4.0)?;
                let aperture = match (row.fields[1].as_str(), row.fields[2].as_str()) {
                    ("gabor", _) => Aperture::Gauss { sigma },
                    ("grating", "rectangular") => Aperture::Square { side: area.sqrt() },
                    ("grating", "tapered_rectangular") => Aperture::Tapered { side: area.sqrt() },
                    ("grating" | "disk", "circular") => Aperture::Circle {
                        radius: (area / std::f64::consts::PI).sqrt(),
                    },
                    (s, a) => {
                        return Err(table.error(
                            row,
                            format!(
                                "stimulus '{}' in aperture '{}' is not one of gabor, grating \
                                 (rectangular, tapered_rectangular, circular), disk (circular)",
                                crate::error::quote(s),
                                crate::error::quote(a)
                            ),
                        ));
                    }
                };
                Ok(Condition {
                    dataset: row.fields[0].clone(),
                    grating: Grating {
                        frequency,
                        orientation,
                        aperture,
                    },
                    luminance,
                    area,
                    observed,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(CastleCsf { conditions })
    }
}

/// One condition's result.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CastleRow {
    /// castleCSF's dataset name.
    pub dataset: String,
    /// Background luminance, cd/m².
    pub luminance: f64,
    /// Cycles per degree.
    pub frequency: f64,
    /// Area, deg².
    pub area: f64,
    /// Observers' log10 sensitivity.
    pub observed: f64,
    /// The VDP's log10 sensitivity; empty where the condition was not rendered.
    pub predicted: Option<f64>,
    /// Set where the prediction is a bound of the search (`above_max`: not seen at 100 %
    /// contrast), not a threshold.
    pub bound: Option<Bound>,
    /// 20·(predicted − observed), dB; empty for bounds and unrendered rows.
    pub residual_db: Option<f64>,
    /// The raster used: pixels per degree (0 where not rendered).
    pub ppd: f64,
    /// The raster used: side in pixels (0 where not rendered).
    pub side: usize,
}

/// The whole check.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CastleCalibration {
    /// Mean over datasets of the RMSE as predicted, dB.
    pub rmse_db: f64,
    /// Mean over datasets of the RMSE after a per-dataset factor, dB (castleCSF's own fit: 2.76).
    pub rmse_adjusted_db: f64,
    /// Per dataset.
    pub datasets: Vec<DatasetAgreement>,
    /// Per condition, in file order.
    pub conditions: Vec<CastleRow>,
}

/// Predict one condition.
fn predict(params: VdpParams, c: &Condition) -> CastleRow {
    let mut row = CastleRow {
        dataset: c.dataset.clone(),
        luminance: c.luminance,
        frequency: c.grating.frequency,
        area: c.area,
        observed: c.observed,
        predicted: None,
        bound: None,
        residual_db: None,
        ppd: 0.0,
        side: 0,
    };
    let Some((ppd, side)) = raster_for(c.grating.extent(), c.grating.frequency) else {
        return row;
    };
    let vdp = Vdp::with_params(ppd, Display::DEFAULT, params);
    let pattern = c.grating.raster(ppd, side);
    let l0 = c.luminance as f32;
    let background = vdp.prepare_luminance(side, side, vec![l0; side * side]);
    let t = threshold(&vdp, &background, |k| {
        pattern.iter().map(|&s| l0 * (1.0 + k as f32 * s)).collect()
    });
    let predicted = -t.contrast.log10();
    row.predicted = Some(predicted);
    row.bound = t.bound;
    row.residual_db = t.bound.is_none().then_some(20.0 * (predicted - c.observed));
    row.ppd = ppd;
    row.side = side;
    row
}

/// Run the check on every condition (or those of `only`, a dataset name) with `params`.
pub fn calibrate(
    data: &CastleCsf,
    params: VdpParams,
    only: Option<&str>,
) -> Result<CastleCalibration> {
    let chosen: Vec<&Condition> = data
        .conditions
        .iter()
        .filter(|c| only.is_none_or(|d| c.dataset == d))
        .collect();
    if chosen.is_empty() {
        return Err(Error::Usage(format!(
            "no castleCSF condition belongs to dataset '{}'",
            only.unwrap_or_default()
        )));
    }
    let conditions: Vec<CastleRow> = chosen.par_iter().map(|c| predict(params, c)).collect();
    let datasets = per_dataset(
        conditions
            .iter()
            .map(|r| (r.dataset.as_str(), r.residual_db)),
    );
    Ok(CastleCalibration {
        rmse_db: average(&datasets, |d| d.rmse_db),
        rmse_adjusted_db: average(&datasets, |d| d.rmse_adjusted_db),
        datasets,
        conditions,
    })
}
