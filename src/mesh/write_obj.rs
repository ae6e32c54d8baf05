//! Writing a mesh as Wavefront OBJ + MTL (what `lodeval simplify` produces), so its LODs load in
//! every tool and back into lodeval.
//!
//! Decisions:
//! - Vertices are written as they are in the [`Mesh`] (split at seams), with `v`, `vn` and `vt`
//!   lines of equal count and faces `f a/a/a`; UV v is written as stored (OpenGL convention, the
//!   same one the OBJ reader returns), so a round trip is exact up to float printing.
//! - Materials go to `STEM.mtl` beside the OBJ: `Kd` (linear base colour back to the file's
//!   convention, as MTL colours are read linearly), `Ks`, `Ns`, `Ke`, `d`, and for
//!   metallic–roughness materials the PBR extension keys `Pr`, `Pm`; textures beside it
//!   (`STEM-MATERIAL-basecolor`, `-normal`, `-emissive`, and the packed metallic–roughness image
//!   split into `-roughness` and `-metallic` grey PNGs for `map_Pr`/`map_Pm`), as the bytes they
//!   were read from where kept, else as PNG, so the output folder is self-contained.
//! - What MTL cannot say (occlusion maps, a second UV set, texture transforms, samplers, alpha
//!   masks, double-sidedness, glTF extensions, lights, nodes) is returned as warnings, one line
//!   per material. Vertex colours are written as OBJ's `v x y z r g b` (sRGB-encoded).
//! - Floats are printed in Rust's shortest round-trip form: reading the file back gives the same
//!   `f32` values. Every file is written atomically.

use std::fmt::Write;
use std::path::{Path, PathBuf};

use super::{AlphaMode, Material, Mesh, Model, Texture};
use crate::error::Result;

/// The stem of the output's file names (`lod` for `lod.obj`).
fn stem_of(path: &Path) -> String {
    path.file_stem()
        .map_or_else(|| "mesh".to_string(), |s| s.to_string_lossy().into_owned())
}

/// One texture file an MTL names: the MTL key, the file name's role, and what to write.
struct MapFile<'a> {
    key: &'static str,
    role: &'static str,
    texture: &'a Texture,
    /// `Some(c)`: write channel `c` alone as a grey PNG (glTF's packed metallic–roughness).
    channel: Option<usize>,
}

impl MapFile<'_> {
    /// The file's extension: the kept bytes' format, or PNG.
    fn extension(&self) -> &'static str {
        match (self.channel, self.texture.encoded()) {
            (None, Some(e)) if e.mime == "image/jpeg" => "jpg",
            _ => "png",
        }
    }
}

/// The texture files of material `m`, in MTL key order.
fn map_files(m: &Material) -> Vec<MapFile<'_>> {
    let mut out: Vec<MapFile> = [
        (&m.base_color_texture, "map_Kd", "basecolor"),
        (&m.normal_texture, "norm", "normal"),
        (&m.emissive_texture, "map_Ke", "emissive"),
    ]
    .into_iter()
    .filter_map(|(slot, key, role)| {
        slot.as_ref().map(|s| MapFile {
            key,
            role,
            texture: &s.texture,
            channel: None,
        })
    })
    .collect();
    if let Some(s) = &m.metallic_roughness_texture {
        for (key, role, channel) in [("map_Pr", "roughness", 1), ("map_Pm", "metallic", 2)] {
            out.push(MapFile {
                key,
                role,
                texture: &s.texture,
                channel: Some(channel),
            });
        }
    }
    out
}

/// Every file [`write()`] writes for `mesh` at `path`: the OBJ, the MTL and each texture.
pub fn planned_files(mesh: &Mesh, path: &Path) -> Vec<PathBuf> {
    let (stem, dir) = (stem_of(path), crate::io::parent_dir(path));
    let mut files = vec![path.to_path_buf(), dir.join(format!("{stem}.mtl"))];
    for (m, name) in mesh.materials().iter().zip(material_names(mesh)) {
        for f in map_files(m) {
            files.push(dir.join(format!("{stem}-{name}-{}.{}", f.role, f.extension())));
        }
    }
    files
}

/// What an MTL cannot say about material `m`.
fn material_warnings(m: &Material) -> Vec<String> {
    let mut lost = Vec::new();
    if m.occlusion_texture.is_some() {
        lost.push("its occlusion texture (MTL has no key for it)".to_string());
    }
    for (slot, t) in m.slots() {
        let Some(t) = t else { continue };
        if t.set() != 0 {
            lost.push(format!("{slot} reads TEXCOORD_{}", t.set()));
        }
        if t.transform.is_some() {
            lost.push(format!("{slot}'s KHR_texture_transform"));
        }
        if t.sampler != super::Sampler::default() {
            lost.push(format!("{slot}'s sampler"));
        }
    }
    if m.alpha_mode == AlphaMode::Mask {
        lost.push(format!("alpha MASK with cutoff {}", m.alpha_cutoff));
    }
    if m.double_sided {
        lost.push("double-sidedness".into());
    }
    if m.normal_scale != 1.0 {
        lost.push(format!("the normal map scale {}", m.normal_scale));
    }
    lost.extend(m.other_extensions.iter().map(|(name, _)| name.clone()));
    if m.extras.is_some() {
        lost.push("its extras".into());
    }
    if lost.is_empty() {
        return Vec::new();
    }
    vec![format!(
        "material '{}': the OBJ/MTL output does not keep {}",
        m.name,
        lost.join(", ")
    )]
}

/// The MTL text of material `m` (named `name`), with each map's file name.
fn mtl_entry(m: &Material, name: &str, stem: &str) -> String {
    let mut mtl = String::new();
    let _ = writeln!(mtl, "newmtl {name}");
    let c = m.base_color;
    let _ = writeln!(mtl, "Kd {} {} {}", c.x, c.y, c.z);
    let s = m.specular;
    let _ = writeln!(mtl, "Ks {} {} {}", s.x, s.y, s.z);
    let _ = writeln!(mtl, "Ns {}", m.shininess);
    let e = m.emission();
    if e != glam::Vec3::ZERO || m.emissive_texture.is_some() {
        let _ = writeln!(mtl, "Ke {} {} {}", e.x, e.y, e.z);
    }
    if m.base_alpha < 1.0 {
        let _ = writeln!(mtl, "d {}", m.base_alpha);
    }
    if m.model == Model::MetallicRoughness {
        let _ = writeln!(mtl, "Pr {}", m.roughness);
        let _ = writeln!(mtl, "Pm {}", m.metallic);
    }
    for f in map_files(m) {
        let _ = writeln!(mtl, "{} {stem}-{name}-{}.{}", f.key, f.role, f.extension());
    }
    mtl.push('\n');
    mtl
}

/// One map file's bytes: the kept bytes as they are, or the texels (or one channel) as PNG.
fn map_bytes(f: &MapFile, file: &Path) -> Result<Vec<u8>> {
    let t = f.texture;
    if let (None, Some(e)) = (f.channel, t.encoded()) {
        return Ok(e.bytes.to_vec());
    }
    let img = match f.channel {
        Some(c) => {
            let grey: Vec<u8> = t.rgba().chunks_exact(4).map(|p| p[c]).collect();
            image::DynamicImage::ImageLuma8(
                image::GrayImage::from_raw(t.width(), t.height(), grey)
                    .ok_or_else(|| crate::Error::Internal("texture size".into()))?,
            )
        }
        None => image::DynamicImage::ImageRgba8(
            image::RgbaImage::from_raw(t.width(), t.height(), t.rgba().to_vec())
                .ok_or_else(|| crate::Error::Internal("texture size".into()))?,
        ),
    };
    crate::io::encode_image(file, &img)
}

/// Write `mesh` to `path` (an `.obj`), with its `.mtl` and textures beside it. Refuses (before
/// writing anything) when one of those files is a file the mesh was loaded from. Returns what the
/// input had that OBJ/MTL cannot keep, one line each.
#[must_use = "the warnings name what the output does not keep; show them to the user"]
pub fn write(mesh: &Mesh, path: &Path) -> Result<Vec<String>> {
    crate::io::check_not_inputs(&planned_files(mesh, path), &mesh.source().files)?;
    let stem = stem_of(path);
    let dir = crate::io::parent_dir(path);
    let mut mtl = String::new();
    let mut warnings = Vec::new();
    // Every file lands together (or none does), the OBJ last.
    let mut staged = crate::io::Staged::default();
    let names = material_names(mesh);
    for (m, name) in mesh.materials().iter().zip(&names) {
        mtl.push_str(&mtl_entry(m, name, &stem));
        for f in map_files(m) {
            let file = dir.join(format!("{stem}-{name}-{}.{}", f.role, f.extension()));
            staged.write(&file, &map_bytes(&f, &file)?)?;
        }
        warnings.extend(material_warnings(m));
    }
    if mesh.uvs1().is_some() {
        warnings.push(
            "the second texture coordinate set (TEXCOORD_1) is not kept (OBJ has one)".into(),
        );
    }
    if !mesh.lights().is_empty() {
        warnings.push(format!(
            "the input's {} lights are not kept (OBJ has none)",
            mesh.lights().len()
        ));
    }
    if !mesh.source().nodes.is_empty() {
        warnings.push("the glTF nodes' names and transforms are not kept (OBJ has no nodes; the transforms are applied to the vertices)".into());
    }
    let mut obj = format!("# written by lodeval\nmtllib {stem}.mtl\n");
    let colors = mesh.colors();
    for (v, p) in mesh.positions().iter().enumerate() {
        match colors {
            // OBJ vertex colours are sRGB-encoded (the reader linearises them).
            Some(c) => {
                let e = c[v].to_array().map(crate::color::linear_to_srgb);
                let _ = writeln!(obj, "v {} {} {} {} {} {}", p.x, p.y, p.z, e[0], e[1], e[2]);
            }
            None => {
                let _ = writeln!(obj, "v {} {} {}", p.x, p.y, p.z);
            }
        }
    }
    write_faces(mesh, &names, &mut obj);
    staged.write(&dir.join(format!("{stem}.mtl")), mtl.as_bytes())?;
    staged.write(path, obj.as_bytes())?;
    staged.commit()?;
    Ok(warnings)
}

/// The `vn`, `vt`, `usemtl` and `f` records.
fn write_faces(mesh: &Mesh, names: &[String], obj: &mut String) {
    for n in mesh.normals() {
        let _ = writeln!(obj, "vn {} {} {}", n.x, n.y, n.z);
    }
    if let Some(uvs) = mesh.uvs() {
        for t in uvs {
            let _ = writeln!(obj, "vt {} {}", t.x, t.y);
        }
    }
    let mut current = u32::MAX;
    for (t, &m) in mesh.triangles().iter().zip(mesh.material_ids()) {
        if m != current {
            current = m;
            let _ = writeln!(obj, "usemtl {}", names[m as usize]);
        }
        let [a, b, c] = t.map(|i| i + 1);
        if mesh.uvs().is_some() {
            let _ = writeln!(obj, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}");
        } else {
            let _ = writeln!(obj, "f {a}//{a} {b}//{b} {c}//{c}");
        }
    }
}

/// `name` with every character other than ASCII letters, digits, `-`, `_` and `.` replaced by `_`:
/// safe in a file name and an MTL statement.
pub(super) fn file_safe(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Each material's name in the MTL: [`file_safe`], and made unique (`name-2`, …) where two
/// materials would share one (the same name twice, or `a b` and `a_b`), so no LOD's faces take
/// another material's maps.
fn material_names(mesh: &Mesh) -> Vec<String> {
    let mut used = std::collections::HashSet::new();
    let mut out = Vec::with_capacity(mesh.materials().len());
    for (i, m) in mesh.materials().iter().enumerate() {
        let mut s = file_safe(&m.name);
        if s.is_empty() {
            s = format!("material{i}");
        }
        let mut name = s.clone();
        let mut k = 2;
        while !used.insert(name.to_ascii_lowercase()) {
            name = format!("{s}-{k}");
            k += 1;
        }
        out.push(name);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_keeps_geometry_and_attributes() {
        let dir = tempfile::tempdir().unwrap();
        let spot = super::super::load(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join("reference/models/spot/spot_mtl.obj"),
            &Default::default(),
        )
        .unwrap();
        let out = dir.path().join("lod.obj");
        let warnings = write(&spot, &out).unwrap();
        assert!(warnings.is_empty(), "{warnings:?}");
        let back = super::super::load(&out, &Default::default()).unwrap();
        assert_eq!(back.triangle_count(), spot.triangle_count());
        assert_eq!(back.vertex_count(), spot.vertex_count());
        assert_eq!(back.positions(), spot.positions());
        assert_eq!(back.uvs(), spot.uvs());
        let (a, b) = (&spot.materials()[0], &back.materials()[0]);
        assert!(b.base_color_texture.is_some());
        assert_eq!(
            a.base_color_texture.as_ref().unwrap().texture.rgba(),
            b.base_color_texture.as_ref().unwrap().texture.rgba()
        );
        // A metallic–roughness material keeps its model and factors (Pr, Pm).
        assert_eq!(a.model, b.model);
        assert!((a.roughness - b.roughness).abs() < 1e-6 && a.metallic == b.metallic);
    }
}
