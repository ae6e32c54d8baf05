//! `lodeval calibrate modelfest|castle|foley|all`: the VDP against human thresholds.

use std::path::PathBuf;

use clap::Args;
use lodeval::Error;
use lodeval::app::CalibrationSet;

use super::print::{emit, emit_json};

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  lodeval calibrate modelfest\n  lodeval calibrate all --json --out results/calibration\n\nExit codes: 0 calibrated and reported · 2 a missing or damaged oracle, or bad conditions · 3 internal error"
)]
pub(crate) struct CalibrateArgs {
    /// The human data.
    #[arg(value_enum)]
    pub(crate) set: CalibrationSet,
    /// The oracle folder (default: reference/oracles/modelfest, …/castlecsf or …/foley1994;
    /// for `all`, reference/oracles, the folder that holds the three).
    #[arg(long)]
    pub(crate) data: Option<PathBuf>,
    /// castle only: check one of its datasets (hdr_csf, rovamo1993, …).
    #[arg(long)]
    pub(crate) dataset: Option<String>,
    /// Pixels per degree the stimuli are shown at (ModelFest's: 120).
    #[arg(long, default_value_t = 120.0)]
    pub(crate) ppd: f64,
    /// Background luminance in cd/m² (ModelFest's: 30).
    #[arg(long, default_value_t = 30.0)]
    pub(crate) background_cd_m2: f64,
    /// Write each dataset's table (modelfest.csv, castle.csv, foley.csv) and plot of predicted
    /// against observed (.svg) into this folder.
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,
    /// Print JSON: {"modelfest": {"rmse_log10", "stimuli": [...]}, "castle": {"rmse_db",
    /// "rmse_adjusted_db", "datasets": [...], "conditions": [...]}, "foley": {"agreement",
    /// "points"}}, with the datasets asked for.
    #[arg(long)]
    pub(crate) json: bool,
}

/// Run `calibrate`.
pub(crate) fn run(a: CalibrateArgs) -> Result<(), Error> {
    use lodeval::app::CalibrationSet as S;
    let set = a.set;
    if a.dataset.is_some() && !matches!(set, S::Castle | S::All) {
        return Err(Error::Usage(
            "--dataset picks one of castleCSF's datasets: use it with `calibrate castle`".into(),
        ));
    }
    let mut job = lodeval::app::CalibrateJob::new(set);
    if let Some(data) = &a.data {
        job.data = data.clone();
    }
    job.condition = lodeval::metric::vdp::modelfest::Condition {
        ppd: a.ppd,
        background_cd_m2: a.background_cd_m2,
    };
    job.dataset = a.dataset.clone();
    job.out = a.out.clone();
    let report = lodeval::app::calibrate(&job)?;
    if a.json {
        return emit_json(&report);
    }
    let mut t = String::new();
    if let Some(c) = &report.modelfest {
        t.push_str(&modelfest_text(c));
    }
    if let Some(c) = &report.castle {
        t.push_str(&castle_text(c));
    }
    if let Some(f) = &report.foley {
        t.push_str(&foley_text(f));
    }
    if let Some(dir) = &a.out {
        t.push_str(&format!(
            "wrote the tables and plots into {}\n",
            dir.display()
        ));
    }
    emit(&t)
}

/// ModelFest's table.
fn modelfest_text(c: &lodeval::metric::vdp::modelfest::Calibration) -> String {
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
    t
}

/// castleCSF's per-dataset table.
fn castle_text(c: &lodeval::metric::vdp::castle::CastleCalibration) -> String {
    let mut t = format!(
        "castleCSF, achromatic static foveal: RMSE in dB of sensitivity (2 dB = 0.1 log10)\n\
         {:<14} {:>5} {:>9} {:>10} {:>9} {:>12}\n",
        "dataset", "rows", "left out", "factor dB", "RMSE dB", "adjusted dB"
    );
    for d in &c.datasets {
        t.push_str(&format!(
            "{:<14} {:>5} {:>9} {:>+10.2} {:>9.2} {:>12.2}\n",
            d.dataset, d.n, d.left_out, d.factor_db, d.rmse_db, d.rmse_adjusted_db
        ));
    }
    t.push_str(&format!(
        "mean over datasets: {:.2} dB as predicted, {:.2} dB after a factor per dataset \
         (castleCSF's own fit: 2.76 dB)\n",
        c.rmse_db, c.rmse_adjusted_db
    ));
    t
}

/// Foley's agreement.
fn foley_text(f: &lodeval::metric::vdp::foley::FoleyCalibration) -> String {
    let a = &f.agreement;
    format!(
        "Foley 1994 masking: {} thresholds ({} left out), {:.2} dB as predicted, {:.2} dB after \
         a factor of {:+.2} dB\n",
        a.n, a.left_out, a.rmse_db, a.rmse_adjusted_db, a.factor_db
    )
}
