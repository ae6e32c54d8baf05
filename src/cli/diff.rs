//! `lodeval diff REF TEST`: two images scored with the perceptual metrics.

use std::path::PathBuf;

use clap::Args;
use lodeval::Error;
use lodeval::app::MetricChoice;
use lodeval::backend::Backend;
use lodeval::metric::Metric;

use super::args::value;
use super::print::{emit, emit_json, warnings};

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  lodeval diff expected.png actual.png --metric flip --fail 0.05\n  lodeval diff ref.png a.png b.png --fail-percent 0.5 --fail-pixel 0.1 --csv diff.csv\n\nExit codes: 0 pass (or warn, with a warning line) · 1 a --fail gate failed · 2 bad input or usage · 3 internal error"
)]
pub(crate) struct DiffArgs {
    /// Reference image (PNG/JPEG: sRGB; EXR: linear).
    pub(crate) reference: PathBuf,
    /// Where FLIP, MSE and PSNR run: cpu, gpu (compute kernels) or auto.
    #[arg(long, value_enum, default_value_t = Backend::Cpu)]
    pub(crate) backend: Backend,
    /// Test image(s), each the reference's size; each is compared with the reference.
    #[arg(required = true, num_args = 1..)]
    pub(crate) test: Vec<PathBuf>,
    /// Metric: flip, ssim, msssim, psnr, mse, vdp or all.
    #[arg(long, value_enum, default_value_t = MetricChoice(Some(Metric::Flip)))]
    pub(crate) metric: MetricChoice,
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
    /// Fail (exit 1) when the gated metric's pooled value is worse than this (above it for
    /// flip, mse and vdp; below it for ssim, msssim and psnr). The gated metric is --metric's
    /// (flip for `all`).
    #[arg(long, value_parser = super::args::finite)]
    pub(crate) fail: Option<f64>,
    /// Warn (exit 0, a warning line) when the pooled value is worse than this.
    #[arg(long, value_parser = super::args::finite)]
    pub(crate) warn: Option<f64>,
    /// Fail when more than this percentage of pixels exceed --fail-pixel on the gated metric's
    /// map (FLIP error, 1 − SSIM, or the VDP's detection probability).
    #[arg(long, requires = "fail_pixel", value_parser = super::args::finite)]
    pub(crate) fail_percent: Option<f64>,
    /// Warn when more than this percentage of pixels exceed --fail-pixel.
    #[arg(long, requires = "fail_pixel", value_parser = super::args::finite)]
    pub(crate) warn_percent: Option<f64>,
    /// The per-pixel threshold of --fail-percent and --warn-percent, in the map's units (0–1).
    #[arg(long, value_parser = super::args::finite)]
    pub(crate) fail_pixel: Option<f64>,
    /// HDR-FLIP (two EXR images): the shortest exposure, in stops (with --stop-exposure and
    /// --num-exposures; default: NVIDIA's automatic range from the reference's peak and median).
    #[arg(long, allow_negative_numbers = true, requires_all = ["stop_exposure", "num_exposures"],
          value_parser = value(&lodeval::limits::EXPOSURE_STOPS))]
    pub(crate) start_exposure: Option<f64>,
    /// HDR-FLIP: the longest exposure, in stops.
    #[arg(long, allow_negative_numbers = true, requires_all = ["start_exposure", "num_exposures"],
          value_parser = value(&lodeval::limits::EXPOSURE_STOPS))]
    pub(crate) stop_exposure: Option<f64>,
    /// HDR-FLIP: the number of exposures, 1 to 64.
    #[arg(long, requires_all = ["start_exposure", "stop_exposure"],
          value_parser = super::args::count::<usize>(&lodeval::limits::EXPOSURES))]
    pub(crate) num_exposures: Option<usize>,
    /// Also write every result as CSV here (reference, test, metric, value, the worst pixel, the
    /// share over --fail-pixel, the verdict).
    #[arg(long)]
    pub(crate) csv: Option<PathBuf>,
    /// Print JSON (an array, one object per metric; with several test images, one object per
    /// image with its results and verdict).
    #[arg(long)]
    pub(crate) json: bool,
}

/// One row of `--csv`.
#[derive(serde::Serialize)]
struct CsvRow<'a> {
    reference: String,
    test: String,
    metric: &'a str,
    value: Option<f64>,
    jnd: Option<f64>,
    worst_x: Option<usize>,
    worst_y: Option<usize>,
    worst_value: Option<f64>,
    share_over: Option<f64>,
    verdict: &'a str,
}

/// One test image's results and verdict, for JSON with several images.
#[derive(serde::Serialize)]
struct PerTest<'a> {
    test: &'a std::path::Path,
    results: &'a [lodeval::app::DiffResult],
    verdict: &'a str,
    reasons: Vec<String>,
}

/// Run `diff`.
pub(crate) fn run(a: DiffArgs) -> Result<(), Error> {
    let metrics = a.metric.metrics();
    // With `all`, metrics that do not apply to this image size report a note instead.
    let lenient = a.metric.0.is_none();
    let engine = lodeval::backend::Engine::new(a.backend)?;
    warnings(
        &engine
            .fallback()
            .map(str::to_string)
            .into_iter()
            .collect::<Vec<_>>(),
    );
    let gates = lodeval::app::DiffGates {
        fail: a.fail,
        warn: a.warn,
        fail_percent: a.fail_percent,
        warn_percent: a.warn_percent,
        pixel: a.fail_pixel,
    };
    let gated = metrics[0];
    if (a.fail_percent.is_some() || a.warn_percent.is_some()) && !gated.has_map() {
        return Err(Error::Usage(format!(
            "--fail-percent and --warn-percent need a per-pixel map: use --metric flip, ssim or \
             vdp, not {}",
            gated.name()
        )));
    }
    gates.check(gated).map_err(Error::Usage)?;
    let is_exr = lodeval::app::is_exr;
    let all_exr = is_exr(&a.reference) && a.test.iter().all(|t| is_exr(t));
    if a.start_exposure.is_some() && !(all_exr && metrics.contains(&Metric::Flip)) {
        warnings(&["--start-exposure, --stop-exposure and --num-exposures apply to HDR-FLIP                     (--metric flip on two EXR images) only; they do nothing here"
            .to_string()]);
    }
    // No output of this run may replace one of its images.
    let inputs: Vec<PathBuf> = std::iter::once(a.reference.clone())
        .chain(a.test.iter().cloned())
        .collect();
    let outputs: Vec<PathBuf> = a.csv.iter().chain(a.map.iter()).cloned().collect();
    lodeval::io::check_not_inputs(&outputs, &inputs)?;
    let seen = seen(&a)?;
    let several = a.test.len() > 1;
    let mut all = Vec::new();
    for test in &a.test {
        // With several test images, each one's heat map is named after it.
        let map = a.map.as_ref().map(|m| {
            if several {
                let stem = test.file_stem().unwrap_or_default().to_string_lossy();
                let base = m.file_stem().unwrap_or_default().to_string_lossy();
                m.with_file_name(format!("{base}-{stem}.png"))
            } else {
                m.clone()
            }
        });
        let mut options = lodeval::app::DiffOptions::DEFAULT;
        options.map = map.as_deref();
        options.lenient = lenient;
        options.pixel_threshold = a.fail_pixel;
        if let (Some(start), Some(stop), Some(count)) =
            (a.start_exposure, a.stop_exposure, a.num_exposures)
        {
            options.exposures = Some(lodeval::metric::hdr_flip::Exposures { start, stop, count });
        }
        let results = lodeval::app::diff(&engine, &a.reference, test, &metrics, &seen, &options)?;
        let gate_row = results.iter().find(|r| r.metric == gated);
        let (fail, warn) = gate_row.map_or((None, None), |r| lodeval::app::judge(r, &gates));
        all.push((test.clone(), results, fail, warn));
    }
    if let Some(path) = &a.csv {
        write_csv(&a, path, &all, gated)?;
    }
    print(&a, &all)?;
    let mut failed = Vec::new();
    for (test, results, fail, warn) in &all {
        if let Some(hint) = results.first().and_then(|r| r.framing.as_ref()) {
            note!("warning: {}: {hint}", test.display());
        }
        if let Some(w) = warn
            && fail.is_none()
        {
            note!("warning: {}: {w}", test.display());
        }
        if let Some(f) = fail {
            failed.push(format!("{}: {f}", test.display()));
        }
    }
    if failed.is_empty() {
        Ok(())
    } else {
        Err(Error::Regression(failed.join("; ")))
    }
}

/// One test image's results and the gate's verdict: (test, results, fail, warn).
type Judged = (
    PathBuf,
    Vec<lodeval::app::DiffResult>,
    Option<String>,
    Option<String>,
);

/// `fail`, `warn` or `pass`.
fn verdict(fail: &Option<String>, warn: &Option<String>) -> &'static str {
    if fail.is_some() {
        "fail"
    } else if warn.is_some() {
        "warn"
    } else {
        "pass"
    }
}

/// The viewing geometry and the display, checked.
fn seen(a: &DiffArgs) -> Result<lodeval::app::Seen, Error> {
    let viewing = match a.ppd {
        Some(p) => lodeval::scene::Viewing::from_ppd(p),
        None => {
            lodeval::scene::Viewing::from_display(a.display_width_m, a.display_px, a.distance_m)
        }
    };
    viewing.check().map_err(Error::Usage)?;
    let display = lodeval::metric::vdp::Display::new(
        a.peak_cd_m2,
        a.black_cd_m2,
        a.ambient_lux,
        a.reflectivity,
    )?;
    Ok(lodeval::app::Seen { viewing, display })
}

/// `--csv`: every result of every test image, with the gated metric's verdict.
fn write_csv(
    a: &DiffArgs,
    path: &std::path::Path,
    all: &[Judged],
    gated: Metric,
) -> Result<(), Error> {
    let mut rows = Vec::new();
    for (test, results, fail, warn) in all {
        for r in results {
            rows.push(CsvRow {
                reference: a.reference.display().to_string(),
                test: test.display().to_string(),
                metric: r.metric.name(),
                value: r.value,
                jnd: r.jnd,
                worst_x: r.worst_pixel.map(|w| w.x),
                worst_y: r.worst_pixel.map(|w| w.y),
                worst_value: r.worst_pixel.map(|w| w.value),
                share_over: r.share_over,
                verdict: if r.metric == gated {
                    verdict(fail, warn)
                } else {
                    ""
                },
            });
        }
    }
    lodeval::io::csv::write_rows(path, None, &rows)?;
    Ok(())
}

/// The results as JSON (`--json`) or text.
fn print(a: &DiffArgs, all: &[Judged]) -> Result<(), Error> {
    let several = all.len() > 1;
    if a.json {
        if several {
            let per: Vec<PerTest> = all
                .iter()
                .map(|(test, results, fail, warn)| PerTest {
                    test,
                    results,
                    verdict: verdict(fail, warn),
                    reasons: fail.iter().chain(warn).cloned().collect(),
                })
                .collect();
            emit_json(&per)?;
        } else {
            emit_json(&all[0].1)?;
        }
    } else {
        let mut text = String::new();
        for (test, results, _, _) in all {
            if several {
                text.push_str(&format!("{}:\n", test.display()));
            }
            for r in results {
                text.push_str(&line(r));
            }
        }
        emit(&text)?;
    }
    Ok(())
}

/// One metric's line of text.
fn line(r: &lodeval::app::DiffResult) -> String {
    let value = match (r.value, &r.note) {
        (Some(v), _) => format!("{v:.6}"),
        (None, Some(note)) => format!("-  ({note})"),
        (None, None) => "inf".to_string(),
    };
    let mut text = format!("{:<7} {value}", r.metric.name());
    if let Some(p) = &r.percentiles {
        text.push_str(&format!(
            "  (p95 {:.4}, max {:.4}, {:.2} ppd)",
            p["p95"], p["max"], r.ppd
        ));
    }
    if let Some(j) = r.jnd {
        text.push_str(&format!("  ({j:.3} JND, {:.2} ppd)", r.ppd));
    }
    if let Some(e) = r.exposures {
        text.push_str(&format!(
            "  HDR-FLIP over {} exposures from {:.4} to {:.4} stops",
            e.count, e.start, e.stop
        ));
    }
    if let Some(w) = r.worst_pixel {
        let what = r.metric.map_label().unwrap_or("value");
        text.push_str(&format!(
            "  worst pixel ({}, {}): {what} {:.4}",
            w.x, w.y, w.value
        ));
    }
    if let Some(s) = r.share_over {
        text.push_str(&format!("  {:.3} % over the pixel limit", 100.0 * s));
    }
    if let Some(m) = &r.map {
        text.push_str(&format!("  map: {}", m.display()));
    }
    text.push('\n');
    text
}
