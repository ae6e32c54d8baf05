//! The paper's evaluation (Williams et al. 2003 §6, Figure 4), rebuilt with lodeval's renderer and
//! metrics: for each scene (a model and the shading it is shown with), each error criterion —
//! the perceptual imperceptibility distance, view-independent object-space error, screen-space
//! texture deviation, and screen-space deviation ×10 on the silhouette — and each triangle budget,
//! the view-dependent LOD of each view is rendered on a mid-grey background and scored against the
//! original's render with FLIP and the VDP.
//!
//! As in the paper, one view per curve (view 0 of the dodecahedron rig, at `single_size`, 1024²
//! by default); in addition the mean over all views of the rig (at `mean_size`), walking the views
//! in order with the cut and queues carried from one view to the next (temporal coherence). Every
//! LOD is made for the image size it is scored at.
//!
//! Writes `results.csv` (one row per scene, criterion, budget, view and size), `summary.csv` (view
//! 0 and the mean per scene, criterion and budget), `preprocess.csv` (hierarchy build and
//! preprocessing time per scene), one SVG per scene (`SCENE.svg`: FLIP and VDP JND against budget),
//! and a contact sheet per scene at the smallest budget (`SCENE-sheet.png`: the original and each
//! criterion's LOD, view 0 at `mean_size`, shown at most [`SHEET_SIZE`] pixels wide).

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::eval::score::{Reference, Scorer};
use crate::image::LinearImage;
use crate::io::plot::{Series, line_plot};
use crate::io::plot_png::Chart;
use crate::mesh::{self, LoadOptions, Mesh};
use crate::metric::{Metric, MetricFamily};
use crate::raster::{self, Frame, RenderScene, RenderSettings, SamplePattern, Shading};
use crate::scene::{Camera, Rig, Viewing};
use crate::simplify::williams::{Criterion, Cut, Options, Williams};

/// Largest image side in the contact sheets, pixels.
pub const SHEET_SIZE: u32 = 512;

/// One scene: a model and its shading.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// Name for files and tables.
    pub name: String,
    /// Mesh path, relative to the config file.
    pub mesh: PathBuf,
    /// Shading model name (`gouraud`, `normal-mapped`, `unlit`, `phong`).
    pub shading: String,
}

/// The experiment config.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Experiment {
    /// Output folder, relative to the config file.
    pub out: PathBuf,
    /// Budgets as fractions of each original's triangles.
    pub budgets: Vec<f64>,
    /// Criteria to compare. Default value: all four.
    #[serde(default = "all_criteria")]
    pub criteria: Vec<Criterion>,
    /// Image size of the single-view curves. Default value: 1024.
    #[serde(default = "default_single")]
    pub single_size: u32,
    /// Image size of the all-views mean. Default value: 512.
    #[serde(default = "default_mean")]
    pub mean_size: u32,
    /// Views of the mean: a rig name. Default value: `dodecahedron` (20 views).
    #[serde(default = "default_rig")]
    pub rig: String,
    /// Samples per pixel (n×n rotated grid, n). Default value: 2 (4 samples).
    #[serde(default = "default_samples")]
    pub samples: u32,
    /// Carry the cut from one view of the mean to the next (§5.1's temporal coherence); false
    /// starts every view from the coarsest cut. Default value: true.
    #[serde(default = "default_true")]
    pub temporal_coherence: bool,
    /// Scenes.
    pub scene: Vec<SceneSpec>,
}

fn default_true() -> bool {
    true
}

fn all_criteria() -> Vec<Criterion> {
    Criterion::ALL.to_vec()
}
fn default_single() -> u32 {
    1024
}
fn default_mean() -> u32 {
    512
}
fn default_rig() -> String {
    "dodecahedron".into()
}
fn default_samples() -> u32 {
    2
}

/// One scored LOD.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// Scene name.
    pub scene: String,
    /// Criterion name.
    pub criterion: String,
    /// Budget, triangles.
    pub budget: usize,
    /// Budget as a fraction of the original.
    pub ratio: f64,
    /// View index.
    pub view: usize,
    /// Image size.
    pub size: u32,
    /// Triangles of the LOD.
    pub triangles: usize,
    /// FLIP mean.
    pub flip: f64,
    /// VDP detection probability.
    pub vdp: f64,
    /// VDP in JND.
    pub vdp_jnd: f64,
}

/// One line of `summary.csv`.
#[derive(Debug, Clone, Serialize)]
pub struct SummaryRow {
    /// Scene name.
    pub scene: String,
    /// Criterion name.
    pub criterion: String,
    /// Budget, triangles.
    pub budget: usize,
    /// Budget as a fraction of the original.
    pub ratio: f64,
    /// View 0 at `single_size`: FLIP.
    pub view0_flip: f64,
    /// View 0 at `single_size`: VDP JND.
    pub view0_vdp_jnd: f64,
    /// Mean over the rig at `mean_size`: FLIP.
    pub mean_flip: f64,
    /// Mean over the rig at `mean_size`: VDP JND.
    pub mean_vdp_jnd: f64,
}

/// One line of `preprocess.csv`.
#[derive(Debug, Clone, Serialize)]
pub struct PreprocessRow {
    /// Scene name.
    pub scene: String,
    /// Triangles of the original.
    pub triangles: usize,
    /// MT nodes.
    pub nodes: usize,
    /// MT triangles (all levels).
    pub mt_triangles: usize,
    /// Seconds to build the MT and preprocess it (wall clock; reporting only).
    pub seconds: f64,
}

/// Parse a config file.
pub fn load(config: &Path) -> Result<Experiment> {
    let exp: Experiment =
        crate::simplify::read_experiment(config, "configs/papers/williams2003.toml")?;
    if exp.budgets.iter().any(|&b| !(b > 0.0 && b <= 1.0)) {
        return Err(Error::input(
            config,
            "a budget is outside (0, 1]",
            "give budgets as fractions of the original's triangles",
        ));
    }
    for s in &exp.scene {
        if Shading::parse(&s.shading).is_none() {
            return Err(Error::input(
                config,
                format!("scene {}: unknown shading {}", s.name, s.shading),
                "use gouraud, phong, normal-mapped or unlit",
            ));
        }
    }
    if let Err(problem) = Rig::parse(&exp.rig) {
        return Err(Error::input(
            config,
            problem,
            "use dodecahedron, icosahedron or fibonacci:N",
        ));
    }
    Ok(exp)
}

fn settings(size: u32, samples: u32, shading: Shading) -> RenderSettings {
    RenderSettings {
        width: size,
        height: size,
        samples: SamplePattern::Rotated(samples),
        shading,
        ..RenderSettings::DEFAULT
    }
}

fn linear(frame: &Frame) -> Result<LinearImage> {
    LinearImage::new(
        frame.width() as usize,
        frame.height() as usize,
        frame.color().to_vec(),
    )
    .ok_or_else(|| Error::Internal("empty frame".into()))
}

/// Render `mesh` from `camera` and score it against `reference`.
fn score(
    scorer: &Scorer,
    reference: &Reference,
    mesh: Mesh,
    camera: &Camera,
    settings: &RenderSettings,
) -> Result<(f64, f64, f64, Frame)> {
    let frame = raster::render(&RenderScene::of(Arc::new(mesh)), camera, settings)?;
    let s = scorer.score(reference, &linear(&frame)?)?;
    let get = |m: Metric| s.get(m).unwrap_or(f64::NAN);
    Ok((
        get(Metric::Flip),
        get(Metric::Vdp),
        get(Metric::VdpJnd),
        frame,
    ))
}

/// Run the experiment in `config`; `log` receives one line per finished curve.
pub fn run(config: &Path, log: &mut dyn FnMut(&str)) -> Result<Vec<SummaryRow>> {
    let exp = load(config)?;
    let base = config.parent().unwrap_or(Path::new("."));
    let out = base.join(&exp.out);
    std::fs::create_dir_all(&out)
        .map_err(|e| Error::Internal(format!("cannot create {}: {e}", out.display())))?;
    let scorer = Scorer::new(
        &[MetricFamily::Flip, MetricFamily::Vdp],
        &Viewing::DEFAULT,
        crate::metric::vdp::Display::DEFAULT,
        0.1,
    );
    let rig = Rig::parse(&exp.rig).expect("checked");
    let (mut rows, mut summary, mut pre_rows) = (Vec::new(), Vec::new(), Vec::new());
    for spec in &exp.scene {
        let tables = Tables {
            rows: &mut rows,
            summary: &mut summary,
            preprocess: &mut pre_rows,
        };
        let setting = Setting {
            exp: &exp,
            base,
            out: &out,
            scorer: &scorer,
            rig: &rig,
        };
        run_scene(&setting, spec, tables, log)?;
    }
    crate::io::csv::write_rows(&out.join("results.csv"), None, &rows)?;
    crate::io::csv::write_rows(&out.join("summary.csv"), None, &summary)?;
    crate::io::csv::write_rows(&out.join("preprocess.csv"), None, &pre_rows)?;
    Ok(summary)
}

/// The tables the runs append to.
struct Tables<'a> {
    rows: &'a mut Vec<Row>,
    summary: &'a mut Vec<SummaryRow>,
    preprocess: &'a mut Vec<PreprocessRow>,
}

/// What every scene of a run shares.
struct Setting<'a> {
    exp: &'a Experiment,
    base: &'a Path,
    out: &'a Path,
    scorer: &'a Scorer,
    rig: &'a Rig,
}

/// One scene: preprocess, then every criterion at every budget, on view 0 and along the rig's
/// path; its plots and contact sheet.
fn run_scene(
    setting: &Setting<'_>,
    spec: &SceneSpec,
    tables: Tables<'_>,
    log: &mut dyn FnMut(&str),
) -> Result<()> {
    let Setting {
        exp,
        base,
        out,
        scorer,
        rig,
    } = *setting;
    let Tables {
        rows,
        summary,
        preprocess: pre_rows,
    } = tables;
    let shading = Shading::parse(&spec.shading).expect("checked");
    let original = mesh::load(&base.join(&spec.mesh), &LoadOptions::default())?;
    let start = Instant::now();
    let w = Williams::build(&original)?;
    pre_rows.push(PreprocessRow {
        scene: spec.name.clone(),
        triangles: original.triangle_count(),
        nodes: w.hierarchy.node_count(),
        mt_triangles: w.hierarchy.tris.len(),
        seconds: start.elapsed().as_secs_f64(),
    });
    let cameras = rig.cameras(&original, 1.0);
    let original = Arc::new(original);
    let scene = RenderScene::of(original.clone());
    let single = settings(exp.single_size, exp.samples, shading);
    let mean = settings(exp.mean_size, exp.samples, shading);
    let single_ref = scorer.prepare(linear(&raster::render(&scene, &cameras[0], &single)?)?);
    let (mean_refs, first) = references(scorer, &scene, &cameras, &mean)?;
    let mut sheet = vec![first];
    let n = original.triangle_count();
    let smallest = exp.budgets.iter().copied().fold(1.0, f64::min);
    for &criterion in &exp.criteria {
        let opts = |size: u32| Options {
            shading,
            criterion,
            size: (size, size),
            ..Options::default()
        };
        for &ratio in &exp.budgets {
            let budget = ((n as f64 * ratio).round() as usize).max(1);
            // View 0, as the paper plots it.
            let mut cut = Cut::coarsest(&w.hierarchy);
            w.adapt(&mut cut, &cameras[0], budget, &opts(exp.single_size));
            let lod = w.mesh(&cut)?;
            let triangles = lod.triangle_count();
            let (flip, vdp, jnd, _) = score(scorer, &single_ref, lod, &cameras[0], &single)?;
            rows.push(Row {
                scene: spec.name.clone(),
                criterion: criterion.name().into(),
                budget,
                ratio,
                view: 0,
                size: exp.single_size,
                triangles,
                flip,
                vdp,
                vdp_jnd: jnd,
            });
            let (view0_flip, view0_jnd) = (flip, jnd);
            // Every view along the rig's path, the cut carried over.
            let mut cut = Cut::coarsest(&w.hierarchy);
            let (mut sum_flip, mut sum_jnd) = (0.0, 0.0);
            for (v, camera) in cameras.iter().enumerate() {
                if !exp.temporal_coherence {
                    cut = Cut::coarsest(&w.hierarchy);
                }
                w.adapt(&mut cut, camera, budget, &opts(exp.mean_size));
                let lod = w.mesh(&cut)?;
                let triangles = lod.triangle_count();
                let (flip, vdp, jnd, frame) = score(scorer, &mean_refs[v], lod, camera, &mean)?;
                if v == 0 && ratio == smallest {
                    sheet.push(frame);
                }
                sum_flip += flip;
                sum_jnd += jnd;
                rows.push(Row {
                    scene: spec.name.clone(),
                    criterion: criterion.name().into(),
                    budget,
                    ratio,
                    view: v,
                    size: exp.mean_size,
                    triangles,
                    flip,
                    vdp,
                    vdp_jnd: jnd,
                });
            }
            let views = cameras.len() as f64;
            let s = SummaryRow {
                scene: spec.name.clone(),
                criterion: criterion.name().into(),
                budget,
                ratio,
                view0_flip,
                view0_vdp_jnd: view0_jnd,
                mean_flip: crate::eval::tables::round7(sum_flip / views),
                mean_vdp_jnd: crate::eval::tables::round7(sum_jnd / views),
            };
            log(&s.describe());
            summary.push(s);
        }
    }
    write_plots(out, &spec.name, summary)?;
    write_sheet(out, &spec.name, &sheet)
}

impl SummaryRow {
    /// One line for the log.
    fn describe(&self) -> String {
        format!(
            "{} {} budget {}: view 0 FLIP {:.4} JND {:.3}; mean FLIP {:.4} JND {:.3}",
            self.scene,
            self.criterion,
            self.budget,
            self.view0_flip,
            self.view0_vdp_jnd,
            self.mean_flip,
            self.mean_vdp_jnd
        )
    }
}

/// The original's prepared render from every camera, and its first frame (the sheet's first).
fn references(
    scorer: &Scorer,
    scene: &RenderScene,
    cameras: &[crate::scene::Camera],
    settings: &RenderSettings,
) -> Result<(Vec<crate::eval::score::Reference>, crate::raster::Frame)> {
    let mut first = None;
    let mut refs = Vec::new();
    for c in cameras {
        let frame = raster::render(scene, c, settings)?;
        refs.push(scorer.prepare(linear(&frame)?));
        first.get_or_insert(frame);
    }
    let first = first.ok_or_else(|| Error::Internal("a rig without cameras".into()))?;
    Ok((refs, first))
}

/// `SCENE-sheet.png`: the frames side by side, at most `SHEET_SIZE` pixels a side each, so the
/// sheets stay small enough to commit.
fn write_sheet(out: &Path, name: &str, sheet: &[crate::raster::Frame]) -> Result<()> {
    let images: Vec<image::RgbImage> = sheet
        .iter()
        .map(|f| {
            let img = f.to_srgb8();
            if img.width() > SHEET_SIZE {
                let h = img.height() * SHEET_SIZE / img.width();
                image::imageops::resize(&img, SHEET_SIZE, h, image::imageops::FilterType::Triangle)
            } else {
                img
            }
        })
        .collect();
    let sheet = crate::io::sheet::contact_sheet(&images, images.len() as u32, 4, [255; 3])?;
    crate::io::write_image(
        &out.join(format!("{name}-sheet.png")),
        &image::DynamicImage::ImageRgb8(sheet),
    )
}

/// `SCENE.svg` and `SCENE.png`: four panels stacked — view-0 FLIP, view-0 VDP JND, mean FLIP, mean VDP JND —
/// against the budget in triangles, one line per criterion.
fn write_plots(out: &Path, scene: &str, summary: &[SummaryRow]) -> Result<()> {
    let mut panels = Vec::new();
    let mut charts = Vec::new();
    type Pick = fn(&SummaryRow) -> f64;
    let picks: [(&str, &str, Pick); 4] = [
        ("view 0: FLIP", "FLIP mean", |r| r.view0_flip),
        ("view 0: VDP", "VDP JND", |r| r.view0_vdp_jnd),
        ("mean over views: FLIP", "FLIP mean", |r| r.mean_flip),
        ("mean over views: VDP", "VDP JND", |r| r.mean_vdp_jnd),
    ];
    for (title, y, pick) in picks {
        let mut series: Vec<Series> = Vec::new();
        for c in Criterion::ALL {
            let pts: Vec<(f64, f64)> = summary
                .iter()
                .filter(|r| r.scene == scene && r.criterion == c.name())
                .map(|r| (r.budget as f64, pick(r)))
                .collect();
            if !pts.is_empty() {
                series.push((c.name().to_string(), pts, false));
            }
        }
        let title = format!("{scene} — {title}");
        let x = "triangle budget (log scale)";
        panels.push(line_plot(&title, x, y, &series, true));
        charts.push(Chart::from_series(&title, x, y, &series, true));
    }
    crate::io::write_atomic(
        &out.join(format!("{scene}.png")),
        &crate::io::plot_png::encode_stack(&charts)?,
    )?;
    // Stack the panels vertically in one SVG.
    let mut svg =
        String::from("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"720\" height=\"1680\">");
    for (i, p) in panels.iter().enumerate() {
        svg.push_str(&format!(
            "<g transform=\"translate(0 {})\">{}</g>",
            420 * i,
            p.replacen("<svg ", "<svg y=\"0\" ", 1)
        ));
    }
    svg.push_str("</svg>");
    crate::io::write_atomic(&out.join(format!("{scene}.svg")), svg.as_bytes())
}
