//! glTF materials, loaded whole: every metallic–roughness factor and texture slot, samplers,
//! texture coordinate sets, `KHR_texture_transform`, `KHR_materials_emissive_strength`, alpha
//! mode and cutoff, double-sidedness, and the images behind the slots (each decoded once per
//! colour space, its file bytes kept for a lossless export).
//!
//! Based on: the glTF 2.0 specification (Khronos, 2021), §3.8 (textures, images, samplers) and
//! §3.9 (materials); the extensions `KHR_texture_transform` and `KHR_materials_emissive_strength`.
//!
//! Decisions:
//! - Colour spaces follow §3.9: base colour and emissive images are sRGB; metallic–roughness,
//!   normal and occlusion images are linear data.
//! - Material extensions lodeval does not model (clearcoat, sheen, transmission, unlit, …) are
//!   kept verbatim for the exporter and reported once as a warning: they change how engines draw
//!   the asset, and lodeval's images do not show them.
//! - The Blinn–Phong fields (for the `gouraud`/`phong` models) are derived from the factors, with
//!   the metallic–roughness texture's mean standing in for the texture.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::texture::{ColorSpace, EncodedImage, Texture};
use super::{
    AlphaMode, Filter, LoadOptions, Material, MissingAssets, Model, Sampler, TextureSlot,
    TextureTransform, Wrap,
};
use crate::error::{Error, Location, Result};

/// Extensions the loader models (not kept verbatim).
const MODELLED: &[&str] = &["KHR_materials_emissive_strength"];

/// Decodes each image a material uses once per colour space, and remembers failures by policy.
pub(super) struct Images<'a> {
    path: &'a Path,
    base: &'a Path,
    buffers: &'a [gltf::buffer::Data],
    options: &'a LoadOptions,
    decoded: BTreeMap<(usize, bool), Arc<Texture>>,
    pub warnings: Vec<String>,
}

impl<'a> Images<'a> {
    pub fn new(
        path: &'a Path,
        base: &'a Path,
        buffers: &'a [gltf::buffer::Data],
        options: &'a LoadOptions,
    ) -> Images<'a> {
        Images {
            path,
            base,
            buffers,
            options,
            decoded: BTreeMap::new(),
            warnings: Vec::new(),
        }
    }

    /// The texture for `image` in `space`, decoded the first time; `Ok(None)` where the image
    /// cannot be read and the policy is to warn.
    fn get(
        &mut self,
        material: &str,
        image: gltf::Image,
        space: ColorSpace,
    ) -> Result<Option<Arc<Texture>>> {
        let key = (image.index(), space == ColorSpace::Srgb);
        if let Some(t) = self.decoded.get(&key) {
            return Ok(Some(t.clone()));
        }
        let label = match image.source() {
            gltf::image::Source::Uri { uri, .. } if !uri.starts_with("data:") => {
                self.base.join(uri).display().to_string()
            }
            _ => format!("{} image {}", self.path.display(), image.index()),
        };
        let decoded = self
            .bytes(&image)
            .and_then(|bytes| {
                let name = image
                    .name()
                    .map(str::to_string)
                    .or_else(|| uri_stem(&image));
                let img = image::load_from_memory(&bytes).map_err(|e| e.to_string())?;
                Ok(Texture::from_image(&label, img, space)?
                    .with_encoded(EncodedImage::sniff(&bytes, name)))
            })
            .map_err(|e| format!("image {} ('{label}'): {e}", image.index()));
        match decoded {
            Ok(t) => {
                let t = Arc::new(t);
                self.decoded.insert(key, t.clone());
                Ok(Some(t))
            }
            Err(e) => match self.options.missing_assets {
                MissingAssets::Error => Err(Error::input_at(
                    self.path,
                    Location::Element(format!("material '{material}'")),
                    format!("texture cannot be loaded: {e}"),
                    "put the image next to the file, or pass --missing-assets warn to render \
                     without it",
                )),
                MissingAssets::Warn => {
                    self.warnings.push(format!("material '{material}': {e}"));
                    Ok(None)
                }
            },
        }
    }

    /// The encoded bytes of `image`: a buffer view, a data URI, or a file beside the glTF (a
    /// regular file within [`crate::limits::IMAGE_BYTES`], read once).
    fn bytes(&self, image: &gltf::Image) -> std::result::Result<Vec<u8>, String> {
        match image.source() {
            gltf::image::Source::View { view, .. } => {
                let buffer = self
                    .buffers
                    .get(view.buffer().index())
                    .ok_or("its buffer is missing")?;
                let (start, len) = (view.offset(), view.length());
                buffer
                    .0
                    .get(start..start.saturating_add(len))
                    .map(<[u8]>::to_vec)
                    .ok_or_else(|| "its buffer view lies outside its buffer".into())
            }
            gltf::image::Source::Uri { uri, .. } => {
                if let Some(data) = uri.strip_prefix("data:") {
                    let (_, payload) = data
                        .split_once(";base64,")
                        .ok_or("a data URI that is not base64")?;
                    use base64::Engine;
                    return base64::engine::general_purpose::STANDARD
                        .decode(payload)
                        .map_err(|e| format!("bad base64 data: {e}"));
                }
                let name = urlencoding::decode(uri).map_err(|e| e.to_string())?;
                crate::io::read_input(
                    &self.base.join(name.as_ref()),
                    "image",
                    crate::limits::IMAGE_BYTES,
                    "",
                )
                .map_err(|e| match e {
                    Error::Input { problem, .. } => problem,
                    other => other.to_string(),
                })
            }
        }
    }
}

/// The file stem of an image given by URI, as its name for export.
fn uri_stem(image: &gltf::Image) -> Option<String> {
    match image.source() {
        gltf::image::Source::Uri { uri, .. } if !uri.starts_with("data:") => Path::new(uri)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned()),
        _ => None,
    }
}

fn sampler(s: gltf::texture::Sampler) -> Sampler {
    use gltf::texture::{MagFilter as Mag, MinFilter as Min, WrappingMode as W};
    let wrap = |w: W| match w {
        W::Repeat => Wrap::Repeat,
        W::ClampToEdge => Wrap::ClampToEdge,
        W::MirroredRepeat => Wrap::MirroredRepeat,
    };
    Sampler {
        mag: s.mag_filter().map(|f| match f {
            Mag::Nearest => Filter::Nearest,
            Mag::Linear => Filter::Linear,
        }),
        min: s.min_filter().map(|f| match f {
            Min::Nearest => Filter::Nearest,
            Min::Linear => Filter::Linear,
            Min::NearestMipmapNearest => Filter::NearestMipmapNearest,
            Min::LinearMipmapNearest => Filter::LinearMipmapNearest,
            Min::NearestMipmapLinear => Filter::NearestMipmapLinear,
            Min::LinearMipmapLinear => Filter::LinearMipmapLinear,
        }),
        wrap_s: wrap(s.wrap_s()),
        wrap_t: wrap(s.wrap_t()),
        name: s.name().map(str::to_string),
    }
}

/// `KHR_texture_transform` from its JSON (the form normal and occlusion textures give it in).
fn transform_json(v: &serde_json::Value) -> TextureTransform {
    let pair = |key: &str, default: f32| {
        v.get(key)
            .and_then(|p| p.as_array())
            .filter(|a| a.len() == 2)
            .map_or(Vec2::splat(default), |a| {
                let f = |x: &serde_json::Value| x.as_f64().map_or(f32::NAN, |x| x as f32);
                Vec2::new(f(&a[0]), f(&a[1]))
            })
    };
    TextureTransform {
        offset: pair("offset", 0.0),
        rotation: v
            .get("rotation")
            .map_or(0.0, |r| r.as_f64().map_or(f32::NAN, |r| r as f32)),
        scale: pair("scale", 1.0),
        tex_coord: v.get("texCoord").and_then(|t| t.as_u64()).map(|t| t as u32),
    }
}

/// What a slot names in the file: its texture, set, and transform.
struct SlotRef<'a> {
    texture: gltf::Texture<'a>,
    tex_coord: u32,
    transform: Option<TextureTransform>,
}

impl<'a> SlotRef<'a> {
    fn info(info: gltf::texture::Info<'a>) -> SlotRef<'a> {
        SlotRef {
            transform: info.texture_transform().map(|t| TextureTransform {
                offset: Vec2::from(t.offset()),
                rotation: t.rotation(),
                scale: Vec2::from(t.scale()),
                tex_coord: t.tex_coord(),
            }),
            tex_coord: info.tex_coord(),
            texture: info.texture(),
        }
    }
}

/// Load material `m` with every slot.
pub(super) fn load(m: &gltf::Material, index: usize, images: &mut Images) -> Result<Material> {
    let name = m
        .name()
        .map(str::to_string)
        .unwrap_or_else(|| format!("material {index}"));
    let pbr = m.pbr_metallic_roughness();
    let [r, g, b, a] = pbr.base_color_factor();
    let mut mat = Material::metallic_roughness(
        &name,
        Vec3::new(r, g, b),
        pbr.metallic_factor(),
        pbr.roughness_factor(),
    );
    mat.base_alpha = a;
    mat.emissive = Vec3::from(m.emissive_factor());
    mat.emissive_strength = m.emissive_strength().unwrap_or(1.0);
    mat.alpha_mode = match m.alpha_mode() {
        gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
        gltf::material::AlphaMode::Mask => AlphaMode::Mask,
        gltf::material::AlphaMode::Blend => AlphaMode::Blend,
    };
    mat.alpha_cutoff = m.alpha_cutoff().unwrap_or(0.5);
    if mat.alpha_mode != AlphaMode::Opaque {
        images.warnings.push(format!(
            "material '{name}': alpha mode {:?} is kept for export, but lodeval draws the material \
             opaque (alpha testing and blending are not implemented)",
            mat.alpha_mode
        ));
    }
    mat.double_sided = m.double_sided();
    mat.extras = m
        .extras()
        .as_ref()
        .and_then(|raw| serde_json::from_str(raw.get()).ok());
    let normal = m.normal_texture();
    let occlusion = m.occlusion_texture();
    if let Some(n) = &normal {
        mat.normal_scale = n.scale();
    }
    if let Some(o) = &occlusion {
        mat.occlusion_strength = o.strength();
    }
    let transform_of = |ext: Option<&serde_json::Value>| ext.map(transform_json);
    let refs = [
        pbr.base_color_texture().map(SlotRef::info),
        pbr.metallic_roughness_texture().map(SlotRef::info),
        normal.map(|n| SlotRef {
            transform: transform_of(n.extension_value("KHR_texture_transform")),
            tex_coord: n.tex_coord(),
            texture: n.texture(),
        }),
        occlusion.map(|o| SlotRef {
            transform: transform_of(o.extension_value("KHR_texture_transform")),
            tex_coord: o.tex_coord(),
            texture: o.texture(),
        }),
        m.emissive_texture().map(SlotRef::info),
    ];
    let spaces = [
        ColorSpace::Srgb,
        ColorSpace::Linear,
        ColorSpace::Linear,
        ColorSpace::Linear,
        ColorSpace::Srgb,
    ];
    let mut slots: [Option<TextureSlot>; 5] = Default::default();
    for ((out, r), space) in slots.iter_mut().zip(refs).zip(spaces) {
        let Some(r) = r else { continue };
        *out = images
            .get(&name, r.texture.source(), space)?
            .map(|texture| TextureSlot {
                texture,
                tex_coord: r.tex_coord,
                sampler: sampler(r.texture.sampler()),
                transform: r.transform,
                name: r.texture.name().map(str::to_string),
            });
    }
    let [base, mr, normal, occlusion, emissive] = slots;
    // The Blinn–Phong stand-in uses the metallic–roughness texture's mean (G rough, B metal).
    let (rough_mean, metal_mean) = mr
        .as_ref()
        .map_or((1.0, 1.0), |s| mean_g_b(s.texture.rgba()));
    mat.derive_blinn_phong(rough_mean, metal_mean);
    (
        mat.base_color_texture,
        mat.metallic_roughness_texture,
        mat.normal_texture,
        mat.occlusion_texture,
        mat.emissive_texture,
    ) = (base, mr, normal, occlusion, emissive);
    for (key, value) in m.extensions().into_iter().flatten() {
        if MODELLED.contains(&key.as_str()) {
            continue;
        }
        images.warnings.push(format!(
            "material '{name}': {key} is kept for export but not rendered (lodeval draws the \
             metallic–roughness core)"
        ));
        mat.other_extensions.push((key.clone(), value.clone()));
    }
    debug_assert_eq!(mat.model, Model::MetallicRoughness);
    Ok(mat)
}

/// Mean of the G and B channels of RGBA8 texels, in 0..1.
fn mean_g_b(rgba: &[u8]) -> (f32, f32) {
    let (mut g, mut b) = (0u64, 0u64);
    for px in rgba.chunks_exact(4) {
        g += px[1] as u64;
        b += px[2] as u64;
    }
    let n = (rgba.len() / 4).max(1) as f64 * 255.0;
    ((g as f64 / n) as f32, (b as f64 / n) as f32)
}
