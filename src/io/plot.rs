//! SVG line plots for the paper experiments (energy against evaluations, error against budget):
//! a linear y axis from zero, a linear x axis from zero or a logarithmic one (ticks at the data's x
//! values), one colour per series (pairs of solid and dashed series share one when
//! any series is dashed), a legend on the right.

use std::fmt::Write as _;

/// A plotted series: name, points, dashed.
pub type Series = (String, Vec<(f64, f64)>, bool);

pub(crate) const COLORS: [&str; 8] = [
    "#1b9e77", "#d95f02", "#7570b3", "#e7298a", "#66a61e", "#e6ab02", "#a6761d", "#666666",
];

/// A line plot: series of (name, points, dashed); `log_x` for a logarithmic x axis (positive x
/// only).
pub fn line_plot(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    log_x: bool,
) -> String {
    let (w, h, ml, mr, mt, mb) = (720.0, 420.0, 80.0, 220.0, 40.0, 50.0);
    let all = series.iter().flat_map(|s| s.1.iter());
    let x_max = all.clone().map(|p| p.0).fold(0.0f64, f64::max).max(1e-12) * 1.05;
    let x_min = all
        .clone()
        .map(|p| p.0)
        .filter(|&x| x > 0.0)
        .fold(f64::INFINITY, f64::min)
        .min(x_max / 1.05)
        / 1.05;
    let y_max = all.clone().map(|p| p.1).fold(0.0f64, f64::max).max(1e-12) * 1.1;
    let px = |x: f64| {
        let t = if log_x {
            (x.max(x_min) / x_min).ln() / (x_max / x_min).ln()
        } else {
            x / x_max
        };
        ml + t * (w - ml - mr)
    };
    let mut x_ticks: Vec<f64> = if log_x {
        all.map(|p| p.0).filter(|&x| x > 0.0).collect()
    } else {
        (0..=4).map(|k| x_max * k as f64 / 4.0).collect()
    };
    x_ticks.sort_by(f64::total_cmp);
    x_ticks.dedup();
    let py = |y: f64| h - mb - y / y_max * (h - mt - mb);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"12\"><rect width=\"{w}\" height=\"{h}\" fill=\"#fff\"/><text x=\"{ml}\" y=\"24\" font-size=\"15\">{title}</text><rect x=\"{ml}\" y=\"{mt}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#888\"/>",
        w - ml - mr,
        h - mt - mb
    );
    for x in x_ticks {
        let _ = writeln!(
            s,
            "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text>",
            px(x),
            h - mb + 16.0,
            x.round()
        );
    }
    for k in 0..=4 {
        let y = y_max * k as f64 / 4.0;
        let _ = writeln!(
            s,
            "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">{:.3e}</text><line x1=\"{ml}\" x2=\"{:.1}\" y1=\"{:.1}\" y2=\"{:.1}\" stroke=\"#eee\"/>",
            ml - 4.0,
            py(y) + 4.0,
            y,
            w - mr,
            py(y),
            py(y)
        );
    }
    for (k, (name, pts, dashed)) in series.iter().enumerate() {
        let color = COLORS[(k / if series.iter().any(|s| s.2) { 2 } else { 1 }) % COLORS.len()];
        let dash = if *dashed {
            " stroke-dasharray=\"6 4\""
        } else {
            ""
        };
        let mut pts = pts.clone();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let line: Vec<String> = pts
            .iter()
            .map(|p| format!("{:.1},{:.1}", px(p.0), py(p.1)))
            .collect();
        let _ = writeln!(
            s,
            "<polyline points=\"{}\" fill=\"none\" stroke=\"{color}\" stroke-width=\"2\"{dash}/>",
            line.join(" ")
        );
        for p in &pts {
            let _ = writeln!(
                s,
                "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"2.5\" fill=\"{color}\"/>",
                px(p.0),
                py(p.1)
            );
        }
        let ly = mt + 16.0 * k as f64 + 8.0;
        let _ = writeln!(
            s,
            "<line x1=\"{0:.1}\" x2=\"{1:.1}\" y1=\"{ly:.1}\" y2=\"{ly:.1}\" stroke=\"{color}\" stroke-width=\"2\"{dash}/><text x=\"{2:.1}\" y=\"{3:.1}\">{name}</text>",
            w - mr + 10.0,
            w - mr + 34.0,
            w - mr + 40.0,
            ly + 4.0
        );
    }
    let _ = writeln!(
        s,
        "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{x_label}</text><text x=\"16\" y=\"{:.1}\" transform=\"rotate(-90 16 {:.1})\" text-anchor=\"middle\">{y_label}</text></svg>",
        (ml + w - mr) / 2.0,
        h - 10.0,
        h / 2.0,
        h / 2.0
    );
    s
}

/// A labelled point of a scatter plot: x, y and a short label drawn beside it.
pub type LabelledPoint = (f64, f64, String);

/// A square scatter plot of predictions against observations on equal axes: the identity line,
/// a band of ±`band` around it (dashed), every point with its label, and a note line under the
/// title (the figure of merit).
pub fn scatter_identity(
    title: &str,
    note: &str,
    x_label: &str,
    y_label: &str,
    points: &[LabelledPoint],
    band: f64,
) -> String {
    let (size, m) = (560.0, 60.0);
    let lo = points
        .iter()
        .flat_map(|p| [p.0, p.1])
        .fold(f64::INFINITY, f64::min);
    let hi = points
        .iter()
        .flat_map(|p| [p.0, p.1])
        .fold(f64::NEG_INFINITY, f64::max);
    // Ticks about eight to the side, at 1, 2, 2.5 or 5 times a power of ten (0.25 for
    // log10 sensitivities, 2.5 or 5 for dB).
    let step = if lo.is_finite() && hi > lo {
        let raw = (hi - lo + 0.1) / 8.0;
        let decade = 10f64.powf(raw.log10().floor());
        [1.0, 2.0, 2.5, 5.0, 10.0]
            .into_iter()
            .map(|k| k * decade)
            .find(|&s| s >= raw * 0.999)
            .unwrap_or(10.0 * decade)
    } else {
        0.25
    };
    let (lo, hi) = if lo.is_finite() && hi > lo {
        (
            ((lo - 0.05) / step).floor() * step,
            ((hi + 0.05) / step).ceil() * step,
        )
    } else {
        (0.0, 1.0)
    };
    let span = size - 2.0 * m;
    let p = |v: f64| (v - lo) / (hi - lo) * span;
    let (px, py) = (|x: f64| m + p(x), |y: f64| size - m - p(y));
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{size}\" height=\"{size}\" font-family=\"sans-serif\" font-size=\"12\"><rect width=\"{size}\" height=\"{size}\" fill=\"#fff\"/><text x=\"{m}\" y=\"22\" font-size=\"15\">{title}</text><text x=\"{m}\" y=\"40\" fill=\"#555\">{note}</text><rect x=\"{m}\" y=\"{m}\" width=\"{span}\" height=\"{span}\" fill=\"none\" stroke=\"#888\"/>"
    );
    let mut t = lo;
    while t <= hi + 1e-9 {
        let _ = writeln!(
            s,
            "<line x1=\"{0:.1}\" x2=\"{0:.1}\" y1=\"{m}\" y2=\"{1:.1}\" stroke=\"#eee\"/><line y1=\"{2:.1}\" y2=\"{2:.1}\" x1=\"{m}\" x2=\"{3:.1}\" stroke=\"#eee\"/><text x=\"{0:.1}\" y=\"{4:.1}\" text-anchor=\"middle\">{t:.2}</text><text x=\"{5:.1}\" y=\"{6:.1}\" text-anchor=\"end\">{t:.2}</text>",
            px(t),
            size - m,
            py(t),
            size - m,
            size - m + 16.0,
            m - 4.0,
            py(t) + 4.0
        );
        t += step;
    }
    for (offset, dash) in [
        (0.0, ""),
        (band, " stroke-dasharray=\"5 4\""),
        (-band, " stroke-dasharray=\"5 4\""),
    ] {
        let (a, b) = ((lo - offset).max(lo), (hi - offset).min(hi));
        let _ = writeln!(
            s,
            "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"#999\"{dash}/>",
            px(a),
            py(a + offset),
            px(b),
            py(b + offset)
        );
    }
    for (x, y, label) in points {
        let _ = writeln!(
            s,
            "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"3.5\" fill=\"#d95f02\" fill-opacity=\"0.8\"/><text x=\"{:.1}\" y=\"{:.1}\" font-size=\"9\" fill=\"#333\">{label}</text>",
            px(*x),
            py(*y),
            px(*x) + 5.0,
            py(*y) - 3.0
        );
    }
    let _ = writeln!(
        s,
        "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{x_label}</text><text x=\"16\" y=\"{:.1}\" transform=\"rotate(-90 16 {:.1})\" text-anchor=\"middle\">{y_label}</text></svg>",
        size / 2.0,
        size - 16.0,
        size / 2.0,
        size / 2.0
    );
    s
}
