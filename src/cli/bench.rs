//! `lodeval bench WHAT`: the benchmarks, printed as Markdown tables or JSON rows. Reporting only.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use lodeval::backend::Backend;
use lodeval::raster::Shading;
use lodeval::{Error, LoadOptions};

use super::args::{count, parse_samples, parse_shading};
use super::print::{emit, emit_json};

/// What `lodeval bench` measures.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum BenchTarget {
    /// The rasterizer on a large torus (1 and 4 samples per pixel).
    Raster,
    /// FLIP, the VDP, SSIM and PSNR on REF TEST.
    Metrics,
    /// QEM, clustering and meshoptimizer on MESH..., in turns.
    Simplify,
    /// Williams et al.'s preprocessing and per-frame cut adaptation on MESH....
    Williams,
    /// The image-driven optimizer's evaluations per second on our QEM LOD of MESH....
    Optimize,
    /// Menzel & Guthe's applied collapses per second on MESH..., beside our QEM's.
    #[value(name = "menzel-guthe")]
    MenzelGuthe,
}

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  lodeval bench raster\n  lodeval bench menzel-guthe reference/models/bunny/stanford-bunny.obj\n\nExit codes: 0 measured · 2 bad input or usage · 3 internal error"
)]
pub(crate) struct BenchArgs {
    /// What to measure: `raster`, `metrics REF TEST`, `simplify MESH...`, `williams MESH...` or
    /// `optimize MESH...` (the image-driven optimizer's evaluations per second, 20 views at 256²,
    /// on our QEM LOD of each mesh).
    #[arg(value_enum)]
    pub(crate) what: BenchTarget,
    /// For `metrics`: the reference and test images; for `simplify`, `williams` and `optimize`:
    /// the meshes.
    pub(crate) images: Vec<PathBuf>,
    /// For `optimize`: the LOD's triangle count.
    #[arg(long, default_value_t = 1400)]
    pub(crate) triangles: usize,
    /// For `optimize`: energy evaluations per timed run.
    #[arg(long, default_value_t = 20_000, value_parser = count::<u64>(&lodeval::limits::EVALS))]
    pub(crate) evals: u64,
    /// For `simplify`: target ratios, comma separated; for `menzel-guthe` the first is the goal
    /// (default there 0.1).
    #[arg(long, value_delimiter = ',')]
    pub(crate) ratios: Vec<f64>,
    /// For `simplify`: also a procedural bumpy sphere of 20·4^N triangles (0: none).
    #[arg(long, default_value_t = 0)]
    pub(crate) bumpy: u32,
    /// For `metrics`: timed runs per metric; for `simplify`: timed runs per method and ratio
    /// (best and median reported); for `optimize`: timed optimizer runs per mesh.
    #[arg(long, default_value_t = 5, value_parser = count::<usize>(&lodeval::limits::RUNS))]
    pub(crate) runs: usize,
    /// Torus rings (triangles = 2 · rings · sides), at least 3.
    #[arg(long, default_value_t = 1000, value_parser = count::<u32>(&lodeval::limits::TORUS_SEGMENTS))]
    pub(crate) rings: u32,
    /// Torus sides, at least 3.
    #[arg(long, default_value_t = 500, value_parser = count::<u32>(&lodeval::limits::TORUS_SEGMENTS))]
    pub(crate) sides: u32,
    /// Image edge in pixels.
    #[arg(long, default_value_t = 1024, value_parser = count::<u32>(&lodeval::limits::IMAGE_SIDE))]
    pub(crate) size: u32,
    /// Number of views (Fibonacci rig).
    #[arg(long, default_value_t = 20, value_parser = count::<u32>(&lodeval::limits::VIEWS))]
    pub(crate) views: u32,
    /// Samples per pixel to measure, comma separated (squares: 1, 4, 9, ..., 64).
    #[arg(long, value_delimiter = ',', default_value = "1,4", value_parser = parse_samples)]
    pub(crate) samples: Vec<u32>,
    /// Shading model.
    #[arg(long, default_value = "gouraud", value_parser = parse_shading)]
    pub(crate) shading: Shading,
    /// Print JSON rows instead of a table.
    #[arg(long)]
    pub(crate) json: bool,
    /// Also export the benchmark scene to this folder (for benches/llvmpipe_raster.py).
    #[arg(long)]
    pub(crate) export: Option<PathBuf>,
    /// Renderer to time: cpu, gpu or auto.
    #[arg(long, value_enum, default_value_t = Backend::Cpu)]
    pub(crate) backend: Backend,
}

/// Load each mesh, named by its file stem (for the benchmarks' tables).
fn named_meshes(paths: &[PathBuf]) -> Result<Vec<(String, lodeval::mesh::Mesh)>, Error> {
    paths
        .iter()
        .map(|p| {
            let name = p
                .file_stem()
                .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
            Ok((name, lodeval::mesh::load(p, &LoadOptions::DEFAULT)?))
        })
        .collect()
}

/// Run `bench`.
pub(crate) fn run(a: BenchArgs) -> Result<(), Error> {
    match a.what {
        BenchTarget::Metrics => metrics(&a),
        BenchTarget::Williams => williams(&a),
        BenchTarget::Optimize => optimize(&a),
        BenchTarget::MenzelGuthe => menzel_guthe(&a),
        BenchTarget::Simplify => simplify(&a),
        BenchTarget::Raster => raster(a),
    }
}

/// `bench metrics REF TEST`: the metrics on one image pair, as JSON.
fn metrics(a: &BenchArgs) -> Result<(), Error> {
    let [reference, test] = a.images.as_slice() else {
        return Err(Error::Usage(
            "lodeval bench metrics REF TEST: give two images".into(),
        ));
    };
    let rows = lodeval::app::bench::bench_metrics(reference, test, a.runs)?;
    emit_json(&rows)
}

/// `bench williams MESH...`: preprocessing and per-frame cut adaptation, as a table.
fn williams(a: &BenchArgs) -> Result<(), Error> {
    let mut t = String::from(
        "| mesh | triangles | MT nodes | hierarchy s | preprocess s | budget | frames | adapt ms median | p95 | max | first frame ms | nodes changed per frame (median) |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for (name, mesh) in named_meshes(&a.images)? {
        let ratios = if a.ratios.is_empty() {
            vec![0.5, 0.1, 0.01]
        } else {
            a.ratios.clone()
        };
        for r in lodeval::app::bench::bench_williams(&mesh, &ratios, a.views)? {
            t.push_str(&format!(
                "| {name} | {} | {} | {:.2} | {:.2} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {} |\n",
                r.triangles,
                r.nodes,
                r.hierarchy_seconds,
                r.preprocess_seconds,
                r.budget,
                r.frames,
                r.median_ms,
                r.p95_ms,
                r.max_ms,
                r.first_ms,
                r.median_changes
            ));
        }
    }
    emit(&t)
}

/// `bench optimize MESH...`: the optimizer's evaluations per second.
fn optimize(a: &BenchArgs) -> Result<(), Error> {
    let meshes = named_meshes(&a.images)?;
    if meshes.is_empty() {
        return Err(Error::Usage(
            "lodeval bench optimize MESH...: give at least one mesh".into(),
        ));
    }
    let rows = lodeval::app::bench::bench_optimize(&meshes, a.triangles, a.evals, a.runs)?;
    if a.json {
        return emit_json(&rows);
    }
    let mut t = String::from(
        "| mesh | input triangles | LOD triangles | LOD vertices | views | size | threads | evaluations | runs | best /s | median /s | worst /s | set-up s |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in &rows {
        t.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.0} | {:.0} | {:.0} | {:.2} |\n",
            r.mesh,
            r.input_triangles,
            r.triangles,
            r.vertices,
            r.views,
            r.size,
            r.threads,
            r.evaluations,
            r.runs,
            r.best_per_s,
            r.median_per_s,
            r.worst_per_s,
            r.setup_seconds
        ));
    }
    emit(&t)
}

/// `bench menzel-guthe MESH...`: applied collapses per second beside our QEM's.
fn menzel_guthe(a: &BenchArgs) -> Result<(), Error> {
    let meshes = named_meshes(&a.images)?;
    if meshes.is_empty() {
        return Err(Error::Usage(
            "lodeval bench menzel-guthe MESH...: give at least one mesh".into(),
        ));
    }
    let ratio = a.ratios.first().copied().unwrap_or(0.1);
    if !(ratio > 0.0 && ratio < 1.0) {
        return Err(Error::Usage(format!(
            "--ratios {ratio}: use a value in (0, 1)"
        )));
    }
    let rows = lodeval::app::bench::bench_menzel_guthe(&meshes, ratio, a.runs)?;
    if a.json {
        return emit_json(&rows);
    }
    let mut t = String::from(
        "| mesh | input triangles | LOD triangles | threads | runs | collapses | perception tests | Hausdorff tests | postponed | collapses/s best | median | worst | set-up s | QEM collapses/s |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in &rows {
        t.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.0} | {:.0} | {:.0} | {:.2} | {:.0} |\n",
            r.mesh,
            r.input_triangles,
            r.triangles,
            r.threads,
            r.runs,
            r.collapses,
            r.perception_tests,
            r.hausdorff_tests,
            r.postponed,
            r.collapses_per_second,
            r.median_collapses_per_second,
            r.worst_collapses_per_second,
            r.setup_seconds,
            r.qem_collapses_per_second
        ));
    }
    emit(&t)
}

/// `bench simplify MESH...`: every simplifier at each ratio.
fn simplify(a: &BenchArgs) -> Result<(), Error> {
    let mut meshes = named_meshes(&a.images)?;
    if a.bumpy > 0 {
        let triangles = 20u64.saturating_mul(4u64.saturating_pow(a.bumpy));
        lodeval::limits::GENERATED_TRIANGLES
            .check("the --bumpy sphere (20 × 4^N triangles):", triangles)
            .map_err(Error::Usage)?;
        meshes.push((
            format!("bumpy-sphere-s{}", a.bumpy),
            lodeval::mesh::shapes::bumpy_sphere(a.bumpy),
        ));
    }
    let ratios = if a.ratios.is_empty() {
        vec![0.5, 0.1, 0.01]
    } else {
        a.ratios.clone()
    };
    let rows = lodeval::app::bench::bench_simplify(&meshes, &ratios, 1_000_000, a.runs)?;
    if a.json {
        return emit_json(&rows);
    }
    let mut t = String::from(
        "| mesh | input triangles | method | ratio | triangles | best s | median s | M input tri/s (best) | Hausdorff / diagonal | mean / diagonal |\n|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in &rows {
        t.push_str(&format!(
            "| {} | {} | {} | {} | {} | {:.4} | {:.4} | {:.2} | {:.3e} | {:.3e} |\n",
            r.mesh,
            r.input_triangles,
            r.method,
            r.ratio,
            r.triangles,
            r.seconds,
            r.median_seconds,
            r.mtri_per_s,
            r.hausdorff_relative,
            r.mean_relative
        ));
    }
    emit(&t)
}

/// `bench raster`: the rasterizer on a large torus.
fn raster(a: BenchArgs) -> Result<(), Error> {
    let job = lodeval::app::bench::RasterBench {
        rings: a.rings,
        sides: a.sides,
        size: a.size,
        views: a.views,
        samples: a.samples,
        shading: a.shading,
        export: a.export,
        backend: a.backend,
    };
    let rows = lodeval::app::bench::bench_raster(&job)?;
    let rss = lodeval::app::bench::peak_rss_mib().unwrap_or(f64::NAN);
    if a.json {
        return emit_json(&rows);
    }
    emit(&(lodeval::app::bench::raster_bench_table(&rows) + &format!("peak RSS: {rss:.0} MiB\n")))
}
