//! `lodeval bench williams`: Williams et al.'s preprocessing and per-frame cut adaptation.

use crate::error::Result;
use crate::mesh::Mesh;
use crate::scene::Rig;

/// One row of `lodeval bench williams`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct WilliamsBenchRow {
    /// Input triangles.
    pub triangles: usize,
    /// MT nodes.
    pub nodes: usize,
    /// Seconds to build the MT (QEM run and its replay).
    pub hierarchy_seconds: f64,
    /// Seconds of the per-node preprocessing.
    pub preprocess_seconds: f64,
    /// Triangle budget.
    pub budget: usize,
    /// Frames (views along the path) after the first.
    pub frames: usize,
    /// Adapt time per frame after the first: median, 95th percentile, max (ms).
    pub median_ms: f64,
    /// 95th percentile (ms).
    pub p95_ms: f64,
    /// Max (ms).
    pub max_ms: f64,
    /// The first frame, from the coarsest cut (ms).
    pub first_ms: f64,
    /// Nodes raised or lowered per frame (median).
    pub median_changes: usize,
}

/// Williams et al. preprocessing time and per-frame cut adaptation along a camera path: an orbit
/// of `views` cameras around the model (slightly above it), each turned 360°/`views` from the
/// last, for each budget ratio. Times are wall clock (reporting only).
pub fn bench_williams(mesh: &Mesh, ratios: &[f64], views: u32) -> Result<Vec<WilliamsBenchRow>> {
    use crate::simplify::williams::{Cut, Options, Williams};
    let (w, [hierarchy_seconds, preprocess_seconds]) = Williams::build_timed(mesh)?;
    let n = views.max(2);
    let orbit = (0..n)
        .map(|i| {
            let a = i as f32 * std::f32::consts::TAU / n as f32;
            glam::Vec3::new(a.sin(), 0.3, a.cos()).normalize()
        })
        .collect();
    let cameras = Rig::Explicit(orbit).cameras(mesh, 1.0);
    let opts = Options::default();
    let mut rows = Vec::new();
    for &r in ratios {
        let budget = ((mesh.triangle_count() as f64 * r).round() as usize).max(1);
        let mut cut = Cut::coarsest(&w.hierarchy);
        let mut times = Vec::new();
        let mut changes = Vec::new();
        for c in &cameras {
            let t = std::time::Instant::now();
            w.adapt(&mut cut, c, budget, &opts);
            times.push(t.elapsed().as_secs_f64() * 1e3);
            changes.push(cut.last_changes);
        }
        let first_ms = times.remove(0);
        changes.remove(0);
        let mut sorted = times.clone();
        sorted.sort_by(f64::total_cmp);
        changes.sort_unstable();
        let pick = |q: f64| sorted[((sorted.len() - 1) as f64 * q).round() as usize];
        rows.push(WilliamsBenchRow {
            triangles: mesh.triangle_count(),
            nodes: w.hierarchy.node_count(),
            hierarchy_seconds,
            preprocess_seconds,
            budget,
            frames: sorted.len(),
            median_ms: pick(0.5),
            p95_ms: pick(0.95),
            max_ms: pick(1.0),
            first_ms,
            median_changes: changes[changes.len() / 2],
        });
    }
    Ok(rows)
}
