//! A LOD chain as one glTF 2.0 asset: `.glb` (everything in one file) or `.gltf` (JSON, a `.bin`
//! buffer and PNG images beside it). The finest mesh's node links the coarser ones through
//! `MSFT_lod`, and its `extras.MSFT_screencoverage` gives, per level, the screen coverage down to
//! which that level is shown — so an engine that reads the extension switches where the caller's
//! numbers say (lodeval's are measured imperceptibility distances).
//!
//! Based on: the glTF 2.0 specification (Khronos, 2021): buffers, accessors (POSITION with its
//! bounds), primitives, metallic–roughness materials, GLB chunks; Microsoft's `MSFT_lod` vendor
//! extension (node `extensions.MSFT_lod.ids`, the coarser levels in order, and
//! `extras.MSFT_screencoverage`, one value per level including the finest: level k is used while
//! the object covers at least value k of the screen; a last value of 0 never culls).
//!
//! Decisions:
//! - One mesh per level, one primitive per material it uses; levels share materials, textures and
//!   images (the same material written once). Only the finest level's node is in the scene (the
//!   others are reached through the extension), so a reader without `MSFT_lod` shows the original.
//! - Texture coordinates are flipped back to glTF's top-left origin (the loader flipped them).
//! - lodeval's materials are Blinn–Phong; they go back to metallic–roughness by inverting the
//!   loader's mapping: roughness = (2 / (n + 2))^¼ for the exponent n, metallic from where the
//!   specular colour lies between 0.04 and the base colour. Base colour, its texture and the
//!   normal map are kept exactly; a glTF input's own metallic–roughness texture is not kept.

use std::borrow::Cow;
use std::path::Path;
use std::sync::Arc;

use glam::Vec3;
use serde_json::{Value, json};

use super::{Material, Mesh, Texture};
use crate::error::{Error, Result};

/// Byte offset alignment of buffer views.
const ALIGN: usize = 4;

/// The binary buffer being built and the views into it.
#[derive(Default)]
struct Buffer {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Buffer {
    /// Append `data` as a buffer view (with `target` where it is vertex or index data).
    fn view(&mut self, data: &[u8], target: Option<u32>) -> usize {
        while !self.bytes.len().is_multiple_of(ALIGN) {
            self.bytes.push(0);
        }
        let mut v = json!({
            "buffer": 0,
            "byteOffset": self.bytes.len(),
            "byteLength": data.len(),
        });
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.bytes.extend_from_slice(data);
        self.views.push(v);
        self.views.len() - 1
    }

    /// Append float vectors of `n` components as a vertex accessor.
    fn floats(&mut self, values: &[f32], n: usize, bounds: bool) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(34962));
        let kind = ["SCALAR", "VEC2", "VEC3", "VEC4"][n - 1];
        let mut a = json!({
            "bufferView": view,
            "componentType": 5126,
            "count": values.len() / n,
            "type": kind,
        });
        if bounds {
            let mut lo = vec![f32::INFINITY; n];
            let mut hi = vec![f32::NEG_INFINITY; n];
            for chunk in values.chunks(n) {
                for k in 0..n {
                    lo[k] = lo[k].min(chunk[k]);
                    hi[k] = hi[k].max(chunk[k]);
                }
            }
            a["min"] = json!(lo);
            a["max"] = json!(hi);
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    /// Append triangle indices as an index accessor.
    fn indices(&mut self, values: &[u32]) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(34963));
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": 5125,
            "count": values.len(),
            "type": "SCALAR",
        }));
        self.accessors.len() - 1
    }
}

/// Materials and their textures, each written once however many levels use them.
#[derive(Default)]
struct Materials {
    written: Vec<Material>,
    json: Vec<Value>,
    textures: Vec<(Arc<Texture>, usize)>,
    /// PNG bytes per image (texture k uses image k).
    pngs: Vec<Vec<u8>>,
    texture_json: Vec<Value>,
}

impl Materials {
    /// The glTF texture index of `t`, its PNG added to the buffer the first time.
    fn texture(&mut self, t: &Arc<Texture>) -> Result<usize> {
        if let Some((_, i)) = self.textures.iter().find(|(x, _)| Arc::ptr_eq(x, t)) {
            return Ok(*i);
        }
        let img = image::RgbaImage::from_raw(t.width(), t.height(), t.rgba().to_vec())
            .ok_or_else(|| Error::Internal("glTF export: texture size".into()))?;
        let mut png = Vec::new();
        image::DynamicImage::ImageRgba8(img)
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .map_err(|e| Error::Internal(format!("glTF export: PNG: {e}")))?;
        self.pngs.push(png);
        self.texture_json
            .push(json!({ "source": self.pngs.len() - 1 }));
        let i = self.texture_json.len() - 1;
        self.textures.push((t.clone(), i));
        Ok(i)
    }

    /// The glTF material index of `m`.
    fn material(&mut self, m: &Material) -> Result<usize> {
        let same = |a: &Material| {
            let tex = |x: &Option<Arc<Texture>>, y: &Option<Arc<Texture>>| match (x, y) {
                (Some(x), Some(y)) => Arc::ptr_eq(x, y),
                (None, None) => true,
                _ => false,
            };
            a.name == m.name
                && a.base_color == m.base_color
                && a.specular == m.specular
                && a.shininess == m.shininess
                && tex(&a.base_color_texture, &m.base_color_texture)
                && tex(&a.normal_texture, &m.normal_texture)
        };
        if let Some(i) = self.written.iter().position(same) {
            return Ok(i);
        }
        let (metallic, roughness) = metallic_roughness(m);
        let c = m.base_color;
        let mut pbr = json!({
            "baseColorFactor": [c.x, c.y, c.z, 1.0],
            "metallicFactor": metallic,
            "roughnessFactor": roughness,
        });
        if let Some(t) = &m.base_color_texture {
            pbr["baseColorTexture"] = json!({ "index": self.texture(t)? });
        }
        let mut mat = json!({ "name": m.name, "pbrMetallicRoughness": pbr });
        if let Some(t) = &m.normal_texture {
            mat["normalTexture"] = json!({ "index": self.texture(t)? });
        }
        self.json.push(mat);
        self.written.push(m.clone());
        Ok(self.written.len() - 1)
    }
}

/// Metallic and roughness for a Blinn–Phong material (the inverse of the loader's mapping).
pub fn metallic_roughness(m: &Material) -> (f32, f32) {
    let alpha = (2.0 / (m.shininess.max(1.0) + 2.0)).sqrt();
    let roughness = alpha.sqrt().clamp(0.0, 1.0);
    // specular = 0.04 + (base − 0.04)·metallic, per channel; the mean over channels with room.
    let (mut sum, mut n) = (0.0, 0);
    for k in 0..3 {
        let span = m.base_color[k] - 0.04;
        if span.abs() > 0.05 {
            sum += ((m.specular[k] - 0.04) / span).clamp(0.0, 1.0);
            n += 1;
        }
    }
    (if n > 0 { sum / n as f32 } else { 0.0 }, roughness)
}

/// Write `levels` (finest first, each with its name) as one glTF asset at `path` (`.glb` or
/// `.gltf`), linked by `MSFT_lod`, with `coverage` (one value per level, non-increasing, the last
/// usually 0) as `MSFT_screencoverage`. Returns every file written.
pub fn write_lod_chain(
    levels: &[(&str, &Mesh)],
    coverage: &[f64],
    path: &Path,
) -> Result<Vec<std::path::PathBuf>> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if ext != "glb" && ext != "gltf" {
        return Err(Error::Usage(format!(
            "{}: a glTF LOD chain is written as .glb or .gltf",
            path.display()
        )));
    }
    if levels.is_empty() || coverage.len() != levels.len() {
        return Err(Error::Internal(format!(
            "glTF export: {} levels and {} coverage values",
            levels.len(),
            coverage.len()
        )));
    }
    if coverage.iter().any(|c| !c.is_finite()) || coverage.windows(2).any(|w| w[1] > w[0]) {
        return Err(Error::Internal(format!(
            "glTF export: screen coverage {coverage:?} must be finite and non-increasing"
        )));
    }
    let mut buffer = Buffer::default();
    let mut materials = Materials::default();
    let mut meshes = Vec::new();
    for (name, mesh) in levels {
        let p: Vec<f32> = mesh.positions().iter().flat_map(|v| v.to_array()).collect();
        let n: Vec<f32> = mesh.normals().iter().flat_map(|v| v.to_array()).collect();
        let mut attributes = json!({
            "POSITION": buffer.floats(&p, 3, true),
            "NORMAL": buffer.floats(&n, 3, false),
        });
        if let Some(uvs) = mesh.uvs() {
            let t: Vec<f32> = uvs.iter().flat_map(|u| [u.x, 1.0 - u.y]).collect();
            attributes["TEXCOORD_0"] = json!(buffer.floats(&t, 2, false));
        }
        if let Some(colors) = mesh.colors() {
            let c: Vec<f32> = colors.iter().flat_map(|c: &Vec3| c.to_array()).collect();
            attributes["COLOR_0"] = json!(buffer.floats(&c, 3, false));
        }
        let mut primitives = Vec::new();
        for (mi, m) in mesh.materials().iter().enumerate() {
            let idx: Vec<u32> = mesh
                .triangles()
                .iter()
                .zip(mesh.material_ids())
                .filter(|(_, id)| **id as usize == mi)
                .flat_map(|(t, _)| *t)
                .collect();
            if idx.is_empty() {
                continue;
            }
            let material = materials.material(m)?;
            primitives.push(json!({
                "attributes": attributes.clone(),
                "indices": buffer.indices(&idx),
                "material": material,
                "mode": 4,
            }));
        }
        meshes.push(json!({ "name": name, "primitives": primitives }));
    }
    let mut nodes: Vec<Value> = levels
        .iter()
        .enumerate()
        .map(|(i, (name, _))| json!({ "name": name, "mesh": i }))
        .collect();
    if levels.len() > 1 {
        nodes[0]["extensions"] =
            json!({ "MSFT_lod": { "ids": (1..levels.len()).collect::<Vec<_>>() } });
        nodes[0]["extras"] = json!({ "MSFT_screencoverage": coverage });
    }
    let stem = path
        .file_stem()
        .map_or_else(|| "lods".into(), |s| s.to_string_lossy().into_owned());
    let mut written = vec![path.to_path_buf()];
    let mut images = Vec::new();
    let dir = crate::io::parent_dir(path);
    for (k, png) in materials.pngs.iter().enumerate() {
        if ext == "glb" {
            let view = buffer.view(png, None);
            images.push(json!({ "bufferView": view, "mimeType": "image/png" }));
        } else {
            // Images as files beside the JSON.
            let file = format!("{stem}-image{k}.png");
            crate::io::write_atomic(&dir.join(&file), png)?;
            written.push(dir.join(&file));
            images.push(json!({ "uri": file, "mimeType": "image/png" }));
        }
    }
    let mut buffer_json = json!({ "byteLength": buffer.bytes.len() });
    if ext == "gltf" {
        let bin = format!("{stem}.bin");
        crate::io::write_atomic(&dir.join(&bin), &buffer.bytes)?;
        written.push(dir.join(&bin));
        buffer_json["uri"] = json!(bin);
    }
    let mut root = json!({
        "asset": { "version": "2.0", "generator": concat!("lodeval ", env!("CARGO_PKG_VERSION")) },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials.json,
        "buffers": [buffer_json],
        "bufferViews": buffer.views,
        "accessors": buffer.accessors,
    });
    if !images.is_empty() {
        root["images"] = json!(images);
        root["textures"] = json!(materials.texture_json);
    }
    if levels.len() > 1 {
        root["extensionsUsed"] = json!(["MSFT_lod"]);
    }
    let text = serde_json::to_vec(&root)
        .map_err(|e| Error::Internal(format!("glTF export: JSON: {e}")))?;
    if ext == "glb" {
        let glb = gltf::binary::Glb {
            header: gltf::binary::Header {
                magic: *b"glTF",
                version: 2,
                length: 0,
            },
            json: Cow::Owned(text),
            bin: Some(Cow::Owned(buffer.bytes)),
        };
        let bytes = glb
            .to_vec()
            .map_err(|e| Error::Internal(format!("glTF export: GLB: {e}")))?;
        crate::io::write_atomic(path, &bytes)?;
    } else {
        crate::io::write_atomic(path, &text)?;
    }
    Ok(written)
}
