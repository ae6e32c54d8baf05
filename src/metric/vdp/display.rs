//! Stage 1 of the VDP: the display, from linear pixel values to the luminance that reaches the eye.
//!
//! Based on: the display model of HDR-VDP-2 (Rafał Mantiuk, Kil Joong Kim, Allan Rempel, Wolfgang
//! Heidrich. HDR-VDP-2: A calibrated visual metric for visibility and quality predictions in all
//! luminance conditions. ACM TOG 30(4) 2011, §3 "display model"): a display maps a linear value v
//! in [0, 1] to L = L_black + (L_peak − L_black)·v, and the screen reflects part of the room's
//! light, L_refl = k·E_amb/π for a screen of reflectivity k under E_amb lux (a Lambertian
//! reflector), which adds to every pixel.
//!
//! Decision (the papers leave the display open): the defaults are an office monitor in an office,
//! 100 cd/m² white, 0.5 cd/m² black, 250 lux of ambient light on a matte screen of reflectivity
//! 0.5 % (0.4 cd/m² reflected). The rendered images are linear light already (the
//! colour contract), so the display applies no transfer function of its own: `v` is the linear
//! value an sRGB display would produce from the encoded pixel.
//!
//! # Guarantees
//! A [`Display`] built with [`Display::new`] has finite values, a peak above its black level and
//! a non-negative black level, ambient illuminance and reflectivity; every luminance it returns is
//! finite and positive (≥ black + reflection > 0 unless both are 0, which `new` refuses).

use crate::error::{Error, Result};

/// The display the images are shown on, and the room it stands in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Display {
    /// Luminance of white, cd/m². Default value: 100.
    pub peak_cd_m2: f32,
    /// Luminance of black in a dark room, cd/m². Default value: 0.5.
    pub black_cd_m2: f32,
    /// Illuminance of the room's light on the screen, lux. Default value: 250.
    pub ambient_lux: f32,
    /// Fraction of the ambient light the screen reflects (Lambertian). Default value: 0.005.
    pub reflectivity: f32,
}

impl Display {
    /// An office monitor in an office.
    pub const DEFAULT: Display = Display {
        peak_cd_m2: 100.0,
        black_cd_m2: 0.5,
        ambient_lux: 250.0,
        reflectivity: 0.005,
    };

    /// A display, checked: every value finite; 0 ≤ black < peak; ambient ≥ 0; reflectivity in
    /// [0, 1]; and some light at black (black + reflection > 0), or the logarithm of a black pixel
    /// would be −∞.
    pub fn new(
        peak_cd_m2: f32,
        black_cd_m2: f32,
        ambient_lux: f32,
        reflectivity: f32,
    ) -> Result<Display> {
        let d = Display {
            peak_cd_m2,
            black_cd_m2,
            ambient_lux,
            reflectivity,
        };
        let bad = |what: String| {
            Err(Error::Usage(format!(
                "display: {what}; give finite values with 0 ≤ black < peak (cd/m²), ambient ≥ 0 \
                 lux and reflectivity in [0, 1]"
            )))
        };
        for (name, v) in [
            ("peak luminance", peak_cd_m2),
            ("black level", black_cd_m2),
            ("ambient illuminance", ambient_lux),
            ("reflectivity", reflectivity),
        ] {
            if !v.is_finite() {
                return bad(format!("the {name} is {v}"));
            }
        }
        if peak_cd_m2 <= 0.0 {
            return bad(format!("the peak luminance is {peak_cd_m2} cd/m²"));
        }
        if black_cd_m2 < 0.0 || black_cd_m2 >= peak_cd_m2 {
            return bad(format!(
                "the black level {black_cd_m2} cd/m² is not in [0, peak = {peak_cd_m2})"
            ));
        }
        if ambient_lux < 0.0 || !(0.0..=1.0).contains(&reflectivity) {
            return bad(format!(
                "ambient {ambient_lux} lux with reflectivity {reflectivity}"
            ));
        }
        if d.reflected_cd_m2() + black_cd_m2 <= 0.0 {
            return bad(
                "black is 0 cd/m² with no reflected light (a black pixel would have no \
                        luminance at all)"
                    .to_string(),
            );
        }
        Ok(d)
    }

    /// Luminance the screen reflects from the room, cd/m² (k·E/π).
    pub fn reflected_cd_m2(&self) -> f32 {
        self.reflectivity * self.ambient_lux / std::f32::consts::PI
    }

    /// Luminance in cd/m² of a linear value (clamped to the display's range, NaN as 0), reflection
    /// included.
    pub fn luminance(&self, linear: f32) -> f32 {
        self.black_cd_m2
            + self.reflected_cd_m2()
            + (self.peak_cd_m2 - self.black_cd_m2)
                * if linear.is_nan() {
                    0.0
                } else {
                    linear.clamp(0.0, 1.0)
                }
    }

    /// The linear value this display shows as `cd_m2` (outside [0, 1] when out of its range): puts
    /// a stimulus's background at a given luminance (ModelFest's 30 cd/m²).
    pub fn linear_for(&self, cd_m2: f32) -> f32 {
        (cd_m2 - self.black_cd_m2 - self.reflected_cd_m2()) / (self.peak_cd_m2 - self.black_cd_m2)
    }
}

impl Default for Display {
    fn default() -> Self {
        Self::DEFAULT
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_display_is_an_office_monitor() {
        let d = Display::DEFAULT;
        assert_eq!(Display::new(100.0, 0.5, 250.0, 0.005).unwrap(), d);
        // 0.005 · 250 / π = 0.398 cd/m² reflected on top of the 0.5 cd/m² black.
        assert!((d.luminance(0.0) - 0.898).abs() < 1e-3);
        assert!((d.luminance(1.0) - 100.398).abs() < 1e-3);
        assert!((d.luminance(d.linear_for(30.0)) - 30.0).abs() < 1e-4);
    }

    #[test]
    fn nonsense_displays_are_refused() {
        for (p, b, a, k) in [
            (0.0, 0.0, 0.0, 0.0),
            (-1.0, 0.0, 10.0, 0.01),
            (100.0, 100.0, 0.0, 0.0),
            (100.0, -0.1, 0.0, 0.0),
            (f32::NAN, 0.5, 0.0, 0.0),
            (100.0, 0.5, f32::INFINITY, 0.0),
            (100.0, 0.5, 10.0, 1.5),
            (100.0, 0.0, 0.0, 0.01),
        ] {
            assert!(Display::new(p, b, a, k).is_err(), "{p} {b} {a} {k}");
        }
    }
}
