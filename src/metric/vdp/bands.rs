//! Stage 3 of the VDP: the octave bands — Laplacian and Gaussian pyramids, and the collapse that
//! puts (masked) bands back together into one image.
//!
//! Based on: Peter Burt, Edward Adelson. The Laplacian Pyramid as a Compact Image Code. IEEE
//! Trans. Communications 1983: the 5-tap binomial kernel w = (1, 4, 6, 4, 1)/16, REDUCE (blur,
//! keep every second sample) and EXPAND (insert zeros, blur with 4·w, i.e. the polyphase form
//! even = (q[i−1] + 6·q[i] + q[i+1])/8, odd = (q[i] + q[i+1])/2); band k = G_k − EXPAND(G_{k+1}).
//!
//! Each band k keeps its own resolution (2^k pixels per sample) and is centred on
//! ρ_k = 0.375 · ppd / 2^k cycles per degree (the middle of the octave [¼, ½] cycles per sample).
//! The decomposition is exact: collapsing the bands and the residual with the same EXPAND gives
//! the input back to rounding, so with no masking the VDP's detection stage sees the CSF-filtered
//! image itself (the single-channel model that ModelFest calibrates), and masking acts band by
//! band. Decision: no orientation channels. The previous four cos²-weighted channels split each
//! sample by its local gradient direction, a non-linear split that is ill-conditioned at band
//! extrema and broke the exact collapse; masking here is within a band across orientations
//! (Foley 1994's broadly tuned gain pool), and the oblique effect sits in the CSF filter.
//! Borders are mirrored (… c b | a b c | b a …).

use rayon::prelude::*;

/// A single-channel image, row-major.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Plane {
    pub w: usize,
    pub h: usize,
    pub v: Vec<f32>,
}

/// Mirrored index (… c b | a b c | b a …), valid for any offset.
fn reflect(i: isize, n: usize) -> usize {
    if n == 1 {
        return 0;
    }
    let period = 2 * (n as isize - 1);
    let m = i.rem_euclid(period);
    (if m < n as isize { m } else { period - m }) as usize
}

const W0: f32 = 6.0 / 16.0;
const W1: f32 = 4.0 / 16.0;
const W2: f32 = 1.0 / 16.0;

/// One output sample of the 5-tap binomial filter centred on input index `c` of a line read
/// through `at`.
#[inline]
fn tap5(at: impl Fn(isize) -> f32, c: isize) -> f32 {
    W2 * (at(c - 2) + at(c + 2)) + W1 * (at(c - 1) + at(c + 1)) + W0 * at(c)
}

/// Burt–Adelson REDUCE: blur with the binomial kernel, keep every second sample (the even ones),
/// to ⌈w/2⌉ × ⌈h/2⌉. Only the kept samples are filtered.
pub(crate) fn reduce(p: &Plane) -> Plane {
    let (w, h) = (p.w.div_ceil(2), p.h.div_ceil(2));
    // Horizontal pass at the kept columns, all rows.
    let mut mid = vec![0.0f32; w * p.h];
    mid.par_chunks_mut(w).enumerate().for_each(|(y, out)| {
        let row = &p.v[y * p.w..(y + 1) * p.w];
        let n = p.w;
        for (i, o) in out.iter_mut().enumerate() {
            let c = 2 * i as isize;
            *o = if c >= 2 && (c as usize) + 2 < n {
                let c = c as usize;
                W2 * (row[c - 2] + row[c + 2]) + W1 * (row[c - 1] + row[c + 1]) + W0 * row[c]
            } else {
                tap5(|j| row[reflect(j, n)], c)
            };
        }
    });
    // Vertical pass at the kept rows.
    let mut v = vec![0.0f32; w * h];
    v.par_chunks_mut(w).enumerate().for_each(|(j, out)| {
        let c = 2 * j as isize;
        let rows: [&[f32]; 5] = std::array::from_fn(|t| {
            let r = reflect(c + t as isize - 2, p.h);
            &mid[r * w..(r + 1) * w]
        });
        for (x, o) in out.iter_mut().enumerate() {
            *o = W2 * (rows[0][x] + rows[4][x]) + W1 * (rows[1][x] + rows[3][x]) + W0 * rows[2][x];
        }
    });
    Plane { w, h, v }
}

/// EXPAND of one line of `n_out` samples from the coarse line `q` (length ⌈n_out/2⌉).
#[inline]
fn expand_line(q: &[f32], out: &mut [f32]) {
    let n = q.len();
    let at = |i: isize| q[reflect(i, n)];
    for (x, o) in out.iter_mut().enumerate() {
        let i = (x / 2) as isize;
        *o = if x % 2 == 0 {
            (at(i - 1) + at(i + 1)) * 0.125 + at(i) * 0.75
        } else {
            (at(i) + at(i + 1)) * 0.5
        };
    }
}

/// Burt–Adelson EXPAND of `q` to `w × h` (which must reduce to `q`'s size).
pub(crate) fn expand(q: &Plane, w: usize, h: usize) -> Plane {
    debug_assert!(w.div_ceil(2) == q.w && h.div_ceil(2) == q.h);
    // Horizontal, at the coarse rows.
    let mut mid = vec![0.0f32; w * q.h];
    mid.par_chunks_mut(w)
        .enumerate()
        .for_each(|(y, out)| expand_line(&q.v[y * q.w..(y + 1) * q.w], out));
    // Vertical: fine row y from coarse rows y/2 (even y) or y/2, y/2+1 (odd y).
    let mut v = vec![0.0f32; w * h];
    v.par_chunks_mut(w).enumerate().for_each(|(y, out)| {
        let i = (y / 2) as isize;
        let row = |k: isize| {
            let r = reflect(k, q.h);
            &mid[r * w..(r + 1) * w]
        };
        if y % 2 == 0 {
            let (a, b, c) = (row(i - 1), row(i), row(i + 1));
            for x in 0..w {
                out[x] = (a[x] + c[x]) * 0.125 + b[x] * 0.75;
            }
        } else {
            let (a, b) = (row(i), row(i + 1));
            for x in 0..w {
                out[x] = (a[x] + b[x]) * 0.5;
            }
        }
    });
    Plane { w, h, v }
}

/// Smallest side a level must have to be split further.
const MIN_SIDE: usize = 8;

/// Laplacian pyramid of `p`: up to `max_levels` bands, finest first, and the low-pass residual
/// (the Gaussian level below the last band).
pub(crate) fn laplacian(p: &Plane, max_levels: usize) -> (Vec<Plane>, Plane) {
    let mut bands = Vec::new();
    let mut g = p.clone();
    while bands.len() < max_levels && g.w >= MIN_SIDE && g.h >= MIN_SIDE {
        let next = reduce(&g);
        let up = expand(&next, g.w, g.h);
        let mut lap = g;
        lap.v.par_iter_mut().zip(&up.v).for_each(|(a, b)| *a -= b);
        bands.push(lap);
        g = next;
    }
    (bands, g)
}

/// Gaussian pyramid of `p`: level 0 is `p`, then `levels` REDUCEs (or until a side is too small
/// to reduce, the last level repeated so that every index up to `levels` exists).
pub(crate) fn gaussian(p: &Plane, levels: usize) -> Vec<Plane> {
    let mut out = vec![p.clone()];
    for _ in 0..levels {
        let last = out.last().expect("level 0 exists");
        let next = if last.w >= 2 && last.h >= 2 {
            reduce(last)
        } else {
            last.clone()
        };
        out.push(next);
    }
    out
}

/// The image whose Laplacian pyramid is `bands` (finest first) over `residual`.
pub(crate) fn collapse(bands: Vec<Plane>, residual: Plane) -> Plane {
    let mut g = residual;
    for mut band in bands.into_iter().rev() {
        let up = expand(&g, band.w, band.h);
        band.v.par_iter_mut().zip(&up.v).for_each(|(a, b)| *a += b);
        g = band;
    }
    g
}

#[cfg(test)]
mod tests {
    use super::*;

    fn noise(w: usize, h: usize) -> Plane {
        let mut s = 0x9e37_79b9_u32;
        let v = (0..w * h)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 17;
                s ^= s << 5;
                (s % 1000) as f32 / 1000.0
            })
            .collect();
        Plane { w, h, v }
    }

    #[test]
    fn collapse_inverts_the_laplacian_pyramid() {
        // Odd and even sizes: the decomposition is exact by construction (the same EXPAND goes
        // both ways), so only rounding separates the round trip from the input.
        for (w, h) in [(64, 64), (67, 41), (9, 130)] {
            let p = noise(w, h);
            let (bands, residual) = laplacian(&p, 8);
            assert!(!bands.is_empty());
            let back = collapse(bands, residual);
            let err =
                p.v.iter()
                    .zip(&back.v)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f32::max);
            assert!(err < 1e-5, "{w}×{h}: {err}");
        }
    }

    #[test]
    fn reduce_and_expand_keep_a_constant() {
        // The binomial kernel sums to 1 and EXPAND's polyphase weights too, borders included.
        let p = Plane {
            w: 13,
            h: 6,
            v: vec![0.25; 78],
        };
        let r = reduce(&p);
        assert_eq!((r.w, r.h), (7, 3));
        assert!(r.v.iter().all(|v| (v - 0.25).abs() < 1e-7));
        let e = expand(&r, 13, 6);
        assert!(e.v.iter().all(|v| (v - 0.25).abs() < 1e-7));
        // A constant has no band content.
        let (bands, residual) = laplacian(&noise(1, 1), 4);
        assert!(bands.is_empty() && residual.v.len() == 1);
    }
}
