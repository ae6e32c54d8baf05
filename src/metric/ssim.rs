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
//! border, so that only windows fully inside the image count. The local moments are filtered in
//! `f32` on values centred at 0.5 (no cancellation in E\[x²\] − E\[x\]²; the oracle pairs agree to
//! < 5e-7) and combined in `f64`; bands of rows run in parallel and sums are combined in row order.

use std::borrow::Cow;

use rayon::prelude::*;

use crate::color::{linear_to_srgb_fast, luminance};
use crate::error::{Error, Result};
use crate::image::{LinearImage, same_size};

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

/// A single-channel image. f32 is enough for values in [0, 1] (the moments are accumulated
/// centred, see `terms`), and half the memory of f64 keeps the per-call allocation small.
#[derive(Debug, Clone)]
struct Plane {
    w: usize,
    h: usize,
    v: Vec<f32>,
}

fn plane(img: &LinearImage, input: SsimInput) -> Plane {
    let v = img
        .pixels()
        .par_iter()
        .map(|&c| match input {
            SsimInput::SrgbLuma => {
                (0.2126 * linear_to_srgb_fast(c.x) as f64
                    + 0.7152 * linear_to_srgb_fast(c.y) as f64
                    + 0.0722 * linear_to_srgb_fast(c.z) as f64) as f32
            }
            SsimInput::LinearLuminance => luminance(c),
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

/// Rows per parallel band of the fused filter-and-score pass.
const BAND: usize = 64;

/// Per-pixel SSIM terms, computed band by band: for each band of output rows, the five local
/// moments (x, y, x², y², xy) are Gaussian-filtered horizontally for the band plus its ±5-row halo
/// (reflected at the image border, scipy's "reflect"), then vertically, and turned into the
/// luminance term l and the contrast–structure term cs right away. No full-size moment images are
/// ever allocated (an earlier version spent more time in page faults than in arithmetic).
/// Returns the SSIM map (if `want_map`) and, per row, the sums of (l·cs, cs, l) over the columns
/// at least `RADIUS` from the left and right borders.
fn terms(a: &Plane, b: &Plane, want_map: bool) -> (Vec<f32>, Vec<[f64; 3]>) {
    let (w, h) = (a.w, a.h);
    let (c1, c2) = ((K1 * 1.0).powi(2), (K2 * 1.0).powi(2));
    let k = kernel().map(|v| v as f32);
    // Scratch buffers are reused across the bands a worker takes (`map_init`): allocating them per
    // band put every band's half-megabyte buffer through mmap and page faults.
    let bands: Vec<(Vec<f32>, Vec<[f64; 3]>)> = (0..h.div_ceil(BAND))
        .into_par_iter()
        .map_init(
            || (Vec::new(), Vec::new(), Vec::new()),
            |(mid, padded, acc): &mut (Vec<f32>, Vec<f32>, Vec<f32>), band| {
                let (y0, y1) = (band * BAND, ((band + 1) * BAND).min(h));
                // Horizontal pass over the band and its halo; each row padded once.
                let rows = y1 - y0 + 2 * RADIUS;
                mid.clear();
                mid.resize(rows * w * 5, 0.0);
                padded.clear();
                padded.resize((w + 2 * RADIUS) * 5, 0.0);
                let columns: Vec<usize> = (0..w + 2 * RADIUS)
                    .map(|i| reflect(i as isize - RADIUS as isize, w))
                    .collect();
                for r in 0..rows {
                    let y = reflect((y0 + r) as isize - RADIUS as isize, h);
                    for (p, &col) in padded.chunks_exact_mut(5).zip(&columns) {
                        let idx = y * w + col;
                        // Centred on the middle of the range: the moments are accumulated in f32 (twice
                        // the SIMD width of f64), and centring keeps E\[x²\] − E\[x\]² free of cancellation.
                        let (x, yv) = (a.v[idx] - 0.5, b.v[idx] - 0.5);
                        p.copy_from_slice(&[x, yv, x * x, yv * yv, x * yv]);
                    }
                    let out = &mut mid[r * w * 5..(r + 1) * w * 5];
                    for (t, &kw) in k.iter().enumerate() {
                        for (o, &s) in out.iter_mut().zip(&padded[t * 5..t * 5 + w * 5]) {
                            *o += kw * s;
                        }
                    }
                }
                // Vertical pass and the SSIM terms, row by row.
                let mut map = Vec::with_capacity(if want_map { (y1 - y0) * w } else { 0 });
                let mut sums = Vec::with_capacity(y1 - y0);
                acc.clear();
                acc.resize(w * 5, 0.0);
                for y in y0..y1 {
                    acc.fill(0.0);
                    for (t, &kw) in k.iter().enumerate() {
                        let r = y - y0 + t;
                        for (o, &s) in acc.iter_mut().zip(&mid[r * w * 5..(r + 1) * w * 5]) {
                            *o += kw * s;
                        }
                    }
                    let mut row_sum = [0.0f64; 3];
                    for (x, m) in acc.chunks_exact(5).enumerate() {
                        let [cx, cy, uxx, uyy, uxy] = [m[0], m[1], m[2], m[3], m[4]].map(f64::from);
                        let (vx, vy, vxy) = (uxx - cx * cx, uyy - cy * cy, uxy - cx * cy);
                        let (ux, uy) = (cx + 0.5, cy + 0.5);
                        let l = (2.0 * ux * uy + c1) / (ux * ux + uy * uy + c1);
                        let cs = (2.0 * vxy + c2) / (vx + vy + c2);
                        if want_map {
                            map.push((l * cs) as f32);
                        }
                        if x >= RADIUS && x + RADIUS < w {
                            row_sum[0] += l * cs;
                            row_sum[1] += cs;
                            row_sum[2] += l;
                        }
                    }
                    sums.push(row_sum);
                }
                (map, sums)
            },
        )
        .collect();
    let mut map = Vec::with_capacity(if want_map { w * h } else { 0 });
    let mut sums = Vec::with_capacity(h);
    for (m, s) in bands {
        map.extend(m);
        sums.extend(s);
    }
    (map, sums)
}

/// Means of (l·cs, cs, l) over the pixels at least `RADIUS` from every border (rows in order);
/// `None` when no such pixel exists.
fn cropped_means(w: usize, h: usize, sums: &[[f64; 3]]) -> Option<[f64; 3]> {
    if w <= 2 * RADIUS || h <= 2 * RADIUS {
        return None;
    }
    let mut total = [0.0; 3];
    for s in &sums[RADIUS..h - RADIUS] {
        for c in 0..3 {
            total[c] += s[c];
        }
    }
    let n = ((w - 2 * RADIUS) * (h - 2 * RADIUS)) as f64;
    Some(total.map(|t| t / n))
}

fn too_small(w: usize, h: usize, what: &str) -> Error {
    Error::Usage(format!(
        "{what} needs images of at least {0}x{0} pixels (got {w}x{h}); use FLIP or PSNR for smaller images",
        2 * RADIUS + 1
    ))
}

/// Mean SSIM in [−1, 1] (1 = identical) and the per-pixel SSIM map.
pub fn ssim(
    reference: &LinearImage,
    test: &LinearImage,
    input: SsimInput,
) -> Result<(f64, Vec<f32>)> {
    same_size(reference, test)?;
    let s = compare_prepared(
        &prepare(reference, input),
        &prepare(test, input),
        true,
        false,
    )?;
    Ok((s.mean.unwrap_or_default(), s.map))
}

/// One image's SSIM channel (see [`SsimInput`]), ready to be compared with several others.
#[derive(Debug, Clone)]
pub struct SsimPrepared(Plane);

/// An image's SSIM channel.
pub fn prepare(image: &LinearImage, input: SsimInput) -> SsimPrepared {
    SsimPrepared(plane(image, input))
}

/// What [`compare_prepared`] found.
#[derive(Debug, Clone, Default)]
pub struct SsimScores {
    /// Mean SSIM, where asked for.
    pub mean: Option<f64>,
    /// The per-pixel SSIM map (empty unless SSIM was asked for).
    pub map: Vec<f32>,
    /// MS-SSIM, where asked for.
    pub ms: Option<f64>,
}

/// SSIM (mean and map) and MS-SSIM of two prepared channels, as asked for: MS-SSIM's first scale
/// is SSIM's own pass over the full-size images, done once for both.
pub fn compare_prepared(
    reference: &SsimPrepared,
    test: &SsimPrepared,
    want_ssim: bool,
    want_ms: bool,
) -> Result<SsimScores> {
    let (a, b) = (&reference.0, &test.0);
    crate::image::same_dims((a.w, a.h), (b.w, b.h))?;
    let min_side = (2 * RADIUS + 1) << (MS_WEIGHTS.len() - 1);
    if want_ms && (a.w < min_side || a.h < min_side) {
        return Err(Error::Usage(format!(
            "MS-SSIM needs images of at least {min_side}x{min_side} pixels (got {}x{}); use SSIM",
            a.w, a.h
        )));
    }
    if !want_ssim && !want_ms {
        return Ok(SsimScores::default());
    }
    let (map, sums) = terms(a, b, want_ssim);
    let mut out = SsimScores {
        map,
        ..SsimScores::default()
    };
    if want_ssim {
        let [mean, _, _] =
            cropped_means(a.w, a.h, &sums).ok_or_else(|| too_small(a.w, a.h, "SSIM"))?;
        out.mean = Some(mean);
    }
    if want_ms {
        out.ms = Some(ms_ssim_from(a, b, &sums)?);
    }
    Ok(out)
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
    let s = compare_prepared(
        &prepare(reference, input),
        &prepare(test, input),
        false,
        true,
    )?;
    Ok(s.ms.unwrap_or_default())
}

/// MS-SSIM of `a` and `b` given the row sums of their full-size scale (`terms`).
fn ms_ssim_from(a: &Plane, b: &Plane, first: &[[f64; 3]]) -> Result<f64> {
    let mut product = 1.0;
    let (mut a, mut b) = (Cow::Borrowed(a), Cow::Borrowed(b));
    for (scale, &weight) in MS_WEIGHTS.iter().enumerate() {
        let sums = if scale == 0 {
            Cow::Borrowed(first)
        } else {
            Cow::Owned(terms(&a, &b, false).1)
        };
        let [_, mean_cs, mean_l] =
            cropped_means(a.w, a.h, &sums).ok_or_else(|| too_small(a.w, a.h, "MS-SSIM"))?;
        if scale + 1 == MS_WEIGHTS.len() {
            product *= (mean_l * mean_cs).max(0.0).powf(weight);
        } else {
            product *= mean_cs.max(0.0).powf(weight);
            a = Cow::Owned(downsample(&a));
            b = Cow::Owned(downsample(&b));
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
