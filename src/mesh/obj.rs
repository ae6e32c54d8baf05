//! Wavefront OBJ + MTL loader (parsing by `tobj`).
//!
//! Steps: read and UTF-8-check the file (a byte-order mark dropped, Latin-1 accepted in comments
//! and names only); `scan` it once ourselves, which (a) gives line numbers
//! for every error `tobj` would only name by kind (bad numbers, NaN coordinates, face indices out of
//! range or before their vertex), (b) counts records for `lodeval info`, and (c) moves `mtllib`
//! lines to the front, because `tobj` binds `usemtl` names only to libraries already read and some
//! exporters write `mtllib` last (Crane's Bob); then `tobj` parses the text, every `usemtl` is
//! checked against the materials the libraries define (an undefined one is a missing asset), and
//! we build vertices from the distinct (position, UV, normal) index triples, so seams split
//! vertices.
//!
//! Decisions: `l` and `p` records (lines, points) are ignored; polygons are fan-triangulated by
//! `tobj`; OBJ vertex colours are taken as sRGB-encoded values in 0..1 and linearised; `map_Bump`,
//! `bump` and `norm` all name a tangent-space normal map. Each MTL material is mapped by
//! `mtl.rs` (Blinn–Phong keys, and the PBR extension keys where present).

use std::collections::HashMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

use super::texture::{TextureCache, resolve_asset_path};
use super::{Format, LoadOptions, Material, MeshData, MissingAssets, Source};
use crate::color::srgb_to_linear;
use crate::error::{Error, Location, Result};

const FIX_SYNTAX: &str = "fix or delete that line, or re-export the OBJ";

/// What the line scan found.
#[derive(Debug)]
struct Scan {
    positions: usize,
    unreferenced: usize,
    /// Vertex colours were given on some `v` lines but not all, and were dropped.
    partial_colors: bool,
    faces: usize,
    mtllibs: Vec<(usize, String)>,
    /// Every `usemtl` line and the material it names (as `tobj` reads the name).
    usemtls: Vec<(usize, String)>,
    /// The text with every `mtllib`, `l` and `p` line blanked and the `mtllib` lines prepended.
    text: String,
}

/// Parse `count` floats from the tokens, or say which line is wrong.
fn floats<'a>(
    path: &Path,
    line_no: usize,
    tokens: &mut impl Iterator<Item = &'a str>,
    count: usize,
    what: &str,
) -> Result<[f32; 3]> {
    let mut out = [0.0; 3];
    for (i, slot) in out.iter_mut().enumerate().take(count) {
        let tok = tokens.next().ok_or_else(|| {
            Error::input_at(
                path,
                Location::Line(line_no),
                format!("{what} record has {i} numbers; it needs {count}"),
                FIX_SYNTAX,
            )
        })?;
        *slot = tok.parse::<f32>().map_err(|_| {
            Error::input_at(
                path,
                Location::Line(line_no),
                format!("'{tok}' in a {what} record is not a number"),
                FIX_SYNTAX,
            )
        })?;
        if !slot.is_finite() {
            return Err(Error::input_at(
                path,
                Location::Line(line_no),
                format!("{what} record has a non-finite value '{tok}'"),
                "replace NaN/inf coordinates with real values or delete the vertex and its faces",
            ));
        }
    }
    Ok(out)
}

/// Check one face-vertex token `p[/t[/n]]` against the records defined so far.
fn face_ref(
    path: &Path,
    line_no: usize,
    tok: &str,
    counts: [usize; 3],
    referenced: &mut [bool],
) -> Result<()> {
    const NAMES: [(&str, &str); 3] = [
        ("vertex", "vertices"),
        ("texture coordinate", "texture coordinates"),
        ("normal", "normals"),
    ];
    for (slot, part) in tok.split('/').enumerate().take(3) {
        if part.is_empty() && slot > 0 {
            continue;
        }
        let idx: i64 = part.parse().map_err(|_| {
            Error::input_at(
                path,
                Location::Line(line_no),
                format!("face entry '{tok}' is not of the form v, v/vt, v//vn or v/vt/vn"),
                FIX_SYNTAX,
            )
        })?;
        let n = counts[slot] as i64;
        let resolved = if idx < 0 { n + idx + 1 } else { idx };
        if idx == 0 || resolved < 1 || resolved > n {
            return Err(Error::input_at(
                path,
                Location::Line(line_no),
                format!(
                    "face refers to {} {idx}, but only {n} {} are defined before this line",
                    NAMES[slot].0, NAMES[slot].1
                ),
                "fix the face indices (OBJ indices start at 1) or add the missing records",
            ));
        }
        if slot == 0 {
            referenced[resolved as usize - 1] = true;
        }
    }
    Ok(())
}

fn scan(path: &Path, text: &str) -> Result<Scan> {
    let mut counts = [0usize; 3];
    let mut faces = 0;
    let mut colored = 0;
    let mut referenced: Vec<bool> = Vec::new();
    let mut mtllibs = Vec::new();
    let mut usemtls = Vec::new();
    let mut body = String::with_capacity(text.len() + 64);
    for (i, raw) in text.split('\n').enumerate() {
        let line_no = i + 1;
        let line = raw.strip_suffix('\r').unwrap_or(raw);
        let mut tokens = line.split_whitespace();
        let keep = match tokens.next() {
            Some("v") => {
                floats(path, line_no, &mut tokens, 3, "vertex")?;
                if vertex_extras(path, line_no, line, tokens)? {
                    colored += 1;
                }
                counts[0] += 1;
                referenced.push(false);
                true
            }
            Some("vt") => {
                floats(path, line_no, &mut tokens, 2, "texture coordinate")?;
                counts[1] += 1;
                true
            }
            Some("vn") => {
                floats(path, line_no, &mut tokens, 3, "normal")?;
                counts[2] += 1;
                true
            }
            Some("f") => {
                let mut corners = 0;
                for tok in tokens {
                    face_ref(path, line_no, tok, counts, &mut referenced)?;
                    corners += 1;
                }
                if corners < 3 {
                    return Err(Error::input_at(
                        path,
                        Location::Line(line_no),
                        format!("face has {corners} vertices; a face needs at least 3"),
                        FIX_SYNTAX,
                    ));
                }
                faces += 1;
                true
            }
            Some("mtllib") => {
                let name = line.trim_start()["mtllib".len()..].trim();
                mtllibs.push((line_no, name.to_string()));
                false
            }
            Some("usemtl") => {
                let name = line
                    .trim_start()
                    .split_once(' ')
                    .unwrap_or_default()
                    .1
                    .trim();
                if !name.is_empty() {
                    usemtls.push((line_no, name.to_string()));
                }
                true
            }
            Some("l") | Some("p") => false,
            _ => true,
        };
        // Keep the line count identical so any later tobj complaint maps to the same lines.
        if keep {
            body.push_str(line);
        }
        body.push('\n');
    }
    // tobj needs colours on every vertex or none; with only some, drop them all (and say so).
    let partial_colors = colored > 0 && colored < counts[0];
    if partial_colors {
        body = without_colors(&body);
    }
    let mut text = String::with_capacity(body.len() + 64);
    for (_, name) in &mtllibs {
        text.push_str("mtllib ");
        text.push_str(name);
        text.push('\n');
    }
    text.push_str(&body);
    Ok(Scan {
        positions: counts[0],
        unreferenced: referenced.iter().filter(|&&r| !r).count(),
        partial_colors,
        faces,
        mtllibs,
        usemtls,
        text,
    })
}

/// What follows a vertex record's x y z: nothing, a weight w (x y z are divided by it), or an
/// RGB colour (`true`).
fn vertex_extras<'a>(
    path: &Path,
    line_no: usize,
    line: &str,
    tokens: impl Iterator<Item = &'a str>,
) -> Result<bool> {
    let rest: Vec<&str> = tokens.collect();
    match rest.len() {
        0 => {}
        1 if rest[0]
            .parse::<f32>()
            .map_or(true, |w| w == 0.0 || !w.is_finite()) =>
        {
            return Err(Error::input_at(
                path,
                Location::Line(line_no),
                format!("vertex weight w = '{}' must be a non-zero number", rest[0]),
                FIX_SYNTAX,
            ));
        }
        1 => {}
        3 => {
            floats(
                path,
                line_no,
                &mut line.split_whitespace().skip(4),
                3,
                "vertex colour",
            )?;
        }
        n => {
            return Err(Error::input_at(
                path,
                Location::Line(line_no),
                format!(
                    "vertex record has {} numbers; expected 3 (x y z), 4 (x y z w) or 6 (x y z r g b)",
                    n + 3
                ),
                FIX_SYNTAX,
            ));
        }
    }
    Ok(rest.len() == 3)
}

/// `body` with the colours dropped from every vertex record (tobj needs colours on every vertex
/// or none).
fn without_colors(body: &str) -> String {
    body.split('\n')
        .map(|l| {
            let t: Vec<&str> = l.split_whitespace().collect();
            if t.first() == Some(&"v") && t.len() == 7 {
                t[..4].join(" ")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The file's text: UTF-8 without a leading byte-order mark (which would glue itself to the first
/// record and drop it). Real exporters write Latin-1 in comments and object or group names, so a
/// line that is not UTF-8 is accepted there (read as Latin-1, where it is never used); anywhere
/// else it is an error naming the line.
fn decode(path: &Path, bytes: Vec<u8>) -> Result<String> {
    let text = match String::from_utf8(bytes) {
        Ok(text) => text,
        Err(e) => {
            let bytes = e.into_bytes();
            let mut text = String::with_capacity(bytes.len() + 16);
            for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
                if i > 0 {
                    text.push('\n');
                }
                match std::str::from_utf8(line) {
                    Ok(l) => text.push_str(l),
                    Err(_) => {
                        let key = line
                            .iter()
                            .skip_while(|b| b.is_ascii_whitespace())
                            .take_while(|b| !b.is_ascii_whitespace())
                            .copied()
                            .collect::<Vec<u8>>();
                        let free_text = key.first() == Some(&b'#') || key == b"o" || key == b"g";
                        if !free_text {
                            return Err(Error::input_at(
                                path,
                                Location::Line(i + 1),
                                "the line is not text (invalid UTF-8; only comments and o/g \
                                 names may hold other bytes); is it really an OBJ file?",
                                "re-export it as a UTF-8 text OBJ",
                            ));
                        }
                        text.extend(line.iter().map(|&b| b as char));
                    }
                }
            }
            text
        }
    };
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    })
}

/// Check the numeric statements of an MTL file with line numbers. `tobj` reports these only by
/// kind, and panics on a colour with fewer than three numbers (found by the fuzz tests).
fn check_mtl(path: &Path) -> Result<()> {
    let bytes = crate::io::read_input(
        path,
        "material library",
        crate::limits::MESH_BYTES,
        "give a .mtl text file",
    )?;
    let text = String::from_utf8_lossy(&bytes).into_owned();
    for (i, line) in text.split('\n').enumerate() {
        let mut tokens = line.split_whitespace();
        let (count, what) = match tokens.next() {
            Some("Ka" | "Kd" | "Ks" | "Ke") => (3, "colour"),
            Some("Ns" | "Ni" | "d" | "Tr") => (1, "material value"),
            _ => continue,
        };
        floats(path, i + 1, &mut tokens, count, what).map_err(|e| match e {
            Error::Input {
                path,
                location,
                problem,
                ..
            } => Error::Input {
                path,
                location,
                problem,
                fix: "fix that line of the .mtl file or re-export it".into(),
            },
            other => other,
        })?;
    }
    Ok(())
}

/// A missing asset named at a line of the OBJ: an input error, or with `--missing-assets warn`
/// a warning.
fn missing_asset(
    options: &LoadOptions,
    warnings: &mut Vec<String>,
    (path, line): (&Path, usize),
    problem: String,
    fix: &str,
) -> Result<()> {
    match options.missing_assets {
        MissingAssets::Error => Err(Error::input_at(path, Location::Line(line), problem, fix)),
        MissingAssets::Warn => {
            warnings.push(problem);
            Ok(())
        }
    }
}

/// Load an OBJ file and the MTL libraries and textures it names.
pub(crate) fn load(path: &Path, options: &LoadOptions) -> Result<MeshData> {
    let text = decode(path, super::read_text_file(path)?)?;
    let scan = scan(path, &text)?;
    let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let mut warnings = Vec::new();
    if scan.partial_colors {
        warnings.push("vertex colours are given for only some vertices; all were ignored".into());
    }
    let mtl_paths = libraries(path, &dir, &scan, options, &mut warnings)?;
    let (models, tobj_materials) = parse(path, &dir, &scan, &mtl_paths)?;
    check_usemtls(path, &scan, &tobj_materials, options, &mut warnings)?;
    // Materials and their textures (decoded once, shared).
    let mut cache = TextureCache::default();
    let mut out_materials = Vec::with_capacity(tobj_materials.len() + 1);
    for m in &tobj_materials {
        let mtl_dir = scan
            .mtllibs
            .iter()
            .filter_map(|(_, n)| mtl_paths.get(n))
            .find_map(|p| p.parent())
            .unwrap_or(&dir)
            .to_path_buf();
        let ctx = super::mtl::MtlContext {
            obj: path,
            dir: &mtl_dir,
            options,
        };
        let mat = super::mtl::material(m, &ctx, &mut cache, &mut warnings)?;
        out_materials.push(mat);
    }
    let g = geometry(&models, out_materials.len());
    if g.needs_default {
        out_materials.push(Material::default_material());
    }
    let mut files = vec![path.to_path_buf()];
    files.extend(mtl_paths.into_values().filter(|p| p.is_file()));
    files.extend(cache.paths());
    files.sort();
    files.dedup();
    Ok(MeshData {
        positions: g.positions,
        normals: g.normals,
        uvs: g.uvs,
        uvs1: None,
        colors: g.colors,
        triangles: g.triangles,
        material_ids: g.material_ids,
        materials: out_materials,
        lights: Vec::new(),
        source: Source {
            path: path.to_path_buf(),
            format: Format::Obj,
            file_vertices: scan.positions,
            file_faces: scan.faces,
            file_unreferenced: scan.unreferenced,
            edited: false,
            files,
            nodes: Vec::new(),
            lod_chain: None,
        },
        warnings,
    })
}

/// Where each `mtllib` resolves; a missing library is an error unless the user asked for
/// warnings.
fn libraries(
    path: &Path,
    dir: &Path,
    scan: &Scan,
    options: &LoadOptions,
    warnings: &mut Vec<String>,
) -> Result<HashMap<String, PathBuf>> {
    let mut mtl_paths: HashMap<String, PathBuf> = HashMap::new();
    for (line_no, name) in &scan.mtllibs {
        let resolved = resolve_asset_path(dir, name);
        if !resolved.exists() {
            let problem = format!(
                "material library '{name}' not found at {}",
                resolved.display()
            );
            missing_asset(
                options,
                warnings,
                (path, *line_no),
                problem,
                "put the .mtl file there, fix the mtllib line, or pass --missing-assets warn to use default materials",
            )?;
        }
        if resolved.exists() {
            check_mtl(&resolved)?;
        }
        mtl_paths.insert(name.clone(), resolved);
    }
    Ok(mtl_paths)
}

/// tobj's models and materials of the scanned text.
fn parse(
    path: &Path,
    dir: &Path,
    scan: &Scan,
    mtl_paths: &HashMap<String, PathBuf>,
) -> Result<(Vec<tobj::Model>, Vec<tobj::Material>)> {
    let load_options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let mtl_error: std::cell::RefCell<Option<(PathBuf, tobj::LoadError)>> = Default::default();
    let (models, materials) =
        tobj::load_obj_buf(&mut Cursor::new(scan.text.as_bytes()), &load_options, |p| {
            let name = p.to_string_lossy().to_string();
            let resolved = mtl_paths.get(&name).cloned().unwrap_or_else(|| dir.join(p));
            if !resolved.is_file() {
                // Already reported (or warned about) above.
                return Ok((Vec::new(), Default::default()));
            }
            let result = tobj::load_mtl(&resolved);
            if let Err(e) = &result {
                mtl_error.borrow_mut().get_or_insert((resolved, *e));
            }
            result
        })
        .map_err(|e| {
            Error::input(
                path,
                format!("the OBJ parser rejected the file: {e}"),
                FIX_SYNTAX,
            )
        })?;
    if let Some((mtl, e)) = mtl_error.into_inner() {
        return Err(Error::input(
            &mtl,
            format!("the material library is malformed: {e}"),
            "fix or re-export the .mtl file",
        ));
    }
    Ok((models, materials.unwrap_or_default()))
}

/// A `usemtl` naming a material no library defines is a missing asset like a missing library:
/// tobj would quietly give those faces the default material.
fn check_usemtls(
    path: &Path,
    scan: &Scan,
    tobj_materials: &[tobj::Material],
    options: &LoadOptions,
    warnings: &mut Vec<String>,
) -> Result<()> {
    // A `usemtl` naming a material no library defines is a missing asset like a missing
    // library: tobj would quietly give those faces the default material.
    let defined: std::collections::HashSet<&str> =
        tobj_materials.iter().map(|m| m.name.as_str()).collect();
    let mut said = std::collections::HashSet::new();
    for (line_no, name) in &scan.usemtls {
        if defined.contains(name.as_str()) || !said.insert(name.as_str()) {
            continue; // defined, or the same undefined material used again
        }
        let libraries: Vec<&str> = scan.mtllibs.iter().map(|(_, n)| n.as_str()).collect();
        let problem = if libraries.is_empty() {
            format!("usemtl names material '{name}', but the file has no mtllib line")
        } else {
            format!(
                "usemtl names material '{name}', which no material library defines ({})",
                libraries.join(", ")
            )
        };
        missing_asset(
            options,
            warnings,
            (path, *line_no),
            problem,
            "add the material to its .mtl file (newmtl NAME), fix the usemtl line, or pass \
             --missing-assets warn to use the default material",
        )?;
    }

    Ok(())
}

/// The welded vertices, triangles and material ids of tobj's models.
struct Geometry {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    uvs: Option<Vec<Vec2>>,
    colors: Option<Vec<Vec3>>,
    triangles: Vec<[u32; 3]>,
    material_ids: Vec<u32>,
    /// Some faces have no (known) material: the default one goes after the file's.
    needs_default: bool,
}

fn geometry(models: &[tobj::Model], material_count: usize) -> Geometry {
    let default_id = material_count as u32;
    let mut needs_default = false;
    // Vertices: one per distinct (model, position, uv, normal) triple, in order of first use.
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    let mut normals = Vec::new();
    let mut colors = Vec::new();
    // UVs: if any part has them, parts without get (0, 0); normals only if every part has them
    // (otherwise all are computed, so shading is consistent across parts).
    let has_uv = models.iter().any(|m| !m.mesh.texcoord_indices.is_empty());
    let has_n = models.iter().all(|m| !m.mesh.normal_indices.is_empty()) && !models.is_empty();
    let has_c = models.iter().all(|m| !m.mesh.vertex_color.is_empty()) && !models.is_empty();
    let mut triangles = Vec::new();
    let mut material_ids = Vec::new();
    for model in models {
        let mesh = &model.mesh;
        let mut seen: HashMap<(u32, u32, u32), u32> = HashMap::new();
        let mat = match mesh.material_id {
            Some(id) if id < material_count => id as u32,
            _ => {
                needs_default = true;
                default_id
            }
        };
        let corner = |c: usize| -> (u32, u32, u32) {
            let p = mesh.indices[c];
            let t = mesh.texcoord_indices.get(c).copied().unwrap_or(u32::MAX);
            let n = if has_n { mesh.normal_indices[c] } else { 0 };
            (p, t, n)
        };
        for tri in mesh.indices.chunks_exact(3).enumerate().map(|(t, _)| t) {
            let mut out = [0u32; 3];
            for (k, slot) in out.iter_mut().enumerate() {
                let key = corner(tri * 3 + k);
                *slot = *seen.entry(key).or_insert_with(|| {
                    let (p, t, n) = (key.0 as usize, key.1 as usize, key.2 as usize);
                    positions.push(Vec3::new(
                        mesh.positions[3 * p],
                        mesh.positions[3 * p + 1],
                        mesh.positions[3 * p + 2],
                    ));
                    if has_uv {
                        uvs.push(match key.1 {
                            u32::MAX => Vec2::ZERO,
                            _ => Vec2::new(mesh.texcoords[2 * t], mesh.texcoords[2 * t + 1]),
                        });
                    }
                    if has_n {
                        normals.push(Vec3::new(
                            mesh.normals[3 * n],
                            mesh.normals[3 * n + 1],
                            mesh.normals[3 * n + 2],
                        ));
                    }
                    if has_c {
                        let c = &mesh.vertex_color[3 * p..3 * p + 3];
                        colors.push(Vec3::new(
                            srgb_to_linear(c[0]),
                            srgb_to_linear(c[1]),
                            srgb_to_linear(c[2]),
                        ));
                    }
                    (positions.len() - 1) as u32
                });
            }
            triangles.push(out);
            material_ids.push(mat);
        }
    }
    Geometry {
        positions,
        normals: has_n.then_some(normals),
        uvs: has_uv.then_some(uvs),
        colors: has_c.then_some(colors),
        triangles,
        material_ids,
        needs_default,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scan_moves_mtllib_first_and_keeps_line_count() {
        let s = scan(Path::new("x.obj"), "v 0 0 0\nusemtl a\nmtllib m.mtl\n").unwrap();
        assert!(s.text.starts_with("mtllib m.mtl\nv 0 0 0\nusemtl a\n"));
        assert_eq!(s.mtllibs, vec![(3, "m.mtl".to_string())]);
    }

    #[test]
    fn face_before_its_vertex_is_reported_with_its_line() {
        let e = scan(Path::new("x.obj"), "v 0 0 0\nf 1 2 3\nv 1 0 0\nv 0 1 0\n").unwrap_err();
        assert!(e.to_string().contains("line 2"), "{e}");
    }

    #[test]
    fn negative_indices_are_relative() {
        assert!(
            scan(
                Path::new("x.obj"),
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n"
            )
            .is_ok()
        );
    }
}
