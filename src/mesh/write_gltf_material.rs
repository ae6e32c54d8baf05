//! glTF export of materials, whole: every metallic–roughness factor and texture slot, samplers,
//! texture coordinate sets, `KHR_texture_transform`, `KHR_materials_emissive_strength`, alpha
//! mode and cutoff, double-sidedness, material extensions lodeval kept verbatim, and `extras`;
//! each image written once, as the bytes it was read from where they were kept.
//!
//! Based on: the glTF 2.0 specification (Khronos, 2021), §3.8 and §3.9; the extensions
//! `KHR_texture_transform` and `KHR_materials_emissive_strength`.
//!
//! Decisions:
//! - Materials are written once per distinct material (textures compared by identity, so the
//!   levels of one chain share them); images once per distinct source (the kept file bytes, or the
//!   decoded texture), so an image the input used in an sRGB and a linear slot is one image.
//! - An image whose file bytes were kept (PNG, JPEG) is written byte for byte; one made by lodeval
//!   (an MTL's combined `map_Pr` + `map_Pm`) is encoded as PNG.
//! - A material extension kept verbatim that names a texture (`"index"` inside it) cannot be
//!   carried — its texture indices would point at the wrong images — and is a warning instead.
//! - A Blinn–Phong material (an OBJ without PBR keys) is written as the metallic–roughness
//!   material lodeval derives from its `Kd`, `Ks`, `Ns`, with a warning that says so.

use std::collections::BTreeSet;
use std::sync::Arc;

use serde_json::{Value, json};

use super::{AlphaMode, Material, Model, Sampler, Texture, TextureSlot};
use crate::error::{Error, Result};

/// One image to write: its bytes, MIME type and a name for a file beside a `.gltf`.
pub(super) struct ImageOut {
    pub bytes: Arc<[u8]>,
    pub mime: &'static str,
    pub name: String,
}

impl ImageOut {
    /// The file extension for its MIME type.
    pub fn extension(&self) -> &'static str {
        if self.mime == "image/jpeg" {
            "jpg"
        } else {
            "png"
        }
    }
}

/// Materials, textures, samplers and images, each written once.
#[derive(Default)]
pub(super) struct Materials {
    written: Vec<Material>,
    pub json: Vec<Value>,
    /// (texture identity, sampler index) → glTF texture index.
    textures: Vec<(usize, Option<usize>, Option<String>)>,
    pub texture_json: Vec<Value>,
    samplers: Vec<Sampler>,
    pub sampler_json: Vec<Value>,
    /// The source identity of each image (kept bytes or texture address).
    image_keys: Vec<usize>,
    pub images: Vec<ImageOut>,
    /// Extensions the written materials use.
    pub extensions_used: BTreeSet<String>,
    pub warnings: Vec<String>,
}

/// Whether two slots name the same texture the same way (textures by identity).
fn same_slot(a: Option<&TextureSlot>, b: Option<&TextureSlot>) -> bool {
    match (a, b) {
        (Some(a), Some(b)) => {
            Arc::ptr_eq(&a.texture, &b.texture)
                && a.tex_coord == b.tex_coord
                && a.sampler == b.sampler
                && a.transform == b.transform
                && a.name == b.name
        }
        (None, None) => true,
        _ => false,
    }
}

/// Whether two materials would be written alike.
fn same_material(a: &Material, b: &Material) -> bool {
    a.slots()
        .iter()
        .zip(b.slots())
        .all(|((_, x), (_, y))| same_slot(*x, y))
        && a.name == b.name
        && a.model == b.model
        && a.base_color == b.base_color
        && a.base_alpha == b.base_alpha
        && a.metallic == b.metallic
        && a.roughness == b.roughness
        && a.normal_scale == b.normal_scale
        && a.occlusion_strength == b.occlusion_strength
        && a.emissive == b.emissive
        && a.emissive_strength == b.emissive_strength
        && a.alpha_mode == b.alpha_mode
        && a.alpha_cutoff == b.alpha_cutoff
        && a.double_sided == b.double_sided
        && a.specular == b.specular
        && a.shininess == b.shininess
        && a.other_extensions == b.other_extensions
        && a.extras == b.extras
}

/// Whether a JSON value names a texture (an object with an `"index"` key, at any depth).
fn names_texture(v: &Value) -> bool {
    match v {
        Value::Object(map) => map.contains_key("index") || map.values().any(names_texture),
        Value::Array(items) => items.iter().any(names_texture),
        _ => false,
    }
}

impl Materials {
    /// The glTF material index of `m`, written the first time it is met.
    pub fn material(&mut self, m: &Material) -> Result<usize> {
        if let Some(i) = self.written.iter().position(|w| same_material(w, m)) {
            return Ok(i);
        }
        let c = m.base_color;
        let mut pbr = json!({
            "baseColorFactor": [c.x, c.y, c.z, m.base_alpha],
            "metallicFactor": m.metallic,
            "roughnessFactor": m.roughness,
        });
        if let Some(s) = &m.base_color_texture {
            pbr["baseColorTexture"] = self.slot(s)?;
        }
        if let Some(s) = &m.metallic_roughness_texture {
            pbr["metallicRoughnessTexture"] = self.slot(s)?;
        }
        let mut mat = json!({ "name": m.name, "pbrMetallicRoughness": pbr });
        if let Some(s) = &m.normal_texture {
            mat["normalTexture"] = self.slot(s)?;
            if m.normal_scale != 1.0 {
                mat["normalTexture"]["scale"] = json!(m.normal_scale);
            }
        }
        if let Some(s) = &m.occlusion_texture {
            mat["occlusionTexture"] = self.slot(s)?;
            if m.occlusion_strength != 1.0 {
                mat["occlusionTexture"]["strength"] = json!(m.occlusion_strength);
            }
        }
        if let Some(s) = &m.emissive_texture {
            mat["emissiveTexture"] = self.slot(s)?;
        }
        if m.emissive != glam::Vec3::ZERO {
            mat["emissiveFactor"] = json!(m.emissive.to_array());
        }
        match m.alpha_mode {
            AlphaMode::Opaque => {}
            AlphaMode::Mask => {
                mat["alphaMode"] = json!("MASK");
                mat["alphaCutoff"] = json!(m.alpha_cutoff);
            }
            AlphaMode::Blend => mat["alphaMode"] = json!("BLEND"),
        }
        if m.double_sided {
            mat["doubleSided"] = json!(true);
        }
        let mut extensions = serde_json::Map::new();
        if m.emissive_strength != 1.0 {
            extensions.insert(
                "KHR_materials_emissive_strength".into(),
                json!({ "emissiveStrength": m.emissive_strength }),
            );
            self.extensions_used
                .insert("KHR_materials_emissive_strength".into());
        }
        for (name, value) in &m.other_extensions {
            if names_texture(value) {
                self.warnings.push(format!(
                    "material '{}': {name} is not written (it names textures, which this export \
                     renumbers)",
                    m.name
                ));
                continue;
            }
            extensions.insert(name.clone(), value.clone());
            self.extensions_used.insert(name.clone());
        }
        if !extensions.is_empty() {
            mat["extensions"] = Value::Object(extensions);
        }
        if let Some(extras) = &m.extras {
            mat["extras"] = extras.clone();
        }
        if m.model == Model::BlinnPhong {
            self.warnings.push(format!(
                "material '{}' is Blinn–Phong (Kd, Ks, Ns) in the input; it is written as the \
                 metallic–roughness material lodeval derives from it (metallic {:.3}, roughness \
                 {:.3})",
                m.name, m.metallic, m.roughness
            ));
        }
        self.json.push(mat);
        self.written.push(m.clone());
        Ok(self.written.len() - 1)
    }

    /// A textureInfo for `slot`: index, texCoord, and `KHR_texture_transform`.
    fn slot(&mut self, slot: &TextureSlot) -> Result<Value> {
        let mut info = json!({ "index": self.texture(slot)? });
        if slot.tex_coord != 0 {
            info["texCoord"] = json!(slot.tex_coord);
        }
        if let Some(t) = &slot.transform {
            let mut tr = json!({
                "offset": t.offset.to_array(),
                "rotation": t.rotation,
                "scale": t.scale.to_array(),
            });
            if let Some(set) = t.tex_coord {
                tr["texCoord"] = json!(set);
            }
            info["extensions"] = json!({ "KHR_texture_transform": tr });
            self.extensions_used.insert("KHR_texture_transform".into());
        }
        Ok(info)
    }

    /// The glTF texture index for `slot` (image, sampler and name), written the first time.
    fn texture(&mut self, slot: &TextureSlot) -> Result<usize> {
        let image = self.image(&slot.texture)?;
        let sampler = self.sampler(&slot.sampler);
        let key = (image, sampler, slot.name.clone());
        if let Some(i) = self.textures.iter().position(|k| *k == key) {
            return Ok(i);
        }
        let mut t = json!({ "source": image });
        if let Some(s) = sampler {
            t["sampler"] = json!(s);
        }
        if let Some(name) = &slot.name {
            t["name"] = json!(name);
        }
        self.textures.push(key);
        self.texture_json.push(t);
        Ok(self.textures.len() - 1)
    }

    /// The glTF sampler index, or `None` for the default sampler (repeat, filters unset).
    fn sampler(&mut self, s: &Sampler) -> Option<usize> {
        if *s == Sampler::default() {
            return None;
        }
        if let Some(i) = self.samplers.iter().position(|x| x == s) {
            return Some(i);
        }
        let mut j = json!({ "wrapS": s.wrap_s.gl(), "wrapT": s.wrap_t.gl() });
        if let Some(f) = s.mag {
            j["magFilter"] = json!(f.gl());
        }
        if let Some(f) = s.min {
            j["minFilter"] = json!(f.gl());
        }
        if let Some(name) = &s.name {
            j["name"] = json!(name);
        }
        self.samplers.push(s.clone());
        self.sampler_json.push(j);
        Some(self.samplers.len() - 1)
    }

    /// The image index of `t`'s source, added the first time.
    fn image(&mut self, t: &Arc<Texture>) -> Result<usize> {
        let key = t
            .encoded()
            .map_or(Arc::as_ptr(t) as *const u8 as usize, |e| {
                e.bytes.as_ptr() as usize
            });
        if let Some(i) = self.image_keys.iter().position(|&k| k == key) {
            return Ok(i);
        }
        let image = match t.encoded() {
            Some(e) => ImageOut {
                bytes: e.bytes.clone(),
                mime: e.mime,
                name: e
                    .name
                    .clone()
                    .unwrap_or_else(|| format!("image{}", self.images.len())),
            },
            None => ImageOut {
                bytes: png(t)?.into(),
                mime: "image/png",
                name: format!("image{}", self.images.len()),
            },
        };
        self.image_keys.push(key);
        self.images.push(image);
        Ok(self.images.len() - 1)
    }
}

/// A decoded texture as PNG (RGB where every alpha is 255).
fn png(t: &Texture) -> Result<Vec<u8>> {
    let rgba = image::RgbaImage::from_raw(t.width(), t.height(), t.rgba().to_vec())
        .ok_or_else(|| Error::Internal("glTF export: texture size".into()))?;
    let img = if t.has_alpha() {
        image::DynamicImage::ImageRgba8(rgba)
    } else {
        image::DynamicImage::ImageRgb8(image::DynamicImage::ImageRgba8(rgba).into_rgb8())
    };
    let mut out = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png)
        .map_err(|e| Error::Internal(format!("glTF export: PNG: {e}")))?;
    Ok(out)
}
