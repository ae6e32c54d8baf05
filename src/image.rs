//! `LinearImage`: the input every metric takes — linear RGB `f32`, row-major, top row first — and
//! `ErrorMap`, a per-pixel score. Metrics work on any two images of equal size, rendered or loaded.

use glam::Vec3;

use crate::color::srgb8_to_linear_table;
use crate::error::{Error, Result};

/// A linear-light RGB image.
///
/// # Guarantees
/// - `width, height >= 1` and `pixels().len() == width * height`.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearImage {
    width: usize,
    height: usize,
    pixels: Vec<Vec3>,
}

impl LinearImage {
    /// An image from linear RGB pixels; `None` if the sizes disagree or either is zero.
    pub fn new(width: usize, height: usize, pixels: Vec<Vec3>) -> Option<LinearImage> {
        (width >= 1 && height >= 1 && pixels.len() == width * height).then_some(LinearImage {
            width,
            height,
            pixels,
        })
    }

    /// Decode 8-bit sRGB RGB bytes (row-major) to linear light.
    pub fn from_srgb8(width: usize, height: usize, rgb: &[u8]) -> Option<LinearImage> {
        let lut = srgb8_to_linear_table();
        let pixels = rgb
            .chunks_exact(3)
            .map(|c| Vec3::new(lut[c[0] as usize], lut[c[1] as usize], lut[c[2] as usize]))
            .collect();
        LinearImage::new(width, height, pixels)
    }

    /// Load a PNG/JPEG/EXR file: 8-bit files are sRGB-decoded, float files taken as linear.
    /// Only a regular file of at most [`crate::limits::IMAGE_BYTES`] is read, decoding is bounded
    /// by the `image` crate's default limits, and a float image with a NaN or infinite pixel is
    /// refused (a metric would turn it into NaN scores).
    pub fn load(path: &std::path::Path) -> Result<LinearImage> {
        let fix = "give a PNG, JPEG or EXR file";
        let bytes = crate::io::read_input(path, "image", crate::limits::IMAGE_BYTES, fix)?;
        let img = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| Error::input(path, format!("cannot read the image: {e}"), fix))?
            .decode()
            .map_err(|e| Error::input(path, format!("cannot read the image: {e}"), fix))?;
        let (w, h) = (img.width() as usize, img.height() as usize);
        let out = match img {
            image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_) => {
                let f = img.into_rgb32f();
                if let Some((i, _)) = f
                    .pixels()
                    .enumerate()
                    .find(|(_, p)| p.0.iter().any(|c| !c.is_finite()))
                {
                    return Err(Error::input_at(
                        path,
                        crate::error::Location::Element(format!("pixel ({}, {})", i % w, i / w)),
                        "the pixel is NaN or infinite, so no metric can score the image",
                        "re-export the image with finite values (clamp or fill the bad pixels)",
                    ));
                }
                LinearImage::new(w, h, f.pixels().map(|p| Vec3::from(p.0)).collect())
            }
            other => LinearImage::from_srgb8(w, h, other.into_rgb8().as_raw()),
        };
        out.ok_or_else(|| {
            Error::input(
                path,
                format!("the image has zero size ({w}x{h})"),
                "give a non-empty image",
            )
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }
    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }
    /// Linear RGB pixels.
    pub fn pixels(&self) -> &[Vec3] {
        &self.pixels
    }

    /// The image as 8-bit sRGB, RGB order (values outside 0..1 clipped), as a PNG stores it.
    pub fn to_srgb8(&self) -> image::RgbImage {
        srgb8_image(self.width, self.height, &self.pixels)
    }

    /// The object in a render on a plain background: the pixels that differ from the colour all
    /// four corners share. `None` when the corners differ (not a render on a plain background) or
    /// nothing differs.
    pub fn silhouette(&self) -> Option<Silhouette> {
        let (w, h) = (self.width, self.height);
        let bg = self.pixels[0];
        let corners = [w - 1, (h - 1) * w, h * w - 1];
        if corners
            .iter()
            .any(|&i| (self.pixels[i] - bg).abs().max_element() > 1e-3)
        {
            return None;
        }
        let (mut n, mut sx, mut sy) = (0usize, 0f64, 0f64);
        for (i, p) in self.pixels.iter().enumerate() {
            if (*p - bg).abs().max_element() > 1e-3 {
                n += 1;
                sx += (i % w) as f64 + 0.5;
                sy += (i / w) as f64 + 0.5;
            }
        }
        (n > 0).then(|| Silhouette {
            area: n,
            centroid: (sx / n as f64, sy / n as f64),
        })
    }
}

/// Where an object sits in a render: [`LinearImage::silhouette`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Silhouette {
    /// Pixels that are not background.
    pub area: usize,
    /// Their mean position (x, y), pixels from the top-left corner.
    pub centroid: (f64, f64),
}

impl Silhouette {
    /// Whether `other` is the same object framed differently: its centre moved by more than 2 %
    /// of the object's size (√area), or its area changed by more than 10 % (a scale of ±5 %).
    /// A simplification changes a silhouette by a few pixels along its outline; a render framed
    /// by another bounding sphere moves and scales all of it. Returns the shift in pixels and
    /// the area ratio when misframed.
    pub fn misframed(&self, other: &Silhouette) -> Option<(f64, f64)> {
        let size = (self.area as f64).sqrt();
        let shift = (self.centroid.0 - other.centroid.0).hypot(self.centroid.1 - other.centroid.1);
        let ratio = other.area as f64 / self.area as f64;
        (shift > 0.02 * size || !(0.9..=1.1).contains(&ratio)).then_some((shift, ratio))
    }
}

/// `width` × `height` linear RGB pixels (row-major) as 8-bit sRGB, RGB order, values outside
/// 0..1 clipped ([`crate::color::linear_to_srgb8`]): the one encoding of every 8-bit output.
/// Rows are encoded in parallel.
pub fn srgb8_image(width: usize, height: usize, pixels: &[Vec3]) -> image::RgbImage {
    use rayon::prelude::*;
    assert_eq!(pixels.len(), width * height, "one colour per pixel");
    let mut img = image::RgbImage::new(width as u32, height as u32);
    img.par_chunks_mut(3 * width.max(1))
        .zip(pixels.par_chunks(width.max(1)))
        .for_each(|(bytes, row)| {
            for (px, c) in bytes.chunks_exact_mut(3).zip(row) {
                px.copy_from_slice(&c.to_array().map(crate::color::linear_to_srgb8));
            }
        });
    img
}

/// A per-pixel error, row-major, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorMap {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// One value per pixel, in the metric's units.
    pub values: Vec<f32>,
}

/// Check that two images can be compared.
pub(crate) fn same_size(a: &LinearImage, b: &LinearImage) -> Result<()> {
    same_dims((a.width, a.height), (b.width, b.height))
}

/// Check that two (width, height) pairs agree, with the message every metric gives.
pub(crate) fn same_dims(a: (usize, usize), b: (usize, usize)) -> Result<()> {
    if a != b {
        return Err(Error::Usage(format!(
            "the images differ in size ({}x{} vs {}x{}); render or crop them to the same size",
            a.0, a.1, b.0, b.1
        )));
    }
    Ok(())
}
