//! `lodeval bench optimize`: the image-driven optimizer's steady evaluations per second.

use crate::error::{Error, Result};
use crate::mesh::Mesh;

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
            threads: crate::raster::incremental::crew_threads(),
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
