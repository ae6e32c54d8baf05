//! The paper's experiment (§6, Figures 5–6) as a config: each model is simplified by vertex
//! clustering, by our QEM and by meshoptimizer to several vertex counts, each result is optimized,
//! and the energy is measured on held-out views (24 by default, a turned Fibonacci sphere: each at least
//! 10° from the 20 dodecahedron views used while optimizing), before and after, relative to each
//! input. Writes `results.csv`, one energy log per run (`energy/MODEL-METHOD-V.csv`), the meshes
//! (`meshes/`), and two SVG plots: held-out energy against vertex count, and energy against
//! evaluations.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::io::plot::{Series, line_plot as plot};
use crate::io::plot_png::Chart;
use crate::mesh::{self, LoadOptions, Mesh};
use crate::simplify::lindstrom_turk::{
    Options, Targets, cameras, d_ms, held_out_rig, optimize_towards, target_images,
};
use crate::simplify::{Goal, Method, chain};

/// One model of the experiment.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    /// Short name for files and tables.
    pub name: String,
    /// Mesh path, relative to the config file.
    pub path: PathBuf,
    /// Target vertex counts of the simplified inputs.
    pub vertices: Vec<usize>,
}

/// The experiment config.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Experiment {
    /// Output folder, relative to the config file.
    pub out: PathBuf,
    /// Evaluation budget per run.
    pub evals: u64,
    /// Views while optimizing.
    #[serde(default = "default_views")]
    pub views: u32,
    /// Image size.
    #[serde(default = "default_size")]
    pub size: u32,
    /// Held-out views for the final energies.
    #[serde(default = "default_held_out")]
    pub held_out_views: u32,
    /// Seed.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Simplifiers making the inputs.
    pub methods: Vec<Method>,
    /// Models.
    pub model: Vec<ModelSpec>,
}

fn default_views() -> u32 {
    20
}
fn default_size() -> u32 {
    256
}
fn default_held_out() -> u32 {
    24
}
fn default_seed() -> u64 {
    1
}

/// One row of `results.csv`.
#[derive(Debug, Clone, Serialize)]
pub struct ResultRow {
    /// Model name.
    pub model: String,
    /// Simplifier of the input.
    pub method: String,
    /// Vertices of the input (and the output).
    pub vertices: usize,
    /// Triangles of the input.
    pub triangles_in: usize,
    /// Triangles of the output.
    pub triangles_out: usize,
    /// Held-out d_MS of the input.
    pub held_out_before: f64,
    /// Held-out d_MS of the optimized mesh.
    pub held_out_after: f64,
    /// after / before.
    pub held_out_relative: f64,
    /// d_MS over the optimization views, before and after.
    pub train_before: f64,
    /// See `train_before`.
    pub train_after: f64,
    /// Energy evaluations.
    pub evals: u64,
    /// Seconds of the optimization (wall clock; reporting only; the targets, rendered once per
    /// model, are not included).
    pub seconds: f64,
    /// Accepted no-ops, swaps, teleports.
    pub accepted_no_op: u64,
    /// See `accepted_no_op`.
    pub accepted_swap: u64,
    /// See `accepted_no_op`.
    pub accepted_teleport: u64,
}

/// Run the experiment in `config`; `log` receives one line per finished run.
pub fn run(config: &Path, log: &mut dyn FnMut(&str)) -> Result<Vec<ResultRow>> {
    let exp: Experiment =
        crate::simplify::read_experiment(config, "configs/papers/lindstrom-turk.toml")?;
    let base = config.parent().unwrap_or(Path::new("."));
    let out = base.join(&exp.out);
    for d in ["energy", "meshes"] {
        std::fs::create_dir_all(out.join(d))
            .map_err(|e| Error::Internal(format!("cannot create {}: {e}", out.display())))?;
    }
    let opts = Options {
        evals: exp.evals,
        views: exp.views,
        size: exp.size,
        seed: exp.seed,
        ..Options::default()
    };
    let mut rows = Vec::new();
    let mut curves: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for spec in &exp.model {
        let path = base.join(&spec.path);
        let original: Arc<Mesh> = Arc::new(mesh::load(&path, &LoadOptions::default())?);
        let held_cams = cameras(&original, &held_out_rig(exp.held_out_views));
        let held_targets = target_images(&original, &held_cams, exp.size)?;
        // The optimization views' targets, rendered once per model.
        let targets = Targets::new(&original, &opts)?;
        for &method in &exp.methods {
            for &v in &spec.vertices {
                let lods = chain(&original, method, &[Goal::Triangles(2 * v)])?;
                let input = Arc::new(
                    lods.into_iter()
                        .next()
                        .map(|l| l.mesh)
                        .ok_or_else(|| Error::Internal("the simplifier returned no LOD".into()))?,
                );
                let before = d_ms(&input, &held_cams, exp.size, held_targets.clone())?;
                let o = optimize_towards(targets.clone(), &input, &opts, &|_| {})?;
                let result = Arc::new(o.mesh.clone());
                let after = d_ms(&result, &held_cams, exp.size, held_targets.clone())?;
                let stem = format!("{}-{}-{}", spec.name, method.name(), v);
                // The experiment's scans carry no materials an OBJ cannot keep.
                let _ = crate::mesh::write_obj::write(
                    &input,
                    &out.join("meshes").join(format!("{stem}-input.obj")),
                )?;
                let _ = crate::mesh::write_obj::write(
                    &result,
                    &out.join("meshes").join(format!("{stem}-optimized.obj")),
                )?;
                crate::io::csv::write_rows(
                    &out.join("energy").join(format!("{stem}.csv")),
                    None,
                    &o.log,
                )?;
                curves.push((
                    stem.clone(),
                    o.log.iter().map(|r| (r.evals as f64, r.relative)).collect(),
                ));
                let row = ResultRow {
                    model: spec.name.clone(),
                    method: method.name().into(),
                    vertices: o.vertices.1,
                    triangles_in: input.triangle_count(),
                    triangles_out: result.triangle_count(),
                    held_out_before: before,
                    held_out_after: after,
                    held_out_relative: after / before.max(f64::MIN_POSITIVE),
                    train_before: o.initial_d_ms,
                    train_after: o.final_d_ms,
                    evals: o.evals,
                    seconds: o.seconds,
                    accepted_no_op: o.accepted.no_op,
                    accepted_swap: o.accepted.swap,
                    accepted_teleport: o.accepted.teleport,
                };
                log(&format!(
                    "{stem}: {} vertices, held-out d_MS {:.4e} -> {:.4e} ({:.1} %), {} evals in {:.1} s",
                    row.vertices,
                    before,
                    after,
                    100.0 * row.held_out_relative,
                    o.evals,
                    o.seconds
                ));
                rows.push(row);
            }
        }
    }
    crate::io::csv::write_rows(&out.join("results.csv"), None, &rows)?;
    write_vertex_figures(&exp, &rows, &out)?;
    let series: Vec<Series> = curves.into_iter().map(|(n, p)| (n, p, false)).collect();
    write_figure(
        &out.join("energy-vs-evals"),
        "energy (relative to the input) against evaluations",
        "energy evaluations",
        "E / E(input)",
        &series,
    )?;
    Ok(rows)
}

/// `MODEL-energy-vs-vertices`: held-out d_MS before and after optimization against the vertex
/// count, one pair of lines per method.
fn write_vertex_figures(exp: &Experiment, rows: &[ResultRow], out: &Path) -> Result<()> {
    for spec in &exp.model {
        let mut series = Vec::new();
        for m in &exp.methods {
            let pts = |f: fn(&ResultRow) -> f64| -> Vec<(f64, f64)> {
                rows.iter()
                    .filter(|r| r.model == spec.name && r.method == m.name())
                    .map(|r| (r.vertices as f64, f(r)))
                    .collect()
            };
            series.push((
                format!("{} input", m.name()),
                pts(|r| r.held_out_before),
                true,
            ));
            series.push((
                format!("{} optimized", m.name()),
                pts(|r| r.held_out_after),
                false,
            ));
        }
        write_figure(
            &out.join(format!("{}-energy-vs-vertices", spec.name)),
            &format!("{}: held-out d_MS against vertex count", spec.name),
            "vertices",
            "held-out d_MS",
            &series,
        )?;
    }
    Ok(())
}

/// One figure as `STEM.svg` and `STEM.png` (linear axes).
fn write_figure(stem: &Path, title: &str, x: &str, y: &str, series: &[Series]) -> Result<()> {
    let svg = plot(title, x, y, series, false);
    crate::io::write_atomic(&stem.with_extension("svg"), svg.as_bytes())?;
    crate::io::plot_png::write(
        &stem.with_extension("png"),
        &Chart::from_series(title, x, y, series, false),
    )
}

#[cfg(test)]
mod tests {
    use crate::scene::Rig;

    use crate::simplify::lindstrom_turk::held_out_rig;

    #[test]
    fn held_out_views_differ_from_the_optimization_views() {
        // The paper measures on 24 views "all different from the ones used during optimization".
        let train = Rig::Dodecahedron.directions();
        let held = held_out_rig(24).directions();
        let min_angle = held
            .iter()
            .flat_map(|h| train.iter().map(move |t| h.angle_between(*t).to_degrees()))
            .fold(f32::MAX, f32::min);
        assert!(min_angle > 10.0, "closest pair {min_angle}°");
    }
}
