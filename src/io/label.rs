//! Text in PNG images: plot ticks and titles, contact-sheet captions, heat-map legends.
//!
//! The font is a subset of DejaVu Sans (Latin-1, Greek and the symbols labels use; 20 KB) embedded
//! in the binary from `reference/fonts/` (made by `make_font.sh` there; licence beside it), so a
//! label looks the same on every machine and no system font is looked up. `ab_glyph` turns each
//! glyph's outline into per-pixel coverage; this file places the glyphs (advance widths and `kern`
//! pairs, no shaping: labels are short Latin or Greek runs) and blends the coverage into a
//! `tiny_skia::Pixmap` or an `image::RgbImage`. Vertical text (a y-axis title) is the same run
//! turned a quarter turn anticlockwise, an exact pixel permutation. Everything is deterministic:
//! the same text, size and position give the same pixels.

use std::sync::OnceLock;

use ab_glyph::{Font, FontRef, PxScale, ScaleFont, point};

const FONT_BYTES: &[u8] = include_bytes!("../../reference/fonts/DejaVuSans-subset.ttf");

fn font() -> &'static FontRef<'static> {
    static FONT: OnceLock<FontRef<'static>> = OnceLock::new();
    FONT.get_or_init(|| {
        FontRef::try_from_slice(FONT_BYTES).expect("the embedded font is a valid TrueType file")
    })
}

/// Where the anchor point sits on the text's baseline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Align {
    /// The text starts at the anchor.
    Left,
    /// The text is centred on the anchor.
    Center,
    /// The text ends at the anchor.
    Right,
}

/// How a run of text is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Style {
    /// Font size in pixels (the em height).
    pub px: f32,
    /// sRGB colour.
    pub color: [u8; 3],
    /// Horizontal placement against the anchor.
    pub align: Align,
    /// A quarter turn anticlockwise (reading upwards); the anchor's `x` is then the baseline.
    pub vertical: bool,
}

impl Style {
    /// Left-aligned, horizontal text of `px` pixels in `color`.
    pub fn new(px: f32, color: [u8; 3]) -> Style {
        Style {
            px,
            color,
            align: Align::Left,
            vertical: false,
        }
    }

    /// The same style with another alignment.
    pub fn align(self, align: Align) -> Style {
        Style { align, ..self }
    }

    /// The same style turned a quarter turn anticlockwise.
    pub fn vertical(self) -> Style {
        Style {
            vertical: true,
            ..self
        }
    }
}

/// The advance width of `text` at `px` pixels.
pub fn text_width(text: &str, px: f32) -> f32 {
    let scaled = font().as_scaled(PxScale::from(px));
    let mut width = 0.0;
    let mut prev = None;
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(p) = prev {
            width += scaled.kern(p, id);
        }
        width += scaled.h_advance(id);
        prev = Some(id);
    }
    width
}

/// Ascent above the baseline at `px` pixels (for placing text below a line).
pub fn ascent(px: f32) -> f32 {
    font().as_scaled(PxScale::from(px)).ascent()
}

/// Calls `put(u, v, coverage)` for every pixel the text covers, in text coordinates: `u` along
/// the baseline from the anchor, `v` down from it.
fn coverage(text: &str, style: &Style, mut put: impl FnMut(i32, i32, f32)) {
    let scaled = font().as_scaled(PxScale::from(style.px));
    let start = match style.align {
        Align::Left => 0.0,
        Align::Center => -text_width(text, style.px) / 2.0,
        Align::Right => -text_width(text, style.px),
    };
    let mut caret = start.round();
    let mut prev = None;
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(p) = prev {
            caret += scaled.kern(p, id);
        }
        let glyph = id.with_scale_and_position(PxScale::from(style.px), point(caret, 0.0));
        caret += scaled.h_advance(id);
        prev = Some(id);
        if let Some(outline) = font().outline_glyph(glyph) {
            let b = outline.px_bounds();
            let (x0, y0) = (b.min.x as i32, b.min.y as i32);
            outline.draw(|gx, gy, c| {
                if c > 0.0 {
                    put(x0 + gx as i32, y0 + gy as i32, c.min(1.0));
                }
            });
        }
    }
}

/// Image coordinates of text coordinate (u, v) for an anchor at (x, y).
fn place(style: &Style, x: f32, y: f32, u: i32, v: i32) -> (i32, i32) {
    let (x, y) = (x.round() as i32, y.round() as i32);
    if style.vertical {
        (x + v, y - u)
    } else {
        (x + u, y + v)
    }
}

/// Draws `text` into `pixmap` with its anchor (on the baseline) at (x, y).
pub fn draw_pixmap(pixmap: &mut tiny_skia::Pixmap, text: &str, x: f32, y: f32, style: Style) {
    let (w, h) = (pixmap.width() as i32, pixmap.height() as i32);
    let pixels = pixmap.pixels_mut();
    coverage(text, &style, |u, v, c| {
        let (px, py) = place(&style, x, y, u, v);
        if px < 0 || py < 0 || px >= w || py >= h {
            return;
        }
        let p = &mut pixels[(py * w + px) as usize];
        let blend = |dst: u8, src: u8| (src as f32 * c + dst as f32 * (1.0 - c)).round() as u8;
        let alpha = blend(p.alpha(), 255);
        let [r, g, b] = style.color;
        // Premultiplied: the source is opaque, so its premultiplied channels are its colour.
        *p = tiny_skia::PremultipliedColorU8::from_rgba(
            blend(p.red(), r).min(alpha),
            blend(p.green(), g).min(alpha),
            blend(p.blue(), b).min(alpha),
            alpha,
        )
        .expect("channels are clamped to alpha");
    });
}

/// Draws `text` into an 8-bit sRGB image with its anchor (on the baseline) at (x, y).
pub fn draw_rgb(img: &mut image::RgbImage, text: &str, x: f32, y: f32, style: Style) {
    let (w, h) = (img.width() as i32, img.height() as i32);
    coverage(text, &style, |u, v, c| {
        let (px, py) = place(&style, x, y, u, v);
        if px < 0 || py < 0 || px >= w || py >= h {
            return;
        }
        let p = img.get_pixel_mut(px as u32, py as u32);
        for (d, s) in p.0.iter_mut().zip(style.color) {
            *d = (s as f32 * c + *d as f32 * (1.0 - c)).round() as u8;
        }
    });
}

/// Writes `text` in white across the top of `img` on a darkened band (a contact-sheet tile's
/// caption), at `px` pixels; a caption wider than the image is cut at its edge.
pub fn caption_rgb(img: &mut image::RgbImage, text: &str, px: f32) {
    let band = (px * 1.45).ceil() as u32;
    for y in 0..band.min(img.height()) {
        for x in 0..img.width() {
            let p = img.get_pixel_mut(x, y);
            p.0 = p.0.map(|c| (c as f32 * 0.3).round() as u8);
        }
    }
    let baseline = ((band as f32 + ascent(px) * 0.75) / 2.0).round();
    draw_rgb(img, text, 4.0, baseline, Style::new(px, [255, 255, 255]));
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ink(img: &image::RgbImage) -> Vec<(u32, u32)> {
        img.enumerate_pixels()
            .filter(|(_, _, p)| p.0 != [255, 255, 255])
            .map(|(x, y, _)| (x, y))
            .collect()
    }

    #[test]
    fn text_is_drawn_where_it_is_anchored_and_nowhere_else() {
        let mut img = image::RgbImage::from_pixel(200, 40, image::Rgb([255; 3]));
        draw_rgb(&mut img, "view 07", 10.0, 25.0, Style::new(14.0, [0; 3]));
        let pixels = ink(&img);
        assert!(pixels.len() > 60, "{} inked pixels", pixels.len());
        let (x_min, x_max) = (
            pixels.iter().map(|p| p.0).min().unwrap(),
            pixels.iter().map(|p| p.0).max().unwrap(),
        );
        let (y_min, y_max) = (
            pixels.iter().map(|p| p.1).min().unwrap(),
            pixels.iter().map(|p| p.1).max().unwrap(),
        );
        assert!((10..=12).contains(&x_min), "starts at {x_min}");
        let width = text_width("view 07", 14.0);
        assert!(
            (x_max as f32 - 10.0 - width).abs() < 3.0,
            "{x_max} vs {width}"
        );
        // Cap height of a 14 px font is about 10 px, all above the baseline (no descenders here).
        assert!(y_min >= 13 && y_max <= 25, "rows {y_min}..{y_max}");
    }

    #[test]
    fn alignment_moves_the_run_by_its_width() {
        let draw = |align| {
            let mut img = image::RgbImage::from_pixel(300, 30, image::Rgb([255; 3]));
            draw_rgb(
                &mut img,
                "0.25",
                150.0,
                20.0,
                Style::new(12.0, [0; 3]).align(align),
            );
            ink(&img).iter().map(|p| p.0).min().unwrap() as f32
        };
        let w = text_width("0.25", 12.0);
        assert!((draw(Align::Left) - draw(Align::Right) - w).abs() <= 1.5);
        assert!((draw(Align::Left) - draw(Align::Center) - w / 2.0).abs() <= 1.5);
    }

    #[test]
    fn vertical_text_is_the_horizontal_run_turned_a_quarter() {
        let mut flat = image::RgbImage::from_pixel(120, 120, image::Rgb([255; 3]));
        let mut turned = flat.clone();
        draw_rgb(&mut flat, "FLIP", 20.0, 60.0, Style::new(16.0, [0; 3]));
        draw_rgb(
            &mut turned,
            "FLIP",
            60.0,
            100.0,
            Style::new(16.0, [0; 3]).vertical(),
        );
        let mut a: Vec<(i32, i32)> = ink(&flat)
            .iter()
            .map(|&(x, y)| (x as i32 - 20, y as i32 - 60))
            .collect();
        let mut b: Vec<(i32, i32)> = ink(&turned)
            .iter()
            .map(|&(x, y)| (100 - y as i32, x as i32 - 60))
            .collect();
        a.sort();
        b.sort();
        assert_eq!(a, b);
    }

    #[test]
    fn pixmap_and_rgb_drawing_agree_on_an_opaque_background() {
        let mut img = image::RgbImage::from_pixel(80, 24, image::Rgb([250, 250, 250]));
        let mut pm = tiny_skia::Pixmap::new(80, 24).unwrap();
        pm.fill(tiny_skia::Color::from_rgba8(250, 250, 250, 255));
        let style = Style::new(13.0, [20, 60, 200]);
        draw_rgb(&mut img, "≥ 12 m", 4.0, 18.0, style);
        draw_pixmap(&mut pm, "≥ 12 m", 4.0, 18.0, style);
        for (p, q) in img.pixels().zip(pm.pixels()) {
            assert_eq!(p.0, [q.red(), q.green(), q.blue()]);
            assert_eq!(q.alpha(), 255);
        }
        assert!(img.pixels().any(|p| p.0 != [250, 250, 250]));
    }

    #[test]
    fn every_symbol_labels_use_is_in_the_subset() {
        for c in "0123456789.,:;-+×−–—≤≥≈·°²µ%()[]/ abcxyzABCXYZ αβγδεσωΔ→".chars()
        {
            assert_ne!(
                font().glyph_id(c).0,
                0,
                "{c:?} is missing from the font subset"
            );
        }
    }
}
