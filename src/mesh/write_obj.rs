//! Writing a mesh as Wavefront OBJ + MTL (what `lodeval simplify` produces), so its LODs load in
//! every tool and back into lodeval.
//!
//! Decisions:
//! - Vertices are written as they are in the [`Mesh`] (split at seams), with `v`, `vn` and `vt`
//!   lines of equal count and faces `f a/a/a`; UV v is written as stored (OpenGL convention, the
//!   same one the OBJ reader returns), so a round trip is exact up to float printing.
//! - Materials go to `STEM.mtl` beside the OBJ: `Kd` (linear base colour back to the file's
//!   convention, as MTL colours are read linearly), `Ks`, `Ns`, and textures as PNG files beside it
//!   (`STEM-MATERIAL-basecolor.png`, `-normal.png`), written from the decoded pixels, so the output
//!   folder is self-contained.
//! - Floats are printed in Rust's shortest round-trip form: reading the file back gives the same
//!   `f32` values. Every file is written atomically.

use std::fmt::Write;
use std::path::{Path, PathBuf};

use super::Mesh;
use crate::error::Result;

/// The stem of the output's file names (`lod` for `lod.obj`).
fn stem_of(path: &Path) -> String {
    path.file_stem()
        .map_or_else(|| "mesh".to_string(), |s| s.to_string_lossy().into_owned())
}

/// Every file [`write()`] writes for `mesh` at `path`: the OBJ, the MTL and each texture.
pub fn planned_files(mesh: &Mesh, path: &Path) -> Vec<PathBuf> {
    let (stem, dir) = (stem_of(path), crate::io::parent_dir(path));
    let mut files = vec![path.to_path_buf(), dir.join(format!("{stem}.mtl"))];
    for (i, m) in mesh.materials().iter().enumerate() {
        let name = safe(&m.name, i);
        for (tex, role) in [
            (&m.base_color_texture, "basecolor"),
            (&m.normal_texture, "normal"),
        ] {
            if tex.is_some() {
                files.push(dir.join(format!("{stem}-{name}-{role}.png")));
            }
        }
    }
    files
}

/// Write `mesh` to `path` (an `.obj`), with its `.mtl` and textures beside it. Refuses (before
/// writing anything) when one of those files is a file the mesh was loaded from.
pub fn write(mesh: &Mesh, path: &Path) -> Result<()> {
    crate::io::check_not_inputs(&planned_files(mesh, path), &mesh.source().files)?;
    let stem = stem_of(path);
    let dir = crate::io::parent_dir(path);
    let mut mtl = String::new();
    for (i, m) in mesh.materials().iter().enumerate() {
        let name = safe(&m.name, i);
        let _ = writeln!(mtl, "newmtl {name}");
        let c = m.base_color;
        let _ = writeln!(mtl, "Kd {} {} {}", c.x, c.y, c.z);
        let s = m.specular;
        let _ = writeln!(mtl, "Ks {} {} {}", s.x, s.y, s.z);
        let _ = writeln!(mtl, "Ns {}", m.shininess);
        for (tex, role, key) in [
            (&m.base_color_texture, "basecolor", "map_Kd"),
            (&m.normal_texture, "normal", "norm"),
        ] {
            if let Some(t) = tex {
                let file = format!("{stem}-{name}-{role}.png");
                let img = image::RgbaImage::from_raw(t.width(), t.height(), t.rgba().to_vec())
                    .ok_or_else(|| crate::Error::Internal("texture size".into()))?;
                crate::io::write_image(&dir.join(&file), &image::DynamicImage::ImageRgba8(img))?;
                let _ = writeln!(mtl, "{key} {file}");
            }
        }
        mtl.push('\n');
    }
    let mut obj = format!("# written by lodeval\nmtllib {stem}.mtl\n");
    for p in mesh.positions() {
        let _ = writeln!(obj, "v {} {} {}", p.x, p.y, p.z);
    }
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
            let _ = writeln!(
                obj,
                "usemtl {}",
                safe(&mesh.materials()[m as usize].name, m as usize)
            );
        }
        let [a, b, c] = t.map(|i| i + 1);
        if mesh.uvs().is_some() {
            let _ = writeln!(obj, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}");
        } else {
            let _ = writeln!(obj, "f {a}//{a} {b}//{b} {c}//{c}");
        }
    }
    crate::io::write_atomic(&dir.join(format!("{stem}.mtl")), mtl.as_bytes())?;
    crate::io::write_atomic(path, obj.as_bytes())
}

fn safe(name: &str, i: usize) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() {
        format!("material{i}")
    } else {
        s
    }
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
        write(&spot, &out).unwrap();
        let back = super::super::load(&out, &Default::default()).unwrap();
        assert_eq!(back.triangle_count(), spot.triangle_count());
        assert_eq!(back.vertex_count(), spot.vertex_count());
        assert_eq!(back.positions(), spot.positions());
        assert_eq!(back.uvs(), spot.uvs());
        let (a, b) = (&spot.materials()[0], &back.materials()[0]);
        assert!(b.base_color_texture.is_some());
        assert_eq!(
            a.base_color_texture.as_ref().unwrap().rgba(),
            b.base_color_texture.as_ref().unwrap().rgba()
        );
    }
}
