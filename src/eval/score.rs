//! Scoring one rendered view pair with the configured metric families: the reference (the
//! original's render) is prepared once per view and compared with every LOD's render.
//!
//! Each family writes its metrics of `metric::catalog` (names, units and directions there): FLIP
//! its mean, `flip_p95` and `flip_share` (pixels over `flip_pixel_threshold`); PSNR the 8-bit
//! sRGB PSNR, luminance PSNR and MSE; the VDP its probability and JND.

use std::borrow::Cow;

use super::config::MetricFamily;
use super::tables::round7;
use crate::error::Result;
use crate::metric::flip::{Flip, FlipPrepared};
use crate::metric::vdp::{Display, Vdp, VdpPrepared};
use crate::metric::{ErrorMap, LinearImage, Metric, colormap, mse, pool, ssim};
use crate::scene::Viewing;

/// The configured metrics at one viewing condition.
#[derive(Debug, Clone)]
pub struct Scorer {
    families: Vec<MetricFamily>,
    flip: Flip,
    vdp: Vdp,
    flip_pixel: f32,
}

/// A reference image and its prepared forms.
#[derive(Debug)]
pub struct Reference {
    image: LinearImage,
    flip: Option<FlipPrepared>,
    vdp: Option<VdpPrepared>,
    /// SSIM's channel, for SSIM and MS-SSIM.
    ssim: Option<ssim::SsimPrepared>,
    /// 8-bit sRGB, for PSNR.
    srgb8: Option<image::RgbImage>,
}

/// Scores of one pair: values in metric-name order, and the error maps worth drawing.
#[derive(Debug, Clone, Default)]
pub struct Scored {
    /// (metric, value), rounded to 7 significant digits.
    pub values: Vec<(Metric, f64)>,
    /// (metric, per-pixel map in [0, 1] where larger is worse).
    pub maps: Vec<(Metric, ErrorMap)>,
    /// The test image in 8-bit sRGB, where PSNR made it anyway.
    pub srgb8: Option<image::RgbImage>,
}

impl Scored {
    /// A value by metric name.
    pub fn get(&self, metric: Metric) -> Option<f64> {
        self.values.iter().find(|v| v.0 == metric).map(|v| v.1)
    }
}

impl Reference {
    /// The reference in 8-bit sRGB, the encoding kept for PSNR where there is one.
    pub fn srgb8(&self) -> Cow<'_, image::RgbImage> {
        match &self.srgb8 {
            Some(rgb) => Cow::Borrowed(rgb),
            None => Cow::Owned(self.image.to_srgb8()),
        }
    }
}

impl Scorer {
    /// Metrics `families` at `viewing`; `flip_pixel` is the per-pixel FLIP level for `flip_share`.
    pub fn new(
        families: &[MetricFamily],
        viewing: &Viewing,
        display: Display,
        flip_pixel: f64,
    ) -> Scorer {
        let mut families = families.to_vec();
        families.sort();
        families.dedup();
        Scorer {
            families,
            flip: Flip::new(viewing.ppd() as f32),
            vdp: Vdp::new(viewing, display),
            flip_pixel: flip_pixel as f32,
        }
    }

    fn has(&self, f: MetricFamily) -> bool {
        self.families.contains(&f)
    }

    /// Prepare a reference image.
    pub fn prepare(&self, image: LinearImage) -> Reference {
        Reference {
            flip: self
                .has(MetricFamily::Flip)
                .then(|| self.flip.prepare(&image)),
            vdp: self
                .has(MetricFamily::Vdp)
                .then(|| self.vdp.prepare(&image)),
            ssim: (self.has(MetricFamily::Ssim) || self.has(MetricFamily::Msssim))
                .then(|| ssim::prepare(&image, ssim::SsimInput::SrgbLuma)),
            srgb8: self.has(MetricFamily::Psnr).then(|| image.to_srgb8()),
            image,
        }
    }

    /// Score `test` against a prepared reference.
    pub fn score(&self, reference: &Reference, test: &LinearImage) -> Result<Scored> {
        let mut out = Scored::default();
        let mut ssim_scores: Option<ssim::SsimScores> = None;
        for &family in &self.families {
            match family {
                MetricFamily::Flip => {
                    let prepared = reference.flip.as_ref().expect("prepared with FLIP");
                    let s = self
                        .flip
                        .compare_prepared(prepared, &self.flip.prepare(test))?;
                    let v = &s.map.values;
                    let over = v.iter().filter(|&&e| e > self.flip_pixel).count();
                    out.values.push((Metric::Flip, round7(s.mean)));
                    out.values.push((
                        Metric::FlipP95,
                        round7(pool::percentile(v, 95.0).unwrap_or(0.0)),
                    ));
                    out.values.push((
                        Metric::FlipShare,
                        round7(over as f64 / v.len().max(1) as f64),
                    ));
                    out.maps.push((Metric::Flip, s.map));
                }
                MetricFamily::Ssim | MetricFamily::Msssim => {
                    // One pass gives SSIM and MS-SSIM's first scale: made at the first of the
                    // two families, recorded at each.
                    if ssim_scores.is_none() {
                        let prepared = reference.ssim.as_ref().expect("prepared with SSIM");
                        let test = ssim::prepare(test, ssim::SsimInput::SrgbLuma);
                        ssim_scores = Some(ssim::compare_prepared(
                            prepared,
                            &test,
                            self.has(MetricFamily::Ssim),
                            self.has(MetricFamily::Msssim),
                        )?);
                    }
                    let scores = ssim_scores.as_mut().expect("made above");
                    if family == MetricFamily::Msssim {
                        out.values
                            .push((Metric::Msssim, round7(scores.ms.unwrap_or_default())));
                        continue;
                    }
                    out.values
                        .push((Metric::Ssim, round7(scores.mean.unwrap_or_default())));
                    out.maps.push((
                        Metric::Ssim,
                        ErrorMap {
                            width: test.width(),
                            height: test.height(),
                            values: std::mem::take(&mut scores.map)
                                .iter()
                                .map(|s| (1.0 - s).clamp(0.0, 1.0))
                                .collect(),
                        },
                    ));
                }
                MetricFamily::Psnr => {
                    let s = mse::mse(&reference.image, test)?;
                    let encoded = reference.srgb8.as_ref().expect("prepared with PSNR");
                    let test_encoded = test.to_srgb8();
                    let rgb = mse::psnr_srgb8_encoded(encoded, &test_encoded);
                    out.srgb8 = Some(test_encoded);
                    out.values.push((Metric::Psnr, round7(rgb)));
                    out.values.push((Metric::PsnrLuminance, round7(s.psnr_db)));
                    out.values.push((Metric::Mse, round7(s.mse)));
                }
                MetricFamily::Vdp => {
                    let prepared = reference.vdp.as_ref().expect("prepared with VDP");
                    let s = self
                        .vdp
                        .compare_prepared(prepared, &self.vdp.prepare(test))?;
                    out.values.push((Metric::Vdp, round7(s.probability)));
                    out.values.push((Metric::VdpJnd, round7(s.jnd)));
                    // Drawn on the JND scale: at a close-up render the probability is 1
                    // almost everywhere on the object, a solid blob.
                    let mut map = s.jnd_map;
                    map.values
                        .iter_mut()
                        .for_each(|v| *v = colormap::jnd_scale(*v));
                    out.maps.push((Metric::Vdp, map));
                }
            }
        }
        Ok(out)
    }
}
