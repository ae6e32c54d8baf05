//! A visible-difference predictor (VDP): the probability that a person sees a difference between
//! two images, per pixel and overall, and the size of that difference in just-noticeable
//! differences (JND).
//!
//! Based on: Scott Daly. The Visible Differences Predictor: An Algorithm for the Assessment of
//! Image Fidelity. Digital Images and Human Vision 1993 (the architecture: amplitude
//! non-linearity, CSF, multi-channel decomposition, masking with mutual masking, psychometric
//! function, probability summation); Jeffrey Lubin. A Visual Discrimination Model for Imaging
//! System Design and Evaluation. 1995 (Laplacian-pyramid channels); Rafał Mantiuk, Karol
//! Myszkowski, Hans-Peter Seidel. Visible Difference Predicator for High Dynamic Range Images.
//! IEEE SMC 2004 (JND-scaled luminance instead of a fixed adaptation level).
//!
//! The stages, one file each, in the order they run:
//! 1. `amplitude.rs` — display luminance, then the JND-scaled response (luminance adaptation: TVI).
//! 2. `bands.rs` — Laplacian pyramid (octave bands) with four cos²-tuned orientation channels.
//! 3. CSF weighting (here): each band's responses are multiplied by the normalised CSF at its
//!    centre frequency, Daly's CSF in the Rushmeier approximation ([`crate::metric::csf`]), at the
//!    viewing condition's pixels per degree; the result is in JND units at every frequency.
//! 4. `masking.rs` — threshold elevation from the smaller of the two images' local channel
//!    magnitudes (mutual masking).
//! 5. `psychometric.rs` — d = |Δ| / elevation per channel and sample; Weibull psychometric function
//!    and probability summation over channels, bands and pixels.
//!
//! Calibration: one unit of the response is one luminance JND at the CSF's peak frequency, so a
//! grating of Michelson contrast c at the peak frequency on a bright background has about 100·c
//! JND of amplitude in the pyramid (the band gain is below 1, which makes absolute thresholds
//! within a factor of about two of the human peak sensitivity of ≈ 200). The tests check the
//! behaviour vision science establishes — the CSF's shape across frequency, masking, the TVI and
//! ranking along an LOD chain — rather than absolute agreement with an observer panel, which no
//! dataset within reach provides.

mod amplitude;
mod bands;
mod masking;
mod psychometric;

use rayon::prelude::*;

pub use amplitude::Display;
pub use masking::threshold_elevation;
pub use psychometric::BETA;

use self::bands::{Band, ORIENTATIONS, Plane};
use super::csf::{ClampedCsf, daly_rushmeier};
use super::image::{ErrorMap, LinearImage, same_dims, same_size};
use crate::error::Result;
use crate::scene::Viewing;

/// Value of a band-`k` sample grid at full-resolution pixel (x, y), bilinear between sample
/// centres ((x + ½)/2^k − ½), clamped at the borders.
fn bilinear(v: &[f64], bw: usize, bh: usize, x: usize, y: usize, k: usize) -> f64 {
    let scale = (1u64 << k) as f64;
    let fx = ((x as f64 + 0.5) / scale - 0.5).clamp(0.0, (bw - 1) as f64);
    let fy = ((y as f64 + 0.5) / scale - 0.5).clamp(0.0, (bh - 1) as f64);
    let (x0, y0) = (fx.floor() as usize, fy.floor() as usize);
    let (x1, y1) = ((x0 + 1).min(bw - 1), (y0 + 1).min(bh - 1));
    let (tx, ty) = (fx - x0 as f64, fy - y0 as f64);
    let top = v[y0 * bw + x0] * (1.0 - tx) + v[y0 * bw + x1] * tx;
    let bottom = v[y1 * bw + x0] * (1.0 - tx) + v[y1 * bw + x1] * tx;
    top * (1.0 - ty) + bottom * ty
}

/// The VDP for one display and viewing condition.
#[derive(Debug, Clone)]
pub struct Vdp {
    ppd: f64,
    display: Display,
    max_levels: usize,
    csf_peak: f64,
}

/// One image after the per-image stages (response and decomposition).
#[derive(Debug, Clone)]
pub struct VdpPrepared {
    width: usize,
    height: usize,
    bands: Vec<Band>,
}

/// What the VDP predicts for an image pair.
#[derive(Debug, Clone, PartialEq)]
pub struct VdpScore {
    /// Probability that the difference is detected anywhere in the image, in [0, 1].
    pub probability: f64,
    /// The difference in JND (Minkowski sum with exponent β over channels and pixels);
    /// probability = 1 − exp(−jnd^β).
    pub jnd: f64,
    /// Per-pixel detection probability in [0, 1].
    pub map: ErrorMap,
}

impl Vdp {
    /// Default number of pyramid levels (octaves); fewer when the image is small.
    pub const DEFAULT_LEVELS: usize = 8;

    /// A VDP for `viewing` on `display`.
    pub fn new(viewing: &Viewing, display: Display) -> Vdp {
        let peak_f = ClampedCsf::daly().peak_frequency();
        Vdp {
            ppd: viewing.ppd(),
            display,
            max_levels: Self::DEFAULT_LEVELS,
            csf_peak: daly_rushmeier(peak_f),
        }
    }

    /// Centre frequency of band `k`, cycles per degree.
    pub fn band_frequency(&self, k: usize) -> f64 {
        0.375 * self.ppd / (1u64 << k) as f64
    }

    /// CSF weight of band `k` (1 at the CSF's peak frequency).
    fn band_weight(&self, k: usize) -> f32 {
        (daly_rushmeier(self.band_frequency(k)) / self.csf_peak) as f32
    }

    /// Stages 1–2 for one image.
    pub fn prepare(&self, image: &LinearImage) -> VdpPrepared {
        let r = amplitude::response(image, &self.display);
        let plane = Plane {
            w: image.width(),
            h: image.height(),
            v: r,
        };
        VdpPrepared {
            width: image.width(),
            height: image.height(),
            bands: bands::decompose(&plane, self.max_levels),
        }
    }

    /// CSF-weighted channel responses (JND) of band `k` of an image: one vector per orientation.
    ///
    /// `weights` are the orientation weights to split by. A comparison splits both images by the
    /// weights of their mean band: the cos² tuning comes from the local gradient direction, which
    /// is ill-conditioned at the extrema of a band (gradient ≈ 0, value large), so splitting each
    /// image by its own weights could put one large value into different orientations in two
    /// nearly equal images and show a several-JND "difference" where there is almost none
    /// (seen on 40-pixel renders of a LOD: 5.3 JND from one band sample, 0.25 JND without it).
    fn channels(
        &self,
        band: &Band,
        weights: &[[f32; ORIENTATIONS]],
        k: usize,
    ) -> [Vec<f32>; ORIENTATIONS] {
        let w = self.band_weight(k);
        std::array::from_fn(|c| {
            band.plane
                .v
                .iter()
                .zip(weights)
                .map(|(v, wt)| v * wt[c] * w)
                .collect()
        })
    }

    /// Compare two prepared images.
    pub fn compare_prepared(
        &self,
        reference: &VdpPrepared,
        test: &VdpPrepared,
    ) -> Result<VdpScore> {
        same_dims(
            (reference.width, reference.height),
            (test.width, test.height),
        )?;
        let (w, h) = (reference.width, reference.height);
        let beta = BETA;
        let mut pixel_sum = vec![0.0f64; w * h];
        let mut total = 0.0f64;
        for (k, (rb, tb)) in reference.bands.iter().zip(&test.bands).enumerate() {
            let (bw, bh) = (rb.plane.w, rb.plane.h);
            let mean = bands::Plane {
                w: bw,
                h: bh,
                v: rb
                    .plane
                    .v
                    .iter()
                    .zip(&tb.plane.v)
                    .map(|(a, b)| 0.5 * (a + b))
                    .collect(),
            };
            let weights = bands::orientation_weights(&mean);
            let (rc, tc) = (
                self.channels(rb, &weights, k),
                self.channels(tb, &weights, k),
            );
            // Σ_c d_c^β per band sample (stages 4–5).
            let mut sample_sum = vec![0.0f64; bw * bh];
            for c in 0..ORIENTATIONS {
                let mr = masking::local_magnitude(&rc[c], bw, bh);
                let mt = masking::local_magnitude(&tc[c], bw, bh);
                sample_sum.par_iter_mut().enumerate().for_each(|(i, s)| {
                    let elevation = threshold_elevation(mr[i].min(mt[i]));
                    let d = (tc[c][i] - rc[c][i]).abs() / elevation;
                    *s += (d as f64).powf(beta as f64);
                });
            }
            total += sample_sum.iter().sum::<f64>();
            // Spread over the full-resolution pixels, interpolating bilinearly between band samples
            // (nearest-neighbour spreading draws the coarse bands as visible blocks).
            pixel_sum
                .par_chunks_mut(w)
                .enumerate()
                .for_each(|(y, row)| {
                    for (x, p) in row.iter_mut().enumerate() {
                        *p += bilinear(&sample_sum, bw, bh, x, y, k);
                    }
                });
        }
        let map = pixel_sum
            .iter()
            .map(|&s| psychometric::probability(s) as f32)
            .collect();
        Ok(VdpScore {
            probability: psychometric::probability(total),
            jnd: psychometric::jnd(total),
            map: ErrorMap {
                width: w,
                height: h,
                values: map,
            },
        })
    }

    /// Compare two images (prepares both).
    pub fn compare(&self, reference: &LinearImage, test: &LinearImage) -> Result<VdpScore> {
        same_size(reference, test)?;
        self.compare_prepared(&self.prepare(reference), &self.prepare(test))
    }

    /// How strongly an image's own content masks errors (Qu & Meyer §4.2): per pixel the largest
    /// threshold elevation (≥ 1) over bands and orientations, 1 meaning no masking.
    pub fn masking_map(&self, image: &LinearImage) -> ErrorMap {
        let p = self.prepare(image);
        let (w, h) = (p.width, p.height);
        let mut out = vec![1.0f32; w * h];
        for (k, band) in p.bands.iter().enumerate() {
            let (bw, bh) = (band.plane.w, band.plane.h);
            let ch = self.channels(band, &band.weights, k);
            for c in ch.iter() {
                let m = masking::local_magnitude(c, bw, bh);
                out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
                    let by = (y >> k).min(bh - 1);
                    for (x, o) in row.iter_mut().enumerate() {
                        *o = o.max(threshold_elevation(m[by * bw + (x >> k).min(bw - 1)]));
                    }
                });
            }
        }
        ErrorMap {
            width: w,
            height: h,
            values: out,
        }
    }
}
