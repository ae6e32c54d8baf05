//! Image-based lighting, prepared once per environment: the split-sum approximation's
//! GGX-prefiltered radiance chain, the diffuse irradiance map, and the BRDF integration table.
//!
//! Based on: Brian Karis. Real Shading in Unreal Engine 4. SIGGRAPH 2013 course notes (the split
//! sum: prefiltered radiance with N = V = R, weighted by N·L, and a 2D table of the
//! environment-BRDF's scale and bias over (N·V, roughness); GGX importance sampling on the
//! Hammersley set); Mark Colbert and Jaroslav Křivánek. GPU-Based Importance Sampling. GPU Gems 3,
//! ch. 20, 2007 (filtered importance sampling: each sample reads the source mip level whose texel
//! covers the sample's solid angle, Ω_s = 1 / (N·pdf), level ½·log2(Ω_s/Ω_p) + 1); Eric Heitz.
//! Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs. JCGT 2014 (the
//! height-correlated Smith visibility the table integrates, as glTF's Appendix B uses it).
//!
//! Layout: every map is equirectangular in the environment's own frame (`scene::Environment`'s
//! convention; rotation and intensity are applied when shading). The specular chain has
//! [`LEVELS`] levels for perceptual roughness k/(LEVELS−1), k = 0 … 8: level 0 is the map itself
//! (its mip no wider than [`BASE_WIDTH`]), level k ≥ 1 is [`BASE_WIDTH`]/2^k wide (at least 32)
//! and prefiltered with [`SAMPLES`] GGX samples of α = roughness². A lookup blends the two levels
//! around roughness·(LEVELS−1), as the Khronos sample renderer blends its mips. The irradiance map
//! (64 × 32) is the cosine-weighted mean radiance about each normal, E/π, summed over the 128-wide
//! mip by solid angle and normalised by the summed weights, so a uniform map gives itself back
//! exactly (the white furnace holds by construction, not by tuning).
//!
//! Determinism: every texel is a pure function of the map (fixed sample sets, sums in sample
//! order, f32/f64 throughout), computed in parallel into its own slot; the table likewise. Equal
//! maps give bit-identical preparations on every run and for any thread count.
//!
//! Caching: [`prepared`] keeps one preparation per environment content key for the process. A
//! missing entry is computed without holding any lock (two threads that race both compute it and
//! the first stored wins: the results are identical), so a rayon worker never waits on another.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, OnceLock};

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use crate::scene::Environment;

/// Levels of the prefiltered chain (roughness 0, ⅛, …, 1).
pub const LEVELS: usize = 9;
/// Width of level 0.
pub const BASE_WIDTH: usize = 512;
/// GGX samples per prefiltered texel.
pub const SAMPLES: usize = 128;
/// Width of the irradiance map.
const IRRADIANCE_WIDTH: usize = 64;
/// Width of the source mip the irradiance is summed over.
const IRRADIANCE_SOURCE: usize = 128;
/// Entries per axis of the BRDF table.
pub const LUT_SIZE: usize = 32;
/// GGX samples per table entry.
const LUT_SAMPLES: usize = 1024;

/// An equirectangular map, row 0 at the top.
#[derive(Debug, Clone, PartialEq)]
pub struct EquirectMap {
    width: usize,
    height: usize,
    texels: Vec<Vec3>,
}

impl EquirectMap {
    fn new(width: usize, texels: Vec<Vec3>) -> EquirectMap {
        let height = width / 2;
        debug_assert_eq!(texels.len(), width * height);
        EquirectMap {
            width,
            height,
            texels,
        }
    }

    /// Width in texels.
    pub fn width(&self) -> usize {
        self.width
    }
    /// Height in texels.
    pub fn height(&self) -> usize {
        self.height
    }
    /// Texels, row-major, row 0 at the top.
    pub fn texels(&self) -> &[Vec3] {
        &self.texels
    }

    /// The map halved (2 × 2 means), or `None` at 8 wide.
    fn halved(&self) -> Option<EquirectMap> {
        (self.width > 8).then(|| {
            let w = self.width / 2;
            let h = w / 2;
            let t = |x: usize, y: usize| self.texels[y * self.width + x];
            let texels = (0..w * h)
                .map(|i| {
                    let (x, y) = (2 * (i % w), 2 * (i / w));
                    (t(x, y) + t(x + 1, y) + t(x, y + 1) + t(x + 1, y + 1)) * 0.25
                })
                .collect();
            EquirectMap::new(w, texels)
        })
    }

    /// Bilinear sample at map coordinates `uv` (u wraps, v clamps at the poles).
    #[inline]
    pub fn sample_uv(&self, uv: Vec2) -> Vec3 {
        let x = uv.x * self.width as f32 - 0.5;
        let y = (uv.y * self.height as f32 - 0.5).clamp(0.0, (self.height - 1) as f32);
        let (fx, fy) = (x.floor(), y.floor());
        let (tx, ty) = (x - fx, y - fy);
        // u ∈ [0, 1] puts fx in −1 … width − 1: one step wraps it (no division). A NaN
        // coordinate becomes texel 0.
        let w = self.width as i64;
        let mut x0 = fx as i64;
        if x0 < 0 {
            x0 += w;
        }
        if x0 >= w {
            x0 = x0.rem_euclid(w);
        }
        let x0 = x0 as usize;
        let x1 = if x0 + 1 == self.width { 0 } else { x0 + 1 };
        let y0 = fy as usize;
        let y1 = (y0 + 1).min(self.height - 1);
        let t = |xx: usize, yy: usize| self.texels[yy * self.width + xx];
        let top = t(x0, y0).lerp(t(x1, y0), tx);
        let bottom = t(x0, y1).lerp(t(x1, y1), tx);
        top.lerp(bottom, ty)
    }

    /// Bilinear sample in world direction `d` (the map's own frame).
    pub fn sample(&self, d: Vec3) -> Vec3 {
        self.sample_uv(Environment::uv_of(d))
    }

    /// Solid angle of a texel of row `y`, steradians.
    fn texel_solid_angle(&self, y: usize) -> f64 {
        let (h, w) = (self.height as f64, self.width as f64);
        let lat0 = std::f64::consts::FRAC_PI_2 - std::f64::consts::PI * y as f64 / h;
        let lat1 = std::f64::consts::FRAC_PI_2 - std::f64::consts::PI * (y + 1) as f64 / h;
        (lat0.sin() - lat1.sin()) * 2.0 * std::f64::consts::PI / w
    }
}

/// Everything the `pbr` model reads of an environment.
#[derive(Debug, Clone, PartialEq)]
pub struct PreparedEnvironment {
    /// The prefiltered chain, level k for roughness k/(LEVELS−1).
    pub levels: Vec<EquirectMap>,
    /// Cosine-weighted mean radiance about each normal (E/π).
    pub irradiance: EquirectMap,
}

impl PreparedEnvironment {
    /// Prefiltered radiance in direction `r` (the map's frame) for perceptual `roughness`.
    pub fn specular(&self, r: Vec3, roughness: f32) -> Vec3 {
        let lod = roughness.clamp(0.0, 1.0) * (LEVELS - 1) as f32;
        let l0 = lod.floor() as usize;
        let frac = lod - l0 as f32;
        let uv = Environment::uv_of(r);
        let a = self.levels[l0].sample_uv(uv);
        if frac == 0.0 || l0 + 1 >= LEVELS {
            return a;
        }
        a.lerp(self.levels[l0 + 1].sample_uv(uv), frac)
    }

    /// Mean cosine-weighted radiance about normal `n` (the map's frame).
    pub fn diffuse(&self, n: Vec3) -> Vec3 {
        self.irradiance.sample(n)
    }
}

/// The preparation of `env`, computed the first time this process asks for it.
pub fn prepared(env: &Environment) -> Arc<PreparedEnvironment> {
    static CACHE: OnceLock<Mutex<BTreeMap<u64, Arc<PreparedEnvironment>>>> = OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    let lookup = || {
        cache
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .get(&env.key())
            .cloned()
    };
    if let Some(p) = lookup() {
        return p;
    }
    let made = Arc::new(prepare(env));
    cache
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .entry(env.key())
        .or_insert(made)
        .clone()
}

/// Build the chain and the irradiance map of `env`.
fn prepare(env: &Environment) -> PreparedEnvironment {
    // The source pyramid, finest first.
    let mut pyramid = vec![EquirectMap::new(env.width(), env.texels().to_vec())];
    while let Some(next) = pyramid.last().and_then(EquirectMap::halved) {
        pyramid.push(next);
    }
    let base = pyramid
        .iter()
        .position(|m| m.width <= BASE_WIDTH)
        .unwrap_or(pyramid.len() - 1);
    let samples = hammersley(SAMPLES);
    let mut levels = vec![pyramid[base].clone()];
    for k in 1..LEVELS {
        let width = (BASE_WIDTH >> k).max(32);
        let roughness = k as f32 / (LEVELS - 1) as f32;
        levels.push(prefilter(&pyramid[base..], width, roughness, &samples));
    }
    let source = pyramid
        .iter()
        .find(|m| m.width <= IRRADIANCE_SOURCE)
        .unwrap_or(&pyramid[pyramid.len() - 1]);
    PreparedEnvironment {
        levels,
        irradiance: irradiance(source, IRRADIANCE_WIDTH),
    }
}

/// The first `n` points of the Hammersley set (i/n, radical inverse of i in base 2).
fn hammersley(n: usize) -> Vec<Vec2> {
    (0..n)
        .map(|i| {
            let r = (i as u32).reverse_bits() as f32 * (1.0 / 4_294_967_296.0);
            Vec2::new(i as f32 / n as f32, r)
        })
        .collect()
}

/// The GGX half vector for sample `xi` about +Z (Karis 2013, eq. in "Image-Based Lighting"):
/// φ = 2π ξ₁, cos θ = √((1 − ξ₂) / (1 + (α² − 1) ξ₂)).
fn ggx_half_vector(xi: Vec2, alpha: f32) -> Vec3 {
    let phi = 2.0 * std::f32::consts::PI * xi.x;
    let a2 = alpha * alpha;
    let cos_theta = ((1.0 - xi.y) / (1.0 + (a2 - 1.0) * xi.y)).sqrt();
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let (sp, cp) = phi.sin_cos();
    Vec3::new(sin_theta * cp, sin_theta * sp, cos_theta)
}

/// An orthonormal basis (t, b) with n (Frisvad-style, branch-free on the sign of z).
fn basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// Trowbridge–Reitz (GGX) normal distribution D(N·H) for α.
pub fn ggx_d(n_dot_h: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let f = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    a2 / (std::f32::consts::PI * f * f)
}

/// One level of the chain: `width` wide, radiance prefiltered by GGX of perceptual `roughness`,
/// reading the source mips `pyramid` (finest first) by filtered importance sampling.
fn prefilter(pyramid: &[EquirectMap], width: usize, roughness: f32, xi: &[Vec2]) -> EquirectMap {
    let alpha = roughness * roughness;
    let height = width / 2;
    let src = &pyramid[0];
    // Mean solid angle of a source texel at the finest level.
    let texel = 4.0 * std::f32::consts::PI / (src.width * src.height) as f32;
    let max_level = (pyramid.len() - 1) as f32;
    // The half vectors and their pdf-derived source levels are the same for every texel.
    let lobe: Vec<(Vec3, f32)> = xi
        .iter()
        .map(|&x| {
            let h = ggx_half_vector(x, alpha);
            // N = V: pdf(L) = D·(N·H)/(4 V·H) = D/4.
            let pdf = ggx_d(h.z, alpha) * 0.25;
            let omega_s = 1.0 / (xi.len() as f32 * pdf.max(1e-12));
            let level = (0.5 * (omega_s / texel).log2() + 1.0).clamp(0.0, max_level);
            (h, level)
        })
        .collect();
    let texels: Vec<Vec3> = (0..width * height)
        .into_par_iter()
        .with_min_len(64)
        .map(|i| {
            let uv = Vec2::new(
                ((i % width) as f32 + 0.5) / width as f32,
                ((i / width) as f32 + 0.5) / height as f32,
            );
            let n = Environment::direction_of(uv);
            let (t, b) = basis(n);
            let (mut sum, mut weight) = (Vec3::ZERO, 0.0f32);
            for &(h, level) in &lobe {
                let h = t * h.x + b * h.y + n * h.z;
                let l = 2.0 * n.dot(h) * h - n;
                let n_dot_l = n.dot(l);
                if n_dot_l > 0.0 {
                    sum += sample_pyramid(pyramid, l, level) * n_dot_l;
                    weight += n_dot_l;
                }
            }
            if weight > 0.0 {
                sum / weight
            } else {
                src.sample(n)
            }
        })
        .collect();
    EquirectMap::new(width, texels)
}

/// Trilinear sample of the source mips at fractional `level`.
fn sample_pyramid(pyramid: &[EquirectMap], d: Vec3, level: f32) -> Vec3 {
    let l0 = level.floor() as usize;
    let frac = level - l0 as f32;
    let uv = Environment::uv_of(d);
    let a = pyramid[l0].sample_uv(uv);
    if frac == 0.0 || l0 + 1 >= pyramid.len() {
        return a;
    }
    a.lerp(pyramid[l0 + 1].sample_uv(uv), frac)
}

/// The irradiance map: for each normal, Σ L·max(N·ω, 0)·dω / Σ max(N·ω, 0)·dω over `source`'s
/// texels (E/π; exact for a uniform map).
fn irradiance(source: &EquirectMap, width: usize) -> EquirectMap {
    let height = width / 2;
    let dirs: Vec<(Vec3, Vec3, f64)> = (0..source.width * source.height)
        .map(|i| {
            let (x, y) = (i % source.width, i / source.width);
            let uv = Vec2::new(
                (x as f32 + 0.5) / source.width as f32,
                (y as f32 + 0.5) / source.height as f32,
            );
            (
                Environment::direction_of(uv),
                source.texels[i],
                source.texel_solid_angle(y),
            )
        })
        .collect();
    let texels = (0..width * height)
        .into_par_iter()
        .map(|i| {
            let uv = Vec2::new(
                ((i % width) as f32 + 0.5) / width as f32,
                ((i / width) as f32 + 0.5) / height as f32,
            );
            let n = Environment::direction_of(uv);
            let (mut sum, mut weight) = ([0.0f64; 3], 0.0f64);
            for &(d, l, omega) in &dirs {
                let c = n.dot(d);
                if c > 0.0 {
                    let w = c as f64 * omega;
                    for k in 0..3 {
                        sum[k] += l[k] as f64 * w;
                    }
                    weight += w;
                }
            }
            Vec3::new(
                (sum[0] / weight) as f32,
                (sum[1] / weight) as f32,
                (sum[2] / weight) as f32,
            )
        })
        .collect();
    EquirectMap::new(width, texels)
}

/// Height-correlated Smith visibility V = G / (4 N·L N·V) for α (glTF 2.0 Appendix B).
pub fn smith_visibility(n_dot_l: f32, n_dot_v: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let ggxv = n_dot_l * (n_dot_v * n_dot_v * (1.0 - a2) + a2).sqrt();
    let ggxl = n_dot_v * (n_dot_l * n_dot_l * (1.0 - a2) + a2).sqrt();
    let s = ggxv + ggxl;
    if s > 0.0 { 0.5 / s } else { 0.0 }
}

/// The environment-BRDF's scale and bias (A, B) at (N·V, perceptual roughness), by GGX importance
/// sampling on the points `xi`: the mean of f·cos/pdf = V_vis·4·N·L·V·H/N·H, split by Schlick's
/// weight F_c = (1 − V·H)^5 into (1 − F_c) and F_c parts.
fn integrate(n_dot_v: f32, roughness: f32, xi: &[Vec2]) -> Vec2 {
    let alpha = roughness * roughness;
    let v = Vec3::new((1.0 - n_dot_v * n_dot_v).sqrt(), 0.0, n_dot_v);
    let (mut a, mut b) = (0.0f64, 0.0f64);
    for &x in xi {
        let h = ggx_half_vector(x, alpha);
        let l = 2.0 * v.dot(h) * h - v;
        let (n_dot_l, n_dot_h, v_dot_h) = (l.z, h.z, v.dot(h).max(0.0));
        if n_dot_l > 0.0 {
            let g = smith_visibility(n_dot_l, n_dot_v, alpha) * 4.0 * n_dot_l * v_dot_h / n_dot_h;
            let fc = (1.0 - v_dot_h).powi(5);
            a += ((1.0 - fc) * g) as f64;
            b += (fc * g) as f64;
        }
    }
    let n = xi.len() as f64;
    Vec2::new((a / n) as f32, (b / n) as f32)
}

/// The split sum's environment-BRDF table: for (N·V, perceptual roughness), the scale A and bias
/// B with ∫ f·cos = F0·A + B for Schlick's Fresnel (Karis 2013).
#[derive(Debug, Clone, PartialEq)]
pub struct BrdfLut {
    table: Vec<Vec2>,
}

impl BrdfLut {
    /// The table, computed once per process.
    pub fn get() -> &'static BrdfLut {
        static LUT: OnceLock<BrdfLut> = OnceLock::new();
        LUT.get_or_init(BrdfLut::compute)
    }

    fn compute() -> BrdfLut {
        let xi = hammersley(LUT_SAMPLES);
        let table = (0..LUT_SIZE * LUT_SIZE)
            .into_par_iter()
            .map(|i| {
                // Entry centres: N·V = (x + ½)/n, roughness = (y + ½)/n.
                let n_dot_v = ((i % LUT_SIZE) as f32 + 0.5) / LUT_SIZE as f32;
                let roughness = ((i / LUT_SIZE) as f32 + 0.5) / LUT_SIZE as f32;
                integrate(n_dot_v, roughness, &xi)
            })
            .collect();
        BrdfLut { table }
    }

    /// Bilinear lookup at (N·V, perceptual roughness), both clamped to [0, 1].
    pub fn sample(&self, n_dot_v: f32, roughness: f32) -> Vec2 {
        let n = LUT_SIZE as f32;
        let x = (n_dot_v.clamp(0.0, 1.0) * n - 0.5).clamp(0.0, n - 1.0);
        let y = (roughness.clamp(0.0, 1.0) * n - 0.5).clamp(0.0, n - 1.0);
        let (x0, y0) = (x.floor() as usize, y.floor() as usize);
        let (x1, y1) = ((x0 + 1).min(LUT_SIZE - 1), (y0 + 1).min(LUT_SIZE - 1));
        let (tx, ty) = (x - x0 as f32, y - y0 as f32);
        let t = |xx: usize, yy: usize| self.table[yy * LUT_SIZE + xx];
        t(x0, y0)
            .lerp(t(x1, y0), tx)
            .lerp(t(x0, y1).lerp(t(x1, y1), tx), ty)
    }

    /// The entries, row-major: N·V across, roughness down (for the GPU mirror).
    pub fn entries(&self) -> &[Vec2] {
        &self.table
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_uniform_environment_prefilters_to_itself() {
        let env = Environment::uniform(Vec3::splat(0.7)).unwrap();
        let p = prepare(&env);
        for d in [Vec3::X, Vec3::Y, Vec3::new(0.3, -0.8, 0.5).normalize()] {
            for r in [0.0, 0.3, 0.77, 1.0] {
                let s = p.specular(d, r);
                assert!(
                    (s - Vec3::splat(0.7)).abs().max_element() < 1e-5,
                    "{d} {r} {s}"
                );
            }
            let e = p.diffuse(d);
            assert!((e - Vec3::splat(0.7)).abs().max_element() < 1e-5, "{e}");
        }
    }

    #[test]
    fn the_brdf_table_matches_known_values() {
        let lut = BrdfLut::get();
        // At normal incidence on a smooth surface all the energy is reflected: A + B = 1.
        let s = lut.sample(1.0, 0.0);
        assert!((s.x + s.y - 1.0).abs() < 0.02, "{s}");
        // At α = 1 (D = 1/π, H cosine-distributed) and normal incidence, half the half vectors
        // reflect below the horizon and the rest give E = 2u/(1 + u) for u = N·L uniform in
        // [0, 1]: A + B = ½ · 2(1 − ln 2) = 1 − ln 2 ≈ 0.307, the single-scattering loss that
        // Fdez-Agüera's term makes up.
        let e = integrate(1.0, 1.0, &hammersley(1 << 14));
        assert!((e.x + e.y - (1.0 - 2f32.ln())).abs() < 0.005, "{e}");
        // Rough surfaces lose more: A + B falls with roughness.
        let (smooth, rough) = (lut.sample(1.0, 0.2), lut.sample(1.0, 0.8));
        assert!(
            smooth.x + smooth.y > rough.x + rough.y + 0.2,
            "{smooth} {rough}"
        );
        // Fresnel's share grows towards grazing angles.
        assert!(lut.sample(0.1, 0.3).y > lut.sample(0.9, 0.3).y);
    }

    #[test]
    fn preparation_is_identical_for_any_thread_count() {
        let env = Environment::neutral();
        let one = crate::raster::with_threads(1, || prepare(&env)).unwrap();
        let eight = crate::raster::with_threads(8, || prepare(&env)).unwrap();
        assert!(one == eight);
    }
}
