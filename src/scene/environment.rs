//! The light that surrounds a scene: an equirectangular radiance map (loaded from a Radiance
//! `.hdr` or OpenEXR file, or the built-in neutral room lodeval generates), which the `pbr`
//! shading model lights with (image-based lighting; the prefiltered forms are the renderer's,
//! `raster/ibl.rs`).
//!
//! Based on: Greg Ward. Real Pixels. Graphics Gems II, 1991 (the RGBE format, read by `image`);
//! the equirectangular (latitude–longitude) mapping as Blender's Cycles
//! (`direction_to_equirectangular`: u = ½ − atan2(y, x)/2π in its Z-up frame) and three.js use
//! it, so a file lights a glTF scene the same way in all three (Blender turns glTF's Y-up into its
//! Z-up: x → x, y → z, z → −y). Checked against Blender with an axis-coloured map
//! (`examples/export_environment.rs axes`).
//!
//! Conventions: directions are in glTF's world space (+Y up). Texel (x, y) of a W × H map covers
//! u = (x + ½)/W, v = (y + ½)/H with row 0 at the top; direction d has
//! u = ½ + atan2(d.z, d.x) / 2π (the map's centre looks along +X) and v = acos(d.y) / π.
//!
//! Decisions:
//! - A loaded map must be 2:1 (equirectangular), at least 16 × 8 and at most
//!   [`crate::limits::ENVIRONMENT_SIDE`] wide, with every radiance finite and non-negative: a NaN
//!   or negative texel would light every surface with it. Each is an input error naming the file
//!   (and the texel).
//! - The built-in neutral environment is a grey room lit by five rectangular soft boxes, computed
//!   from the geometry below at 512 × 256 with 4 × 4 samples per texel in a fixed order, so it is
//!   the same on every run and machine; its mean radiance over the sphere is scaled to 1 (a white
//!   Lambertian surface averages 1 over all orientations, as under a uniform white sky). This is
//!   how three.js's `RoomEnvironment` and model-viewer's "neutral" lighting are made: a studio of
//!   area lights that gives glossy metal something to reflect from every side.
//! - Every map carries a content key (SHA-256 of its size and texels) under which the renderer
//!   caches what it derives from it.

use std::path::Path;
use std::sync::{Arc, OnceLock};

use glam::{Vec2, Vec3};

use crate::error::{Error, Location, Result};

/// An equirectangular map of incoming radiance (linear RGB), +Y up.
///
/// # Guarantees
/// - `width == 2 * height`, `height >= 4`, `texels.len() == width * height`.
/// - Every texel is finite and non-negative.
#[derive(Debug, Clone, PartialEq)]
pub struct Environment {
    label: String,
    width: usize,
    height: usize,
    texels: Vec<Vec3>,
    key: u64,
}

/// The smallest map side a file may give (width; the height is half).
const MIN_WIDTH: usize = 16;

impl Environment {
    /// A map from texels, row-major with row 0 at the top; `None` unless it is 2:1, at least
    /// 8 × 4, and every texel is finite and non-negative.
    pub fn from_texels(label: &str, width: usize, texels: Vec<Vec3>) -> Option<Environment> {
        let height = width / 2;
        let valid = width >= 8
            && width == 2 * height
            && texels.len() == width * height
            && texels
                .iter()
                .all(|t| t.is_finite() && t.min_element() >= 0.0);
        valid.then(|| {
            let key = content_key(width, &texels);
            Environment {
                label: label.to_string(),
                width,
                height,
                texels,
                key,
            }
        })
    }

    /// A uniform environment of `radiance` (the white furnace's sky when 1).
    pub fn uniform(radiance: Vec3) -> Option<Environment> {
        Environment::from_texels("uniform", 8, vec![radiance; 32])
    }

    /// The built-in neutral room (module docs), generated once per process.
    pub fn neutral() -> Arc<Environment> {
        static NEUTRAL: OnceLock<Arc<Environment>> = OnceLock::new();
        NEUTRAL.get_or_init(|| Arc::new(neutral_room(512))).clone()
    }

    /// Load a Radiance `.hdr` or OpenEXR `.exr` equirectangular map.
    pub fn load(path: &Path) -> Result<Environment> {
        let fix = "give an equirectangular (2:1) Radiance .hdr or OpenEXR .exr file";
        let bytes = crate::io::read_input(path, "environment", crate::limits::IMAGE_BYTES, fix)?;
        let reader = image::ImageReader::new(std::io::Cursor::new(&bytes))
            .with_guessed_format()
            .map_err(|e| Error::input(path, format!("cannot read the environment: {e}"), fix))?;
        match reader.format() {
            Some(image::ImageFormat::Hdr | image::ImageFormat::OpenExr) => {}
            other => {
                let what = other.map_or("an unknown format".to_string(), |f| format!("{f:?}"));
                return Err(Error::input(
                    path,
                    format!("the file is {what}, not a high-dynamic-range image"),
                    fix,
                ));
            }
        }
        let (w, h) = reader
            .into_dimensions()
            .map_err(|e| Error::input(path, format!("cannot read the environment: {e}"), fix))?;
        let (w, h) = (w as usize, h as usize);
        if w != 2 * h || w < MIN_WIDTH {
            return Err(Error::input(
                path,
                format!("the map is {w} × {h}; an environment must be 2:1 and at least 16 × 8"),
                fix,
            ));
        }
        if let Some(e) = crate::limits::ENVIRONMENT_SIDE.refuse(w as u64) {
            return Err(Error::input(path, format!("the map's width {e}"), fix));
        }
        let img = image::ImageReader::new(std::io::Cursor::new(&bytes))
            .with_guessed_format()
            .and_then(|r| r.decode().map_err(std::io::Error::other))
            .map_err(|e| Error::input(path, format!("cannot decode the environment: {e}"), fix))?
            .into_rgb32f();
        let texels: Vec<Vec3> = img.pixels().map(|p| Vec3::from(p.0)).collect();
        if let Some(i) = texels
            .iter()
            .position(|t| !(t.is_finite() && t.min_element() >= 0.0))
        {
            return Err(Error::input_at(
                path,
                Location::Element(format!("texel ({}, {})", i % w, i / w)),
                format!(
                    "the radiance {:?} is not a finite non-negative number",
                    texels[i].to_array()
                ),
                "repair or re-export the map (clamp negative values, fill NaN and infinite ones)",
            ));
        }
        Environment::from_texels(&path.display().to_string(), w, texels)
            .ok_or_else(|| Error::Internal(format!("{}: checked environment", path.display())))
    }

    /// Where it came from: `neutral`, `uniform`, or the file.
    pub fn label(&self) -> &str {
        &self.label
    }
    /// Width in texels (twice the height).
    pub fn width(&self) -> usize {
        self.width
    }
    /// Height in texels.
    pub fn height(&self) -> usize {
        self.height
    }
    /// Radiance, row-major, row 0 at the top (+Y).
    pub fn texels(&self) -> &[Vec3] {
        &self.texels
    }
    /// A key that identifies the content (equal maps, equal keys).
    pub fn key(&self) -> u64 {
        self.key
    }

    /// The map coordinates (u, v ∈ [0, 1], v from the top) of world direction `d` (any length;
    /// zero looks up): u = ½ + atan2(z, x)/2π, v = acos(y/|d|)/π, with the polynomials of
    /// `atan2` and `acos` below (the shading hot path; the GPU mirror evaluates the same ones).
    #[inline]
    pub fn uv_of(d: Vec3) -> Vec2 {
        let len = d.length();
        if len.is_nan() || len <= 0.0 {
            return Vec2::new(0.5, 0.0);
        }
        let u = 0.5 + atan2(d.z, d.x) * (0.5 / std::f32::consts::PI);
        let v = acos(d.y / len) * std::f32::consts::FRAC_1_PI;
        Vec2::new(u, v)
    }

    /// The unit world direction at map coordinates (u, v).
    pub fn direction_of(uv: Vec2) -> Vec3 {
        let phi = (uv.x - 0.5) * 2.0 * std::f32::consts::PI;
        let theta = (0.5 - uv.y) * std::f32::consts::PI;
        let (sp, cp) = phi.sin_cos();
        let (st, ct) = theta.sin_cos();
        // atan2(z, x) = φ  ⇒  x = cos φ, z = sin φ (scaled by cos θ).
        Vec3::new(cp * ct, st, sp * ct)
    }
}

/// atan2(y, x) in (−π, π] by a degree-11 odd minimax polynomial for atan on [0, 1] (error below
/// 2·10⁻⁶ rad, far under a texel of the 512-wide map), with the octant reduced by |y| ≤ |x| swaps
/// and signs: several times faster than the C library's, and the same operations on every
/// platform and in the GPU mirror's shader.
#[inline]
pub fn atan2(y: f32, x: f32) -> f32 {
    use std::f32::consts::{FRAC_PI_2, PI};
    let (ax, ay) = (x.abs(), y.abs());
    let (num, den) = if ay > ax { (ax, ay) } else { (ay, ax) };
    if den == 0.0 {
        return 0.0;
    }
    let z = num / den;
    let z2 = z * z;
    let mut a = z
        * (0.999_977_3
            + z2 * (-0.332_623_5
                + z2 * (0.193_543_5
                    + z2 * (-0.116_432_9 + z2 * (0.052_653_3 - z2 * 0.011_721_2)))));
    if ay > ax {
        a = FRAC_PI_2 - a;
    }
    if x < 0.0 {
        a = PI - a;
    }
    if y < 0.0 { -a } else { a }
}

/// acos(y) for y in [−1, 1] (clamped) by Abramowitz & Stegun 4.4.46: √(1 − |y|) times a
/// degree-7 polynomial, error below 2·10⁻⁷ rad; π minus it for negative y.
#[inline]
pub fn acos(y: f32) -> f32 {
    let a = y.abs().min(1.0);
    let p = std::f32::consts::FRAC_PI_2
        + a * (-0.214_598_8
            + a * (0.088_978_99
                + a * (-0.050_174_3
                    + a * (0.030_891_88
                        + a * (-0.017_088_1 + a * (0.006_670_09 - a * 0.001_262_491))))));
    let r = (1.0 - a).sqrt() * p;
    if y < 0.0 { std::f32::consts::PI - r } else { r }
}

/// SHA-256 of the size and texel bits, folded to 64 bits.
fn content_key(width: usize, texels: &[Vec3]) -> u64 {
    use sha2::Digest;
    let mut h = sha2::Sha256::new();
    h.update((width as u64).to_le_bytes());
    for t in texels {
        for c in t.to_array() {
            h.update(c.to_bits().to_le_bytes());
        }
    }
    let d = h.finalize();
    u64::from_le_bytes(d[..8].try_into().expect("a SHA-256 has 32 bytes"))
}

/// The room: walls from −`HALF`.x to `HALF`.x (and z), floor at `FLOOR`, ceiling at `CEILING`,
/// seen from the origin.
const HALF: f32 = 5.0;
const FLOOR: f32 = -2.0;
const CEILING: f32 = 4.0;

/// A soft box: on the wall whose normal axis is `axis` (0 x, 1 y, 2 z) at `at`, covering
/// [`lo`, `hi`] in the other two axes (in increasing axis order), with radiance `radiance`.
struct SoftBox {
    axis: usize,
    at: f32,
    lo: Vec2,
    hi: Vec2,
    radiance: f32,
}

const BOXES: [SoftBox; 5] = [
    // Above: a large ceiling panel.
    SoftBox {
        axis: 1,
        at: CEILING,
        lo: Vec2::new(-1.5, -1.5),
        hi: Vec2::new(1.5, 1.5),
        radiance: 9.0,
    },
    // The key light, on the +X wall.
    SoftBox {
        axis: 0,
        at: HALF,
        lo: Vec2::new(-0.5, -2.0),
        hi: Vec2::new(2.5, 2.0),
        radiance: 6.0,
    },
    // A fill on the −X wall.
    SoftBox {
        axis: 0,
        at: -HALF,
        lo: Vec2::new(0.0, -1.0),
        hi: Vec2::new(2.0, 1.0),
        radiance: 3.0,
    },
    // Two strips on the −Z and +Z walls.
    SoftBox {
        axis: 2,
        at: -HALF,
        lo: Vec2::new(-3.0, 0.5),
        hi: Vec2::new(-1.0, 3.0),
        radiance: 4.0,
    },
    SoftBox {
        axis: 2,
        at: HALF,
        lo: Vec2::new(1.5, -0.5),
        hi: Vec2::new(3.5, 1.5),
        radiance: 2.5,
    },
];

/// Radiance seen from the room's origin along unit direction `d` (unnormalised).
fn room_radiance(d: Vec3) -> f32 {
    // The nearest wall the ray hits: for each axis, the plane it heads towards.
    let bounds = [(-HALF, HALF), (FLOOR, CEILING), (-HALF, HALF)];
    let mut best = (f32::INFINITY, 0usize, 0.0f32);
    for (axis, &(lo, hi)) in bounds.iter().enumerate() {
        let c = d[axis];
        if c.abs() < 1e-9 {
            continue;
        }
        let plane = if c > 0.0 { hi } else { lo };
        let t = plane / c;
        if t < best.0 {
            best = (t, axis, plane);
        }
    }
    let (t, axis, plane) = best;
    let p = d * t;
    for b in &BOXES {
        if b.axis == axis && b.at == plane {
            let (i, j) = match axis {
                0 => (1, 2),
                1 => (0, 2),
                _ => (0, 1),
            };
            let q = Vec2::new(p[i], p[j]);
            if q.cmpge(b.lo).all() && q.cmple(b.hi).all() {
                return b.radiance;
            }
        }
    }
    // Walls brighten towards the ceiling; the floor is darker, the ceiling lighter.
    match (axis, plane == CEILING) {
        (1, true) => 0.7,
        (1, false) => 0.25,
        _ => 0.35 + 0.25 * (p.y - FLOOR) / (CEILING - FLOOR),
    }
}

/// The neutral room at `width` × `width`/2, each texel the mean of 4 × 4 directions, scaled so
/// the mean radiance over the sphere (texels weighted by solid angle) is 1.
fn neutral_room(width: usize) -> Environment {
    let height = width / 2;
    const S: usize = 4;
    let mut texels = Vec::with_capacity(width * height);
    for y in 0..height {
        for x in 0..width {
            let mut sum = 0.0f32;
            for k in 0..S * S {
                let uv = Vec2::new(
                    (x as f32 + ((k % S) as f32 + 0.5) / S as f32) / width as f32,
                    (y as f32 + ((k / S) as f32 + 0.5) / S as f32) / height as f32,
                );
                sum += room_radiance(Environment::direction_of(uv));
            }
            texels.push(Vec3::splat(sum / (S * S) as f32));
        }
    }
    // Mean over the sphere: rows weighted by cos(latitude), summed in row order.
    let (mut total, mut weight) = (0.0f64, 0.0f64);
    for y in 0..height {
        let lat = (0.5 - (y as f64 + 0.5) / height as f64) * std::f64::consts::PI;
        let w = lat.cos();
        let row: f64 = texels[y * width..(y + 1) * width]
            .iter()
            .map(|t| t.x as f64)
            .sum();
        total += row * w;
        weight += width as f64 * w;
    }
    let scale = (weight / total) as f32;
    for t in &mut texels {
        *t *= scale;
    }
    Environment::from_texels("neutral", width, texels).expect("the room is 2:1 and positive")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fast_atan2_is_within_two_microradians_of_the_library() {
        let mut worst = 0.0f32;
        for i in 0..2000 {
            let a = (i as f32 / 1000.0 - 1.0) * std::f32::consts::PI;
            for r in [1e-3, 1.0, 1e3] {
                let (y, x) = (a.sin() * r, a.cos() * r);
                worst = worst.max((atan2(y, x) - y.atan2(x)).abs());
            }
        }
        assert!(worst < 2e-6, "{worst}");
        assert_eq!(atan2(0.0, 0.0), 0.0);
        let worst = (0..=2000)
            .map(|i| {
                let y = i as f32 / 1000.0 - 1.0;
                (acos(y) - y.acos()).abs()
            })
            .fold(0.0f32, f32::max);
        assert!(worst < 1e-6, "acos: {worst}");
    }

    #[test]
    fn directions_and_map_coordinates_invert_each_other() {
        for d in [
            Vec3::new(0.3, 0.5, -0.8),
            Vec3::new(-0.9, -0.1, 0.2),
            Vec3::new(0.0, 0.2, 1.0),
        ] {
            let d = d.normalize();
            let back = Environment::direction_of(Environment::uv_of(d));
            assert!(back.distance(d) < 1e-5, "{d} → {back}");
        }
        // The map's centre looks along +X (Blender's and three.js's convention), a quarter turn
        // left of it along −Z; the top row is up.
        let centre = Environment::direction_of(Vec2::new(0.5, 0.5));
        assert!(centre.distance(Vec3::X) < 1e-6, "{centre}");
        let quarter = Environment::direction_of(Vec2::new(0.25, 0.5));
        assert!(quarter.distance(-Vec3::Z) < 1e-6, "{quarter}");
        assert!(Environment::uv_of(Vec3::Y).y < 1e-6);
    }

    #[test]
    fn the_neutral_room_is_the_same_every_time_and_averages_one() {
        let a = neutral_room(64);
        let b = neutral_room(64);
        assert_eq!(a.texels(), b.texels());
        assert_eq!(a.key(), b.key());
        // The soft boxes are far brighter than the walls, and the mean is 1.
        let max = a.texels().iter().map(|t| t.x).fold(0.0, f32::max);
        let min = a.texels().iter().map(|t| t.x).fold(f32::MAX, f32::min);
        assert!(max > 5.0 && min > 0.1 && min < 0.6, "{min} {max}");
        assert_eq!(Environment::neutral().width(), 512);
    }

    #[test]
    fn maps_that_are_not_2_to_1_or_hold_bad_radiance_are_refused() {
        assert!(Environment::from_texels("x", 1, vec![Vec3::ONE]).is_none());
        assert!(Environment::from_texels("x", 8, vec![Vec3::ONE; 31]).is_none());
        let mut bad = vec![Vec3::ONE; 32];
        bad[5] = Vec3::new(f32::NAN, 0.0, 0.0);
        assert!(Environment::from_texels("x", 8, bad.clone()).is_none());
        bad[5] = Vec3::new(-1.0, 0.0, 0.0);
        assert!(Environment::from_texels("x", 8, bad).is_none());
        assert!(Environment::uniform(Vec3::ONE).is_some());
    }
}
