//! The industrial baseline: meshoptimizer's `meshopt_simplify` (through the `meshopt` crate), as
//! engines use it to build LOD chains.
//!
//! Decisions:
//! - Only the index buffer changes; the LOD keeps the original vertices and their normals, as an
//!   engine's LOD built this way shares the vertex buffer. Unused vertices are dropped afterwards.
//! - Multi-material meshes are simplified one material at a time, with the vertices that several
//!   materials share locked, so material borders cannot open cracks. The triangle target is
//!   shared out in proportion to each material's triangles.
//! - meshoptimizer detects UV/normal seams itself from coinciding positions, and keeps them.
//!   Meshes split only by normals go through [`super::chain`]'s welded path first.
//! - The reported error is meshoptimizer's own estimate, relative to the mesh extent (its
//!   `result_error`); an absolute value in model units is that times `simplify_scale`. It is known
//!   to under-state the true maximum deviation; lodeval's Hausdorff distance is the honest one.

use crate::error::Result;
use crate::mesh::{LoadOptions, Mesh};

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

/// Simplify `mesh` towards `target`.
pub fn simplify(mesh: &Mesh, target: Target) -> Result<Simplified> {
    let positions: Vec<[f32; 3]> = mesh.positions().iter().map(|p| p.to_array()).collect();
    let tris = mesh.triangles().to_vec();
    let (out_tris, out_mats, worst_error) = by_material(mesh, &positions, &tris, target);
    let mut data = mesh.to_data();
    data.normals = Some(mesh.normals().to_vec());
    data.triangles = out_tris;
    data.material_ids = out_mats;
    let scale = ::meshopt::simplify_scale_decoder(&positions);
    Ok(Simplified {
        mesh: Mesh::new(data, &LoadOptions::default())?,
        relative_error: worst_error,
        absolute_error: worst_error * scale,
    })
}

/// Simplify `tris` (indices into `positions`) material by material; returns the triangles, their
/// material ids and the largest relative error.
fn by_material(
    mesh: &Mesh,
    positions: &[[f32; 3]],
    tris: &[[u32; 3]],
    target: Target,
) -> (Vec<[u32; 3]>, Vec<u32>, f32) {
    let mats = mesh.material_ids();
    let material_count = mesh.materials().len();
    // Vertices used by more than one material are locked.
    let mut first_material = vec![u32::MAX; positions.len()];
    let mut locked = vec![false; positions.len()];
    for (t, &m) in tris.iter().zip(mats) {
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
    for m in 0..material_count as u32 {
        let indices: Vec<u32> = tris
            .iter()
            .zip(mats)
            .filter(|(_, id)| **id == m)
            .flat_map(|(t, _)| *t)
            .collect();
        if indices.is_empty() {
            continue;
        }
        let group = indices.len() / 3;
        let (target_count, target_error) = match target {
            Target::Triangles(n) => {
                let share = (n as f64 * group as f64 / tris.len() as f64).round() as usize;
                (share.max(1) * 3, f32::MAX)
            }
            Target::Error(e) => (0, e),
        };
        let mut error = 0f32;
        let result = ::meshopt::simplify_with_locks_decoder(
            &indices,
            positions,
            &locked,
            target_count,
            target_error,
            ::meshopt::SimplifyOptions::None,
            Some(&mut error),
        );
        worst_error = worst_error.max(error);
        for t in result.chunks_exact(3) {
            out_tris.push([t[0], t[1], t[2]]);
            out_mats.push(m);
        }
    }
    (out_tris, out_mats, worst_error)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halves_a_sphere_and_keeps_it_closed() {
        let sphere = crate::mesh::shapes::icosphere(4);
        let n = sphere.triangle_count();
        let s = simplify(&sphere, Target::Triangles(n / 2)).unwrap();
        let m = s.mesh.triangle_count();
        assert!(m <= n / 2 && m > n / 3, "{n} -> {m}");
        assert!(s.relative_error > 0.0 && s.absolute_error > 0.0);
        // Closed: every welded edge has exactly two triangles.
        let mut edges = std::collections::BTreeMap::new();
        let w = s.mesh.weld();
        for t in s.mesh.triangles() {
            for k in 0..3 {
                let (a, b) = (w[t[k] as usize], w[t[(k + 1) % 3] as usize]);
                *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        assert!(edges.values().all(|&c| c == 2));
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
