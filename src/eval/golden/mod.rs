//! Golden images (`lodeval golden CONFIG [--bless]`): render every view of each asset's original
//! (and LODs, unless `[golden] lods = false`) with the config's settings and compare it with the PNG
//! committed under the golden folder (`ASSET/LOD/view-NN.png`, the original as LOD `original`)
//! under a perceptual tolerance: FLIP mean and per-pixel 99th percentile at the config's viewing
//! conditions. On a mismatch the actual render and the FLIP heat map are written to the run's
//! output folder (`golden/ASSET/LOD/view-NN-actual.png`, `-diff.png`) and the exact bless command
//! is printed. `--bless` writes new goldens and refuses when the `CI` environment variable is set.
//!
//! Every run also writes `golden/report.html` (`golden/report.rs`): the mismatches first, each as
//! expected | actual | diff with a slider between expected and actual. `--bless ASSET[/LOD[/VIEW]]`
//! blesses only the images a filter names and compares the rest, as insta and Playwright accept
//! one snapshot at a time; the mismatches' `-actual.png` files are the pending ones.
//!
//! Decision: both sides are compared as 8-bit sRGB (the render is quantised exactly as the golden
//! PNG was), so a clean checkout compares equal to its own goldens to the bit.

use std::path::{Path, PathBuf};
use std::sync::Arc;

mod report;

use crate::error::{Error, Result};
use crate::eval::config::{config_dir, resolve, stem};
use crate::eval::plan::Plan;
use crate::mesh::{self, LoadOptions, Mesh};
use crate::metric::flip::Flip;
use crate::metric::{LinearImage, colormap, pool};

use crate::raster;

/// What `golden` found.
#[derive(Debug, Default)]
pub struct GoldenOutcome {
    /// Images compared (or blessed).
    pub checked: usize,
    /// Images blessed.
    pub blessed: usize,
    /// One line per mismatch.
    pub mismatches: Vec<String>,
    /// Images with no golden yet (not blessed, not written: `--bless` makes them).
    pub missing: usize,
    /// Files written (blessed goldens, or actual/diff images of mismatches).
    pub written: Vec<PathBuf>,
    /// Every image and what became of it, for the report.
    pub images: Vec<GoldenImage>,
    /// The report written (`golden/report.html` in the output folder).
    pub report: Option<PathBuf>,
}

/// One golden image's check.
#[derive(Debug, Clone)]
pub struct GoldenImage {
    /// Asset, LOD (`original` for the original) and view.
    pub asset: String,
    /// LOD name.
    pub lod: String,
    /// View index.
    pub view: usize,
    /// The golden file.
    pub golden: PathBuf,
    /// What happened.
    pub status: GoldenStatus,
}

/// See [`GoldenImage::status`].
#[derive(Debug, Clone)]
pub enum GoldenStatus {
    /// Within tolerance.
    Match,
    /// Written as the new golden.
    Blessed,
    /// No golden yet (nothing written for it; `--bless` makes it).
    Missing,
    /// Outside tolerance: why, the actual render, and the heat map where the sizes agree.
    Mismatch {
        /// The reason.
        why: String,
        /// The pending actual render.
        actual: PathBuf,
        /// The FLIP heat map.
        diff: Option<PathBuf>,
    },
}

/// Which images `--bless` writes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Bless {
    /// None: compare everything.
    No,
    /// Every image.
    All,
    /// The images a filter names (`ASSET`, `ASSET/LOD` or `ASSET/LOD/VIEW`); the rest are
    /// compared.
    Only(Vec<String>),
}

impl Bless {
    /// Whether the image of `asset`, `lod`, `view` is blessed.
    pub fn covers(&self, asset: &str, lod: &str, view: usize) -> bool {
        match self {
            Bless::No => false,
            Bless::All => true,
            Bless::Only(filters) => filters.iter().any(|f| {
                let parts: Vec<&str> = f.split('/').collect();
                parts.first() == Some(&asset)
                    && parts.get(1).is_none_or(|l| *l == lod)
                    && parts
                        .get(2)
                        .is_none_or(|v| v.trim_start_matches("view-").parse::<usize>() == Ok(view))
            }),
        }
    }

    /// Whether any image is blessed at all.
    pub fn any(&self) -> bool {
        *self != Bless::No
    }
}

/// The golden folder of a plan.
pub fn golden_dir(plan: &Plan) -> PathBuf {
    let base = config_dir(&plan.config_path);
    match &plan.config.golden.dir {
        Some(d) => resolve(&base, d),
        None => resolve(
            &base,
            &Path::new("..")
                .join("reference")
                .join("golden")
                .join(stem(&plan.config_path)),
        ),
    }
}

/// Compare (or with `bless`, write) the goldens of `plan`. `ci` says whether the `CI` environment
/// variable is set; `out_dir` receives actual and diff images of mismatches.
pub fn run(plan: &Plan, bless: &Bless, ci: bool, out_dir: &Path) -> Result<GoldenOutcome> {
    if bless.any() && ci {
        return Err(Error::Usage(
            "refusing to bless golden images with CI set: goldens are updated by a person, \
             on purpose; run `lodeval golden CONFIG --bless` locally and commit the images"
                .into(),
        ));
    }
    let cfg = &plan.config;
    let dir = golden_dir(plan);
    // Every filter must name something the plan renders: a typo blesses nothing silently.
    if let Bless::Only(filters) = bless {
        for f in filters {
            let parts: Vec<&str> = f.split('/').collect();
            let asset = plan.assets.iter().find(|a| a.name == parts[0]);
            let lod_ok = |a: &crate::eval::plan::AssetPlan| {
                parts.get(1).is_none_or(|l| {
                    *l == "original" || (cfg.golden.lods && a.lods.iter().any(|x| x.name == *l))
                })
            };
            let view_ok = parts.get(2).is_none_or(|v| {
                v.trim_start_matches("view-")
                    .parse::<usize>()
                    .is_ok_and(|v| v < cfg.render.rig.0.directions().len())
            });
            if parts.len() > 3 || !asset.is_some_and(lod_ok) || !view_ok {
                return Err(Error::Usage(format!(
                    "--bless {f}: no golden image matches; give ASSET, ASSET/LOD or \
                     ASSET/LOD/VIEW with an asset of the config, a LOD of it (or `original`) and \
                     a view number of the rig"
                )));
            }
        }
    }
    // Mismatch images of an earlier run go first, so what is left is this run's.
    let mut inputs = plan.input_files();
    inputs.push(dir.clone());
    let run_dir = crate::eval::out::prepare(out_dir, crate::eval::out::GOLDEN, &inputs)?;
    let settings = cfg.render.settings();
    let flip = Flip::new(cfg.viewing.viewing().ppd() as f32);
    let mut outcome = GoldenOutcome::default();
    for asset in &plan.assets {
        let original = Arc::new(mesh::load(&asset.mesh, &LoadOptions::default())?);
        let cameras = cfg.render.rig.0.cameras(&original, 1.0);
        let mut meshes: Vec<(String, Arc<Mesh>)> = vec![("original".into(), original.clone())];
        if cfg.golden.lods {
            let all = vec![true; asset.lods.len()];
            for (name, m, _) in crate::eval::assets::build_lods(asset, &original, &all)? {
                meshes.push((name, Arc::new(m)));
            }
        }
        for (name, m) in meshes {
            let scene = crate::eval::assets::scene_for(cfg, m);
            for (v, cam) in cameras.iter().enumerate() {
                let rel = Path::new(&asset.name)
                    .join(&name)
                    .join(format!("view-{v:02}.png"));
                let golden_path = dir.join(&rel);
                let actual = raster::render(&scene, cam, &settings)?.to_srgb8();
                outcome.checked += 1;
                let mut record = GoldenImage {
                    asset: asset.name.clone(),
                    lod: name.clone(),
                    view: v,
                    golden: golden_path.clone(),
                    status: GoldenStatus::Match,
                };
                if bless.covers(&asset.name, &name, v) {
                    crate::io::write_image(&golden_path, &image::DynamicImage::ImageRgb8(actual))?;
                    outcome.written.push(golden_path);
                    outcome.blessed += 1;
                    record.status = GoldenStatus::Blessed;
                    outcome.images.push(record);
                    continue;
                }
                if !golden_path.exists() {
                    outcome.missing += 1;
                    record.status = GoldenStatus::Missing;
                    outcome.images.push(record);
                    continue;
                }
                let problem = compare(&flip, &golden_path, &actual, cfg)?;
                if let Some((why, diff)) = problem {
                    let base = out_dir.join("golden").join(&rel);
                    let actual_path = base.with_file_name(format!("view-{v:02}-actual.png"));
                    crate::io::write_image(&actual_path, &image::DynamicImage::ImageRgb8(actual))?;
                    outcome.written.push(actual_path.clone());
                    let mut line = format!(
                        "MISMATCH {}: {why}; actual: {}",
                        golden_path.display(),
                        actual_path.display()
                    );
                    let mut diff_out = None;
                    if let Some(diff) = diff {
                        let diff_path = base.with_file_name(format!("view-{v:02}-diff.png"));
                        crate::io::write_image(&diff_path, &image::DynamicImage::ImageRgb8(diff))?;
                        line.push_str(&format!(", diff: {}", diff_path.display()));
                        outcome.written.push(diff_path.clone());
                        diff_out = Some(diff_path);
                    }
                    outcome.mismatches.push(line);
                    record.status = GoldenStatus::Mismatch {
                        why,
                        actual: actual_path,
                        diff: diff_out,
                    };
                }
                outcome.images.push(record);
            }
        }
    }
    let report = out_dir.join("golden").join("report.html");
    crate::io::write_atomic(
        &report,
        report::render(&plan.config_path, &outcome)?.as_bytes(),
    )?;
    outcome.report = Some(report);
    run_dir.seal()?;
    Ok(outcome)
}

/// Compare a render with its golden; `None` when within tolerance, else the reason and (when
/// the sizes agree) the FLIP heat map.
fn compare(
    flip: &Flip,
    golden_path: &Path,
    actual: &image::RgbImage,
    cfg: &crate::eval::config::Config,
) -> Result<Option<(String, Option<image::RgbImage>)>> {
    let golden = LinearImage::load(golden_path)?;
    let (w, h) = (actual.width() as usize, actual.height() as usize);
    if (golden.width(), golden.height()) != (w, h) {
        return Ok(Some((
            format!(
                "golden is {}x{}, the render {w}x{h}",
                golden.width(),
                golden.height()
            ),
            None,
        )));
    }
    let test = LinearImage::from_srgb8(w, h, actual.as_raw())
        .ok_or_else(|| Error::Internal("render size mismatch".into()))?;
    let s = flip.compare(&golden, &test)?;
    let p99 = pool::percentile(&s.map.values, 99.0).unwrap_or(0.0);
    let (tm, tp) = (cfg.golden.flip_mean.0, cfg.golden.flip_p99.0);
    if s.mean <= tm && p99 <= tp {
        return Ok(None);
    }
    let why = format!(
        "FLIP mean {:.5} (limit {tm}), p99 {:.5} (limit {tp})",
        s.mean, p99
    );
    Ok(Some((
        why,
        Some(colormap::heat_map(&s.map.values, w, h, (h / 32).max(4))),
    )))
}
