//! `plots/*.png`: the pictures of an `eval` run for people who will not open `report.html`
//! (a terminal, a CI artefact list). Per asset:
//!
//! - `ASSET-METRIC.png` for each of FLIP, VDP, SSIM, PSNR and MS-SSIM the run computed: the mean
//!   over views (solid) and the worst view (dashed) against triangles on a log axis, each point
//!   named by its LOD, the original's triangle count upright, and the gate's limits on that metric
//!   across (with the statistic they bound);
//! - `ASSET-distances.png` when distances were searched: the on-screen diameter (pixels) beyond
//!   which each LOD is imperceptible, per criterion, each point labelled with its LOD, pixels and
//!   metres; a bound carries `≤`/`≥` instead of passing for a measurement.
//!
//! Drawing is `io::plot_png`'s; this file only chooses what goes on each chart.

use std::path::Path;

use super::config::ThresholdKey;
use super::plan::Plan;
use super::tables::{DistanceBound, Results};
use crate::error::Result;
use crate::io::plot_png::{self, Chart, Line, Mark, PointBound};
use crate::metric::Metric;

/// The metrics plotted, in this order, each with its catalogue title.
const PLOTTED: [Metric; 5] = Metric::LEADING;

/// Write every plot of `results` into `dir/plots/`.
pub fn write(plan: &Plan, results: &Results, dir: &Path) -> Result<()> {
    for asset in &plan.assets {
        let lods: Vec<_> = results
            .lods
            .iter()
            .filter(|l| l.asset == asset.name)
            .collect();
        let Some(first) = lods.first() else {
            continue; // another shard's asset
        };
        let original = Mark {
            at: first.original_triangles as f64,
            label: format!("original {}", first.original_triangles),
        };
        for metric in PLOTTED {
            let title = metric.entry().title;
            if !results
                .rows
                .iter()
                .any(|r| r.asset == asset.name && r.metric == metric)
            {
                continue;
            }
            let mut mean = Line {
                name: "mean over views".into(),
                ..Line::default()
            };
            let mut worst = Line {
                name: "worst view".into(),
                dashed: true,
                ..Line::default()
            };
            for l in &lods {
                let x = l.triangles as f64;
                if let Some(m) = results.mean(&asset.name, &l.lod, metric) {
                    mean.points.push((x, m));
                    mean.labels.push(l.lod.clone());
                }
                if let Some((_, w)) = results.worst(&asset.name, &l.lod, metric) {
                    worst.points.push((x, w));
                }
            }
            let mut h_marks: Vec<Mark> = Vec::new();
            for lod in &asset.lods {
                for limit in &lod.limits {
                    let key = ThresholdKey::of(limit.name);
                    if key.metric != metric {
                        continue;
                    }
                    let label = format!("gate: {} limit {}", key.statistic.label(), limit.value);
                    if !h_marks.iter().any(|m| m.label == label) {
                        h_marks.push(Mark {
                            at: limit.value,
                            label,
                        });
                    }
                }
            }
            let chart = Chart {
                title: format!("{} — {title} against triangles", asset.name),
                subtitle: view_conditions(plan),
                x_label: "triangles (log scale)".into(),
                y_label: title.into(),
                lines: vec![mean, worst],
                log_x: true,
                h_marks,
                v_marks: vec![original.clone()],
                tight_y: metric == Metric::Psnr,
            };
            plot_png::write(
                &dir.join("plots")
                    .join(format!("{}-{metric}.png", asset.name)),
                &chart,
            )?;
        }
        distance_chart(plan, results, &asset.name, original, dir)?;
    }
    Ok(())
}

/// `ASSET-distances.png`, when distances were searched: the on-screen diameter (pixels) beyond
/// which each LOD is imperceptible, one line per criterion.
fn distance_chart(
    plan: &Plan,
    results: &Results,
    asset: &str,
    original: Mark,
    dir: &Path,
) -> Result<()> {
    let mut criteria: Vec<&str> = Vec::new();
    for d in results.distances.iter().filter(|d| d.asset == asset) {
        if !criteria.contains(&d.criterion.as_str()) {
            criteria.push(&d.criterion);
        }
    }
    if criteria.is_empty() {
        return Ok(());
    }
    let lines = criteria
        .iter()
        .map(|c| {
            let mut line = Line {
                name: c.to_string(),
                ..Line::default()
            };
            for d in results
                .distances
                .iter()
                .filter(|d| d.asset == asset && d.criterion == *c)
            {
                line.points.push((d.triangles as f64, d.diameter_px));
                // The diameter's bound runs opposite to the distance's.
                line.bounds.push(match d.bound {
                    DistanceBound::Measured => PointBound::Measured,
                    DistanceBound::AtLeast => PointBound::AtMost,
                    DistanceBound::AtMost => PointBound::AtLeast,
                });
                line.labels.push(format!(
                    "{} {} px · {} m",
                    d.lod,
                    d.diameter_text(),
                    d.distance_text()
                ));
            }
            line
        })
        .collect();
    let chart = Chart {
        title: format!("{} — below what size each LOD is imperceptible", asset),
        subtitle: format!(
            "{}; the LOD can replace the original at this on-screen size and below (higher is \
             better)",
            view_conditions(plan)
        ),
        x_label: "triangles (log scale)".into(),
        y_label: "imperceptible below, px on screen".into(),
        lines,
        log_x: true,
        h_marks: Vec::new(),
        v_marks: vec![original],
        tight_y: false,
    };
    plot_png::write(
        &dir.join("plots").join(format!("{asset}-distances.png")),
        &chart,
    )
}

fn view_conditions(plan: &Plan) -> String {
    let r = &plan.config.render;
    format!(
        "{} views at {}×{}, {:.1} pixels per degree",
        r.rig.0.directions().len(),
        r.size.0,
        r.size.0,
        plan.config.viewing.viewing().ppd()
    )
}
