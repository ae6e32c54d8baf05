//! `lodeval bench simplify`: QEM, clustering and meshoptimizer timed in turns.

use crate::error::{Error, Result};
use crate::mesh::Mesh;

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
