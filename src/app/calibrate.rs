//! `lodeval calibrate modelfest`: the VDP against ModelFest's observers, with the table and plot.

use std::path::PathBuf;

use crate::error::{Error, Result};

/// A `lodeval calibrate modelfest` request.
#[derive(Debug, Clone)]
pub struct CalibrateJob {
    /// The oracle folder (`reference/oracles/modelfest`).
    pub data: PathBuf,
    /// The viewing condition (ModelFest's by default).
    pub condition: crate::metric::vdp::modelfest::Condition,
    /// Where to write `modelfest.csv` and `modelfest.svg` (none: nothing written).
    pub out: Option<PathBuf>,
}

/// Check the VDP against ModelFest; write the per-stimulus table and the plot when asked.
pub fn calibrate(job: &CalibrateJob) -> Result<crate::metric::vdp::modelfest::Calibration> {
    use crate::metric::vdp::{VdpParams, modelfest};
    job.condition.check()?;
    let data = modelfest::ModelFest::load(&job.data)?;
    let result = modelfest::calibrate(&data, VdpParams::fitted(), job.condition)?;
    if let Some(dir) = &job.out {
        std::fs::create_dir_all(dir).map_err(|e| {
            Error::input(
                dir,
                format!("cannot create the output folder: {e}"),
                "give a writable --out folder",
            )
        })?;
        crate::io::csv::write_rows(&dir.join("modelfest.csv"), None, &result.stimuli)?;
        let points: Vec<crate::io::plot::LabelledPoint> = result
            .stimuli
            .iter()
            .map(|r| (r.observed, r.predicted, r.id.to_string()))
            .collect();
        let svg = crate::io::plot::scatter_identity(
            "ModelFest: lodeval's VDP against 16 observers",
            &format!(
                "RMSE {:.3} log10 over {} stimuli at {} ppd, {} cd/m²; dashed: ±0.1",
                result.rmse_log10,
                result.stimuli.len(),
                result.ppd,
                result.background_cd_m2
            ),
            "observed log10 contrast sensitivity (mean of 16 observers)",
            "predicted log10 contrast sensitivity",
            &points,
            0.1,
        );
        crate::io::write_atomic(&dir.join("modelfest.svg"), svg.as_bytes())?;
    }
    Ok(result)
}
