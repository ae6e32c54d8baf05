//! `lodeval calibrate modelfest`: the VDP against ModelFest's observers.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use lodeval::Error;

use super::print::{emit, emit_json};

/// Datasets `lodeval calibrate` knows.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum CalibrationSet {
    /// ModelFest: 43 foveal detection thresholds of 16 observers (Carney et al. 1999).
    Modelfest,
}

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  lodeval calibrate modelfest\n\nExit codes: 0 calibrated and reported · 2 a missing or damaged oracle, or bad conditions · 3 internal error"
)]
pub(crate) struct CalibrateArgs {
    /// The dataset.
    #[arg(value_enum)]
    pub(crate) dataset: CalibrationSet,
    /// The oracle folder (thresholds.csv and the stimulus PNGs).
    #[arg(long, default_value = "reference/oracles/modelfest")]
    pub(crate) data: PathBuf,
    /// Pixels per degree the stimuli are shown at (ModelFest's: 120).
    #[arg(long, default_value_t = 120.0)]
    pub(crate) ppd: f64,
    /// Background luminance in cd/m² (ModelFest's: 30).
    #[arg(long, default_value_t = 30.0)]
    pub(crate) background_cd_m2: f64,
    /// Write modelfest.csv (the per-stimulus table) and modelfest.svg (predicted against
    /// observed) into this folder.
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,
    /// Print JSON: {"rmse_log10", "stimuli": [{"id", "name", "observed", "sd", "predicted",
    /// "residual"}], ...}.
    #[arg(long)]
    pub(crate) json: bool,
}

/// Run `calibrate`.
pub(crate) fn run(a: CalibrateArgs) -> Result<(), Error> {
    let CalibrationSet::Modelfest = a.dataset;
    let job = lodeval::app::CalibrateJob {
        data: a.data.clone(),
        condition: lodeval::metric::vdp::modelfest::Condition {
            ppd: a.ppd,
            background_cd_m2: a.background_cd_m2,
        },
        out: a.out.clone(),
    };
    let c = lodeval::app::calibrate(&job)?;
    if a.json {
        return emit_json(&c);
    }
    let mut t = format!(
        "ModelFest at {} ppd on {} cd/m²; threshold: detection probability {} (2AFC 84 % \
         correct)\n{:>3}  {:<18} {:>8} {:>6} {:>9} {:>8}\n",
        c.ppd,
        c.background_cd_m2,
        c.criterion_probability,
        "id",
        "stimulus",
        "observed",
        "sd",
        "predicted",
        "residual"
    );
    for r in &c.stimuli {
        t.push_str(&format!(
            "{:>3}  {:<18} {:>8.3} {:>6.3} {:>9.3} {:>+8.3}\n",
            r.id, r.name, r.observed, r.sd, r.predicted, r.residual
        ));
    }
    t.push_str(&format!(
        "RMSE {:.4} log10 over {} stimuli (one observer against the group: 0.17)\n",
        c.rmse_log10,
        c.stimuli.len()
    ));
    if let Some(dir) = &a.out {
        t.push_str(&format!(
            "wrote {} and {}\n",
            dir.join("modelfest.csv").display(),
            dir.join("modelfest.svg").display()
        ));
    }
    emit(&t)
}
