//! The one validator every loader's output passes through before it becomes a [`Mesh`].
//!
//! Loaders check what they can with file positions (line numbers for text formats); this stage is
//! the backstop that holds for every format and for meshes built in code (simplifiers). It reports
//! elements in the loaded numbering ("vertex 12", "triangle 40").
//!
//! Fatal: no triangles, an index out of range, a non-finite coordinate, normal, UV or colour, an
//! attribute array whose length differs from the position count, a material id past the material
//! list. Not fatal: zero-area triangles (counted and reported: LODs produce them and users need to
//! see them, but they do not stop rendering).
//!
//! [`Mesh`]: super::Mesh

use glam::Vec3;

use super::MeshData;
use crate::error::{Error, Location, Result};

/// What the validator counted on valid input.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Report {
    /// Triangles with repeated corners or zero area.
    pub degenerate_triangles: usize,
}

const REEXPORT: &str = "re-export the mesh from its authoring tool or repair it (e.g. in MeshLab)";

/// Check `data` against the rules in the module docs.
pub(crate) fn check(data: &MeshData) -> Result<Report> {
    let path = &data.source.path;
    let n = data.positions.len();
    if data.triangles.is_empty() && data.source.edited {
        return Err(Error::input(
            path,
            "simplifying the mesh left no triangles",
            "ask for more triangles (a larger ratio or count, a smaller error) or another method",
        ));
    }
    if data.triangles.is_empty() {
        return Err(Error::input(
            path,
            "the file contains no triangles",
            "check that it holds a surface mesh (point clouds and line sets are not supported)",
        ));
    }
    // Attribute arrays must match the position count.
    let lengths = [
        ("normal", data.normals.as_ref().map(Vec::len)),
        ("texture coordinate", data.uvs.as_ref().map(Vec::len)),
        (
            "second texture coordinate",
            data.uvs1.as_ref().map(Vec::len),
        ),
        ("colour", data.colors.as_ref().map(Vec::len)),
    ];
    for (what, len) in lengths {
        if let Some(len) = len.filter(|&len| len != n) {
            return Err(Error::input(
                path,
                format!("{len} {what}s for {n} vertices; every vertex needs exactly one"),
                REEXPORT,
            ));
        }
    }
    if !data.material_ids.is_empty() && data.material_ids.len() != data.triangles.len() {
        return Err(Error::internal_mismatch(
            path,
            "material ids",
            data.material_ids.len(),
            data.triangles.len(),
        ));
    }
    // Every coordinate and attribute must be finite.
    let non_finite = |what: &str, v: usize, value: String, fix: &str| {
        Err(Error::input_at(
            path,
            Location::Element(format!("vertex {v}")),
            format!("{what} {value} is not a finite number"),
            fix,
        ))
    };
    if let Some(v) = data.positions.iter().position(|p| !p.is_finite()) {
        return non_finite("position", v, fmt_vec(data.positions[v]), REEXPORT);
    }
    check_scale(data)?;
    let normals = data.normals.as_deref().unwrap_or_default();
    if let Some(v) = normals.iter().position(|p| !p.is_finite()) {
        let fix = "remove the normals to let lodeval compute them, or re-export the mesh";
        return non_finite("normal", v, fmt_vec(normals[v]), fix);
    }
    for (what, uvs) in [
        ("texture coordinate", &data.uvs),
        ("second texture coordinate", &data.uvs1),
    ] {
        let uvs = uvs.as_deref().unwrap_or_default();
        if let Some(v) = uvs.iter().position(|p| !p.is_finite()) {
            return non_finite(what, v, format!("({}, {})", uvs[v].x, uvs[v].y), REEXPORT);
        }
    }
    super::material_check::check(path, &data.materials)?;
    let colors = data.colors.as_deref().unwrap_or_default();
    if let Some(v) = colors.iter().position(|p| !p.is_finite()) {
        return non_finite("colour", v, fmt_vec(colors[v]), REEXPORT);
    }
    // Indices in range; count zero-area triangles.
    let mut degenerate = 0;
    for (t, tri) in data.triangles.iter().enumerate() {
        if let Some(&bad) = tri.iter().find(|&&i| i as usize >= n) {
            return Err(Error::input_at(
                path,
                Location::Element(format!("triangle {t}")),
                format!("vertex index {bad} is out of range (the mesh has {n} vertices)"),
                REEXPORT,
            ));
        }
        let [a, b, c] = tri.map(|i| data.positions[i as usize]);
        if (b - a).cross(c - a).length_squared() == 0.0 {
            degenerate += 1;
        }
    }
    let material_count = data.materials.len().max(1);
    if let Some(t) = data
        .material_ids
        .iter()
        .position(|&m| m as usize >= material_count)
    {
        return Err(Error::input_at(
            path,
            Location::Element(format!("triangle {t}")),
            format!(
                "material index {} is out of range ({material_count} materials)",
                data.material_ids[t]
            ),
            REEXPORT,
        ));
    }
    Ok(Report {
        degenerate_triangles: degenerate,
    })
}

/// The mesh's size and place must suit single precision ([`crate::limits::MESH_EXTENT`],
/// [`crate::limits::MESH_OFFSET`]): a model 1e30 units across gave infinite bounds and NaN
/// distances, one 1e-30 across zero-area triangles everywhere, and one far from the origin
/// merged vertices and blank renders. Computed in f64 from the (finite) f32 positions, which
/// cannot overflow. Only the vertices triangles use count.
fn check_scale(data: &MeshData) -> Result<()> {
    use crate::limits::{MESH_EXTENT, MESH_OFFSET, Quantity};
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let (mut far, mut far_v) = (0.0f64, 0usize);
    let n = data.positions.len();
    for &i in data
        .triangles
        .iter()
        .flatten()
        .filter(|&&i| (i as usize) < n)
    {
        let p = data.positions[i as usize].to_array().map(f64::from);
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
            if p[k].abs() > far {
                (far, far_v) = (p[k].abs(), i as usize);
            }
        }
    }
    let size = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    let fix = "scale the model to sensible units (e.g. metres) and move it to the origin in its \
               authoring tool (Blender: Object > Set Origin, then Apply > All Transforms)";
    if let Some(m) = MESH_EXTENT.refuse(size) {
        return Err(Error::input(
            &data.source.path,
            format!("the mesh's bounding-box diagonal {m}"),
            fix,
        ));
    }
    if MESH_OFFSET.refuse(far / size).is_some() {
        return Err(Error::input_at(
            &data.source.path,
            Location::Element(format!("vertex {far_v}")),
            format!(
                "{} is {} units from the origin, {} times the mesh's size ({}): {}",
                fmt_vec(data.positions[far_v]),
                far.show(),
                (far / size).show(),
                size.show(),
                MESH_OFFSET.outside()
            ),
            fix,
        ));
    }
    Ok(())
}

/// Remove vertices no triangle references, renumbering triangles; returns how many were removed.
/// Requires `check` to have passed.
pub(crate) fn compact_unreferenced(data: &mut MeshData) -> usize {
    let n = data.positions.len();
    let mut new_index = vec![u32::MAX; n];
    for tri in &data.triangles {
        for &i in tri {
            new_index[i as usize] = 0;
        }
    }
    let mut next = 0u32;
    for slot in new_index.iter_mut() {
        if *slot == 0 {
            *slot = next;
            next += 1;
        }
    }
    let kept = next as usize;
    if kept == n {
        return 0;
    }
    fn keep<T: Copy>(values: &mut Vec<T>, new_index: &[u32]) {
        let mut w = 0;
        for r in 0..values.len() {
            if new_index[r] != u32::MAX {
                values[w] = values[r];
                w += 1;
            }
        }
        values.truncate(w);
    }
    keep(&mut data.positions, &new_index);
    if let Some(v) = data.normals.as_mut() {
        keep(v, &new_index);
    }
    if let Some(v) = data.uvs.as_mut() {
        keep(v, &new_index);
    }
    if let Some(v) = data.uvs1.as_mut() {
        keep(v, &new_index);
    }
    if let Some(v) = data.colors.as_mut() {
        keep(v, &new_index);
    }
    for tri in &mut data.triangles {
        *tri = tri.map(|i| new_index[i as usize]);
    }
    n - kept
}

fn fmt_vec(v: Vec3) -> String {
    use crate::limits::Quantity;
    format!("({}, {}, {})", v.x.show(), v.y.show(), v.z.show())
}

impl Error {
    fn internal_mismatch(path: &std::path::Path, what: &str, got: usize, want: usize) -> Error {
        Error::Internal(format!(
            "{}: loader produced {got} {what} for {want} triangles",
            path.display()
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{Format, Source};
    use std::path::PathBuf;

    fn tetra() -> MeshData {
        MeshData {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
            normals: None,
            uvs: None,
            uvs1: None,
            colors: None,
            triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
            material_ids: vec![],
            materials: vec![],
            lights: Vec::new(),
            source: Source {
                path: PathBuf::from("t.obj"),
                format: Format::Obj,
                file_vertices: 4,
                file_faces: 4,
                file_unreferenced: 0,
                edited: false,
                files: Vec::new(),
                nodes: Vec::new(),
                lod_chain: None,
            },
            warnings: vec![],
        }
    }

    #[test]
    fn valid_tetrahedron_passes_with_no_degenerates() {
        assert_eq!(check(&tetra()).unwrap().degenerate_triangles, 0);
    }

    #[test]
    fn index_out_of_range_names_the_triangle() {
        let mut m = tetra();
        m.triangles[2] = [1, 2, 4];
        let msg = check(&m).unwrap_err().to_string();
        assert!(
            msg.contains("triangle 2") && msg.contains("index 4"),
            "{msg}"
        );
    }

    #[test]
    fn nan_position_names_the_vertex() {
        let mut m = tetra();
        m.positions[3].y = f32::NAN;
        let msg = check(&m).unwrap_err().to_string();
        assert!(msg.contains("vertex 3") && msg.contains("NaN"), "{msg}");
    }

    #[test]
    fn repeated_corner_is_degenerate_not_fatal() {
        // A triangle with a repeated index has zero area by construction.
        let mut m = tetra();
        m.triangles.push([0, 0, 1]);
        assert_eq!(check(&m).unwrap().degenerate_triangles, 1);
    }

    #[test]
    fn unreferenced_vertices_are_compacted() {
        let mut m = tetra();
        m.positions.insert(0, Vec3::splat(9.0));
        for t in &mut m.triangles {
            *t = t.map(|i| i + 1);
        }
        assert_eq!(compact_unreferenced(&mut m), 1);
        assert_eq!(m.positions[0], Vec3::ZERO);
        assert_eq!(m.triangles[0], [0, 2, 1]);
    }
}
