//! `Frame`: what a render produces — linear RGB colour, depth, coverage and triangle id per pixel —
//! and its conversions to 8-bit sRGB images.

use glam::Vec3;

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

    /// A `width`×`height` frame on recycled channel buffers (`recycle.rs`): their contents are
    /// a fill value or an earlier frame's pixels, so every pixel must be written before it is
    /// read (the tiles of a render each write all of theirs).
    pub(super) fn recycled(width: u32, height: u32) -> Frame {
        let n = width as usize * height as usize;
        Frame {
            width,
            height,
            color: super::recycle::take(n, Vec3::ZERO),
            depth: super::recycle::take(n, 0.0),
            coverage: super::recycle::take(n, 0.0),
            triangle: super::recycle::take(n, 0),
        }
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

impl From<&Frame> for crate::image::LinearImage {
    fn from(f: &Frame) -> crate::image::LinearImage {
        crate::image::LinearImage::new(f.width() as usize, f.height() as usize, f.color().to_vec())
            .expect("a frame has at least one pixel and one colour per pixel")
    }
}
