//! LOD chains for engines: each asset's original and LODs as one glTF asset linked by
//! `MSFT_lod`, its `MSFT_screencoverage` switch points taken from the *measured*
//! imperceptibility distances (`distances.csv`), not guessed.
//!
//! Decisions:
//! - Levels go finest first, by triangle count (ties in chain order).
//! - The criterion is the VDP's (`vdp_p…`, the calibrated one) where the run computed it, else
//!   the first criterion of the run. Level k of the chain is shown while the object covers at
//!   least the screen coverage at which level k+1 becomes imperceptible; the coarsest level is
//!   never culled (a last value of 0).
//! - A coarser level imperceptible at a larger coverage than a finer one (the finer one is then
//!   never needed) keeps the finer one's value: coverage must not increase along the chain.
//! - A distance that is a bound of the search is used as it stands, with a warning: "invisible up
//!   to the largest size tried" switches there (it may be safe sooner), "visible down to 4 px"
//!   switches only below that size.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::tables::{DistanceBound, DistanceRow};
use crate::error::Result;
use crate::mesh::Mesh;

/// The criterion the switch points come from, of those in `rows`.
pub fn criterion(rows: &[DistanceRow]) -> Option<String> {
    rows.iter()
        .find(|r| r.criterion.starts_with("vdp_p"))
        .or(rows.first())
        .map(|r| r.criterion.clone())
}

/// `MSFT_screencoverage` for `asset`'s levels: the original, then `lods` (finest first), one
/// value per level; and the warnings about bounds or missing rows.
pub fn coverage(rows: &[DistanceRow], asset: &str, lods: &[&str]) -> (Vec<f64>, Vec<String>) {
    let mine: Vec<&DistanceRow> = rows.iter().filter(|r| r.asset == asset).collect();
    let picked = criterion(&mine.iter().map(|r| (*r).clone()).collect::<Vec<_>>());
    let mut out = Vec::with_capacity(lods.len() + 1);
    let mut warnings = Vec::new();
    let mut last = 1.0f64;
    for lod in lods {
        let row = mine
            .iter()
            .find(|r| r.lod == *lod && Some(&r.criterion) == picked.as_ref());
        let c = match row {
            Some(r) => {
                if r.bound != DistanceBound::Measured {
                    warnings.push(format!(
                        "{asset} {lod}: the {} distance is a bound of the search ({}); its switch \
                         point uses it as it stands",
                        r.criterion,
                        r.distance_text()
                    ));
                }
                r.screen_coverage
            }
            None => {
                warnings.push(format!(
                    "{asset} {lod}: no distance measured; it is never switched in"
                ));
                0.0
            }
        };
        last = last.min(c);
        out.push(last);
    }
    out.push(0.0);
    (out, warnings)
}

/// What [`write_chain`] wrote.
#[derive(Debug, Clone)]
pub struct ChainWritten {
    /// Every file written.
    pub files: Vec<PathBuf>,
    /// The LODs' names in level order (level 1 first; level 0 is the original).
    pub levels: Vec<String>,
    /// `MSFT_screencoverage` as written, one per level including the original: level k is used
    /// down to `coverage[k]`, so LOD level k takes over below `coverage[k - 1]`.
    pub coverage: Vec<f64>,
    /// The criterion the switch points come from.
    pub criterion: Option<String>,
    /// What could not be kept, and switch points that rest on a bound.
    pub warnings: Vec<String>,
}

/// Write `original` (named `asset`) and its `lods` (name, mesh) as one glTF asset at `path`
/// (`.glb` or `.gltf`) with switch points from `rows`.
pub fn write_chain(
    path: &Path,
    asset: &str,
    original: &Mesh,
    lods: &[(&str, &Mesh)],
    rows: &[DistanceRow],
) -> Result<ChainWritten> {
    let mut order: Vec<usize> = (0..lods.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(lods[i].1.triangle_count()));
    let names: Vec<&str> = order.iter().map(|&i| lods[i].0).collect();
    let (coverage, warnings) = coverage(rows, asset, &names);
    let mut levels: Vec<(&str, &Mesh)> = vec![(asset, original)];
    levels.extend(order.iter().map(|&i| lods[i]));
    let mut written = crate::mesh::write_gltf::write_lod_chain(&levels, &coverage, path)?;
    let mut all = warnings;
    all.append(&mut written.warnings);
    let mine: Vec<DistanceRow> = rows.iter().filter(|r| r.asset == asset).cloned().collect();
    Ok(ChainWritten {
        files: written.files,
        levels: names.iter().map(|n| n.to_string()).collect(),
        coverage,
        criterion: criterion(&mine),
        warnings: all,
    })
}

/// The imperceptibility distances of `lods` against `original` with `eval`'s defaults (the
/// default display and viewer, the FLIP and VDP criteria, the first three views of the
/// dodecahedron rig) and `look` (shading, lighting, display), for a chain made outside `eval`
/// (`lodeval simplify -o CHAIN.glb`).
pub fn measure(
    original: &Arc<Mesh>,
    lods: &[(&str, Arc<Mesh>)],
    meters_per_unit: f64,
    look: &super::config::Look,
) -> Result<Vec<DistanceRow>> {
    let mut cfg = super::config::Config::new(Vec::new());
    look.apply_to(&mut cfg.render)
        .map_err(|why| crate::error::Error::Usage(format!("the look: {why}")))?;
    cfg.render.lighting = crate::scene::Lighting::new(
        &cfg.render.environment,
        std::path::Path::new("."),
        cfg.render.environment_rotation.0 as f32,
        cfg.render.environment_intensity.0 as f32,
    )?;
    let reference = super::assets::scene_for(&cfg, original.clone());
    let cameras = cfg.render.rig.0.cameras(original, 1.0);
    let directions: Vec<glam::Vec3> = cameras.iter().take(3).map(|c| c.to_eye()).collect();
    let settings = cfg.render.settings();
    let mut rows = Vec::new();
    let originals = super::distance::OriginalProbes::new();
    for (name, lod) in lods {
        let scene = super::assets::scene_for(&cfg, lod.clone());
        let job = super::distance::DistanceJob {
            original: &reference,
            lod: &scene,
            directions: directions.clone(),
            meters_per_unit,
            simplifier_error: None,
            names: (ORIGINAL, name, lod.triangle_count()),
            switch_m: None,
            originals: Some(&originals),
        };
        rows.extend(super::distance::search(
            &job,
            &cfg.distance,
            &cfg.viewing,
            &settings,
        )?);
    }
    Ok(rows)
}

/// The asset name [`measure`]'s rows are filed under (and the finest level's node name).
pub const ORIGINAL: &str = "original";

#[cfg(test)]
mod tests {
    use super::*;

    fn row(lod: &str, criterion: &str, coverage: f64, bound: DistanceBound) -> DistanceRow {
        DistanceRow {
            asset: "a".into(),
            lod: lod.into(),
            triangles: 10,
            criterion: criterion.into(),
            imperceptible_beyond_m: 1.0,
            screen_height_fraction: 0.1,
            unreal_screen_size: 0.1,
            screen_coverage: coverage,
            pixel_error: None,
            diameter_px: 100.0,
            resolved: bound == DistanceBound::Measured,
            renderer: "cpu".into(),
            vdp_probability: None,
            vdp_jnd: None,
            bound,
        }
    }

    #[test]
    fn coverage_follows_the_vdp_distances_and_never_increases() {
        let m = DistanceBound::Measured;
        let rows = vec![
            row("l1", "flip_mean0.01", 0.9, m),
            row("l1", "vdp_p0.5", 0.2, m),
            row("l2", "flip_mean0.01", 0.5, m),
            row("l2", "vdp_p0.5", 0.05, m),
            row("l3", "vdp_p0.5", 0.08, DistanceBound::AtLeast),
        ];
        let (c, w) = coverage(&rows, "a", &["l1", "l2", "l3"]);
        // The original until l1 is invisible (0.2), l1 until l2 (0.05), l2 until l3 (0.08,
        // kept at 0.05), l3 to the end.
        assert_eq!(c, vec![0.2, 0.05, 0.05, 0.0]);
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].contains("bound"), "{w:?}");
        let (c, w) = coverage(&rows, "a", &["l1", "missing"]);
        assert_eq!(c, vec![0.2, 0.0, 0.0]);
        assert!(w[0].contains("no distance"), "{w:?}");
    }
}
