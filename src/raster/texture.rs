//! Mip-mapped textures in linear light and trilinear sampling.
//!
//! Based on: Lance Williams. Pyramidal Parametrics. SIGGRAPH 1983 (mip-maps, trilinear filtering);
//! the OpenGL 4.6 specification §8.14 for the level-of-detail formula
//! λ = log2(max(|∂(u,v)/∂x|, |∂(u,v)/∂y|) in texels).
//!
//! The pyramid is built once per texture from the 8-bit texels, decoded to linear light first
//! (sRGB textures through a 256-entry table; normal maps as stored), then averaged 2×2 per level —
//! averaging sRGB-encoded values would darken every minified edge. Texture coordinates follow the
//! OpenGL convention: v = 0 is the bottom row of the image.
//!
//! Sampling follows the glTF sampler (§3.8.4, with OpenGL's definitions): wrapping per axis
//! (repeat, clamp to edge, mirrored repeat), the magnification filter where the level of detail
//! is ≤ 0 and the minification filter above (nearest or linear texels; no mip-maps, the nearest
//! level, or a blend of the two nearest). Unset filters are linear and trilinear.

use glam::{Vec2, Vec3};

use crate::color::srgb8_to_linear_table;
use crate::mesh::{ColorSpace, Filter, Sampler, Texture, Wrap};

/// A glTF sampler resolved for sampling: wrap per axis, filters with unset ones filled in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct SamplerState {
    pub wrap: [Wrap; 2],
    /// Magnification: linear texels.
    pub mag_linear: bool,
    /// Minification: linear texels.
    pub min_linear: bool,
    /// Minification: `None` no mip-maps, `Some(false)` nearest level, `Some(true)` two levels.
    pub mip: Option<bool>,
}

impl SamplerState {
    /// Repeat, linear, trilinear: the default and what unset filters mean.
    pub const TRILINEAR: SamplerState = SamplerState {
        wrap: [Wrap::Repeat, Wrap::Repeat],
        mag_linear: true,
        min_linear: true,
        mip: Some(true),
    };

    /// The state for a glTF sampler.
    pub fn of(s: &Sampler) -> SamplerState {
        let min = s.min.unwrap_or(Filter::LinearMipmapLinear);
        SamplerState {
            wrap: [s.wrap_s, s.wrap_t],
            mag_linear: s.mag.unwrap_or(Filter::Linear).linear_texels(),
            min_linear: min.linear_texels(),
            mip: min.mip_blend(),
        }
    }
}

/// Texel index `i` (may be outside 0..n) wrapped onto 0..n.
fn wrap_index(i: i64, n: usize, wrap: Wrap) -> usize {
    let n = n as i64;
    if (0..n).contains(&i) {
        return i as usize;
    }
    (match wrap {
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::ClampToEdge => i.clamp(0, n - 1),
        Wrap::MirroredRepeat => {
            let k = i.rem_euclid(2 * n);
            if k < n { k } else { 2 * n - 1 - k }
        }
    }) as usize
}

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

    /// Trilinear sample at `uv` with screen-space derivatives `duv_dx`, `duv_dy` (per pixel),
    /// repeat wrapping.
    pub fn sample(&self, uv: Vec2, duv_dx: Vec2, duv_dy: Vec2) -> Vec3 {
        self.sample_with(&SamplerState::TRILINEAR, uv, duv_dx, duv_dy)
    }

    /// Sample at `uv` with derivatives `duv_dx`, `duv_dy` (per pixel) as `sampler` says.
    pub(crate) fn sample_with(
        &self,
        sampler: &SamplerState,
        uv: Vec2,
        duv_dx: Vec2,
        duv_dy: Vec2,
    ) -> Vec3 {
        let base = &self.levels[0];
        let size = Vec2::new(base.width as f32, base.height as f32);
        let rho = (duv_dx * size).length().max((duv_dy * size).length());
        let lod = if rho > 1.0 { rho.log2() } else { 0.0 };
        let at = |l: usize, linear: bool| {
            let level = &self.levels[l];
            if linear {
                bilinear(level, uv, sampler.wrap)
            } else {
                nearest(level, uv, sampler.wrap)
            }
        };
        if lod <= 0.0 {
            return at(0, sampler.mag_linear);
        }
        let max = (self.levels.len() - 1) as f32;
        let lod = lod.clamp(0.0, max);
        match sampler.mip {
            None => at(0, sampler.min_linear),
            Some(false) => at((lod + 0.5).floor() as usize, sampler.min_linear),
            Some(true) => {
                let l0 = lod.floor() as usize;
                let frac = lod - l0 as f32;
                let a = at(l0, sampler.min_linear);
                if frac == 0.0 || l0 + 1 >= self.levels.len() {
                    return a;
                }
                a.lerp(at(l0 + 1, sampler.min_linear), frac)
            }
        }
    }
}

/// The texel containing `uv`.
fn nearest(level: &Level, uv: Vec2, wrap: [Wrap; 2]) -> Vec3 {
    let x = (uv.x * level.width as f32).floor() as i64;
    let y = ((1.0 - uv.y) * level.height as f32).floor() as i64;
    let (x, y) = (
        wrap_index(x, level.width, wrap[0]),
        wrap_index(y, level.height, wrap[1]),
    );
    level.texels[y * level.width + x]
}

/// Bilinear sample; texel centres at half-integers.
fn bilinear(level: &Level, uv: Vec2, wrap: [Wrap; 2]) -> Vec3 {
    let (w, h) = (level.width as f32, level.height as f32);
    // Row 0 is the top of the image and v = 0 the bottom.
    let x = uv.x * w - 0.5;
    let y = (1.0 - uv.y) * h - 0.5;
    let (fx, fy) = (x.floor(), y.floor());
    let (tx, ty) = (x - fx, y - fy);
    let (x0, x1) = (
        wrap_index(fx as i64, level.width, wrap[0]),
        wrap_index((fx as i64).saturating_add(1), level.width, wrap[0]),
    );
    let (y0, y1) = (
        wrap_index(fy as i64, level.height, wrap[1]),
        wrap_index((fy as i64).saturating_add(1), level.height, wrap[1]),
    );
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
