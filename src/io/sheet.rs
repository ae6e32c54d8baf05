//! Contact sheets: 8-bit images tiled into one grid image, with the size check that keeps a
//! sheet within what lodeval holds in memory (`limits::SHEET_PIXELS`). Used by `render --sheet`,
//! `eval`'s per-LOD sheets and the paper figures.

use crate::error::{Error, Result};

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
