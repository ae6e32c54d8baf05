//! The `lodeval` command line: parse (clap derive), call the library, map errors to exit codes
//! (0 ok · 1 regression or golden mismatch · 2 bad input or usage · 3 internal error). No logic.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Mutex;

use clap::{Args, Parser, Subcommand, ValueEnum};
use lodeval::commands::{RenderJob, ViewSelection};
use lodeval::raster::{RenderSettings, SamplePattern, Shading};
use lodeval::scene::Rig;
use lodeval::{Error, LoadOptions, MeshSummary, MissingAssets};

#[derive(Parser, Debug)]
#[command(
    name = "lodeval",
    version,
    about = "Does a simplified mesh still look like the original, and from how far away can nobody tell them apart?"
)]
struct Cli {
    /// Worker threads (default: all cores). Results are identical for any value.
    #[arg(long, global = true, value_name = "N")]
    threads: Option<usize>,
    /// No progress output.
    #[arg(long, short, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Print what a mesh file contains: counts, attributes, materials, textures, bounds.
    Info(InfoArgs),
    /// Render a mesh from the views of a rig with the CPU rasterizer.
    Render(RenderArgs),
    /// Compare two images with the perceptual metrics.
    Diff(DiffArgs),
    /// Run a batch evaluation config: render, score, write CSVs, heat maps, report; gate.
    Eval(EvalArgs),
    /// Compare renders with golden images, or bless new ones.
    Golden(GoldenArgs),
    /// Simplify a mesh (QEM edge collapse, vertex clustering, or meshoptimizer) and write OBJ.
    Simplify(SimplifyArgs),
    /// Image-driven optimization of a simplified mesh (Lindstrom & Turk): same vertex count,
    /// renderings closer to the original's.
    Optimize(OptimizeArgs),
    /// Geometric error between two meshes: Hausdorff, mean and RMS surface distance (Metro-style).
    Geometry(GeometryArgs),
    /// Run a benchmark (`raster`) and print its table.
    Bench(BenchArgs),
    /// Merge the outputs of sharded runs into what one machine would have written.
    Merge(MergeArgs),
    /// Check the visible-difference predictor against observers' detection thresholds.
    Calibrate(CalibrateArgs),
}

/// Datasets `lodeval calibrate` knows.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum CalibrationSet {
    /// ModelFest: 43 foveal detection thresholds of 16 observers (Carney et al. 1999).
    Modelfest,
}

#[derive(Args, Debug)]
struct CalibrateArgs {
    /// The dataset.
    #[arg(value_enum)]
    dataset: CalibrationSet,
    /// The oracle folder (thresholds.csv and the stimulus PNGs).
    #[arg(long, default_value = "reference/oracles/modelfest")]
    data: PathBuf,
    /// Pixels per degree the stimuli are shown at (ModelFest's: 120).
    #[arg(long, default_value_t = 120.0)]
    ppd: f64,
    /// Background luminance in cd/m² (ModelFest's: 30).
    #[arg(long, default_value_t = 30.0)]
    background_cd_m2: f64,
    /// Write modelfest.csv (the per-stimulus table) and modelfest.svg (predicted against
    /// observed) into this folder.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print JSON: {"rmse_log10", "stimuli": [{"id", "name", "observed", "sd", "predicted",
    /// "residual"}], ...}.
    #[arg(long)]
    json: bool,
}

#[derive(Args, Debug)]
struct InfoArgs {
    /// The mesh file (.obj, .ply, .gltf, .glb, .off).
    mesh: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    load: LoadArgs,
}

#[derive(Args, Debug)]
struct RenderArgs {
    /// The mesh file.
    mesh: PathBuf,
    /// Output PNG (one view, or the contact sheet with --sheet).
    #[arg(short, long, required_unless_present = "all_views")]
    out: Option<PathBuf>,
    /// Image width and height in pixels.
    #[arg(long, default_value_t = 512)]
    size: u32,
    /// View rig: dodecahedron (20 views), icosahedron (12) or fibonacci:N.
    #[arg(long, default_value = "dodecahedron")]
    rig: String,
    /// Which view of the rig to render.
    #[arg(long, default_value_t = 0, conflicts_with_all = ["all_views", "sheet"])]
    view: usize,
    /// Render every view of the rig into --out-dir as view-NN.png.
    #[arg(long, requires = "out_dir", conflicts_with = "sheet")]
    all_views: bool,
    /// Folder for --all-views.
    #[arg(long)]
    out_dir: Option<PathBuf>,
    /// Write every view as one contact sheet (a grid) to --out.
    #[arg(long)]
    sheet: bool,
    /// Shading model: unlit, gouraud, phong, normal-mapped, normals, depth.
    #[arg(long, default_value = "gouraud")]
    shading: String,
    /// Samples per pixel (a square: 1, 4, 9, 16, ...).
    #[arg(long, default_value_t = 4)]
    samples: u32,
    /// Sample grid: rotated or ordered.
    #[arg(long, value_enum, default_value_t = PatternArg::Rotated)]
    pattern: PatternArg,
    /// Skip back-facing triangles (off by default, so flipped LOD triangles show).
    #[arg(long)]
    cull_backfaces: bool,
    /// Also write linear float EXR beside each PNG.
    #[arg(long)]
    exr: bool,
    /// Renderer: cpu (the reference), gpu (the wgpu mirror; needs the `gpu` feature and an
    /// adapter) or auto (gpu when available).
    #[arg(long, value_enum, default_value_t = BackendArg::Cpu)]
    backend: BackendArg,
    #[command(flatten)]
    load: LoadArgs,
}

#[derive(Copy, Clone, Debug, ValueEnum)]
enum BackendArg {
    /// The CPU reference rasterizer and metrics.
    Cpu,
    /// The wgpu mirror (cargo feature `gpu`).
    Gpu,
    /// The GPU when built and an adapter exists, else the CPU.
    Auto,
}

impl From<BackendArg> for lodeval::backend::Backend {
    fn from(b: BackendArg) -> Self {
        match b {
            BackendArg::Cpu => Self::Cpu,
            BackendArg::Gpu => Self::Gpu,
            BackendArg::Auto => Self::Auto,
        }
    }
}

#[derive(Args, Debug)]
struct DiffArgs {
    /// Reference image (PNG/JPEG: sRGB; EXR: linear).
    reference: PathBuf,
    /// Where FLIP, MSE and PSNR run: cpu, gpu (compute kernels) or auto.
    #[arg(long, value_enum, default_value_t = BackendArg::Cpu)]
    backend: BackendArg,
    /// Test image, same size.
    test: PathBuf,
    /// Metric: flip, ssim, msssim, psnr, mse, vdp or all.
    #[arg(long, default_value = "flip")]
    metric: String,
    /// Pixels per degree of visual angle (overrides the display flags).
    #[arg(long, conflicts_with_all = ["display_width_m", "display_px", "distance_m"])]
    ppd: Option<f64>,
    /// Display width in metres.
    #[arg(long, default_value_t = 0.7)]
    display_width_m: f64,
    /// Display width in pixels.
    #[arg(long, default_value_t = 3840.0)]
    display_px: f64,
    /// Viewing distance in metres.
    #[arg(long, default_value_t = 0.7)]
    distance_m: f64,
    /// VDP display model: luminance of white, cd/m².
    #[arg(long, default_value_t = 100.0)]
    peak_cd_m2: f32,
    /// VDP display model: luminance of black in a dark room, cd/m².
    #[arg(long, default_value_t = 0.5)]
    black_cd_m2: f32,
    /// VDP display model: room light on the screen, lux.
    #[arg(long, default_value_t = 250.0)]
    ambient_lux: f32,
    /// VDP display model: fraction of the room light the screen reflects.
    #[arg(long, default_value_t = 0.005)]
    reflectivity: f32,
    /// Write a magma heat map of the error here (FLIP error, 1 − SSIM, or the VDP's detection
    /// probability).
    #[arg(long)]
    map: Option<PathBuf>,
    /// Print JSON (an array, one object per metric).
    #[arg(long)]
    json: bool,
}

#[derive(Args, Debug)]
struct BenchArgs {
    /// What to measure: `raster`, `metrics REF TEST`, `simplify MESH...`, `williams MESH...` or
    /// `optimize MESH...` (the image-driven optimizer's evaluations per second, 20 views at 256²,
    /// on our QEM LOD of each mesh).
    what: String,
    /// For `metrics`: the reference and test images; for `simplify`, `williams` and `optimize`:
    /// the meshes.
    images: Vec<PathBuf>,
    /// For `optimize`: the LOD's triangle count.
    #[arg(long, default_value_t = 1400)]
    triangles: usize,
    /// For `optimize`: energy evaluations per timed run.
    #[arg(long, default_value_t = 20_000)]
    evals: u64,
    /// For `simplify`: target ratios, comma separated.
    #[arg(long, value_delimiter = ',', default_value = "0.5,0.1,0.01")]
    ratios: Vec<f64>,
    /// For `simplify`: also a procedural bumpy sphere of 20·4^N triangles (0: none).
    #[arg(long, default_value_t = 0)]
    bumpy: u32,
    /// For `metrics`: timed runs per metric; for `simplify`: timed runs per method and ratio
    /// (best and median reported); for `optimize`: timed optimizer runs per mesh.
    #[arg(long, default_value_t = 5)]
    runs: usize,
    /// Torus rings (triangles = 2 · rings · sides).
    #[arg(long, default_value_t = 1000)]
    rings: u32,
    /// Torus sides.
    #[arg(long, default_value_t = 500)]
    sides: u32,
    /// Image edge in pixels.
    #[arg(long, default_value_t = 1024)]
    size: u32,
    /// Number of views (Fibonacci rig).
    #[arg(long, default_value_t = 20)]
    views: u32,
    /// Samples per pixel to measure, comma separated.
    #[arg(long, value_delimiter = ',', default_value = "1,4")]
    samples: Vec<u32>,
    /// Shading model.
    #[arg(long, default_value = "gouraud")]
    shading: String,
    /// Print JSON rows instead of a table.
    #[arg(long)]
    json: bool,
    /// Also export the benchmark scene to this folder (for benches/llvmpipe_raster.py).
    #[arg(long)]
    export: Option<PathBuf>,
    /// Renderer to time: cpu, gpu or auto.
    #[arg(long, value_enum, default_value_t = BackendArg::Cpu)]
    backend: BackendArg,
}

#[derive(Copy, Clone, Debug, ValueEnum)]
enum PatternArg {
    /// Rotated ("n-rooks") grid.
    Rotated,
    /// Regular grid.
    Ordered,
}

impl RenderArgs {
    fn job(self) -> Result<RenderJob, Error> {
        let rig = Rig::parse(&self.rig).ok_or_else(|| {
            Error::Usage(format!(
                "--rig {}: use dodecahedron, icosahedron or fibonacci:N",
                self.rig
            ))
        })?;
        let shading = Shading::parse(&self.shading).ok_or_else(|| {
            let names: Vec<&str> = Shading::ALL.iter().map(|s| s.name()).collect();
            Error::Usage(format!(
                "--shading {}: use one of {}",
                self.shading,
                names.join(", ")
            ))
        })?;
        let n = (self.samples as f64).sqrt().round() as u32;
        if n * n != self.samples || n == 0 {
            return Err(Error::Usage(format!(
                "--samples {}: use a square number (1, 4, 9, 16, ...)",
                self.samples
            )));
        }
        let mut settings = RenderSettings::DEFAULT;
        settings.width = self.size;
        settings.height = self.size;
        settings.shading = shading;
        settings.cull_backfaces = self.cull_backfaces;
        settings.samples = match self.pattern {
            PatternArg::Rotated => SamplePattern::Rotated(n),
            PatternArg::Ordered => SamplePattern::Ordered(n),
        };
        let views = match (self.all_views, self.sheet, self.out, self.out_dir) {
            (true, _, _, Some(out_dir)) => ViewSelection::All { out_dir },
            (_, true, Some(out), _) => ViewSelection::Sheet { out },
            (_, _, Some(out), _) => ViewSelection::One {
                view: self.view,
                out,
            },
            _ => {
                return Err(Error::Usage(
                    "name an output with -o (or --all-views --out-dir DIR)".into(),
                ));
            }
        };
        Ok(RenderJob {
            mesh: self.mesh,
            load: self.load.options()?,
            settings,
            rig,
            views,
            exr: self.exr,
            backend: self.backend.into(),
        })
    }
}

#[derive(Args, Debug)]
struct LoadArgs {
    /// What to do when a texture or material library is missing or undecodable.
    #[arg(long, value_enum, default_value_t = MissingArg::Error)]
    missing_assets: MissingArg,
    /// Crease angle in degrees for computed normals (180 = smooth everywhere).
    #[arg(long, default_value_t = 180.0, value_name = "DEGREES")]
    crease_angle: f32,
}

#[derive(Copy, Clone, Debug, ValueEnum)]
enum MissingArg {
    /// Fail with a message naming the file.
    Error,
    /// Warn and render with the material's base colour.
    Warn,
}

#[derive(Args, Debug)]
struct EvalArgs {
    /// The batch config (TOML; see configs/README.md).
    config: PathBuf,
    /// Output folder (default: the config's `out`, else ../results/<config name> beside it).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Run one shard: INDEX/COUNT, 0-based (also from TEST_SHARD_INDEX/TEST_TOTAL_SHARDS,
    /// CI_NODE_INDEX/CI_NODE_TOTAL, JOB_COMPLETION_INDEX with LODEVAL_SHARD_COUNT).
    #[arg(long, value_name = "INDEX/COUNT")]
    shard: Option<String>,
    /// Renderer and FLIP/MSE kernels: cpu, gpu or auto (recorded in the CSVs and the report).
    #[arg(long, value_enum, default_value_t = BackendArg::Cpu)]
    backend: BackendArg,
}

#[derive(Args, Debug)]
struct GoldenArgs {
    /// The batch config whose renders are checked.
    config: PathBuf,
    /// Write the current renders as the new goldens (refused when CI is set).
    #[arg(long)]
    bless: bool,
    /// Where actual and diff images of mismatches go (default: the config's output folder).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

#[derive(Args, Debug)]
struct SimplifyArgs {
    /// The mesh to simplify.
    #[arg(required_unless_present = "experiment")]
    mesh: Option<PathBuf>,
    /// Output .obj (with --chain: files STEM-rXX.obj beside it).
    #[arg(short, long, required_unless_present = "experiment")]
    out: Option<PathBuf>,
    /// Run Williams et al. 2003's evaluation from a config (configs/papers/williams2003.toml).
    #[arg(long, conflicts_with_all = ["mesh", "out"])]
    experiment: Option<PathBuf>,
    /// qem (our edge collapse, Garland–Heckbert quadrics), cluster (Rossignac–Borrel), meshopt,
    /// meshopt-update (meshoptimizer moving vertices and attributes, as qem does), or williams
    /// (Williams et al. 2003: perceptual, view-dependent, to a --budget).
    #[arg(long, default_value = "qem")]
    method: String,
    /// williams: triangle budget.
    #[arg(long, conflicts_with_all = ["ratio", "triangles", "error", "chain", "distance"])]
    budget: Option<usize>,
    /// williams: instead of a budget, refine until the LOD is imperceptible from this viewing
    /// distance in metres (the display and viewer of DESIGN.md's viewing conditions).
    #[arg(long, conflicts_with_all = ["ratio", "triangles", "error", "chain"])]
    distance: Option<f64>,
    /// williams: the camera, as EX,EY,EZ (looking at the model's centre, default field of view) or
    /// EX,EY,EZ,TX,TY,TZ. Default: view 0 of the default rig at the default framing.
    #[arg(long, value_delimiter = ',', num_args = 1, conflicts_with_all = ["view", "all_views"])]
    camera: Vec<f32>,
    /// williams: use view K of --rig.
    #[arg(long, conflicts_with = "all_views")]
    view: Option<usize>,
    /// williams: one static LOD for every view of --rig (each node keyed by its worst view).
    #[arg(long)]
    all_views: bool,
    /// williams: view rig for --view and --all-views.
    #[arg(long, default_value = "dodecahedron")]
    rig: String,
    /// williams: the shading the LOD is for (gouraud, phong, normal-mapped, unlit).
    #[arg(long, default_value = "gouraud")]
    shading: String,
    /// williams: perceptual, object-space, screen-space or silhouette-10.
    #[arg(long, default_value = "perceptual")]
    criterion: String,
    /// williams: image size the views are rendered at (pixels).
    #[arg(long, default_value_t = 512)]
    size: u32,
    /// Target ratio of the input's triangles.
    #[arg(long, conflicts_with_all = ["triangles", "error", "chain"])]
    ratio: Option<f64>,
    /// Target triangle count: the LOD has at most this many triangles (unless the mesh
    /// cannot be simplified that far).
    #[arg(long, conflicts_with_all = ["error", "chain"])]
    triangles: Option<usize>,
    /// Target error relative to the bounding-box diagonal (qem, meshopt).
    #[arg(long, conflicts_with = "chain")]
    error: Option<f64>,
    /// A chain of ratios, e.g. 0.5,0.25,0.1.
    #[arg(long, value_delimiter = ',')]
    chain: Vec<f64>,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

#[derive(Args, Debug)]
struct GeometryArgs {
    /// The original mesh (distances are also given relative to its bounding-box diagonal).
    a: PathBuf,
    /// The mesh compared with it.
    b: PathBuf,
    /// Face samples per mesh (every vertex is sampled too).
    #[arg(long, default_value_t = 1_000_000)]
    samples: usize,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

#[derive(Args, Debug)]
struct MergeArgs {
    /// Output folders of the shard runs.
    #[arg(required = true)]
    shards: Vec<PathBuf>,
    /// The merged output folder.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

#[derive(Args, Debug)]
struct OptimizeArgs {
    /// The original mesh (the target of the renderings).
    #[arg(required_unless_present = "experiment")]
    original: Option<PathBuf>,
    /// The simplified mesh to improve (any simplifier's output).
    #[arg(required_unless_present = "experiment")]
    simplified: Option<PathBuf>,
    /// Output OBJ.
    #[arg(short, long, required_unless_present = "experiment")]
    out: Option<PathBuf>,
    /// Run the paper's experiment from a config (configs/papers/lindstrom-turk.toml) instead.
    #[arg(long, conflicts_with_all = ["original", "simplified", "out"])]
    experiment: Option<PathBuf>,
    /// Budget in energy evaluations.
    #[arg(long, default_value_t = 20_000)]
    evals: u64,
    /// Views while optimizing (20: dodecahedron, 12: icosahedron, else a Fibonacci sphere).
    #[arg(long, default_value_t = 20)]
    views: u32,
    /// Image edge in pixels.
    #[arg(long, default_value_t = 256)]
    size: u32,
    /// Seed of the random edge choice.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Normals: derived (from the geometry) or free (optimized as attributes).
    #[arg(long, default_value = "derived")]
    normals: String,
    /// Do not optimize UVs and colours.
    #[arg(long)]
    no_attributes: bool,
    /// Write energy against evaluations (and seconds) here.
    #[arg(long)]
    energy_csv: Option<PathBuf>,
}

impl LoadArgs {
    fn options(&self) -> Result<LoadOptions, Error> {
        if !(0.0..=180.0).contains(&self.crease_angle) {
            return Err(Error::Usage(format!(
                "--crease-angle {} is outside 0..180 degrees",
                self.crease_angle
            )));
        }
        let mut o = LoadOptions::DEFAULT;
        o.missing_assets = match self.missing_assets {
            MissingArg::Error => MissingAssets::Error,
            MissingArg::Warn => MissingAssets::Warn,
        };
        o.crease_angle_deg = self.crease_angle;
        Ok(o)
    }
}

/// Tell the user (stderr) when a LOD stopped well above its triangle goal: the simplifier ran out
/// of collapses it may make, and the file holds less simplification than asked for.
fn warn_short_of_goals(
    rows: &[lodeval::commands::SimplifyRow],
    goals: &[lodeval::simplify::Goal],
    method: &str,
) {
    use lodeval::simplify::Goal;
    for (r, g) in rows.iter().zip(goals) {
        let input = r.triangles as f64 / r.ratio.max(f64::MIN_POSITIVE);
        let target = match *g {
            Goal::Ratio(x) => (x * input).round(),
            Goal::Triangles(n) => n as f64,
            Goal::Error(_) => continue,
        };
        if r.triangles as f64 > 1.05 * target + 2.0 {
            eprintln!(
                "warning: {}: {method} stopped at {} triangles, short of the goal of {target}: \
                 every remaining collapse would change the surface's topology or fold it over \
                 (closed parts are not collapsed away, borders only shrink along themselves). Ask \
                 for less reduction, or try another --method.",
                r.file.display(),
                r.triangles
            );
        }
    }
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

/// Write a value to stdout as pretty JSON with a trailing newline.
fn emit_json<T: serde::Serialize>(value: &T) -> Result<(), Error> {
    let json = serde_json::to_string_pretty(value).map_err(|e| Error::Internal(e.to_string()))?;
    emit(&(json + "\n"))
}

/// Write to stdout; a closed pipe (e.g. `| head`) is not an error.
fn emit(text: &str) -> Result<(), Error> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|_| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(Error::Internal(format!(
            "cannot write to standard output: {e}"
        ))),
        _ => Ok(()),
    }
}

fn run(cli: Cli) -> Result<(), Error> {
    if let Some(n) = cli.threads {
        if n == 0 {
            return Err(Error::Usage("--threads must be at least 1".into()));
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| Error::Internal(format!("cannot start {n} worker threads: {e}")))?;
    }
    match cli.command {
        Command::Info(a) => {
            let mesh = lodeval::mesh::load(&a.mesh, &a.load.options()?)?;
            let summary = MeshSummary::of(&mesh);
            if a.json {
                emit_json(&summary)
            } else {
                emit(&summary.to_string())
            }
        }
        Command::Render(a) => {
            let written = lodeval::commands::render(&a.job()?)?;
            if !cli.quiet {
                eprintln!(
                    "wrote {} file(s), first {}",
                    written.len(),
                    written[0].display()
                );
            }
            Ok(())
        }
        Command::Diff(a) => {
            use lodeval::commands::DiffMetric;
            let metrics: Vec<DiffMetric> = match a.metric.as_str() {
                "all" => DiffMetric::ALL.to_vec(),
                "flip" => vec![DiffMetric::Flip],
                "ssim" => vec![DiffMetric::Ssim],
                "msssim" => vec![DiffMetric::Msssim],
                "psnr" => vec![DiffMetric::Psnr],
                "mse" => vec![DiffMetric::Mse],
                "vdp" => vec![DiffMetric::Vdp],
                other => {
                    return Err(Error::Usage(format!(
                        "--metric {other}: use flip, ssim, msssim, psnr, mse, vdp or all"
                    )));
                }
            };
            let viewing = match a.ppd {
                Some(p) if p > 0.0 && p.is_finite() => lodeval::scene::Viewing::from_ppd(p),
                Some(p) => {
                    return Err(Error::Usage(format!(
                        "--ppd {p}: must be a positive number"
                    )));
                }
                None => {
                    if !(a.display_width_m > 0.0 && a.display_px > 0.0 && a.distance_m > 0.0) {
                        return Err(Error::Usage(
                            "display width, pixels and distance must be positive".into(),
                        ));
                    }
                    lodeval::scene::Viewing::from_display(
                        a.display_width_m,
                        a.display_px,
                        a.distance_m,
                    )
                }
            };
            // With `all`, metrics that do not apply to this image size report a note instead.
            let lenient = a.metric == "all";
            let engine = lodeval::backend::Engine::new(a.backend.into())?;
            let display = lodeval::metric::vdp::Display::new(
                a.peak_cd_m2,
                a.black_cd_m2,
                a.ambient_lux,
                a.reflectivity,
            )?;
            let results = lodeval::commands::diff(
                &engine,
                &a.reference,
                &a.test,
                &metrics,
                &lodeval::commands::Seen { viewing, display },
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
        Command::Bench(a) => {
            if a.what == "metrics" {
                let [reference, test] = a.images.as_slice() else {
                    return Err(Error::Usage(
                        "lodeval bench metrics REF TEST: give two images".into(),
                    ));
                };
                let rows = lodeval::commands::bench_metrics(reference, test, a.runs)?;
                return emit_json(&rows);
            }
            if a.what == "williams" {
                let mut t = String::from(
                    "| mesh | triangles | MT nodes | hierarchy s | preprocess s | budget | frames | adapt ms median | p95 | max | first frame ms | nodes changed per frame (median) |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
                );
                for (name, mesh) in named_meshes(&a.images)? {
                    for r in lodeval::commands::bench_williams(&mesh, &a.ratios, a.views)? {
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
                return emit(&t);
            }
            if a.what == "optimize" {
                let meshes = named_meshes(&a.images)?;
                if meshes.is_empty() {
                    return Err(Error::Usage(
                        "lodeval bench optimize MESH...: give at least one mesh".into(),
                    ));
                }
                let rows =
                    lodeval::commands::bench_optimize(&meshes, a.triangles, a.evals, a.runs)?;
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
                return emit(&t);
            }
            if a.what == "simplify" {
                let mut meshes = named_meshes(&a.images)?;
                if a.bumpy > 0 {
                    meshes.push((
                        format!("bumpy-sphere-s{}", a.bumpy),
                        lodeval::mesh::shapes::bumpy_sphere(a.bumpy),
                    ));
                }
                let rows =
                    lodeval::commands::bench_simplify(&meshes, &a.ratios, 1_000_000, a.runs)?;
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
                return emit(&t);
            }
            if a.what != "raster" {
                return Err(Error::Usage(format!(
                    "lodeval bench {}: use `raster`, `metrics REF TEST`, `simplify MESH...`, `williams MESH...` or `optimize MESH...`",
                    a.what
                )));
            }
            let shading = Shading::parse(&a.shading).ok_or_else(|| {
                Error::Usage(format!("--shading {}: unknown shading model", a.shading))
            })?;
            if let Some(bad) = a
                .samples
                .iter()
                .find(|&&s| ((s as f64).sqrt().round() as u32).pow(2) != s || s == 0)
            {
                return Err(Error::Usage(format!(
                    "--samples {bad}: use square numbers (1, 4, 9, ...)"
                )));
            }
            let job = lodeval::commands::RasterBench {
                rings: a.rings,
                sides: a.sides,
                size: a.size,
                views: a.views,
                samples: a.samples,
                shading,
                export: a.export,
                backend: a.backend.into(),
            };
            let rows = lodeval::commands::bench_raster(&job)?;
            let rss = lodeval::commands::peak_rss_mib().unwrap_or(f64::NAN);
            if a.json {
                return emit_json(&rows);
            }
            emit(
                &(lodeval::commands::raster_bench_table(&rows)
                    + &format!("peak RSS: {rss:.0} MiB\n")),
            )
        }
        Command::Eval(a) => {
            use std::io::IsTerminal;
            let shard = match &a.shard {
                Some(s) => lodeval::eval::Shard::parse(s)?,
                None => lodeval::eval::Shard::from_env(|k| std::env::var(k).ok())?
                    .unwrap_or(lodeval::eval::Shard::ALL),
            };
            let options = lodeval::eval::RunOptions {
                out: a.out,
                shard,
                progress: !cli.quiet && std::io::stderr().is_terminal(),
                backend: a.backend.into(),
            };
            let outcome = lodeval::eval::eval(&a.config, &options)?;
            gate_result(&outcome)
        }
        Command::Optimize(a) => {
            use lodeval::simplify::lindstrom_turk::{Normals, Options};
            if let Some(config) = &a.experiment {
                let quiet = cli.quiet;
                let rows = lodeval::experiments::lindstrom_turk::run(config, &mut |line| {
                    if !quiet {
                        eprintln!("{line}");
                    }
                })?;
                println!("{} runs; results.csv and plots written", rows.len());
                return Ok(());
            }
            let (Some(original), Some(simplified), Some(out)) =
                (a.original.clone(), a.simplified.clone(), a.out.clone())
            else {
                return Err(Error::Usage(
                    "give ORIGINAL SIMPLIFIED -o OUT, or --experiment CONFIG".into(),
                ));
            };
            let normals = match a.normals.as_str() {
                "derived" => Normals::Derived,
                "free" => Normals::Free,
                n => {
                    return Err(Error::Usage(format!("--normals {n}: use derived or free")));
                }
            };
            if a.views == 0 || a.size < 8 || a.size > 4096 {
                return Err(Error::Usage(
                    "--views must be at least 1 and --size within 8..4096".into(),
                ));
            }
            let mut options = Options::default();
            options.views = a.views;
            options.size = a.size;
            options.evals = a.evals;
            options.seed = a.seed;
            options.normals = normals;
            options.attributes = !a.no_attributes;
            let job = lodeval::commands::OptimizeJob {
                original,
                simplified,
                out: out.clone(),
                energy_csv: a.energy_csv,
                options,
                progress: !cli.quiet && std::io::IsTerminal::is_terminal(&std::io::stderr()),
            };
            let o = lodeval::commands::optimize(&job)?;
            println!(
                "{}  {} vertices  d_MS {:.6e} -> {:.6e} ({:.1} % of the input's energy)  {} evaluations in {:.1} s ({:.0}/s)  accepted: {} no-op, {} swap, {} teleport",
                out.display(),
                o.vertices.1,
                o.initial_d_ms,
                o.final_d_ms,
                100.0 * o.final_d_ms / o.initial_d_ms.max(f64::MIN_POSITIVE),
                o.evals,
                o.seconds,
                o.evals as f64 / o.seconds.max(1e-9),
                o.accepted.no_op,
                o.accepted.swap,
                o.accepted.teleport
            );
            Ok(())
        }
        Command::Simplify(SimplifyArgs {
            experiment: Some(config),
            ..
        }) => {
            let rows =
                lodeval::experiments::williams2003::run(&config, &mut |line| eprintln!("{line}"))?;
            eprintln!("{} curve points written", rows.len());
            Ok(())
        }
        Command::Simplify(a) if a.method == "williams" => {
            let rows = lodeval::commands::simplify_williams(&williams_job(&a)?)?;
            if a.json {
                return emit_json(&rows);
            }
            for r in &rows {
                println!(
                    "{}  {} triangles ({:.4} of the input)",
                    r.file.display(),
                    r.triangles,
                    r.ratio
                );
            }
            Ok(())
        }
        Command::Simplify(a) => {
            use lodeval::simplify::{Goal, Method};
            let method = match a.method.as_str() {
                "qem" => Method::Qem,
                "cluster" => Method::Cluster,
                "meshopt" => Method::Meshopt,
                "meshopt-update" => Method::MeshoptUpdate,
                m => {
                    return Err(Error::Usage(format!(
                        "--method {m}: use qem, cluster, meshopt, meshopt-update or williams"
                    )));
                }
            };
            let unit = |r: f64, what: &str| {
                if r > 0.0 && r <= 1.0 {
                    Ok(r)
                } else {
                    Err(Error::Usage(format!("{what} {r}: use a value in (0, 1]")))
                }
            };
            let goals: Vec<Goal> = if !a.chain.is_empty() {
                a.chain
                    .iter()
                    .map(|&r| unit(r, "--chain").map(Goal::Ratio))
                    .collect::<Result<_, _>>()?
            } else if let Some(r) = a.ratio {
                vec![Goal::Ratio(unit(r, "--ratio")?)]
            } else if let Some(t) = a.triangles {
                vec![Goal::Triangles(t.max(1))]
            } else if let Some(e) = a.error {
                vec![Goal::Error(unit(e, "--error")?)]
            } else {
                return Err(Error::Usage(
                    "give --ratio R, --triangles N, --error E or --chain R1,R2,...".into(),
                ));
            };
            let job = lodeval::commands::SimplifyJob {
                mesh: a.mesh.expect("clap requires it"),
                out: a.out.expect("clap requires it"),
                method,
                chain: !a.chain.is_empty(),
                goals: goals.clone(),
                progress: !cli.quiet && std::io::IsTerminal::is_terminal(&std::io::stderr()),
            };
            let rows = lodeval::commands::simplify(&job)?;
            warn_short_of_goals(&rows, &goals, method.name());
            if a.json {
                return emit_json(&rows);
            }
            let mut text = String::new();
            for r in &rows {
                text.push_str(&format!(
                    "{}  {} triangles ({:.4} of the input), simplifier error {}\n",
                    r.file.display(),
                    r.triangles,
                    r.ratio,
                    r.simplifier_error
                        .map_or_else(|| "-".to_string(), |e| format!("{e:.3e}"))
                ));
            }
            emit(&text)
        }
        Command::Geometry(a) => {
            let opts = LoadOptions::DEFAULT;
            let (ma, mb) = (
                lodeval::mesh::load(&a.a, &opts)?,
                lodeval::mesh::load(&a.b, &opts)?,
            );
            let d = lodeval::mesh::surface_distance::compare(&ma, &mb, a.samples);
            if a.json {
                return emit_json(&d);
            }
            emit(&format!(
                "hausdorff {:.6e} ({:.4} % of the diagonal)\nmean      {:.6e} ({:.4} %)\nrms       {:.6e} ({:.4} %)\nsamples   {} on A, {} on B; one-sided max A→B {:.6e}, B→A {:.6e}\n",
                d.hausdorff,
                d.hausdorff_relative * 100.0,
                d.mean,
                d.mean_relative * 100.0,
                d.rms,
                d.rms_relative * 100.0,
                d.samples[0],
                d.samples[1],
                d.one_sided_max[0],
                d.one_sided_max[1]
            ))
        }
        Command::Calibrate(a) => {
            let CalibrationSet::Modelfest = a.dataset;
            let job = lodeval::commands::CalibrateJob {
                data: a.data.clone(),
                condition: lodeval::metric::vdp::modelfest::Condition {
                    ppd: a.ppd,
                    background_cd_m2: a.background_cd_m2,
                },
                out: a.out.clone(),
            };
            let c = lodeval::commands::calibrate(&job)?;
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
        Command::Merge(a) => {
            let outcome = lodeval::eval::merge(&a.shards, &a.out)?;
            gate_result(&outcome)
        }
        Command::Golden(a) => {
            let plan = lodeval::eval::Plan::load(&a.config)?;
            let out = plan.config.out_dir(&plan.config_path, a.out.as_deref());
            let ci = std::env::var_os("CI").is_some_and(|v| !v.is_empty());
            let g = lodeval::eval::golden::run(&plan, a.bless, ci, &out)?;
            let dir = lodeval::eval::golden::golden_dir(&plan);
            if a.bless {
                return emit(&format!(
                    "blessed {} golden image(s) in {}\n",
                    g.checked,
                    dir.display()
                ));
            }
            for m in &g.mismatches {
                eprintln!("{m}");
            }
            if g.mismatches.is_empty() {
                emit(&format!(
                    "{} image(s) match their goldens in {}\n",
                    g.checked,
                    dir.display()
                ))
            } else {
                Err(Error::Regression(format!(
                    "{} of {} image(s) differ from their goldens; if the change is intended, run: lodeval golden {} --bless",
                    g.mismatches.len(),
                    g.checked,
                    a.config.display()
                )))
            }
        }
    }
}

/// Print an eval or merge outcome: the summary table on stdout, failures on stderr, exit 1 on
/// failure.
fn gate_result(outcome: &lodeval::eval::Outcome) -> Result<(), Error> {
    emit(&lodeval::eval::summary_table(outcome))?;
    for f in &outcome.failures {
        eprintln!("{}", f.message);
    }
    if outcome.failures.is_empty() {
        emit(&format!("wrote {}\n", outcome.out_dir.display()))
    } else {
        Err(Error::Regression(format!(
            "{} gate check(s) failed; details in {}",
            outcome.failures.len(),
            outcome.out_dir.join("report.html").display()
        )))
    }
}

/// The message of the last panic, kept so a crash is reported once, as an internal error.
static PANIC_MESSAGE: Mutex<Option<String>> = Mutex::new(None);

fn main() -> ExitCode {
    // Before anything else: a build for newer CPUs than this one would die of an illegal
    // instruction somewhere later.
    let missing = lodeval::cpu::missing();
    if !missing.is_empty() {
        let e = Error::Usage(format!(
            "this lodeval was built for x86-64-v3 CPUs and this CPU lacks {}; build it for this \
             CPU with RUSTFLAGS=\"\" cargo build --release (see .cargo/config.toml)",
            missing.join(", ")
        ));
        eprintln!("error: {e}");
        return ExitCode::from(e.exit_code());
    }
    let cli = Cli::parse();
    std::panic::set_hook(Box::new(|info| {
        if let Ok(mut slot) = PANIC_MESSAGE.lock() {
            *slot = Some(info.to_string());
        }
    }));
    let outcome = std::panic::catch_unwind(move || run(cli)).unwrap_or_else(|_| {
        let msg = PANIC_MESSAGE
            .lock()
            .ok()
            .and_then(|m| m.clone())
            .unwrap_or_default();
        Err(Error::Internal(msg))
    });
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}

/// The `simplify --method williams` request from its arguments.
fn williams_job(a: &SimplifyArgs) -> Result<lodeval::commands::WilliamsJob, Error> {
    use lodeval::commands::WilliamsViews;
    use lodeval::simplify::williams::Criterion;
    let shading = Shading::parse(&a.shading)
        .ok_or_else(|| Error::Usage(format!("--shading {}: unknown shading model", a.shading)))?;
    let criterion = Criterion::ALL
        .into_iter()
        .find(|c| c.name() == a.criterion)
        .ok_or_else(|| {
            Error::Usage(format!(
                "--criterion {}: use perceptual, object-space, screen-space or silhouette-10",
                a.criterion
            ))
        })?;
    let rig = Rig::parse(&a.rig).ok_or_else(|| {
        Error::Usage(format!(
            "--rig {}: use dodecahedron, icosahedron or fibonacci:N",
            a.rig
        ))
    })?;
    let views = match (a.camera.len(), a.all_views) {
        (0, true) => WilliamsViews::All(rig),
        (0, false) => WilliamsViews::One(rig, a.view.unwrap_or(0)),
        (3, _) => {
            WilliamsViews::Camera(glam::Vec3::new(a.camera[0], a.camera[1], a.camera[2]), None)
        }
        (6, _) => WilliamsViews::Camera(
            glam::Vec3::new(a.camera[0], a.camera[1], a.camera[2]),
            Some(glam::Vec3::new(a.camera[3], a.camera[4], a.camera[5])),
        ),
        (n, _) => {
            return Err(Error::Usage(format!(
                "--camera takes 3 numbers (eye) or 6 (eye, target), not {n}"
            )));
        }
    };
    use lodeval::simplify::williams::StaticGoal;
    let goal = match (a.budget, a.distance) {
        (Some(b), _) => StaticGoal::Budget(b),
        (None, Some(d)) if d.is_finite() && d > 0.0 => StaticGoal::Distance(d),
        (None, Some(d)) => {
            return Err(Error::Usage(format!(
                "--distance {d}: give a positive distance in metres"
            )));
        }
        (None, None) => {
            return Err(Error::Usage(
                "--method williams needs --budget N (triangles) or --distance METRES".into(),
            ));
        }
    };
    if a.size == 0 || a.size > 16384 {
        return Err(Error::Usage(format!(
            "--size {}: use 1..16384 pixels",
            a.size
        )));
    }
    Ok(lodeval::commands::WilliamsJob {
        mesh: a.mesh.clone().expect("clap requires it"),
        out: a.out.clone().expect("clap requires it"),
        goal,
        views,
        shading,
        criterion,
        size: a.size,
    })
}
