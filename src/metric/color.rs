//! Colour encodings. Rendering and metrics work in linear RGB `f32`; sRGB appears only when
//! reading or writing 8-bit images (DESIGN.md, "Colour").
//!
//! Based on: IEC 61966-2-1:1999 (sRGB transfer function, piecewise with the linear toe).

/// sRGB-encoded value in 0..1 → linear light.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear light in 0..1 → sRGB-encoded value.
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Rec. 709 luminance of linear RGB (DESIGN.md: the luminance lodeval uses unless a metric's
/// definition says otherwise).
pub fn luminance(c: glam::Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_known_points() {
        // Mid-grey sRGB 0.5 is 0.214 linear (the DESIGN.md background).
        assert!((srgb_to_linear(0.5) - 0.214_041).abs() < 1e-5);
        for i in 0..=255 {
            let c = i as f32 / 255.0;
            assert!((linear_to_srgb(srgb_to_linear(c)) - c).abs() < 1e-5);
        }
    }
}
