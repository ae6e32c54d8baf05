//! `report.html`: one page per run (no scripts, no network; the contact sheets are the PNGs in
//! `sheets/` beside it, referenced relatively, so keep the output folder together). The first
//! screen answers what a user came for: below what on-screen size each LOD cannot be told from
//! its original, and what that is in each engine's own LOD parameter (the "at a glance" table),
//! after the gate's messages when it failed (assets with failures also come first below). Per asset: a table of LODs
//! (where each can replace the original, then the scores at the evaluation's close-up render size,
//! labelled as such — there every LOD is visible, which is not the question), a plot of error
//! against triangle count, and the contact sheets.
//!
//! Decision: the plot is inline SVG rather than a raster image, so its text is real text (no
//! bundled font needed), it scales, and it stays inside the one HTML file.

use std::fmt::Write;

use super::gate::Failure;
use super::plan::Plan;
use super::tables::{DistanceRow, Results};
use crate::metric::Metric;

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn num(v: Option<f64>, digits: usize) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x:.digits$}"),
        Some(x) if x > 0.0 => "∞".into(),
        _ => "–".into(),
    }
}

/// The report's HTML.
pub fn render(plan: &Plan, results: &Results, failures: &[Failure]) -> String {
    let mut h = String::new();
    let title = format!("lodeval report — {}", plan.config_path.display());
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title>\n<style>{}</style></head><body>\n<h1>{}</h1>\n",
        esc(&title),
        CSS,
        esc(&title)
    );
    let mut renderers: Vec<&str> = results.rows.iter().map(|r| r.renderer.as_str()).collect();
    renderers.dedup();
    renderers.sort_unstable();
    renderers.dedup();
    let _ = writeln!(
        h,
        "<p class=\"renderer\">Rendered on: {}</p>",
        esc(&renderers.join("; "))
    );
    let cases = results.lods.len();
    let failing: std::collections::BTreeSet<(&str, &str)> = failures
        .iter()
        .map(|f| (f.asset.as_str(), f.lod.as_str()))
        .collect();
    let _ = writeln!(
        h,
        "<p class=\"{}\"><b>{}</b>: {} of {cases} LODs pass the gate. {} views per LOD at {}×{}, {} samples per pixel, {} shading, {:.2} pixels per degree.</p>",
        if failures.is_empty() { "pass" } else { "fail" },
        if failures.is_empty() { "PASS" } else { "FAIL" },
        cases - failing.len(),
        plan.config.render.rig.0.directions().len(),
        plan.config.render.size.0,
        plan.config.render.size.0,
        plan.config.render.samples.0,
        plan.config.render.shading.0.name(),
        plan.config.viewing.viewing().ppd()
    );
    // A failing gate's messages come first (short, and what a CI run is opened for); then what
    // everyone came for.
    if !failures.is_empty() {
        h.push_str("<h2>Failures</h2>\n<ul class=\"failures\">\n");
        for f in failures {
            let _ = writeln!(h, "<li>{}</li>", esc(&f.message));
        }
        h.push_str("</ul>\n");
    }
    h.push_str(&at_a_glance(plan, results));
    // Assets with failures first, then config order.
    let mut assets: Vec<&super::plan::AssetPlan> = plan
        .assets
        .iter()
        .filter(|a| results.lods.iter().any(|l| l.asset == a.name))
        .collect();
    assets.sort_by_key(|a| !failures.iter().any(|f| f.asset == a.name));
    for asset in assets {
        let lods: Vec<_> = results
            .lods
            .iter()
            .filter(|l| l.asset == asset.name)
            .collect();
        let original = lods.first().map_or(0, |l| l.original_triangles);
        let _ = writeln!(
            h,
            "<h2 id=\"{0}\">{0}</h2>\n<p>Original: <code>{1}</code>, {original} triangles.</p>",
            esc(&asset.name),
            esc(&asset.mesh.display().to_string())
        );
        h.push_str(&lod_table(plan, results, &lods, &failing));
        h.push_str(&plot(results, &asset.name, original));
        h.push_str("<div class=\"sheets\">\n");
        for l in &lods {
            let src = format!("sheets/{}/{}.png", asset.name, l.lod);
            let _ = writeln!(
                h,
                "<figure><img src=\"{}\" alt=\"contact sheet {}\" loading=\"lazy\"><figcaption>{} — original | LOD | heat map, worst views first</figcaption></figure>",
                esc(&src),
                esc(&l.lod),
                esc(&l.lod)
            );
        }
        h.push_str("</div>\n");
    }
    h.push_str("</body></html>\n");
    h
}

/// The first screen: per LOD, below what on-screen size (and beyond what distance) it cannot be
/// told from its original by the VDP, and that point in Unity's, Unreal's and glTF's terms.
fn at_a_glance(plan: &Plan, results: &Results) -> String {
    if results.distances.is_empty() {
        return String::new();
    }
    let viewing = &plan.config.viewing;
    let mut h = format!(
        "<h2>At a glance: where each LOD can replace the original</h2>\n<p class=\"lead\">A LOD \
         cannot be told from its original (the VDP's detection probability ≤ {}) while the object \
         is <b>smaller on screen</b> than the size given — its bounding sphere's diameter in pixels \
         of a {:.0} × {:.0} display — or <b>farther</b> than the distance. Switch to it there: the \
         engine columns are that point in each engine's own LOD parameter, computed from the bound \
         that engine uses (type them in as they are). ≥/≤ mark a bound of the search, not a \
         measurement.</p>\n",
        plan.config.distance.probability.0, viewing.display_px.0, viewing.display_height_px.0
    );
    h.push_str(
        "<table class=\"glance\"><tr><th>asset</th><th>LOD</th><th>triangles</th>\
         <th>imperceptible below (px on screen)</th><th>imperceptible beyond (m)</th>\
         <th>Unity relative screen height</th><th>Unreal ScreenSize</th>\
         <th>glTF MSFT_screencoverage</th></tr>\n",
    );
    for l in &results.lods {
        let Some(d) = results.headline(&l.asset, &l.lod).distance else {
            continue;
        };
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td><b>{}</b></td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            esc(&l.asset),
            esc(&l.lod),
            l.triangles,
            esc(&d.diameter_text()),
            esc(&d.distance_text()),
            num(Some(d.screen_height_fraction), 4),
            num(Some(d.unreal_screen_size), 4),
            num(Some(d.screen_coverage), 6)
        );
    }
    h.push_str("</table>\n");
    h
}

/// One asset's table of LODs: where each can replace the original, then its scores at the
/// evaluation's render size (labelled with it).
fn lod_table(
    plan: &Plan,
    results: &Results,
    lods: &[&super::tables::LodInfo],
    failing: &std::collections::BTreeSet<(&str, &str)>,
) -> String {
    let size = plan.config.render.size.0;
    let mut h = format!(
        "<table><tr><th colspan=\"3\"></th><th colspan=\"4\">where it can replace the original \
         (VDP)</th><th colspan=\"6\">scores at the {size} × {size} px close-up render (the object \
         fills the frame; every LOD is visible this close)</th><th></th></tr>\n<tr><th>LOD</th>\
         <th>triangles</th><th>ratio</th><th>imperceptible below (px on screen)</th>\
         <th>imperceptible beyond (m)</th><th>Unity relative screen height</th>\
         <th>engine switch (m)</th><th>FLIP mean</th><th>FLIP worst view</th><th>SSIM worst</th>\
         <th>PSNR worst (dB)</th><th>VDP p worst at {size} px</th><th>VDP JND worst at {size} px</th>\
         <th>gate</th></tr>\n"
    );
    for l in lods {
        let hl = results.headline(&l.asset, &l.lod);
        let dist: Option<&DistanceRow> = hl.distance.as_ref();
        let bad = failing.contains(&(l.asset.as_str(), l.lod.as_str()));
        let _ = writeln!(
            h,
            "<tr class=\"{}\"><td>{}</td><td>{}</td><td>{:.4}</td><td><b>{}</b></td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            if bad { "fail" } else { "pass" },
            esc(&l.lod),
            l.triangles,
            l.triangles as f64 / l.original_triangles.max(1) as f64,
            dist.map_or_else(|| "–".to_string(), |d| esc(&d.diameter_text())),
            dist.map_or_else(|| "–".to_string(), |d| esc(&d.distance_text())),
            num(dist.map(|d| d.screen_height_fraction), 4),
            num(l.switch_m, 2),
            num(hl.flip_mean, 4),
            num(hl.flip_worst, 4),
            num(hl.ssim_worst, 4),
            num(hl.psnr_worst, 2),
            num(hl.vdp_worst, 3),
            num(hl.vdp_jnd_worst, 2),
            if bad { "FAIL" } else { "pass" }
        );
    }
    h.push_str("</table>\n");
    h
}

/// Inline SVG: FLIP mean (or the first metric) over views against triangle count, log x axis.
fn plot(results: &Results, asset: &str, original: usize) -> String {
    let metric = Metric::LEADING
        .into_iter()
        .find(|m| {
            results
                .rows
                .iter()
                .any(|r| r.asset == asset && r.metric == *m)
        })
        .unwrap_or(Metric::Flip);
    let mut pts: Vec<(f64, f64)> = results
        .lods
        .iter()
        .filter(|l| l.asset == asset)
        .filter_map(|l| Some((l.triangles as f64, results.mean(asset, &l.lod, metric)?)))
        .filter(|p| p.1.is_finite() && p.0 > 0.0)
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    if pts.is_empty() {
        return String::new();
    }
    let (w, h, ml, mr, mt, mb) = (560.0, 320.0, 70.0, 20.0, 20.0, 50.0);
    let x_lo = pts[0].0.log10().floor();
    let x_hi = (original.max(1) as f64)
        .log10()
        .max(pts[pts.len() - 1].0.log10())
        .ceil();
    let x_hi = if x_hi <= x_lo { x_lo + 1.0 } else { x_hi };
    let y_max = pts.iter().map(|p| p.1).fold(0.0f64, f64::max);
    let y_min = pts.iter().map(|p| p.1).fold(0.0f64, f64::min);
    let y_max = if y_max <= y_min {
        y_min + 1.0
    } else {
        y_max * 1.1
    };
    let px = |x: f64| ml + (x.log10() - x_lo) / (x_hi - x_lo) * (w - ml - mr);
    let py = |y: f64| h - mb - (y - y_min) / (y_max - y_min) * (h - mt - mb);
    let mut s = String::new();
    let _ = write!(
        s,
        "<svg class=\"plot\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" role=\"img\" aria-label=\"{metric} against triangle count\">\n<rect x=\"{ml}\" y=\"{mt}\" width=\"{}\" height=\"{}\" fill=\"#fff\" stroke=\"#888\"/>\n",
        w - ml - mr,
        h - mt - mb
    );
    for e in (x_lo as i32)..=(x_hi as i32) {
        let x = px(10f64.powi(e));
        let _ = writeln!(
            s,
            "<line x1=\"{x:.1}\" y1=\"{mt}\" x2=\"{x:.1}\" y2=\"{:.1}\" stroke=\"#ddd\"/><text x=\"{x:.1}\" y=\"{:.1}\" text-anchor=\"middle\">10^{e}</text>",
            h - mb,
            h - mb + 18.0
        );
    }
    for k in 0..=4 {
        let y = y_min + (y_max - y_min) * k as f64 / 4.0;
        let _ = writeln!(
            s,
            "<line x1=\"{ml}\" y1=\"{0:.1}\" x2=\"{1}\" y2=\"{0:.1}\" stroke=\"#ddd\"/><text x=\"{2}\" y=\"{3:.1}\" text-anchor=\"end\">{y:.4}</text>",
            py(y),
            w - mr,
            ml - 6.0,
            py(y) + 4.0
        );
    }
    let path: Vec<String> = pts
        .iter()
        .map(|p| format!("{:.1},{:.1}", px(p.0), py(p.1)))
        .collect();
    let _ = writeln!(
        s,
        "<polyline points=\"{}\" fill=\"none\" stroke=\"#b5367a\" stroke-width=\"2\"/>",
        path.join(" ")
    );
    for p in &pts {
        let _ = writeln!(
            s,
            "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"4\" fill=\"#b5367a\"><title>{} triangles: {}</title></circle>",
            px(p.0),
            py(p.1),
            p.0,
            p.1
        );
    }
    let _ = writeln!(
        s,
        "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">triangles (log scale)</text><text x=\"14\" y=\"{:.1}\" transform=\"rotate(-90 14 {:.1})\" text-anchor=\"middle\">{metric} (mean over views)</text></svg>",
        (ml + w - mr) / 2.0,
        h - 8.0,
        h / 2.0,
        h / 2.0
    );
    s
}

const CSS: &str = "body{font-family:system-ui,sans-serif;margin:2em;max-width:1400px;color:#222}\
table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:4px 8px;text-align:right}\
th{background:#eee}td:first-child{text-align:left}tr.fail td{background:#fde2e2}\
p.fail{color:#a00}p.pass{color:#070}ul.failures li{color:#a00;font-family:monospace}\
.sheets{display:flex;flex-wrap:wrap;gap:1em}figure{margin:0}figure img{max-width:400px;display:block}\
svg.plot text{font-size:12px;fill:#333}p.lead{max-width:60em}table.glance td:nth-child(2){text-align:left}td{white-space:nowrap}";
