//! `lodeval bench menzel-guthe`: Menzel & Guthe's applied collapses per second (perception and
//! Hausdorff tests included), beside our QEM engine's on the same mesh to the same triangle count.

use crate::error::Result;
use crate::mesh::Mesh;

/// One row of `lodeval bench menzel-guthe`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct MenzelGutheBenchRow {
    /// Mesh name.
    pub mesh: String,
    /// The input's triangles.
    pub input_triangles: usize,
    /// The goal, as a fraction of them.
    pub ratio: f64,
    /// Triangles of the LOD.
    pub triangles: usize,
    /// Threads.
    pub threads: usize,
    /// Timed runs.
    pub runs: usize,
    /// Collapses applied per run.
    pub collapses: u64,
    /// Perception tests per run.
    pub perception_tests: u64,
    /// Hausdorff tests per run.
    pub hausdorff_tests: u64,
    /// Collapses postponed (perceptual + geometric) per run.
    pub postponed: u64,
    /// Applied collapses per second of the collapse loop, best run.
    pub collapses_per_second: f64,
    /// The same, median run.
    pub median_collapses_per_second: f64,
    /// The same, worst run.
    pub worst_collapses_per_second: f64,
    /// Seconds before the loop (BVH, curvatures, global masking), median.
    pub setup_seconds: f64,
    /// Applied collapses per second of the whole run (set-up included), median.
    pub median_total_per_second: f64,
    /// Our QEM engine's collapses per second to the same triangle count, median of the runs.
    pub qem_collapses_per_second: f64,
}

/// Run Menzel–Guthe and QEM `runs` times each, alternating, on every mesh to `ratio` of its
/// triangles. Timing is for reporting only.
pub fn bench_menzel_guthe(
    meshes: &[(String, Mesh)],
    ratio: f64,
    runs: usize,
) -> Result<Vec<MenzelGutheBenchRow>> {
    use crate::simplify::menzel_guthe::{self, Goal, Options};
    use crate::simplify::qem;
    let runs = runs.max(1);
    let mut rows = Vec::new();
    for (name, mesh) in meshes {
        let n = mesh.triangle_count();
        let target = ((n as f64 * ratio).round() as usize).clamp(1, n);
        let (mut mg_rates, mut totals, mut setups, mut qem_rates) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut last = None;
        for _ in 0..runs {
            let s = menzel_guthe::simplify(mesh, &[Goal::Triangles(target)], &Options::DEFAULT)?;
            let applied = s.counts.applied as f64;
            mg_rates.push(applied / (s.seconds - s.setup_seconds).max(1e-9));
            totals.push(applied / s.seconds.max(1e-9));
            setups.push(s.setup_seconds);
            let start = std::time::Instant::now();
            let pm = qem::progressive(mesh, qem::Stop::Triangles(target));
            let seconds = start.elapsed().as_secs_f64();
            qem_rates.push(pm.collapses.len() as f64 / seconds.max(1e-9));
            last = Some(s);
        }
        let s = last.expect("at least one run");
        let median = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let mut sorted = mg_rates.clone();
        sorted.sort_by(f64::total_cmp);
        rows.push(MenzelGutheBenchRow {
            mesh: name.clone(),
            input_triangles: n,
            ratio,
            triangles: s.lods[0].mesh.triangle_count(),
            threads: rayon::current_num_threads(),
            runs,
            collapses: s.counts.applied,
            perception_tests: s.counts.perception_tests,
            hausdorff_tests: s.counts.hausdorff_tests,
            postponed: s.counts.postponed_perceptual + s.counts.postponed_geometric,
            collapses_per_second: sorted[sorted.len() - 1],
            median_collapses_per_second: median(&mut mg_rates),
            worst_collapses_per_second: sorted[0],
            setup_seconds: median(&mut setups),
            median_total_per_second: median(&mut totals),
            qem_collapses_per_second: median(&mut qem_rates),
        });
    }
    Ok(rows)
}
