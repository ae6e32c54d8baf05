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

use super::assets::{build_lods, scene_for};
use super::config::{GltfExport, HeatmapChoice, MetricFamily};
use super::distance::{self, DistanceJob};
use super::plan::{AssetPlan, LodSource, Plan, Shard, case_id};
use super::score::Scorer;
use super::tables::{LodInfo, MetricRow, Results, round7};
use crate::backend::SceneRenderer;
use crate::error::Result;
use crate::mesh::{self, LoadOptions, Mesh, surface_distance};
use crate::metric::{LinearImage, Metric, colormap};
use crate::progress::Progress;
use crate::raster::{self, RenderScene};

/// How to run. Start from [`RunOptions::DEFAULT`] and set what differs.
#[derive(Debug, Clone)]
#[non_exhaustive]
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

impl RunOptions {
    /// The config's output folder, the whole run, the CPU reference, no render cache.
    pub const DEFAULT: RunOptions = RunOptions {
        out: None,
        shard: Shard::ALL,
        backend: crate::backend::Backend::Cpu,
        cache: None,
    };
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions::DEFAULT
    }
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

/// One view's contact-sheet tiles: original, LOD, heat map.
type Tiles = [image::RgbImage; 3];

/// One LOD scored from one view: (metric, value) pairs and its sheet tiles.
type LodOfView = (Vec<(Metric, f64)>, Option<Tiles>);

/// Thumbnails kept for one LOD's contact sheet: per view (original, LOD, heat map).
type SheetViews = Vec<(usize, Tiles)>;

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
    let shared = Shared {
        cfg,
        settings: &settings,
        scorer: &scorer,
        images,
        bar,
    };
    let mut export_warnings = Vec::new();
    let mut inputs: Vec<PathBuf> = Vec::new();
    let (cache, warning) = options
        .cache
        .as_deref()
        .map_or((None, None), super::cache::RenderCache::open);
    export_warnings.extend(warning);
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
        let lods = lod_scenes(cfg, asset, &original, &wanted)?;
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
        let cached = cache.as_ref().zip(scene_key.as_ref());
        let original_view =
            |v: usize| reference_view(&shared, &renderer, cached, &reference_renderer, &cameras[v]);
        let sheets = score_views(
            &shared,
            &asset.name,
            &cameras,
            (&lods, &lod_renderers),
            original_view,
            &renderer,
            &mut results,
        )?;
        let orders: Vec<Vec<usize>> = lods
            .iter()
            .map(|lod| worst_first(&results, &asset.name, &lod.name, &cfg.metrics))
            .collect();
        // Heat maps and sheets beside the distance searches: both only read what is done.
        let views = Views {
            cameras: &cameras,
            reference: &reference_renderer,
            lods: &lods,
            renderers: &lod_renderers,
            orders: &orders,
        };
        let write_images = || write_images(&shared, &asset.name, &views, &sheets);
        let search_distances =
            || search_distances(&shared, asset, &reference, &lods, &orders, &cameras);
        let (written, rows) = rayon::join(write_images, search_distances);
        written?;
        results.distances.extend(rows?);
        // A chain for engines: only from a run that has every LOD of the asset (not a shard's
        // part of it).
        if let Some(out_dir) = images
            && wanted.iter().all(|w| *w)
        {
            let notes = export_chain(cfg, out_dir, &asset.name, &original, &lods, &results)?;
            export_warnings.extend(notes);
        }
        results.lods.extend(lods.into_iter().map(|l| l.info));
    }
    bar.finish();
    results.sort(&plan.case_ids());
    let mut warnings: Vec<String> = engine.fallback().map(str::to_string).into_iter().collect();
    warnings.extend(export_warnings);
    warnings.extend(cache.iter().flat_map(|c| c.warnings()));
    inputs.extend(mesh_files(plan));
    Ok((results, warnings, inputs))
}

/// The wanted LODs of `asset` ready to render, with their surface distances to the original
/// where the config asks for them.
fn lod_scenes(
    cfg: &super::config::Config,
    asset: &AssetPlan,
    original: &Mesh,
    wanted: &[bool],
) -> Result<Vec<LodScene>> {
    let geometry = (cfg.geometry_samples > 0)
        .then(|| surface_distance::Original::new(original, cfg.geometry_samples));
    Ok(build_lods(asset, original, wanted)?
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
        .collect())
}

/// An asset's views, renderers and each LOD's views worst first: what the image writers read.
struct Views<'a, 'r> {
    cameras: &'a [crate::scene::Camera],
    reference: &'a SceneRenderer<'r>,
    lods: &'a [LodScene],
    renderers: &'a [SceneRenderer<'r>],
    orders: &'a [Vec<usize>],
}

/// `heatmaps = "worst"`: re-render each LOD's worst view only, for its heat maps: each distinct
/// worst view's original once, its LODs in parallel.
fn worst_heat_maps(
    out_dir: &Path,
    asset: &str,
    views: &Views<'_, '_>,
    scorer: &Scorer,
    settings: &raster::RenderSettings,
) -> Result<()> {
    let mut worst: Vec<usize> = views
        .orders
        .iter()
        .filter_map(|o| o.first().copied())
        .collect();
    worst.sort_unstable();
    worst.dedup();
    for view in worst {
        let camera = &views.cameras[view];
        let a = LinearImage::from(&views.reference.render(camera, settings)?);
        let reference = scorer.prepare(a);
        views
            .lods
            .par_iter()
            .zip(views.renderers)
            .zip(views.orders)
            .filter(|(_, order)| order.first() == Some(&view))
            .map(|((lod, lod_renderer), _)| -> Result<()> {
                let b = LinearImage::from(&lod_renderer.render(camera, settings)?);
                let scored = scorer.score(&reference, &b)?;
                for (metric, map) in &scored.maps {
                    write_heat_map(out_dir, asset, &lod.name, view, *metric, map)?;
                }
                Ok(())
            })
            .collect::<Result<()>>()?;
    }
    Ok(())
}

/// Each LOD's contact sheet: its `sheet_views` worst views, three tiles each.
fn write_sheets(
    out_dir: &Path,
    asset: &str,
    views: &Views<'_, '_>,
    sheets: &[SheetViews],
    sheet_views: usize,
) -> Result<()> {
    views
        .lods
        .par_iter()
        .zip(sheets)
        .zip(views.orders)
        .filter(|((_, sheet), _)| !sheet.is_empty())
        .map(|((lod, sheet), order)| -> Result<()> {
            let mut tiles = Vec::new();
            for &v in order.iter().take(sheet_views.max(1)) {
                if let Some((_, t)) = sheet.iter().find(|(view, _)| *view == v) {
                    tiles.extend(t.iter().cloned());
                }
            }
            let sheet = crate::io::sheet::contact_sheet(&tiles, 3, 4, [32, 32, 32])?;
            crate::io::write_image(
                &out_dir
                    .join("sheets")
                    .join(asset)
                    .join(format!("{}.png", lod.name)),
                &image::DynamicImage::ImageRgb8(sheet),
            )
        })
        .collect()
}

/// `[export] gltf`: the asset's chain as one glTF file, switching at the measured distances;
/// returns what it could not keep.
fn export_chain(
    cfg: &super::config::Config,
    out_dir: &Path,
    asset: &str,
    original: &Mesh,
    lods: &[LodScene],
    results: &Results,
) -> Result<Vec<String>> {
    let ext = match cfg.export.gltf {
        GltfExport::None => return Ok(Vec::new()),
        GltfExport::Glb => "glb",
        GltfExport::Gltf => "gltf",
    };
    let chain: Vec<(&str, &Mesh)> = lods
        .iter()
        .map(|l| (l.name.as_str(), l.scene.scene().mesh()))
        .collect();
    let written = super::export::write_chain(
        &out_dir.join("export").join(format!("{asset}.{ext}")),
        asset,
        original,
        &chain,
        &results.distances,
    )?;
    Ok(written.warnings)
}

/// The plan's mesh and LOD files as the config names them (a chain level `FILE#K` as its file),
/// also those of assets a shard ran none of the cases of.
fn mesh_files(plan: &Plan) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for asset in &plan.assets {
        files.push(crate::mesh::split_level(&asset.mesh).0);
        for l in &asset.lods {
            if let LodSource::File(p) = &l.source {
                files.push(crate::mesh::split_level(p).0);
            }
        }
    }
    // A chain's levels are one file.
    files.dedup();
    files
}

/// The original's frame of `camera` (from the render cache where it holds this very frame),
/// prepared for scoring, and its thumbnail.
fn reference_view(
    sh: &Shared<'_>,
    renderer: &str,
    cache: Option<(&super::cache::RenderCache, &super::cache::SceneKey)>,
    reference_renderer: &SceneRenderer,
    camera: &crate::scene::Camera,
) -> Result<(super::score::Reference, image::RgbImage)> {
    let settings = sh.settings;
    let cached = cache.and_then(|(c, k)| c.get(k, settings, camera, renderer));
    let reference_image = match cached {
        Some(px) => LinearImage::new(settings.width as usize, settings.height as usize, px)
            .ok_or_else(|| crate::error::Error::Internal("render cache: size".into()))?,
        None => {
            let image = LinearImage::from(&reference_renderer.render(camera, settings)?);
            if let Some((c, k)) = cache {
                c.put(k, settings, camera, renderer, image.pixels());
            }
            image
        }
    };
    let prepared = sh.scorer.prepare(reference_image);
    let ref_thumb = thumbnail(&prepared.srgb8());
    Ok((prepared, ref_thumb))
}

/// Render and score every LOD of `lods` from every camera, recording the rows in `results`;
/// returns each LOD's contact-sheet tiles. The LODs of one view are independent: rendered and
/// scored in parallel, then recorded in LOD order (outputs never depend on which finished
/// first). The next view's original is prepared meanwhile, so that no core waits for it.
fn score_views(
    sh: &Shared<'_>,
    asset: &str,
    cameras: &[crate::scene::Camera],
    (lods, lod_renderers): (&[LodScene], &[SceneRenderer]),
    original_view: impl Fn(usize) -> Result<(super::score::Reference, image::RgbImage)> + Sync,
    renderer: &str,
    results: &mut Results,
) -> Result<Vec<SheetViews>> {
    let mut sheets: Vec<SheetViews> = vec![Vec::new(); lods.len()];
    let mut next = (!cameras.is_empty()).then(|| original_view(0));
    for (v, camera) in cameras.iter().enumerate() {
        let (prepared, ref_thumb) = next.take().expect("prepared ahead")?;
        let at = ViewAt {
            asset,
            v,
            camera,
            prepared: &prepared,
            ref_thumb: &ref_thumb,
        };
        let (per_lod, following) = rayon::join(
            || {
                lods.par_iter()
                    .zip(lod_renderers)
                    .map(|(lod, r)| score_lod(sh, &at, lod, r))
                    .collect::<Result<Vec<_>>>()
            },
            || (v + 1 < cameras.len()).then(|| original_view(v + 1)),
        );
        let per_lod = per_lod?;
        next = following;
        for (k, (lod, (values, thumbs))) in lods.iter().zip(per_lod).enumerate() {
            for (metric, value) in values {
                results.rows.push(MetricRow {
                    asset: asset.to_string(),
                    lod: lod.name.clone(),
                    triangles: lod.info.triangles,
                    view: v,
                    metric,
                    value,
                    renderer: renderer.to_string(),
                });
            }
            if let Some(t) = thumbs {
                sheets[k].push((v, t));
            }
        }
    }
    Ok(sheets)
}

/// The worst views' heat maps (`heatmaps = "worst"`) and the contact sheets, where the run
/// writes images.
fn write_images(
    sh: &Shared<'_>,
    asset: &str,
    views: &Views<'_, '_>,
    sheets: &[SheetViews],
) -> Result<()> {
    let (Some(out_dir), cfg) = (sh.images, sh.cfg) else {
        return Ok(());
    };
    if cfg.images.heatmaps == HeatmapChoice::Worst {
        worst_heat_maps(out_dir, asset, views, sh.scorer, sh.settings)?;
    }
    if cfg.images.contact_sheets {
        write_sheets(out_dir, asset, views, sheets, cfg.images.sheet_views)?;
    }
    Ok(())
}

/// What every case of a run shares.
struct Shared<'a> {
    cfg: &'a super::config::Config,
    settings: &'a raster::RenderSettings,
    scorer: &'a Scorer,
    images: Option<&'a Path>,
    bar: &'a dyn Progress,
}

/// One view of an asset, with its original prepared for scoring and its thumbnail.
struct ViewAt<'a> {
    asset: &'a str,
    v: usize,
    camera: &'a crate::scene::Camera,
    prepared: &'a super::score::Reference,
    ref_thumb: &'a image::RgbImage,
}

/// One LOD of one view: rendered, scored, its heat maps written (`heatmaps = "all"`), its
/// contact-sheet tiles (original, LOD, the first metric's heat map).
fn score_lod(
    sh: &Shared<'_>,
    at: &ViewAt<'_>,
    lod: &LodScene,
    lod_renderer: &SceneRenderer,
) -> Result<LodOfView> {
    let (v, cfg) = (at.v, sh.cfg);
    let test_frame = lod_renderer.render(at.camera, sh.settings)?;
    let scored = sh
        .scorer
        .score(at.prepared, &LinearImage::from(&test_frame))?;
    if let Some(out_dir) = sh.images
        && cfg.images.heatmaps == HeatmapChoice::All
    {
        for (metric, map) in &scored.maps {
            write_heat_map(out_dir, at.asset, &lod.name, v, *metric, map)?;
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
            captioned(at.ref_thumb.clone(), &format!("view {v} · original")),
            captioned(thumbnail(&test_rgb8), &format!("view {v} · {}", lod.name)),
            captioned(
                thumbnail(&heat),
                &format!("{}{score}", metric.name().to_uppercase()),
            ),
        ]
    });
    sh.bar.advance(1);
    Ok((scored.values, thumbs))
}

/// The LODs' distance searches in parallel, sharing the original's probe renders; rows in LOD
/// order (none when the config turns the search off).
fn search_distances(
    sh: &Shared<'_>,
    asset: &AssetPlan,
    reference: &RenderScene,
    lods: &[LodScene],
    orders: &[Vec<usize>],
    cameras: &[crate::scene::Camera],
) -> Result<Vec<super::tables::DistanceRow>> {
    let cfg = sh.cfg;
    if !cfg.distance.enabled {
        return Ok(Vec::new());
    }
    sh.bar.set_message(&format!("{} distances", asset.name));
    let originals = distance::OriginalProbes::new();
    let take = cfg.distance.views.unwrap_or(3).max(1);
    let rows = lods
        .par_iter()
        .zip(orders)
        .map(|(lod, order)| {
            let job = DistanceJob {
                original: reference,
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
            let rows = distance::search(&job, &cfg.distance, &cfg.viewing, sh.settings);
            sh.bar.advance(1);
            rows
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(rows.into_iter().flatten().collect())
}

/// Views of one LOD, worst first, by the first configured metric with a per-view value (FLIP if
/// configured); ties keep view order.
pub fn worst_first(
    results: &Results,
    asset: &str,
    lod: &str,
    families: &[MetricFamily],
) -> Vec<usize> {
    let metric = Metric::LEADING
        .into_iter()
        .find(|m| families.contains(&m.family()))
        .unwrap_or(Metric::Msssim);
    let mut views: Vec<(usize, f64)> = results
        .rows
        .iter()
        .filter(|r| r.asset == asset && r.lod == lod && r.metric == metric)
        .map(|r| (r.view, r.value))
        .collect();
    let sign = if metric.higher_is_worse() { -1.0 } else { 1.0 };
    views.sort_by(|a, b| (sign * a.1).total_cmp(&(sign * b.1)).then(a.0.cmp(&b.0)));
    views.into_iter().map(|v| v.0).collect()
}

/// `heatmaps/ASSET/LOD/VV-METRIC.png`.
pub fn heat_map_path(out: &Path, asset: &str, lod: &str, view: usize, metric: Metric) -> PathBuf {
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
    metric: Metric,
    map: &crate::image::ErrorMap,
) -> Result<()> {
    let legend = if metric == Metric::Vdp {
        &colormap::JND_LEGEND[..]
    } else {
        &colormap::UNIT_LEGEND[..]
    };
    let strip = (map.height / 32).max(4);
    let img = colormap::heat_map_with(&map.values, map.width, map.height, strip, legend);
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
