//! One MTL material (as `tobj` parsed it) → a lodeval [`Material`]: the classic Blinn–Phong keys,
//! and the PBR extension keys where a file has them.
//!
//! Based on: the Wavefront MTL format (Alias|Wavefront, 1995: `Kd`, `Ks`, `Ns`, `d`, `map_Kd`,
//! `map_Bump`/`bump`); the PBR extension to MTL proposed by Exocortex (2012) and written by
//! Blender's exporter: `Pr` roughness, `Pm` metallic, `Ke` emission, `map_Pr`, `map_Pm`,
//! `map_Ke`, `norm` (a tangent-space normal map).
//!
//! Decisions:
//! - A material with any of `Pr`, `Pm`, `map_Pr`, `map_Pm` (or nvdiffrec's `bsdf pbr` line, which
//!   stores (occlusion, roughness, metallic) in `Ks`) is a metallic–roughness material; otherwise
//!   it is Blinn–Phong (`Kd`, `Ks`, `Ns`) and its metallic–roughness fields are derived.
//!   `Ke`/`map_Ke` set the emission of either model.
//! - `map_Pr` and `map_Pm` are single-channel images; glTF keeps roughness and metalness in the G
//!   and B channels of one image, so they are combined into one linear texture (the first channel
//!   of each; the other channel 255 where only one is given; a smaller image resampled to the
//!   larger's size with a warning). That texture has no file of its own: an export writes it as
//!   PNG.
//! - A missing `Kd` is 0.8 (lodeval's default diffuse), for either model. `d` < 1 makes the
//!   material alpha-blended with that alpha; `map_d` is not read (a warning says so).

use std::path::Path;
use std::sync::Arc;

use glam::Vec3;

use super::texture::{ColorSpace, Texture, TextureCache, resolve_asset_path};
use super::{AlphaMode, LoadOptions, Material, MissingAssets, Model, TextureSlot};
use crate::error::{Error, Location, Result};

/// Where a material's files are looked up and reported.
pub(super) struct MtlContext<'a> {
    /// The OBJ file (errors name it with the material).
    pub obj: &'a Path,
    /// The folder of the material library (texture names are relative to it).
    pub dir: &'a Path,
    pub options: &'a LoadOptions,
}

/// The keys that make a material metallic–roughness.
const PBR_KEYS: [&str; 4] = ["Pr", "Pm", "map_Pr", "map_Pm"];

/// Map `m` to a material, loading its textures through `cache`.
pub(super) fn material(
    m: &tobj::Material,
    ctx: &MtlContext,
    cache: &mut TextureCache,
    warnings: &mut Vec<String>,
) -> Result<Material> {
    let param = |key: &str| m.unknown_param.get(key).map(|v| v.trim().to_string());
    let mut mat = base_material(m, ctx)?;
    mat.name = m.name.clone();
    if let Some(ke) = m.emissive {
        mat.emissive = Vec3::from(ke);
    }
    if let Some(d) = m.dissolve.filter(|&d| d < 1.0) {
        mat.base_alpha = d;
        mat.alpha_mode = AlphaMode::Blend;
        warnings.push(format!(
            "material '{}': d = {d} (alpha blending) is kept for export, but lodeval draws the \
             material opaque",
            m.name
        ));
    }
    if m.dissolve_texture.is_some() {
        warnings.push(format!(
            "material '{}': map_d (an alpha map) is not read; the material uses d = {}",
            m.name, mat.base_alpha
        ));
    }
    let mut load = |name: Option<String>, space: ColorSpace| -> Result<Option<Arc<Texture>>> {
        let Some(name) = name.filter(|n| !n.trim().is_empty()) else {
            return Ok(None);
        };
        let tex_path = resolve_asset_path(ctx.dir, &name);
        let referrer = ctx.dir.join(format!("(material '{}')", m.name));
        match cache.load(&tex_path, space, &referrer) {
            Ok(t) => Ok(Some(t)),
            Err(e) => match ctx.options.missing_assets {
                MissingAssets::Error => Err(Error::input_at(
                    ctx.obj,
                    Location::Element(format!("material '{}'", m.name)),
                    format!("texture problem: {e}"),
                    "",
                )),
                MissingAssets::Warn => {
                    warnings.push(format!("material '{}': {e}", m.name));
                    Ok(None)
                }
            },
        }
    };
    let normal_name = m.normal_texture.clone().or_else(|| param("norm"));
    mat.base_color_texture =
        load(m.diffuse_texture.clone(), ColorSpace::Srgb)?.map(TextureSlot::plain);
    mat.normal_texture = load(normal_name, ColorSpace::Linear)?.map(TextureSlot::plain);
    mat.emissive_texture = load(param("map_Ke"), ColorSpace::Srgb)?.map(TextureSlot::plain);
    if mat.emissive_texture.is_some() && m.emissive.is_none() {
        // A map with no factor: the map is the emission (glTF's factor default of 0 would hide it).
        mat.emissive = Vec3::ONE;
    }
    let rough = load(param("map_Pr"), ColorSpace::Linear)?;
    let metal = load(param("map_Pm"), ColorSpace::Linear)?;
    if rough.is_some() || metal.is_some() {
        let (combined, resampled) = combine_roughness_metallic(&m.name, rough, metal);
        if resampled {
            warnings.push(format!(
                "material '{}': map_Pr and map_Pm differ in size; the smaller was resampled to \
                 combine them into one metallic–roughness texture",
                m.name
            ));
        }
        mat.metallic_roughness_texture = Some(TextureSlot::plain(Arc::new(combined)));
    }
    if m.unknown_param.contains_key("map_Ps") || m.unknown_param.contains_key("Ps") {
        warnings.push(format!(
            "material '{}': sheen (Ps, map_Ps) is not rendered or exported",
            m.name
        ));
    }
    Ok(mat)
}

/// The material's model and factors: metallic–roughness where the MTL has PBR keys (or is
/// nvdiffrec's `bsdf pbr`), else Blinn–Phong with a metallic–roughness equivalent.
fn base_material(m: &tobj::Material, ctx: &MtlContext) -> Result<Material> {
    let param = |key: &str| m.unknown_param.get(key).map(|v| v.trim().to_string());
    let scalar = |key: &str| -> Result<Option<f32>> {
        param(key)
            .map(|v| {
                v.split_whitespace()
                    .next()
                    .and_then(|t| t.parse::<f32>().ok())
                    .ok_or_else(|| {
                        Error::input_at(
                            ctx.obj,
                            Location::Element(format!("material '{}'", m.name)),
                            format!("{key} '{v}' is not a number"),
                            "fix the value in the .mtl file",
                        )
                    })
            })
            .transpose()
    };
    let nvdiffrec = param("bsdf").is_some_and(|b| b == "pbr");
    let is_pbr = nvdiffrec || PBR_KEYS.iter().any(|k| m.unknown_param.contains_key(*k));
    let diffuse = m.diffuse.map_or(Vec3::splat(0.8), Vec3::from);
    let mat = if is_pbr {
        let (mut metallic, mut roughness) = (0.0, 1.0);
        if let (true, Some([_, r, mm])) = (nvdiffrec, m.specular) {
            (metallic, roughness) = (mm, r);
        }
        roughness = scalar("Pr")?.unwrap_or(roughness);
        metallic = scalar("Pm")?.unwrap_or(metallic);
        Material::metallic_roughness(&m.name, diffuse, metallic, roughness)
    } else {
        let mut mat = Material::default_material();
        mat.base_color = diffuse;
        if let Some(ks) = m.specular {
            mat.specular = Vec3::from(ks);
        }
        if let Some(ns) = m.shininess {
            mat.shininess = ns.max(1.0);
        }
        let (metallic, roughness) =
            Material::metallic_roughness_from_specular(mat.base_color, mat.specular, mat.shininess);
        (mat.metallic, mat.roughness) = (metallic, roughness);
        mat
    };
    debug_assert_eq!(mat.model == Model::MetallicRoughness, is_pbr);
    Ok(mat)
}

/// One linear RGBA texture with roughness in G and metalness in B (glTF's layout), from the first
/// channel of each map; `true` when one had to be resampled to the other's size.
fn combine_roughness_metallic(
    material: &str,
    rough: Option<Arc<Texture>>,
    metal: Option<Arc<Texture>>,
) -> (Texture, bool) {
    let size = |t: &Option<Arc<Texture>>| t.as_ref().map_or((0, 0), |t| (t.width(), t.height()));
    let (w, h) = {
        let (a, b) = (size(&rough), size(&metal));
        (a.0.max(b.0), a.1.max(b.1))
    };
    let mut resampled = false;
    let mut channel = |t: &Option<Arc<Texture>>| -> Vec<u8> {
        let Some(t) = t else {
            return vec![255; (w * h) as usize];
        };
        let img = image::RgbaImage::from_raw(t.width(), t.height(), t.rgba().to_vec())
            .expect("a texture's sizes agree");
        let img = if (t.width(), t.height()) == (w, h) {
            img
        } else {
            resampled = true;
            image::imageops::resize(&img, w, h, image::imageops::FilterType::Triangle)
        };
        img.pixels().map(|p| p[0]).collect()
    };
    let (g, b) = (channel(&rough), channel(&metal));
    let rgba = g
        .iter()
        .zip(&b)
        .flat_map(|(&g, &b)| [0, g, b, 255])
        .collect();
    let label = format!("(material '{material}' map_Pr + map_Pm)");
    let texture =
        Texture::new(label, w, h, rgba, ColorSpace::Linear).expect("both maps are at least 1×1");
    (texture, resampled)
}
