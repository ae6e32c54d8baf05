//! Qu & Meyer's evaluation (§5.3, Figure 7), rebuilt on the shipped textured models: the same
//! vertex budgets remeshed uniformly, by curvature, and by curvature and visual masking, each
//! scored against the original by `eval` (FLIP and the calibrated VDP over the 20 dodecahedron
//! views) and by where its vertices went (the share in the most strongly masked quarter of the
//! surface), with the perceptual method's maps as pictures.
//!
//! The paper's claim: the vertices saved under strong masking are invisible, and the detail
//! moves to unmasked regions (Figure 7's eyes, nose and mouth). The results' README says whether
//! the measurements agree.
//!
//! Writes into the config's `out` folder: `meshes/` (every remesh as OBJ), `maps/MODEL/` (the
//! qu-meyer method's signal, masking, curvature, density and sample maps at the first budget),
//! `eval.toml` and `eval/` (the `eval` config and its full output), and `results.csv`.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::eval::config::{
    AssetConfig, Config, HeatmapChoice, ImageSize, LodConfig, RigName, SampleCount, ShadingName,
};
use crate::mesh::{self, LoadOptions};
use crate::metric::{Metric, MetricFamily};
use crate::simplify::qu_meyer::{self, Method, Options};

/// One model of the experiment.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    /// Name for tables and files.
    pub name: String,
    /// Mesh path, relative to the config file (with texture coordinates).
    pub mesh: PathBuf,
    /// Vertex budgets.
    pub vertices: Vec<usize>,
}

/// The experiment config.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Experiment {
    /// `"qu-meyer"`.
    pub paper: String,
    /// Output folder, relative to the config file.
    pub out: PathBuf,
    /// Image size of the scoring renders.
    #[serde(default = "default_size")]
    pub size: u32,
    /// γ_c for the curvature and qu-meyer methods.
    #[serde(default = "default_curvature_gamma")]
    pub curvature_gamma: f64,
    /// γ_p for the qu-meyer method.
    #[serde(default = "default_perceptual_gamma")]
    pub perceptual_gamma: f64,
    /// Also remesh with the masking map's pattern term alone (TVI weight 0), as `qu-meyer-pattern`.
    #[serde(default)]
    pub pattern_only: bool,
    /// The models.
    pub model: Vec<ModelSpec>,
}

fn default_size() -> u32 {
    512
}
fn default_curvature_gamma() -> f64 {
    1.2
}
fn default_perceptual_gamma() -> f64 {
    1.0
}

/// One row of `results.csv`.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// Model.
    pub model: String,
    /// Vertex budget.
    pub budget: usize,
    /// Method.
    pub method: String,
    /// 3D points of the remesh.
    pub vertices: usize,
    /// Its triangles.
    pub triangles: usize,
    /// Share of its vertices in the most strongly masked quarter of the surface.
    pub masked_share: f64,
    /// FLIP, mean over the 20 views.
    pub flip_mean: f64,
    /// FLIP of the worst view.
    pub flip_worst: f64,
    /// VDP JND, mean over the views.
    pub vdp_jnd_mean: f64,
    /// VDP detection probability, mean over the views.
    pub vdp_mean: f64,
    /// Seconds of the remesh.
    pub seconds: f64,
}

/// What the experiment wrote.
#[derive(Debug, Clone)]
pub struct Report {
    /// The output folder.
    pub out: PathBuf,
    /// One row per model, budget and method.
    pub rows: Vec<Row>,
}

/// `path` written relative to the folder `base` (both made absolute first), with `/`.
fn relative(path: &Path, base: &Path) -> PathBuf {
    let abs = |p: &Path| -> Vec<std::ffi::OsString> {
        std::path::absolute(p)
            .unwrap_or_else(|_| p.to_path_buf())
            .components()
            .map(|c| c.as_os_str().to_os_string())
            .collect()
    };
    let (p, b) = (abs(path), abs(base));
    let common = p.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut out = PathBuf::new();
    for _ in common..b.len() {
        out.push("..");
    }
    for c in &p[common..] {
        out.push(c);
    }
    out
}

/// Run the experiment of `config`.
pub fn run(config: &Path, log: &mut dyn FnMut(&str)) -> Result<Report> {
    let exp: Experiment = crate::simplify::read_experiment(config, "configs/papers/qu-meyer.toml")?;
    if exp.paper != "qu-meyer" {
        return Err(Error::input(
            config,
            format!("paper = \"{}\": this is the qu-meyer experiment", exp.paper),
            "give configs/papers/qu-meyer.toml (paper = \"qu-meyer\")",
        ));
    }
    let base = crate::io::parent_dir(config);
    let out = crate::io::resolve(&base, &exp.out);
    let meshes_dir = out.join("meshes");
    std::fs::create_dir_all(&meshes_dir).map_err(|e| {
        Error::input(
            &out,
            format!("cannot create the output folder: {e}"),
            "give an `out` folder you can write to",
        )
    })?;
    let mut made: Vec<Made> = Vec::new();
    let mut assets: Vec<AssetConfig> = Vec::new();
    let named = |e: String| {
        Error::input(
            config,
            e,
            "model names and budgets name files and rows: letters, digits, '-', '_', '.'",
        )
    };
    for m in &exp.model {
        let path = crate::io::resolve(&base, &m.mesh);
        let input = Arc::new(mesh::load(&path, &LoadOptions::default())?);
        let mut asset = AssetConfig::new(&m.name, relative(&path, &out)).map_err(named)?;
        for (k, &budget) in m.vertices.iter().enumerate() {
            // (label, method, TVI weight)
            let mut variants: Vec<(&str, Method, f64)> = vec![
                ("uniform", Method::Uniform, 0.5),
                ("curvature", Method::Curvature, 0.5),
                ("qu-meyer", Method::QuMeyer, 0.5),
            ];
            if exp.pattern_only {
                variants.push(("qu-meyer-pattern", Method::QuMeyer, 0.0));
            }
            for (label, method, tvi_weight) in variants {
                let mut options = Options::new(budget);
                options.method = method;
                options.curvature_gamma = exp.curvature_gamma;
                options.perceptual_gamma = exp.perceptual_gamma;
                options.tvi_weight = tvi_weight;
                options.keep_maps = k == 0 && label == "qu-meyer";
                let start = std::time::Instant::now();
                let r = qu_meyer::remesh(&input, &options)?;
                let seconds = start.elapsed().as_secs_f64();
                let name = format!("{label}-{budget}");
                let file = meshes_dir.join(format!("{}-{name}.obj", m.name));
                // Its textured OBJ inputs carry nothing an OBJ cannot keep.
                let _ = mesh::write_obj::write(&r.mesh, &file)?;
                if let Some(images) = &r.maps {
                    images.write(&out.join("maps").join(&m.name))?;
                }
                log(&format!(
                    "{} {}: {} vertices, {} triangles, {:.0} % in the most masked quarter, {:.2} s",
                    m.name,
                    name,
                    r.vertices,
                    r.mesh.triangle_count(),
                    100.0 * r.masked_share,
                    seconds
                ));
                asset
                    .lods
                    .push(LodConfig::new(&name, relative(&file, &out)).map_err(named)?);
                made.push(Made {
                    model: m.name.clone(),
                    budget,
                    label,
                    vertices: r.vertices,
                    triangles: r.mesh.triangle_count(),
                    masked_share: r.masked_share,
                    seconds,
                });
            }
        }
        assets.push(asset);
    }
    // Score every remesh with eval, from a config written beside the results.
    let eval_config = out.join("eval.toml");
    let text = format!(
        "# Written by `lodeval remesh --experiment` (Qu & Meyer): every remesh scored against its\n\
         # original over the 20 dodecahedron views. Rerun with `lodeval eval` on this file.\n{}",
        scoring_config(assets, exp.size)?.to_toml()?
    );
    crate::io::write_atomic(&eval_config, text.as_bytes())?;
    log("scoring every remesh with eval (FLIP and the VDP, 20 views)");
    let outcome = crate::eval::eval(
        &eval_config,
        &crate::eval::RunOptions::DEFAULT,
        &crate::progress::Silent,
    )?;
    let rows = result_rows(&made, &outcome.results);
    crate::io::csv::write_rows(&out.join("results.csv"), None, &rows)?;
    Ok(Report { out, rows })
}

/// One remesh the experiment made.
struct Made {
    model: String,
    budget: usize,
    label: &'static str,
    vertices: usize,
    triangles: usize,
    masked_share: f64,
    seconds: f64,
}

/// `results.csv`'s rows: each remesh with its scores from the `eval` run.
fn result_rows(made: &[Made], results: &crate::eval::Results) -> Vec<Row> {
    let mean = |a: &str, l: &str, metric: Metric| results.mean(a, l, metric).unwrap_or(0.0);
    made.iter()
        .map(|m| {
            let lod = format!("{}-{}", m.label, m.budget);
            Row {
                model: m.model.clone(),
                budget: m.budget,
                method: m.label.to_string(),
                vertices: m.vertices,
                triangles: m.triangles,
                masked_share: m.masked_share,
                flip_mean: mean(&m.model, &lod, Metric::Flip),
                flip_worst: results
                    .worst(&m.model, &lod, Metric::Flip)
                    .map_or(0.0, |w| w.1),
                vdp_jnd_mean: mean(&m.model, &lod, Metric::VdpJnd),
                vdp_mean: mean(&m.model, &lod, Metric::Vdp),
                seconds: m.seconds,
            }
        })
        .collect()
}

/// The `eval` config that scores every remesh: FLIP and the VDP over the 20 dodecahedron views,
/// Phong shading, no distances, contact sheets, into `eval/` beside it.
fn scoring_config(assets: Vec<AssetConfig>, size: u32) -> Result<Config> {
    let mut c = Config::new(assets);
    c.out = Some("eval".into());
    c.metrics = vec![MetricFamily::Flip, MetricFamily::Vdp];
    c.render.size = ImageSize::try_from(size).map_err(Error::Usage)?;
    c.render.samples = SampleCount(4);
    c.render.rig = RigName(crate::scene::Rig::Dodecahedron);
    c.render.shading = ShadingName(crate::raster::Shading::Phong);
    c.distance.enabled = false;
    c.images.heatmaps = HeatmapChoice::None;
    c.images.contact_sheets = true;
    Ok(c)
}
