//! The rows a run produces and the CSV files that hold them (columns in the README): `metrics.csv`,
//! `summary.csv`, `distances.csv` (schemas fixed; columns are only ever added at the end), plus
//! `lods.csv`, the per-LOD facts a merge needs.
//!
//! Decisions:
//! - Every value is rounded to 7 significant digits when it is produced, and written in Rust's
//!   shortest round-trip form, so reading a CSV back gives exactly the numbers that were written,
//!   and a summary recomputed from merged shards equals the one a single machine writes.
//! - Summary statistics over views are literal: `mean`, `p95` (95th percentile, linear
//!   interpolation) and `max` of the per-view values. `worst_view` is the view with the worst value
//!   in the metric's own direction (lowest for SSIM, MS-SSIM and PSNR, highest otherwise).
//! - Rows are sorted by (asset, LOD, view, metric) in plan order before writing, never in the
//!   order work finished.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::metric::Metric;
use crate::metric::pool::percentile;

/// One image pair and metric.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MetricRow {
    /// Asset name.
    pub asset: String,
    /// LOD name.
    pub lod: String,
    /// LOD triangles.
    pub triangles: usize,
    /// View number in the rig.
    pub view: usize,
    /// The metric (its name from `metric::catalog`: `flip`, `flip_p95`, `flip_share`, `ssim`,
    /// `msssim`, `psnr`, `psnr_luminance`, `mse`, `vdp`, `vdp_jnd`).
    pub metric: Metric,
    /// Its value.
    pub value: f64,
    /// What rendered the pair: `cpu`, or `gpu: ADAPTER (DRIVER, API, TYPE)` (scores are computed
    /// on the CPU either way).
    #[serde(default)]
    pub renderer: String,
}

/// What is known about one LOD besides its scores.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LodInfo {
    /// Asset name.
    pub asset: String,
    /// LOD name.
    pub lod: String,
    /// LOD triangles.
    pub triangles: usize,
    /// The original's triangles.
    pub original_triangles: usize,
    /// Where the LOD came from (file path or generator step).
    pub source: String,
    /// The simplifier's own error estimate in model units, for generated LODs (meshoptimizer's
    /// accumulated along its chain; QEM's largest collapse error).
    pub simplifier_error: Option<f64>,
    /// The engine's switch distance from the config, metres.
    pub switch_m: Option<f64>,
    /// Symmetric Hausdorff distance to the original, model units (Metro-style sampling).
    pub hausdorff: Option<f64>,
    /// Mean surface distance to the original, model units.
    pub mean_distance: Option<f64>,
    /// RMS surface distance to the original, model units.
    pub rms_distance: Option<f64>,
    /// `hausdorff` over the original's bounding-box diagonal.
    pub hausdorff_relative: Option<f64>,
    /// `mean_distance` over the diagonal.
    pub mean_relative: Option<f64>,
}

/// One imperceptibility distance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DistanceRow {
    /// Asset name.
    pub asset: String,
    /// LOD name.
    pub lod: String,
    /// LOD triangles.
    pub triangles: usize,
    /// `vdp_p<level>` or `flip_mean<level>`.
    pub criterion: String,
    /// Nearest distance (metres, viewer to bounding-sphere centre) beyond which the LOD is
    /// imperceptible by the criterion.
    pub imperceptible_beyond_m: f64,
    /// Bounding-sphere diameter over display height at that distance (Unity's LODGroup relative
    /// screen height).
    pub screen_height_fraction: f64,
    /// Unreal Engine's `ScreenSize` at that distance.
    pub unreal_screen_size: f64,
    /// Share of the screen area the bounding sphere covers (glTF `MSFT_lod` screen coverage).
    pub screen_coverage: f64,
    /// The simplifier's error estimate projected to display pixels at that distance (as
    /// meshoptimizer-based LOD selection does), where known.
    pub pixel_error: Option<f64>,
    /// On-screen bounding-sphere diameter at that distance, display pixels.
    pub diameter_px: f64,
    /// False when the search hit a limit, so the distance is a bound: visible even at the smallest
    /// probe (4 px; the true distance is larger), or invisible up to `max_diameter_px` (the LOD may
    /// also be imperceptible nearer).
    pub resolved: bool,
    /// What rendered the search's frames (always `cpu`: the search runs on the reference renderer).
    #[serde(default)]
    pub renderer: String,
    /// The VDP's detection probability of the worst searched view at `diameter_px`.
    #[serde(default)]
    pub vdp_probability: Option<f64>,
    /// The same difference in JND (1 = the observers' detection threshold).
    #[serde(default)]
    pub vdp_jnd: Option<f64>,
    /// Whether `imperceptible_beyond_m` is a measurement or which kind of bound it is.
    #[serde(default)]
    pub bound: DistanceBound,
}

/// What an imperceptibility distance is: measured, or a bound because the search hit one of its
/// limits. Written to `distances.csv` as `measured`, `at_least` or `at_most`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DistanceBound {
    /// The search bracketed the change from visible to invisible: a measured distance.
    #[default]
    Measured,
    /// Visible even at the smallest size searched: imperceptible only farther than this (the
    /// on-screen diameter is at most the one given).
    AtLeast,
    /// Invisible even at the largest size searched: imperceptible from this distance at the
    /// latest, perhaps nearer (the diameter is at least the one given).
    AtMost,
}

impl DistanceRow {
    /// The distance in metres as a person reads it: `4.46`, `≥ 16.50` or `≤ 13.02` (a bound is
    /// never shown as a measurement).
    pub fn distance_text(&self) -> String {
        format!(
            "{}{:.2}",
            self.bound.distance_sign(),
            self.imperceptible_beyond_m
        )
    }

    /// The on-screen diameter in pixels the same way: `185`, `≤ 4` or `≥ 512`.
    pub fn diameter_text(&self) -> String {
        let sign = match self.bound {
            DistanceBound::Measured => "",
            DistanceBound::AtLeast => "≤ ",
            DistanceBound::AtMost => "≥ ",
        };
        format!("{sign}{:.0}", self.diameter_px)
    }
}

impl DistanceBound {
    /// "", "≥ " or "≤ " before a distance.
    pub fn distance_sign(self) -> &'static str {
        match self {
            DistanceBound::Measured => "",
            DistanceBound::AtLeast => "≥ ",
            DistanceBound::AtMost => "≤ ",
        }
    }
}

/// One line of `summary.csv`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SummaryRow {
    /// Asset name.
    pub asset: String,
    /// LOD name.
    pub lod: String,
    /// LOD triangles.
    pub triangles: usize,
    /// LOD triangles over the original's.
    pub triangle_ratio: f64,
    /// Metric name.
    pub metric: Metric,
    /// Mean over views.
    pub mean: f64,
    /// 95th percentile over views.
    pub p95: f64,
    /// Maximum over views.
    pub max: f64,
    /// The view with the worst value.
    pub worst_view: usize,
    /// What rendered the views (as `metrics.csv`).
    #[serde(default)]
    pub renderer: String,
}

/// Everything a run (or a merge of shards) produced.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Results {
    /// Per view and metric.
    pub rows: Vec<MetricRow>,
    /// Per LOD.
    pub lods: Vec<LodInfo>,
    /// Per LOD and criterion.
    pub distances: Vec<DistanceRow>,
}

/// One LOD's headline figures (see [`Results::headline`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Headline {
    /// FLIP mean over views.
    pub flip_mean: Option<f64>,
    /// FLIP mean of the worst view.
    pub flip_worst: Option<f64>,
    /// SSIM of the worst view.
    pub ssim_worst: Option<f64>,
    /// PSNR of the worst view.
    pub psnr_worst: Option<f64>,
    /// VDP detection probability of the worst view.
    pub vdp_worst: Option<f64>,
    /// VDP difference of the worst view, JND.
    pub vdp_jnd_worst: Option<f64>,
    /// The VDP-criterion distance row.
    pub distance: Option<DistanceRow>,
}

/// The (view, value) with the worst value — the largest if `higher_is_worse`, else the smallest;
/// the first such view on ties.
fn worst_of(
    values: impl Iterator<Item = (usize, f64)>,
    higher_is_worse: bool,
) -> Option<(usize, f64)> {
    values.fold(None, |best, (view, v)| match best {
        Some((_, b)) if (higher_is_worse && v <= b) || (!higher_is_worse && v >= b) => best,
        _ => Some((view, v)),
    })
}

/// Round to 7 significant digits (see the module comment).
pub fn round7(v: f64) -> f64 {
    if !v.is_finite() || v == 0.0 {
        return v;
    }
    format!("{v:.6e}").parse().unwrap_or(v)
}

impl Results {
    /// Sort every table into plan order: `order` lists case ids (`ASSET/LOD`) in plan order.
    pub fn sort(&mut self, order: &[String]) {
        let pos = |a: &str, l: &str| {
            order
                .iter()
                .position(|c| *c == super::plan::case_id(a, l))
                .unwrap_or(usize::MAX)
        };
        self.rows.sort_by(|x, y| {
            (pos(&x.asset, &x.lod), x.view, x.metric).cmp(&(
                pos(&y.asset, &y.lod),
                y.view,
                y.metric,
            ))
        });
        self.lods.sort_by_key(|l| pos(&l.asset, &l.lod));
        self.distances.sort_by(|x, y| {
            (pos(&x.asset, &x.lod), &x.criterion).cmp(&(pos(&y.asset, &y.lod), &y.criterion))
        });
    }

    /// Per (asset, LOD, metric) statistics over views, in row order.
    pub fn summary(&self) -> Vec<SummaryRow> {
        let mut out: Vec<SummaryRow> = Vec::new();
        type Key = (String, String, Metric, String);
        let mut groups: Vec<(Key, Vec<(usize, f64)>)> = Vec::new();
        for r in &self.rows {
            let key = (r.asset.clone(), r.lod.clone(), r.metric, r.renderer.clone());
            match groups.iter_mut().find(|(k, _)| *k == key) {
                Some((_, v)) => v.push((r.view, r.value)),
                None => groups.push((key, vec![(r.view, r.value)])),
            }
        }
        for ((asset, lod, metric, renderer), values) in groups {
            let info = self.lods.iter().find(|l| l.asset == asset && l.lod == lod);
            let (triangles, ratio) = info.map_or((0, 0.0), |l| {
                (
                    l.triangles,
                    l.triangles as f64 / l.original_triangles.max(1) as f64,
                )
            });
            let vals: Vec<f64> = values.iter().map(|v| v.1).collect();
            let worse = metric.higher_is_worse();
            let worst_view = worst_of(values.iter().copied(), worse).map_or(0, |b| b.0);
            out.push(SummaryRow {
                asset,
                lod,
                triangles,
                triangle_ratio: round7(ratio),
                metric,
                mean: round7(vals.iter().sum::<f64>() / vals.len() as f64),
                p95: round7(percentile(&vals, 95.0).expect("a group has a value")),
                max: vals.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                worst_view,
                renderer,
            });
        }
        out
    }

    /// The worst per-view value of `metric` for one LOD, in the metric's direction.
    pub fn worst(&self, asset: &str, lod: &str, metric: Metric) -> Option<(usize, f64)> {
        worst_of(
            self.rows
                .iter()
                .filter(|r| r.asset == asset && r.lod == lod && r.metric == metric)
                .map(|r| (r.view, r.value)),
            metric.higher_is_worse(),
        )
    }

    /// The headline figures of one LOD, as the summary table and the report show them.
    pub fn headline(&self, asset: &str, lod: &str) -> Headline {
        let worst = |m: Metric| self.worst(asset, lod, m).map(|w| w.1);
        Headline {
            flip_mean: self.mean(asset, lod, Metric::Flip),
            flip_worst: worst(Metric::Flip),
            ssim_worst: worst(Metric::Ssim),
            psnr_worst: worst(Metric::Psnr),
            vdp_worst: worst(Metric::Vdp),
            vdp_jnd_worst: worst(Metric::VdpJnd),
            distance: self
                .distances
                .iter()
                .find(|d| d.asset == asset && d.lod == lod && d.criterion.starts_with("vdp"))
                .cloned(),
        }
    }

    /// The mean over views of `metric` for one LOD.
    pub fn mean(&self, asset: &str, lod: &str, metric: Metric) -> Option<f64> {
        let v: Vec<f64> = self
            .rows
            .iter()
            .filter(|r| r.asset == asset && r.lod == lod && r.metric == metric)
            .map(|r| r.value)
            .collect();
        (!v.is_empty()).then(|| round7(v.iter().sum::<f64>() / v.len() as f64))
    }

    /// Write `metrics.csv`, `summary.csv`, `distances.csv` and `lods.csv` into `dir`.
    pub fn write_csvs(&self, dir: &Path) -> Result<()> {
        write_csv(&dir.join("metrics.csv"), &self.rows)?;
        write_csv(&dir.join("summary.csv"), &self.summary())?;
        write_csv(&dir.join("distances.csv"), &self.distances)?;
        write_csv(&dir.join("lods.csv"), &self.lods)
    }

    /// Read the tables a run wrote into `dir` (for `merge`).
    pub fn read_csvs(dir: &Path) -> Result<Results> {
        Ok(Results {
            rows: read_csv(&dir.join("metrics.csv"))?,
            lods: read_csv(&dir.join("lods.csv"))?,
            distances: read_csv(&dir.join("distances.csv"))?,
        })
    }
}

/// A table row type and its CSV header (the README's schema; the serde field order must match).
pub trait Columns {
    /// Column names in order.
    const COLUMNS: &'static [&'static str];
}

impl Columns for MetricRow {
    const COLUMNS: &'static [&'static str] = &[
        "asset",
        "lod",
        "triangles",
        "view",
        "metric",
        "value",
        "renderer",
    ];
}

impl Columns for SummaryRow {
    const COLUMNS: &'static [&'static str] = &[
        "asset",
        "lod",
        "triangles",
        "triangle_ratio",
        "metric",
        "mean",
        "p95",
        "max",
        "worst_view",
        "renderer",
    ];
}

impl Columns for DistanceRow {
    const COLUMNS: &'static [&'static str] = &[
        "asset",
        "lod",
        "triangles",
        "criterion",
        "imperceptible_beyond_m",
        "screen_height_fraction",
        "unreal_screen_size",
        "screen_coverage",
        "pixel_error",
        "diameter_px",
        "resolved",
        "renderer",
        "vdp_probability",
        "vdp_jnd",
        "bound",
    ];
}

impl Columns for LodInfo {
    const COLUMNS: &'static [&'static str] = &[
        "asset",
        "lod",
        "triangles",
        "original_triangles",
        "source",
        "simplifier_error",
        "switch_m",
        "hausdorff",
        "mean_distance",
        "rms_distance",
        "hausdorff_relative",
        "mean_relative",
    ];
}

/// Write rows as CSV with their schema's header (also for an empty table), atomically.
pub fn write_csv<T: Serialize + Columns>(path: &Path, rows: &[T]) -> Result<()> {
    crate::io::csv::write_rows(path, Some(T::COLUMNS), rows)
}

/// Read a CSV written by [`write_csv`].
pub fn read_csv<T: for<'de> Deserialize<'de>>(path: &Path) -> Result<Vec<T>> {
    crate::io::csv::read_rows(path, "give the output folder of an `lodeval eval` run")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(lod: &str, view: usize, metric: &str, value: f64) -> MetricRow {
        MetricRow {
            asset: "a".into(),
            lod: lod.into(),
            triangles: 10,
            view,
            metric: Metric::from_name(metric).expect("a metric name"),
            value,
            renderer: "cpu".into(),
        }
    }

    #[test]
    fn summary_statistics_and_worst_view_direction() {
        let mut r = Results::default();
        for (v, f, s) in [(0, 0.1, 0.9), (1, 0.3, 0.7), (2, 0.2, 0.95)] {
            r.rows.push(row("l", v, "flip", f));
            r.rows.push(row("l", v, "ssim", s));
        }
        let s = r.summary();
        let flip = s.iter().find(|x| x.metric == Metric::Flip).unwrap();
        assert_eq!((flip.worst_view, flip.max), (1, 0.3));
        assert!((flip.mean - 0.2).abs() < 1e-12);
        assert!((flip.p95 - 0.29).abs() < 1e-12);
        let ssim = s.iter().find(|x| x.metric == Metric::Ssim).unwrap();
        assert_eq!(ssim.worst_view, 1);
    }

    #[test]
    fn csv_round_trip_is_exact() {
        let dir = tempfile::tempdir().unwrap();
        let mut r = Results::default();
        for (i, v) in [0.1234567, 1e-9, 100.0, 42.0].iter().enumerate() {
            r.rows.push(row("l", i, "psnr", round7(*v)));
        }
        r.write_csvs(dir.path()).unwrap();
        let back = Results::read_csvs(dir.path()).unwrap();
        assert_eq!(back.rows, r.rows);
        let text = std::fs::read_to_string(dir.path().join("metrics.csv")).unwrap();
        assert!(
            text.starts_with("asset,lod,triangles,view,metric,value,renderer\n"),
            "{text}"
        );
        let d = std::fs::read_to_string(dir.path().join("distances.csv")).unwrap();
        assert!(d.starts_with(
            "asset,lod,triangles,criterion,imperceptible_beyond_m,screen_height_fraction,"
        ));
    }

    #[test]
    fn a_non_finite_value_never_reaches_a_table() {
        let dir = tempfile::tempdir().unwrap();
        let mut r = Results::default();
        r.rows.push(row("l", 0, "psnr", f64::INFINITY));
        let e = r.write_csvs(dir.path()).unwrap_err().to_string();
        assert!(
            e.contains("value = inf") && e.contains("metrics.csv"),
            "{e}"
        );
        assert!(!dir.path().join("metrics.csv").exists());
    }

    #[test]
    fn the_readme_lists_every_column_of_every_table() {
        // The README's output table: the backticked column lists of each file's row, joined.
        let readme = include_str!("../../README.md");
        let documented = |file: &str| -> String {
            let row = readme
                .lines()
                .find(|l| l.starts_with(&format!("| `{file}` |")))
                .unwrap_or_else(|| panic!("the README has no row for {file}"));
            let cell = row.splitn(3, '|').nth(2).unwrap_or("");
            let cell = cell.split(" — ").next().unwrap_or(cell);
            cell.split('`').skip(1).step_by(2).collect::<String>()
        };
        assert_eq!(documented("metrics.csv"), MetricRow::COLUMNS.join(","));
        assert_eq!(documented("summary.csv"), SummaryRow::COLUMNS.join(","));
        assert_eq!(documented("distances.csv"), DistanceRow::COLUMNS.join(","));
    }

    #[test]
    fn columns_match_serde_field_order() {
        fn header<T: Serialize + Columns>(row: T) {
            let mut w = ::csv::Writer::from_writer(Vec::new());
            w.serialize(row).unwrap();
            let text = String::from_utf8(w.into_inner().unwrap()).unwrap();
            assert_eq!(text.lines().next().unwrap(), T::COLUMNS.join(","));
        }
        header(row("l", 0, "flip", 0.1));
        header(
            Results {
                rows: vec![row("l", 0, "flip", 0.1)],
                ..Default::default()
            }
            .summary()
            .remove(0),
        );
        header(LodInfo {
            asset: "a".into(),
            lod: "l".into(),
            triangles: 1,
            original_triangles: 2,
            source: "s".into(),
            simplifier_error: None,
            switch_m: None,
            hausdorff: None,
            mean_distance: None,
            rms_distance: None,
            hausdorff_relative: None,
            mean_relative: None,
        });
        header(DistanceRow {
            asset: "a".into(),
            lod: "l".into(),
            triangles: 1,
            criterion: "c".into(),
            imperceptible_beyond_m: 1.0,
            screen_height_fraction: 0.1,
            unreal_screen_size: 0.1,
            screen_coverage: 0.1,
            pixel_error: None,
            diameter_px: 1.0,
            resolved: true,
            renderer: "cpu".into(),
            vdp_probability: Some(0.5),
            vdp_jnd: Some(0.8),
            bound: DistanceBound::Measured,
        });
    }
}
