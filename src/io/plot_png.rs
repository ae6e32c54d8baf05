//! Line plots as PNG, drawn with tiny-skia and labelled with the bundled font (`label.rs`), for
//! terminals and CI artefacts where nobody opens a browser: `eval`'s error-against-triangles and
//! switch-distance plots, and the paper experiments' figures beside their SVGs.
//!
//! A [`Chart`] is data only (series, point labels, reference lines); [`render`] lays it out:
//! a title, a plot area with a light grid, a linear y axis with "nice" ticks (about six steps of 1,
//! 2 or 5 × 10^k, from zero unless the data are negative or the chart asks for a tight range), a linear
//! or logarithmic x axis (a quarter beyond the data each side; decade ticks labelled 1k, 10k, 1M,
//! with 2× and 5× ticks when it spans at most two decades), reference lines (a gate limit across, the original's triangle
//! count upright), and a legend on the right. Colours are the SVG plots' palette (`plot.rs`).
//! Nothing depends on the machine: the same chart gives the same bytes.

use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Rect, Stroke, StrokeDash, Transform};

use super::label::{self, Align, Style};
use super::plot::{COLORS, Series};
use crate::error::{Error, Result};

/// One plotted series.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Line {
    /// Legend entry.
    pub name: String,
    /// Points (x, y); non-finite points are left out, and so are x ≤ 0 on a log axis.
    pub points: Vec<(f64, f64)>,
    /// Labels drawn beside the points, in the order of `points` (empty: none): above them for the
    /// first, third, … series, below for the others.
    pub labels: Vec<String>,
    /// Dashed instead of solid.
    pub dashed: bool,
    /// Which points are bounds rather than measurements, in the order of `points` (empty: all
    /// measured). A bound is drawn as an open ring with an arrow towards where the true value
    /// lies, joined to its neighbours by a dotted segment.
    pub bounds: Vec<PointBound>,
}

/// What a plotted point is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PointBound {
    /// A measured value.
    #[default]
    Measured,
    /// The true value is at most this (arrow down).
    AtMost,
    /// The true value is at least this (arrow up).
    AtLeast,
}

/// A reference line across the plot (`Chart::h_marks`: at a y value) or upright (`v_marks`: at an
/// x value), drawn dashed in grey with its label.
#[derive(Debug, Clone, PartialEq)]
pub struct Mark {
    /// Where it is, in data units.
    pub at: f64,
    /// What it is ("gate limit 0.05", "original 69 451").
    pub label: String,
}

/// A whole line plot.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Chart {
    /// Title above the plot.
    pub title: String,
    /// A second, smaller line under the title (units, conditions); may be empty.
    pub subtitle: String,
    /// The x axis's title.
    pub x_label: String,
    /// The y axis's title.
    pub y_label: String,
    /// The series.
    pub lines: Vec<Line>,
    /// A logarithmic x axis.
    pub log_x: bool,
    /// Reference lines at y values.
    pub h_marks: Vec<Mark>,
    /// Reference lines at x values.
    pub v_marks: Vec<Mark>,
    /// Let the y axis start at the data's minimum instead of zero (PSNR in dB, for example).
    pub tight_y: bool,
}

const WIDTH: u32 = 880;
const HEIGHT: u32 = 500;
const LEFT: f32 = 84.0;
const RIGHT: f32 = 200.0;
const TOP: f32 = 62.0;
const BOTTOM: f32 = 58.0;
/// About how many steps a linear axis is divided into.
const TICKS: f64 = 6.0;
/// Series with more points than this are drawn without dots.
const MAX_DOTS: usize = 16;
const INK: [u8; 3] = [40, 40, 40];
const MUTED: [u8; 3] = [100, 100, 100];

impl Chart {
    /// The chart of an SVG plot's series (`plot::line_plot`'s arguments), so that a figure can be
    /// written both ways from one description.
    pub fn from_series(
        title: &str,
        x_label: &str,
        y_label: &str,
        series: &[Series],
        log_x: bool,
    ) -> Chart {
        Chart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            lines: series
                .iter()
                .map(|(name, points, dashed)| Line {
                    name: name.clone(),
                    points: points.clone(),
                    labels: Vec::new(),
                    dashed: *dashed,
                    bounds: Vec::new(),
                })
                .collect(),
            log_x,
            ..Chart::default()
        }
    }
}

/// The chart as PNG bytes.
pub fn encode(chart: &Chart) -> Result<Vec<u8>> {
    encode_stack(std::slice::from_ref(chart))
}

/// Charts stacked top to bottom in one PNG (a figure's panels).
pub fn encode_stack(charts: &[Chart]) -> Result<Vec<u8>> {
    let mut sheet = Pixmap::new(WIDTH, HEIGHT * charts.len().max(1) as u32)
        .ok_or_else(|| Error::Internal(format!("a stack of {} plots is too tall", charts.len())))?;
    sheet.fill(Color::WHITE);
    for (i, chart) in charts.iter().enumerate() {
        sheet.draw_pixmap(
            0,
            (HEIGHT as usize * i) as i32,
            render(chart).as_ref(),
            &tiny_skia::PixmapPaint::default(),
            Transform::identity(),
            None,
        );
    }
    let title = charts.first().map(|c| c.title.as_str()).unwrap_or("");
    sheet
        .encode_png()
        .map_err(|e| Error::Internal(format!("encoding the plot '{title}': {e}")))
}

/// Writes the chart as a PNG file (atomically).
pub fn write(path: &std::path::Path, chart: &Chart) -> Result<()> {
    super::write_atomic(path, &encode(chart)?)
}

/// The chart drawn into an opaque pixmap of 880 × 500 pixels.
pub fn render(chart: &Chart) -> Pixmap {
    let mut pm = Pixmap::new(WIDTH, HEIGHT).expect("a fixed, non-zero size");
    pm.fill(Color::WHITE);
    label::draw_pixmap(&mut pm, &chart.title, LEFT, 26.0, Style::new(17.0, INK));
    if !chart.subtitle.is_empty() {
        label::draw_pixmap(
            &mut pm,
            &chart.subtitle,
            LEFT,
            46.0,
            Style::new(12.0, MUTED),
        );
    }
    let lines = plotted_points(chart);
    let area = Area::new(chart, &lines);
    draw_grid(&mut pm, &area, chart);
    draw_marks(&mut pm, &area, chart);
    draw_series(&mut pm, &area, chart, &lines);
    pm
}

/// A series' points that can be drawn (finite, positive x on a log axis), sorted by x, each with
/// its label.
type Points<'a> = Vec<(f64, f64, Option<&'a str>, PointBound)>;

/// Every line's drawable points.
fn plotted_points(chart: &Chart) -> Vec<Points<'_>> {
    chart
        .lines
        .iter()
        .map(|l| {
            let mut pts: Points = l
                .points
                .iter()
                .enumerate()
                .filter(|(_, p)| p.0.is_finite() && p.1.is_finite() && (!chart.log_x || p.0 > 0.0))
                .map(|(i, p)| {
                    let bound = l.bounds.get(i).copied().unwrap_or_default();
                    (p.0, p.1, l.labels.get(i).map(String::as_str), bound)
                })
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            pts
        })
        .collect()
}

/// The plot area in pixels and its two axes.
struct Area {
    x0: f32,
    x1: f32,
    y0: f32,
    y1: f32,
    x_axis: Axis,
    y_axis: Axis,
}

impl Area {
    /// The axes fitted to the points and the marks.
    fn new(chart: &Chart, lines: &[Points<'_>]) -> Area {
        let xs = lines
            .iter()
            .flatten()
            .map(|p| p.0)
            .chain(chart.v_marks.iter().map(|m| m.at))
            .filter(|x| x.is_finite() && (!chart.log_x || *x > 0.0));
        let ys = lines
            .iter()
            .flatten()
            .map(|p| p.1)
            .chain(chart.h_marks.iter().map(|m| m.at))
            .filter(|y| y.is_finite());
        Area {
            x0: LEFT,
            x1: WIDTH as f32 - RIGHT,
            y0: TOP,
            y1: HEIGHT as f32 - BOTTOM,
            x_axis: Axis::x(xs, chart.log_x),
            y_axis: Axis::y(ys, chart.tight_y),
        }
    }

    fn px(&self, x: f64) -> f32 {
        self.x0 + self.x_axis.fraction(x) as f32 * (self.x1 - self.x0)
    }

    fn py(&self, y: f64) -> f32 {
        self.y1 - self.y_axis.fraction(y) as f32 * (self.y1 - self.y0)
    }
}

/// Grid, ticks, the frame and the axis titles.
fn draw_grid(pm: &mut Pixmap, area: &Area, chart: &Chart) {
    let (x0, x1, y0, y1) = (area.x0, area.x1, area.y0, area.y1);
    // Grid and ticks.
    let grid = paint([230, 230, 230]);
    let tick_style = Style::new(12.0, INK);
    for (x, text) in area.x_axis.ticks() {
        let sx = area.px(x);
        stroke_line(pm, (sx, y0), (sx, y1), &grid, 1.0, false);
        if !text.is_empty() {
            label::draw_pixmap(pm, &text, sx, y1 + 18.0, tick_style.align(Align::Center));
        }
    }
    for (y, text) in area.y_axis.ticks() {
        let sy = area.py(y);
        stroke_line(pm, (x0, sy), (x1, sy), &grid, 1.0, false);
        label::draw_pixmap(
            pm,
            &text,
            x0 - 6.0,
            sy + 4.0,
            tick_style.align(Align::Right),
        );
    }
    let frame = Rect::from_ltrb(x0, y0, x1, y1).expect("a non-empty plot area");
    pm.stroke_path(
        &PathBuilder::from_rect(frame),
        &paint([136, 136, 136]),
        &Stroke::default(),
        Transform::identity(),
        None,
    );
    label::draw_pixmap(
        pm,
        &chart.x_label,
        (x0 + x1) / 2.0,
        HEIGHT as f32 - 14.0,
        Style::new(13.0, INK).align(Align::Center),
    );
    label::draw_pixmap(
        pm,
        &chart.y_label,
        22.0,
        (y0 + y1) / 2.0,
        Style::new(13.0, INK).align(Align::Center).vertical(),
    );
}

/// Reference lines, under the data.
fn draw_marks(pm: &mut Pixmap, area: &Area, chart: &Chart) {
    let (x0, x1, y0, y1) = (area.x0, area.x1, area.y0, area.y1);
    // Reference lines under the data.
    let mark = paint([150, 150, 150]);
    let mark_style = Style::new(11.0, MUTED);
    for m in chart.h_marks.iter().filter(|m| m.at.is_finite()) {
        let sy = area.py(m.at);
        stroke_line(pm, (x0, sy), (x1, sy), &mark, 1.5, true);
        label::draw_pixmap(pm, &m.label, x0 + 6.0, sy - 5.0, mark_style);
    }
    for m in chart.v_marks.iter().filter(|m| m.at.is_finite()) {
        if chart.log_x && m.at <= 0.0 {
            continue;
        }
        let sx = area.px(m.at);
        stroke_line(pm, (sx, y0), (sx, y1), &mark, 1.5, true);
        label::draw_pixmap(pm, &m.label, sx - 5.0, y1 - 6.0, mark_style.vertical());
    }
}

/// Series, point labels and the legend.
fn draw_series(pm: &mut Pixmap, area: &Area, chart: &Chart, lines: &[Points<'_>]) {
    let (x0, x1, y0, y1) = (area.x0, area.x1, area.y0, area.y1);
    // Series, point labels and the legend.
    let share = if chart.lines.iter().any(|l| l.dashed) {
        2
    } else {
        1
    };
    let pclip = Rect::from_ltrb(x0 - 6.0, y0 - 6.0, x1 + 6.0, y1 + 6.0).expect("non-empty");
    let mut labels = Labels::new(area);
    for (k, (line, pts)) in chart.lines.iter().zip(lines).enumerate() {
        let color = hex(COLORS[(k / share) % COLORS.len()]);
        let ink = paint(color);
        // Segment by segment: dotted where either end is a bound, not a measurement.
        for w in pts.windows(2) {
            let bound = w[0].3 != PointBound::Measured || w[1].3 != PointBound::Measured;
            let style = if bound {
                dotted(2.0)
            } else {
                stroke(2.0, line.dashed)
            };
            let (a, b) = (
                (area.px(w[0].0), area.py(w[0].1)),
                (area.px(w[1].0), area.py(w[1].1)),
            );
            let mut pb = PathBuilder::new();
            pb.move_to(a.0, a.1);
            pb.line_to(b.0, b.1);
            if let Some(path) = pb.finish() {
                pm.stroke_path(&path, &ink, &style, Transform::identity(), None);
            }
        }
        for &(x, y, text, bound) in pts {
            let (sx, sy) = (area.px(x), area.py(y));
            if sx < pclip.left() || sx > pclip.right() || sy < pclip.top() || sy > pclip.bottom() {
                continue;
            }
            // A dense curve's dots would hide its line.
            if pts.len() <= MAX_DOTS || bound != PointBound::Measured {
                draw_point(pm, (sx, sy), &ink, bound);
            }
            if let Some(text) = text.filter(|t| !t.is_empty()) {
                let (lx, ly) = labels.place(text, (sx, sy), k % 2 == 0);
                // A label pushed away from its point gets a leader line back to it.
                if (ly - sy).abs() > 20.0 {
                    let end = if lx > sx { lx - 1.0 } else { lx + 4.0 };
                    stroke_line(pm, (sx, sy), (end, ly - 4.0), &ink, 0.6, false);
                }
                label::draw_pixmap(pm, text, lx, ly, Style::new(11.0, color));
            }
        }
        let ly = y0 + 8.0 + 20.0 * k as f32;
        stroke_line(pm, (x1 + 12.0, ly), (x1 + 40.0, ly), &ink, 2.0, line.dashed);
        label::draw_pixmap(pm, &line.name, x1 + 46.0, ly + 4.0, Style::new(12.0, INK));
    }
    if lines.iter().flatten().any(|p| p.3 != PointBound::Measured) {
        let ly = y0 + 8.0 + 20.0 * chart.lines.len() as f32 + 6.0;
        draw_point(pm, (x1 + 26.0, ly), &paint(INK), PointBound::AtMost);
        let note = "bound: true value past arrow";
        label::draw_pixmap(pm, note, x1 + 46.0, ly + 4.0, Style::new(11.0, INK));
    }
}

/// A point's marker: a dot for a measurement, an open ring with an arrow (down for "at most", up
/// for "at least") for a bound.
fn draw_point(pm: &mut Pixmap, (sx, sy): (f32, f32), ink: &Paint<'_>, bound: PointBound) {
    let dir = match bound {
        PointBound::Measured => {
            if let Some(dot) = PathBuilder::from_circle(sx, sy, 3.5) {
                pm.fill_path(&dot, ink, FillRule::Winding, Transform::identity(), None);
            }
            return;
        }
        PointBound::AtMost => 1.0,
        PointBound::AtLeast => -1.0,
    };
    if let Some(ring) = PathBuilder::from_circle(sx, sy, 4.5) {
        pm.stroke_path(&ring, ink, &stroke(1.5, false), Transform::identity(), None);
    }
    stroke_line(
        pm,
        (sx, sy + dir * 5.0),
        (sx, sy + dir * 16.0),
        ink,
        1.5,
        false,
    );
    let mut head = PathBuilder::new();
    head.move_to(sx - 4.0, sy + dir * 12.0);
    head.line_to(sx, sy + dir * 17.0);
    head.line_to(sx + 4.0, sy + dir * 12.0);
    if let Some(path) = head.finish() {
        pm.stroke_path(&path, ink, &stroke(1.5, false), Transform::identity(), None);
    }
}

/// A dotted stroke (bounds' segments).
fn dotted(width: f32) -> Stroke {
    let mut s = stroke(width, false);
    s.dash = tiny_skia::StrokeDash::new(vec![2.0, 4.0], 0.0);
    s
}

/// Point labels placed so that none overlaps another or leaves the plot: each tries spots around
/// its point, nearest first, and takes the first free one (the preferred side first: above for
/// even series, below for odd ones).
struct Labels {
    placed: Vec<Rect>,
    bounds: (f32, f32, f32, f32),
}

impl Labels {
    fn new(area: &Area) -> Labels {
        Labels {
            placed: Vec::new(),
            bounds: (area.x0, area.y0, area.x1, area.y1),
        }
    }

    /// The baseline origin for `text` beside the point at `at`.
    fn place(&mut self, text: &str, at: (f32, f32), above: bool) -> (f32, f32) {
        let (w, h) = (label::text_width(text, 11.0), 11.0);
        let (bx0, by0, bx1, by1) = self.bounds;
        let mut candidates = Vec::new();
        for step in 0..24 {
            let lift = 14.0 * step as f32;
            let (up, down) = ((6.0, -6.0 - lift), (6.0, 15.0 + lift));
            let (first, second) = if above { (up, down) } else { (down, up) };
            candidates.extend([first, second, (-6.0 - w, first.1), (-6.0 - w, second.1)]);
        }
        let rect = |(dx, dy): (f32, f32)| {
            let (x, y) = (at.0 + dx, at.1 + dy);
            Rect::from_xywh(x, y - h, w, h + 2.0)
        };
        let free = candidates.iter().copied().find(|&c| {
            rect(c).is_some_and(|r| {
                r.left() >= bx0
                    && r.right() <= bx1 + 40.0
                    && r.top() >= by0
                    && r.bottom() <= by1
                    && !self.placed.iter().any(|p| overlaps(p, &r))
            })
        });
        let chosen = free.unwrap_or(candidates[0]);
        if let Some(r) = rect(chosen) {
            self.placed.push(r);
        }
        (at.0 + chosen.0, at.1 + chosen.1)
    }
}

fn overlaps(a: &Rect, b: &Rect) -> bool {
    a.left() < b.right() && b.left() < a.right() && a.top() < b.bottom() && b.top() < a.bottom()
}

/// One axis: its data range and how values map onto it.
struct Axis {
    lo: f64,
    hi: f64,
    log: bool,
}

impl Axis {
    fn x(values: impl Iterator<Item = f64>, log: bool) -> Axis {
        let (lo, hi) = range(values);
        if log {
            let (lo, hi) = if lo.is_finite() {
                (lo, hi)
            } else {
                (1.0, 10.0)
            };
            // A quarter beyond the data on each side, not out to whole decades: 700 to 14 000
            // would otherwise spread over 100 to 100 000.
            Axis {
                lo: (lo / 1.25).log10(),
                hi: (hi * 1.25).log10(),
                log: true,
            }
        } else {
            let (lo, hi) = if lo.is_finite() {
                (lo.min(0.0), hi)
            } else {
                (0.0, 1.0)
            };
            Axis::linear(lo, hi)
        }
    }

    fn y(values: impl Iterator<Item = f64>, tight: bool) -> Axis {
        let (lo, hi) = range(values);
        if !lo.is_finite() {
            return Axis::linear(0.0, 1.0);
        }
        let lo = if tight { lo } else { lo.min(0.0) };
        let pad = (hi - lo).abs().max(hi.abs() * 1e-3).max(1e-12) * 0.08;
        Axis::linear(if tight { lo - pad } else { lo }, hi + pad)
    }

    /// A linear axis over [lo, hi] widened to whole tick steps.
    fn linear(lo: f64, hi: f64) -> Axis {
        let hi = if hi > lo { hi } else { lo + 1.0 };
        let step = nice_step((hi - lo) / TICKS);
        Axis {
            lo: (lo / step).floor() * step,
            hi: (hi / step).ceil() * step,
            log: false,
        }
    }

    fn fraction(&self, v: f64) -> f64 {
        let v = if self.log { v.max(1e-300).log10() } else { v };
        (v - self.lo) / (self.hi - self.lo)
    }

    /// Tick positions in data units with their labels (an empty label: a minor tick).
    fn ticks(&self) -> Vec<(f64, String)> {
        if self.log {
            let few = self.hi - self.lo <= 2.0;
            let mut ticks = Vec::new();
            let mut e = self.lo.floor() as i32;
            while (e as f64) <= self.hi {
                for m in 1..10 {
                    let v = m as f64 * 10f64.powi(e);
                    let t = v.log10();
                    if t < self.lo - 1e-9 || t > self.hi + 1e-9 {
                        continue;
                    }
                    let labelled = m == 1 || (few && (m == 2 || m == 5));
                    ticks.push((v, if labelled { si(v) } else { String::new() }));
                }
                e += 1;
            }
            ticks
        } else {
            let step = nice_step((self.hi - self.lo) / TICKS);
            let n = ((self.hi - self.lo) / step).round() as i64;
            let decimals = (-step.log10().floor()).max(0.0) as usize;
            (0..=n)
                .map(|k| {
                    let v = self.lo + k as f64 * step;
                    let v = if v.abs() < step * 1e-9 { 0.0 } else { v };
                    (v, format!("{v:.decimals$}"))
                })
                .collect()
        }
    }
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    })
}

/// The smallest 1, 2 or 5 × 10^k at or above `raw`.
fn nice_step(raw: f64) -> f64 {
    let raw = if raw.is_finite() && raw > 0.0 {
        raw
    } else {
        1.0
    };
    let base = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * base)
        .find(|&s| s >= raw * (1.0 - 1e-9))
        .unwrap_or(10.0 * base)
}

/// A power of ten or a small multiple of one as a short label: 500, 1k, 20k, 1M.
fn si(v: f64) -> String {
    let (scaled, suffix) = if v >= 1e9 {
        (v / 1e9, "G")
    } else if v >= 1e6 {
        (v / 1e6, "M")
    } else if v >= 1e3 {
        (v / 1e3, "k")
    } else {
        (v, "")
    };
    if scaled >= 1.0 || scaled == 0.0 {
        format!("{}{suffix}", scaled.round())
    } else {
        format!("{scaled}{suffix}")
    }
}

fn hex(code: &str) -> [u8; 3] {
    let byte = |i: usize| u8::from_str_radix(&code[i..i + 2], 16).unwrap_or(0);
    [byte(1), byte(3), byte(5)]
}

fn paint(rgb: [u8; 3]) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color_rgba8(rgb[0], rgb[1], rgb[2], 255);
    p.anti_alias = true;
    p
}

fn stroke(width: f32, dashed: bool) -> Stroke {
    Stroke {
        width,
        dash: if dashed {
            StrokeDash::new(vec![7.0, 5.0], 0.0)
        } else {
            None
        },
        ..Stroke::default()
    }
}

fn stroke_line(
    pm: &mut Pixmap,
    a: (f32, f32),
    b: (f32, f32),
    ink: &Paint,
    width: f32,
    dashed: bool,
) {
    let mut pb = PathBuilder::new();
    pb.move_to(a.0, a.1);
    pb.line_to(b.0, b.1);
    if let Some(path) = pb.finish() {
        pm.stroke_path(
            &path,
            ink,
            &stroke(width, dashed),
            Transform::identity(),
            None,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chart() -> Chart {
        Chart {
            title: "FLIP against triangles".into(),
            subtitle: "bunny, 20 views".into(),
            x_label: "triangles".into(),
            y_label: "FLIP mean".into(),
            lines: vec![Line {
                name: "bunny".into(),
                points: vec![(700.0, 0.08), (7_000.0, 0.02), (35_000.0, 0.004)],
                labels: vec!["r01".into(), "r10".into(), "r50".into()],
                dashed: false,
                bounds: Vec::new(),
            }],
            log_x: true,
            h_marks: vec![Mark {
                at: 0.05,
                label: "gate flip_mean 0.05".into(),
            }],
            v_marks: vec![Mark {
                at: 69_451.0,
                label: "original".into(),
            }],
            tight_y: false,
        }
    }

    fn rgb(pm: &Pixmap, x: f32, y: f32) -> [u8; 3] {
        let p = pm.pixel(x.round() as u32, y.round() as u32).unwrap();
        [p.red(), p.green(), p.blue()]
    }

    #[test]
    fn point_labels_never_overlap_and_stay_inside_the_plot() {
        // Two series of five points crowded into one corner: every label finds a free spot.
        let mut c = chart();
        c.lines = (0..2)
            .map(|k| Line {
                name: format!("s{k}"),
                points: (0..5)
                    .map(|i| (1000.0 + 150.0 * i as f64, 0.001 * (i + k) as f64))
                    .collect(),
                labels: (0..5)
                    .map(|i| format!("meshopt-r{i} {k} px · 12.34 m"))
                    .collect(),
                bounds: vec![PointBound::AtMost],
                ..Line::default()
            })
            .collect();
        let pts = plotted_points(&c);
        let area = Area::new(&c, &pts);
        let mut labels = Labels::new(&area);
        for (k, line) in pts.iter().enumerate() {
            for p in line {
                labels.place(p.2.unwrap(), (area.px(p.0), area.py(p.1)), k % 2 == 0);
            }
        }
        assert_eq!(labels.placed.len(), 10);
        for (i, a) in labels.placed.iter().enumerate() {
            assert!(a.top() >= area.y0 && a.bottom() <= area.y1, "{a:?}");
            for b in &labels.placed[i + 1..] {
                assert!(!overlaps(a, b), "{a:?} {b:?}");
            }
        }
        // The first point of each series is a bound: drawn, with the bound's legend entry.
        let png = encode(&c).unwrap();
        assert!(!png.is_empty());
    }

    #[test]
    fn nice_steps_are_one_two_or_five_times_a_power_of_ten() {
        assert_eq!(nice_step(0.013), 0.02);
        assert_eq!(nice_step(0.02), 0.02);
        assert_eq!(nice_step(3.1), 5.0);
        assert_eq!(nice_step(7.0), 10.0);
        assert_eq!(nice_step(0.0), 1.0);
        assert_eq!(nice_step(f64::NAN), 1.0);
    }

    #[test]
    fn log_ticks_are_decades_with_short_names() {
        let axis = Axis::x([700.0, 35_000.0, 69_451.0].into_iter(), true);
        let labelled: Vec<String> = axis
            .ticks()
            .into_iter()
            .map(|t| t.1)
            .filter(|t| !t.is_empty())
            .collect();
        assert_eq!(labelled, ["1k", "10k"]);
        let narrow = Axis::x([1_200.0, 8_000.0].into_iter(), true);
        let labelled: Vec<String> = narrow
            .ticks()
            .into_iter()
            .map(|t| t.1)
            .filter(|t| !t.is_empty())
            .collect();
        assert_eq!(labelled, ["1k", "2k", "5k", "10k"]);
    }

    #[test]
    fn linear_ticks_cover_the_data_from_zero() {
        let axis = Axis::y([0.004, 0.08, 0.05].into_iter(), false);
        let ticks = axis.ticks();
        assert_eq!(ticks[0], (0.0, "0.00".to_string()));
        assert!(ticks.last().unwrap().0 >= 0.08);
        assert!(ticks.len() >= 4 && ticks.len() <= 7, "{ticks:?}");
        let tight = Axis::y([31.0, 38.0].into_iter(), true);
        assert!(tight.lo > 25.0 && tight.lo <= 31.0, "{}", tight.lo);
    }

    #[test]
    fn points_and_marks_land_where_the_axes_put_them() {
        let c = chart();
        let pm = render(&c);
        let x_axis = Axis::x([700.0, 35_000.0, 69_451.0].into_iter(), true);
        let y_axis = Axis::y([0.08, 0.02, 0.004, 0.05].into_iter(), false);
        let (x0, x1, y0, y1) = (LEFT, WIDTH as f32 - RIGHT, TOP, HEIGHT as f32 - BOTTOM);
        let px = |x: f64| x0 + x_axis.fraction(x) as f32 * (x1 - x0);
        let py = |y: f64| y1 - y_axis.fraction(y) as f32 * (y1 - y0);
        // The middle point's dot is the series colour.
        assert_eq!(rgb(&pm, px(7_000.0), py(0.02)), hex(COLORS[0]));
        // A grey dashed line somewhere along the gate limit.
        let sy = py(0.05);
        let grey = (0..200).any(|d| {
            let c = rgb(&pm, x0 + 200.0 + d as f32, sy);
            c[0] < 200 && c[0] == c[1] && c[1] == c[2]
        });
        assert!(grey, "the gate limit's line is missing");
        // Nothing outside the plot's frame is the series colour except the legend.
        assert_ne!(rgb(&pm, px(7_000.0), y1 + 30.0), hex(COLORS[0]));
    }

    #[test]
    fn the_same_chart_gives_the_same_bytes_and_another_chart_others() {
        let a = encode(&chart()).unwrap();
        assert_eq!(a, encode(&chart()).unwrap());
        assert_eq!(&a[1..4], b"PNG");
        let mut other = chart();
        other.lines[0].points[1].1 = 0.03;
        assert_ne!(a, encode(&other).unwrap());
        let stack = encode_stack(&[chart(), other]).unwrap();
        let decoded = image::load_from_memory(&stack).unwrap();
        assert_eq!((decoded.width(), decoded.height()), (WIDTH, 2 * HEIGHT));
    }

    #[test]
    fn svg_series_become_the_same_lines() {
        let series: Vec<Series> = vec![
            ("qem input".into(), vec![(350.0, 2.0), (700.0, 1.0)], true),
            (
                "qem optimized".into(),
                vec![(350.0, 1.5), (700.0, 0.8)],
                false,
            ),
        ];
        let c = Chart::from_series("t", "x", "y", &series, false);
        assert_eq!(c.lines.len(), 2);
        assert!(c.lines[0].dashed && !c.lines[1].dashed);
        assert_eq!(c.lines[1].points, series[1].1);
    }

    #[test]
    fn empty_and_non_finite_data_still_draw_a_frame() {
        let mut c = chart();
        c.lines[0].points = vec![(f64::NAN, 1.0), (0.0, f64::INFINITY), (-5.0, 1.0)];
        c.h_marks.clear();
        c.v_marks.clear();
        let pm = render(&c);
        let frame = rgb(&pm, LEFT, TOP + 100.0);
        assert!(
            frame[0] < 250 && frame[0] == frame[2],
            "no frame: {frame:?}"
        );
        c.lines.clear();
        assert!(encode(&c).is_ok());
    }
}
