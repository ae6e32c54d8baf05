//! Orchestration behind the CLI subcommands that do more than call one library function. `main.rs`
//! parses arguments into these job structs and maps the `Result` to an exit code; everything that
//! touches meshes, frames or files happens here, so it is testable without a process.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::error::{Error, Result};
use crate::mesh::{self, LoadOptions, Mesh};
use crate::raster::{self, Frame, RenderScene, RenderSettings};
use crate::scene::{Camera, Rig, Scene};

/// Which views `lodeval render` writes.
#[derive(Debug, Clone, PartialEq)]
pub enum ViewSelection {
    /// One view, by number, to one file.
    One {
        /// View number within the rig.
        view: usize,
        /// Output PNG.
        out: PathBuf,
    },
    /// Every view of the rig into a folder as `view-NN.png`.
    All {
        /// Output folder.
        out_dir: PathBuf,
    },
    /// Every view of the rig tiled into one contact-sheet PNG.
    Sheet {
        /// Output PNG.
        out: PathBuf,
    },
}

/// A `lodeval render` request.
#[derive(Debug, Clone)]
pub struct RenderJob {
    /// Mesh file.
    pub mesh: PathBuf,
    /// Loader options.
    pub load: LoadOptions,
    /// Render settings (size, samples, shading, culling).
    pub settings: RenderSettings,
    /// View rig.
    pub rig: Rig,
    /// Views and outputs.
    pub views: ViewSelection,
    /// Also write linear float EXR files beside each PNG.
    pub exr: bool,
    /// Where to render.
    pub backend: crate::backend::Backend,
}

fn write_frame(path: &Path, frame: &Frame, exr: bool) -> Result<()> {
    crate::io::write_image(path, &image::DynamicImage::ImageRgb8(frame.to_srgb8()))?;
    if exr {
        crate::io::write_image(
            &path.with_extension("exr"),
            &image::DynamicImage::ImageRgb32F(frame.to_rgb32f()),
        )?;
    }
    Ok(())
}

/// Run a render job; returns the files written.
pub fn render(job: &RenderJob) -> Result<Vec<PathBuf>> {
    let mesh = Arc::new(mesh::load(&job.mesh, &job.load)?);
    let scene = RenderScene::of(mesh.clone());
    let aspect = job.settings.width as f32 / job.settings.height as f32;
    let cameras = job.rig.cameras(&mesh, aspect);
    let engine = crate::backend::Engine::new(job.backend)?;
    let renderer = engine.scene(&scene)?;
    let mut written = Vec::new();
    match &job.views {
        ViewSelection::One { view, out } => {
            let camera = cameras.get(*view).ok_or_else(|| {
                Error::Usage(format!(
                    "--view {view} does not exist: the rig has views 0..{}",
                    cameras.len() - 1
                ))
            })?;
            write_frame(out, &renderer.render(camera, &job.settings)?, job.exr)?;
            written.push(out.clone());
        }
        ViewSelection::All { out_dir } => {
            for (k, camera) in cameras.iter().enumerate() {
                let out = out_dir.join(format!("view-{k:02}.png"));
                write_frame(&out, &renderer.render(camera, &job.settings)?, job.exr)?;
                written.push(out);
            }
        }
        ViewSelection::Sheet { out } => {
            let frames = cameras
                .iter()
                .map(|c| renderer.render(c, &job.settings).map(|f| f.to_srgb8()))
                .collect::<Result<Vec<_>>>()?;
            let columns = (frames.len() as f32).sqrt().ceil() as u32;
            let sheet = raster::contact_sheet(&frames, columns, 4, [32, 32, 32]);
            crate::io::write_image(out, &image::DynamicImage::ImageRgb8(sheet))?;
            written.push(out.clone());
        }
    }
    Ok(written)
}

/// A `lodeval bench raster` request.
#[derive(Debug, Clone)]
pub struct RasterBench {
    /// Torus resolution: `rings × sides × 2` triangles (1000 × 500 gives exactly 1 M).
    pub rings: u32,
    /// See `rings`.
    pub sides: u32,
    /// Image edge in pixels.
    pub size: u32,
    /// Views (Fibonacci rig), rendered once each per sample setting.
    pub views: u32,
    /// Sample counts to measure (each a square).
    pub samples: Vec<u32>,
    /// Shading model.
    pub shading: raster::Shading,
    /// Also write the scene (mesh and per-view matrices) here, for rendering the identical scene
    /// with another renderer (`benches/llvmpipe_raster.py`).
    pub export: Option<PathBuf>,
    /// Where the frames are rendered (the region re-render is CPU-only and is timed on the CPU).
    pub backend: crate::backend::Backend,
}

/// One line of the benchmark table.
#[derive(Debug, Clone, serde::Serialize)]
pub struct RasterBenchRow {
    /// Triangles in the mesh.
    pub triangles: usize,
    /// Image edge, pixels.
    pub size: u32,
    /// Samples per pixel.
    pub samples: u32,
    /// Views rendered.
    pub views: u32,
    /// Worker threads.
    pub threads: usize,
    /// Mean milliseconds per frame.
    pub ms_per_frame: f64,
    /// Frames per second.
    pub frames_per_s: f64,
    /// Millions of triangles per second.
    pub mtri_per_s: f64,
    /// Mean microseconds to re-render one 16×16-pixel rectangle of a kept frame
    /// ([`raster::RegionRenderer::render_rect`]), over 256 rectangles across the object.
    pub region_16_us: f64,
    /// The renderer timed (`cpu` or `gpu: ADAPTER …`).
    pub backend: String,
}

/// Render a procedural torus from every view and time it. Timing is for reporting only: nothing
/// asserts on it.
pub fn bench_raster(b: &RasterBench) -> Result<Vec<RasterBenchRow>> {
    let mesh = Arc::new(crate::mesh::shapes::torus(b.rings, b.sides, 0.35));
    let scene = RenderScene::of(mesh.clone());
    let cameras = Rig::Fibonacci(b.views).cameras(&mesh, 1.0);
    if let Some(dir) = &b.export {
        export_scene(dir, &scene, &cameras)?;
        // View 0 at 1 sample, to compare pictures with the other renderer's.
        let mut one = RenderSettings::DEFAULT;
        (one.width, one.height, one.shading) = (b.size, b.size, b.shading);
        one.samples = raster::SamplePattern::Ordered(1);
        write_frame(
            &dir.join("lodeval-view0.png"),
            &raster::render(&scene, &cameras[0], &one)?,
            false,
        )?;
    }
    let engine = crate::backend::Engine::new(b.backend)?;
    let timed = engine.scene(&scene)?;
    let mut rows = Vec::new();
    for &samples in &b.samples {
        let n = (samples as f64).sqrt().round() as u32;
        let mut settings = RenderSettings::DEFAULT;
        settings.width = b.size;
        settings.height = b.size;
        settings.shading = b.shading;
        settings.samples = raster::SamplePattern::Rotated(n);
        // Warm-up frame (page faults, allocator), not timed.
        timed.render(&cameras[0], &settings)?;
        let start = std::time::Instant::now();
        for c in &cameras {
            std::hint::black_box(timed.render(c, &settings)?);
        }
        let secs = start.elapsed().as_secs_f64() / cameras.len() as f64;
        // Region re-render: 16×16 rectangles on a 16×16 grid over the middle of the image.
        let mut region = raster::RegionRenderer::new(&scene, &cameras[0], &settings)?;
        let step = (b.size / 2 / 16).max(1) as i32;
        let origin = (b.size / 4) as i32;
        let start = std::time::Instant::now();
        for i in 0..256 {
            let (x, y) = (origin + (i % 16) * step, origin + (i / 16) * step);
            region.render_rect([x, y, x + 16, y + 16]);
        }
        let region_16_us = start.elapsed().as_secs_f64() / 256.0 * 1e6;
        rows.push(RasterBenchRow {
            region_16_us,
            triangles: mesh.triangle_count(),
            size: b.size,
            samples: n * n,
            views: b.views,
            threads: rayon::current_num_threads(),
            ms_per_frame: secs * 1e3,
            frames_per_s: 1.0 / secs,
            mtri_per_s: mesh.triangle_count() as f64 / secs / 1e6,
            backend: engine.describe(),
        });
    }
    Ok(rows)
}

/// The rows of `lodeval bench raster` as a Markdown table.
pub fn raster_bench_table(rows: &[RasterBenchRow]) -> String {
    let mut text = String::from(
        "| triangles | size | samples | views | threads | ms/frame | frames/s | Mtri/s | 16×16 region µs (CPU) | backend |\n|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        text.push_str(&format!(
            "| {} | {} | {} | {} | {} | {:.1} | {:.2} | {:.1} | {:.0} | {} |\n",
            r.triangles,
            r.size,
            r.samples,
            r.views,
            r.threads,
            r.ms_per_frame,
            r.frames_per_s,
            r.mtri_per_s,
            r.region_16_us,
            r.backend
        ));
    }
    text
}

/// Peak resident set size of this process in MiB (Linux `VmHWM`), if known.
pub fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// Write a scene as raw little-endian arrays plus a JSON list of views: `positions.f32`,
/// `normals.f32` (xyz per vertex), `indices.u32` (three per triangle) and `views.json` with each
/// view's column-major model-view-projection matrix (depth 0..1), unit light direction, light
/// colour, direction towards the eye, ambient term and the material's Blinn–Phong parameters.
pub fn export_scene(dir: &Path, scene: &Scene, cameras: &[Camera]) -> Result<()> {
    let mesh = scene.mesh();
    let floats = |v: &[glam::Vec3]| {
        v.iter()
            .flat_map(|p| p.to_array())
            .flat_map(f32::to_le_bytes)
            .collect::<Vec<u8>>()
    };
    crate::io::write_atomic(&dir.join("positions.f32"), &floats(mesh.positions()))?;
    crate::io::write_atomic(&dir.join("normals.f32"), &floats(mesh.normals()))?;
    let idx: Vec<u8> = mesh
        .triangles()
        .iter()
        .flatten()
        .flat_map(|i| i.to_le_bytes())
        .collect();
    crate::io::write_atomic(&dir.join("indices.u32"), &idx)?;
    let m = &mesh.materials()[0];
    let views: Vec<serde_json::Value> = cameras
        .iter()
        .map(|c| {
            let mvp = c.projection(1.0) * c.view();
            let (l, color) = scene.lights[0].resolve(c);
            serde_json::json!({
                "mvp": mvp.to_cols_array(),
                "light_dir": l.to_array(),
                "light_color": color.to_array(),
                "to_eye": c.to_eye().to_array(),
                "ambient": scene.ambient,
                "base_color": m.base_color.to_array(),
                "specular": m.specular.to_array(),
                "shininess": m.shininess,
                "background": scene.background.to_array(),
            })
        })
        .collect();
    let json = serde_json::to_string_pretty(&views).map_err(|e| Error::Internal(e.to_string()))?;
    crate::io::write_atomic(&dir.join("views.json"), json.as_bytes())
}

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
                DiffMetric::Psnr => {
                    r.value = Some(engine.mse(&a, &b)?.psnr_db).filter(|v| v.is_finite())
                }
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
    let cases: [(&str, &dyn Fn() -> Result<f64>); 4] = [
        ("flip", &|| flip.compare(&a, &b).map(|s| s.mean)),
        ("vdp", &|| vdp.compare(&a, &b).map(|s| s.jnd)),
        ("ssim", &|| {
            ssim::ssim(&a, &b, ssim::SsimInput::SrgbLuma).map(|s| s.0)
        }),
        ("psnr", &|| mse::mse(&a, &b).map(|s| s.psnr_db)),
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

/// A `lodeval simplify` request.
#[derive(Debug, Clone)]
pub struct SimplifyJob {
    /// Input mesh.
    pub mesh: PathBuf,
    /// Output `.obj` (with `--chain`: the stem; files become `STEM-rXX.obj`).
    pub out: PathBuf,
    /// Method.
    pub method: crate::simplify::Method,
    /// Goals (one, or the chain).
    pub goals: Vec<crate::simplify::Goal>,
    /// Write one file per goal with a suffix (a chain) rather than `out` itself.
    pub chain: bool,
    /// Show a spinner on stderr while simplifying (large meshes take seconds).
    pub progress: bool,
}

/// One written LOD.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SimplifyRow {
    /// The file written.
    pub file: PathBuf,
    /// Triangles.
    pub triangles: usize,
    /// Over the input's triangles.
    pub ratio: f64,
    /// The simplifier's own error estimate, model units.
    pub simplifier_error: Option<f64>,
    /// Seconds for the whole chain (wall clock; reporting only).
    pub seconds: f64,
}

/// Check that `out` is an OBJ path, then load `input` (the simplifiers' common start).
fn load_for_lod(input: &Path, out: &Path) -> Result<Mesh> {
    if out.extension().and_then(|e| e.to_str()) != Some("obj") {
        return Err(Error::Usage(format!(
            "-o {}: lodeval writes LODs as .obj (with .mtl and textures beside it)",
            out.display()
        )));
    }
    mesh::load(input, &LoadOptions::default())
}

/// Simplify a mesh and write the LOD(s) as OBJ.
pub fn simplify(job: &SimplifyJob) -> Result<Vec<SimplifyRow>> {
    let mesh = load_for_lod(&job.mesh, &job.out)?;
    let start = std::time::Instant::now();
    let spinner = crate::eval::run::spinner(
        job.progress,
        format!(
            "simplifying {} triangles with {}",
            mesh.triangle_count(),
            job.method.name()
        ),
    );
    let lods = crate::simplify::chain(&mesh, job.method, &job.goals);
    spinner.finish_and_clear();
    let lods = lods?;
    let seconds = start.elapsed().as_secs_f64();
    let stem = job
        .out
        .file_stem()
        .map_or_else(|| "lod".into(), |s| s.to_string_lossy().into_owned());
    let mut rows = Vec::new();
    for (lod, goal) in lods.iter().zip(&job.goals) {
        let file = if job.chain {
            let suffix = match goal {
                crate::simplify::Goal::Ratio(r) => {
                    format!("r{}", crate::eval::config::percent_label(*r))
                }
                crate::simplify::Goal::Triangles(t) => format!("t{t}"),
                crate::simplify::Goal::Error(e) => format!("e{e}"),
            };
            job.out.with_file_name(format!("{stem}-{suffix}.obj"))
        } else {
            job.out.clone()
        };
        crate::mesh::write_obj::write(&lod.mesh, &file)?;
        rows.push(SimplifyRow {
            file,
            triangles: lod.mesh.triangle_count(),
            ratio: lod.mesh.triangle_count() as f64 / mesh.triangle_count() as f64,
            simplifier_error: lod.error,
            seconds,
        });
    }
    Ok(rows)
}

/// Which views a Williams et al. LOD is made for.
#[derive(Debug, Clone)]
pub enum WilliamsViews {
    /// View K of a rig (default framing).
    One(Rig, usize),
    /// One static LOD for every view of a rig.
    All(Rig),
    /// A camera at an eye position looking at a target (default: the model's centre), framed
    /// with the default field of view.
    Camera(glam::Vec3, Option<glam::Vec3>),
}

/// A `lodeval simplify --method williams` request.
#[derive(Debug, Clone)]
pub struct WilliamsJob {
    /// Input mesh.
    pub mesh: PathBuf,
    /// Output `.obj`.
    pub out: PathBuf,
    /// A triangle budget, or a viewing distance (metres) from which the LOD is to be
    /// imperceptible.
    pub goal: crate::simplify::williams::StaticGoal,
    /// Views.
    pub views: WilliamsViews,
    /// Shading the LOD is for.
    pub shading: crate::raster::Shading,
    /// Error criterion.
    pub criterion: crate::simplify::williams::Criterion,
    /// Image size (pixels) the views are seen at.
    pub size: u32,
}

/// Simplify with Williams et al. 2003 and write the LOD as OBJ.
pub fn simplify_williams(job: &WilliamsJob) -> Result<Vec<SimplifyRow>> {
    use crate::simplify::williams::{Options, Williams};
    let mesh = load_for_lod(&job.mesh, &job.out)?;
    let start = std::time::Instant::now();
    let w = Williams::build(&mesh)?;
    let opts = Options {
        shading: job.shading,
        criterion: job.criterion,
        size: (job.size, job.size),
        ..Options::default()
    };
    let cameras = match &job.views {
        WilliamsViews::All(rig) => rig.cameras(&mesh, 1.0),
        WilliamsViews::One(rig, k) => {
            let cams = rig.cameras(&mesh, 1.0);
            vec![*cams.get(*k).ok_or_else(|| {
                Error::Usage(format!("--view {k}: the rig has views 0..{}", cams.len()))
            })?]
        }
        WilliamsViews::Camera(eye, target) => {
            let sphere = mesh.bounding_sphere();
            let target = target.unwrap_or(sphere.center);
            if !(eye.is_finite() && target.is_finite()) || eye.distance(target) <= 0.0 {
                return Err(Error::Usage(
                    "--camera: the eye must be finite and apart from the target".into(),
                ));
            }
            vec![Camera::looking_at(
                sphere,
                *eye,
                target,
                Camera::DEFAULT_FOV_Y_DEG,
            )]
        }
    };
    let lod = w.static_lod(&cameras, job.goal, &opts)?;
    let seconds = start.elapsed().as_secs_f64();
    crate::mesh::write_obj::write(&lod, &job.out)?;
    Ok(vec![SimplifyRow {
        file: job.out.clone(),
        triangles: lod.triangle_count(),
        ratio: lod.triangle_count() as f64 / mesh.triangle_count() as f64,
        simplifier_error: None,
        seconds,
    }])
}

/// One row of `lodeval bench williams`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct WilliamsBenchRow {
    /// Input triangles.
    pub triangles: usize,
    /// MT nodes.
    pub nodes: usize,
    /// Seconds to build the MT (QEM run and its replay).
    pub hierarchy_seconds: f64,
    /// Seconds of the per-node preprocessing.
    pub preprocess_seconds: f64,
    /// Triangle budget.
    pub budget: usize,
    /// Frames (views along the path) after the first.
    pub frames: usize,
    /// Adapt time per frame after the first: median, 95th percentile, max (ms).
    pub median_ms: f64,
    /// 95th percentile (ms).
    pub p95_ms: f64,
    /// Max (ms).
    pub max_ms: f64,
    /// The first frame, from the coarsest cut (ms).
    pub first_ms: f64,
    /// Nodes raised or lowered per frame (median).
    pub median_changes: usize,
}

/// Williams et al. preprocessing time and per-frame cut adaptation along a camera path: an orbit
/// of `views` cameras around the model (slightly above it), each turned 360°/`views` from the
/// last, for each budget ratio. Times are wall clock (reporting only).
pub fn bench_williams(mesh: &Mesh, ratios: &[f64], views: u32) -> Result<Vec<WilliamsBenchRow>> {
    use crate::simplify::williams::{Cut, Options, Williams};
    let (w, [hierarchy_seconds, preprocess_seconds]) = Williams::build_timed(mesh)?;
    let n = views.max(2);
    let orbit = (0..n)
        .map(|i| {
            let a = i as f32 * std::f32::consts::TAU / n as f32;
            glam::Vec3::new(a.sin(), 0.3, a.cos()).normalize()
        })
        .collect();
    let cameras = Rig::Explicit(orbit).cameras(mesh, 1.0);
    let opts = Options::default();
    let mut rows = Vec::new();
    for &r in ratios {
        let budget = ((mesh.triangle_count() as f64 * r).round() as usize).max(1);
        let mut cut = Cut::coarsest(&w.hierarchy);
        let mut times = Vec::new();
        let mut changes = Vec::new();
        for c in &cameras {
            let t = std::time::Instant::now();
            w.adapt(&mut cut, c, budget, &opts);
            times.push(t.elapsed().as_secs_f64() * 1e3);
            changes.push(cut.last_changes);
        }
        let first_ms = times.remove(0);
        changes.remove(0);
        let mut sorted = times.clone();
        sorted.sort_by(f64::total_cmp);
        changes.sort_unstable();
        let pick = |q: f64| sorted[((sorted.len() - 1) as f64 * q).round() as usize];
        rows.push(WilliamsBenchRow {
            triangles: mesh.triangle_count(),
            nodes: w.hierarchy.node_count(),
            hierarchy_seconds,
            preprocess_seconds,
            budget,
            frames: sorted.len(),
            median_ms: pick(0.5),
            p95_ms: pick(0.95),
            max_ms: pick(1.0),
            first_ms,
            median_changes: changes[changes.len() / 2],
        });
    }
    Ok(rows)
}

/// One row of `lodeval bench optimize`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct OptimizeBenchRow {
    /// Mesh name.
    pub mesh: String,
    /// The original's triangles.
    pub input_triangles: usize,
    /// The optimizer's input, our QEM's LOD of the original: its triangles.
    pub triangles: usize,
    /// Its (welded) vertices.
    pub vertices: usize,
    /// Views (the optimizer's default, the dodecahedron's 20).
    pub views: u32,
    /// Image edge in pixels (the optimizer's default).
    pub size: u32,
    /// Threads the optimizer's trials ran on (the pool's, at most one per core).
    pub threads: usize,
    /// Energy evaluations per run.
    pub evaluations: u64,
    /// Timed runs.
    pub runs: usize,
    /// Steady evaluations per second (from the energy log's first row, after the set-up, to its
    /// last) of the best run.
    pub best_per_s: f64,
    /// The same, median run.
    pub median_per_s: f64,
    /// The same, worst run.
    pub worst_per_s: f64,
    /// Set-up seconds (target images and the input's first render), median of the runs.
    pub setup_seconds: f64,
}

/// Simplify each mesh with our QEM to `triangles` triangles and run the image-driven optimizer
/// on it `runs` times for `evals` evaluations (20 views at 256², derived normals: the issue's
/// throughput case); report the steady evaluation rate of each run. The runs' outputs are the
/// same (the optimizer is deterministic); only their times differ.
pub fn bench_optimize(
    meshes: &[(String, Mesh)],
    triangles: usize,
    evals: u64,
    runs: usize,
) -> Result<Vec<OptimizeBenchRow>> {
    use crate::simplify::lindstrom_turk::{self, Options};
    use crate::simplify::{Goal, Method};
    let options = Options {
        evals,
        ..Options::default()
    };
    let mut rows = Vec::new();
    for (name, mesh) in meshes {
        let lod = crate::simplify::chain(mesh, Method::Qem, &[Goal::Triangles(triangles)])?
            .pop()
            .ok_or_else(|| Error::Internal("no LOD".into()))?;
        let (original, input) = (
            std::sync::Arc::new(mesh.clone()),
            std::sync::Arc::new(lod.mesh),
        );
        let (mut rates, mut setups) = (Vec::new(), Vec::new());
        for _ in 0..runs.max(1) {
            let outcome = lindstrom_turk::optimize(&original, &input, &options, &|_| {})?;
            let (Some(first), Some(last)) = (outcome.log.first(), outcome.log.last()) else {
                return Err(Error::Internal("an empty energy log".into()));
            };
            let seconds = last.seconds - first.seconds;
            if last.evals <= first.evals || seconds <= 0.0 {
                return Err(Error::Usage(format!(
                    "{name}: {evals} evaluations are too few to time; give --evals 1000 or more"
                )));
            }
            rates.push((last.evals - first.evals) as f64 / seconds);
            setups.push(first.seconds);
        }
        rates.sort_by(f64::total_cmp);
        setups.sort_by(f64::total_cmp);
        rows.push(OptimizeBenchRow {
            mesh: name.clone(),
            input_triangles: mesh.triangle_count(),
            triangles: input.triangle_count(),
            vertices: input.welded_vertex_count(),
            views: options.views,
            size: options.size,
            threads: crate::raster::luminance::crew_threads(),
            evaluations: evals,
            runs: rates.len(),
            best_per_s: rates[rates.len() - 1],
            median_per_s: rates[rates.len() / 2],
            worst_per_s: rates[0],
            setup_seconds: setups[setups.len() / 2],
        });
    }
    Ok(rows)
}

/// One row of `lodeval bench simplify`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SimplifyBenchRow {
    /// Mesh name.
    pub mesh: String,
    /// Input triangles.
    pub input_triangles: usize,
    /// Method.
    pub method: String,
    /// Target ratio.
    pub ratio: f64,
    /// Output triangles.
    pub triangles: usize,
    /// Seconds for this one simplification from the original (single target), the best of the
    /// timed runs (one thread for meshopt; ours as many as the pool has).
    pub seconds: f64,
    /// The median of the timed runs' seconds.
    pub median_seconds: f64,
    /// Millions of input triangles per second.
    pub mtri_per_s: f64,
    /// Measured symmetric Hausdorff distance over the bounding-box diagonal.
    pub hausdorff_relative: f64,
    /// Measured mean surface distance over the diagonal.
    pub mean_relative: f64,
}

/// Simplify each mesh with QEM and meshopt to each ratio (each from the original), time it and
/// measure the result with the Metro-style distance. Each simplification is timed `runs` times,
/// the methods taking turns (so a slow spell of the machine hits all of them); the best and the
/// median are reported. Reporting only.
pub fn bench_simplify(
    meshes: &[(String, Mesh)],
    ratios: &[f64],
    samples: usize,
    runs: usize,
) -> Result<Vec<SimplifyBenchRow>> {
    use crate::simplify::{Goal, Method};
    const METHODS: [Method; 3] = [Method::Meshopt, Method::MeshoptUpdate, Method::Qem];
    let mut rows = Vec::new();
    for (name, mesh) in meshes {
        let original = crate::mesh::surface_distance::Original::new(mesh, samples);
        for &ratio in ratios {
            let mut times = [const { Vec::new() }; METHODS.len()];
            let mut lods = Vec::new();
            for _ in 0..runs.max(1) {
                lods.clear();
                for (k, &method) in METHODS.iter().enumerate() {
                    let start = std::time::Instant::now();
                    let lod = crate::simplify::chain(mesh, method, &[Goal::Ratio(ratio)])?
                        .pop()
                        .ok_or_else(|| Error::Internal("no LOD".into()))?;
                    times[k].push(start.elapsed().as_secs_f64());
                    lods.push(lod);
                }
            }
            for ((method, lod), times) in METHODS.into_iter().zip(&lods).zip(&mut times) {
                times.sort_by(f64::total_cmp);
                let (seconds, median_seconds) = (times[0], times[times.len() / 2]);
                let d = original.compare(&lod.mesh);
                rows.push(SimplifyBenchRow {
                    mesh: name.clone(),
                    input_triangles: mesh.triangle_count(),
                    method: method.name().into(),
                    ratio,
                    triangles: lod.mesh.triangle_count(),
                    seconds,
                    median_seconds,
                    mtri_per_s: mesh.triangle_count() as f64 / seconds / 1e6,
                    hausdorff_relative: d.hausdorff_relative,
                    mean_relative: d.mean_relative,
                });
            }
        }
    }
    Ok(rows)
}

/// What `lodeval optimize` does.
#[derive(Debug, Clone)]
pub struct OptimizeJob {
    /// The original (target) mesh.
    pub original: PathBuf,
    /// The simplified mesh to improve.
    pub simplified: PathBuf,
    /// Output OBJ.
    pub out: PathBuf,
    /// Energy log CSV, if wanted.
    pub energy_csv: Option<PathBuf>,
    /// Optimizer settings.
    pub options: crate::simplify::lindstrom_turk::Options,
    /// Show a progress bar.
    pub progress: bool,
}

/// Run the image-driven optimizer and write the mesh (and the energy log).
pub fn optimize(job: &OptimizeJob) -> Result<crate::simplify::lindstrom_turk::Outcome> {
    use crate::simplify::lindstrom_turk;
    if job.out.extension().and_then(|e| e.to_str()) != Some("obj") {
        return Err(Error::Usage(format!(
            "-o {}: lodeval writes optimized meshes as .obj",
            job.out.display()
        )));
    }
    let original = std::sync::Arc::new(mesh::load(&job.original, &LoadOptions::default())?);
    let simplified = std::sync::Arc::new(mesh::load(&job.simplified, &LoadOptions::default())?);
    let bar = crate::eval::run::progress_bar(job.progress, job.options.evals, "evaluations");
    let outcome = lindstrom_turk::optimize(&original, &simplified, &job.options, &|n| {
        bar.set_position(n)
    })?;
    bar.finish_and_clear();
    crate::mesh::write_obj::write(&outcome.mesh, &job.out)?;
    if let Some(path) = &job.energy_csv {
        crate::io::csv::write_rows(path, None, &outcome.log)?;
    }
    Ok(outcome)
}

/// A `lodeval calibrate modelfest` request.
#[derive(Debug, Clone)]
pub struct CalibrateJob {
    /// The oracle folder (`reference/oracles/modelfest`).
    pub data: PathBuf,
    /// The viewing condition (ModelFest's by default).
    pub condition: crate::metric::vdp::modelfest::Condition,
    /// Where to write `modelfest.csv` and `modelfest.svg` (none: nothing written).
    pub out: Option<PathBuf>,
}

/// Check the VDP against ModelFest; write the per-stimulus table and the plot when asked.
pub fn calibrate(job: &CalibrateJob) -> Result<crate::metric::vdp::modelfest::Calibration> {
    use crate::metric::vdp::{VdpParams, modelfest};
    job.condition.check()?;
    let data = modelfest::ModelFest::load(&job.data)?;
    let result = modelfest::calibrate(&data, VdpParams::fitted(), job.condition)?;
    if let Some(dir) = &job.out {
        std::fs::create_dir_all(dir).map_err(|e| {
            Error::input(
                dir,
                format!("cannot create the output folder: {e}"),
                "give a writable --out folder",
            )
        })?;
        crate::io::csv::write_rows(&dir.join("modelfest.csv"), None, &result.stimuli)?;
        let points: Vec<crate::io::plot::LabelledPoint> = result
            .stimuli
            .iter()
            .map(|r| (r.observed, r.predicted, r.id.to_string()))
            .collect();
        let svg = crate::io::plot::scatter_identity(
            "ModelFest: lodeval's VDP against 16 observers",
            &format!(
                "RMSE {:.3} log10 over {} stimuli at {} ppd, {} cd/m²; dashed: ±0.1",
                result.rmse_log10,
                result.stimuli.len(),
                result.ppd,
                result.background_cd_m2
            ),
            "observed log10 contrast sensitivity (mean of 16 observers)",
            "predicted log10 contrast sensitivity",
            &points,
            0.1,
        );
        crate::io::write_atomic(&dir.join("modelfest.svg"), svg.as_bytes())?;
    }
    Ok(result)
}
