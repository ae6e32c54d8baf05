//! The VDP's calibration check: ModelFest's 43 detection thresholds against the model's.
//!
//! Based on: Thom Carney et al. Development of an image/threshold database for designing and
//! testing human vision models. Proc. SPIE 3644 1999 (the stimuli: 256 × 256 pixels at 120 pixels
//! per degree on a uniform 30 cd/m² field; 16 observers, 2AFC thresholds at 84 % correct);
//! Andrew Watson, Albert Ahumada. A standard model for foveal detection of spatial contrast.
//! Journal of Vision 5(9) 2005 (the figure of merit: RMS error of predicted against observed log10
//! contrast sensitivity).
//!
//! The data (`reference/oracles/modelfest/`, made by its `make_modelfest.py` from the PyPI package
//! stimupy 1.2.0): `thresholds.csv` (id, name, observed mean log10 sensitivity, its standard
//! deviation over observers, observers, file) and one 16-bit grey PNG per stimulus holding its
//! contrast pattern s ∈ [−1, 1] as (s + 1)/2 · 65535.
//!
//! For each stimulus the reference image is the uniform background L0 and the test image
//! L0·(1 + c·s); the predicted threshold is the contrast c at which the VDP's detection probability
//! is the observers' criterion ([`THRESHOLD_PROBABILITY`]: 2AFC 84 % correct, corrected for
//! guessing, i.e. pooled sum S = 1), found by `threshold.rs`. The predicted log10 sensitivity is
//! −log10 c.

use std::path::Path;

use rayon::prelude::*;

use super::{THRESHOLD_PROBABILITY, Vdp, VdpParams};
use crate::error::{Error, Location, Result};
use crate::metric::vdp::Display;

/// Number of ModelFest stimuli.
pub const STIMULI: usize = 43;
/// Side of every stimulus, pixels.
pub const SIDE: usize = 256;
/// ModelFest's raster: pixels per degree.
pub const PPD: f64 = 120.0;
/// ModelFest's background luminance, cd/m².
pub const BACKGROUND_CD_M2: f64 = 30.0;
/// Largest file the loader reads (the PNGs are ≈ 20–130 KB).
const MAX_FILE_BYTES: u64 = 16 << 20;

/// One stimulus and what the observers saw.
#[derive(Debug, Clone)]
pub struct Stimulus {
    /// 1-based ModelFest number.
    pub id: usize,
    /// ModelFest's name (`GaborPatch1`, …).
    pub name: String,
    /// Mean over observers of log10 contrast sensitivity.
    pub observed: f64,
    /// Standard deviation of that mean over observers, log10 units.
    pub sd: f64,
    /// The contrast pattern s ∈ [−1, 1], row-major, [`SIDE`]².
    pub pattern: Vec<f32>,
}

/// The dataset as loaded.
#[derive(Debug, Clone)]
pub struct ModelFest {
    /// The stimuli in ModelFest order.
    pub stimuli: Vec<Stimulus>,
}

/// The viewing condition the stimuli are shown at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Condition {
    /// Pixels per degree. Default value: 120 (ModelFest's).
    pub ppd: f64,
    /// Background luminance, cd/m². Default value: 30 (ModelFest's).
    pub background_cd_m2: f64,
}

impl Condition {
    /// ModelFest's own condition.
    pub const MODELFEST: Condition = Condition {
        ppd: PPD,
        background_cd_m2: BACKGROUND_CD_M2,
    };

    /// Refuse conditions that make no sense (usage error naming the value).
    pub fn check(&self) -> Result<()> {
        if let Err(m) = crate::limits::PPD.check("--ppd", self.ppd) {
            return Err(Error::Usage(format!("{m}; ModelFest's is 120")));
        }
        if !self.background_cd_m2.is_finite()
            || self.background_cd_m2 <= 0.0
            || self.background_cd_m2 > 1e5
        {
            return Err(Error::Usage(format!(
                "--background-cd-m2 {}: give a luminance above 0 and at most 100000 cd/m² \
                 (ModelFest's is 30)",
                self.background_cd_m2
            )));
        }
        Ok(())
    }
}

/// One stimulus's result.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CalibrationRow {
    /// 1-based ModelFest number.
    pub id: usize,
    /// ModelFest's name.
    pub name: String,
    /// Observers' mean log10 sensitivity.
    pub observed: f64,
    /// Its standard deviation over observers.
    pub sd: f64,
    /// The VDP's log10 sensitivity (−log10 of its threshold contrast).
    pub predicted: f64,
    /// predicted − observed.
    pub residual: f64,
}

/// The whole check.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Calibration {
    /// RMS of the residuals over the stimuli, log10 units.
    pub rmse_log10: f64,
    /// Detection probability taken as threshold.
    pub criterion_probability: f64,
    /// The condition used: pixels per degree.
    pub ppd: f64,
    /// The condition used: background luminance, cd/m².
    pub background_cd_m2: f64,
    /// Per stimulus, in ModelFest order.
    pub stimuli: Vec<CalibrationRow>,
}

/// Read a small regular file, or say what is wrong with it.
fn read_small(path: &Path, what: &str) -> Result<Vec<u8>> {
    let fix = "regenerate the folder with reference/oracles/modelfest/make_modelfest.py, or pass \
               --data with the folder that holds it";
    crate::io::read_input(path, what, MAX_FILE_BYTES, fix)
}

impl ModelFest {
    /// Load the oracle folder `dir`, checking every value and image.
    pub fn load(dir: &Path) -> Result<ModelFest> {
        let fix =
            "regenerate it with reference/oracles/modelfest/make_modelfest.py (stimupy 1.2.0)";
        if !dir.is_dir() {
            return Err(Error::input(
                dir,
                "the ModelFest oracle folder does not exist",
                "run from the repository root (the default is reference/oracles/modelfest) or pass \
                 --data DIR",
            ));
        }
        let table = dir.join("thresholds.csv");
        let bytes = read_small(&table, "threshold table")?;
        let mut reader = csv::ReaderBuilder::new().from_reader(bytes.as_slice());
        let header: Vec<String> = reader
            .headers()
            .map_err(|e| Error::input(&table, format!("cannot read the header: {e}"), fix))?
            .iter()
            .map(str::to_string)
            .collect();
        if header != ["id", "name", "observed", "sd", "observers", "file"] {
            return Err(Error::input_at(
                &table,
                Location::Line(1),
                format!("the header is {header:?}, not id,name,observed,sd,observers,file"),
                fix,
            ));
        }
        let mut rows = Vec::new();
        for (i, record) in reader.records().enumerate() {
            let line = Location::Line(i + 2);
            let record = record.map_err(|e| {
                Error::input_at(&table, line.clone(), format!("unreadable row: {e}"), fix)
            })?;
            if record.len() != 6 {
                return Err(Error::input_at(
                    &table,
                    line,
                    format!("{} fields instead of 6", record.len()),
                    fix,
                ));
            }
            let number = |k: usize, what: &str, lo: f64, hi: f64| -> Result<f64> {
                record[k]
                    .trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite() && (lo..=hi).contains(v))
                    .ok_or_else(|| {
                        Error::input_at(
                            &table,
                            line.clone(),
                            format!("{what} '{}' is not a number in [{lo}, {hi}]", &record[k]),
                            fix,
                        )
                    })
            };
            let id = number(0, "id", 1.0, STIMULI as f64)? as usize;
            if id != rows.len() + 1 {
                return Err(Error::input_at(
                    &table,
                    line,
                    format!("stimulus {id} where {} was expected", rows.len() + 1),
                    fix,
                ));
            }
            let observed = number(2, "observed", -1.0, 4.0)?;
            let sd = number(3, "sd", 0.0, 2.0)?;
            let file = record[5].trim();
            if file.is_empty() || file.contains(['/', '\\']) || file.starts_with('.') {
                return Err(Error::input_at(
                    &table,
                    line,
                    format!("file '{file}' is not a plain file name in the folder"),
                    fix,
                ));
            }
            rows.push((
                id,
                record[1].trim().to_string(),
                observed,
                sd,
                dir.join(file),
            ));
        }
        if rows.len() != STIMULI {
            return Err(Error::input(
                &table,
                format!("{} stimuli instead of ModelFest's {STIMULI}", rows.len()),
                fix,
            ));
        }
        let stimuli = rows
            .into_par_iter()
            .map(|(id, name, observed, sd, path)| {
                Ok(Stimulus {
                    id,
                    name,
                    observed,
                    sd,
                    pattern: load_pattern(&path)?,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(ModelFest { stimuli })
    }
}

/// A stimulus PNG → s ∈ [−1, 1].
fn load_pattern(path: &Path) -> Result<Vec<f32>> {
    let fix = "regenerate it with reference/oracles/modelfest/make_modelfest.py";
    let bytes = read_small(path, "stimulus image")?;
    let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .map_err(|e| Error::input(path, format!("cannot decode the PNG: {e}"), fix))?;
    let img = match img {
        image::DynamicImage::ImageLuma16(g) => g,
        other => {
            return Err(Error::input(
                path,
                format!("the PNG is {:?}, not 16-bit grey", other.color()),
                fix,
            ));
        }
    };
    if (img.width() as usize, img.height() as usize) != (SIDE, SIDE) {
        return Err(Error::input(
            path,
            format!(
                "the PNG is {}×{}, not {SIDE}×{SIDE}",
                img.width(),
                img.height()
            ),
            fix,
        ));
    }
    Ok(img
        .as_raw()
        .iter()
        .map(|&q| (q as f32 / 65535.0) * 2.0 - 1.0)
        .collect())
}

/// Threshold contrast of one pattern against its uniform background (the bracket's end where
/// the search stops at one: ModelFest's stimuli all lie well inside it).
fn threshold(vdp: &Vdp, background: &super::VdpPrepared, pattern: &[f32], l0: f32) -> f64 {
    super::threshold::threshold(vdp, background, |c| {
        pattern.iter().map(|&s| l0 * (1.0 + c as f32 * s)).collect()
    })
    .contrast
}

/// Run the check: every stimulus's predicted threshold at `condition` with `params`.
pub fn calibrate(data: &ModelFest, params: VdpParams, condition: Condition) -> Result<Calibration> {
    condition.check()?;
    let l0 = condition.background_cd_m2 as f32;
    // The display only matters for `prepare`; stimuli arrive as luminance.
    let vdp = Vdp::with_params(condition.ppd, Display::DEFAULT, params);
    let background = vdp.prepare_luminance(SIDE, SIDE, vec![l0; SIDE * SIDE]);
    let stimuli: Vec<CalibrationRow> = data
        .stimuli
        .par_iter()
        .map(|s| {
            let predicted = -threshold(&vdp, &background, &s.pattern, l0).log10();
            CalibrationRow {
                id: s.id,
                name: s.name.clone(),
                observed: s.observed,
                sd: s.sd,
                predicted,
                residual: predicted - s.observed,
            }
        })
        .collect();
    let rmse_log10 = (stimuli.iter().map(|r| r.residual * r.residual).sum::<f64>()
        / stimuli.len().max(1) as f64)
        .sqrt();
    Ok(Calibration {
        rmse_log10,
        criterion_probability: THRESHOLD_PROBABILITY,
        ppd: condition.ppd,
        background_cd_m2: condition.background_cd_m2,
        stimuli,
    })
}
