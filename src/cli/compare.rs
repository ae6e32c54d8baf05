//! `lodeval compare ORIGINAL LOD`: the one-shot "idiff for meshes" — both meshes rendered from
//! the original's framing, every view scored, the table and the distances printed.

use std::path::PathBuf;

use clap::Args;
use lodeval::Error;
use lodeval::backend::Backend;
use lodeval::eval::compare::{CompareJob, CompareReport};
use lodeval::metric::Metric;

use super::args::{LookArgs, count, parse_shading};
use super::print::{emit, emit_json, warnings};
use super::progress::Reporter;

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  lodeval compare reference/models/bunny/stanford-bunny.obj \
    bunny-lod.obj --views 12\n\nExit codes: 0 compared · 2 bad input or usage · 3 internal error"
)]
pub(crate) struct CompareArgs {
    /// The original mesh (its bounding sphere frames both renders).
    pub(crate) original: PathBuf,
    /// The mesh to compare with it (a LOD, a remesh, an export).
    pub(crate) lod: PathBuf,
    /// Views: 20 (dodecahedron), 12 (icosahedron) or any count on a Fibonacci sphere.
    #[arg(long, default_value_t = 20, value_parser = count::<u32>(&lodeval::limits::VIEWS))]
    pub(crate) views: u32,
    /// Image edge in pixels.
    #[arg(long, default_value_t = 512, value_parser = count::<u32>(&lodeval::limits::IMAGE_SIDE))]
    pub(crate) size: u32,
    /// Skip the imperceptibility-distance search (scores only).
    #[arg(long)]
    pub(crate) no_distances: bool,
    /// Where to render: cpu (the reference), gpu or auto.
    #[arg(long, value_enum, default_value_t = Backend::Cpu)]
    pub(crate) backend: Backend,
    /// Print JSON: every view's scores, the summary and the distances.
    #[arg(long)]
    pub(crate) json: bool,
    /// Shading model: auto (pbr for metallic–roughness materials, gouraud otherwise), pbr,
    /// gouraud, phong, normal-mapped, unlit.
    #[arg(long, default_value = "auto", value_parser = parse_shading)]
    pub(crate) shading: lodeval::raster::Shading,
    #[command(flatten)]
    pub(crate) look: LookArgs,
}

/// Run `compare`.
pub(crate) fn run(a: CompareArgs, quiet: bool) -> Result<(), Error> {
    let mut job = CompareJob::new(a.original, a.lod);
    job.views = a.views;
    job.size = a.size;
    job.distances = !a.no_distances;
    job.backend = a.backend;
    job.look = a.look.look(a.shading);
    let report = lodeval::eval::compare::compare(&job, &Reporter::new(quiet || a.json))?;
    warnings(&report.warnings);
    if a.json {
        return emit_json(&report);
    }
    emit(&table(&report))
}

/// The per-view table, the summary and the distances as text.
fn table(r: &CompareReport) -> String {
    // The console's columns; every metric is in --json and the CSVs.
    const COLUMNS: [Metric; 5] = [
        Metric::Flip,
        Metric::Ssim,
        Metric::Psnr,
        Metric::Vdp,
        Metric::VdpJnd,
    ];
    let metrics: Vec<Metric> = r
        .summary
        .iter()
        .map(|s| s.metric)
        .filter(|m| COLUMNS.contains(m))
        .collect();
    let mut s = format!(
        "{} triangles against {} ({:.4} of the original)\n\n{:>5}",
        r.triangles.1,
        r.triangles.0,
        r.triangles.1 as f64 / r.triangles.0.max(1) as f64,
        "view"
    );
    for m in &metrics {
        s.push_str(&format!(" {:>9}", m.name()));
    }
    s.push('\n');
    let mut views: Vec<usize> = r.views.iter().map(|v| v.view).collect();
    views.dedup();
    for v in views {
        s.push_str(&format!("{v:>5}"));
        for m in &metrics {
            let x = r
                .views
                .iter()
                .find(|row| row.view == v && row.metric == *m)
                .map(|row| row.value);
            s.push_str(&x.map_or(format!(" {:>9}", "-"), |x| format!(" {x:>9.4}")));
        }
        s.push('\n');
    }
    for label in ["mean", "worst"] {
        s.push_str(&format!("{label:>5}"));
        for m in &metrics {
            let values = r
                .views
                .iter()
                .filter(|row| row.metric == *m)
                .map(|row| row.value);
            // The worst view in the metric's own direction (lowest SSIM, MS-SSIM and PSNR).
            let x = if label == "mean" {
                r.summary.iter().find(|x| x.metric == *m).map(|x| x.mean)
            } else if m.higher_is_worse() {
                values.reduce(f64::max)
            } else {
                values.reduce(f64::min)
            };
            s.push_str(&x.map_or(format!(" {:>9}", "-"), |x| format!(" {x:>9.4}")));
        }
        s.push('\n');
    }
    if !r.distances.is_empty() {
        s.push_str("\nimperceptible beyond (≥/≤ mark bounds of the search):\n");
        s.push_str(&format!(
            "  {:<18} {:>10} {:>14}\n",
            "criterion", "metres", "diameter px"
        ));
        for d in &r.distances {
            s.push_str(&format!(
                "  {:<18} {:>10} {:>14}\n",
                d.criterion,
                d.distance_text(),
                d.diameter_text()
            ));
        }
    }
    s.push_str("\nflip: mean ꟻLIP (0 same … 1), ssim (1 same), psnr (dB, 8-bit sRGB), vdp: detection probability, vdp_jnd: JND (1 = threshold)\n");
    s
}
