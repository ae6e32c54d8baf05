//! Viewing conditions: how large a pixel looks to the viewer, in pixels per degree of visual angle.
//!
//! Decision: pixels per degree follow FLIP's reference implementation (and its paper's
//! definition), the small-angle form ppd = d · (N_px / W) · π/180 for a display W metres wide with
//! N_px pixels seen from d metres. The default (ARCHITECTURE.md, "Defaults") — a 0.7 m wide, 3840-pixel display at
//! 0.7 m — gives 67.02 ppd.

/// A display and the viewer's distance to it.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Viewing {
    /// Display width in metres. Default value: 0.7.
    pub display_width_m: f64,
    /// Display width in pixels. Default value: 3840.
    pub display_px: f64,
    /// Viewing distance in metres. Default value: 0.7.
    pub distance_m: f64,
    /// Pixels per degree given directly, overriding the three fields above. Default value: None.
    pub ppd_override: Option<f64>,
}

impl Viewing {
    /// the defaults of the README's architecture section.
    pub const DEFAULT: Viewing = Viewing {
        display_width_m: 0.7,
        display_px: 3840.0,
        distance_m: 0.7,
        ppd_override: None,
    };

    /// A given number of pixels per degree.
    pub fn from_ppd(ppd: f64) -> Viewing {
        Viewing {
            ppd_override: Some(ppd),
            ..Self::DEFAULT
        }
    }

    /// A display of `width_m` metres and `px` pixels seen from `distance_m` metres.
    pub fn from_display(width_m: f64, px: f64, distance_m: f64) -> Viewing {
        Viewing {
            display_width_m: width_m,
            display_px: px,
            distance_m,
            ppd_override: None,
        }
    }

    /// Pixels per degree of visual angle.
    pub fn ppd(&self) -> f64 {
        self.ppd_override.unwrap_or(
            self.distance_m * (self.display_px / self.display_width_m) * std::f64::consts::PI
                / 180.0,
        )
    }

    /// `Ok` when every field is a finite number above 0 and the pixels per degree they give lie
    /// within [`crate::limits::PPD`]; else the message (the metrics' filters are sized by it, so
    /// 1e-30 gave NaN scores and 1e30 an allocation that aborted).
    pub fn check(&self) -> Result<(), String> {
        let fields = [
            ("display width", self.display_width_m, "m"),
            ("display pixels", self.display_px, "px"),
            ("viewing distance", self.distance_m, "m"),
        ];
        if self.ppd_override.is_none() {
            for (name, v, unit) in fields {
                if !(v.is_finite() && v > 0.0) {
                    return Err(format!(
                        "the {name} {v} {unit} is not a finite number above 0"
                    ));
                }
            }
        }
        use crate::limits::{PPD, Quantity};
        let ppd = self.ppd();
        match PPD.refuse(ppd) {
            None => Ok(()),
            Some(m) if self.ppd_override.is_some() => Err(format!("pixels per degree {m}")),
            Some(_) => Err(format!(
                "the display ({} m wide, {} px, seen from {} m) gives {} pixels per degree, {}",
                self.display_width_m.show(),
                self.display_px.show(),
                self.distance_m.show(),
                ppd.show(),
                PPD.outside()
            )),
        }
    }
}

impl Default for Viewing {
    fn default() -> Self {
        Self::DEFAULT
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_67_ppd() {
        // 0.7 · (3840 / 0.7) · π / 180 = 3840 · π / 180 = 67.0206.
        assert!((Viewing::DEFAULT.ppd() - 67.020_643).abs() < 1e-5);
    }
}
