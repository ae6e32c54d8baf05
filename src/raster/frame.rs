//! `Frame`: what a render produces — linear RGB colour, depth, coverage and triangle id per pixel —
//! and its conversions to 8-bit sRGB images.

use glam::Vec3;

use crate::error::{Error, Result};

/// Triangle id of a pixel no triangle covers.
pub const NO_TRIANGLE: u32 = u32::MAX;

/// A rendered image with its diagnostic channels.
///
/// # Guarantees
/// - `width, height >= 1`; every channel has `width * height` entries, row-major, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    pub(crate) width: u32,
    pub(crate) height: u32,
    /// Linear RGB, resolved over the samples.
    pub(crate) color: Vec<Vec3>,
    /// Nearest NDC depth (0 near .. 1 far) over the pixel's samples; `f32::INFINITY` if none.
    pub(crate) depth: Vec<f32>,
    /// Fraction of the pixel's samples covered by any triangle, 0..1.
    pub(crate) coverage: Vec<f32>,
    /// Source triangle covering most samples (ties: earliest sample), or [`NO_TRIANGLE`].
    pub(crate) triangle: Vec<u32>,
}

impl Drop for Frame {
    /// The channels go back to the renderer's pool (`recycle.rs`) for the next frame of this size.
    fn drop(&mut self) {
        super::recycle::give(std::mem::take(&mut self.color));
        super::recycle::give(std::mem::take(&mut self.depth));
        super::recycle::give(std::mem::take(&mut self.coverage));
        super::recycle::give(std::mem::take(&mut self.triangle));
    }
}

impl Frame {
    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }
    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }
    /// Linear RGB per pixel.
    pub fn color(&self) -> &[Vec3] {
        &self.color
    }
    /// Nearest NDC depth per pixel (`f32::INFINITY` where empty).
    pub fn depth(&self) -> &[f32] {
        &self.depth
    }
    /// Covered fraction of samples per pixel.
    pub fn coverage(&self) -> &[f32] {
        &self.coverage
    }
    /// Source triangle id per pixel ([`NO_TRIANGLE`] where empty).
    pub fn triangle_ids(&self) -> &[u32] {
        &self.triangle
    }

    /// The colour as 8-bit sRGB, RGB order (values outside 0..1 are clipped).
    pub fn to_srgb8(&self) -> image::RgbImage {
        crate::image::srgb8_image(self.width as usize, self.height as usize, &self.color)
    }

    /// The colour as linear 32-bit float RGB (for EXR output).
    pub fn to_rgb32f(&self) -> image::Rgb32FImage {
        let v = self.color.iter().flat_map(|c| c.to_array()).collect();
        image::Rgb32FImage::from_raw(self.width, self.height, v)
            .expect("sizes match by construction")
    }
}

/// The pixel size (width, height) of a contact sheet of `count` tiles of `tile` pixels in a grid
/// `columns` wide with `gap`-pixel borders, in 64 bits (no overflow for any `u32` inputs).
pub fn sheet_dimensions(count: u64, columns: u64, tile: (u64, u64), gap: u64) -> (u64, u64) {
    let columns = columns.max(1);
    let rows = count.div_ceil(columns).max(1);
    (columns * (tile.0 + gap) + gap, rows * (tile.1 + gap) + gap)
}

/// `Ok` when a contact sheet of that layout stays within [`crate::limits::SHEET_PIXELS`] (it is
/// held in memory whole), else a usage error that names its size. Callers check before they
/// render the tiles; [`contact_sheet`] checks again.
pub fn check_sheet(count: u64, columns: u64, tile: (u64, u64), gap: u64) -> Result<()> {
    let (w, h) = sheet_dimensions(count, columns, tile, gap);
    match crate::limits::SHEET_PIXELS.refuse(w * h) {
        None if w <= u32::MAX as u64 && h <= u32::MAX as u64 => Ok(()),
        refusal => Err(Error::Usage(format!(
            "a contact sheet of {count} images of {}x{} pixels would be {w}x{h} pixels: {}",
            tile.0,
            tile.1,
            refusal.unwrap_or_else(|| "wider than an image can be".into())
        ))),
    }
}

/// Tile 8-bit images into a grid `columns` wide, in order, with a `gap`-pixel border of `bg`.
/// All images must have the same size; the sheet must pass [`check_sheet`].
pub fn contact_sheet(
    images: &[image::RgbImage],
    columns: u32,
    gap: u32,
    bg: [u8; 3],
) -> Result<image::RgbImage> {
    let columns = columns.max(1);
    let (w, h) = images.first().map_or((1, 1), |i| i.dimensions());
    let count = images.len() as u64;
    check_sheet(count, columns as u64, (w as u64, h as u64), gap as u64)?;
    let (sw, sh) = sheet_dimensions(count, columns as u64, (w as u64, h as u64), gap as u64);
    let mut sheet = image::RgbImage::from_pixel(sw as u32, sh as u32, image::Rgb(bg));
    for (k, img) in images.iter().enumerate() {
        let (c, r) = (k as u32 % columns, k as u32 / columns);
        image::imageops::replace(
            &mut sheet,
            img,
            (gap + c * (w + gap)) as i64,
            (gap + r * (h + gap)) as i64,
        );
    }
    Ok(sheet)
}

impl From<&Frame> for crate::image::LinearImage {
    fn from(f: &Frame) -> crate::image::LinearImage {
        crate::image::LinearImage::new(f.width() as usize, f.height() as usize, f.color().to_vec())
            .expect("a frame has at least one pixel and one colour per pixel")
    }
}
