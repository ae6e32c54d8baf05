//! Texture content for the preprocessing of Williams et al. 2003 §4: a pyramid of per-texel
//! luminance ranges (min and max over each texel's footprint at every level), so the range of
//! luminance a triangle covers in a texture is found from a few texels at a coarse enough level
//! instead of every texel; and, for normal maps, how far the map tilts normals from the surface
//! normal (the widening of the shading normal cone, §5.4).
//!
//! Luminance is Rec. 709 of linear RGB (sRGB textures decoded, the display gamma of the paper's
//! "gamma corrected for our display hardware"), times the material's base colour, on a 0..1 scale.
//!
//! Decision (the paper rasterizes the triangle hierarchically into the pyramid): a triangle's
//! range is taken over its UV bounding box at the finest level where that box spans at most
//! [`MAX_SPAN`] texels a side. The box holds the triangle, so the range is conservative (a superset
//! of the texels the triangle covers), and it costs at most 25 look-ups per triangle.

use glam::{Vec2, Vec3};

use super::bounds::Range;
use crate::color::{luminance, srgb_to_linear};
use crate::mesh::{ColorSpace, Texture};

/// Largest box side, in texels, read at the chosen level.
pub const MAX_SPAN: i64 = 4;

/// Luminance min/max pyramid of one material's base-colour texture.
#[derive(Debug, Clone)]
pub struct LuminancePyramid {
    /// Levels, finest first: (width, height, ranges row-major, top row first).
    levels: Vec<(i64, i64, Vec<Range>)>,
}

impl LuminancePyramid {
    /// The pyramid of `texture` (sRGB-decoded unless it is tagged linear) times `base`.
    pub fn new(texture: &Texture, base: Vec3) -> LuminancePyramid {
        let (w, h) = (texture.width() as i64, texture.height() as i64);
        let decode = |c: u8| match texture.color_space() {
            ColorSpace::Srgb => srgb_to_linear(c as f32 / 255.0),
            ColorSpace::Linear => c as f32 / 255.0,
        };
        let finest: Vec<Range> = texture
            .rgba()
            .chunks_exact(4)
            .map(|p| {
                Range::of(luminance(
                    Vec3::new(decode(p[0]), decode(p[1]), decode(p[2])) * base,
                ))
            })
            .collect();
        let mut levels = vec![(w, h, finest)];
        while let Some((w, h, below)) = levels.last().filter(|l| l.0 > 1 || l.1 > 1) {
            let (nw, nh) = ((w + 1) / 2, (h + 1) / 2);
            let mut up = vec![Range::EMPTY; (nw * nh) as usize];
            for y in 0..*h {
                for x in 0..*w {
                    let i = ((y / 2) * nw + x / 2) as usize;
                    up[i] = up[i].merge(below[(y * w + x) as usize]);
                }
            }
            levels.push((nw, nh, up));
        }
        LuminancePyramid { levels }
    }

    /// The whole texture's range.
    pub fn total(&self) -> Range {
        self.levels.last().map_or(Range::EMPTY, |l| l.2[0])
    }

    /// A conservative luminance range of the texels under the UV triangle `uv` (repeat wrap; the
    /// texture's v axis points up, as OBJ and the renderer have it).
    pub fn triangle_range(&self, uv: [Vec2; 3]) -> Range {
        let (w0, h0) = (self.levels[0].0 as f32, self.levels[0].1 as f32);
        let lo = uv[0].min(uv[1]).min(uv[2]);
        let hi = uv[0].max(uv[1]).max(uv[2]);
        if !(lo.is_finite() && hi.is_finite()) || hi.x - lo.x >= 1.0 || hi.y - lo.y >= 1.0 {
            return self.total();
        }
        // Texel box at level 0 (x right, y down), inclusive.
        let x0 = (lo.x * w0).floor() as i64;
        let x1 = (hi.x * w0).floor() as i64;
        let y0 = ((1.0 - hi.y) * h0).floor() as i64;
        let y1 = ((1.0 - lo.y) * h0).floor() as i64;
        for (level, (w, h, ranges)) in self.levels.iter().enumerate() {
            let s = 1i64 << level;
            let (bx0, bx1, by0, by1) = (
                x0.div_euclid(s),
                x1.div_euclid(s),
                y0.div_euclid(s),
                y1.div_euclid(s),
            );
            if bx1 - bx0 < MAX_SPAN && by1 - by0 < MAX_SPAN || level + 1 == self.levels.len() {
                let mut r = Range::EMPTY;
                for y in by0..=by1 {
                    for x in bx0..=bx1 {
                        let i = (y.rem_euclid(*h) * w + x.rem_euclid(*w)) as usize;
                        r = r.merge(ranges[i]);
                    }
                }
                return r;
            }
        }
        self.total()
    }
}

/// The largest angle (radians) by which a tangent-space normal map tilts a normal away from the
/// surface normal: max over texels of acos(n_z), with n = 2·rgb − 1 normalised.
pub fn normal_map_tilt(texture: &Texture) -> f32 {
    texture
        .rgba()
        .chunks_exact(4)
        .map(|p| {
            let n = Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32) / 127.5 - Vec3::ONE;
            n.try_normalize()
                .map_or(std::f32::consts::PI, |n| n.z.clamp(-1.0, 1.0).acos())
        })
        .fold(0.0, f32::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checker(size: u32, cell: u32) -> Texture {
        let mut rgba = Vec::new();
        for y in 0..size {
            for x in 0..size {
                let v = if (x / cell + y / cell).is_multiple_of(2) {
                    255
                } else {
                    0
                };
                rgba.extend_from_slice(&[v, v, v, 255]);
            }
        }
        Texture::new("checker".into(), size, size, rgba, ColorSpace::Srgb).unwrap()
    }

    #[test]
    fn ranges_are_conservative_and_tight_on_uniform_patches() {
        let t = checker(64, 16);
        let p = LuminancePyramid::new(&t, Vec3::ONE);
        assert_eq!(p.total(), Range { lo: 0.0, hi: 1.0 });
        // Inside one white cell (texels 0..16, top-left): exactly white.
        let uv = |x: f32, y: f32| Vec2::new(x / 64.0, 1.0 - y / 64.0);
        let r = p.triangle_range([uv(2.0, 2.0), uv(12.0, 3.0), uv(4.0, 13.0)]);
        assert_eq!(r, Range::of(1.0));
        // Spanning a cell border: both colours.
        let r = p.triangle_range([uv(10.0, 2.0), uv(20.0, 3.0), uv(12.0, 10.0)]);
        assert_eq!(r, Range { lo: 0.0, hi: 1.0 });
        // A large triangle (read at a coarse level) still sees both.
        let r = p.triangle_range([uv(0.0, 0.0), uv(60.0, 0.0), uv(0.0, 60.0)]);
        assert_eq!(r, Range { lo: 0.0, hi: 1.0 });
        // Repeat wrap: u in 1..1.2 is the same as 0..0.2.
        let shifted = |x: f32, y: f32| Vec2::new(1.0 + x / 64.0, 1.0 - y / 64.0);
        let r = p.triangle_range([shifted(2.0, 2.0), shifted(12.0, 3.0), shifted(4.0, 13.0)]);
        assert_eq!(r, Range::of(1.0));
    }

    #[test]
    fn a_flat_normal_map_does_not_tilt() {
        let flat = Texture::new(
            "n".into(),
            2,
            2,
            [128, 128, 255, 255].repeat(4),
            ColorSpace::Linear,
        )
        .unwrap();
        assert!(normal_map_tilt(&flat) < 0.01);
        // One texel tilted 45° about y: (sin 45°, 0, cos 45°) → rgb ≈ (218, 128, 218).
        let mut rgba = [128, 128, 255, 255].repeat(4);
        rgba[0..3].copy_from_slice(&[218, 128, 218]);
        let t = Texture::new("n".into(), 2, 2, rgba, ColorSpace::Linear).unwrap();
        assert!((normal_map_tilt(&t) - std::f32::consts::FRAC_PI_4).abs() < 0.02);
    }
}
