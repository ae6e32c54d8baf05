//! Stage 1 of the VDP: from linear display values to a luminance-adapted, JND-scaled response.
//!
//! Based on: the display model of HDR-VDP (Rafał Mantiuk, Karol Myszkowski, Hans-Peter Seidel.
//! Visible Difference Predicator for High Dynamic Range Images. IEEE SMC 2004): a display maps
//! linear values to luminance between a black level and a peak; and Menzel & Guthe 2010 §4.1's
//! fit of the threshold-versus-intensity function, l = k_l·ln(y + k_y) with k_l = 100 and
//! k_y = 1.02 cd/m² ([`jnd_response`]), so that one unit of the response is one just-noticeable
//! luminance difference at any adaptation level: Weber behaviour (thresholds proportional to
//! luminance) on bright backgrounds, rising relative thresholds in the dark.
//!
//! Decision (DESIGN.md is silent on the display): 100 cd/m² peak, 0.5 cd/m² black — an office
//! monitor.

use rayon::prelude::*;

use crate::metric::LinearImage;
use crate::metric::color::{jnd_response, luminance};

/// The display the images are shown on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Display {
    /// Luminance of white, cd/m². Default value: 100.
    pub peak_cd_m2: f32,
    /// Luminance of black, cd/m². Default value: 0.5.
    pub black_cd_m2: f32,
}

impl Display {
    /// An office monitor.
    pub const DEFAULT: Display = Display {
        peak_cd_m2: 100.0,
        black_cd_m2: 0.5,
    };

    /// Luminance in cd/m² of a linear value (clamped to the display's range).
    pub fn luminance(&self, linear: f32) -> f32 {
        self.black_cd_m2 + (self.peak_cd_m2 - self.black_cd_m2) * linear.clamp(0.0, 1.0)
    }
}

impl Default for Display {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// JND-scaled response of every pixel (row-major).
pub(crate) fn response(image: &LinearImage, display: &Display) -> Vec<f32> {
    image
        .pixels()
        .par_iter()
        .map(|&c| jnd_response(display.luminance(luminance(c))))
        .collect()
}
