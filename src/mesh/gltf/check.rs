//! Structural checks of a glTF document before anything reads through it: the node hierarchy is
//! a forest (glTF 2.0 §3.5.3: no cycles, at most one parent per node, scene roots are roots), and
//! every accessor lies inside its buffer view and every buffer view inside its buffer, with a
//! stride of at least one element (§3.6.2).
//!
//! The `gltf` crate checks that indices are in range but not these: a node that is its own
//! descendant made the scene walk loop forever while memory grew, and an accessor past its view's
//! end surfaced as "has no POSITION attribute". Each check names the node, accessor or buffer
//! view at fault.

use std::path::Path;

use gltf::json::validation::Checked;

use super::REEXPORT;
use crate::error::{Error, Location, Result};

/// Run every structural check on `root`.
pub(super) fn check(path: &Path, root: &gltf::json::Root) -> Result<()> {
    check_version(path, root)?;
    check_nodes(path, root)?;
    check_views(path, root)?;
    check_accessors(path, root)
}

/// A GLB's header states the file's whole length (glTF 2.0 §4.4.2); one that disagrees with the
/// bytes is a truncated or spliced file.
pub(super) fn check_glb_header(path: &Path, bytes: &[u8]) -> Result<()> {
    if bytes.len() < 12 || &bytes[..4] != b"glTF" {
        return Ok(()); // JSON glTF, or too short: the parser says so
    }
    let version = u32::from_le_bytes([bytes[4], bytes[5], bytes[6], bytes[7]]);
    let length = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize;
    if version != 2 {
        return Err(at(
            path,
            "GLB header".into(),
            format!(
                "not a valid glTF file: the header states container version {version}; lodeval reads GLB version 2"
            ),
        ));
    }
    if length != bytes.len() {
        return Err(at(
            path,
            "GLB header".into(),
            format!(
                "not a valid glTF file: the header states a length of {length} bytes, but the \
                 file has {}: it is truncated or spliced",
                bytes.len()
            ),
        ));
    }
    Ok(())
}

/// `asset.version` (and `minVersion`) must be a 2.x glTF: a later major version may mean
/// anything.
fn check_version(path: &Path, root: &gltf::json::Root) -> Result<()> {
    let major = |v: &str| v.split('.').next().and_then(|m| m.parse::<u32>().ok());
    for (key, v) in [
        ("asset.version", Some(&root.asset.version)),
        ("asset.minVersion", root.asset.min_version.as_ref()),
    ] {
        let Some(v) = v else { continue };
        if major(v) != Some(2) {
            return Err(at(
                path,
                key.into(),
                format!("is '{}'; lodeval reads glTF 2.x", crate::error::quote(v)),
            ));
        }
    }
    Ok(())
}

/// Every texture a primitive's material reads names a `TEXCOORD_n` set the primitive has (run
/// once the materials and their images have loaded, so a missing image is named first).
pub(super) fn check_tex_coords(path: &Path, root: &gltf::json::Root) -> Result<()> {
    use gltf::json::mesh::Semantic;
    for (mi, mesh) in root.meshes.iter().enumerate() {
        for (pi, prim) in mesh.primitives.iter().enumerate() {
            let Some(m) = prim.material.and_then(|m| root.materials.get(m.value())) else {
                continue;
            };
            let has = |n: u32| {
                prim.attributes
                    .keys()
                    .any(|s| matches!(s, Checked::Valid(Semantic::TexCoords(k)) if *k == n))
            };
            let pbr = &m.pbr_metallic_roughness;
            let slots = [
                (
                    "baseColorTexture",
                    pbr.base_color_texture.as_ref().map(info_set),
                ),
                (
                    "metallicRoughnessTexture",
                    pbr.metallic_roughness_texture.as_ref().map(info_set),
                ),
                (
                    "normalTexture",
                    m.normal_texture.as_ref().map(|t| t.tex_coord),
                ),
                (
                    "occlusionTexture",
                    m.occlusion_texture.as_ref().map(|t| t.tex_coord),
                ),
                ("emissiveTexture", m.emissive_texture.as_ref().map(info_set)),
            ];
            for (slot, set) in slots {
                if let Some(n) = set.filter(|&n| !has(n)) {
                    return Err(at(
                        path,
                        format!("mesh {mi} primitive {pi}"),
                        format!(
                            "its material {}'s {slot} reads TEXCOORD_{n}, which the primitive \
                             does not have",
                            prim.material.map_or(0, |m| m.value())
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// The UV set a texture reads (`KHR_texture_transform` may override it).
fn info_set(t: &gltf::json::texture::Info) -> u32 {
    t.extensions
        .as_ref()
        .and_then(|e| e.texture_transform.as_ref())
        .and_then(|x| x.tex_coord)
        .unwrap_or(t.tex_coord)
}

fn at(path: &Path, element: String, problem: String) -> Error {
    Error::input_at(path, Location::Element(element), problem, REEXPORT)
}

/// The node hierarchy must be a forest: in-range children, one parent at most, no cycles, and
/// scenes list only root nodes.
fn check_nodes(path: &Path, root: &gltf::json::Root) -> Result<()> {
    let n = root.nodes.len();
    let mut parent: Vec<Option<usize>> = vec![None; n];
    for (i, node) in root.nodes.iter().enumerate() {
        for child in node.children.iter().flatten() {
            let c = child.value();
            if c >= n {
                return Err(at(
                    path,
                    format!("node {i}"),
                    format!("lists child node {c}, but the file has {n} nodes"),
                ));
            }
            if c == i {
                return Err(at(
                    path,
                    format!("node {i}"),
                    "is its own child, so the hierarchy has a cycle".into(),
                ));
            }
            if let Some(p) = parent[c] {
                return Err(at(
                    path,
                    format!("node {c}"),
                    format!("is a child of both node {p} and node {i}; a glTF node has one parent"),
                ));
            }
            parent[c] = Some(i);
        }
    }
    // With one parent each, a cycle is a chain of parents that comes back to where it started;
    // `state` marks nodes known to reach a root (2) and nodes on the chain being walked (1).
    let mut state = vec![0u8; n];
    for start in 0..n {
        let mut chain = Vec::new();
        let mut cur = Some(start);
        while let Some(c) = cur {
            match state[c] {
                2 => break,
                1 => {
                    let cycle: Vec<String> = chain.iter().rev().map(usize::to_string).collect();
                    return Err(at(
                        path,
                        format!("node {c}"),
                        format!(
                            "is its own ancestor (through nodes {}), so the hierarchy has a cycle",
                            cycle.join(", ")
                        ),
                    ));
                }
                _ => {
                    state[c] = 1;
                    chain.push(c);
                    cur = parent[c];
                }
            }
        }
        for c in chain {
            state[c] = 2;
        }
    }
    for (si, scene) in root.scenes.iter().enumerate() {
        for node in &scene.nodes {
            let r = node.value();
            if r >= n {
                return Err(at(
                    path,
                    format!("scene {si}"),
                    format!("lists node {r}, but the file has {n} nodes"),
                ));
            }
            if let Some(p) = parent[r] {
                return Err(at(
                    path,
                    format!("scene {si}"),
                    format!("lists node {r} as a root, but it is a child of node {p}"),
                ));
            }
        }
    }
    Ok(())
}

/// Every buffer view lies inside its buffer.
fn check_views(path: &Path, root: &gltf::json::Root) -> Result<()> {
    for (vi, view) in root.buffer_views.iter().enumerate() {
        let b = view.buffer.value();
        let Some(buffer) = root.buffers.get(b) else {
            return Err(at(
                path,
                format!("buffer view {vi}"),
                format!(
                    "refers to buffer {b}, but the file has {} buffers",
                    root.buffers.len()
                ),
            ));
        };
        let offset = view.byte_offset.map_or(0, |o| o.0);
        let end = offset.checked_add(view.byte_length.0);
        if end.is_none_or(|e| e > buffer.byte_length.0) {
            return Err(at(
                path,
                format!("buffer view {vi}"),
                format!(
                    "spans bytes {offset}..{offset}+{}, past the end of buffer {b} ({} bytes)",
                    view.byte_length.0, buffer.byte_length.0
                ),
            ));
        }
    }
    Ok(())
}

/// Every accessor's elements lie inside its buffer view (sparse accessors without a view are
/// zeros plus substitutions and need no check here).
fn check_accessors(path: &Path, root: &gltf::json::Root) -> Result<()> {
    for (ai, acc) in root.accessors.iter().enumerate() {
        let Some(view_index) = acc.buffer_view else {
            continue;
        };
        let vi = view_index.value();
        let Some(view) = root.buffer_views.get(vi) else {
            return Err(at(
                path,
                format!("accessor {ai}"),
                format!(
                    "refers to buffer view {vi}, but the file has {} buffer views",
                    root.buffer_views.len()
                ),
            ));
        };
        let (Checked::Valid(ty), Checked::Valid(ct)) = (&acc.type_, &acc.component_type) else {
            continue; // the crate's validation names an unknown type
        };
        let element = (ty.multiplicity() * ct.0.size()) as u64;
        // §3.6.2.4: a stride is at least one element (the reader would take overlapping,
        // short slices: an assertion in the `gltf` crate).
        if let Some(st) = view.byte_stride
            && (st.0 as u64) < element
        {
            return Err(at(
                path,
                format!("buffer view {vi}"),
                format!(
                    "has byteStride {}, less than the {element} bytes of one element of accessor \
                     {ai}",
                    st.0
                ),
            ));
        }
        let stride = view.byte_stride.map_or(element, |st| st.0 as u64);
        let count = acc.count.0;
        let offset = acc.byte_offset.map_or(0, |o| o.0);
        let need = match count {
            0 => Some(offset),
            _ => (count - 1)
                .checked_mul(stride)
                .and_then(|s| s.checked_add(element))
                .and_then(|s| s.checked_add(offset)),
        };
        if need.is_none_or(|e| e > view.byte_length.0) {
            return Err(at(
                path,
                format!("accessor {ai}"),
                format!(
                    "needs {} bytes for {count} elements from offset {offset}, but buffer view \
                     {vi} has {} bytes",
                    need.map_or("more than 2^64".to_string(), |e| e.to_string()),
                    view.byte_length.0
                ),
            ));
        }
    }
    Ok(())
}
