//! The paper's evaluation (Menzel & Guthe 2010 §6), rebuilt with lodeval's simplifiers, renderer
//! and calibrated VDP:
//!
//! - Table 2: triangles of each scan simplified to 0.1 % and 1 % of its bounding-box diagonal —
//!   Menzel–Guthe (the error mapped to a viewing distance by the paper's 1/30° scaling) against
//!   our attribute-preserving QEM stopped at the same geometric error — and, beyond the paper, how
//!   visible each LOD is at that distance (the VDP's detection probability and FLIP, worst of the
//!   views), since a triangle count means little without it.
//! - Figure 1: one model with four materials of different frequency content at 0.2 %: the
//!   triangle counts, the visibility, and a contact sheet of the LODs.
//! - The user study's analogue (Table 3): LODs made for one viewing distance with the threshold at
//!   ¼, ½, 1, 2 and 4 JND, each seen at that distance: the VDP's detection probability (the paper
//!   found about half of its observers noticing at 1 JND) and FLIP.
//!
//! Writes `table2.csv`, `figure1.csv`, `figure1-sheet.png`, `study.csv`, `study.svg` and
//! `study.png` into the config's `out` folder. Decisions where the paper is silent are in the
//! config (`configs/papers/menzel-guthe2010.toml`) and in the results' README.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::eval::config::{DistanceConfig, SampleCount, ViewingConfig};
use crate::eval::distance::{DistanceJob, search, visibility_at};
use crate::eval::tables::DistanceBound;
use crate::io::plot::{Series, line_plot};
use crate::io::plot_png::Chart;
use crate::mesh::{self, ColorSpace, LoadOptions, Material, Mesh, Texture, TextureSlot};
use crate::raster::{self, RenderScene, RenderSettings, SamplePattern};
use crate::scene::{Camera, Rig};
use crate::simplify::menzel_guthe::{self, Goal, Options};
use crate::simplify::qem;

/// One scan of Table 2.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScanSpec {
    /// Name for tables.
    pub name: String,
    /// Mesh path, relative to the config file.
    pub mesh: PathBuf,
    /// Metres per model unit (the viewing distances are reported in metres).
    #[serde(default = "one")]
    pub meters_per_unit: f64,
}

fn one() -> f64 {
    1.0
}

/// Figure 1's settings.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FigureSpec {
    /// The model (with UVs: two of the materials are textures).
    pub mesh: PathBuf,
    /// Error as a fraction of the bounding-box diagonal (the paper's 0.2 %).
    pub error: f64,
    /// Metres per model unit.
    #[serde(default = "one")]
    pub meters_per_unit: f64,
}

/// The user study's settings.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudySpec {
    /// Table 2 scans to use, by name.
    pub scans: Vec<String>,
    /// Thresholds in JND.
    pub jnds: Vec<f64>,
    /// The on-screen diameter (display pixels) the LODs are made for and viewed at.
    pub diameter_px: f64,
}

/// The experiment config.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Experiment {
    /// `"menzel-guthe2010"`: which paper's experiment the config is for.
    pub paper: String,
    /// Output folder, relative to the config file.
    pub out: PathBuf,
    /// Table 2's errors, fractions of the bounding-box diagonal.
    pub errors: Vec<f64>,
    /// Views of the visibility checks (the first N of the dodecahedron rig).
    pub views: usize,
    /// Samples per pixel of the visibility renders.
    pub samples: u32,
    /// Table 2's scans.
    pub scan: Vec<ScanSpec>,
    /// Figure 1.
    pub figure1: FigureSpec,
    /// The user study's analogue.
    pub study: StudySpec,
}

/// One row of `table2.csv`.
#[derive(Debug, Clone, Serialize)]
pub struct Table2Row {
    /// Scan.
    pub scan: String,
    /// Its triangles.
    pub input_triangles: usize,
    /// Error, fraction of the diagonal.
    pub error: f64,
    /// The viewing distance the error maps to, metres.
    pub distance_m: f64,
    /// Menzel–Guthe's triangles.
    pub mg_triangles: usize,
    /// The same loop without the perception test: our attribute-aware QEM with the Hausdorff
    /// distance to the original guaranteed within the error (what the paper's baseline
    /// guarantees geometrically, without its attribute bounds).
    pub bounded_triangles: usize,
    /// Our attribute-aware QEM stopped before the first collapse whose quadric error exceeds
    /// the error (no guarantee: the quadric under-states the deviation).
    pub qem_triangles: usize,
    /// mg / bounded: the paper's Table 2 ratio (it found about 0.5 against its baseline).
    pub ratio: f64,
    /// VDP detection probability of Menzel–Guthe's LOD at that distance (worst view).
    pub mg_vdp: f64,
    /// The bounded QEM's.
    pub bounded_vdp: f64,
    /// The QEM's.
    pub qem_vdp: f64,
    /// FLIP mean of Menzel–Guthe's LOD there (worst view).
    pub mg_flip: f64,
    /// The bounded QEM's.
    pub bounded_flip: f64,
    /// The QEM's.
    pub qem_flip: f64,
}

/// One row of `figure1.csv`.
#[derive(Debug, Clone, Serialize)]
pub struct Figure1Row {
    /// Material.
    pub material: String,
    /// Triangles of the LOD.
    pub triangles: usize,
    /// Of the original's.
    pub input_triangles: usize,
    /// The viewing distance, metres.
    pub distance_m: f64,
    /// VDP detection probability there (worst view).
    pub vdp: f64,
    /// FLIP mean there (worst view).
    pub flip: f64,
}

/// One row of `study.csv`.
#[derive(Debug, Clone, Serialize)]
pub struct StudyRow {
    /// Scan.
    pub scan: String,
    /// Threshold, JND.
    pub jnd: f64,
    /// The viewing distance, metres.
    pub distance_m: f64,
    /// Triangles of the LOD.
    pub triangles: usize,
    /// Of the original's.
    pub input_triangles: usize,
    /// VDP detection probability at the distance (worst view).
    pub vdp: f64,
    /// VDP JND there.
    pub vdp_jnd: f64,
    /// FLIP mean there (worst view).
    pub flip: f64,
    /// The calibrated VDP's own answer for the LOD: the distance beyond which its detection
    /// probability stays at or below 0.5 (worst view), metres.
    pub vdp_distance_m: f64,
    /// Whether that is a measurement or a bound (`measured`, `at_least`, `at_most`).
    pub vdp_bound: DistanceBound,
    /// vdp_distance_m / distance_m: how much farther the VDP puts the LOD's threshold.
    pub vdp_over_mg: f64,
}

/// What the experiment wrote.
#[derive(Debug, Clone)]
pub struct Report {
    /// Table 2.
    pub table2: Vec<Table2Row>,
    /// Figure 1.
    pub figure1: Vec<Figure1Row>,
    /// The study.
    pub study: Vec<StudyRow>,
}

/// Read and check the config.
pub fn load(config: &Path) -> Result<Experiment> {
    let exp: Experiment =
        crate::simplify::read_experiment(config, "configs/papers/menzel-guthe2010.toml")?;
    let bad = |what: String| {
        Err(Error::input(
            config,
            what,
            "see configs/papers/menzel-guthe2010.toml for the keys and their ranges",
        ))
    };
    if exp
        .errors
        .iter()
        .chain([&exp.figure1.error])
        .any(|e| !(e.is_finite() && *e > 0.0 && *e < 1.0))
    {
        return bad("errors are fractions of the diagonal in (0, 1)".into());
    }
    if exp.views == 0 || exp.views > 20 {
        return bad(format!("views = {}: use 1 to 20", exp.views));
    }
    if SampleCount::try_from(exp.samples).is_err() {
        return bad(format!("samples = {}: use 1, 4, 9, …, 64", exp.samples));
    }
    if exp.study.jnds.iter().any(|j| !(j.is_finite() && *j > 0.0))
        || !(exp.study.diameter_px.is_finite() && exp.study.diameter_px >= 4.0)
    {
        return bad("study: jnds above 0 and diameter_px of at least 4".into());
    }
    for s in &exp.study.scans {
        if !exp.scan.iter().any(|x| &x.name == s) {
            return bad(format!("study: scan '{s}' is not one of the [[scan]]s"));
        }
    }
    Ok(exp)
}

/// The distance job of `lod` against `original`, seen from the first `views` rig directions.
fn job<'a>(
    original: &'a RenderScene,
    lod: &'a RenderScene,
    mpu: f64,
    views: usize,
) -> DistanceJob<'a> {
    DistanceJob {
        original,
        lod,
        directions: Rig::Dodecahedron.directions()[..views].to_vec(),
        meters_per_unit: mpu,
        simplifier_error: None,
        names: ("", "", 0),
        switch_m: None,
        originals: None,
    }
}

/// The visibility of `lod` against `original` at `distance_m`.
fn visibility(
    original: &RenderScene,
    lod: &Mesh,
    mpu: f64,
    views: usize,
    samples: u32,
    distance_m: f64,
) -> Result<(f64, f64, f64)> {
    let lod = RenderScene::of(Arc::new(lod.clone()));
    visibility_at(
        &job(original, &lod, mpu, views),
        &ViewingConfig::default(),
        &RenderSettings::DEFAULT,
        SampleCount::try_from(samples).map_err(Error::Usage)?,
        distance_m,
    )
}

/// The VDP's distance for `lod`: beyond it the detection probability stays at or below 0.5.
fn vdp_distance(
    original: &RenderScene,
    lod: &Mesh,
    mpu: f64,
    views: usize,
    samples: u32,
) -> Result<(f64, DistanceBound)> {
    let lod = RenderScene::of(Arc::new(lod.clone()));
    let config = DistanceConfig {
        flip_mean: None,
        samples: SampleCount::try_from(samples).map_err(Error::Usage)?,
        ..DistanceConfig::default()
    };
    let rows = search(
        &job(original, &lod, mpu, views),
        &config,
        &ViewingConfig::default(),
        &RenderSettings::DEFAULT,
    )?;
    let row = rows
        .first()
        .ok_or_else(|| Error::Internal("the distance search returned no row".into()))?;
    Ok((row.imperceptible_beyond_m, row.bound))
}

/// Run the experiment of `config`; `log` gets a line per step.
pub fn run(config: &Path, log: &mut dyn FnMut(&str)) -> Result<Report> {
    let exp = load(config)?;
    let base = crate::io::parent_dir(config);
    let out = base.join(&exp.out);
    std::fs::create_dir_all(&out)
        .map_err(|e| Error::Internal(format!("cannot create {}: {e}", out.display())))?;
    let mut table2 = Vec::new();
    let mut scans: Vec<(String, Arc<Mesh>, f64)> = Vec::new();
    for spec in &exp.scan {
        let mesh = Arc::new(mesh::load(&base.join(&spec.mesh), &LoadOptions::default())?);
        let original = RenderScene::of(mesh.clone());
        let diagonal = mesh.aabb().diagonal() as f64;
        let options = Options {
            meters_per_unit: spec.meters_per_unit,
            ..Options::DEFAULT
        };
        let goals: Vec<Goal> = exp.errors.iter().map(|&e| Goal::Error(e)).collect();
        let mg = menzel_guthe::simplify(&mesh, &goals, &options)?;
        let bounded = menzel_guthe::simplify(
            &mesh,
            &goals,
            &Options {
                perception: false,
                ..options
            },
        )?;
        log(&format!(
            "table 2: {}: menzel-guthe {:.1} s, bounded qem {:.1} s",
            spec.name, mg.seconds, bounded.seconds
        ));
        let round = crate::eval::tables::round7;
        for ((e, lod), bounded) in exp.errors.iter().zip(&mg.lods).zip(&bounded.lods) {
            let (qem_lod, _) = qem::simplify(&mesh, qem::Stop::RelativeError(*e))?;
            let distance_m =
                menzel_guthe::distance::error_distance(e * diagonal) * spec.meters_per_unit;
            let seen = |lod: &Mesh| {
                visibility(
                    &original,
                    lod,
                    spec.meters_per_unit,
                    exp.views,
                    exp.samples,
                    distance_m,
                )
            };
            let (mg_vdp, _, mg_flip) = seen(&lod.mesh)?;
            let (bounded_vdp, _, bounded_flip) = seen(&bounded.mesh)?;
            let (qem_vdp, _, qem_flip) = seen(&qem_lod)?;
            let row = Table2Row {
                scan: spec.name.clone(),
                input_triangles: mesh.triangle_count(),
                error: *e,
                distance_m: round(distance_m),
                mg_triangles: lod.mesh.triangle_count(),
                bounded_triangles: bounded.mesh.triangle_count(),
                qem_triangles: qem_lod.triangle_count(),
                ratio: round(
                    lod.mesh.triangle_count() as f64 / bounded.mesh.triangle_count().max(1) as f64,
                ),
                mg_vdp: round(mg_vdp),
                bounded_vdp: round(bounded_vdp),
                qem_vdp: round(qem_vdp),
                mg_flip: round(mg_flip),
                bounded_flip: round(bounded_flip),
                qem_flip: round(qem_flip),
            };
            log(&format!(
                "table 2: {} at {} %: menzel-guthe {} triangles (VDP {:.2}), bounded qem {} \
                 (VDP {:.2}), qem {} (VDP {:.2})",
                row.scan,
                e * 100.0,
                row.mg_triangles,
                row.mg_vdp,
                row.bounded_triangles,
                row.bounded_vdp,
                row.qem_triangles,
                row.qem_vdp
            ));
            table2.push(row);
        }
        scans.push((spec.name.clone(), mesh, spec.meters_per_unit));
    }
    crate::io::csv::write_rows(&out.join("table2.csv"), None, &table2)?;
    let figure1 = figure1(&exp, &base, &out, log)?;
    let study = study(&exp, &scans, &out, log)?;
    Ok(Report {
        table2,
        figure1,
        study,
    })
}

/// `mesh` with every triangle given `material`.
fn with_material(mesh: &Mesh, material: Material) -> Result<Mesh> {
    let mut data = mesh.to_data();
    data.materials = vec![material];
    data.material_ids = vec![0; data.triangles.len()];
    Mesh::new(data, &LoadOptions::default())
}

/// A 512² texture of independent grey values in [0.25, 0.95] (sRGB), seeded: the highest
/// frequency content a texture can have.
fn noise_texture() -> Result<Texture> {
    let (w, h) = (512u32, 512u32);
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut px = Vec::with_capacity((w * h * 4) as usize);
    for _ in 0..w * h {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let g = (64 + (state >> 56) as u32 * 180 / 255) as u8;
        px.extend_from_slice(&[g, g, g, 255]);
    }
    Texture::new("noise".into(), w, h, px, ColorSpace::Srgb)
        .ok_or_else(|| Error::Internal("noise texture".into()))
}

/// Figure 1: four materials on one model at one error.
fn figure1(
    exp: &Experiment,
    base: &Path,
    out: &Path,
    log: &mut dyn FnMut(&str),
) -> Result<Vec<Figure1Row>> {
    let spec = &exp.figure1;
    let source = mesh::load(&base.join(&spec.mesh), &LoadOptions::default())?;
    let own = source
        .materials()
        .first()
        .cloned()
        .unwrap_or_else(Material::default_material);
    let plain = Material {
        base_color_texture: None,
        normal_texture: None,
        base_color: Vec3::splat(0.7),
        ..own.clone()
    };
    let materials = [
        (
            "matte",
            Material {
                specular: Vec3::ZERO,
                ..plain.clone()
            },
        ),
        (
            "glossy",
            Material {
                specular: Vec3::splat(0.5),
                shininess: 64.0,
                ..plain.clone()
            },
        ),
        ("texture", own.clone()),
        (
            "noise",
            Material {
                base_color: Vec3::ONE,
                base_color_texture: Some(TextureSlot::plain(Arc::new(noise_texture()?))),
                ..own
            },
        ),
    ];
    let options = Options {
        meters_per_unit: spec.meters_per_unit,
        ..Options::DEFAULT
    };
    let mut rows = Vec::new();
    let mut tiles = Vec::new();
    let mut settings = RenderSettings::DEFAULT;
    settings.width = 384;
    settings.height = 384;
    settings.samples = SamplePattern::Rotated(2);
    let camera = Camera::frame_sphere(
        source.bounding_sphere(),
        Rig::Dodecahedron.directions()[0],
        30.0,
        1.0,
        0.05,
    );
    for (name, material) in materials {
        let original = Arc::new(with_material(&source, material)?);
        let s = menzel_guthe::simplify(&original, &[Goal::Error(spec.error)], &options)?;
        let lod = &s.lods[0].mesh;
        let distance_m =
            menzel_guthe::distance::error_distance(spec.error * original.aabb().diagonal() as f64)
                * spec.meters_per_unit;
        let scene = RenderScene::of(original.clone());
        let (vdp, _, flip) = visibility(
            &scene,
            lod,
            spec.meters_per_unit,
            exp.views,
            exp.samples,
            distance_m,
        )?;
        log(&format!(
            "figure 1: {name}: {} of {} triangles (VDP {vdp:.2} at {distance_m:.2} m)",
            lod.triangle_count(),
            original.triangle_count()
        ));
        rows.push(Figure1Row {
            material: name.into(),
            triangles: lod.triangle_count(),
            input_triangles: original.triangle_count(),
            distance_m: crate::eval::tables::round7(distance_m),
            vdp: crate::eval::tables::round7(vdp),
            flip: crate::eval::tables::round7(flip),
        });
        for m in [&original, &Arc::new(lod.clone())] {
            let frame = raster::render(&RenderScene::of(m.clone()), &camera, &settings)?;
            tiles.push(frame.to_srgb8());
        }
    }
    crate::io::csv::write_rows(&out.join("figure1.csv"), None, &rows)?;
    // Two columns (original | LOD), one row per material.
    let sheet = crate::io::sheet::contact_sheet(&tiles, 2, 4, [255; 3])?;
    crate::io::write_image(
        &out.join("figure1-sheet.png"),
        &image::DynamicImage::ImageRgb8(sheet),
    )?;
    Ok(rows)
}

/// The user study's analogue.
fn study(
    exp: &Experiment,
    scans: &[(String, Arc<Mesh>, f64)],
    out: &Path,
    log: &mut dyn FnMut(&str),
) -> Result<Vec<StudyRow>> {
    let display = crate::eval::distance::Screen::new(&ViewingConfig::default());
    let mut rows = Vec::new();
    for name in &exp.study.scans {
        let (_, mesh, mpu) = scans
            .iter()
            .find(|(n, _, _)| n == name)
            .expect("checked by load");
        let r_m = mesh.bounding_sphere().radius as f64 * mpu;
        let distance_m = display.distance_for(r_m, exp.study.diameter_px);
        let original = RenderScene::of(mesh.clone());
        for &jnd in &exp.study.jnds {
            let options = Options {
                meters_per_unit: *mpu,
                jnd,
                ..Options::DEFAULT
            };
            let s = menzel_guthe::simplify(mesh, &[Goal::Distance(distance_m)], &options)?;
            let lod = &s.lods[0].mesh;
            let (vdp, vdp_jnd, flip) =
                visibility(&original, lod, *mpu, exp.views, exp.samples, distance_m)?;
            let (vdp_distance_m, vdp_bound) =
                vdp_distance(&original, lod, *mpu, exp.views, exp.samples)?;
            log(&format!(
                "study: {name} at {jnd} JND: {} triangles, VDP {vdp:.2} ({vdp_jnd:.2} JND); \
                 the VDP's distance {vdp_distance_m:.2} m against {distance_m:.2} m",
                lod.triangle_count()
            ));
            rows.push(StudyRow {
                scan: name.clone(),
                jnd,
                distance_m: crate::eval::tables::round7(distance_m),
                triangles: lod.triangle_count(),
                input_triangles: mesh.triangle_count(),
                vdp: crate::eval::tables::round7(vdp),
                vdp_jnd: crate::eval::tables::round7(vdp_jnd),
                flip: crate::eval::tables::round7(flip),
                vdp_distance_m,
                vdp_bound,
                vdp_over_mg: crate::eval::tables::round7(vdp_distance_m / distance_m),
            });
        }
    }
    crate::io::csv::write_rows(&out.join("study.csv"), None, &rows)?;
    let series: Vec<Series> = exp
        .study
        .scans
        .iter()
        .map(|n| {
            (
                n.clone(),
                rows.iter()
                    .filter(|r| &r.scan == n)
                    .map(|r| (r.jnd, r.vdp))
                    .collect(),
                false,
            )
        })
        .collect();
    let title = format!(
        "LODs at k JND seen from their distance ({} px across)",
        exp.study.diameter_px
    );
    let (x, y) = (
        "threshold of the LOD, JND (log scale)",
        "VDP detection probability, worst view",
    );
    crate::io::write_atomic(
        &out.join("study.svg"),
        line_plot(&title, x, y, &series, true).as_bytes(),
    )?;
    crate::io::write_atomic(
        &out.join("study.png"),
        &crate::io::plot_png::encode(&Chart::from_series(&title, x, y, &series, true))?,
    )?;
    Ok(rows)
}
