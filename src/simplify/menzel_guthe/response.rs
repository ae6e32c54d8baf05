//! §4.1: from a shaded colour to what the visual system compares — the display's light, the
//! cones' absorptions, their JND-scaled responses and the opponent channels.
//!
//! Based on: Nicolas Menzel, Michael Guthe. Towards Perceptual Simplification of Models with
//! Arbitrary Materials. Pacific Graphics 2010, §4.1: sRGB → linear → XYZ → LMS (Hunt 1995) →
//! l = k_l·log(y + k_y) with k_l = 100, k_y = 1.02 cd/m² → the Poirson–Wandell (1996) opponent
//! channels W−K, R−G, B−Y. The conversions themselves live in `crate::color`.
//!
//! Decision: the shaded colour is linear RGB in the display's [0, 1] range (what the rasterizer
//! writes); the display model of the README (`metric::vdp::Display`: 100 cd/m² white, 0.5 cd/m²
//! black, reflected room light) turns it into cd/m², the black and reflected light counted as
//! achromatic (D65). The paper used a 1000 cd/m² display and notes it has little influence.

use glam::Vec3;

use crate::color::{WHITE, jnd_response, lms_to_opponent, rgb_to_xyz, xyz_to_lms};
use crate::metric::vdp::Display;

/// The opponent-channel JND responses (W−K, R−G, B−Y) of a linear RGB colour on `display`.
#[derive(Debug, Clone, Copy)]
pub struct Response {
    /// (peak − black) cd/m²: the scale of the linear range.
    gain: f32,
    /// Luminance at linear 0 (black level and reflected room light), cd/m².
    floor: f32,
}

impl Response {
    /// The response model of `display`.
    pub fn new(display: &Display) -> Response {
        Response {
            gain: display.peak_cd_m2 - display.black_cd_m2,
            floor: display.black_cd_m2 + display.reflected_cd_m2(),
        }
    }

    /// The display's light for linear RGB `c` (each channel clamped to [0, 1]) as CIE XYZ in
    /// cd/m².
    pub fn xyz(&self, c: Vec3) -> Vec3 {
        rgb_to_xyz(c.clamp(Vec3::ZERO, Vec3::ONE)) * self.gain + WHITE * self.floor
    }

    /// W−K, R−G, B−Y of linear RGB `c`, in JND-scaled units.
    pub fn opponent(&self, c: Vec3) -> Vec3 {
        let lms = xyz_to_lms(self.xyz(c));
        lms_to_opponent(Vec3::new(
            jnd_response(lms.x),
            jnd_response(lms.y),
            jnd_response(lms.z),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_one_percent_step_is_about_one_jnd_on_the_achromatic_channel() {
        // k_l = 100 with the natural logarithm: d l / d y = 100 / (y + 1.02), so a 1 % luminance
        // step of a bright grey moves each cone response by about 1 unit, and the achromatic
        // channel (row sum 0.990 − 0.106 − 0.094 = 0.79) by about 0.79.
        let r = Response::new(&Display::DEFAULT);
        let (a, b) = (r.opponent(Vec3::splat(0.5)), r.opponent(Vec3::splat(0.505)));
        let step = b.x - a.x;
        assert!((0.7..0.8).contains(&step), "{step}");
        // A grey change leaves red–green nearly alone (its row sums to 0.046).
        assert!((b.y - a.y).abs() < 0.1 * step, "{a} {b}");
        // A red change moves red–green.
        let red = r.opponent(Vec3::new(0.55, 0.5, 0.5));
        assert!((red.y - a.y).abs() > 1.0, "{red} {a}");
    }
}
