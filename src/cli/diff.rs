//! `lodeval diff REF TEST`: two images scored with the perceptual metrics.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use lodeval::Error;
use lodeval::app::DiffMetric;

use super::args::{BackendArg, value};
use super::print::{emit, emit_json, warnings};

/// `--metric`.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum MetricArg {
    /// ꟻLIP mean error.
    Flip,
    /// SSIM on sRGB luma.
    Ssim,
    /// Multi-scale SSIM (images of at least 176×176).
    Msssim,
    /// PSNR of linear luminance.
    Psnr,
    /// MSE of linear luminance.
    Mse,
    /// The visible-difference predictor (probability and JND).
    Vdp,
    /// Every metric (those that do not apply to the image size say why).
    All,
}

impl MetricArg {
    /// The metrics it asks for.
    fn metrics(self) -> Vec<DiffMetric> {
        match self {
            MetricArg::Flip => vec![DiffMetric::Flip],
            MetricArg::Ssim => vec![DiffMetric::Ssim],
            MetricArg::Msssim => vec![DiffMetric::Msssim],
            MetricArg::Psnr => vec![DiffMetric::Psnr],
            MetricArg::Mse => vec![DiffMetric::Mse],
            MetricArg::Vdp => vec![DiffMetric::Vdp],
            MetricArg::All => DiffMetric::ALL.to_vec(),
        }
    }
}

#[derive(Args, Debug)]
pub(crate) struct DiffArgs {
    /// Reference image (PNG/JPEG: sRGB; EXR: linear).
    pub(crate) reference: PathBuf,
    /// Where FLIP, MSE and PSNR run: cpu, gpu (compute kernels) or auto.
    #[arg(long, value_enum, default_value_t = BackendArg::Cpu)]
    pub(crate) backend: BackendArg,
    /// Test image, same size.
    pub(crate) test: PathBuf,
    /// Metric: flip, ssim, msssim, psnr, mse, vdp or all.
    #[arg(long, value_enum, default_value_t = MetricArg::Flip)]
    pub(crate) metric: MetricArg,
    /// Pixels per degree of visual angle (overrides the display flags).
    #[arg(long, conflicts_with_all = ["display_width_m", "display_px", "distance_m"],
          value_parser = value(&lodeval::limits::PPD))]
    pub(crate) ppd: Option<f64>,
    /// Display width in metres.
    #[arg(long, default_value_t = 0.7)]
    pub(crate) display_width_m: f64,
    /// Display width in pixels.
    #[arg(long, default_value_t = 3840.0)]
    pub(crate) display_px: f64,
    /// Viewing distance in metres.
    #[arg(long, default_value_t = 0.7)]
    pub(crate) distance_m: f64,
    /// VDP display model: luminance of white, cd/m².
    #[arg(long, default_value_t = 100.0)]
    pub(crate) peak_cd_m2: f32,
    /// VDP display model: luminance of black in a dark room, cd/m².
    #[arg(long, default_value_t = 0.5)]
    pub(crate) black_cd_m2: f32,
    /// VDP display model: room light on the screen, lux.
    #[arg(long, default_value_t = 250.0)]
    pub(crate) ambient_lux: f32,
    /// VDP display model: fraction of the room light the screen reflects.
    #[arg(long, default_value_t = 0.005)]
    pub(crate) reflectivity: f32,
    /// Write a magma heat map of the error here (FLIP error, 1 − SSIM, or the VDP's detection
    /// probability).
    #[arg(long)]
    pub(crate) map: Option<PathBuf>,
    /// Print JSON (an array, one object per metric).
    #[arg(long)]
    pub(crate) json: bool,
}

/// Run `diff`.
pub(crate) fn run(a: DiffArgs) -> Result<(), Error> {
    let metrics = a.metric.metrics();
    let viewing = match a.ppd {
        Some(p) => lodeval::scene::Viewing::from_ppd(p),
        None => {
            lodeval::scene::Viewing::from_display(a.display_width_m, a.display_px, a.distance_m)
        }
    };
    viewing.check().map_err(Error::Usage)?;
    // With `all`, metrics that do not apply to this image size report a note instead.
    let lenient = a.metric == MetricArg::All;
    let engine = lodeval::backend::Engine::new(a.backend.into())?;
    warnings(
        &engine
            .fallback()
            .map(str::to_string)
            .into_iter()
            .collect::<Vec<_>>(),
    );
    let display = lodeval::metric::vdp::Display::new(
        a.peak_cd_m2,
        a.black_cd_m2,
        a.ambient_lux,
        a.reflectivity,
    )?;
    let results = lodeval::app::diff(
        &engine,
        &a.reference,
        &a.test,
        &metrics,
        &lodeval::app::Seen { viewing, display },
        a.map.as_deref(),
        lenient,
    )?;
    if a.json {
        emit_json(&results)
    } else {
        let mut text = String::new();
        for r in &results {
            let name = serde_json::to_value(r.metric)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_default();
            let value = match (r.value, &r.note) {
                (Some(v), _) => format!("{v:.6}"),
                (None, Some(note)) => format!("-  ({note})"),
                (None, None) => "inf".to_string(),
            };
            text.push_str(&format!("{name:<7} {value}"));
            if let Some(p) = &r.percentiles {
                text.push_str(&format!(
                    "  (p95 {:.4}, max {:.4}, {:.2} ppd)",
                    p["p95"], p["max"], r.ppd
                ));
            }
            if let Some(j) = r.jnd {
                text.push_str(&format!("  ({j:.3} JND, {:.2} ppd)", r.ppd));
            }
            if let Some(m) = &r.map {
                text.push_str(&format!("  map: {}", m.display()));
            }
            text.push('\n');
        }
        emit(&text)
    }
}
