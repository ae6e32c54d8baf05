//! Object File Format (OFF) loader, written here because the format is a dozen lines of grammar.
//!
//! Accepts the `OFF` keyword with optional `C`/`N` prefixes (`COFF`, `NOFF`, `CNOFF`: per-vertex
//! colour and normal), the counts on the keyword line or the next, `#` comments, blank lines and
//! CRLF line endings (the Happy Buddha copy has them). Faces are polygons `n i0 … i(n-1)`, fan
//! triangulated; trailing per-face colours are ignored. Every error names its line.

use std::path::Path;

use glam::Vec3;

use super::{Format, MeshData, Source};
use crate::color::srgb_to_linear;
use crate::error::{Error, Location, Result};

const FIX: &str = "fix that line or re-export the OFF file";

/// Non-empty, comment-stripped lines with their 1-based numbers.
fn lines(text: &str) -> impl Iterator<Item = (usize, Vec<&str>)> {
    text.split('\n').enumerate().filter_map(|(i, raw)| {
        let line = raw.split('#').next().unwrap_or("");
        let tokens: Vec<&str> = line.split_whitespace().collect();
        (!tokens.is_empty()).then_some((i + 1, tokens))
    })
}

fn num<T: std::str::FromStr>(path: &Path, line: usize, tok: &str, what: &str) -> Result<T> {
    tok.parse().map_err(|_| {
        Error::input_at(
            path,
            Location::Line(line),
            format!("'{tok}' is not a valid {what}"),
            FIX,
        )
    })
}

/// Load an OFF file.
pub(crate) fn load(path: &Path) -> Result<MeshData> {
    let bytes = super::read_text_file(path)?;
    let text = String::from_utf8_lossy(&bytes);
    let mut it = lines(&text);
    let truncated = |what: &str| {
        Error::input(
            path,
            format!("the file ends before {what}"),
            "the file is truncated; re-export or re-download it",
        )
    };

    // Header: keyword, then "vertices faces edges" on the same line or the next.
    let (line, tokens) = it.next().ok_or_else(|| truncated("the OFF header"))?;
    let keyword = tokens[0];
    let Some(prefix) = keyword.strip_suffix("OFF") else {
        return Err(Error::input_at(
            path,
            Location::Line(line),
            format!("expected the 'OFF' keyword, found '{keyword}'"),
            "check that this is an OFF file",
        ));
    };
    let (has_c, has_n) = (prefix.contains('C'), prefix.contains('N'));
    let (count_line, counts) = if tokens.len() > 1 {
        (line, tokens[1..].to_vec())
    } else {
        it.next()
            .ok_or_else(|| truncated("the vertex and face counts"))?
    };
    if counts.len() < 2 {
        return Err(Error::input_at(
            path,
            Location::Line(count_line),
            "expected 'vertices faces [edges]' counts",
            FIX,
        ));
    }
    let nv: usize = num(path, count_line, counts[0], "vertex count")?;
    let nf: usize = num(path, count_line, counts[1], "face count")?;

    // Vertices, one per line.
    let mut positions = Vec::with_capacity(nv.min(1 << 24));
    let mut normals = Vec::new();
    let mut colors = Vec::new();
    for i in 0..nv {
        let (line, t) = it
            .next()
            .ok_or_else(|| truncated(&format!("vertex {i} of {nv}")))?;
        let (p, n, c) = vertex(path, line, &t, i, (has_n, has_c))?;
        positions.push(p);
        normals.extend(n);
        colors.extend(c);
    }

    // Faces, one polygon per line.
    let mut triangles = Vec::with_capacity(nf.min(1 << 24));
    for i in 0..nf {
        let (line, t) = it
            .next()
            .ok_or_else(|| truncated(&format!("face {i} of {nf}")))?;
        let idx = face(path, line, &t, i, nv)?;
        let k = idx.len();
        for j in 1..k - 1 {
            triangles.push([idx[0], idx[j], idx[j + 1]]);
        }
    }

    Ok(MeshData {
        positions,
        normals: has_n.then_some(normals),
        uvs: None,
        uvs1: None,
        colors: has_c.then_some(colors),
        triangles,
        material_ids: vec![],
        materials: vec![],
        lights: Vec::new(),
        source: Source {
            path: path.to_path_buf(),
            format: Format::Off,
            file_vertices: nv,
            file_faces: nf,
            file_unreferenced: 0,
            edited: false,
            files: vec![path.to_path_buf()],
            nodes: Vec::new(),
            lod_chain: None,
        },
        warnings: vec![],
    })
}

/// Vertex `i`'s record on `line`: its position and, where the header says so (`has`: normals,
/// colours), its normal and its colour (integers 0..255 or floats 0..1, both sRGB).
fn vertex(
    path: &Path,
    line: usize,
    t: &[&str],
    i: usize,
    (has_n, has_c): (bool, bool),
) -> Result<(Vec3, Option<Vec3>, Option<Vec3>)> {
    let need = 3 + if has_n { 3 } else { 0 } + if has_c { 3 } else { 0 };
    if t.len() < need {
        return Err(Error::input_at(
            path,
            Location::Line(line),
            format!("vertex {i} has {} numbers; it needs {need}", t.len()),
            FIX,
        ));
    }
    let f = |k: usize| num::<f32>(path, line, t[k], "number");
    let p = Vec3::new(f(0)?, f(1)?, f(2)?);
    if !p.is_finite() {
        return Err(Error::input_at(
            path,
            Location::Line(line),
            format!("vertex {i} has a non-finite coordinate"),
            FIX,
        ));
    }
    let (mut normal, mut color) = (None, None);
    let mut k = 3;
    if has_n {
        normal = Some(Vec3::new(f(k)?, f(k + 1)?, f(k + 2)?));
        k += 3;
    }
    if has_c {
        let c = Vec3::new(f(k)?, f(k + 1)?, f(k + 2)?);
        // Integer colours are 0..255, float colours 0..1; both sRGB.
        let c = if t[k].contains('.') { c } else { c / 255.0 };
        color = Some(c.to_array().map(srgb_to_linear).into());
    }
    Ok((p, normal, color))
}

/// Face `i`'s record on `line`: its vertex indices, each below `nv`.
fn face(path: &Path, line: usize, t: &[&str], i: usize, nv: usize) -> Result<Vec<u32>> {
    let k: usize = num(path, line, t[0], "corner count")?;
    if k < 3 || t.len() < k + 1 {
        return Err(Error::input_at(
            path,
            Location::Line(line),
            format!("face {i} must list at least 3 vertex indices after its count ({k})"),
            FIX,
        ));
    }
    let mut idx = Vec::with_capacity(k);
    for tok in &t[1..=k] {
        let v: usize = num(path, line, tok, "vertex index")?;
        if v >= nv {
            return Err(Error::input_at(
                path,
                Location::Line(line),
                format!("vertex index {v} is out of range (the file has {nv} vertices)"),
                FIX,
            ));
        }
        idx.push(v as u32);
    }
    Ok(idx)
}
