//! HDR-FLIP: ꟻLIP for high-dynamic-range (linear, unbounded) images — both images exposed and
//! tone mapped over a range of exposures, LDR-FLIP at each, and per pixel the largest error.
//!
//! Based on: Pontus Andersson, Jim Nilsson, Peter Shirley, Tomas Akenine-Möller. Visualizing
//! Errors in Rendered High Dynamic Range Images. Eurographics 2021 (short paper), §3: exposure
//! compensation x = 2^c·L, the ACES filmic approximation as a rational polynomial
//! t(x) = (k0·x² + k1·x + k2) / (k3·x² + k4·x + k5) with Narkowicz's constants and the 0.6
//! pre-exposure folded in, and the automatic exposure range: c_start = log2(x_t / Y_max) and
//! c_stop = log2(x_t / Y_median) for the exposure x_t at which the tone mapper reaches t = 0.85,
//! Y the reference's luminance; max(2, ⌈c_stop − c_start⌉) exposures evenly spaced. The error of
//! a pixel is the largest LDR-FLIP over the exposures, the score the mean of that map (NVIDIA's
//! `flip-evaluator` 1.7 gives the oracle values, `reference/oracles/make_hdr_flip.py`; the median
//! is taken as that implementation takes it).
//!
//! Decision: the tone-mapped images go to LDR-FLIP as linear RGB in [0, 1], which is what the
//! reference implementation's sRGB encoding and FLIP's own decoding of it amount to.

use glam::Vec3;

use super::flip::{Flip, FlipScore};
use crate::error::{Error, Result};
use crate::image::{ErrorMap, LinearImage, same_size};

/// ACES filmic tone curve coefficients (Narkowicz 2016) with the 0.6 pre-exposure folded in.
const ACES: [f64; 6] = [
    0.6 * 0.6 * 2.51,
    0.6 * 0.03,
    0.0,
    0.6 * 0.6 * 2.43,
    0.6 * 0.59,
    0.14,
];

/// The tone-mapped value at which the exposure range is anchored.
const T_ANCHOR: f64 = 0.85;

/// An exposure range.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Exposures {
    /// Shortest exposure c_start (stops).
    pub start: f64,
    /// Longest exposure c_stop (stops).
    pub stop: f64,
    /// Exposures evaluated, evenly spaced from start to stop.
    pub count: usize,
}

/// The result of an HDR-FLIP comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct HdrFlipScore {
    /// Mean of the per-pixel maximum over exposures, in [0, 1].
    pub mean: f64,
    /// Per pixel, the largest LDR-FLIP error over the exposures.
    pub map: ErrorMap,
    /// The exposures used.
    pub exposures: Exposures,
}

/// The ACES curve of `x` (≥ 0), clamped to [0, 1].
fn aces(x: f64) -> f64 {
    let [k0, k1, k2, k3, k4, k5] = ACES;
    let (n, d) = (k0 * x * x + k1 * x + k2, k3 * x * x + k4 * x + k5);
    if d.is_infinite() {
        return 1.0;
    }
    (n / d).clamp(0.0, 1.0)
}

/// The exposure at which the ACES curve reaches `t`.
fn aces_inverse(t: f64) -> f64 {
    let [k0, k1, k2, k3, k4, k5] = ACES;
    let c0 = (k1 - k4 * t) / (k0 - k3 * t);
    let c1 = (k2 - k5 * t) / (k0 - k3 * t);
    -0.5 * c0 + ((0.5 * c0).powi(2) - c1).sqrt()
}

/// The automatic exposure range for `reference` (the paper's §3); `None` for an all-black image.
pub fn exposures_for(reference: &LinearImage) -> Option<Exposures> {
    let mut y: Vec<f64> = reference
        .pixels()
        .iter()
        .map(|p| {
            let p = p.max(Vec3::ZERO);
            0.2126 * p.x as f64 + 0.7152 * p.y as f64 + 0.0722 * p.z as f64
        })
        .collect();
    y.sort_by(f64::total_cmp);
    let hi = *y.last()?;
    if hi <= 0.0 {
        return None;
    }
    // The median as NVIDIA's implementation takes it: the element at index n/2 of the sorted
    // luminances (the upper middle one for an even count; the paper's Python reference
    // interpolates between the two, a difference of about 5e-4 stops on the oracle pairs).
    let median = y[y.len() / 2];
    let x = aces_inverse(T_ANCHOR);
    let start = (x / hi).log2();
    // A median of 0 (mostly black) would put the stop at infinity: stop where the start is.
    let stop = if median > 0.0 {
        (x / median).log2()
    } else {
        start
    };
    let count = (stop - start).ceil().max(2.0) as usize;
    Some(Exposures { start, stop, count })
}

/// `image` exposed by 2^`c` and tone mapped.
fn tone_map(image: &LinearImage, c: f64) -> LinearImage {
    let scale = 2f64.powf(c);
    let px = image
        .pixels()
        .iter()
        .map(|p| {
            let m = |v: f32| aces(scale * (v.max(0.0) as f64)) as f32;
            Vec3::new(m(p.x), m(p.y), m(p.z))
        })
        .collect();
    LinearImage::new(image.width(), image.height(), px).expect("same size as the input")
}

/// HDR-FLIP of two linear images, over `exposures` or the automatic range.
pub fn hdr_flip(
    flip: &Flip,
    reference: &LinearImage,
    test: &LinearImage,
    exposures: Option<Exposures>,
) -> Result<HdrFlipScore> {
    same_size(reference, test)?;
    if reference
        .pixels()
        .iter()
        .chain(test.pixels())
        .any(|p| !p.is_finite())
    {
        return Err(Error::Usage(
            "HDR-FLIP: an image has NaN or infinite pixels; give finite, non-negative radiance"
                .into(),
        ));
    }
    let exposures = match exposures {
        Some(e) => {
            let stops = &crate::limits::EXPOSURE_STOPS;
            for v in [e.start, e.stop] {
                stops.check("HDR-FLIP exposure", v).map_err(Error::Usage)?;
            }
            e
        }
        None => exposures_for(reference).unwrap_or(Exposures {
            start: 0.0,
            stop: 0.0,
            count: 2,
        }),
    };
    if !(exposures.start.is_finite() && exposures.stop.is_finite())
        || exposures.stop < exposures.start
        || !(1..=crate::limits::EXPOSURES.max as usize).contains(&exposures.count)
    {
        return Err(Error::Usage(format!(
            "HDR-FLIP exposures {} to {} in {} steps: give a start at most the stop and 1 to {} \
             steps",
            exposures.start,
            exposures.stop,
            exposures.count,
            crate::limits::EXPOSURES.max
        )));
    }
    let step = (exposures.stop - exposures.start) / (exposures.count.max(2) - 1) as f64;
    let mut worst: Option<Vec<f32>> = None;
    for i in 0..exposures.count {
        let c = exposures.start + i as f64 * step;
        let FlipScore { map, .. } = flip.compare(&tone_map(reference, c), &tone_map(test, c))?;
        match &mut worst {
            None => worst = Some(map.values),
            Some(w) => {
                for (a, b) in w.iter_mut().zip(map.values) {
                    *a = a.max(b);
                }
            }
        }
    }
    let values = worst.unwrap_or_default();
    // f64 sum of the f32 map in row order, as LDR-FLIP's mean.
    let mean = values.iter().map(|&v| v as f64).sum::<f64>() / values.len().max(1) as f64;
    Ok(HdrFlipScore {
        mean,
        map: ErrorMap {
            width: reference.width(),
            height: reference.height(),
            values,
        },
        exposures,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tone_curve_and_its_inverse_agree() {
        for t in [0.1, 0.5, 0.85, 0.95] {
            assert!((aces(aces_inverse(t)) - t).abs() < 1e-12, "{t}");
        }
        assert_eq!(aces(0.0), 0.0);
        assert_eq!(aces(1e300), 1.0);
    }

    #[test]
    fn the_exposure_range_spans_the_median_to_the_peak() {
        // Luminance 1 everywhere but one pixel of 16: the start brings 16 to t = 0.85, the stop
        // brings 1 there, four stops apart (so 4 exposures).
        let mut px = vec![Vec3::ONE; 9];
        px[4] = Vec3::splat(16.0);
        let img = LinearImage::new(3, 3, px).unwrap();
        let e = exposures_for(&img).unwrap();
        assert!((e.stop - e.start - 4.0).abs() < 1e-9, "{e:?}");
        assert_eq!(e.count, 4);
        assert!(exposures_for(&LinearImage::new(1, 1, vec![Vec3::ZERO]).unwrap()).is_none());
    }
}
