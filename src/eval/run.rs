//! The batch run behind `lodeval eval`: load each asset and its LODs (files, or a generated chain
//! from `simplify::chain`: meshoptimizer, QEM or clustering), measure their geometric error, render the original once per view as the metric reference, render every LOD from the
//! same camera, score, write heat maps and contact sheets, search the imperceptibility distances,
//! then hand the tables to the sinks (CSV, gate, JUnit, report).
//!
//! Decisions:
//! - Views are the outer loop: one original render and its prepared metric forms are alive at a
//!   time, so memory does not grow with the number of views (1024² nightly runs stay small).
//!   Within a view the LODs run in parallel (besides the parallelism inside the renderer and the
//!   metrics); their results are recorded in LOD order, so nothing depends on which finished
//!   first.
//! - Every LOD is rendered with the original's cameras (framed on the original's bounding sphere),
//!   as an engine would draw it in the original's place.
//! - Contact sheets show original | LOD | FLIP heat map (VDP where FLIP is off; SSIM last), the
//!   LOD's worst views first, as 256-pixel thumbnails, each captioned inside the PNG (the view
//!   number and which image it is; the heat map's metric and that view's score).

use std::borrow::Cow;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use rayon::prelude::*;

use super::config::{GltfExport, HeatmapChoice, MetricFamily};
use super::distance::{self, DistanceJob};
use super::plan::{AssetPlan, GenTarget, LodSource, Plan, Shard, case_id};
use super::score::Scorer;
use super::tables::{LodInfo, MetricRow, Results, higher_is_worse, round7};
use crate::backend::SceneRenderer;
use crate::error::Result;
use crate::mesh::{self, LoadOptions, Mesh, surface_distance};
use crate::metric::{LinearImage, colormap};
use crate::progress::Progress;
use crate::raster::{self, RenderScene};
use crate::scene::Scene;
use crate::simplify::{self, Method};

/// How to run.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// Output folder override (else the config's).
    pub out: Option<PathBuf>,
    /// The shard to run.
    pub shard: Shard,
    /// Where frames are rendered (`--backend`); default the CPU reference.
    pub backend: crate::backend::Backend,
    /// A render cache for the originals' frames (`--cache`; none by default).
    pub cache: Option<PathBuf>,
}

/// A finished (sharded) run.
#[derive(Debug)]
pub struct RunOutput {
    /// The plan.
    pub plan: Plan,
    /// Where the files went.
    pub out_dir: PathBuf,
    /// The tables.
    pub results: Results,
    /// What the user should know (why `--backend auto` rendered on the CPU).
    pub warnings: Vec<String>,
    /// Every file the run read its meshes from (meshes, material libraries, textures, buffers).
    pub inputs: Vec<PathBuf>,
    /// The output folder, locked until the run is sealed or dropped.
    pub dir: super::out::RunDir,
}

/// A LOD ready to render.
struct LodScene {
    name: String,
    scene: RenderScene,
    info: LodInfo,
}

/// Thumbnails kept for one LOD's contact sheet: per view (original, LOD, heat map).
type SheetViews = Vec<(usize, [image::RgbImage; 3])>;

const THUMB: u32 = 256;

/// Run `plan`'s cases in `options.shard`, writing images into the output folder. The tables are
/// returned (written by the caller with the other sinks).
pub fn run(plan: Plan, options: &RunOptions, progress: &dyn Progress) -> Result<RunOutput> {
    let out_dir = plan
        .config
        .out_dir(&plan.config_path, options.out.as_deref());
    // Before anything is rendered: the folder is lodeval's, and an earlier run's outputs go.
    if let Some(cache) = &options.cache
        && crate::io::within(cache, &out_dir)
    {
        return Err(crate::error::Error::Usage(format!(
            "--cache {} lies inside the output folder {}, which each run clears: keep the \
             render cache elsewhere",
            cache.display(),
            out_dir.display()
        )));
    }
    let dir = super::out::prepare(&out_dir, super::out::EVAL, &plan.input_files())?;
    let (results, warnings, inputs) = evaluate(&plan, options, progress, Some(&out_dir))?;
    Ok(RunOutput {
        plan,
        out_dir,
        results,
        warnings,
        inputs,
        dir,
    })
}

/// Render and score every wanted case of `plan`: the tables and the warnings. Heat maps and
/// contact sheets go into `images` where it is given (`lodeval compare` gives none and writes
/// nothing).
pub fn evaluate(
    plan: &Plan,
    options: &RunOptions,
    progress: &dyn Progress,
    images: Option<&Path>,
) -> Result<(Results, Vec<String>, Vec<PathBuf>)> {
    let cfg = &plan.config;
    let viewing = cfg.viewing.viewing();
    let scorer = Scorer::new(
        &cfg.metrics,
        &viewing,
        cfg.viewing.display(),
        cfg.flip_pixel_threshold.0,
    );
    let settings = cfg.render.settings();
    let engine = crate::backend::Engine::new(options.backend)?;
    let renderer = engine.describe();
    let mut results = Results::default();
    let cases: usize = plan
        .assets
        .iter()
        .flat_map(|a| a.lods.iter().map(|l| case_id(&a.name, &l.name)))
        .filter(|c| options.shard.contains(c))
        .count();
    let views = cfg.render.rig.0.directions().len();
    let steps = cases * (views + usize::from(cfg.distance.enabled));
    progress.start(Some(steps as u64), "renders", "");
    let bar = progress;
    let mut export_warnings = Vec::new();
    let mut inputs: Vec<PathBuf> = Vec::new();
    let cache = match &options.cache {
        Some(dir) => {
            let (cache, warning) = super::cache::RenderCache::open(dir);
            export_warnings.extend(warning);
            cache
        }
        None => None,
    };
    for asset in &plan.assets {
        let wanted: Vec<bool> = asset
            .lods
            .iter()
            .map(|l| options.shard.contains(&case_id(&asset.name, &l.name)))
            .collect();
        if !wanted.contains(&true) {
            continue;
        }
        bar.set_message(&asset.name);
        let original = Arc::new(mesh::load(&asset.mesh, &LoadOptions::default())?);
        inputs.extend(original.source().files.iter().cloned());
        let reference = scene_for(cfg, original.clone());
        let geometry = (cfg.geometry_samples > 0)
            .then(|| surface_distance::Original::new(&original, cfg.geometry_samples));
        let lods = build_lods(asset, &original, &wanted)?
            .into_iter()
            .map(|(name, mesh, mut info)| {
                if let Some(g) = &geometry {
                    let d = g.compare(&mesh);
                    info.hausdorff = Some(round7(d.hausdorff));
                    info.mean_distance = Some(round7(d.mean));
                    info.rms_distance = Some(round7(d.rms));
                    info.hausdorff_relative = Some(round7(d.hausdorff_relative));
                    info.mean_relative = Some(round7(d.mean_relative));
                }
                LodScene {
                    name,
                    scene: scene_for(cfg, Arc::new(mesh)),
                    info,
                }
            })
            .collect::<Vec<_>>();
        let cameras = cfg.render.rig.0.cameras(&original, 1.0);
        let reference_renderer = engine.scene(&reference)?;
        let scene_key = match &cache {
            Some(c) => Some(c.scene_key(&reference)?),
            None => None,
        };
        let lod_renderers = lods
            .iter()
            .map(|l| engine.scene(&l.scene))
            .collect::<Result<Vec<_>>>()?;
        let mut sheets: Vec<SheetViews> = vec![Vec::new(); lods.len()];
        // The original's frame of view v, prepared for scoring, and its thumbnail.
        let reference_view = |v: usize| -> Result<_> {
            let camera = &cameras[v];
            // The original's colour, from the cache where it holds this very frame.
            let cached = cache
                .as_ref()
                .zip(scene_key.as_ref())
                .and_then(|(c, k)| c.get(k, &settings, camera, &renderer));
            let reference_image = match cached {
                Some(px) => LinearImage::new(settings.width as usize, settings.height as usize, px)
                    .ok_or_else(|| crate::error::Error::Internal("render cache: size".into()))?,
                None => {
                    let image = LinearImage::from(&reference_renderer.render(camera, &settings)?);
                    if let (Some(c), Some(k)) = (&cache, &scene_key) {
                        c.put(k, &settings, camera, &renderer, image.pixels());
                    }
                    image
                }
            };
            let prepared = scorer.prepare(reference_image);
            let ref_thumb = thumbnail(&prepared.srgb8());
            Ok((prepared, ref_thumb))
        };
        let mut next = (!cameras.is_empty()).then(|| reference_view(0));
        for (v, camera) in cameras.iter().enumerate() {
            let (prepared, ref_thumb) = next.take().expect("prepared ahead")?;
            // One LOD of this view: rendered, scored, its heat maps written, its sheet tiles.
            let score_lod = |(lod, lod_renderer): (&LodScene, &SceneRenderer)| -> Result<_> {
                let test_frame = lod_renderer.render(camera, &settings)?;
                let scored = scorer.score(&prepared, &LinearImage::from(&test_frame))?;
                if let Some(out_dir) = images
                    && cfg.images.heatmaps == HeatmapChoice::All
                {
                    for (metric, map) in &scored.maps {
                        write_heat_map(out_dir, &asset.name, &lod.name, v, metric, map)?;
                    }
                }
                let thumbs = scored.maps.first().map(|(metric, map)| {
                    let test_rgb8: Cow<image::RgbImage> = match &scored.srgb8 {
                        Some(rgb) => Cow::Borrowed(rgb),
                        None => Cow::Owned(test_frame.to_srgb8()),
                    };
                    let heat = colormap::heat_map(&map.values, map.width, map.height, 0);
                    let score = scored
                        .values
                        .iter()
                        .find(|(m, _)| m == metric)
                        .map_or(String::new(), |(_, x)| format!(" {x:.4}"));
                    [
                        captioned(ref_thumb.clone(), &format!("view {v} · original")),
                        captioned(thumbnail(&test_rgb8), &format!("view {v} · {}", lod.name)),
                        captioned(
                            thumbnail(&heat),
                            &format!("{}{score}", metric.to_uppercase()),
                        ),
                    ]
                });
                bar.advance(1);
                Ok((scored.values, thumbs))
            };
            // The LODs of one view are independent: render and score them in parallel, then
            // record them in LOD order (outputs never depend on which finished first). The next
            // view's original is prepared meanwhile, so that no core waits for it.
            let (per_lod, following) = rayon::join(
                || {
                    lods.par_iter()
                        .zip(&lod_renderers)
                        .map(score_lod)
                        .collect::<Result<Vec<_>>>()
                },
                || (v + 1 < cameras.len()).then(|| reference_view(v + 1)),
            );
            let per_lod = per_lod?;
            next = following;
            for (k, (lod, (values, thumbs))) in lods.iter().zip(per_lod).enumerate() {
                for (metric, value) in values {
                    results.rows.push(MetricRow {
                        asset: asset.name.clone(),
                        lod: lod.name.clone(),
                        triangles: lod.info.triangles,
                        view: v,
                        metric: metric.to_string(),
                        value,
                        renderer: renderer.clone(),
                    });
                }
                if let Some(t) = thumbs {
                    sheets[k].push((v, t));
                }
            }
        }
        let orders: Vec<Vec<usize>> = lods
            .iter()
            .map(|lod| worst_first(&results, &asset.name, &lod.name, &cfg.metrics))
            .collect();
        // Heat maps and sheets beside the distance searches: both only read what is done.
        let write_images = || -> Result<()> {
            if let Some(out_dir) = images
                && cfg.images.heatmaps == HeatmapChoice::Worst
            {
                // Re-render the worst view only, for its heat maps: each distinct worst view's
                // original once, its LODs in parallel.
                let mut worst: Vec<usize> =
                    orders.iter().filter_map(|o| o.first().copied()).collect();
                worst.sort_unstable();
                worst.dedup();
                for view in worst {
                    let camera = &cameras[view];
                    let a = LinearImage::from(&reference_renderer.render(camera, &settings)?);
                    let reference = scorer.prepare(a);
                    lods.par_iter()
                        .zip(&lod_renderers)
                        .zip(&orders)
                        .filter(|(_, order)| order.first() == Some(&view))
                        .map(|((lod, lod_renderer), _)| -> Result<()> {
                            let b = LinearImage::from(&lod_renderer.render(camera, &settings)?);
                            let scored = scorer.score(&reference, &b)?;
                            for (metric, map) in &scored.maps {
                                write_heat_map(out_dir, &asset.name, &lod.name, view, metric, map)?;
                            }
                            Ok(())
                        })
                        .collect::<Result<()>>()?;
                }
            }
            if let Some(out_dir) = images
                && cfg.images.contact_sheets
            {
                lods.par_iter()
                    .zip(&sheets)
                    .zip(&orders)
                    .filter(|((_, sheet), _)| !sheet.is_empty())
                    .map(|((lod, sheet), order)| -> Result<()> {
                        let mut tiles = Vec::new();
                        for &v in order.iter().take(cfg.images.sheet_views.max(1)) {
                            if let Some((_, t)) = sheet.iter().find(|(view, _)| *view == v) {
                                tiles.extend(t.iter().cloned());
                            }
                        }
                        let sheet = raster::contact_sheet(&tiles, 3, 4, [32, 32, 32])?;
                        crate::io::write_image(
                            &out_dir
                                .join("sheets")
                                .join(&asset.name)
                                .join(format!("{}.png", lod.name)),
                            &image::DynamicImage::ImageRgb8(sheet),
                        )
                    })
                    .collect::<Result<()>>()?;
            }
            Ok(())
        };
        let search_distances = || -> Result<Vec<_>> {
            if !cfg.distance.enabled {
                return Ok(Vec::new());
            }
            // The LODs' searches in parallel, sharing the original's probe renders; rows in LOD
            // order.
            bar.set_message(&format!("{} distances", asset.name));
            let originals = distance::OriginalProbes::new();
            let take = cfg.distance.views.unwrap_or(3).max(1);
            let rows = lods
                .par_iter()
                .zip(&orders)
                .map(|(lod, order)| {
                    let job = DistanceJob {
                        original: &reference,
                        lod: &lod.scene,
                        directions: order
                            .iter()
                            .take(take)
                            .map(|&v| cameras[v].to_eye())
                            .collect(),
                        meters_per_unit: asset.meters_per_unit,
                        simplifier_error: lod.info.simplifier_error,
                        names: (&asset.name, &lod.name, lod.info.triangles),
                        switch_m: lod.info.switch_m,
                        originals: Some(&originals),
                    };
                    let rows = distance::search(&job, &cfg.distance, &cfg.viewing, &settings);
                    bar.advance(1);
                    rows
                })
                .collect::<Result<Vec<_>>>()?;
            Ok(rows.into_iter().flatten().collect())
        };
        let (written, rows) = rayon::join(write_images, search_distances);
        written?;
        results.distances.extend(rows?);
        let ext = match cfg.export.gltf {
            GltfExport::None => None,
            GltfExport::Glb => Some("glb"),
            GltfExport::Gltf => Some("gltf"),
        };
        // A chain for engines: only from a run that has every LOD of the asset (not a shard's
        // part of it).
        if let (Some(out_dir), Some(ext)) = (images, ext)
            && wanted.iter().all(|w| *w)
        {
            let chain: Vec<(&str, &Mesh)> = lods
                .iter()
                .map(|l| (l.name.as_str(), l.scene.scene().mesh()))
                .collect();
            let (_, notes) = super::export::write_chain(
                &out_dir.join("export").join(format!("{}.{ext}", asset.name)),
                &asset.name,
                &original,
                &chain,
                &results.distances,
            )?;
            export_warnings.extend(notes);
        }
        results.lods.extend(lods.into_iter().map(|l| l.info));
    }
    bar.finish();
    results.sort(&plan.case_ids());
    let mut warnings: Vec<String> = engine.fallback().map(str::to_string).into_iter().collect();
    warnings.extend(export_warnings);
    warnings.extend(cache.iter().flat_map(|c| c.warnings()));
    for asset in &plan.assets {
        inputs.push(asset.mesh.clone()); // also where this shard ran none of its cases
        for l in &asset.lods {
            if let super::plan::LodSource::File(p) = &l.source {
                inputs.push(p.clone());
            }
        }
    }
    Ok((results, warnings, inputs))
}

/// A scene of `mesh` with the config's lights, environment, background and ambient term.
pub fn scene_for(cfg: &super::config::Config, mesh: Arc<Mesh>) -> RenderScene {
    let mut s = Scene::new(mesh);
    s.lights = cfg.render.scene_lights();
    s.light_with(&cfg.render.lighting);
    s.background = glam::Vec3::from_array(cfg.render.background.map(|c| c.0 as f32))
        .map(crate::color::srgb_to_linear);
    s.ambient = cfg.render.ambient.0 as f32;
    RenderScene::new(s)
}

/// Load or generate the wanted LODs of an asset (a generated chain is built up to its last wanted
/// step, since steps may start from the previous one).
pub fn build_lods(
    asset: &AssetPlan,
    original: &Mesh,
    wanted: &[bool],
) -> Result<Vec<(String, Mesh, LodInfo)>> {
    // The generated chain, computed once up to the last wanted step.
    let generated: Vec<(Method, GenTarget)> = asset
        .lods
        .iter()
        .filter_map(|l| match l.source {
            LodSource::Generated { method, target, .. } => Some((method, target)),
            LodSource::File(_) => None,
        })
        .collect();
    let last = asset
        .lods
        .iter()
        .zip(wanted)
        .filter_map(|(l, w)| match l.source {
            LodSource::Generated { step, .. } if *w => Some(step),
            _ => None,
        })
        .max();
    let mut chain = match (last, generated.first()) {
        (Some(last), Some(&(method, _))) => {
            let goals: Vec<_> = generated[..=last].iter().map(|g| g.1.goal()).collect();
            simplify::chain_scaled(original, method, &goals, asset.meters_per_unit)?
                .into_iter()
                .map(Some)
                .collect()
        }
        _ => Vec::new(),
    };
    let mut out = Vec::new();
    for (lod, &want) in asset.lods.iter().zip(wanted) {
        if !want {
            continue;
        }
        let (mesh, source, error) = match &lod.source {
            LodSource::File(path) => (
                mesh::load(path, &LoadOptions::default())?,
                path.display().to_string(),
                None,
            ),
            LodSource::Generated {
                method,
                step,
                target,
            } => {
                let l = chain[*step].take().expect("each step is taken once");
                let what = match target {
                    GenTarget::Ratio(r) => {
                        format!("{} ratio {r} (chain step {})", method.name(), step + 1)
                    }
                    GenTarget::Error(e) => {
                        format!("{} error {e} (chain step {})", method.name(), step + 1)
                    }
                    GenTarget::Distance(d) => {
                        format!("{} distance {d} m (chain step {})", method.name(), step + 1)
                    }
                    GenTarget::Vertices(v) => {
                        format!("{} {v} vertices (chain step {})", method.name(), step + 1)
                    }
                };
                (l.mesh, what, l.error.map(round7))
            }
        };
        let info = LodInfo {
            asset: asset.name.clone(),
            lod: lod.name.clone(),
            triangles: mesh.triangle_count(),
            original_triangles: original.triangle_count(),
            source,
            simplifier_error: error,
            switch_m: lod.switch_m,
            hausdorff: None,
            mean_distance: None,
            rms_distance: None,
            hausdorff_relative: None,
            mean_relative: None,
        };
        out.push((lod.name.clone(), mesh, info));
    }
    Ok(out)
}

/// Views of one LOD, worst first, by the first configured metric with a per-view value (FLIP if
/// configured); ties keep view order.
pub fn worst_first(
    results: &Results,
    asset: &str,
    lod: &str,
    families: &[MetricFamily],
) -> Vec<usize> {
    let metric = if families.contains(&MetricFamily::Flip) {
        "flip"
    } else if families.contains(&MetricFamily::Vdp) {
        "vdp"
    } else if families.contains(&MetricFamily::Ssim) {
        "ssim"
    } else if families.contains(&MetricFamily::Psnr) {
        "psnr"
    } else {
        "msssim"
    };
    let mut views: Vec<(usize, f64)> = results
        .rows
        .iter()
        .filter(|r| r.asset == asset && r.lod == lod && r.metric == metric)
        .map(|r| (r.view, r.value))
        .collect();
    let sign = if higher_is_worse(metric) { -1.0 } else { 1.0 };
    views.sort_by(|a, b| (sign * a.1).total_cmp(&(sign * b.1)).then(a.0.cmp(&b.0)));
    views.into_iter().map(|v| v.0).collect()
}

/// `heatmaps/ASSET/LOD/VV-METRIC.png`.
pub fn heat_map_path(out: &Path, asset: &str, lod: &str, view: usize, metric: &str) -> PathBuf {
    out.join("heatmaps")
        .join(asset)
        .join(lod)
        .join(format!("{view:02}-{metric}.png"))
}

fn write_heat_map(
    out: &Path,
    asset: &str,
    lod: &str,
    view: usize,
    metric: &str,
    map: &crate::image::ErrorMap,
) -> Result<()> {
    let img = colormap::heat_map(&map.values, map.width, map.height, (map.height / 32).max(4));
    crate::io::write_image(
        &heat_map_path(out, asset, lod, view, metric),
        &image::DynamicImage::ImageRgb8(img),
    )
}

/// A contact-sheet tile with its caption across the top.
fn captioned(mut tile: image::RgbImage, text: &str) -> image::RgbImage {
    crate::io::label::caption_rgb(&mut tile, text, 12.0);
    tile
}

fn thumbnail(img: &image::RgbImage) -> image::RgbImage {
    if img.width() <= THUMB && img.height() <= THUMB {
        return img.clone();
    }
    image::imageops::resize(img, THUMB, THUMB, image::imageops::FilterType::Triangle)
}
