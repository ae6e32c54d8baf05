//! `golden/report.html`: what `lodeval golden` found, as a page a person reviews before blessing —
//! the mismatches first, each as expected | actual | FLIP diff, with a slider that wipes between
//! expected and actual over the same pixels (Playwright's image viewer does the same), then the
//! blessed images and a count of the matches. Self-contained: the images are embedded as PNG data
//! URIs, so the file can be kept as one CI artefact.

use std::fmt::Write as _;
use std::path::Path;

use base64::Engine as _;

use super::{GoldenOutcome, GoldenStatus};
use crate::error::Result;

/// A PNG file as a data URI (an empty string when it cannot be read: the cell says so).
fn data_uri(path: &Path) -> String {
    std::fs::read(path)
        .map(|b| {
            format!(
                "data:image/png;base64,{}",
                base64::engine::general_purpose::STANDARD.encode(b)
            )
        })
        .unwrap_or_default()
}

/// Text escaped for HTML.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

const STYLE: &str = "body{font-family:sans-serif;margin:24px;background:#fafafa;color:#222}\
table{border-collapse:collapse;margin:12px 0}td,th{padding:6px 10px;vertical-align:top;text-align:left}\
tr.fail td{background:#fde2e2}tr.fail td.name{border-left:6px solid #c0392b}\
tr.blessed td{background:#e2f0fd}img{image-rendering:pixelated;display:block;width:256px;height:auto}\
.wipe{position:relative;display:inline-block}.wipe img.top{position:absolute;left:0;top:0}\
.cap{font-size:12px;color:#555}code{background:#eee;padding:1px 4px}";

const SCRIPT: &str = "function wipe(r){var t=r.parentNode.querySelector('img.top');\
t.style.clipPath='inset(0 '+(100-r.value)+'% 0 0)';}";

/// The report for `outcome` of the run of `config`.
pub fn render(config: &Path, outcome: &GoldenOutcome) -> Result<String> {
    let failed: Vec<_> = outcome
        .images
        .iter()
        .filter(|i| matches!(i.status, GoldenStatus::Mismatch { .. }))
        .collect();
    let blessed = outcome
        .images
        .iter()
        .filter(|i| matches!(i.status, GoldenStatus::Blessed))
        .count();
    let missing = outcome.missing;
    let matched = outcome.images.len() - failed.len() - blessed - missing;
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>lodeval golden: {}</title>\
         <style>{STYLE}</style><script>{SCRIPT}</script></head><body>\
         <h1>Golden images: {}</h1><p><b>{}</b> of {} image(s) differ, {} match, {} blessed, \
         {} missing.</p>",
        esc(&config.display().to_string()),
        esc(&config.display().to_string()),
        failed.len(),
        outcome.images.len(),
        matched,
        blessed,
        missing
    );
    if missing > 0 {
        let _ = write!(
            h,
            "<h2>Missing</h2><p>{missing} image(s) have no golden yet (nothing was written for \
             them). To make them, run <code>lodeval golden {} --bless</code>.</p>",
            esc(&config.display().to_string())
        );
    }
    if !failed.is_empty() {
        let _ = write!(
            h,
            "<h2>Mismatches</h2><p class=\"cap\">Drag the slider to wipe from the expected image \
             (left) to the actual render (right). To accept one, run <code>lodeval golden {} \
             --bless ASSET/LOD/VIEW</code>.</p><table><tr><th>image</th><th>expected</th>\
             <th>actual</th><th>FLIP diff</th><th>expected ⇄ actual</th></tr>",
            esc(&config.display().to_string())
        );
        for i in &failed {
            let GoldenStatus::Mismatch { why, actual, diff } = &i.status else {
                continue;
            };
            let (e, a) = (data_uri(&i.golden), data_uri(actual));
            let d = diff.as_deref().map(data_uri).unwrap_or_default();
            let img = |uri: &str, what: &str| {
                if uri.is_empty() {
                    format!("<span class=\"cap\">no {what}</span>")
                } else {
                    format!("<img src=\"{uri}\" alt=\"{what}\">")
                }
            };
            let wipe = if e.is_empty() || a.is_empty() {
                "<span class=\"cap\">—</span>".to_string()
            } else {
                format!(
                    "<div class=\"wipe\"><img src=\"{a}\" alt=\"actual\"><img class=\"top\" \
                     src=\"{e}\" alt=\"expected\" style=\"clip-path:inset(0 50% 0 0)\">\
                     <input type=\"range\" min=\"0\" max=\"100\" value=\"50\" oninput=\"wipe(this)\" \
                     style=\"width:100%\"></div>"
                )
            };
            let _ = write!(
                h,
                "<tr class=\"fail\"><td class=\"name\"><b>{}/{}/view {}</b><br><span class=\"cap\">\
                 {}</span></td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                esc(&i.asset),
                esc(&i.lod),
                i.view,
                esc(why),
                img(&e, "golden"),
                img(&a, "actual render"),
                img(&d, "diff (sizes differ)"),
                wipe
            );
        }
        h.push_str("</table>");
    }
    if blessed > 0 {
        h.push_str("<h2>Blessed</h2><table>");
        for i in outcome
            .images
            .iter()
            .filter(|i| matches!(i.status, GoldenStatus::Blessed))
        {
            let _ = write!(
                h,
                "<tr class=\"blessed\"><td>{}/{}/view {}</td><td><img src=\"{}\" alt=\"new golden\">\
                 </td></tr>",
                esc(&i.asset),
                esc(&i.lod),
                i.view,
                data_uri(&i.golden)
            );
        }
        h.push_str("</table>");
    }
    let _ = write!(
        h,
        "<h2>Matches</h2><p class=\"cap\">{matched} image(s) within tolerance.</p></body></html>"
    );
    Ok(h)
}
