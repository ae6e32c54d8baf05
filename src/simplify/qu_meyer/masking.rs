//! §4.2: the visual masking map of the surface signal — where the signal's own detail and
//! brightness hide a change, so that fewer vertices are needed there. Brighter = stronger
//! masking, as in the paper's Figures 3–5.
//!
//! Based on: Qu & Meyer §4.2: the signal compared by a visual discrimination metric with a
//! Gaussian low-passed copy of itself ("a filter kernel of size 15, one degree of vision for our
//! viewing distance and display dot pitch"), so that only the detail the low pass removes counts
//! as a masker, "combined linearly" with the threshold-vs-intensity map of Ferwerda et al. 1996.
//! Their metric is the Sarnoff VDM; ours is lodeval's calibrated VDP (`metric::vdp`), whose stage
//! 5 gives per band the threshold elevation of a masker of known JND.
//!
//! The map, per texel: M = (1 − w)·E_pattern + w·E_tvi with w = ½ by default, where
//! - E_pattern ≥ 1 is the largest threshold elevation over the VDP's bands that the signal's
//!   detail (signal minus its low pass, band by band, local magnitude in JND) gives
//!   (`Vdp::masking_against`);
//! - E_tvi = t(L_a)/t(L̄) is the TVI threshold at the texel's adaptation luminance (the low-passed
//!   signal on the display) over the threshold at the map's mean luminance: above 1 where the
//!   surface is brighter than average, below where it is darker ("brighter areas receive fewer
//!   samples than do darker surface features").
//!
//! A uniform signal gives M = 1 everywhere (no masking). The weights are ours (the paper gives
//! none); both terms are threshold multipliers, so any mix of them is one too. w = 0 keeps the
//! pattern term alone (the experiment measures both).
//!
//! Decisions: the map is seen one texel per display pixel at the configured pixels per degree;
//! the low pass's σ is 1/6 of a degree (its ±3σ kernel spans the paper's one degree). Texels no
//! chart covers are filled with the normalised convolution of the covered ones (the same
//! Gaussian), so that chart borders in the layout are not taken for edges in the signal.

use glam::Vec3;

use crate::error::Result;
use crate::image::LinearImage;
use crate::metric::tvi;
use crate::metric::vdp::{Display, Vdp};
use crate::scene::Viewing;

/// The masking map and what it was made of.
#[derive(Debug, Clone)]
pub struct MaskingMap {
    /// M per texel (1 where uncovered).
    pub masking: Vec<f32>,
    /// The pattern term E_pattern.
    pub pattern: Vec<f32>,
    /// The luminance term E_tvi.
    pub tvi: Vec<f32>,
}

/// σ of the low pass, degrees.
pub const LOW_PASS_SIGMA_DEG: f64 = 1.0 / 6.0;

/// Gaussian blur of `rgb` weighted by `weight` (normalised convolution), σ in texels; where the
/// weight around a texel is below 1e-4 of a full one, `fallback`.
fn weighted_blur(
    size: usize,
    rgb: &[Vec3],
    weight: &[f32],
    sigma: f32,
    fallback: Vec3,
) -> Vec<Vec3> {
    let side = size as u32;
    let buf: Vec<f32> = rgb
        .iter()
        .zip(weight)
        .flat_map(|(c, &w)| [c.x * w, c.y * w, c.z * w, w])
        .collect();
    let img = image::Rgba32FImage::from_raw(side, side, buf).expect("size × size RGBA");
    let blurred = image::imageops::blur(&img, sigma);
    blurred
        .pixels()
        .map(|p| {
            let w = p.0[3];
            if w > 1e-4 {
                Vec3::new(p.0[0], p.0[1], p.0[2]) / w
            } else {
                fallback
            }
        })
        .collect()
}

/// The masking map of the signal `signal` (linear RGB, `size × size`), covered where `covered`,
/// seen at `ppd` pixels per degree on `display`, the TVI term weighted `tvi_weight` (0 to 1).
pub fn masking_map(
    size: usize,
    signal: &[Vec3],
    covered: &[bool],
    ppd: f64,
    display: Display,
    tvi_weight: f32,
) -> Result<MaskingMap> {
    let n = size * size;
    let weight: Vec<f32> = covered.iter().map(|&c| f32::from(u8::from(c))).collect();
    let count = weight.iter().filter(|&&w| w > 0.0).count().max(1);
    let mean = signal
        .iter()
        .zip(covered)
        .filter(|(_, c)| **c)
        .fold(glam::DVec3::ZERO, |a, (s, _)| a + s.as_dvec3())
        / count as f64;
    let sigma = (LOW_PASS_SIGMA_DEG * ppd) as f32;
    // The signal, extended past the charts by its own neighbourhood.
    let extended = weighted_blur(size, signal, &weight, sigma, mean.as_vec3());
    let filled: Vec<Vec3> = (0..n)
        .map(|i| if covered[i] { signal[i] } else { extended[i] })
        .collect();
    let low = weighted_blur(size, &filled, &vec![1.0; n], sigma, mean.as_vec3());
    let (Some(filled_img), Some(low_img)) = (
        LinearImage::new(size, size, filled),
        LinearImage::new(size, size, low.clone()),
    ) else {
        return Err(crate::error::Error::Internal(
            "masking map: the signal has no texels".into(),
        ));
    };
    let vdp = Vdp::new(&Viewing::from_ppd(ppd), display);
    let pattern = vdp.masking_against(&filled_img, &low_img)?.values;
    // Adaptation luminance: the low pass on the display; the reference is the covered mean.
    let la: Vec<f64> = low
        .iter()
        .map(|&c| display.luminance(crate::color::luminance(c)) as f64)
        .collect();
    let la_mean = la
        .iter()
        .zip(covered)
        .filter(|(_, c)| **c)
        .map(|(l, _)| l)
        .sum::<f64>()
        / count as f64;
    let t_ref = tvi::threshold(la_mean);
    let tvi_map: Vec<f32> = la
        .iter()
        .map(|&l| (tvi::threshold(l) / t_ref) as f32)
        .collect();
    let masking = (0..n)
        .map(|i| {
            if covered[i] {
                (1.0 - tvi_weight) * pattern[i] + tvi_weight * tvi_map[i]
            } else {
                1.0
            }
        })
        .collect();
    Ok(MaskingMap {
        masking,
        pattern,
        tvi: tvi_map,
    })
}
