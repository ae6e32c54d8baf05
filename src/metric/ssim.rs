//! SSIM and MS-SSIM.
//!
//! Based on: Zhou Wang, Alan C. Bovik, Hamid R. Sheikh, Eero P. Simoncelli. Image Quality
//! Assessment: From Error Visibility to Structural Similarity. IEEE TIP 2004 — eq. 13 with the
//! paper's settings: 11×11 circular-symmetric Gaussian window, σ = 1.5, K1 = 0.01, K2 = 0.03,
//! dynamic range L = 1; mean SSIM over the window positions. Zhou Wang, Eero P. Simoncelli, Alan C.
//! Bovik. Multi-Scale Structural Similarity for Image Quality Assessment. Asilomar 2003 — five
//! scales, exponents (0.0448, 0.2856, 0.3001, 0.2363, 0.1333), 2×2 averaging between scales,
//! contrast–structure at every scale and luminance at the coarsest.
//!
//! Decisions: by default SSIM compares the Rec. 709 luma of the sRGB-*encoded* images (what SSIM
//! was designed and validated on); [`SsimInput::LinearLuminance`] compares linear luminance
//! instead. Borders follow scikit-image, the oracle (`reference/oracles/`): Gaussian filtering
//! with mirrored borders (scipy's "reflect"), and the mean taken over the image minus a 5-pixel
//! border, so that only windows fully inside the image count. Arithmetic is `f64`; rows run in
//! parallel and sums are combined in row order.

use rayon::prelude::*;

use super::color::{linear_to_srgb, luminance};
use super::image::{LinearImage, same_size};
use crate::error::{Error, Result};

const K1: f64 = 0.01;
const K2: f64 = 0.03;
const SIGMA: f64 = 1.5;
/// Window radius: scipy's int(truncate·σ + ½) with truncate = 3.5 gives 5 (an 11-tap window).
const RADIUS: usize = 5;
/// MS-SSIM scale exponents (Wang et al. 2003).
const MS_WEIGHTS: [f64; 5] = [0.0448, 0.2856, 0.3001, 0.2363, 0.1333];

/// Which single channel SSIM compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum SsimInput {
    /// Rec. 709 luma of sRGB-encoded values (default).
    #[default]
    SrgbLuma,
    /// Rec. 709 luminance of linear values.
    LinearLuminance,
}

/// A single-channel f64 image.
#[derive(Debug, Clone)]
struct Plane {
    w: usize,
    h: usize,
    v: Vec<f64>,
}

fn plane(img: &LinearImage, input: SsimInput) -> Plane {
    let v = img
        .pixels()
        .par_iter()
        .map(|&c| match input {
            SsimInput::SrgbLuma => {
                0.2126 * linear_to_srgb(c.x) as f64
                    + 0.7152 * linear_to_srgb(c.y) as f64
                    + 0.0722 * linear_to_srgb(c.z) as f64
            }
            SsimInput::LinearLuminance => luminance(c) as f64,
        })
        .collect();
    Plane {
        w: img.width(),
        h: img.height(),
        v,
    }
}

/// scipy's "reflect" border (… c b a | a b c … c b a | a b …), valid for any offset.
fn reflect(i: isize, n: usize) -> usize {
    let n = n as isize;
    let period = 2 * n;
    let m = i.rem_euclid(period);
    (if m < n { m } else { period - 1 - m }) as usize
}

fn kernel() -> [f64; 2 * RADIUS + 1] {
    let mut k = [0.0; 2 * RADIUS + 1];
    for (i, w) in k.iter_mut().enumerate() {
        let x = i as f64 - RADIUS as f64;
        *w = (-0.5 * x * x / (SIGMA * SIGMA)).exp();
    }
    let s: f64 = k.iter().sum();
    k.map(|w| w / s)
}

/// Separable Gaussian blur of several planes at once (same geometry), reflected borders.
fn blur<const N: usize>(
    w: usize,
    h: usize,
    src: impl Fn(usize) -> [f64; N] + Sync,
) -> Vec<[f64; N]> {
    let k = kernel();
    let mut mid = vec![[0.0; N]; w * h];
    mid.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, out) in row.iter_mut().enumerate() {
            let mut acc = [0.0; N];
            for (t, &kw) in k.iter().enumerate() {
                let s = src(y * w + reflect(x as isize + t as isize - RADIUS as isize, w));
                for c in 0..N {
                    acc[c] += kw * s[c];
                }
            }
            *out = acc;
        }
    });
    let mut out = vec![[0.0; N]; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            let mut acc = [0.0; N];
            for (t, &kw) in k.iter().enumerate() {
                let s = mid[reflect(y as isize + t as isize - RADIUS as isize, h) * w + x];
                for c in 0..N {
                    acc[c] += kw * s[c];
                }
            }
            *o = acc;
        }
    });
    out
}

/// Per-pixel SSIM terms: (luminance term l, contrast–structure term cs).
fn terms(a: &Plane, b: &Plane) -> Vec<(f64, f64)> {
    let (c1, c2) = ((K1 * 1.0).powi(2), (K2 * 1.0).powi(2));
    let m = blur::<5>(a.w, a.h, |i| {
        let (x, y) = (a.v[i], b.v[i]);
        [x, y, x * x, y * y, x * y]
    });
    m.par_iter()
        .map(|&[ux, uy, uxx, uyy, uxy]| {
            let (vx, vy, vxy) = (uxx - ux * ux, uyy - uy * uy, uxy - ux * uy);
            let l = (2.0 * ux * uy + c1) / (ux * ux + uy * uy + c1);
            let cs = (2.0 * vxy + c2) / (vx + vy + c2);
            (l, cs)
        })
        .collect()
}

/// Mean over the pixels at least `RADIUS` from every border (rows summed in order).
fn cropped_mean(w: usize, h: usize, v: &[f64]) -> Option<f64> {
    if w <= 2 * RADIUS || h <= 2 * RADIUS {
        return None;
    }
    let rows: Vec<f64> = (RADIUS..h - RADIUS)
        .into_par_iter()
        .map(|y| v[y * w + RADIUS..y * w + w - RADIUS].iter().sum())
        .collect();
    Some(rows.iter().sum::<f64>() / ((w - 2 * RADIUS) * (h - 2 * RADIUS)) as f64)
}

fn too_small(w: usize, h: usize, what: &str) -> Error {
    Error::Usage(format!(
        "{what} needs images of at least {0}x{0} pixels (got {w}x{h}); use FLIP or PSNR for smaller images",
        2 * RADIUS + 1
    ))
}

/// Mean SSIM in [−1, 1] (1 = identical) and, if wanted, the per-pixel SSIM map.
pub fn ssim(
    reference: &LinearImage,
    test: &LinearImage,
    input: SsimInput,
) -> Result<(f64, Vec<f32>)> {
    same_size(reference, test)?;
    let (a, b) = (plane(reference, input), plane(test, input));
    let s: Vec<f64> = terms(&a, &b).iter().map(|&(l, cs)| l * cs).collect();
    let mean = cropped_mean(a.w, a.h, &s).ok_or_else(|| too_small(a.w, a.h, "SSIM"))?;
    Ok((mean, s.iter().map(|&v| v as f32).collect()))
}

/// 2×2 box average (odd trailing row/column dropped), as between MS-SSIM scales.
fn downsample(p: &Plane) -> Plane {
    let (w, h) = (p.w / 2, p.h / 2);
    let mut v = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let i = 2 * y * p.w + 2 * x;
            v.push((p.v[i] + p.v[i + 1] + p.v[i + p.w] + p.v[i + p.w + 1]) * 0.25);
        }
    }
    Plane { w, h, v }
}

/// MS-SSIM in [0, 1] (1 = identical). Needs at least 176×176 pixels (five scales of an 11-tap
/// window). Negative contrast–structure means are clamped to 0 before the power, a common guard.
pub fn ms_ssim(reference: &LinearImage, test: &LinearImage, input: SsimInput) -> Result<f64> {
    same_size(reference, test)?;
    let (mut a, mut b) = (plane(reference, input), plane(test, input));
    let min_side = (2 * RADIUS + 1) << (MS_WEIGHTS.len() - 1);
    if a.w < min_side || a.h < min_side {
        return Err(Error::Usage(format!(
            "MS-SSIM needs images of at least {min_side}x{min_side} pixels (got {}x{}); use SSIM",
            a.w, a.h
        )));
    }
    let mut product = 1.0;
    for (scale, &weight) in MS_WEIGHTS.iter().enumerate() {
        let t = terms(&a, &b);
        let cs: Vec<f64> = t.iter().map(|&(_, cs)| cs).collect();
        let mean_cs = cropped_mean(a.w, a.h, &cs).ok_or_else(|| too_small(a.w, a.h, "MS-SSIM"))?;
        if scale + 1 == MS_WEIGHTS.len() {
            let l: Vec<f64> = t.iter().map(|&(l, _)| l).collect();
            let mean_l =
                cropped_mean(a.w, a.h, &l).ok_or_else(|| too_small(a.w, a.h, "MS-SSIM"))?;
            product *= (mean_l * mean_cs).max(0.0).powf(weight);
        } else {
            product *= mean_cs.max(0.0).powf(weight);
            a = downsample(&a);
            b = downsample(&b);
        }
    }
    Ok(product)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn ramp(w: usize, h: usize, f: impl Fn(usize, usize) -> f32) -> LinearImage {
        LinearImage::new(
            w,
            h,
            (0..w * h).map(|i| Vec3::splat(f(i % w, i / w))).collect(),
        )
        .unwrap()
    }

    #[test]
    fn identical_is_one_and_reflect_matches_scipy() {
        let a = ramp(24, 20, |x, y| ((x * 7 + y * 3) % 11) as f32 / 11.0);
        assert!((ssim(&a, &a, SsimInput::default()).unwrap().0 - 1.0).abs() < 1e-12);
        // scipy reflect extends [a b c] as … c c b a | a b c | c b a a …, so indices -4..7 map
        // to 2 2 1 0 | 0 1 2 | 2 1 0 0.
        let got: Vec<usize> = (-4..7).map(|i| reflect(i, 3)).collect();
        assert_eq!(got, vec![2, 2, 1, 0, 0, 1, 2, 2, 1, 0, 0]);
    }

    #[test]
    fn ms_ssim_falls_with_noise() {
        let a = ramp(192, 192, |x, y| ((x / 8 + y / 8) % 2) as f32 * 0.6 + 0.2);
        let noisy = ramp(192, 192, |x, y| {
            let base = ((x / 8 + y / 8) % 2) as f32 * 0.6 + 0.2;
            base + if (x * 31 + y * 17) % 5 == 0 { 0.1 } else { 0.0 }
        });
        assert!((ms_ssim(&a, &a, SsimInput::default()).unwrap() - 1.0).abs() < 1e-12);
        assert!(ms_ssim(&a, &noisy, SsimInput::default()).unwrap() < 0.999);
    }
}
