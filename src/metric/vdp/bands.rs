//! Stage 2 of the VDP: multi-scale, multi-orientation decomposition.
//!
//! Based on: Peter Burt, Edward Adelson. The Laplacian Pyramid as a Compact Image Code. IEEE
//! Trans. Communications 1983 (5-tap binomial kernel, REDUCE/EXPAND; each level is one octave
//! band); William Freeman, Edward Adelson. The Design and Use of Steerable Filters. IEEE PAMI 1991
//! (orientation channels from local orientation with cos² tuning, the angular response of a
//! second-derivative steerable filter).
//!
//! Each band k keeps its own resolution (2^k pixels per sample) and is centred on
//! ρ_k = 0.375 · ppd / 2^k cycles per degree (the middle of the octave [¼, ½] cycles per sample).
//! A band's samples are split over [`ORIENTATIONS`] channels at 0°, 45°, 90°, 135° by weighting
//! them with cos²(θ − θ_c), θ the local orientation of the band's gradient; the weights of the four
//! channels sum to 2, so each weight is halved to keep the band's amplitude.

use rayon::prelude::*;

/// Number of orientation channels per band.
pub const ORIENTATIONS: usize = 4;

/// A single-channel image.
#[derive(Debug, Clone)]
pub(crate) struct Plane {
    pub w: usize,
    pub h: usize,
    pub v: Vec<f32>,
}

impl Plane {
    fn at(&self, x: isize, y: isize) -> f32 {
        let xr = reflect(x, self.w);
        let yr = reflect(y, self.h);
        self.v[yr * self.w + xr]
    }
}

/// Mirrored border (… c b | a b c | b a …), valid for any offset.
fn reflect(i: isize, n: usize) -> usize {
    if n == 1 {
        return 0;
    }
    let period = 2 * (n as isize - 1);
    let m = i.rem_euclid(period);
    (if m < n as isize { m } else { period - m }) as usize
}

const BINOMIAL: [f32; 5] = [1.0 / 16.0, 4.0 / 16.0, 6.0 / 16.0, 4.0 / 16.0, 1.0 / 16.0];

/// Separable 5-tap binomial blur.
fn blur(p: &Plane) -> Plane {
    let mut mid = vec![0.0f32; p.w * p.h];
    mid.par_chunks_mut(p.w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            *o = (0..5)
                .map(|t| BINOMIAL[t] * p.at(x as isize + t as isize - 2, y as isize))
                .sum();
        }
    });
    let m = Plane {
        w: p.w,
        h: p.h,
        v: mid,
    };
    let mut out = vec![0.0f32; p.w * p.h];
    out.par_chunks_mut(p.w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            *o = (0..5)
                .map(|t| BINOMIAL[t] * m.at(x as isize, y as isize + t as isize - 2))
                .sum();
        }
    });
    Plane {
        w: p.w,
        h: p.h,
        v: out,
    }
}

/// Blur and keep every second sample (Burt–Adelson REDUCE).
pub(crate) fn reduce(p: &Plane) -> Plane {
    let b = blur(p);
    let (w, h) = (p.w.div_ceil(2), p.h.div_ceil(2));
    let v = (0..w * h)
        .map(|i| b.v[(2 * (i / w)) * p.w + 2 * (i % w)])
        .collect();
    Plane { w, h, v }
}

/// Back to `w × h`: nearest-neighbour upsampling followed by the binomial blur (an EXPAND).
pub(crate) fn expand(p: &Plane, w: usize, h: usize) -> Plane {
    let v = (0..w * h)
        .map(|i| p.v[((i / w) / 2).min(p.h - 1) * p.w + ((i % w) / 2).min(p.w - 1)])
        .collect();
    blur(&Plane { w, h, v })
}

/// One band: its samples, and per sample the weights of the orientation channels.
#[derive(Debug, Clone)]
pub(crate) struct Band {
    pub plane: Plane,
    pub weights: Vec<[f32; ORIENTATIONS]>,
}

/// Laplacian pyramid of `p` (bands finest first) with orientation weights; the residual low-pass
/// is dropped (it carries the mean luminance, which the response already normalised).
pub(crate) fn decompose(p: &Plane, max_levels: usize) -> Vec<Band> {
    let mut bands = Vec::new();
    let mut g = p.clone();
    while bands.len() < max_levels && g.w >= 4 && g.h >= 4 {
        let next = reduce(&g);
        let up = expand(&next, g.w, g.h);
        let lap = Plane {
            w: g.w,
            h: g.h,
            v: g.v.iter().zip(&up.v).map(|(a, b)| a - b).collect(),
        };
        let weights = orientation_weights(&lap);
        bands.push(Band {
            plane: lap,
            weights,
        });
        g = next;
    }
    bands
}

/// cos²-tuned orientation weights from the local gradient direction (central differences),
/// halved so the four weights sum to 1. Flat samples (no gradient) spread evenly.
pub(crate) fn orientation_weights(p: &Plane) -> Vec<[f32; ORIENTATIONS]> {
    (0..p.w * p.h)
        .into_par_iter()
        .map(|i| {
            let (x, y) = ((i % p.w) as isize, (i / p.w) as isize);
            let gx = p.at(x + 1, y) - p.at(x - 1, y);
            let gy = p.at(x, y + 1) - p.at(x, y - 1);
            if gx == 0.0 && gy == 0.0 {
                return [1.0 / ORIENTATIONS as f32; ORIENTATIONS];
            }
            let theta = gy.atan2(gx);
            std::array::from_fn(|c| {
                let centre = c as f32 * std::f32::consts::PI / ORIENTATIONS as f32;
                0.5 * (theta - centre).cos().powi(2)
            })
        })
        .collect()
}
