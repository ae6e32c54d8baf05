//! `lodeval diff`: two images scored with the perceptual metrics, with optional heat maps.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// The metrics `lodeval diff` computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum DiffMetric {
    /// ꟻLIP mean error in [0, 1].
    Flip,
    /// SSIM (sRGB luma) in [−1, 1].
    Ssim,
    /// MS-SSIM (sRGB luma) in [0, 1].
    Msssim,
    /// PSNR of linear luminance, dB.
    Psnr,
    /// MSE of linear luminance.
    Mse,
    /// Visible-difference predictor: value = detection probability in [0, 1]; `jnd` also given.
    Vdp,
}

impl DiffMetric {
    /// Every metric `diff` can compute, in output order.
    pub const ALL: [DiffMetric; 6] = [
        DiffMetric::Flip,
        DiffMetric::Ssim,
        DiffMetric::Msssim,
        DiffMetric::Psnr,
        DiffMetric::Mse,
        DiffMetric::Vdp,
    ];
}

/// One metric's result for `lodeval diff`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct DiffResult {
    /// Metric name.
    pub metric: DiffMetric,
    /// The pooled value (see [`DiffMetric`] for units); `null` in JSON for an infinite PSNR.
    pub value: Option<f64>,
    /// Pixels per degree used.
    pub ppd: f64,
    /// Image width.
    pub width: usize,
    /// Image height.
    pub height: usize,
    /// FLIP only: percentiles p25, p50, p75, p95, p99 and the maximum of the error map, and FLIP's
    /// weighted percentiles (`weighted_p25`, `weighted_median`, `weighted_p75`; each error weighted
    /// by itself, as NVIDIA's tool reports them).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub percentiles: Option<std::collections::BTreeMap<String, f64>>,
    /// VDP only: the difference in just-noticeable differences.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub jnd: Option<f64>,
    /// FLIP only: histogram of the error map, 20 bins over [0, 1].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub histogram: Option<Vec<u64>>,
    /// The heat map written, if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub map: Option<PathBuf>,
    /// Why the value is missing, when a metric of `--metric all` does not apply to these images.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// Where the metric ran: `cpu`, or `gpu: ADAPTER …` for FLIP, MSE and PSNR on the GPU.
    pub backend: String,
}

/// Where and on what the compared images are seen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Seen {
    /// The viewer's geometry (pixels per degree).
    pub viewing: crate::scene::Viewing,
    /// The display (the VDP's luminance model).
    pub display: crate::metric::vdp::Display,
}

/// Compare two image files with the given metrics; writes magma heat maps if `map` is given
/// (`map` itself for one metric with a map, `STEM-METRIC.png` beside it for several). With
/// `lenient`, a metric that does not apply to images of this size (SSIM below 11×11, MS-SSIM
/// below 176×176) is reported without a value and with a note instead of failing the command.
pub fn diff(
    engine: &crate::backend::Engine,
    reference: &Path,
    test: &Path,
    metrics: &[DiffMetric],
    seen: &Seen,
    map: Option<&Path>,
    lenient: bool,
) -> Result<Vec<DiffResult>> {
    use crate::metric::{LinearImage, colormap, flip::Flip, pool, ssim};
    let (a, b) = (LinearImage::load(reference)?, LinearImage::load(test)?);
    if (a.width(), a.height()) != (b.width(), b.height()) {
        return Err(Error::input(
            test,
            format!(
                "is {}x{} but the reference {} is {}x{}",
                b.width(),
                b.height(),
                reference.display(),
                a.width(),
                a.height()
            ),
            "compare images of the same size",
        ));
    }
    let pixels = (a.width() * a.height()) as u64;
    crate::limits::check_memory(
        &format!("scoring {}x{} pixels", a.width(), a.height()),
        pixels * crate::limits::BYTES_PER_SCORED_PIXEL,
    )
    .map_err(Error::Usage)?;
    let viewing = &seen.viewing;
    let vdp = crate::metric::vdp::Vdp::checked(viewing, seen.display)?;
    let ppd = viewing.ppd();
    let (w, h) = (a.width(), a.height());
    let with_maps = metrics
        .iter()
        .filter(|m| matches!(m, DiffMetric::Flip | DiffMetric::Ssim | DiffMetric::Vdp))
        .count();
    let map_path = |metric: DiffMetric| -> Option<PathBuf> {
        let p = map?;
        if with_maps <= 1 {
            return Some(p.to_path_buf());
        }
        let stem = p.file_stem()?.to_string_lossy();
        let name = serde_json::to_value(metric).ok()?.as_str()?.to_string();
        Some(p.with_file_name(format!("{stem}-{name}.png")))
    };
    let mut out = Vec::new();
    for &metric in metrics {
        let mut r = DiffResult {
            metric,
            value: None,
            ppd,
            width: w,
            height: h,
            percentiles: None,
            histogram: None,
            map: None,
            note: None,
            jnd: None,
            backend: match metric {
                DiffMetric::Flip | DiffMetric::Mse | DiffMetric::Psnr => engine.describe(),
                _ => crate::backend::CPU_RENDERER.to_string(),
            },
        };
        let mut compute = || -> Result<()> {
            match metric {
                DiffMetric::Flip => {
                    let s = engine.flip(&Flip::new(ppd as f32), &a, &b)?;
                    let v = &s.map.values;
                    let mut p = std::collections::BTreeMap::new();
                    for q in [25.0, 50.0, 75.0, 95.0, 99.0] {
                        p.insert(format!("p{q}"), pool::percentile(v, q));
                    }
                    // FLIP's weighted percentiles (what NVIDIA's tool reports).
                    p.insert("weighted_p25".into(), pool::weighted_percentile(v, 0.25));
                    p.insert("weighted_median".into(), pool::weighted_percentile(v, 0.5));
                    p.insert("weighted_p75".into(), pool::weighted_percentile(v, 0.75));
                    p.insert("max".into(), pool::max(v));
                    r.value = Some(s.mean);
                    r.percentiles = Some(p);
                    r.histogram = Some(pool::histogram(v, 20));
                    if let Some(path) = map_path(metric) {
                        crate::io::write_image(
                            &path,
                            &image::DynamicImage::ImageRgb8(colormap::heat_map(
                                v,
                                w,
                                h,
                                (h / 32).max(4),
                            )),
                        )?;
                        r.map = Some(path);
                    }
                }
                DiffMetric::Ssim => {
                    let (mean, smap) = ssim::ssim(&a, &b, ssim::SsimInput::SrgbLuma)?;
                    r.value = Some(mean);
                    if let Some(path) = map_path(metric) {
                        let err: Vec<f32> =
                            smap.iter().map(|s| (1.0 - s).clamp(0.0, 1.0)).collect();
                        crate::io::write_image(
                            &path,
                            &image::DynamicImage::ImageRgb8(colormap::heat_map(
                                &err,
                                w,
                                h,
                                (h / 32).max(4),
                            )),
                        )?;
                        r.map = Some(path);
                    }
                }
                DiffMetric::Msssim => {
                    r.value = Some(ssim::ms_ssim(&a, &b, ssim::SsimInput::SrgbLuma)?)
                }
                DiffMetric::Psnr => r.value = Some(engine.mse(&a, &b)?.psnr_db),
                DiffMetric::Mse => r.value = Some(engine.mse(&a, &b)?.mse),
                DiffMetric::Vdp => {
                    let s = vdp.compare(&a, &b)?;
                    r.value = Some(s.probability);
                    r.jnd = Some(s.jnd);
                    if let Some(path) = map_path(metric) {
                        let img = colormap::heat_map(&s.map.values, w, h, (h / 32).max(4));
                        crate::io::write_image(&path, &image::DynamicImage::ImageRgb8(img))?;
                        r.map = Some(path);
                    }
                }
            }
            Ok(())
        };
        match compute() {
            Err(Error::Usage(why)) if lenient => r.note = Some(why),
            other => other?,
        }
        out.push(r);
    }
    Ok(out)
}
