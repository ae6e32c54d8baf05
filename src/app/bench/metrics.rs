//! `lodeval bench metrics`: FLIP, the VDP, SSIM and PSNR timed on one image pair.

use std::path::Path;

use crate::error::Result;

/// One row of `lodeval bench metrics`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct MetricBenchRow {
    /// Metric name.
    pub metric: String,
    /// Image size.
    pub width: usize,
    /// Image size.
    pub height: usize,
    /// Worker threads.
    pub threads: usize,
    /// Mean milliseconds per image pair (both images' preparation included), over `runs`.
    pub ms_per_pair: f64,
    /// Timed runs (after one warm-up).
    pub runs: usize,
}

/// Time FLIP, SSIM and PSNR on one image pair (decoding excluded). Reporting only.
pub fn bench_metrics(reference: &Path, test: &Path, runs: usize) -> Result<Vec<MetricBenchRow>> {
    use crate::metric::{LinearImage, flip::Flip, mse, ssim};
    let (a, b) = (LinearImage::load(reference)?, LinearImage::load(test)?);
    crate::limits::check_memory(
        &format!("scoring {}x{} pixels", a.width(), a.height()),
        (a.width() * a.height()) as u64 * crate::limits::BYTES_PER_SCORED_PIXEL,
    )
    .map_err(crate::error::Error::Usage)?;
    let runs = runs.max(1);
    let time = |f: &dyn Fn() -> Result<f64>| -> Result<f64> {
        f()?;
        let start = std::time::Instant::now();
        for _ in 0..runs {
            std::hint::black_box(f()?);
        }
        Ok(start.elapsed().as_secs_f64() * 1e3 / runs as f64)
    };
    let flip = Flip::new(crate::scene::Viewing::DEFAULT.ppd() as f32);
    let vdp = crate::metric::vdp::Vdp::new(
        &crate::scene::Viewing::DEFAULT,
        crate::metric::vdp::Display::DEFAULT,
    );
    let cases: [(&str, &dyn Fn() -> Result<f64>); 5] = [
        ("flip", &|| flip.compare(&a, &b).map(|s| s.mean)),
        ("vdp", &|| vdp.compare(&a, &b).map(|s| s.jnd)),
        ("ssim", &|| {
            ssim::ssim(&a, &b, ssim::SsimInput::SrgbLuma).map(|s| s.0)
        }),
        ("psnr", &|| mse::psnr_srgb8(&a, &b)),
        ("psnr_luminance", &|| mse::mse(&a, &b).map(|s| s.psnr_db)),
    ];
    cases
        .iter()
        .map(|(name, f)| {
            Ok(MetricBenchRow {
                metric: name.to_string(),
                width: a.width(),
                height: a.height(),
                threads: rayon::current_num_threads(),
                ms_per_pair: time(*f)?,
                runs,
            })
        })
        .collect()
}
