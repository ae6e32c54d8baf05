//! Stanford PLY loader, ASCII and binary (parsing by `ply-rs-bw`).
//!
//! Reads the `vertex` element (`x y z`, optional `nx ny nz`, colour as `red green blue` or
//! `diffuse_red …`, UVs as `u v`, `s t` or `texture_u texture_v`) and faces from a `face` element
//! (`vertex_indices` or `vertex_index` lists, fan-triangulated) and/or a `tristrips` element
//! (`vertex_indices` lists where −1 restarts the strip; Cyberware's Igea is stored this way).
//!
//! Decisions: strip triangles alternate winding as OpenGL's `GL_TRIANGLE_STRIP` does; strip
//! triangles with a repeated index are the stitching between sub-strips and are dropped (they have
//! no area), so they are not counted as degenerate. Integer colours are 8-bit sRGB; float colours
//! are sRGB in 0..1; both are linearised.

use std::path::Path;

use glam::{Vec2, Vec3};
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};

use super::{Format, MeshData, Source, read_file};
use crate::color::srgb_to_linear;
use crate::error::{Error, Location, Result};

const REEXPORT: &str = "re-export the PLY from its authoring tool";

fn scalar(e: &DefaultElement, names: &[&str]) -> Option<f32> {
    names
        .iter()
        .find_map(|n| e.get(*n))
        .and_then(Property::to_f32_lossy)
}

fn color_channel(p: &Property) -> Option<f32> {
    let v = match p {
        Property::Float(f) => *f,
        Property::Double(d) => *d as f32,
        other => other.to_f32_lossy()? / 255.0,
    };
    Some(srgb_to_linear(v))
}

/// A list property as signed indices (strips use −1 as a restart marker).
fn index_list(p: &Property) -> Option<Vec<i64>> {
    Some(match p {
        Property::ListChar(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUChar(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListShort(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUShort(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListInt(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUInt(v) => v.iter().map(|&x| x as i64).collect(),
        _ => return None,
    })
}

/// The header's promises checked against the bytes before the parser allocates by them: the
/// format is PLY 1.0, and every element count fits in what the file holds (an ASCII value takes
/// at least two bytes, a binary one its size), so a header declaring a billion vertices in a
/// small or sparse file is refused instead of allocating for them.
fn check_header(path: &Path, bytes: &[u8]) -> Result<()> {
    let head_len = bytes
        .windows(10)
        .take(1 << 16)
        .position(|w| w == b"end_header")
        .map(|p| p + 10);
    let Some(head_len) = head_len else {
        return Ok(()); // no header within 64 KiB: the parser names the problem
    };
    let head = String::from_utf8_lossy(&bytes[..head_len]);
    let body = (bytes.len() - head_len) as u128;
    let mut ascii = true;
    let mut elements: Vec<(String, u128, u128)> = Vec::new(); // name, count, least bytes each
    for (i, line) in head.lines().enumerate() {
        let here = Location::Line(i + 1);
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["format", kind, version, ..] => {
                if *version != "1.0" {
                    return Err(Error::input_at(
                        path,
                        here,
                        format!(
                            "declares PLY version {}; lodeval reads PLY 1.0",
                            crate::error::quote(version)
                        ),
                        REEXPORT,
                    ));
                }
                ascii = *kind == "ascii";
            }
            ["element", name, count, ..] => {
                let n = count.parse::<u128>().unwrap_or(0);
                elements.push((crate::error::quote(name), n, 0));
            }
            ["property", "list", count_type, ..] => {
                if let Some(e) = elements.last_mut() {
                    e.2 += if ascii { 2 } else { type_size(count_type) };
                }
            }
            ["property", ty, ..] => {
                if let Some(e) = elements.last_mut() {
                    e.2 += if ascii { 2 } else { type_size(ty) };
                }
            }
            _ => {}
        }
    }
    let need: u128 = elements.iter().map(|(_, n, b)| n * b).sum();
    if need > body {
        let (name, n, _) = elements
            .iter()
            .max_by_key(|(_, n, b)| n * b)
            .cloned()
            .unwrap_or_default();
        return Err(Error::input(
            path,
            format!(
                "the header declares {n} '{name}' elements, but the {body} bytes after it can \
                 hold far fewer: the file is truncated or its header is wrong"
            ),
            REEXPORT,
        ));
    }
    Ok(())
}

/// Bytes of a PLY scalar type (1 for an unknown name: the parser refuses it).
fn type_size(ty: &str) -> u128 {
    match ty {
        "char" | "uchar" | "int8" | "uint8" => 1,
        "short" | "ushort" | "int16" | "uint16" => 2,
        "int" | "uint" | "float" | "int32" | "uint32" | "float32" => 4,
        "double" | "float64" => 8,
        _ => 1,
    }
}

/// Load a PLY file.
pub(crate) fn load(path: &Path) -> Result<MeshData> {
    let bytes = read_file(path)?;
    check_header(path, &bytes)?;
    let ply = parse(path, &bytes)?;
    let empty = Vec::new();
    let vertices = ply.payload.get("vertex").unwrap_or(&empty);
    if vertices.is_empty() {
        return Err(Error::input(
            path,
            "the file has no 'vertex' element",
            REEXPORT,
        ));
    }
    let v = read_vertices(path, vertices)?;
    let n = v.positions.len() as i64;
    let (mut triangles, mut file_faces) =
        read_faces(path, ply.payload.get("face").unwrap_or(&empty), n)?;
    let (strips, strip_faces) =
        read_strips(path, ply.payload.get("tristrips").unwrap_or(&empty), n)?;
    triangles.extend(strips);
    file_faces += strip_faces;
    Ok(MeshData {
        positions: v.positions,
        normals: v.normals,
        uvs: v.uvs,
        uvs1: None,
        colors: v.colors,
        triangles,
        material_ids: vec![],
        materials: vec![],
        lights: Vec::new(),
        source: Source {
            path: path.to_path_buf(),
            format: Format::Ply,
            file_vertices: vertices.len(),
            file_faces,
            file_unreferenced: 0,
            edited: false,
            files: vec![path.to_path_buf()],
            nodes: Vec::new(),
            lod_chain: None,
        },
        warnings: vec![],
    })
}

/// The parser's reading of `bytes`, its errors as input errors at their line.
fn parse(path: &Path, bytes: &[u8]) -> Result<ply_rs_bw::ply::Ply<DefaultElement>> {
    let parser = Parser::<DefaultElement>::new();
    parser.read_ply(&mut &bytes[..]).map_err(|e| {
        let loc = e.line().map(Location::Line);
        // The parser's message starts with its own "Line N: "; we print the line once.
        let text = e.to_string();
        let text = match (e.line(), text.split_once(": ")) {
            (Some(_), Some((head, rest))) if head.starts_with("Line ") => rest.to_string(),
            _ => text,
        };
        let problem = format!("the file is not a valid PLY file: {text}");
        match loc {
            Some(l) => Error::input_at(path, l, problem, REEXPORT),
            None => Error::input(
                path,
                problem,
                "the file may be truncated; re-export or re-download it",
            ),
        }
    })
}

fn elem(what: &str, i: usize) -> Location {
    Location::Element(format!("{what} {i}"))
}

/// The vertex element's attributes (those the first vertex has).
struct Vertices {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    colors: Option<Vec<Vec3>>,
    uvs: Option<Vec<Vec2>>,
}

fn read_vertices(path: &Path, vertices: &[DefaultElement]) -> Result<Vertices> {
    let first = &vertices[0];
    let has_n = ["nx", "ny", "nz"].iter().all(|k| first.contains_key(*k));
    let color_keys: Option<[&str; 3]> = [
        ["red", "green", "blue"],
        ["diffuse_red", "diffuse_green", "diffuse_blue"],
        ["r", "g", "b"],
    ]
    .into_iter()
    .find(|k| k.iter().all(|n| first.contains_key(*n)));
    let uv_keys: Option<[&str; 2]> = [["u", "v"], ["s", "t"], ["texture_u", "texture_v"]]
        .into_iter()
        .find(|k| k.iter().all(|n| first.contains_key(*n)));
    let mut positions = Vec::with_capacity(vertices.len());
    let mut normals = Vec::new();
    let mut colors = Vec::new();
    let mut uvs = Vec::new();
    for (i, v) in vertices.iter().enumerate() {
        let get = |k: &str| {
            scalar(v, &[k]).ok_or_else(|| {
                Error::input_at(
                    path,
                    elem("vertex", i),
                    format!("property '{k}' is missing or not a number"),
                    REEXPORT,
                )
            })
        };
        positions.push(Vec3::new(get("x")?, get("y")?, get("z")?));
        if has_n {
            normals.push(Vec3::new(get("nx")?, get("ny")?, get("nz")?));
        }
        if let Some(keys) = color_keys {
            let c = keys.map(|k| v.get(k).and_then(color_channel).unwrap_or(1.0));
            colors.push(Vec3::from(c));
        }
        if let Some([u, w]) = uv_keys {
            uvs.push(Vec2::new(get(u)?, get(w)?));
        }
    }
    Ok(Vertices {
        positions,
        normals: has_n.then_some(normals),
        colors: color_keys.map(|_| colors),
        uvs: uv_keys.map(|_| uvs),
    })
}

/// `idx` as a vertex index of `n` vertices, or an error at element `what i`.
fn vertex_index(path: &Path, what: &str, i: usize, idx: i64, n: i64) -> Result<u32> {
    if idx < 0 || idx >= n {
        return Err(Error::input_at(
            path,
            elem(what, i),
            format!("vertex index {idx} is out of range (the file has {n} vertices)"),
            REEXPORT,
        ));
    }
    Ok(idx as u32)
}

/// The element's `vertex_indices` list (or `vertex_index`), or an error at element `what i`.
fn index_list_of(path: &Path, what: &str, i: usize, e: &DefaultElement) -> Result<Vec<i64>> {
    ["vertex_indices", "vertex_index"]
        .iter()
        .find_map(|k| e.get(*k))
        .and_then(index_list)
        .ok_or_else(|| {
            Error::input_at(
                path,
                elem(what, i),
                "has no 'vertex_indices' list",
                REEXPORT,
            )
        })
}

/// Polygon faces, fanned into triangles; returns them and the face count.
fn read_faces(path: &Path, faces: &[DefaultElement], n: i64) -> Result<(Vec<[u32; 3]>, usize)> {
    let mut triangles = Vec::new();
    for (i, f) in faces.iter().enumerate() {
        let list = index_list_of(path, "face", i, f)?;
        if list.len() < 3 {
            return Err(Error::input_at(
                path,
                elem("face", i),
                format!("has {} vertices; a face needs at least 3", list.len()),
                REEXPORT,
            ));
        }
        let idx: Vec<u32> = list
            .iter()
            .map(|&x| vertex_index(path, "face", i, x, n))
            .collect::<Result<_>>()?;
        for k in 1..idx.len() - 1 {
            triangles.push([idx[0], idx[k], idx[k + 1]]);
        }
    }
    Ok((triangles, faces.len()))
}

/// Triangle strips (−1 restarts a strip); returns the non-degenerate triangles and their count.
fn read_strips(path: &Path, strips: &[DefaultElement], n: i64) -> Result<(Vec<[u32; 3]>, usize)> {
    let mut triangles = Vec::new();
    for (i, s) in strips.iter().enumerate() {
        let list = s
            .get("vertex_indices")
            .and_then(index_list)
            .ok_or_else(|| {
                Error::input_at(
                    path,
                    elem("tristrips", i),
                    "has no 'vertex_indices' list",
                    REEXPORT,
                )
            })?;
        for strip in list.split(|&x| x == -1) {
            let idx: Vec<u32> = strip
                .iter()
                .map(|&x| vertex_index(path, "tristrips", i, x, n))
                .collect::<Result<_>>()?;
            for k in 0..idx.len().saturating_sub(2) {
                let t = if k % 2 == 0 {
                    [idx[k], idx[k + 1], idx[k + 2]]
                } else {
                    [idx[k + 1], idx[k], idx[k + 2]]
                };
                if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                    triangles.push(t);
                }
            }
        }
    }
    let count = triangles.len();
    Ok((triangles, count))
}
