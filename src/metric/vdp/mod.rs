//! A visible-difference predictor (VDP), calibrated on ModelFest: the probability that a person
//! sees a difference between two images, per pixel and overall, and its size in just-noticeable
//! differences (JND), where 1 JND is the detection threshold of ModelFest's observers.
//!
//! Based on: Scott Daly. The Visible Differences Predictor: An Algorithm for the Assessment of
//! Image Fidelity. Digital Images and Human Vision 1993 (the architecture: CSF filter, channel
//! decomposition, masking with mutual masking, psychometric function, probability summation; his
//! CSF); Andrew Watson, Albert Ahumada. A standard model for foveal detection of spatial contrast.
//! Journal of Vision 5(9) 2005 (what ModelFest needs: a CSF filter and Minkowski summation over
//! space in degrees); Rafał Mantiuk et al. HDR-VDP-2. ACM TOG 30(4) 2011 (display model, per-band
//! sensitivity at the local adaptation luminance).
//!
//! The stages, one file each, in the order they run:
//! 0. `padding.rs` — a surround of 1° of the image's border median on every side, so that how
//!    tightly an image was cropped does not change its verdict; maps are cropped back.
//! 1. `display.rs` — linear pixels → luminance L in cd/m² (peak, black level, ambient reflection);
//!    then ln L, whose small differences are Weber contrasts.
//! 2. `filter.rs` — the CSF (Daly's, fitted) as a linear filter in the DCT domain, at the reference
//!    adaptation luminance: every frequency weighted by its absolute sensitivity, so one unit is one
//!    threshold contrast. The CSF contains the eye's optics (it was measured through them).
//! 3. `bands.rs` — Laplacian pyramid of the filtered image (octave bands, exact collapse).
//! 4. `adaptation.rs` — each band's sensitivity moved from the reference luminance to the local
//!    adaptation luminance (Gaussian pyramid of L): Weber's law when bright, de Vries–Rose in the dark.
//! 5. `masking.rs` — per band, the difference divided by the threshold elevation of the smaller of
//!    the two images' local band magnitudes (mutual masking).
//! 6. `pooling.rs` — the masked bands collapsed into one difference image d(x); Minkowski sum
//!    S = Σ|d|^β·(pixel area in deg²), and a per-pixel map over a small neighbourhood.
//! 7. `psychometric.rs` — P_det = 1 − exp(−k·S), J = S^(1/β); S = 1 is the observers' threshold.
//!
//! Without a masker (a uniform reference, as in ModelFest) the collapse returns the CSF-filtered
//! difference itself, so the calibrated part is exactly Watson & Ahumada's single-channel model,
//! with Daly's CSF: `fitted.rs` holds its four constants, and `modelfest.rs` runs the check
//! (`lodeval calibrate modelfest`). What ModelFest cannot calibrate — luminance dependence and
//! masking — keeps its published constants and is tested against the psychophysics it comes from.
//!
//! Why the previous model said P = 1.000 for every non-identical pair: it summed |d|^β over every
//! band's samples upsampled to full resolution with no unit of area, so the sum grew with the
//! pixel count (a 512² image has 262 144 "detectors"), and its absolute scale was never fitted.
//! Here the sum is over visual angle and its scale is the observers'.

mod adaptation;
#[doc(hidden)] // the calibration against human data behind `lodeval calibrate`; public for tests
pub mod agreement;
pub(crate) mod bands;
#[doc(hidden)] // the calibration against human data behind `lodeval calibrate`; public for tests
pub mod castle;
mod display;
mod filter;
pub mod fitted;
#[doc(hidden)] // the calibration against human data behind `lodeval calibrate`; public for tests
pub mod foley;
pub(crate) mod masking;
#[doc(hidden)] // the calibration against human data behind `lodeval calibrate`; public for tests
pub mod modelfest;
mod padding;
mod pooling;
mod psychometric;
#[doc(hidden)] // the calibration against human data behind `lodeval calibrate`; public for tests
pub mod stimuli;
mod table;
#[doc(hidden)] // the calibration against human data behind `lodeval calibrate`; public for tests
pub mod threshold;

use std::sync::{Arc, Mutex};

use rayon::prelude::*;

pub use adaptation::HighLuminanceLoss;
pub use display::Display;
pub use masking::threshold_elevation;
pub use pooling::MAP_WINDOW_DEG;
pub use psychometric::{THRESHOLD_PROBABILITY, sum_for_probability};

use self::adaptation::BandAdaptation;
use self::bands::Plane;
use self::filter::CsfFilter;
use super::csf::DalyCsf;
use super::runs::map_runs;
use crate::color::luminance;
use crate::error::{Error, Result};
use crate::image::{ErrorMap, LinearImage, same_dims, same_size};
use crate::scene::Viewing;

/// The model's free parameters (the fitted ones by default; others for fitting and experiments).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct VdpParams {
    /// The CSF. Default value: Daly's with [`fitted::PEAK_SENSITIVITY`], [`fitted::FREQUENCY_SCALE`]
    /// and [`fitted::OBLIQUE`].
    pub csf: DalyCsf,
    /// Minkowski exponent and psychometric slope. Default value: [`fitted::BETA`].
    pub beta: f64,
    /// Sensitivity lost on very bright backgrounds (`None`: Daly's CSF alone). Default value:
    /// [`fitted::HIGH_LUMINANCE_KNEE`] and [`fitted::HIGH_LUMINANCE_EXPONENT`].
    pub high_luminance: Option<HighLuminanceLoss>,
}

impl VdpParams {
    /// The ModelFest fit.
    pub fn fitted() -> VdpParams {
        VdpParams {
            csf: DalyCsf::new(
                fitted::PEAK_SENSITIVITY,
                fitted::FREQUENCY_SCALE,
                fitted::OBLIQUE,
            )
            .expect("the fitted constants are positive"),
            beta: fitted::BETA,
            high_luminance: Some(HighLuminanceLoss {
                knee_cd_m2: fitted::HIGH_LUMINANCE_KNEE,
                exponent: fitted::HIGH_LUMINANCE_EXPONENT,
            }),
        }
    }

    /// Parameters from a CSF and an exponent, with the fitted high-luminance loss; `None` unless
    /// `beta` is finite and ≥ 1.
    pub fn new(csf: DalyCsf, beta: f64) -> Option<VdpParams> {
        (beta.is_finite() && beta >= 1.0).then_some(VdpParams {
            csf,
            beta,
            ..VdpParams::fitted()
        })
    }

    /// These parameters with `loss` on bright backgrounds instead (`None`: none).
    pub fn with_high_luminance(self, loss: Option<HighLuminanceLoss>) -> VdpParams {
        VdpParams {
            high_luminance: loss,
            ..self
        }
    }
}

impl Default for VdpParams {
    fn default() -> Self {
        Self::fitted()
    }
}

/// How many CSF filters (one per image size) a [`Vdp`] keeps.
const FILTER_CACHE: usize = 4;

/// The VDP for one display and viewing condition.
#[derive(Debug, Clone)]
pub struct Vdp {
    ppd: f64,
    display: Display,
    params: VdpParams,
    max_levels: usize,
    /// Per band (and one more for the residual): the luminance correction.
    adaptation: Vec<BandAdaptation>,
    /// The most recently used CSF filters, newest last (a cache: results do not depend on it).
    filters: Arc<Mutex<Vec<Arc<CsfFilter>>>>,
}

/// One image after the per-image stages (display, filter, bands, adaptation, masker magnitudes).
#[derive(Debug, Clone)]
pub struct VdpPrepared {
    width: usize,
    height: usize,
    /// The uniform margin added on every side (`padding.rs`); the planes below are
    /// `(width + 2·margin) × (height + 2·margin)`.
    margin: usize,
    bands: Vec<Plane>,
    maskers: Vec<Vec<f32>>,
    residual: Plane,
}

/// What the VDP predicts for an image pair.
#[derive(Debug, Clone, PartialEq)]
pub struct VdpScore {
    /// Probability that the difference is detected anywhere in the image, in [0, 1].
    pub probability: f64,
    /// The difference in JND: 1 is the observers' detection threshold (P = 0.68, 2AFC 84 %
    /// correct); probability = 1 − exp(−k·jnd^β) with k = 1.139.
    pub jnd: f64,
    /// Per-pixel detection probability in [0, 1] of the difference around the pixel
    /// ([`MAP_WINDOW_DEG`]); never above `probability`.
    pub map: ErrorMap,
    /// The same neighbourhood's difference in JND (1 = threshold): unlike the probability,
    /// which saturates at 1 a little past 2 JND, it still tells a clear difference from a glaring
    /// one (the heat maps `eval` draws).
    pub jnd_map: ErrorMap,
}

impl VdpPrepared {
    /// The size of the padded planes.
    fn padded_size(&self) -> (usize, usize) {
        (self.width + 2 * self.margin, self.height + 2 * self.margin)
    }

    /// The image's own `width × height` window of a padded per-pixel map.
    fn crop(&self, padded: Vec<f32>) -> ErrorMap {
        ErrorMap {
            width: self.width,
            height: self.height,
            values: padding::crop(&padded, self.width, self.height, self.margin),
        }
    }
}

impl Vdp {
    /// Default number of pyramid levels (octaves); fewer when the image is small.
    pub const DEFAULT_LEVELS: usize = 8;

    /// The calibrated VDP for `viewing` on `display`. Callers check the viewing condition
    /// ([`Vdp::checked`] does).
    pub fn new(viewing: &Viewing, display: Display) -> Vdp {
        Self::with_params(viewing.ppd(), display, VdpParams::fitted())
    }

    /// The calibrated VDP, or a usage error naming the condition that makes no sense (pixels per
    /// degree not finite and positive; the display is checked by [`Display::new`]).
    pub fn checked(viewing: &Viewing, display: Display) -> Result<Vdp> {
        let ppd = viewing.ppd();
        if !ppd.is_finite() || ppd <= 0.0 || ppd > 1e4 {
            return Err(Error::Usage(format!(
                "the viewing condition gives {ppd} pixels per degree; give a positive display \
                 width, pixel count and distance (or --ppd between 0 and 10000)"
            )));
        }
        let display = Display::new(
            display.peak_cd_m2,
            display.black_cd_m2,
            display.ambient_lux,
            display.reflectivity,
        )?;
        Ok(Self::new(viewing, display))
    }

    /// A VDP at `ppd` pixels per degree with explicit parameters (fitting, experiments).
    pub fn with_params(ppd: f64, display: Display, params: VdpParams) -> Vdp {
        let max_levels = Self::DEFAULT_LEVELS;
        let adaptation = (0..=max_levels)
            .map(|k| {
                BandAdaptation::new(
                    &params.csf,
                    band_frequency(ppd, k),
                    fitted::REFERENCE_LUMINANCE,
                    params.high_luminance,
                )
            })
            .collect();
        Vdp {
            ppd,
            display,
            params,
            max_levels,
            adaptation,
            filters: Arc::default(),
        }
    }

    /// Pixels per degree.
    pub fn ppd(&self) -> f64 {
        self.ppd
    }

    /// The parameters.
    pub fn params(&self) -> &VdpParams {
        &self.params
    }

    /// Centre frequency of band `k`, cycles per degree.
    pub fn band_frequency(&self, k: usize) -> f64 {
        band_frequency(self.ppd, k)
    }

    /// The CSF filter for `w × h` images (from the cache, or made and cached).
    fn filter(&self, w: usize, h: usize) -> Arc<CsfFilter> {
        let mut cache = self.filters.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(i) = cache.iter().position(|f| f.fits(w, h, self.ppd)) {
            let f = cache.remove(i);
            cache.push(f.clone());
            return f;
        }
        let f = Arc::new(CsfFilter::new(
            w,
            h,
            self.ppd,
            &self.params.csf,
            fitted::REFERENCE_LUMINANCE,
        ));
        if cache.len() >= FILTER_CACHE {
            cache.remove(0);
        }
        cache.push(f.clone());
        f
    }

    /// Stages 1–5 for one image.
    pub fn prepare(&self, image: &LinearImage) -> VdpPrepared {
        let l = image
            .pixels()
            .par_iter()
            .map(|&c| self.display.luminance(luminance(c)))
            .collect();
        self.prepare_luminance(image.width(), image.height(), l)
    }

    /// Stages 2–5 for an image given as luminance in cd/m² (row-major, `w × h`, every value
    /// finite and positive): stimuli specified in luminance, such as ModelFest's.
    pub fn prepare_luminance(&self, w: usize, h: usize, luminance: Vec<f32>) -> VdpPrepared {
        assert_eq!(luminance.len(), w * h, "one luminance per pixel");
        let margin = padding::margin(self.ppd);
        let lum = padding::pad(&Plane { w, h, v: luminance }, margin);
        let (pw, ph) = (lum.w, lum.h);
        // Stage 1's logarithm (Weber contrast), then the CSF filter.
        let log = Plane {
            w: pw,
            h: ph,
            v: lum
                .v
                .par_chunks(pw)
                .flat_map_iter(|row| {
                    map_runs(row.iter().copied(), |l| {
                        l.max(adaptation::L_MIN as f32).ln()
                    })
                })
                .collect(),
        };
        let filtered = self.filter(pw, ph).apply(&log);
        let (mut bands, mut residual) = bands::laplacian(&filtered, self.max_levels);
        // Local adaptation from the Gaussian pyramid of luminance, one level below each band.
        let gauss = bands::gaussian(&lum, bands.len() + 1);
        for (k, band) in bands.iter_mut().enumerate() {
            self.adaptation[k].apply(band, &gauss[k + 1]);
        }
        let k = bands.len();
        self.adaptation[k].apply(&mut residual, &gauss[k + 1]);
        let maskers = bands
            .iter()
            .map(|b| masking::local_magnitude(&b.v, b.w, b.h))
            .collect();
        VdpPrepared {
            width: w,
            height: h,
            margin,
            bands,
            maskers,
            residual,
        }
    }

    /// Compare two prepared images (stages 5–7).
    pub fn compare_prepared(
        &self,
        reference: &VdpPrepared,
        test: &VdpPrepared,
    ) -> Result<VdpScore> {
        same_dims(
            (reference.width, reference.height),
            (test.width, test.height),
        )?;
        // Stage 5: masked band differences.
        let masked: Vec<Plane> = (0..reference.bands.len())
            .map(|k| {
                let (rb, tb) = (&reference.bands[k], &test.bands[k]);
                let (mr, mt) = (&reference.maskers[k], &test.maskers[k]);
                let v = (0..rb.v.len())
                    .into_par_iter()
                    .map(|i| {
                        // An unchanged sample stays 0 whatever the masking.
                        let d = tb.v[i] - rb.v[i];
                        if d == 0.0 {
                            0.0
                        } else {
                            d / threshold_elevation(mr[i].min(mt[i]))
                        }
                    })
                    .collect();
                Plane {
                    w: rb.w,
                    h: rb.h,
                    v,
                }
            })
            .collect();
        let residual = Plane {
            w: reference.residual.w,
            h: reference.residual.h,
            v: reference
                .residual
                .v
                .iter()
                .zip(&test.residual.v)
                .map(|(r, t)| t - r)
                .collect(),
        };
        // Stage 6: one difference image, pooled over visual angle.
        let d = bands::collapse(masked, residual);
        let (sum, density) = pooling::minkowski(&d, self.ppd, self.params.beta);
        let (map, jnd_map) =
            pooling::probability_and_jnd_maps(&density, d.w, d.h, self.ppd, self.params.beta);
        // Stage 7.
        Ok(VdpScore {
            probability: psychometric::probability(sum),
            jnd: psychometric::jnd(sum, self.params.beta),
            map: reference.crop(map),
            jnd_map: reference.crop(jnd_map),
        })
    }

    /// Compare two images (prepares both).
    pub fn compare(&self, reference: &LinearImage, test: &LinearImage) -> Result<VdpScore> {
        same_size(reference, test)?;
        self.compare_prepared(&self.prepare(reference), &self.prepare(test))
    }

    /// How strongly an image's own content masks errors: per pixel the largest threshold
    /// elevation (≥ 1) over bands, 1 meaning no masking.
    pub fn masking_map(&self, image: &LinearImage) -> ErrorMap {
        let p = self.prepare(image);
        let maskers: Vec<(usize, usize, &[f32])> = p
            .bands
            .iter()
            .zip(&p.maskers)
            .map(|(b, m)| (b.w, b.h, m.as_slice()))
            .collect();
        let (pw, ph) = p.padded_size();
        p.crop(elevation_map(pw, ph, &maskers))
    }

    /// Qu & Meyer §4.2's visual masking map: `image` compared with `smooth`, its low-passed
    /// copy, through stages 1–5, so that only the detail the low pass removed counts (a slow
    /// gradient or a step between flat regions masks little), and per pixel the largest
    /// threshold elevation (≥ 1) that the difference's local band magnitude gives.
    pub fn masking_against(&self, image: &LinearImage, smooth: &LinearImage) -> Result<ErrorMap> {
        same_size(image, smooth)?;
        let (a, b) = (self.prepare(image), self.prepare(smooth));
        let detail: Vec<(usize, usize, Vec<f32>)> = a
            .bands
            .iter()
            .zip(&b.bands)
            .map(|(x, y)| {
                let d: Vec<f32> = x.v.iter().zip(&y.v).map(|(p, q)| p - q).collect();
                (x.w, x.h, masking::local_magnitude(&d, x.w, x.h))
            })
            .collect();
        let maskers: Vec<(usize, usize, &[f32])> = detail
            .iter()
            .map(|(w, h, m)| (*w, *h, m.as_slice()))
            .collect();
        let (pw, ph) = a.padded_size();
        Ok(a.crop(elevation_map(pw, ph, &maskers)))
    }
}

/// Per pixel of a `w × h` image, the largest [`threshold_elevation`] over bands of masker
/// magnitudes `(band width, band height, values)`, band k at 1/2^k resolution, each band's
/// elevations interpolated bilinearly between its sample centres (so a coarse band does not
/// print its sampling grid into the map).
fn elevation_map(w: usize, h: usize, maskers: &[(usize, usize, &[f32])]) -> Vec<f32> {
    let mut out = vec![1.0f32; w * h];
    for (k, &(bw, bh, m)) in maskers.iter().enumerate() {
        let e: Vec<f32> = m.iter().map(|&v| threshold_elevation(v)).collect();
        let scale = 1.0 / (1u64 << k) as f32;
        // Band coordinate of pixel coordinate i: sample centres at (j + ½)·2^k − ½.
        let at = |i: usize, n: usize| {
            let u = ((i as f32 + 0.5) * scale - 0.5).clamp(0.0, (n - 1) as f32);
            let j = (u.floor() as usize).min(n - 1);
            (j, (j + 1).min(n - 1), u - j as f32)
        };
        let xs: Vec<(usize, usize, f32)> = (0..w).map(|x| at(x, bw)).collect();
        out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            let (y0, y1, fy) = at(y, bh);
            let (r0, r1) = (&e[y0 * bw..][..bw], &e[y1 * bw..][..bw]);
            for (o, &(x0, x1, fx)) in row.iter_mut().zip(&xs) {
                let top = r0[x0] + (r0[x1] - r0[x0]) * fx;
                let bottom = r1[x0] + (r1[x1] - r1[x0]) * fx;
                *o = o.max(top + (bottom - top) * fy);
            }
        });
    }
    out
}

/// Centre frequency of band `k` at `ppd`, cycles per degree.
fn band_frequency(ppd: f64, k: usize) -> f64 {
    0.375 * ppd / (1u64 << k) as f64
}
