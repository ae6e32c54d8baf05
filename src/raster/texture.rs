//! Mip-mapped textures in linear light and trilinear sampling.
//!
//! Based on: Lance Williams. Pyramidal Parametrics. SIGGRAPH 1983 (mip-maps, trilinear filtering);
//! the OpenGL 4.6 specification §8.14 for the level-of-detail formula
//! λ = log2(max(|∂(u,v)/∂x|, |∂(u,v)/∂y|) in texels).
//!
//! The pyramid is built once per texture from the 8-bit texels, decoded to linear light first
//! (sRGB textures through a 256-entry table; normal maps as stored), then averaged 2×2 per level —
//! averaging sRGB-encoded values would darken every minified edge. Texture coordinates follow the
//! OpenGL convention: v = 0 is the bottom row of the image. Wrapping is `repeat`.

use glam::{Vec2, Vec3};

use crate::color::srgb8_to_linear_table;
use crate::mesh::{ColorSpace, Texture};

/// One level of the pyramid.
#[derive(Debug, Clone)]
struct Level {
    width: usize,
    height: usize,
    texels: Vec<Vec3>,
}

/// A mip pyramid in linear RGB.
#[derive(Debug, Clone)]
pub struct MipTexture {
    levels: Vec<Level>,
}

impl MipTexture {
    /// Build the pyramid for a decoded texture.
    pub fn build(texture: &Texture) -> MipTexture {
        let table: [f32; 256] = match texture.color_space() {
            ColorSpace::Srgb => srgb8_to_linear_table(),
            ColorSpace::Linear => std::array::from_fn(|i| i as f32 / 255.0),
        };
        let texels = texture
            .rgba()
            .chunks_exact(4)
            .map(|c| {
                Vec3::new(
                    table[c[0] as usize],
                    table[c[1] as usize],
                    table[c[2] as usize],
                )
            })
            .collect();
        let mut levels = vec![Level {
            width: texture.width() as usize,
            height: texture.height() as usize,
            texels,
        }];
        while let Some(prev) = levels.last().filter(|l| l.width > 1 || l.height > 1) {
            let (w, h) = ((prev.width / 2).max(1), (prev.height / 2).max(1));
            let mut texels = Vec::with_capacity(w * h);
            for y in 0..h {
                for x in 0..w {
                    let (x0, y0) = ((2 * x).min(prev.width - 1), (2 * y).min(prev.height - 1));
                    let (x1, y1) = (
                        (2 * x + 1).min(prev.width - 1),
                        (2 * y + 1).min(prev.height - 1),
                    );
                    let t = |xx: usize, yy: usize| prev.texels[yy * prev.width + xx];
                    texels.push((t(x0, y0) + t(x1, y0) + t(x0, y1) + t(x1, y1)) * 0.25);
                }
            }
            levels.push(Level {
                width: w,
                height: h,
                texels,
            });
        }
        MipTexture { levels }
    }

    /// The levels, finest first: (width, height, texels row-major, top row first).
    #[cfg(feature = "gpu")]
    pub(crate) fn levels(&self) -> impl Iterator<Item = (usize, usize, &[Vec3])> {
        self.levels
            .iter()
            .map(|l| (l.width, l.height, l.texels.as_slice()))
    }

    /// Number of levels (1 for a 1×1 texture).
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// Trilinear sample at `uv` with screen-space derivatives `duv_dx`, `duv_dy` (per pixel).
    pub fn sample(&self, uv: Vec2, duv_dx: Vec2, duv_dy: Vec2) -> Vec3 {
        let base = &self.levels[0];
        let size = Vec2::new(base.width as f32, base.height as f32);
        let rho = (duv_dx * size).length().max((duv_dy * size).length());
        let lod = if rho > 1.0 { rho.log2() } else { 0.0 };
        let max = (self.levels.len() - 1) as f32;
        let lod = lod.clamp(0.0, max);
        let l0 = lod.floor() as usize;
        let frac = lod - l0 as f32;
        let a = bilinear(&self.levels[l0], uv);
        if frac == 0.0 || l0 + 1 >= self.levels.len() {
            return a;
        }
        a.lerp(bilinear(&self.levels[l0 + 1], uv), frac)
    }
}

/// Bilinear sample with repeat wrapping; texel centres at half-integers.
fn bilinear(level: &Level, uv: Vec2) -> Vec3 {
    let (w, h) = (level.width as f32, level.height as f32);
    // Row 0 is the top of the image and v = 0 the bottom.
    let x = uv.x * w - 0.5;
    let y = (1.0 - uv.y) * h - 0.5;
    let (fx, fy) = (x.floor(), y.floor());
    let (tx, ty) = (x - fx, y - fy);
    // Repeat wrapping; coordinates inside the texture (the usual case) need no division.
    let wrap = |i: f32, n: usize| {
        let (i, n) = (i as i64, n as i64);
        (if (0..n).contains(&i) {
            i
        } else {
            i.rem_euclid(n)
        }) as usize
    };
    let (x0, x1) = (wrap(fx, level.width), wrap(fx + 1.0, level.width));
    let (y0, y1) = (wrap(fy, level.height), wrap(fy + 1.0, level.height));
    let t = |xx: usize, yy: usize| level.texels[yy * level.width + xx];
    let top = t(x0, y0).lerp(t(x1, y0), tx);
    let bottom = t(x0, y1).lerp(t(x1, y1), tx);
    top.lerp(bottom, ty)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checker(n: u32) -> Texture {
        let mut px = Vec::new();
        for y in 0..n {
            for x in 0..n {
                let v = if (x + y) % 2 == 0 { 255 } else { 0 };
                px.extend_from_slice(&[v, v, v, 255]);
            }
        }
        Texture::new("checker".into(), n, n, px, ColorSpace::Srgb).unwrap()
    }

    #[test]
    fn pyramid_averages_in_linear_light() {
        // A black/white checker minifies to linear 0.5 (sRGB-space averaging would give 0.5
        // encoded, i.e. 0.214 linear).
        let m = MipTexture::build(&checker(8));
        assert_eq!(m.level_count(), 4);
        let far = m.sample(Vec2::splat(0.3), Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0));
        assert!((far - Vec3::splat(0.5)).length() < 1e-6, "{far}");
    }

    #[test]
    fn magnified_texel_centre_is_exact() {
        // At a texel centre, bilinear filtering returns that texel; v = 0 is the bottom row.
        let m = MipTexture::build(&checker(2));
        let bottom_left = m.sample(Vec2::new(0.25, 0.25), Vec2::ZERO, Vec2::ZERO);
        // Bottom-left texel is image row 1, column 0: (0 + 1) % 2 = 1 → black.
        assert_eq!(bottom_left, Vec3::ZERO);
        let top_left = m.sample(Vec2::new(0.25, 0.75), Vec2::ZERO, Vec2::ZERO);
        assert_eq!(top_left, Vec3::ONE);
    }
}
