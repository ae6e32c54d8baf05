//! Mean squared error, RMSE and PSNR on luminance, Lindstrom–Turk's multi-view d_MS, and PSNR
//! as image tools report it (8-bit sRGB, all three channels).
//!
//! Based on: Peter Lindstrom, Greg Turk. Image-Driven Simplification. ACM TOG 2000, eq. 1:
//! d_MS(Y⁰, Y¹) = 1/(l·m·n) Σ_h Σ_i Σ_j (y⁰_hij − y¹_hij)², the mean squared luminance difference
//! over l views of m × n pixels.
//!
//! Decision: "luminance" is Rec. 709 Y of linear RGB (ARCHITECTURE.md, "Colour"), so MSE is in linear
//! luminance units and PSNR uses a peak of 1 (display white).
//!
//! Decision: PSNR saturates at [`PSNR_CEILING_DB`] = 100 dB (an RMS difference of 1e-5 of white,
//! far below one 8-bit step), as libvmaf clips PSNR at 60 dB for 8-bit video: identical images
//! (MSE 0) read 100 dB, so no infinity reaches a CSV, a summary mean or the gate. The `mse` value
//! beside it stays exact (0 for identical images).

use rayon::prelude::*;

use crate::color::luminance;
use crate::error::Result;
use crate::image::{LinearImage, same_size};

/// MSE-family scores of one image pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MseScore {
    /// Mean squared luminance difference (linear luminance², 0 = identical).
    pub mse: f64,
    /// Its square root (linear luminance).
    pub rmse: f64,
    /// 10·log10(1 / MSE) in dB, at most [`PSNR_CEILING_DB`] (identical images read the ceiling).
    pub psnr_db: f64,
}

/// The highest PSNR reported, dB: MSE 1e-10 of white and below, identical images included.
pub const PSNR_CEILING_DB: f64 = 100.0;

impl MseScore {
    /// The scores for a mean squared error (PSNR saturating at [`PSNR_CEILING_DB`]).
    pub fn from_mse(mse: f64) -> MseScore {
        let psnr_db = if mse > 0.0 {
            (10.0 * (1.0 / mse).log10()).min(PSNR_CEILING_DB)
        } else {
            PSNR_CEILING_DB
        };
        MseScore {
            mse,
            rmse: mse.sqrt(),
            psnr_db,
        }
    }
}

/// Sum of squared luminance differences, rows in parallel, combined in row order.
fn sum_squared(a: &LinearImage, b: &LinearImage) -> f64 {
    let w = a.width();
    let rows: Vec<f64> = a
        .pixels()
        .par_chunks(w)
        .zip(b.pixels().par_chunks(w))
        .map(|(ra, rb)| {
            ra.iter()
                .zip(rb)
                .map(|(&p, &q)| {
                    let d = luminance(p) as f64 - luminance(q) as f64;
                    d * d
                })
                .sum()
        })
        .collect();
    rows.iter().sum()
}

/// MSE, RMSE and PSNR of two images of equal size.
pub fn mse(reference: &LinearImage, test: &LinearImage) -> Result<MseScore> {
    same_size(reference, test)?;
    Ok(MseScore::from_mse(
        sum_squared(reference, test) / reference.pixels().len() as f64,
    ))
}

/// PSNR as scikit-image's `peak_signal_noise_ratio`, ffmpeg's `psnr` filter and OpenImageIO's
/// idiff report it for 8-bit images: both images encoded to 8-bit sRGB (rounded, as a PNG
/// stores them), the mean squared difference over every pixel and all three channels, and
/// 10·log10(255² / MSE) in dB, saturating at [`PSNR_CEILING_DB`] for identical encodings.
pub fn psnr_srgb8(reference: &LinearImage, test: &LinearImage) -> Result<f64> {
    same_size(reference, test)?;
    Ok(psnr_srgb8_encoded(&reference.to_srgb8(), &test.to_srgb8()))
}

/// [`psnr_srgb8`] of two images already encoded ([`LinearImage::to_srgb8`]; equal sizes).
pub fn psnr_srgb8_encoded(reference: &image::RgbImage, test: &image::RgbImage) -> f64 {
    debug_assert_eq!(reference.dimensions(), test.dimensions());
    let row = 3 * (reference.width() as usize).max(1);
    let rows: Vec<f64> = reference
        .par_chunks(row)
        .zip(test.par_chunks(row))
        .map(|(ra, rb)| {
            let s: i64 = ra
                .iter()
                .zip(rb)
                .map(|(&p, &q)| {
                    let d = i64::from(p) - i64::from(q);
                    d * d
                })
                .sum();
            s as f64
        })
        .collect();
    let mse = rows.iter().sum::<f64>() / reference.len().max(1) as f64;
    if mse > 0.0 {
        (10.0 * (255.0 * 255.0 / mse).log10()).min(PSNR_CEILING_DB)
    } else {
        PSNR_CEILING_DB
    }
}

/// Lindstrom–Turk's d_MS over a set of views (eq. 1): the mean squared luminance difference over
/// all pixels of all views. Every pair must have equal sizes; views may differ in size from each other.
pub fn d_ms(pairs: &[(&LinearImage, &LinearImage)]) -> Result<f64> {
    let mut sum = 0.0;
    let mut count = 0usize;
    for (a, b) in pairs {
        same_size(a, b)?;
        sum += sum_squared(a, b);
        count += a.pixels().len();
    }
    Ok(if count == 0 { 0.0 } else { sum / count as f64 })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn known_values() {
        // Luminance 0 vs 0.5 everywhere: MSE 0.25, PSNR = 10·log10(4) ≈ 6.0206 dB.
        let a = LinearImage::new(2, 2, vec![Vec3::ZERO; 4]).unwrap();
        let b = LinearImage::new(2, 2, vec![Vec3::splat(0.5); 4]).unwrap();
        let s = mse(&a, &b).unwrap();
        assert!((s.mse - 0.25).abs() < 1e-7 && (s.psnr_db - 6.020_599_9).abs() < 1e-5);
        assert_eq!(mse(&a, &a).unwrap().psnr_db, PSNR_CEILING_DB);
        // d_MS over two views weights pixels, not views: (4·0.25 + 4·0) / 8.
        assert!((d_ms(&[(&a, &b), (&a, &a)]).unwrap() - 0.125).abs() < 1e-7);
    }
}
