//! `lodeval calibrate modelfest|castle|foley|all`: the VDP against human thresholds, with the
//! tables and predicted-against-measured plots.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::metric::vdp::castle::{CastleCalibration, CastleCsf};
use crate::metric::vdp::foley::{Foley, FoleyCalibration};
use crate::metric::vdp::modelfest::{Calibration, Condition, ModelFest};
use crate::metric::vdp::{VdpParams, castle, foley, modelfest};

/// Which human data to check against.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum CalibrationSet {
    /// ModelFest's 43 thresholds.
    #[value(
        help = "ModelFest: 43 foveal detection thresholds of 16 observers (Carney et al. 1999)"
    )]
    Modelfest,
    /// castleCSF's achromatic, static, foveal subset.
    #[value(
        help = "castleCSF's achromatic, static, foveal thresholds: 271 conditions from 9 datasets, 0.00002–10 000 cd/m², 0.003–980 deg² (Ashraf et al. 2024)"
    )]
    Castle,
    /// Foley 1994's masking thresholds.
    #[value(help = "Foley 1994: a Gabor's threshold on Gabor maskers at 0°, 45° and 90°")]
    Foley,
    /// All three.
    All,
}

impl CalibrationSet {
    /// The default oracle folder (for `All`, the folder that holds the three).
    pub fn default_data(self) -> PathBuf {
        let root = PathBuf::from("reference/oracles");
        match self {
            CalibrationSet::Modelfest => root.join("modelfest"),
            CalibrationSet::Castle => root.join("castlecsf"),
            CalibrationSet::Foley => root.join("foley1994"),
            CalibrationSet::All => root,
        }
    }
}

/// A `lodeval calibrate` request.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct CalibrateJob {
    /// Which data.
    pub set: CalibrationSet,
    /// The oracle folder (see [`CalibrationSet::default_data`]).
    pub data: PathBuf,
    /// ModelFest's viewing condition (ModelFest's own by default).
    pub condition: Condition,
    /// castle only: one of its datasets.
    pub dataset: Option<String>,
    /// Where to write each dataset's table (.csv) and plot (.svg) (none: nothing written).
    pub out: Option<PathBuf>,
}

impl CalibrateJob {
    /// `set` against its shipped data at ModelFest's condition, every dataset, no files
    /// written.
    pub fn new(set: CalibrationSet) -> CalibrateJob {
        CalibrateJob {
            set,
            data: set.default_data(),
            condition: Condition::MODELFEST,
            dataset: None,
            out: None,
        }
    }
}

/// What `calibrate` found, per dataset asked for.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CalibrationReport {
    /// ModelFest.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub modelfest: Option<Calibration>,
    /// castleCSF.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub castle: Option<CastleCalibration>,
    /// Foley 1994.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub foley: Option<FoleyCalibration>,
}

/// Check the VDP against the chosen data; write tables and plots when asked.
pub fn calibrate(job: &CalibrateJob) -> Result<CalibrationReport> {
    job.condition.check()?;
    let params = VdpParams::fitted();
    let all = job.set == CalibrationSet::All;
    let folder = |name: &str| {
        if all {
            job.data.join(name)
        } else {
            job.data.clone()
        }
    };
    let wants = |s: CalibrationSet| all || job.set == s;
    // Every dataset is loaded (and checked) before any is run.
    let mf = wants(CalibrationSet::Modelfest)
        .then(|| ModelFest::load(&folder("modelfest")))
        .transpose()?;
    let cs = wants(CalibrationSet::Castle)
        .then(|| CastleCsf::load(&folder("castlecsf")))
        .transpose()?;
    let fo = wants(CalibrationSet::Foley)
        .then(|| Foley::load(&folder("foley1994")))
        .transpose()?;
    let report = CalibrationReport {
        modelfest: mf
            .map(|d| modelfest::calibrate(&d, params, job.condition))
            .transpose()?,
        castle: cs
            .map(|d| castle::calibrate(&d, params, job.dataset.as_deref()))
            .transpose()?,
        foley: fo.map(|d| foley::calibrate(&d, params)).transpose()?,
    };
    if let Some(dir) = &job.out {
        write_outputs(dir, &report)?;
    }
    Ok(report)
}

/// Each dataset's table and plot into `dir`.
fn write_outputs(dir: &Path, report: &CalibrationReport) -> Result<()> {
    use crate::io::plot::{LabelledPoint, scatter_identity};
    std::fs::create_dir_all(dir).map_err(|e| {
        Error::input(
            dir,
            format!("cannot create the output folder: {e}"),
            "give a writable --out folder",
        )
    })?;
    let svg =
        |name: &str, title: &str, note: &str, axes: [&str; 2], points: &[LabelledPoint], band| {
            let text = scatter_identity(title, note, axes[0], axes[1], points, band);
            crate::io::write_atomic(&dir.join(name), text.as_bytes())
        };
    if let Some(m) = &report.modelfest {
        crate::io::csv::write_rows(&dir.join("modelfest.csv"), None, &m.stimuli)?;
        let points: Vec<LabelledPoint> = m
            .stimuli
            .iter()
            .map(|r| (r.observed, r.predicted, r.id.to_string()))
            .collect();
        let note = format!(
            "RMSE {:.3} log10 over {} stimuli at {} ppd, {} cd/m²; dashed: ±0.1",
            m.rmse_log10,
            m.stimuli.len(),
            m.ppd,
            m.background_cd_m2
        );
        let title = "ModelFest: lodeval's VDP against 16 observers";
        let axes = [
            "observed log10 contrast sensitivity (mean of 16 observers)",
            "predicted log10 contrast sensitivity",
        ];
        svg("modelfest.svg", title, &note, axes, &points, 0.1)?;
    }
    if let Some(c) = &report.castle {
        crate::io::csv::write_rows(&dir.join("castle.csv"), None, &c.conditions)?;
        let points: Vec<LabelledPoint> = c
            .conditions
            .iter()
            .filter(|r| r.bound.is_none())
            .filter_map(|r| Some((r.observed, r.predicted?, short(&r.dataset))))
            .collect();
        let note = format!(
            "mean of {} datasets: {:.2} dB, {:.2} dB after a factor each; dashed: ±2 dB",
            c.datasets.len(),
            c.rmse_db,
            c.rmse_adjusted_db
        );
        let title = "castleCSF, achromatic: lodeval's VDP against the observers";
        let axes = [
            "observed log10 contrast sensitivity (dataset's mean)",
            "predicted log10 contrast sensitivity",
        ];
        svg("castle.svg", title, &note, axes, &points, 0.1)?;
    }
    if let Some(f) = &report.foley {
        crate::io::csv::write_rows(&dir.join("foley.csv"), None, &f.points)?;
        let points: Vec<LabelledPoint> = f
            .points
            .iter()
            .filter(|r| r.bound.is_none())
            .map(|r| (r.observed_db, r.predicted_db, format!("{}°", r.orientation)))
            .collect();
        let note = format!(
            "{:.2} dB as predicted, {:.2} dB after the factor ({:+.2} dB); dashed: ±2 dB",
            f.agreement.rmse_db, f.agreement.rmse_adjusted_db, f.agreement.factor_db
        );
        let title = "Foley 1994 masking: lodeval's VDP against the observer";
        let axes = [
            "observed target threshold, dB",
            "predicted target threshold, dB",
        ];
        svg("foley.svg", title, &note, axes, &points, 2.0)?;
    }
    Ok(())
}

/// A dataset's label on the plot.
fn short(dataset: &str) -> String {
    dataset.chars().take(3).collect()
}
