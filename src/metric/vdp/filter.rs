//! Stage 2 of the VDP: the contrast sensitivity function as a linear filter on log luminance.
//!
//! Based on: Scott Daly. The Visible Differences Predictor. 1993 (the CSF applied as a filter in
//! the frequency domain, ahead of the channel decomposition); Andrew Watson, Albert Ahumada. A
//! standard model for foveal detection of spatial contrast. Journal of Vision 5(9) 2005 (the same
//! filter ahead of Minkowski pooling is the model that fits ModelFest); Stephen Martucci.
//! Symmetric convolution and the discrete sine and cosine transforms. IEEE Trans. Signal
//! Processing 42(5) 1994 (multiplying DCT-II coefficients by a real, even frequency response and
//! inverting with the DCT-III is a convolution of the image's mirrored extension, so the borders
//! get no wrap-around seams).
//!
//! The input is ln L (L in cd/m²), whose small changes are Weber contrasts (Δln L = ΔL/L), so the
//! output is contrast weighted by absolute sensitivity: one unit is one threshold contrast of the
//! CSF. DCT-II coefficient (u, v) of a W × H image is the frequency (u/2W, v/2H) cycles per pixel,
//! i.e. ρ = ppd·√((u/2W)² + (v/2H)²) cycles per degree with cos 4θ = 1 − 8·f_x²·f_y²/ρ⁴; the gain
//! there is the CSF S(ρ, θ, L_ref) at the reference adaptation luminance (the luminance the
//! bands correct from, `adaptation.rs`). The DC gain is S(0) = 0: the mean log luminance, which
//! carries no pattern, is removed.
//!
//! Decision: the transforms are rustdct's (Elliott Mielczarek et al.), unnormalised, so a DCT-II
//! followed by a DCT-III multiplies by N/2 per axis; the gain table carries the 4/(W·H).

use std::sync::Arc;

use rayon::prelude::*;
use rustdct::{DctPlanner, TransformType2And3};

use super::bands::Plane;
use crate::metric::csf::DalyCsf;

/// The CSF sampled on one image size's DCT grid, with the transforms planned for that size.
pub(crate) struct CsfFilter {
    w: usize,
    h: usize,
    ppd: f64,
    /// Gain per coefficient, in the transposed layout the filter multiplies in: row u (the
    /// horizontal frequency), column v (the vertical one).
    gain: Vec<f32>,
    row: Arc<dyn TransformType2And3<f32>>,
    column: Arc<dyn TransformType2And3<f32>>,
}

impl std::fmt::Debug for CsfFilter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "CsfFilter({}×{} at {} ppd)", self.w, self.h, self.ppd)
    }
}

/// `dst[x·h + y] = src[y·w + x]`.
fn transpose(src: &[f32], w: usize, h: usize) -> Vec<f32> {
    let mut dst = vec![0.0f32; w * h];
    dst.par_chunks_mut(h).enumerate().for_each(|(x, col)| {
        for (y, d) in col.iter_mut().enumerate() {
            *d = src[y * w + x];
        }
    });
    dst
}

impl CsfFilter {
    /// The filter for `w × h` images at `ppd`, with `csf` at adaptation luminance `l_ref` cd/m².
    pub(crate) fn new(w: usize, h: usize, ppd: f64, csf: &DalyCsf, l_ref: f64) -> CsfFilter {
        let mut planner = DctPlanner::<f32>::new();
        let (row, column) = (planner.plan_dct2(w), planner.plan_dct2(h));
        let norm = 4.0 / (w * h) as f64;
        let mut gain = vec![0.0f32; w * h];
        gain.par_chunks_mut(h).enumerate().for_each(|(u, col)| {
            let fx = u as f64 / (2 * w) as f64 * ppd;
            for (v, g) in col.iter_mut().enumerate() {
                let fy = v as f64 / (2 * h) as f64 * ppd;
                let rho2 = fx * fx + fy * fy;
                *g = if rho2 == 0.0 {
                    0.0
                } else {
                    let cos4 = 1.0 - 8.0 * fx * fx * fy * fy / (rho2 * rho2);
                    (csf.sensitivity(rho2.sqrt(), cos4, l_ref) * norm) as f32
                };
            }
        });
        CsfFilter {
            w,
            h,
            ppd,
            gain,
            row,
            column,
        }
    }

    /// Whether this filter is the one for `w × h` at `ppd`.
    pub(crate) fn fits(&self, w: usize, h: usize, ppd: f64) -> bool {
        (self.w, self.h) == (w, h) && self.ppd.to_bits() == ppd.to_bits()
    }

    /// Filter `p` (which must be `w × h`).
    pub(crate) fn apply(&self, p: &Plane) -> Plane {
        debug_assert!(p.w == self.w && p.h == self.h);
        let (w, h) = (self.w, self.h);
        let pass = |data: &mut [f32], n: usize, t: &Arc<dyn TransformType2And3<f32>>, two: bool| {
            data.par_chunks_mut(n).for_each_init(
                || vec![0.0f32; t.get_scratch_len()],
                |scratch, line| {
                    if two {
                        t.process_dct2_with_scratch(line, scratch)
                    } else {
                        t.process_dct3_with_scratch(line, scratch)
                    }
                },
            );
        };
        let mut rows = p.v.clone();
        pass(&mut rows, w, &self.row, true);
        let mut cols = transpose(&rows, w, h);
        pass(&mut cols, h, &self.column, true);
        cols.par_iter_mut()
            .zip(&self.gain)
            .for_each(|(c, g)| *c *= g);
        pass(&mut cols, h, &self.column, false);
        let mut rows = transpose(&cols, h, w);
        pass(&mut rows, w, &self.row, false);
        Plane { w, h, v: rows }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_grating_is_scaled_by_the_csf_at_its_frequency() {
        // A vertical cosine that fits the DCT grid exactly (k half-periods over the width) passes
        // with the CSF's gain at its frequency; the mean is removed (DC gain 0).
        let csf = DalyCsf::published();
        let (w, h, ppd, k) = (128usize, 32usize, 64.0, 16usize);
        let f_cpd = k as f64 / (2 * w) as f64 * ppd;
        let v = (0..w * h)
            .map(|i| {
                let x = (i % w) as f64;
                (0.5 + 0.01 * (std::f64::consts::PI * k as f64 * (x + 0.5) / w as f64).cos()) as f32
            })
            .collect();
        let out = CsfFilter::new(w, h, ppd, &csf, 30.0).apply(&Plane { w, h, v });
        let s = csf.sensitivity(f_cpd, 1.0, 30.0);
        for (i, o) in out.v.iter().enumerate() {
            let x = (i % w) as f64;
            let want = 0.01 * s * (std::f64::consts::PI * k as f64 * (x + 0.5) / w as f64).cos();
            assert!((*o as f64 - want).abs() < 1e-4 * s, "{i}: {o} vs {want}");
        }
    }
}
