//! Surface materials: glTF 2.0's metallic–roughness model, whole, as the canonical material, with
//! the Blinn–Phong parameters of the papers' shading models beside it.
//!
//! Based on: the glTF 2.0 specification (Khronos, 2021), §3.9 (materials: base colour, metallic
//! and roughness factors and texture — B = metal, G = rough —, normal texture with `scale`,
//! occlusion with `strength`, emissive factor and texture, alpha mode and cutoff, double-sided),
//! §3.8 (samplers: wrap modes, filters; §3.8.4 texture coordinate sets); the Khronos extensions
//! `KHR_texture_transform` (offset, rotation, scale, texCoord override) and
//! `KHR_materials_emissive_strength`.
//!
//! Decisions:
//! - Every slot and factor a file gives is kept, whether or not the chosen shading model reads
//!   it, so that an exported asset carries what the input had ([`Material::unkept`] lists what
//!   lodeval could not carry, for the exporter's warnings). Material extensions lodeval does not
//!   model are kept verbatim as JSON ([`Material::other_extensions`]) and written back when they
//!   name no texture.
//! - [`Model`] records which model the file described: an OBJ material without PBR keys is
//!   `BlinnPhong` (its `Kd`, `Ks`, `Ns` are the truth and the metallic–roughness fields are
//!   derived from them); glTF materials and MTL materials with `Pr`/`Pm`/`map_Pr`/`map_Pm`/`Ke`
//!   keys are `MetallicRoughness` (and the Blinn–Phong fields are derived). The `auto` shading
//!   picks the PBR model for the latter.
//! - Unset sampler filters stay unset (`None`), so a round trip writes what the file said; the
//!   renderer reads unset as linear / trilinear, as the glTF sample viewer does.

use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::Texture;

/// Which reflectance model a file described for a material.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Model {
    /// glTF 2.0 metallic–roughness (glTF files; MTL files with PBR keys).
    MetallicRoughness,
    /// Blinn–Phong: diffuse `Kd`, specular `Ks`, exponent `Ns` (MTL files without PBR keys).
    BlinnPhong,
}

/// glTF alpha modes (§3.9.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "UPPERCASE")]
pub enum AlphaMode {
    /// Alpha is ignored.
    Opaque,
    /// Fully opaque where alpha ≥ the cutoff, fully transparent elsewhere.
    Mask,
    /// Alpha-blended over what is behind.
    Blend,
}

/// Texture coordinate wrapping (glTF sampler `wrapS`/`wrapT`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Wrap {
    /// 10497 `REPEAT` (the default).
    #[default]
    Repeat,
    /// 33071 `CLAMP_TO_EDGE`.
    ClampToEdge,
    /// 33648 `MIRRORED_REPEAT`.
    MirroredRepeat,
}

impl Wrap {
    /// The glTF enum value.
    pub fn gl(self) -> u32 {
        match self {
            Wrap::Repeat => 10497,
            Wrap::ClampToEdge => 33071,
            Wrap::MirroredRepeat => 33648,
        }
    }
}

/// Texture filters (glTF sampler `magFilter`/`minFilter`), by their GL names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Filter {
    /// 9728 `NEAREST`.
    Nearest,
    /// 9729 `LINEAR`.
    Linear,
    /// 9984 `NEAREST_MIPMAP_NEAREST`.
    NearestMipmapNearest,
    /// 9985 `LINEAR_MIPMAP_NEAREST`.
    LinearMipmapNearest,
    /// 9986 `NEAREST_MIPMAP_LINEAR`.
    NearestMipmapLinear,
    /// 9987 `LINEAR_MIPMAP_LINEAR`.
    LinearMipmapLinear,
}

impl Filter {
    /// The glTF enum value.
    pub fn gl(self) -> u32 {
        match self {
            Filter::Nearest => 9728,
            Filter::Linear => 9729,
            Filter::NearestMipmapNearest => 9984,
            Filter::LinearMipmapNearest => 9985,
            Filter::NearestMipmapLinear => 9986,
            Filter::LinearMipmapLinear => 9987,
        }
    }
    /// Whether texels are blended within a level (the first word of the GL name).
    pub fn linear_texels(self) -> bool {
        matches!(
            self,
            Filter::Linear | Filter::LinearMipmapNearest | Filter::LinearMipmapLinear
        )
    }
    /// How the mip level is chosen: `None` for no mip-mapping, `Some(false)` for the nearest
    /// level, `Some(true)` for a blend of the two nearest.
    pub fn mip_blend(self) -> Option<bool> {
        match self {
            Filter::Nearest | Filter::Linear => None,
            Filter::NearestMipmapNearest | Filter::LinearMipmapNearest => Some(false),
            Filter::NearestMipmapLinear | Filter::LinearMipmapLinear => Some(true),
        }
    }
}

/// How a texture is sampled (glTF §3.8.4). Default value: repeat both ways, filters unset.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize)]
pub struct Sampler {
    /// Magnification filter; `None` = unset (rendered as linear).
    pub mag: Option<Filter>,
    /// Minification filter; `None` = unset (rendered as trilinear).
    pub min: Option<Filter>,
    /// Wrapping of u.
    pub wrap_s: Wrap,
    /// Wrapping of v.
    pub wrap_t: Wrap,
    /// The sampler's name in the file, if any.
    pub name: Option<String>,
}

/// `KHR_texture_transform`: uv' = offset + R(rotation)·(scale ∘ uv) in glTF's texture space
/// (origin top left, v down), with R rotating counter-clockwise in that space as the extension
/// defines: [cos r, sin r; −sin r, cos r].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct TextureTransform {
    /// Offset. Default value: (0, 0).
    pub offset: Vec2,
    /// Rotation in radians. Default value: 0.
    pub rotation: f32,
    /// Scale. Default value: (1, 1).
    pub scale: Vec2,
    /// A texture coordinate set that overrides the slot's own. Default value: none.
    pub tex_coord: Option<u32>,
}

impl TextureTransform {
    /// Transform a point given in lodeval's UV convention (v = 0 at the bottom of the image):
    /// flipped to glTF's convention, transformed, flipped back.
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let g = self.apply_gltf(Vec2::new(uv.x, 1.0 - uv.y));
        Vec2::new(g.x, 1.0 - g.y)
    }

    /// Transform a difference of two UVs (lodeval's convention): the linear part only.
    pub fn apply_vector(&self, d: Vec2) -> Vec2 {
        let g = self.linear(Vec2::new(d.x, -d.y));
        Vec2::new(g.x, -g.y)
    }

    /// Transform a point in glTF's convention.
    pub fn apply_gltf(&self, uv: Vec2) -> Vec2 {
        self.offset + self.linear(uv)
    }

    fn linear(&self, v: Vec2) -> Vec2 {
        let s = v * self.scale;
        let (sin, cos) = self.rotation.sin_cos();
        Vec2::new(cos * s.x + sin * s.y, -sin * s.x + cos * s.y)
    }
}

/// A material's use of a texture: the image, which UV set, how it is sampled and transformed.
#[derive(Debug, Clone, PartialEq)]
pub struct TextureSlot {
    /// The decoded image (shared between slots and materials that name the same image).
    pub texture: Arc<Texture>,
    /// Texture coordinate set (`TEXCOORD_n`). lodeval meshes carry sets 0 and 1.
    pub tex_coord: u32,
    /// Sampler.
    pub sampler: Sampler,
    /// `KHR_texture_transform`, if the file gave one.
    pub transform: Option<TextureTransform>,
    /// The glTF texture's name, if any (written back on export).
    pub name: Option<String>,
}

impl TextureSlot {
    /// A slot sampling `texture` with set 0, the default sampler and no transform.
    pub fn plain(texture: Arc<Texture>) -> TextureSlot {
        TextureSlot {
            texture,
            tex_coord: 0,
            sampler: Sampler::default(),
            transform: None,
            name: None,
        }
    }

    /// The texture coordinate set this slot reads (the transform's override wins).
    pub fn set(&self) -> u32 {
        self.transform
            .and_then(|t| t.tex_coord)
            .unwrap_or(self.tex_coord)
    }
}

/// A surface material: glTF 2.0 metallic–roughness, with the Blinn–Phong parameters of the
/// papers' shading models beside it.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// Name from the file (MTL `newmtl`, glTF material name), or `"default"`.
    pub name: String,
    /// The model the file described.
    pub model: Model,
    /// Linear RGB base colour factor (MTL `Kd`), multiplied with the texture and vertex colour.
    pub base_color: Vec3,
    /// Base colour alpha factor (MTL `d`).
    pub base_alpha: f32,
    /// Base-colour texture (sRGB; alpha in its fourth channel).
    pub base_color_texture: Option<TextureSlot>,
    /// Metallic factor, 0..1.
    pub metallic: f32,
    /// Perceptual roughness factor, 0..1.
    pub roughness: f32,
    /// Metallic–roughness texture (linear; G = roughness, B = metallic).
    pub metallic_roughness_texture: Option<TextureSlot>,
    /// Tangent-space normal map (linear).
    pub normal_texture: Option<TextureSlot>,
    /// The normal map's `scale` (scales its x and y). Default value: 1.
    pub normal_scale: f32,
    /// Ambient occlusion texture (linear; R).
    pub occlusion_texture: Option<TextureSlot>,
    /// Occlusion `strength`, 0..1. Default value: 1.
    pub occlusion_strength: f32,
    /// Linear RGB emissive factor (MTL `Ke`).
    pub emissive: Vec3,
    /// `KHR_materials_emissive_strength` (≥ 0). Default value: 1.
    pub emissive_strength: f32,
    /// Emissive texture (sRGB).
    pub emissive_texture: Option<TextureSlot>,
    /// Alpha mode. Default value: `Opaque`.
    pub alpha_mode: AlphaMode,
    /// Cutoff for [`AlphaMode::Mask`]. Default value: 0.5.
    pub alpha_cutoff: f32,
    /// Whether back faces are lit as front faces (glTF `doubleSided`). Default value: false.
    pub double_sided: bool,
    /// Linear RGB specular colour (Blinn–Phong).
    pub specular: Vec3,
    /// Blinn–Phong exponent.
    pub shininess: f32,
    /// Material extensions lodeval does not model, verbatim (name, JSON), in file order.
    pub other_extensions: Vec<(String, serde_json::Value)>,
    /// The material's glTF `extras`, verbatim.
    pub extras: Option<serde_json::Value>,
}

impl Material {
    /// Blinn–Phong parameters for a metallic–roughness material (glTF, nvdiffrec MTL):
    /// specular colour = mix(0.04, base colour, metallic), exponent = 2/α² − 2 with α = roughness²
    /// (the Beckmann–Phong correspondence; Walter et al. 2007, eq. 30), clamped to 1..10 000.
    pub fn specular_from_metallic_roughness(
        base_color: Vec3,
        metallic: f32,
        roughness: f32,
    ) -> (Vec3, f32) {
        let alpha = roughness.clamp(0.03, 1.0).powi(2);
        let specular = Vec3::splat(0.04).lerp(base_color, metallic.clamp(0.0, 1.0));
        (specular, (2.0 / (alpha * alpha) - 2.0).clamp(1.0, 10_000.0))
    }

    /// Metallic and roughness for Blinn–Phong parameters (the inverse of
    /// [`Material::specular_from_metallic_roughness`]): roughness = (2 / (n + 2))^¼ for the
    /// exponent n, metallic from where the specular colour lies between 0.04 and the base colour
    /// (the mean over channels where the two differ).
    pub fn metallic_roughness_from_specular(
        base_color: Vec3,
        specular: Vec3,
        shininess: f32,
    ) -> (f32, f32) {
        let alpha = (2.0 / (shininess.max(1.0) + 2.0)).sqrt();
        let roughness = alpha.sqrt().clamp(0.0, 1.0);
        let (mut sum, mut n) = (0.0, 0);
        for k in 0..3 {
            let span = base_color[k] - 0.04;
            if span.abs() > 0.05 {
                sum += ((specular[k] - 0.04) / span).clamp(0.0, 1.0);
                n += 1;
            }
        }
        (if n > 0 { sum / n as f32 } else { 0.0 }, roughness)
    }

    /// The material given to triangles the file assigns none: light grey diffuse with a faint
    /// highlight, so shape reads clearly under the default headlight. It is a Blinn–Phong
    /// material (no file described it); its metallic–roughness fields are derived.
    pub fn default_material() -> Material {
        Material::blinn_phong("default", Vec3::splat(0.8), Vec3::splat(0.1), 32.0)
    }

    /// A Blinn–Phong material with the metallic–roughness fields derived from it.
    pub fn blinn_phong(name: &str, diffuse: Vec3, specular: Vec3, shininess: f32) -> Material {
        let (metallic, roughness) =
            Material::metallic_roughness_from_specular(diffuse, specular, shininess);
        Material {
            name: name.into(),
            model: Model::BlinnPhong,
            base_color: diffuse,
            base_alpha: 1.0,
            base_color_texture: None,
            metallic,
            roughness,
            metallic_roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            occlusion_texture: None,
            occlusion_strength: 1.0,
            emissive: Vec3::ZERO,
            emissive_strength: 1.0,
            emissive_texture: None,
            alpha_mode: AlphaMode::Opaque,
            alpha_cutoff: 0.5,
            double_sided: false,
            specular,
            shininess,
            other_extensions: Vec::new(),
            extras: None,
        }
    }

    /// A metallic–roughness material with factors only; the Blinn–Phong fields are derived.
    pub fn metallic_roughness(
        name: &str,
        base_color: Vec3,
        metallic: f32,
        roughness: f32,
    ) -> Material {
        let (specular, shininess) =
            Material::specular_from_metallic_roughness(base_color, metallic, roughness);
        Material {
            model: Model::MetallicRoughness,
            metallic,
            roughness,
            ..Material::blinn_phong(name, base_color, specular, shininess)
        }
    }

    /// Re-derive the Blinn–Phong fields from the metallic–roughness ones (after a loader set
    /// them), with `roughness_scale` and `metallic_scale` standing in for the
    /// metallic–roughness texture (its mean G and B; 1 without one).
    pub fn derive_blinn_phong(&mut self, roughness_scale: f32, metallic_scale: f32) {
        (self.specular, self.shininess) = Material::specular_from_metallic_roughness(
            self.base_color,
            self.metallic * metallic_scale,
            self.roughness * roughness_scale,
        );
    }

    /// Every texture slot with its glTF name, in the order the glTF specification lists them.
    pub fn slots(&self) -> [(&'static str, Option<&TextureSlot>); 5] {
        [
            ("baseColorTexture", self.base_color_texture.as_ref()),
            (
                "metallicRoughnessTexture",
                self.metallic_roughness_texture.as_ref(),
            ),
            ("normalTexture", self.normal_texture.as_ref()),
            ("occlusionTexture", self.occlusion_texture.as_ref()),
            ("emissiveTexture", self.emissive_texture.as_ref()),
        ]
    }

    /// The emitted radiance factor: emissive × strength.
    pub fn emission(&self) -> Vec3 {
        self.emissive * self.emissive_strength
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texture_transform_follows_the_extension_in_gltf_space() {
        // The extension's own example: rotate by 90° about the origin, then offset (0, 1), maps
        // glTF (1, 0) to (0, 1) + R·(1, 0) = (0, 1) + (0, −1) = (0, 0).
        let t = TextureTransform {
            offset: Vec2::new(0.0, 1.0),
            rotation: std::f32::consts::FRAC_PI_2,
            scale: Vec2::ONE,
            tex_coord: None,
        };
        assert!(t.apply_gltf(Vec2::new(1.0, 0.0)).length() < 1e-6);
        // In lodeval's convention (v up) the same point is (1, 1) → (0, 1).
        let p = t.apply(Vec2::new(1.0, 1.0));
        assert!((p - Vec2::new(0.0, 1.0)).length() < 1e-6, "{p}");
        // A vector is moved by the linear part only, with v flipped on both sides.
        let d = t.apply_vector(Vec2::new(1.0, 0.0));
        assert!((d - Vec2::new(0.0, 1.0)).length() < 1e-6, "{d}");
    }

    #[test]
    fn blinn_phong_and_metallic_roughness_invert_each_other() {
        let base = Vec3::new(0.8, 0.5, 0.2);
        for (m, r) in [(0.0, 0.5), (1.0, 0.3), (0.5, 0.8)] {
            let (s, n) = Material::specular_from_metallic_roughness(base, m, r);
            let (m2, r2) = Material::metallic_roughness_from_specular(base, s, n);
            assert!(
                (m - m2).abs() < 1e-4 && (r - r2).abs() < 1e-4,
                "{m} {r} → {m2} {r2}"
            );
        }
    }
}
