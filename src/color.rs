//! Colour encodings and colour spaces. Rendering and metrics work in linear RGB `f32`; sRGB appears only when
//! reading or writing 8-bit images (ARCHITECTURE.md, "Colour").
//!
//! Based on: IEC 61966-2-1:1999 (sRGB transfer function, piecewise with the linear toe; the
//! linear-sRGB ↔ XYZ matrices for D65); CIE 15 (CIELAB); Xuemei Zhang, Brian Wandell. A Spatial
//! Extension of CIELAB for Digital Color Image Reproduction. SID 1996 (YCxCz); Robert Hunt. The
//! Reproduction of Colour 1995 (XYZ → LMS); Allen Poirson, Brian Wandell. Pattern–Color Separable
//! Pathways Predict Sensitivity to Simple Colored Patterns. Vision Research 1996 (opponent space);
//! Nicolas Menzel, Michael Guthe. Pacific Graphics 2010 §4.1 (the JND-scaled response).

use glam::Vec3;

/// sRGB-encoded value in 0..1 → linear light.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear light of every 8-bit sRGB code value (index = byte).
pub fn srgb8_to_linear_table() -> [f32; 256] {
    std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0))
}

/// Linear light in 0..1 → sRGB-encoded value.
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Linear light → the 8-bit sRGB code a PNG stores, round(255 · sRGB(clamp(c, 0, 1))): the one
/// encoding every 8-bit output and the 8-bit PSNR use. Exact (the same code as the formula for
/// every input) and without a `powf`: the 255 inputs at which the code steps up are found once by
/// bisection over the bits of the formula's input, and a code is the number of steps at or below
/// `c` (a test compares both around every step). The count starts from a table of the code at
/// the start of each 1/128 of an octave of `c` (the top 16 bits of its `f32`), within which the
/// code rises by at most two steps.
pub fn linear_to_srgb8(c: f32) -> u8 {
    const SHIFT: u32 = 16;
    struct Tables {
        steps: [f32; 255],
        start: Vec<u8>,
    }
    static TABLES: std::sync::OnceLock<Tables> = std::sync::OnceLock::new();
    let t = TABLES.get_or_init(|| {
        let mut steps = [0.0f32; 255];
        for (k, step) in steps.iter_mut().enumerate() {
            // The smallest non-negative float whose code is at least k + 1.
            let (mut lo, mut hi) = (0u32, 1.0f32.to_bits());
            while lo < hi {
                let mid = lo + (hi - lo) / 2;
                if linear_to_srgb8_formula(f32::from_bits(mid)) as usize > k {
                    hi = mid;
                } else {
                    lo = mid + 1;
                }
            }
            *step = f32::from_bits(lo);
        }
        let start = (0..=(1.0f32.to_bits() >> SHIFT))
            .map(|b| {
                let first = f32::from_bits(b << SHIFT);
                steps.partition_point(|&s| s <= first) as u8
            })
            .collect();
        Tables { steps, start }
    });
    // NaN and everything at or below zero encode as 0, everything at or above one as 255.
    if c.is_nan() || c <= 0.0 {
        return 0;
    }
    if c >= 1.0 {
        return 255;
    }
    let mut k = t.start[(c.to_bits() >> SHIFT) as usize] as usize;
    while k < 255 && t.steps[k] <= c {
        k += 1;
    }
    k as u8
}

/// [`linear_to_srgb8`] by its formula.
pub fn linear_to_srgb8_formula(c: f32) -> u8 {
    (linear_to_srgb(c.clamp(0.0, 1.0)) * 255.0).round() as u8
}

/// D65 reference white (XYZ, Y = 1), with the digits of NVIDIA's FLIP reference implementation,
/// whose results lodeval's FLIP reproduces (FLIP's error at nearly identical pixels is sensitive to
/// the last bit of every constant).
#[allow(clippy::excessive_precision)]
pub const WHITE: Vec3 = Vec3::new(0.950428545, 1.000000000, 1.088900371);
/// Component-wise inverse of [`WHITE`], digits as in FLIP's reference implementation.
#[allow(clippy::excessive_precision)]
pub const INV_WHITE: Vec3 = Vec3::new(1.052156925, 1.000000000, 0.918357670);

/// Linear sRGB → CIE XYZ (D65).
pub fn rgb_to_xyz(c: Vec3) -> Vec3 {
    let m = [
        [
            10_135_552.0 / 24_577_794.0,
            8_788_810.0 / 24_577_794.0,
            4_435_075.0 / 24_577_794.0,
        ],
        [
            2_613_072.0 / 12_288_897.0,
            8_788_810.0 / 12_288_897.0,
            887_015.0 / 12_288_897.0,
        ],
        [
            1_425_312.0 / 73_733_382.0,
            8_788_810.0 / 73_733_382.0,
            70_074_185.0 / 73_733_382.0,
        ],
    ];
    Vec3::new(
        m[0][0] * c.x + m[0][1] * c.y + m[0][2] * c.z,
        m[1][0] * c.x + m[1][1] * c.y + m[1][2] * c.z,
        m[2][0] * c.x + m[2][1] * c.y + m[2][2] * c.z,
    )
}

/// CIE XYZ → linear sRGB (D65).
#[allow(clippy::excessive_precision)]
pub fn xyz_to_rgb(c: Vec3) -> Vec3 {
    Vec3::new(
        3.241003275 * c.x + -1.537398934 * c.y + -0.498615861 * c.z,
        -0.969224334 * c.x + 1.875930071 * c.y + 0.041554224 * c.z,
        0.055639423 * c.x + -0.204011202 * c.y + 1.057148933 * c.z,
    )
}

/// XYZ → YCxCz, the linearised CIELAB of Zhang & Wandell's S-CIELAB (used by FLIP).
pub fn xyz_to_ycxcz(c: Vec3) -> Vec3 {
    let c = c * INV_WHITE;
    Vec3::new(116.0 * c.y - 16.0, 500.0 * (c.x - c.y), 200.0 * (c.y - c.z))
}

/// YCxCz → XYZ.
pub fn ycxcz_to_xyz(c: Vec3) -> Vec3 {
    let y = (c.x + 16.0) / 116.0;
    Vec3::new(y + c.y / 500.0, y, y - c.z / 200.0) * WHITE
}

/// XYZ → CIELAB (D65).
pub fn xyz_to_lab(c: Vec3) -> Vec3 {
    let delta = 6.0f32 / 29.0;
    let delta_sq = delta * delta;
    let delta_cube = delta * delta_sq;
    let factor = 1.0 / (3.0 * delta_sq);
    let term = 4.0f32 / 29.0;
    let c = c * INV_WHITE;
    let f = |v: f32| {
        if v > delta_cube {
            v.powf(1.0 / 3.0)
        } else {
            factor * v + term
        }
    };
    let (x, y, z) = (f(c.x), f(c.y), f(c.z));
    Vec3::new(116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z))
}

/// XYZ → LMS cone space (Hunt 1995; Menzel & Guthe 2010 §4.1).
pub fn xyz_to_lms(c: Vec3) -> Vec3 {
    Vec3::new(
        0.7328 * c.x + 0.4296 * c.y - 0.1624 * c.z,
        -0.7036 * c.x + 1.6975 * c.y + 0.0061 * c.z,
        0.0030 * c.x + 0.0136 * c.y + 0.9834 * c.z,
    )
}

/// Menzel & Guthe's JND-scaled response l = k_l·ln(y + k_y) of a linear cone (or luminance)
/// signal y in cd/m², with their least-squares fit to the threshold-versus-intensity function:
/// k_l = 100, k_y = 1.02 cd/m². One unit of l is one just-noticeable difference: dl/dy =
/// k_l/(y + k_y), i.e. a 1 % Weber fraction at high luminance. Decision: the paper writes "log";
/// the natural logarithm is taken, the one whose 1 % Weber fraction matches the classic value.
pub fn jnd_response(y: f32) -> f32 {
    const K_L: f32 = 100.0;
    const K_Y: f32 = 1.02;
    K_L * (y.max(0.0) + K_Y).ln()
}

/// JND-scaled L′M′S′ → the opponent space of Poirson & Wandell 1996 (white–black, red–green,
/// blue–yellow), as Menzel & Guthe 2010 §4.1 use it.
pub fn lms_to_opponent(c: Vec3) -> Vec3 {
    Vec3::new(
        0.990 * c.x - 0.106 * c.y - 0.094 * c.z,
        -0.669 * c.x + 0.742 * c.y - 0.027 * c.z,
        -0.212 * c.x - 0.354 * c.y + 0.911 * c.z,
    )
}

/// Nodes of [`linear_to_srgb_fast`]'s table, uniform in √x.
const FAST_NODES: usize = 4096;

/// Linear → sRGB through a table uniform in √x with linear interpolation, exact (linear) below the
/// sRGB toe. Parametrising by √x makes the curve smooth enough that the interpolation error stays
/// below 1e-6 (tested), about 10× faster than `powf` — SSIM encodes every pixel with it.
pub fn linear_to_srgb_fast(c: f32) -> f32 {
    static TABLE: std::sync::OnceLock<Vec<f32>> = std::sync::OnceLock::new();
    if c <= 0.003_130_8 {
        return c * 12.92;
    }
    let table = TABLE.get_or_init(|| {
        (0..=FAST_NODES)
            .map(|i| {
                let s = i as f64 / FAST_NODES as f64;
                let x = s * s;
                (if x <= 0.003_130_8 {
                    x * 12.92
                } else {
                    1.055 * x.powf(1.0 / 2.4) - 0.055
                }) as f32
            })
            .collect()
    });
    let s = c.min(1.0).sqrt() * FAST_NODES as f32;
    let i = (s as usize).min(FAST_NODES - 1);
    let t = s - i as f32;
    if c > 1.0 {
        return linear_to_srgb(c);
    }
    table[i] + (table[i + 1] - table[i]) * t
}

/// Rec. 709 luminance of linear RGB (ARCHITECTURE.md, "Colour": the luminance lodeval uses unless a metric's
/// definition says otherwise).
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_8_bit_encoding_by_steps_equals_the_formula() {
        // Around every step (±4096 floats) and on a sweep of the whole range, both encodings
        // agree; out-of-range and NaN inputs clip as the formula does.
        let check = |v: f32| assert_eq!(linear_to_srgb8(v), linear_to_srgb8_formula(v), "{v}");
        for k in 0..=255u32 {
            let v = srgb_to_linear(k as f32 / 255.0);
            let bits = v.to_bits();
            for d in 0..8192u32 {
                check(f32::from_bits((bits + d).saturating_sub(4096)));
            }
        }
        for i in 0..=1_000_000u32 {
            check(i as f32 / 1_000_000.0);
        }
        for v in [
            -1.0,
            -0.0,
            0.0,
            1.0,
            1.5,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ] {
            check(v);
        }
    }

    #[test]
    fn colour_spaces_at_known_points() {
        // D65 white (linear RGB 1) is XYZ ≈ (0.9505, 1, 1.089) and CIELAB (100, 0, 0).
        let white = rgb_to_xyz(Vec3::ONE);
        assert!((white - WHITE).length() < 1e-4, "{white}");
        let lab = xyz_to_lab(white);
        assert!((lab - Vec3::new(100.0, 0.0, 0.0)).length() < 1e-2, "{lab}");
        // XYZ ↔ RGB and XYZ ↔ YCxCz are inverse pairs.
        let c = Vec3::new(0.2, 0.5, 0.7);
        assert!((xyz_to_rgb(rgb_to_xyz(c)) - c).length() < 1e-5);
        assert!((ycxcz_to_xyz(xyz_to_ycxcz(c)) - c).length() < 1e-5);
        // The JND response: one unit of l is a 1 % change at high luminance.
        let (y, dy) = (100.0f32, 1.0f32);
        assert!(
            (jnd_response(y + dy) - jnd_response(y) - 100.0 * (101.0f32 + 1.02).ln()
                + 100.0 * (100.0f32 + 1.02).ln())
            .abs()
                < 1e-3
        );
        assert!((jnd_response(1000.0 * 1.01) - jnd_response(1000.0) - 0.99).abs() < 0.02);
        // Equal cone responses are achromatic: the red–green and blue–yellow channels nearly
        // vanish (the published matrix rows sum to ≈ 0 for the chromatic channels).
        let o = lms_to_opponent(Vec3::splat(1.0));
        assert!(o.y.abs() < 0.05 && o.z.abs() < 0.35 && o.x > 0.7, "{o}");
    }

    #[test]
    fn round_trip_and_known_points() {
        // Mid-grey sRGB 0.5 is 0.214 linear (the default background).
        assert!((srgb_to_linear(0.5) - 0.214_041).abs() < 1e-5);
        for i in 0..=100_000 {
            let x = i as f32 / 100_000.0;
            assert!(
                (linear_to_srgb_fast(x) - linear_to_srgb(x)).abs() < 1e-6,
                "{x}"
            );
        }
        for i in 0..=255 {
            let c = i as f32 / 255.0;
            assert!((linear_to_srgb(srgb_to_linear(c)) - c).abs() < 1e-5);
        }
    }
}
