//! Per-vertex tangent frames for normal mapping, generated from texture coordinates.
//!
//! Based on: Eric Lengyel. Computing Tangent Space Basis Vectors for an Arbitrary Mesh. 2001 —
//! per-triangle ∂P/∂u and ∂P/∂v accumulated at the vertices, Gram–Schmidt against the normal,
//! handedness in `w` from the sign of (N × T) · B. Accumulation runs in triangle order
//! (deterministic). Vertices whose triangles have degenerate UVs get an arbitrary tangent
//! perpendicular to the normal.

use glam::{Vec2, Vec3, Vec4};

/// Tangents (xyz, unit, ⟂ normal) with handedness in w (±1), one per vertex.
pub fn generate(
    positions: &[Vec3],
    normals: &[Vec3],
    uvs: &[Vec2],
    triangles: &[[u32; 3]],
) -> Vec<Vec4> {
    let mut tan = vec![Vec3::ZERO; positions.len()];
    let mut bit = vec![Vec3::ZERO; positions.len()];
    for t in triangles {
        let [i0, i1, i2] = t.map(|i| i as usize);
        let (e1, e2) = (positions[i1] - positions[i0], positions[i2] - positions[i0]);
        let (d1, d2) = (uvs[i1] - uvs[i0], uvs[i2] - uvs[i0]);
        let det = d1.x * d2.y - d2.x * d1.y;
        if det.abs() < 1e-20 {
            continue;
        }
        let r = 1.0 / det;
        let sdir = (e1 * d2.y - e2 * d1.y) * r;
        let tdir = (e2 * d1.x - e1 * d2.x) * r;
        for i in [i0, i1, i2] {
            tan[i] += sdir;
            bit[i] += tdir;
        }
    }
    normals
        .iter()
        .zip(tan.iter().zip(&bit))
        .map(|(&n, (&t, &b))| {
            let t = (t - n * n.dot(t))
                .try_normalize()
                .unwrap_or_else(|| n.any_orthonormal_vector());
            let w = if n.cross(t).dot(b) < 0.0 { -1.0 } else { 1.0 };
            t.extend(w)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planar_quad_tangent_follows_u() {
        // A quad in the XY plane with u along +X and v along +Y: tangent +X, bitangent +Y, so
        // (N × T) · B = (Z × X) · Y = 1 > 0 and w = +1.
        let p = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let uv = [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y];
        let n = [Vec3::Z; 4];
        let t = generate(&p, &n, &uv, &[[0, 1, 2], [0, 2, 3]]);
        for v in t {
            assert!((v - Vec4::new(1.0, 0.0, 0.0, 1.0)).length() < 1e-6, "{v}");
        }
    }
}
