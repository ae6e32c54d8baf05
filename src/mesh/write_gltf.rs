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
//! - Materials are written whole by `write_gltf_material.rs` (every slot, sampler, transform and
//!   kept extension; images as the bytes they were read from).
//! - Attributes: POSITION, NORMAL, TEXCOORD_0 and TEXCOORD_1 (flipped back to glTF's top-left
//!   origin; the loader flipped them), COLOR_0 (linear RGB), and TANGENT for meshes with normal
//!   maps: the tangents lodeval itself normal-maps with (`tangents.rs`), so an engine shades
//!   the LOD as it was measured.
//! - Nodes: the loader applies node transforms to the vertices. Where every merged node shared one
//!   transform (the usual one-node asset), the chain is written under a node of that name and
//!   transform, with the vertices taken back into its space; otherwise the merge is a warning.
//!   The file's `KHR_lights_punctual` lights are written as nodes of the scene.
//! - Side files (`.bin`, images) are written before the `.gltf` that names them.

use std::borrow::Cow;
use std::path::{Path, PathBuf};

use glam::{Mat3, Mat4, Vec3};
use serde_json::{Value, json};

use super::write_gltf_material::{ImageOut, Materials};
use super::{LightKind, Mesh};
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

/// What a chain export wrote: every file, and what it could not carry from the input.
#[derive(Debug, Clone, PartialEq)]
pub struct Written {
    /// Every file written (the `.glb`, or the `.gltf` with its `.bin` and images).
    pub files: Vec<PathBuf>,
    /// What the input had that the export does not carry, one line each.
    pub warnings: Vec<String>,
}

/// The node transform a chain is written under: the one world transform every merged node of
/// the finest level shared (the vertices go back to that node's space), or none.
fn shared_transform(mesh: &Mesh) -> Option<(String, Mat4)> {
    let nodes = &mesh.source().nodes;
    let first = nodes.first()?;
    let invertible = first.world.determinant().abs() > f32::MIN_POSITIVE;
    (invertible && first.world != Mat4::IDENTITY && nodes.iter().all(|n| n.world == first.world))
        .then(|| (first.name.clone(), first.world))
}

/// A node named `name` with transform `world`: translation, rotation and scale where they compose
/// back to it (the usual node), else the matrix.
fn transform_node(name: &str, world: &Mat4) -> Value {
    let (scale, rotation, translation) = world.to_scale_rotation_translation();
    let trs = Mat4::from_scale_rotation_translation(scale, rotation, translation);
    let largest = world
        .abs()
        .to_cols_array()
        .iter()
        .fold(1.0f32, |a, &b| a.max(b));
    if !trs.abs_diff_eq(*world, 1e-6 * largest) {
        return json!({ "name": name, "matrix": world.to_cols_array(), "children": [0] });
    }
    let mut node = json!({ "name": name, "children": [0] });
    if translation != Vec3::ZERO {
        node["translation"] = json!(translation.to_array());
    }
    if rotation != glam::Quat::IDENTITY {
        node["rotation"] = json!(rotation.to_array());
    }
    if scale != Vec3::ONE {
        node["scale"] = json!(scale.to_array());
    }
    node
}

/// The image file names beside a `.gltf` (`STEM-NAME.EXT`, made unique).
fn image_files(stem: &str, images: &[ImageOut]) -> Vec<String> {
    let mut used = std::collections::BTreeSet::new();
    images
        .iter()
        .map(|im| {
            let base = super::write_obj::file_safe(&im.name);
            let mut name = format!("{stem}-{base}.{}", im.extension());
            let mut k = 1;
            while !used.insert(name.clone()) {
                name = format!("{stem}-{base}-{k}.{}", im.extension());
                k += 1;
            }
            name
        })
        .collect()
}

/// One mesh per level, one primitive per material it uses, attributes in `space` (the inverse
/// of the shared node transform, or the identity).
fn level_meshes(
    levels: &[(&str, &Mesh)],
    space: Mat4,
    buffer: &mut Buffer,
    materials: &mut Materials,
) -> Result<Vec<Value>> {
    let normal_space = Mat3::from_mat4(space).inverse().transpose();
    // Tangents are directions in the surface: moved by the linear part; a mirroring transform
    // flips the bitangent's sign.
    let space_vectors = Mat3::from_mat4(space);
    let handedness = space_vectors.determinant().signum();
    let mut meshes = Vec::new();
    for (name, mesh) in levels {
        let p: Vec<f32> = mesh
            .positions()
            .iter()
            .flat_map(|v| space.transform_point3(*v).to_array())
            .collect();
        let n: Vec<f32> = mesh
            .normals()
            .iter()
            .flat_map(|v| (normal_space * *v).normalize_or(*v).to_array())
            .collect();
        let mut attributes = json!({
            "POSITION": buffer.floats(&p, 3, true),
            "NORMAL": buffer.floats(&n, 3, false),
        });
        for (set, uvs) in [(0, mesh.uvs()), (1, mesh.uvs1())] {
            if let Some(uvs) = uvs {
                let t: Vec<f32> = uvs.iter().flat_map(|u| [u.x, 1.0 - u.y]).collect();
                attributes[format!("TEXCOORD_{set}")] = json!(buffer.floats(&t, 2, false));
            }
        }
        if let Some(colors) = mesh.colors() {
            let c: Vec<f32> = colors.iter().flat_map(|c: &Vec3| c.to_array()).collect();
            attributes["COLOR_0"] = json!(buffer.floats(&c, 3, false));
        }
        // The tangents lodeval's normal mapping uses, so an engine draws what was measured.
        let normal_mapped = mesh.materials().iter().any(|m| m.normal_texture.is_some());
        if let (true, Some(uvs)) = (normal_mapped, mesh.uvs()) {
            let t =
                super::tangents::generate(mesh.positions(), mesh.normals(), uvs, mesh.triangles());
            let t: Vec<f32> = t
                .iter()
                .flat_map(|t| {
                    let d = (space_vectors * t.truncate()).normalize_or(t.truncate());
                    [d.x, d.y, d.z, t.w * handedness]
                })
                .collect();
            attributes["TANGENT"] = json!(buffer.floats(&t, 4, false));
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
    Ok(meshes)
}

/// `KHR_lights_punctual` lights and the nodes that place them (world space: position as
/// translation, the −Z axis turned onto the light's direction).
fn light_nodes(mesh: &Mesh, first_node: usize) -> (Vec<Value>, Vec<Value>) {
    let (mut lights, mut nodes) = (Vec::new(), Vec::new());
    for (i, l) in mesh.lights().iter().enumerate() {
        let mut light = json!({
            "color": l.color.to_array(),
            "intensity": l.intensity,
        });
        match l.kind {
            LightKind::Directional => light["type"] = json!("directional"),
            LightKind::Point => light["type"] = json!("point"),
            LightKind::Spot {
                inner_cone,
                outer_cone,
            } => {
                light["type"] = json!("spot");
                light["spot"] =
                    json!({ "innerConeAngle": inner_cone, "outerConeAngle": outer_cone });
            }
        }
        if let Some(r) = l.range {
            light["range"] = json!(r);
        }
        if let Some(name) = &l.name {
            light["name"] = json!(name);
        }
        let rotation = glam::Quat::from_rotation_arc(-Vec3::Z, l.direction.normalize_or(-Vec3::Z));
        nodes.push(json!({
            "name": l.name.clone().unwrap_or_else(|| format!("light {}", first_node + i)),
            "translation": l.position.to_array(),
            "rotation": rotation.to_array(),
            "extensions": { "KHR_lights_punctual": { "light": i } },
        }));
        lights.push(light);
    }
    (lights, nodes)
}

/// Every file [`write_lod_chain`] writes for `levels` at `path`, without writing anything.
pub fn planned_files(levels: &[(&str, &Mesh)], path: &Path) -> Result<Vec<PathBuf>> {
    let mut materials = Materials::default();
    for (_, mesh) in levels {
        for m in mesh.materials() {
            materials.material(m)?;
        }
    }
    let mut files = vec![path.to_path_buf()];
    if path.extension().and_then(|e| e.to_str()) == Some("gltf") {
        let dir = crate::io::parent_dir(path);
        let stem = stem_of(path);
        files.push(dir.join(format!("{stem}.bin")));
        files.extend(
            image_files(&stem, &materials.images)
                .into_iter()
                .map(|f| dir.join(f)),
        );
    }
    Ok(files)
}

fn stem_of(path: &Path) -> String {
    path.file_stem()
        .map_or_else(|| "lods".into(), |s| s.to_string_lossy().into_owned())
}

/// What the chain cannot carry of the finest level's source: nodes merged under different
/// transforms.
fn node_warnings(mesh: &Mesh, shared: &Option<(String, Mat4)>) -> Vec<String> {
    let nodes = &mesh.source().nodes;
    if nodes.len() > 1 && shared.is_none() {
        let mut names: Vec<&str> = nodes.iter().take(4).map(|n| n.name.as_str()).collect();
        if nodes.len() > 4 {
            names.push("…");
        }
        return vec![format!(
            "the input's {} mesh nodes ({}) are merged into one node per level, their transforms \
             applied to the vertices",
            nodes.len(),
            names.join(", ")
        )];
    }
    Vec::new()
}

/// Write `levels` (finest first, each with its name) as one glTF asset at `path` (`.glb` or
/// `.gltf`), linked by `MSFT_lod`, with `coverage` (one value per level, non-increasing, the last
/// usually 0) as `MSFT_screencoverage`. Returns every file written and what could not be kept.
pub fn write_lod_chain(levels: &[(&str, &Mesh)], coverage: &[f64], path: &Path) -> Result<Written> {
    let ext = check_chain(levels, coverage, path)?;
    // The finest level's node: its name and transform where every merged node shared one.
    let finest = levels[0].1;
    let shared = shared_transform(finest);
    let space = shared.as_ref().map_or(Mat4::IDENTITY, |(_, m)| m.inverse());
    let mut buffer = Buffer::default();
    let mut materials = Materials::default();
    let meshes = level_meshes(levels, space, &mut buffer, &mut materials)?;
    let mut nodes: Vec<Value> = levels
        .iter()
        .enumerate()
        .map(|(i, (name, _))| json!({ "name": name, "mesh": i }))
        .collect();
    let mut extensions_used = std::mem::take(&mut materials.extensions_used);
    if levels.len() > 1 {
        nodes[0]["extensions"] =
            json!({ "MSFT_lod": { "ids": (1..levels.len()).collect::<Vec<_>>() } });
        nodes[0]["extras"] = json!({ "MSFT_screencoverage": coverage });
        extensions_used.insert("MSFT_lod".into());
    }
    // The scene: the finest level (under its node's transform), then the file's lights.
    let mut roots = vec![0];
    if let Some((name, world)) = &shared {
        nodes.push(transform_node(name, world));
        roots = vec![nodes.len() - 1];
    }
    let (lights, light_nodes) = light_nodes(finest, nodes.len());
    for n in light_nodes {
        nodes.push(n);
        roots.push(nodes.len() - 1);
    }
    if !lights.is_empty() {
        extensions_used.insert("KHR_lights_punctual".into());
    }
    let stem = stem_of(path);
    let mut written = vec![path.to_path_buf()];
    let dir = crate::io::parent_dir(path);
    let names = image_files(&stem, &materials.images);
    let mut images = Vec::new();
    let mut files_out: Vec<(PathBuf, &[u8])> = Vec::new();
    for (im, file) in materials.images.iter().zip(&names) {
        if ext == "glb" {
            let view = buffer.view(&im.bytes, None);
            images.push(json!({ "bufferView": view, "mimeType": im.mime, "name": im.name }));
        } else {
            files_out.push((dir.join(file), &im.bytes));
            images.push(json!({ "uri": file, "mimeType": im.mime, "name": im.name }));
        }
    }
    let mut buffer_json = json!({ "byteLength": buffer.bytes.len() });
    if ext == "gltf" {
        let bin = format!("{stem}.bin");
        files_out.push((dir.join(&bin), &buffer.bytes));
        buffer_json["uri"] = json!(bin);
    }
    let mut root = json!({
        "asset": { "version": "2.0", "generator": concat!("lodeval ", env!("CARGO_PKG_VERSION")) },
        "scene": 0,
        "scenes": [{ "nodes": roots }],
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
    if !materials.sampler_json.is_empty() {
        root["samplers"] = json!(materials.sampler_json);
    }
    if !lights.is_empty() {
        root["extensions"] = json!({ "KHR_lights_punctual": { "lights": lights } });
    }
    if !extensions_used.is_empty() {
        root["extensionsUsed"] = json!(extensions_used);
    }
    let text = serde_json::to_vec(&root)
        .map_err(|e| Error::Internal(format!("glTF export: JSON: {e}")))?;
    // Nothing written may replace a file any level was read from (an input texture named like
    // an exported image, `-o` through `missing/..`).
    let mut planned: Vec<PathBuf> = files_out.iter().map(|(f, _)| f.clone()).collect();
    planned.push(path.to_path_buf());
    let inputs: Vec<PathBuf> = levels
        .iter()
        .flat_map(|(_, m)| m.source().files.iter().cloned())
        .collect();
    crate::io::check_not_inputs(&planned, &inputs)?;
    // All files land together, the document last: a failure leaves no orphan image and no
    // document naming missing files.
    let mut staged = crate::io::Staged::default();
    for (file, bytes) in &files_out {
        staged.write(file, bytes)?;
        written.push(file.clone());
    }
    if ext == "glb" {
        let bytes = glb(text, buffer.bytes)?;
        staged.write(path, &bytes)?;
    } else {
        staged.write(path, &text)?;
    }
    staged.commit()?;
    let mut warnings = node_warnings(finest, &shared);
    warnings.append(&mut materials.warnings);
    Ok(Written {
        files: written,
        warnings,
    })
}

/// The chain can be written: a `.glb` or `.gltf` path (its extension returned), one coverage
/// value per level, finite and non-increasing.
fn check_chain<'p>(levels: &[(&str, &Mesh)], coverage: &[f64], path: &'p Path) -> Result<&'p str> {
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
    Ok(ext)
}

/// A binary glTF of the JSON document `json` and the buffer `bin`.
fn glb(json: Vec<u8>, bin: Vec<u8>) -> Result<Vec<u8>> {
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: 0,
        },
        json: Cow::Owned(json),
        bin: Some(Cow::Owned(bin)),
    };
    glb.to_vec()
        .map_err(|e| Error::Internal(format!("glTF export: GLB: {e}")))
}
