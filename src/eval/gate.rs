//! The CI gate: thresholds (layered global → asset → LOD, see `plan.rs`), engine switch distances,
//! and a baseline `summary.csv` with a relative tolerance. Any failure makes `eval` exit 1, with
//! one line per failing asset/LOD/check giving the value, the limit and where the limit was set.
//!
//! Threshold semantics (all per LOD): `flip_mean` bounds the FLIP mean averaged over views; every
//! other threshold bounds the worst view (`flip_worst_view`, `flip_p95`, `flip_share`,
//! `vdp_probability` from above; `psnr_min`, `ssim_min`, `msssim_min` from below). A baseline
//! regression is a summary mean worse than the baseline's by more than
//! `tolerance · |baseline| + absolute`, in the metric's own direction.

use std::path::Path;

use super::config::{Statistic, ThresholdKey, config_dir};
use super::plan::Plan;
use super::tables::{DistanceBound, DistanceRow, Results, SummaryRow, read_csv};
use crate::error::{Error, Location, Result};
use crate::metric::Metric;

/// One failed check.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    /// Asset name.
    pub asset: String,
    /// LOD name.
    pub lod: String,
    /// The check (threshold name, `switch_m` or `baseline:METRIC`).
    pub check: String,
    /// The whole message.
    pub message: String,
}

/// Evaluate every check of `plan` against `results`.
pub fn check(plan: &Plan, results: &Results) -> Result<Vec<Failure>> {
    let mut failures = Vec::new();
    let computed = |metric: Metric| results.rows.iter().any(|r| r.metric == metric);
    for asset in &plan.assets {
        for lod in &asset.lods {
            if !results
                .lods
                .iter()
                .any(|l| l.asset == asset.name && l.lod == lod.name)
            {
                continue; // another shard's case
            }
            let mut fail = |check: &str, message: String| {
                failures.push(Failure {
                    asset: asset.name.clone(),
                    lod: lod.name.clone(),
                    check: check.to_string(),
                    message: format!("FAIL {}/{} {check}: {message}", asset.name, lod.name),
                })
            };
            for limit in &lod.limits {
                let key = ThresholdKey::of(limit.name);
                let (metric, upper) = (key.metric, key.upper());
                if !computed(metric) {
                    return Err(Error::input(
                        &plan.config_path,
                        format!(
                            "threshold {} (set in {}) needs the metric '{metric}', which the config does not compute",
                            limit.name, limit.origin
                        ),
                        "add its family to `metrics` or remove the threshold",
                    ));
                }
                let (value, where_) = if key.statistic == Statistic::WorstView {
                    match results.worst(&asset.name, &lod.name, metric) {
                        Some((v, x)) => (x, format!(" (view {v})")),
                        None => continue,
                    }
                } else {
                    match results.mean(&asset.name, &lod.name, metric) {
                        Some(x) => (x, " (mean over views)".to_string()),
                        None => continue,
                    }
                };
                let bad = if upper {
                    value > limit.value
                } else {
                    value < limit.value
                };
                if bad {
                    let op = if upper { ">" } else { "<" };
                    fail(
                        limit.name,
                        format!(
                            "{metric} = {value}{where_} {op} {} (limit from {})",
                            limit.value, limit.origin
                        ),
                    );
                }
            }
            if let Some(switch) = lod.switch_m {
                let row = results.distances.iter().find(|d| {
                    d.asset == asset.name && d.lod == lod.name && d.criterion.starts_with("vdp")
                });
                let Some(row) = row else {
                    return Err(Error::input(
                        &plan.config_path,
                        format!(
                            "asset '{}' LOD '{}' has switch_m but distances are disabled",
                            asset.name, lod.name
                        ),
                        "set [distance] enabled = true or remove switch_m",
                    ));
                };
                if let Some(why) = switch_verdict(&lod.name, switch, row) {
                    fail("switch_m", why);
                }
            }
        }
    }
    if let Some(baseline) = &plan.config.gate.baseline {
        let path = super::config::resolve(&config_dir(&plan.config_path), baseline);
        failures.extend(against_baseline(
            &path,
            &results.summary(),
            plan.config.gate.tolerance.unwrap_or(0.1),
            plan.config.gate.absolute.unwrap_or(1e-4),
        )?);
    }
    Ok(failures)
}

/// A baseline `summary.csv` that can judge a run: at least one row, every mean a finite number.
/// Anything else is an input error (exit 2), never a gate that passes because nothing was
/// compared.
pub fn read_baseline(path: &Path) -> Result<Vec<SummaryRow>> {
    const FIX: &str = "point [gate] baseline at the summary.csv of an earlier run of this config";
    let base: Vec<SummaryRow> = read_csv(path)?;
    if base.is_empty() {
        return Err(Error::input(
            path,
            "the baseline holds no rows (an empty file or a header only), so it cannot judge a run",
            FIX,
        ));
    }
    if let Some(i) = base.iter().position(|b| !b.mean.is_finite()) {
        return Err(Error::input_at(
            path,
            Location::Line(i + 2),
            format!(
                "the baseline's mean for {}/{} {} is not a finite number",
                base[i].asset, base[i].lod, base[i].metric
            ),
            FIX,
        ));
    }
    Ok(base)
}

/// The baseline of `plan`, if it has one, checked before the first render: readable, usable
/// ([`read_baseline`]), and holding rows for at least one of the plan's assets (a baseline of
/// another config compares nothing).
pub fn check_baseline(plan: &Plan) -> Result<()> {
    let Some(baseline) = &plan.config.gate.baseline else {
        return Ok(());
    };
    let path = super::config::resolve(&config_dir(&plan.config_path), baseline);
    let base = read_baseline(&path)?;
    if !base
        .iter()
        .any(|b| plan.assets.iter().any(|a| a.name == b.asset))
    {
        let mut theirs: Vec<&str> = base.iter().map(|b| b.asset.as_str()).collect();
        theirs.dedup();
        return Err(Error::input(
            &path,
            format!(
                "the baseline has no rows for any asset of {} (it has rows for: {})",
                plan.config_path.display(),
                theirs.join(", ")
            ),
            "point [gate] baseline at the summary.csv of an earlier run of this config",
        ));
    }
    Ok(())
}

/// Compare summary means with a baseline `summary.csv`: a mean worse than the baseline's beyond
/// the tolerance, a mean that is not a number, and a LOD or metric the baseline lacks all fail.
pub fn against_baseline(
    path: &Path,
    current: &[SummaryRow],
    tolerance: f64,
    absolute: f64,
) -> Result<Vec<Failure>> {
    let base = read_baseline(path)?;
    let mut out = Vec::new();
    let mut missing_lods: Vec<(&str, &str)> = Vec::new();
    for row in current {
        let key = (row.asset.as_str(), row.lod.as_str());
        if !base.iter().any(|b| b.asset == key.0 && b.lod == key.1) {
            // A LOD the baseline has never seen is reported once, not passed.
            if !missing_lods.contains(&key) {
                missing_lods.push(key);
                out.push(Failure {
                    asset: row.asset.clone(),
                    lod: row.lod.clone(),
                    check: "baseline".into(),
                    message: format!(
                        "FAIL {}/{} baseline: the LOD is not in the baseline {}, so nothing was \
                         compared; if it is new, make this run's summary.csv the baseline",
                        row.asset,
                        row.lod,
                        path.display()
                    ),
                });
            }
            continue;
        }
        let check = format!("baseline:{}", row.metric);
        let Some(b) = base
            .iter()
            .find(|b| b.asset == row.asset && b.lod == row.lod && b.metric == row.metric)
        else {
            out.push(Failure {
                asset: row.asset.clone(),
                lod: row.lod.clone(),
                message: format!(
                    "FAIL {}/{} {check}: the baseline {} has this LOD but not the metric; make \
                     this run's summary.csv the baseline if the metric is new",
                    row.asset,
                    row.lod,
                    path.display()
                ),
                check,
            });
            continue;
        };
        let slack = tolerance * b.mean.abs() + absolute;
        let worse = if row.metric.higher_is_worse() {
            row.mean > b.mean + slack
        } else {
            row.mean < b.mean - slack
        };
        if worse || !row.mean.is_finite() {
            let check = format!("baseline:{}", row.metric);
            out.push(Failure {
                asset: row.asset.clone(),
                lod: row.lod.clone(),
                message: format!(
                    "FAIL {}/{} {check}: mean {} is worse than the baseline's {} by more than {} % + {} (baseline {})",
                    row.asset,
                    row.lod,
                    row.mean,
                    b.mean,
                    tolerance * 100.0,
                    absolute,
                    path.display()
                ),
                check,
            });
        }
    }
    Ok(out)
}

/// Why a LOD used from `switch` metres fails the switch check, if it does. The distance search
/// covers the LOD's on-screen size at `switch` (`distance.rs`), so a bound decides the check too,
/// and the message says which bound it is: a search limit is never reported as a measured
/// distance.
fn switch_verdict(lod: &str, switch: f64, row: &DistanceRow) -> Option<String> {
    let d = row.imperceptible_beyond_m;
    let criterion = &row.criterion;
    match row.bound {
        DistanceBound::Measured => (d > switch).then(|| {
            format!("{lod} is used from {switch} m but is visible until {d:.2} m ({criterion})")
        }),
        DistanceBound::AtLeast => Some(format!(
            "{lod} is used from {switch} m but is visible even at {:.0} px across, the smallest \
             size searched ({criterion}): it stays visible at least until {d:.2} m",
            row.diameter_px
        )),
        DistanceBound::AtMost if d <= switch => None,
        DistanceBound::AtMost => Some(format!(
            "{lod} is used from {switch} m, where the object is larger than the display's height; \
             the search went up to {:.0} px across ({d:.2} m), where the LOD is invisible \
             ({criterion}), and cannot check nearer: set switch_m to {d:.2} m or more",
            row.diameter_px
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(d: f64, px: f64, bound: DistanceBound) -> DistanceRow {
        DistanceRow {
            asset: "a".into(),
            lod: "l".into(),
            triangles: 1,
            criterion: "vdp_p0.5".into(),
            imperceptible_beyond_m: d,
            screen_height_fraction: 0.1,
            unreal_screen_size: 0.1,
            screen_coverage: 0.01,
            pixel_error: None,
            diameter_px: px,
            resolved: bound == DistanceBound::Measured,
            renderer: "cpu".into(),
            vdp_probability: Some(0.0),
            vdp_jnd: Some(0.0),
            bound,
        }
    }

    #[test]
    fn a_bound_decides_the_switch_check_and_is_named_as_one() {
        use DistanceBound::*;
        // Measured: fails only when visible beyond the switch distance.
        assert!(switch_verdict("l", 8.0, &row(6.4, 120.0, Measured)).is_none());
        let m = switch_verdict("l", 8.0, &row(10.7, 70.0, Measured)).unwrap();
        assert!(m.contains("visible until 10.70 m"), "{m}");
        // Invisible at the largest size searched, which took in the switch distance: passes
        // (an identical LOD used to fail here with the search limit as a "measured" distance).
        assert!(switch_verdict("l", 8.0, &row(8.0, 96.0, AtMost)).is_none());
        assert!(switch_verdict("l", 20.0, &row(13.02, 512.0, AtMost)).is_none());
        // The switch distance lay beyond the search (larger than the display): cannot check.
        let m = switch_verdict("l", 0.2, &row(0.9, 2160.0, AtMost)).unwrap();
        assert!(
            m.contains("cannot check") && !m.contains("visible until"),
            "{m}"
        );
        // Visible even at the smallest size: a lower bound, said as one.
        let m = switch_verdict("l", 50.0, &row(60.0, 1.0, AtLeast)).unwrap();
        assert!(m.contains("at least until 60.00 m"), "{m}");
    }
}
