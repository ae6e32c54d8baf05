//! The display transform: exposure in stops, then a tone mapper, turning rendered radiance into
//! the linear [0, 1] values a display shows (which is what the metrics and the VDP score, and
//! what 8-bit outputs encode as sRGB).
//!
//! Based on: the Khronos PBR Neutral tone mapper (Khronos 3D Commerce working group, 2024; the
//! reference GLSL of its specification: compression starts at 0.8 − 0.04, desaturation 0.15);
//! Stephen Hill's fit of the ACES RRT + ODT (the `RRTAndODTFit` rational polynomial between the
//! sRGB → AP1 input matrix and the AP1 → sRGB output matrix, as in BakingLab and the Khronos
//! sample renderer's "ACES Hill" choice); `linear` clamps to [0, 1] (what a renderer without a
//! tone mapper shows).
//!
//! Decisions:
//! - The transform runs per pixel after the samples are resolved in linear light (as a camera
//!   integrates radiance before its response; Blender's Cycles does the same), and only on the
//!   covered part of a pixel: the background is a display colour already and is blended after.
//! - The default for the `pbr` model is Khronos PBR Neutral: designed for product viewing, it
//!   leaves colours below 0.76 untouched but for a small offset in the darks, so base colours
//!   read as authored, and it is model-viewer's default. The Blinn–Phong models default to
//!   `linear` at exposure 0, which changes nothing they draw below 1.

/// A tone mapper.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ToneMapping {
    /// Clamp to [0, 1].
    Linear,
    /// Stephen Hill's ACES fit (RRT + sRGB ODT).
    Aces,
    /// Khronos PBR Neutral.
    PbrNeutral,
}

impl ToneMapping {
    /// Every tone mapper, in the order the CLI lists them.
    pub const ALL: [ToneMapping; 3] = [
        ToneMapping::Linear,
        ToneMapping::Aces,
        ToneMapping::PbrNeutral,
    ];
    /// The config/CLI name.
    pub fn name(self) -> &'static str {
        match self {
            ToneMapping::Linear => "linear",
            ToneMapping::Aces => "aces",
            ToneMapping::PbrNeutral => "pbr-neutral",
        }
    }
    /// Parse a config/CLI name.
    pub fn parse(name: &str) -> Option<ToneMapping> {
        Self::ALL.into_iter().find(|t| t.name() == name)
    }

    /// Map scene-linear `c` (after exposure) to display-linear [0, 1]. A NaN becomes 0 and +∞
    /// 1 (`f32::max` and `min` return the number where one operand is NaN).
    #[inline]
    // max/min, not clamp: clamp passes a NaN through, and no NaN may reach a frame.
    #[allow(clippy::manual_clamp)]
    pub fn apply(self, c: [f32; 3]) -> [f32; 3] {
        let c = c.map(|v| v.max(0.0).min(f32::MAX));
        let out = match self {
            ToneMapping::Linear => c,
            ToneMapping::Aces => aces_hill(c),
            ToneMapping::PbrNeutral => pbr_neutral(c),
        };
        out.map(|v| v.max(0.0).min(1.0))
    }
}

/// Khronos PBR Neutral (the specification's reference code, term for term).
fn pbr_neutral(mut c: [f32; 3]) -> [f32; 3] {
    const START: f32 = 0.8 - 0.04;
    const DESATURATION: f32 = 0.15;
    let x = c[0].min(c[1]).min(c[2]);
    let offset = if x < 0.08 { x - 6.25 * x * x } else { 0.04 };
    c = c.map(|v| v - offset);
    let peak = c[0].max(c[1]).max(c[2]);
    if peak < START {
        return c;
    }
    let d = 1.0 - START;
    let new_peak = 1.0 - d * d / (peak + d - START);
    c = c.map(|v| v * (new_peak / peak));
    let g = 1.0 - 1.0 / (DESATURATION * (peak - new_peak) + 1.0);
    c.map(|v| v + (new_peak - v) * g)
}

/// Stephen Hill's ACES fit: sRGB → AP1 (with the RRT's saturation), the RRT + ODT curve, AP1 →
/// sRGB.
fn aces_hill(c: [f32; 3]) -> [f32; 3] {
    const INPUT: [[f32; 3]; 3] = [
        [0.59719, 0.35458, 0.04823],
        [0.07600, 0.90834, 0.01566],
        [0.02840, 0.13383, 0.83777],
    ];
    const OUTPUT: [[f32; 3]; 3] = [
        [1.60475, -0.53108, -0.07367],
        [-0.10208, 1.10813, -0.00605],
        [-0.00327, -0.07276, 1.07602],
    ];
    let mul = |m: &[[f32; 3]; 3], v: [f32; 3]| {
        [0, 1, 2].map(|r| m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2])
    };
    let v = mul(&INPUT, c).map(|x| {
        let a = x * (x + 0.0245786) - 0.000090537;
        let b = x * (0.983729 * x + 0.432951) + 0.238081;
        a / b
    });
    mul(&OUTPUT, v)
}

/// Exposure and a tone mapper together.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DisplayTransform {
    /// 2^exposure.
    pub scale: f32,
    /// The tone mapper.
    pub tone_mapping: ToneMapping,
}

impl DisplayTransform {
    /// Map scene-linear `c` to display-linear.
    pub fn apply(&self, c: glam::Vec3) -> glam::Vec3 {
        glam::Vec3::from(self.tone_mapping.apply((c * self.scale).to_array()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pbr_neutral_keeps_mid_tones_and_compresses_highlights() {
        // Below the compression start only the dark offset applies: 0.5 grey loses 0.04.
        let mid = ToneMapping::PbrNeutral.apply([0.5; 3]);
        assert!((mid[0] - 0.46).abs() < 1e-6, "{mid:?}");
        // Very bright values approach but never pass 1, and stay ordered.
        let (a, b) = (
            ToneMapping::PbrNeutral.apply([2.0; 3])[0],
            ToneMapping::PbrNeutral.apply([20.0; 3])[0],
        );
        assert!(a < b && b < 1.0 && a > 0.9, "{a} {b}");
        // A saturated highlight desaturates towards white.
        let hot = ToneMapping::PbrNeutral.apply([8.0, 1.0, 1.0]);
        assert!(hot[1] > 0.2 && hot[0] < 1.0, "{hot:?}");
    }

    #[test]
    fn aces_maps_grey_as_hills_fit_does() {
        // A grey passes both matrices unchanged (their rows sum to 1), so it gets the RRT + ODT
        // fit alone: (x(x + 0.0245786) − 0.000090537) / (x(0.983729x + 0.4329510) + 0.238081),
        // worked by hand: 0.18 → 0.036733 / 0.347879 = 0.10559; 1 → 1.024488 / 1.654761 =
        // 0.61912.
        let g = ToneMapping::Aces.apply([0.18; 3]);
        let w = ToneMapping::Aces.apply([1.0; 3]);
        assert!(g.iter().all(|v| (v - 0.10559).abs() < 2e-4), "{g:?}");
        assert!(w.iter().all(|v| (v - 0.61912).abs() < 2e-4), "{w:?}");
    }

    #[test]
    fn linear_clamps_and_no_mapper_lets_a_nan_through() {
        assert_eq!(ToneMapping::Linear.apply([1.5, -0.2, 0.3]), [1.0, 0.0, 0.3]);
        for t in ToneMapping::ALL {
            assert!(
                t.apply([f32::NAN, f32::INFINITY, 0.5])
                    .iter()
                    .all(|v| v.is_finite())
            );
        }
    }
}
