//! `lodeval diff`: two images scored with the perceptual metrics, with optional heat maps.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::metric::Metric;

/// What `diff --metric` asks for: one metric of [`Metric::DIFF`], or `all` of them. Its command
/// line names and help come from `metric::catalog`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MetricChoice(pub Option<Metric>);

impl MetricChoice {
    /// The metrics it asks for, in output order.
    pub fn metrics(self) -> Vec<Metric> {
        match self.0 {
            Some(m) => vec![m],
            None => Metric::DIFF.to_vec(),
        }
    }
}

impl clap::ValueEnum for MetricChoice {
    fn value_variants<'a>() -> &'a [Self] {
        const CHOICES: [MetricChoice; 8] = {
            let mut c = [MetricChoice(None); 8];
            let mut i = 0;
            while i < Metric::DIFF.len() {
                c[i] = MetricChoice(Some(Metric::DIFF[i]));
                i += 1;
            }
            c
        };
        &CHOICES
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        use clap::builder::PossibleValue;
        Some(match self.0 {
            Some(m) => PossibleValue::new(m.name().replace('_', "-")).help(m.entry().what),
            None => PossibleValue::new("all")
                .help("Every metric (those that do not apply to the image size say why)"),
        })
    }
}

/// One metric's result for `lodeval diff`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct DiffResult {
    /// Metric name.
    pub metric: Metric,
    /// The pooled value (units in `metric::catalog`); `null` in JSON for an infinite PSNR.
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
    /// For metrics with a per-pixel map (FLIP error, 1 − SSIM, the VDP's detection probability):
    /// the worst pixel, first in row order where several are equally bad.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub worst_pixel: Option<WorstPixel>,
    /// With a per-pixel threshold: the share of pixels (0–1) whose map value exceeds it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub share_over: Option<f64>,
    /// FLIP on two EXR (linear, high-dynamic-range) images is HDR-FLIP: the exposures it used.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exposures: Option<crate::metric::hdr_flip::Exposures>,
    /// When both images are renders on a plain background and the object in the test image is
    /// moved or scaled against the reference's ([`crate::image::Silhouette::misframed`]): what
    /// moved, and how to render the two alike. The scores then measure the framing, not the LOD.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub framing: Option<String>,
}

/// The hint for two renders whose objects sit differently in the frame, if they do.
pub fn framing_hint(
    reference: &crate::image::LinearImage,
    test: &crate::image::LinearImage,
) -> Option<String> {
    let (a, b) = (reference.silhouette()?, test.silhouette()?);
    let (shift, ratio) = a.misframed(&b)?;
    Some(format!(
        "the object looks framed differently in the two images (its centre moved {shift:.1} px, \
         its area is {:.0} % of the reference's), so the scores measure the framing as well as \
         the shape. If each was rendered on its own, render the LOD with `lodeval render LOD \
         --frame-like ORIGINAL` (or score both with `lodeval compare ORIGINAL LOD`)",
        100.0 * ratio
    ))
}

/// The worst pixel of a per-pixel map.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct WorstPixel {
    /// Column, from the left.
    pub x: usize,
    /// Row, from the top.
    pub y: usize,
    /// The map's value there (larger is worse).
    pub value: f64,
}

impl DiffGates {
    /// `Err` with the reason when a gate can never fail or always fails for `metric`: a limit
    /// outside the metric's range, a percentage outside [0, 100), a pixel threshold outside
    /// [0, 1) of the map's values.
    pub fn check(&self, metric: Metric) -> std::result::Result<(), String> {
        for (flag, v) in [("--fail", self.fail), ("--warn", self.warn)] {
            if let Some(v) = v {
                metric.check_limit(flag, v)?;
            }
        }
        for (flag, v) in [
            ("--fail-percent", self.fail_percent),
            ("--warn-percent", self.warn_percent),
        ] {
            if let Some(v) = v.filter(|v| !(0.0..100.0).contains(v)) {
                return Err(format!(
                    "{flag} {v}: a share of pixels lies in [0, 100) %; at {v} the gate could \
                     never fail (or always would)"
                ));
            }
        }
        if let Some(p) = self.pixel.filter(|p| !(0.0..1.0).contains(p)) {
            return Err(format!(
                "--fail-pixel {p}: the per-pixel maps lie in [0, 1], so no pixel would ever be \
                 counted (or every one would); give a threshold in [0, 1)"
            ));
        }
        Ok(())
    }
}

/// Pass/warn/fail limits on one metric, as idiff and NVIDIA's FLIP tool take them.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DiffGates {
    /// Fail when the pooled value is worse than this.
    pub fail: Option<f64>,
    /// Warn when the pooled value is worse than this.
    pub warn: Option<f64>,
    /// Fail when more than this percentage of pixels exceed `pixel`.
    pub fail_percent: Option<f64>,
    /// Warn when more than this percentage of pixels exceed `pixel`.
    pub warn_percent: Option<f64>,
    /// The per-pixel threshold of the percentage gates (on the metric's map, larger is worse).
    pub pixel: Option<f64>,
}

/// What the gates say of one result: `None` when it passes, else the reason.
pub fn judge(r: &DiffResult, gates: &DiffGates) -> (Option<String>, Option<String>) {
    let worse = |v: f64, limit: f64| {
        if r.metric.higher_is_worse() {
            v > limit
        } else {
            v < limit
        }
    };
    let name = r.metric.name();
    let over = |limit: Option<f64>, verb: &str| -> Option<String> {
        let (limit, v) = (limit?, r.value?);
        worse(v, limit).then(|| {
            format!(
                "{name} {} is {} the {verb} limit {}",
                crate::limits::Quantity::show(v),
                if r.metric.higher_is_worse() {
                    "above"
                } else {
                    "below"
                },
                crate::limits::Quantity::show(limit)
            )
        })
    };
    let share = |limit: Option<f64>, verb: &str| -> Option<String> {
        let (limit, s) = (limit?, r.share_over?);
        (100.0 * s > limit).then(|| {
            format!(
                "{:.3} % of pixels have {name} above {}, more than the {verb} limit of {limit} %",
                100.0 * s,
                gates.pixel.unwrap_or(0.0)
            )
        })
    };
    let fail = over(gates.fail, "fail").or_else(|| share(gates.fail_percent, "fail"));
    let warn = over(gates.warn, "warn").or_else(|| share(gates.warn_percent, "warn"));
    (fail, warn)
}

/// What `diff` writes and how it treats metrics that do not apply.
#[derive(Debug, Clone, Copy, Default)]
#[non_exhaustive]
pub struct DiffOptions<'a> {
    /// Heat map path (see [`diff`]).
    pub map: Option<&'a Path>,
    /// Report a metric that does not apply to the image size with a note instead of failing.
    pub lenient: bool,
    /// A per-pixel threshold: each per-pixel map also gives the share of pixels above it.
    pub pixel_threshold: Option<f64>,
    /// HDR-FLIP's exposure range for EXR pairs (else the automatic one).
    pub exposures: Option<crate::metric::hdr_flip::Exposures>,
}

impl DiffOptions<'_> {
    /// No heat map, strict about sizes, no per-pixel threshold, automatic HDR exposures.
    pub const DEFAULT: DiffOptions<'static> = DiffOptions {
        map: None,
        lenient: false,
        pixel_threshold: None,
        exposures: None,
    };
}

/// Where and on what the compared images are seen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Seen {
    /// The viewer's geometry (pixels per degree).
    pub viewing: crate::scene::Viewing,
    /// The display (the VDP's luminance model).
    pub display: crate::metric::vdp::Display,
}

/// Whether `path` names an EXR file (linear, high-dynamic-range): FLIP on two of them is
/// HDR-FLIP, as NVIDIA's tool decides by the files.
pub fn is_exr(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
}

/// What every metric of one comparison shares.
struct Pair<'a> {
    engine: &'a crate::backend::Engine,
    a: crate::metric::LinearImage,
    b: crate::metric::LinearImage,
    hdr: bool,
    ppd: f64,
    vdp: crate::metric::vdp::Vdp,
    exposures: Option<crate::metric::hdr_flip::Exposures>,
}

/// Load two images of the same size, within the memory bound.
fn load_pair(
    reference: &Path,
    test: &Path,
) -> Result<(crate::metric::LinearImage, crate::metric::LinearImage)> {
    use crate::metric::LinearImage;
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
    Ok((a, b))
}

/// Compare two image files with the given metrics; writes magma heat maps if `options.map` is
/// given (that path for one metric with a map, `STEM-METRIC.png` beside it for several). With
/// `options.lenient`, a metric that does not apply to images of this size (SSIM below 11×11, MS-SSIM
/// below 176×176) is reported without a value and with a note instead of failing the command.
/// With `options.pixel_threshold`, each per-pixel map also gives the share of pixels above it.
pub fn diff(
    engine: &crate::backend::Engine,
    reference: &Path,
    test: &Path,
    metrics: &[Metric],
    seen: &Seen,
    options: &DiffOptions<'_>,
) -> Result<Vec<DiffResult>> {
    let (a, b) = load_pair(reference, test)?;
    let pair = Pair {
        engine,
        hdr: is_exr(reference) && is_exr(test),
        ppd: seen.viewing.ppd(),
        vdp: crate::metric::vdp::Vdp::checked(&seen.viewing, seen.display)?,
        exposures: options.exposures,
        a,
        b,
    };
    let with_maps = metrics.iter().filter(|m| m.has_map()).count();
    let map_path = |metric: Metric| -> Option<PathBuf> {
        let p = options.map.filter(|_| metric.has_map())?;
        if with_maps <= 1 {
            return Some(p.to_path_buf());
        }
        let stem = p.file_stem()?.to_string_lossy();
        Some(p.with_file_name(format!("{stem}-{}.png", metric.name())))
    };
    // No map may replace the images it compares (`--map ref.png`).
    let maps: Vec<PathBuf> = metrics.iter().filter_map(|&m| map_path(m)).collect();
    crate::io::check_not_inputs(&maps, &[reference.to_path_buf(), test.to_path_buf()])?;
    let (w, h) = (pair.a.width(), pair.a.height());
    let framing = framing_hint(&pair.a, &pair.b);
    let mut out = Vec::new();
    for &metric in metrics {
        let mut r = DiffResult {
            metric,
            value: None,
            ppd: pair.ppd,
            width: w,
            height: h,
            percentiles: None,
            histogram: None,
            map: None,
            note: None,
            jnd: None,
            backend: match metric {
                Metric::Flip | Metric::Mse | Metric::PsnrLuminance => engine.describe(),
                _ => crate::backend::CPU_RENDERER.to_string(),
            },
            worst_pixel: None,
            share_over: None,
            exposures: None,
            framing: framing.clone(),
        };
        let mut values = None;
        let scored = score(&pair, &mut r).and_then(|v| {
            values = v;
            match (&values, map_path(metric)) {
                (Some(v), Some(path)) => {
                    let img = crate::metric::colormap::heat_map(v, w, h, (h / 32).max(4));
                    crate::io::write_image(&path, &image::DynamicImage::ImageRgb8(img))?;
                    r.map = Some(path);
                    Ok(())
                }
                _ => Ok(()),
            }
        });
        match scored {
            Err(Error::Usage(why)) if options.lenient => r.note = Some(why),
            other => other?,
        }
        if let Some(v) = &values {
            pixel_stats(&mut r, v, options.pixel_threshold);
        }
        out.push(r);
    }
    Ok(out)
}

/// Score `r.metric` on `pair` into `r`; returns the per-pixel map (larger is worse) where the
/// metric has one.
fn score(pair: &Pair<'_>, r: &mut DiffResult) -> Result<Option<Vec<f32>>> {
    use crate::metric::{flip::Flip, pool, ssim};
    let (a, b) = (&pair.a, &pair.b);
    match r.metric {
        Metric::Flip => {
            let s = if pair.hdr {
                let flip = Flip::new(pair.ppd as f32);
                let h = crate::metric::hdr_flip::hdr_flip(&flip, a, b, pair.exposures)?;
                r.exposures = Some(h.exposures);
                r.backend = crate::backend::CPU_RENDERER.to_string();
                crate::metric::flip::FlipScore {
                    mean: h.mean,
                    map: h.map,
                }
            } else {
                pair.engine.flip(&Flip::new(pair.ppd as f32), a, b)?
            };
            let v = s.map.values;
            let mut p = std::collections::BTreeMap::new();
            for q in [25.0, 50.0, 75.0, 95.0, 99.0] {
                p.insert(format!("p{q}"), pool::percentile(&v, q).unwrap_or(0.0));
            }
            // FLIP's weighted percentiles (what NVIDIA's tool reports).
            p.insert("weighted_p25".into(), pool::weighted_percentile(&v, 0.25));
            p.insert("weighted_median".into(), pool::weighted_percentile(&v, 0.5));
            p.insert("weighted_p75".into(), pool::weighted_percentile(&v, 0.75));
            p.insert("max".into(), pool::max(&v));
            r.value = Some(s.mean);
            r.percentiles = Some(p);
            r.histogram = Some(pool::histogram(&v, 20));
            Ok(Some(v))
        }
        Metric::Ssim => {
            let (mean, smap) = ssim::ssim(a, b, ssim::SsimInput::SrgbLuma)?;
            r.value = Some(mean);
            Ok(Some(
                smap.iter().map(|s| (1.0 - s).clamp(0.0, 1.0)).collect(),
            ))
        }
        Metric::Msssim => {
            r.value = Some(ssim::ms_ssim(a, b, ssim::SsimInput::SrgbLuma)?);
            Ok(None)
        }
        Metric::Psnr => {
            r.value = Some(crate::metric::mse::psnr_srgb8(a, b)?);
            Ok(None)
        }
        Metric::PsnrLuminance => {
            r.value = Some(pair.engine.mse(a, b)?.psnr_db);
            Ok(None)
        }
        Metric::Mse => {
            r.value = Some(pair.engine.mse(a, b)?.mse);
            Ok(None)
        }
        Metric::Vdp => {
            let s = pair.vdp.compare(a, b)?;
            r.value = Some(s.probability);
            r.jnd = Some(s.jnd);
            Ok(Some(s.map.values))
        }
        other @ (Metric::FlipP95 | Metric::FlipShare | Metric::VdpJnd) => {
            Err(Error::Usage(format!(
                "diff does not compute {other}: it reports FLIP's percentiles and the VDP's JND with flip and vdp"
            )))
        }
    }
}

/// The worst pixel of a per-pixel map and, with a threshold, the share of pixels above it.
fn pixel_stats(r: &mut DiffResult, values: &[f32], threshold: Option<f64>) {
    let mut worst: Option<(usize, f32)> = None;
    for (i, &v) in values.iter().enumerate() {
        if worst.is_none_or(|(_, w)| v > w) {
            worst = Some((i, v));
        }
    }
    let w = r.width.max(1);
    r.worst_pixel = worst.map(|(i, v)| WorstPixel {
        x: i % w,
        y: i / w,
        value: v as f64,
    });
    if let Some(t) = threshold {
        let over = values.iter().filter(|&&v| v as f64 > t).count();
        r.share_over = Some(over as f64 / values.len().max(1) as f64);
    }
}
