//! Stage 6 of the VDP: spatial summation — the masked difference image pooled into one number, and
//! into a map of where the difference is seen.
//!
//! Based on: Andrew Watson, Albert Ahumada. A standard model for foveal detection of spatial
//! contrast. Journal of Vision 5(9) 2005 (Minkowski summation over space, in units of visual
//! angle, so that the prediction does not depend on the pixel size: S = Σ_x |d(x)|^β · Δx·Δy with
//! Δx·Δy the pixel's area in deg²); John Robson, Norma Graham 1981 (the same sum as probability
//! summation over detectors).
//!
//! Decisions. The map is, per pixel, the detection probability of the difference within a Gaussian
//! neighbourhood of σ = [`MAP_WINDOW_DEG`] (its weights have peak 1, so no pixel's value exceeds
//! the whole image's probability): a heat map of where a viewer would see something, not of the
//! raw difference. The Gaussian is three box filters (Wells 1986), each a running sum in f64.
//! Sums run per row and rows are added in index order, so the result does not depend on the
//! thread count.

use rayon::prelude::*;

use super::bands::Plane;
use super::psychometric;

/// σ of the map's neighbourhood, degrees of visual angle (7.5 arcmin; 8 pixels at 67 ppd).
pub const MAP_WINDOW_DEG: f64 = 0.125;

/// |d|^β per pixel times the pixel's area in deg².
fn density(d: &Plane, ppd: f64, beta: f64) -> Vec<f64> {
    let area = 1.0 / (ppd * ppd);
    d.v.par_iter()
        .map(|&v| (v.abs() as f64).powf(beta) * area)
        .collect()
}

/// S = Σ |d|^β · pixel area (deg²), rows in index order; and the per-pixel densities.
pub(crate) fn minkowski(d: &Plane, ppd: f64, beta: f64) -> (f64, Vec<f64>) {
    let e = density(d, ppd, beta);
    let rows: Vec<f64> = e.par_chunks(d.w).map(|r| r.iter().sum()).collect();
    (rows.iter().sum(), e)
}

/// One box filter of odd width `2r + 1` along lines of `n` samples with stride 1, in place
/// (clamped borders), divided by the width.
fn box_line(line: &mut [f64], r: usize, tmp: &mut Vec<f64>) {
    let n = line.len();
    tmp.clear();
    tmp.extend_from_slice(line);
    let at = |i: isize| tmp[i.clamp(0, n as isize - 1) as usize];
    let width = (2 * r + 1) as f64;
    let mut acc: f64 = (-(r as isize)..=r as isize).map(at).sum();
    for (i, out) in line.iter_mut().enumerate() {
        *out = acc / width;
        let i = i as isize;
        acc += at(i + r as isize + 1) - at(i - r as isize);
    }
}

/// Columns per block of [`local_sums`]' vertical pass.
const COLUMN_BLOCK: usize = 64;

/// [`box_line`] down every column of `src` (`width` columns, row-major) at once, into `dst`.
fn box_columns(src: &[f64], dst: &mut [f64], width: usize, r: usize) {
    let h = src.len() / width;
    let row = |i: isize| {
        let y = i.clamp(0, h as isize - 1) as usize;
        &src[y * width..(y + 1) * width]
    };
    let r = r as isize;
    let mut acc: Vec<f64> = row(-r).to_vec();
    for i in -r + 1..=r {
        for (a, &s) in acc.iter_mut().zip(row(i)) {
            *a += s;
        }
    }
    let size = (2 * r + 1) as f64;
    for (y, out) in dst.chunks_exact_mut(width).enumerate() {
        let y = y as isize;
        for (((o, a), &add), &sub) in out
            .iter_mut()
            .zip(&mut acc)
            .zip(row(y + r + 1))
            .zip(row(y - r))
        {
            *o = *a / size;
            *a += add - sub;
        }
    }
}

/// Per pixel, the detection probability and the size in JND (with exponent `beta`) of the
/// difference around it: the same windowed sum read on both scales.
pub(crate) fn probability_and_jnd_maps(
    e: &[f64],
    w: usize,
    h: usize,
    ppd: f64,
    beta: f64,
) -> (Vec<f32>, Vec<f32>) {
    let sums = local_sums(e, w, h, ppd);
    let p = sums
        .par_iter()
        .map(|&s| psychometric::probability(s) as f32)
        .collect();
    let j = sums
        .par_iter()
        .map(|&s| psychometric::jnd(s, beta) as f32)
        .collect();
    (p, j)
}

/// The pooled sum S within the Gaussian neighbourhood of each pixel (peak weight 1).
fn local_sums(e: &[f64], w: usize, h: usize, ppd: f64) -> Vec<f64> {
    let sigma = MAP_WINDOW_DEG * ppd;
    // Three boxes of width 2r+1 have variance 3·((2r+1)² − 1)/12 = r(r+1); r(r+1) ≈ σ².
    let r = ((0.25 + sigma * sigma).sqrt() - 0.5).round().max(0.0) as usize;
    // Scale so that the kernel's peak is 1: the 1-D triple box peaks at its centre value.
    let peak = {
        let width = 2 * r + 1;
        let mut k = vec![1.0f64];
        for _ in 0..3 {
            let mut next = vec![0.0; k.len() + width - 1];
            for (i, a) in k.iter().enumerate() {
                for n in &mut next[i..i + width] {
                    *n += a / width as f64;
                }
            }
            k = next;
        }
        k[k.len() / 2]
    };
    let scale = 1.0 / (peak * peak);
    let mut v = e.to_vec();
    v.par_chunks_mut(w).for_each_init(Vec::new, |tmp, row| {
        for _ in 0..3 {
            box_line(row, r, tmp);
        }
    });
    // The vertical boxes on blocks of columns, a row of the block at a time (the same sums per
    // column as `box_line`'s, in the same order, without reading the image column-wise).
    let blocks: Vec<Vec<f64>> = (0..w.div_ceil(COLUMN_BLOCK))
        .into_par_iter()
        .map(|b| {
            let (x0, x1) = (b * COLUMN_BLOCK, ((b + 1) * COLUMN_BLOCK).min(w));
            let mut cur: Vec<f64> = (0..h)
                .flat_map(|y| v[y * w + x0..y * w + x1].iter().copied())
                .collect();
            let mut next = vec![0.0; cur.len()];
            for _ in 0..3 {
                box_columns(&cur, &mut next, x1 - x0, r);
                std::mem::swap(&mut cur, &mut next);
            }
            cur
        })
        .collect();
    let mut out = vec![0.0f64; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            let windowed = if r == 0 {
                e[y * w + x]
            } else {
                let (b, i) = (x / COLUMN_BLOCK, x % COLUMN_BLOCK);
                let bw = COLUMN_BLOCK.min(w - b * COLUMN_BLOCK);
                blocks[b][y * bw + i] * scale
            };
            *o = windowed;
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_jnd_map_is_the_probability_map_on_the_jnd_scale() {
        let (w, h) = (40, 30);
        let mut e = vec![0.0f64; w * h];
        e[10 * w + 12] = 3e-3;
        e[20 * w + 30] = 5.0;
        let beta = 2.8;
        let (p, j) = probability_and_jnd_maps(&e, w, h, 67.0, beta);
        for (&p, &j) in p.iter().zip(&j) {
            // P = 1 − exp(−k·J^β): the same windowed sum read twice.
            let back = psychometric::probability((j as f64).powf(beta));
            assert!((back - p as f64).abs() < 1e-5, "{p} {j}");
        }
        // Where the probability saturates the JND still grows.
        let strong = j.iter().cloned().fold(0.0, f32::max);
        assert!(strong > 1.0, "{strong}");
    }

    #[test]
    fn pooling_is_in_degrees_not_pixels() {
        // The same physical pattern at twice the pixel density has four times the pixels, each a
        // quarter of the area: the same sum.
        let plane = |n: usize| Plane {
            w: n,
            h: n,
            v: vec![0.5; n * n],
        };
        let (a, _) = minkowski(&plane(32), 60.0, 3.0);
        let (b, _) = minkowski(&plane(64), 120.0, 3.0);
        assert!((a - b).abs() < 1e-12 * a, "{a} {b}");
        assert!((a - 0.125 * (32.0f64 / 60.0).powi(2)).abs() < 1e-12);
    }

    #[test]
    fn the_map_never_exceeds_the_whole_image_probability() {
        let (w, h) = (48, 40);
        let mut d = Plane {
            w,
            h,
            v: vec![0.0; w * h],
        };
        // Two points, small enough that the probability is far from saturating.
        d.v[20 * w + 30] = 4.0;
        d.v[5 * w + 3] = 2.0;
        let (s, e) = minkowski(&d, 67.0, 2.8);
        let map = probability_and_jnd_maps(&e, w, h, 67.0, 2.8).0;
        let p = psychometric::probability(s) as f32;
        let max = map.iter().cloned().fold(0.0, f32::max);
        assert!(max <= p + 1e-6 && max > 0.5 * p, "{max} {p}");
        // Far from both points the map is near 0.
        assert!(map[39 * w + 47] < 0.05 * p);
    }
}
