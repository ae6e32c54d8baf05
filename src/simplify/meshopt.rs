//! The industrial baseline: meshoptimizer (through the `meshopt` crate), as engines use it to
//! build LOD chains. Two modes: `meshopt_simplify` (method `meshopt`) and
//! `meshopt_simplifyWithUpdate` (method `meshopt-update`), meshoptimizer's attribute-aware mode
//! that also moves the vertices it keeps, which is what our QEM does.
//!
//! Decisions:
//! - `meshopt`: only the index buffer changes; the LOD keeps the original vertices and their
//!   normals, as an engine's LOD built this way shares the vertex buffer. `meshopt-update`: the kept
//!   vertices get meshoptimizer's new positions and attributes (normals renormalized). Unused
//!   vertices are dropped afterwards.
//! - Multi-material meshes are simplified one material at a time, over that material's own
//!   vertices, with the vertices that several materials share locked, so material borders cannot
//!   open cracks. The triangle target is shared out in proportion to each material's triangles;
//!   an error target stays relative to the whole mesh's extent.
//! - meshoptimizer detects UV/normal seams itself from coinciding positions, and keeps them.
//!   Meshes split only by normals go through [`super::chain`]'s welded path first.
//! - The reported error is meshoptimizer's own estimate, relative to the mesh extent (its
//!   `result_error`); an absolute value in model units is that times `simplify_scale`. It is known
//!   to under-state the true maximum deviation; lodeval's Hausdorff distance is the honest one.

use glam::{Vec2, Vec3};

use crate::error::Result;
use crate::mesh::{LoadOptions, Mesh, MeshData};

/// What to aim for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Target {
    /// Triangle count (at most).
    Triangles(usize),
    /// meshoptimizer's relative error limit (no triangle target).
    Error(f32),
}

/// A simplified mesh and meshoptimizer's estimate of its error.
#[derive(Debug, Clone)]
pub struct Simplified {
    /// The LOD.
    pub mesh: Mesh,
    /// meshoptimizer's error estimate relative to the mesh extent, for this step.
    pub relative_error: f32,
    /// The same in model units.
    pub absolute_error: f32,
}

/// Simplify `mesh` towards `target` (`meshopt_simplify`: the index buffer changes, the vertices
/// stay).
pub fn simplify(mesh: &Mesh, target: Target) -> Result<Simplified> {
    let positions: Vec<[f32; 3]> = mesh.positions().iter().map(|p| p.to_array()).collect();
    let extent = ::meshopt::simplify_scale_decoder(&positions);
    let (tris, mats, worst_error) = by_material(mesh, target, |g| {
        let local: Vec<[f32; 3]> = match &g.vertices {
            Some(v) => v.iter().map(|&i| positions[i as usize]).collect(),
            None => positions.clone(),
        };
        let mut e = 0f32;
        let r = ::meshopt::simplify_with_locks_decoder(
            &g.indices,
            &local,
            &g.locked,
            g.count,
            g.error(extent),
            g.options(),
            Some(&mut e),
        );
        (r, g.relative(e, extent))
    });
    let mut data = mesh.to_data();
    data.normals = Some(mesh.normals().to_vec());
    finish(data, tris, mats, worst_error, extent)
}

/// Simplify `mesh` towards `target` with `meshopt_simplifyWithUpdate`: meshoptimizer's own
/// attribute-aware mode, which also moves the kept vertices and updates their attributes (its
/// counterpart of our QEM's optimal placement and attribute quadrics, so the like-for-like peer).
/// The attributes are the normals, and the UVs and colours where the mesh has them, weighted in
/// the units `attributes.rs` states for our QEM: meshoptimizer measures positions in units of
/// the mesh extent, so each weight is our scale × diagonal / extent.
pub fn simplify_updating(mesh: &Mesh, target: Target) -> Result<Simplified> {
    use super::attributes::{COLOR_SCALE, NORMAL_SCALE, UV_SCALE};
    let mut positions: Vec<[f32; 3]> = mesh.positions().iter().map(|p| p.to_array()).collect();
    let extent = ::meshopt::simplify_scale_decoder(&positions);
    let unit = mesh.aabb().diagonal() / extent.max(f32::MIN_POSITIVE);
    let (uvs, colors) = (mesh.uvs(), mesh.colors());
    let mut weights = vec![NORMAL_SCALE as f32 * unit; 3];
    if uvs.is_some() {
        weights.extend([UV_SCALE as f32 * unit; 2]);
    }
    if colors.is_some() {
        weights.extend([COLOR_SCALE as f32 * unit; 3]);
    }
    let k = weights.len();
    let mut attributes = Vec::with_capacity(k * positions.len());
    for v in 0..positions.len() {
        attributes.extend(mesh.normals()[v].to_array());
        if let Some(uv) = uvs {
            attributes.extend(uv[v].to_array());
        }
        if let Some(c) = colors {
            attributes.extend(c[v].to_array());
        }
    }
    let (tris, mats, worst_error) = by_material(mesh, target, |g| {
        let ids: Vec<u32> = match &g.vertices {
            Some(v) => v.clone(),
            None => (0..positions.len() as u32).collect(),
        };
        let mut local_p: Vec<[f32; 3]> = ids.iter().map(|&i| positions[i as usize]).collect();
        let mut local_a: Vec<f32> = ids
            .iter()
            .flat_map(|&i| {
                attributes[i as usize * k..(i as usize + 1) * k]
                    .iter()
                    .copied()
            })
            .collect();
        let lock: Vec<::meshopt::SimplifyVertex> = g
            .locked
            .iter()
            .map(|&l| {
                if l {
                    ::meshopt::SimplifyVertex::Lock
                } else {
                    ::meshopt::SimplifyVertex::None
                }
            })
            .collect();
        let mut r = g.indices.clone();
        let mut e = 0f32;
        let n = ::meshopt::simplify_with_update(
            &mut r,
            &mut local_p,
            &mut local_a,
            &weights,
            k * std::mem::size_of::<f32>(),
            Some(&lock),
            g.count,
            g.error(extent),
            g.options(),
            Some(&mut e),
        );
        r.truncate(n);
        // The group's vertices back into the mesh's arrays (shared ones are locked: unmoved).
        for (l, &i) in ids.iter().enumerate() {
            positions[i as usize] = local_p[l];
            attributes[i as usize * k..(i as usize + 1) * k]
                .copy_from_slice(&local_a[l * k..(l + 1) * k]);
        }
        (r, g.relative(e, extent))
    });
    let mut data = mesh.to_data();
    data.positions = positions.iter().map(|&p| Vec3::from_array(p)).collect();
    let at = |v: usize, i: usize| attributes[v * k + i];
    let original = mesh.normals();
    data.normals = Some(
        (0..positions.len())
            .map(|v| {
                Vec3::new(at(v, 0), at(v, 1), at(v, 2))
                    .try_normalize()
                    .unwrap_or(original[v])
            })
            .collect(),
    );
    if uvs.is_some() {
        data.uvs = Some(
            (0..positions.len())
                .map(|v| Vec2::new(at(v, 3), at(v, 4)))
                .collect(),
        );
    }
    if colors.is_some() {
        let o = if uvs.is_some() { 5 } else { 3 };
        data.colors = Some(
            (0..positions.len())
                .map(|v| Vec3::new(at(v, o), at(v, o + 1), at(v, o + 2)))
                .collect(),
        );
    }
    // meshoptimizer's error is relative to the extent of the mesh it was given, before the update.
    finish(data, tris, mats, worst_error, extent)
}

/// The LOD from the simplified triangles, with meshoptimizer's error in both units (`extent`: the
/// input's `simplify_scale`).
fn finish(
    mut data: MeshData,
    tris: Vec<[u32; 3]>,
    mats: Vec<u32>,
    worst_error: f32,
    extent: f32,
) -> Result<Simplified> {
    data.triangles = tris;
    data.material_ids = mats;
    Ok(Simplified {
        mesh: Mesh::new(data, &LoadOptions::default())?,
        relative_error: worst_error,
        absolute_error: worst_error * extent,
    })
}

/// One material's share of a simplification: its triangles over its own vertices.
struct Group {
    /// Triangle corners, indexing the group's vertices.
    indices: Vec<u32>,
    /// The mesh's ids of the group's vertices, ascending; `None` when the group uses every
    /// vertex of the mesh (then its indices are the mesh's own).
    vertices: Option<Vec<u32>>,
    /// Per group vertex: shared with another material, so it may not move.
    locked: Vec<bool>,
    /// Target index count (0: none).
    count: usize,
    /// Target error relative to the whole mesh's extent (`f32::MAX`: none).
    relative_error: f32,
}

impl Group {
    /// meshoptimizer's options: a compacted group's error is absolute, so it means the same as
    /// the whole mesh's relative error whatever the group's own extent.
    fn options(&self) -> ::meshopt::SimplifyOptions {
        match self.vertices {
            Some(_) => ::meshopt::SimplifyOptions::ErrorAbsolute,
            None => ::meshopt::SimplifyOptions::None,
        }
    }

    /// The target error in meshoptimizer's units for these options (`extent`: the whole mesh's).
    fn error(&self, extent: f32) -> f32 {
        match self.vertices {
            Some(_) if self.relative_error < f32::MAX => self.relative_error * extent,
            _ => self.relative_error,
        }
    }

    /// meshoptimizer's result error back to the whole mesh's relative units.
    fn relative(&self, e: f32, extent: f32) -> f32 {
        match self.vertices {
            Some(_) => e / extent.max(f32::MIN_POSITIVE),
            None => e,
        }
    }
}

/// Simplify `mesh`'s triangles material by material with `one(group) -> (indices into the
/// group's vertices, error relative to the mesh's extent)`; returns the triangles (mesh vertex
/// ids), their material ids and the largest relative error. Each material is simplified over its
/// own vertices only, so the work grows with the mesh, not with materials × vertices (100 000
/// materials used to take minutes).
fn by_material(
    mesh: &Mesh,
    target: Target,
    mut one: impl FnMut(&Group) -> (Vec<u32>, f32),
) -> (Vec<[u32; 3]>, Vec<u32>, f32) {
    let tris = mesh.triangles();
    let mats = mesh.material_ids();
    let material_count = mesh.materials().len();
    let vertex_count = mesh.vertex_count();
    // Vertices used by more than one material are locked.
    let mut first_material = vec![u32::MAX; vertex_count];
    let mut locked = vec![false; vertex_count];
    let mut by_mat: Vec<Vec<u32>> = vec![Vec::new(); material_count];
    for (t, &m) in tris.iter().zip(mats) {
        by_mat[m as usize].extend_from_slice(t);
        for &v in t {
            let f = &mut first_material[v as usize];
            if *f == u32::MAX {
                *f = m;
            } else if *f != m {
                locked[v as usize] = true;
            }
        }
    }
    let (mut out_tris, mut out_mats) = (Vec::new(), Vec::new());
    let mut worst_error = 0f32;
    let mut local_of = vec![u32::MAX; vertex_count];
    for (m, indices) in by_mat.into_iter().enumerate() {
        if indices.is_empty() {
            continue;
        }
        let group = indices.len() / 3;
        let (count, relative_error) = match target {
            Target::Triangles(n) => {
                // meshoptimizer asserts (aborts the process) on a target above its input, which
                // a chained goal can ask for when an earlier LOD stopped short of its own.
                let share = (n as f64 * group as f64 / tris.len() as f64).round() as usize;
                (share.clamp(1, group) * 3, f32::MAX)
            }
            Target::Error(e) => (0, e),
        };
        let mut ids: Vec<u32> = indices.clone();
        ids.sort_unstable();
        ids.dedup();
        let g = if ids.len() == vertex_count {
            Group {
                indices,
                vertices: None,
                locked: locked.clone(),
                count,
                relative_error,
            }
        } else {
            for (l, &v) in ids.iter().enumerate() {
                local_of[v as usize] = l as u32;
            }
            let g = Group {
                indices: indices.iter().map(|&v| local_of[v as usize]).collect(),
                locked: ids.iter().map(|&v| locked[v as usize]).collect(),
                vertices: Some(ids),
                count,
                relative_error,
            };
            for &v in g.vertices.iter().flatten() {
                local_of[v as usize] = u32::MAX;
            }
            g
        };
        let (result, error) = one(&g);
        worst_error = worst_error.max(error);
        for t in result.chunks_exact(3) {
            let global = |l: u32| g.vertices.as_ref().map_or(l, |v| v[l as usize]);
            out_tris.push([global(t[0]), global(t[1]), global(t[2])]);
            out_mats.push(m as u32);
        }
    }
    (out_tris, out_mats, worst_error)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An icosphere and `f`'s LOD of it at half the triangles (checked to be about half).
    fn halved_sphere(f: fn(&Mesh, Target) -> Result<Simplified>) -> (Mesh, Simplified) {
        let sphere = crate::mesh::shapes::icosphere(4);
        let n = sphere.triangle_count();
        let s = f(&sphere, Target::Triangles(n / 2)).unwrap();
        let m = s.mesh.triangle_count();
        assert!(m <= n / 2 && m > n / 3, "{n} -> {m}");
        (sphere, s)
    }

    #[test]
    fn halves_a_sphere_and_keeps_it_closed() {
        let (_, s) = halved_sphere(simplify);
        assert!(s.relative_error > 0.0 && s.absolute_error > 0.0);
        assert_closed(&s.mesh);
    }

    #[test]
    fn the_update_mode_moves_both_sides_of_a_uv_seam_together() {
        // Spot is closed and has UV seams (3 225 vertices on 2 930 positions). If the update
        // moved one copy of a seam vertex and not the other, the welded LOD would have cracks:
        // edges with one triangle.
        let spot = crate::mesh::load(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("reference/models/spot/spot_mtl.obj"),
            &LoadOptions::default(),
        )
        .unwrap();
        assert_closed(&spot);
        for n in [2928, 586] {
            let s = simplify_updating(&spot, Target::Triangles(n)).unwrap();
            assert!(s.mesh.vertex_count() > s.mesh.welded_vertex_count());
            assert_closed(&s.mesh);
        }
    }

    /// Closed: every welded edge has exactly two triangles.
    fn assert_closed(mesh: &Mesh) {
        let mut edges = std::collections::BTreeMap::new();
        let w = mesh.weld();
        for t in mesh.triangles() {
            for k in 0..3 {
                let (a, b) = (w[t[k] as usize], w[t[(k + 1) % 3] as usize]);
                *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        assert!(edges.values().all(|&c| c == 2));
    }

    #[test]
    fn the_update_mode_moves_vertices_and_keeps_the_sphere_closed() {
        // simplifyWithUpdate places the kept vertices anew: some of them are off the original's
        // vertex positions (the index-only mode keeps every one of them), the result stays a
        // closed surface at half the triangles, and its normals are unit length.
        let (sphere, s) = halved_sphere(simplify_updating);
        let original: std::collections::HashSet<[u32; 3]> = sphere
            .positions()
            .iter()
            .map(|p| p.to_array().map(f32::to_bits))
            .collect();
        let moved = s
            .mesh
            .positions()
            .iter()
            .filter(|p| !original.contains(&p.to_array().map(f32::to_bits)))
            .count();
        assert!(moved > 0, "no vertex moved");
        let (_, indexed) = halved_sphere(simplify);
        assert!(
            indexed
                .mesh
                .positions()
                .iter()
                .all(|p| original.contains(&p.to_array().map(f32::to_bits)))
        );
        assert!(
            s.mesh
                .normals()
                .iter()
                .all(|v| (v.length() - 1.0).abs() < 1e-5)
        );
        assert_closed(&s.mesh);
    }

    #[test]
    fn error_target_limits_error() {
        let sphere = crate::mesh::shapes::icosphere(4);
        let loose = simplify(&sphere, Target::Error(0.05)).unwrap();
        let tight = simplify(&sphere, Target::Error(0.001)).unwrap();
        assert!(loose.mesh.triangle_count() < tight.mesh.triangle_count());
        assert!(loose.relative_error <= 0.05 && tight.relative_error <= 0.001);
    }
}
