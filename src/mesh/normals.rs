//! Vertex normals: normalising the file's, or computing angle-weighted ones with crease splitting.
//!
//! Based on: Grit Thürmer, Charles A. Wüthrich. Computing Vertex Normals from Polygonal Facets.
//! Journal of Graphics Tools 1998 — each incident face contributes its unit normal weighted by the
//! corner angle at the vertex, which makes the result independent of how a surface is triangulated.
//!
//! Faces are gathered around *welded* positions, so UV seams do not show up as shading seams.
//! With a crease angle below 180°, a corner only averages faces whose normals are within the
//! crease angle of its own face; corners of one vertex that end with different normals get their
//! own vertex copies (attributes duplicated). Sums run in triangle order: deterministic.
//! Where every incident face is degenerate the normal falls back to +Z (documented, not fatal).

use glam::Vec3;

use super::MeshData;
use super::weld;

/// Unit normal of each triangle (zero for degenerate ones) and its corner angles.
fn face_frames(positions: &[Vec3], triangles: &[[u32; 3]]) -> (Vec<Vec3>, Vec<[f32; 3]>) {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            let n = (b - a).cross(c - a).normalize_or_zero();
            let angle = |p: Vec3, q: Vec3, r: Vec3| {
                let (u, v) = ((q - p).normalize_or_zero(), (r - p).normalize_or_zero());
                u.dot(v).clamp(-1.0, 1.0).acos()
            };
            (n, [angle(a, b, c), angle(b, c, a), angle(c, a, b)])
        })
        .unzip()
}

/// Compressed lists of the (triangle, corner) pairs around each welded position.
struct Incidence {
    start: Vec<u32>,
    corners: Vec<(u32, u8)>,
}

fn incidence(weld: &[u32], welded: usize, triangles: &[[u32; 3]]) -> Incidence {
    let mut start = vec![0u32; welded + 1];
    for t in triangles {
        for &v in t {
            start[weld[v as usize] as usize + 1] += 1;
        }
    }
    for i in 0..welded {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut corners = vec![(0u32, 0u8); triangles.len() * 3];
    for (ti, t) in triangles.iter().enumerate() {
        for (k, &v) in t.iter().enumerate() {
            let w = weld[v as usize] as usize;
            corners[fill[w] as usize] = (ti as u32, k as u8);
            fill[w] += 1;
        }
    }
    Incidence { start, corners }
}

/// Smooth angle-weighted normals (no creases), one per vertex; vertices sharing a position get
/// the same normal.
fn smooth(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let n = Neighbourhoods::new(positions, triangles);
    let (weld, welded, face_n, angles) = (&n.weld, n.welded, &n.face_n, &n.angles);
    let around = |w: usize| n.around(w);
    // One normal per welded position.
    let per_welded: Vec<Vec3> = (0..welded)
        .map(|w| {
            let sum: Vec3 = around(w)
                .iter()
                .map(|&(t, k)| face_n[t as usize] * angles[t as usize][k as usize])
                .sum();
            sum.try_normalize().unwrap_or(Vec3::Z)
        })
        .collect();
    weld.iter().map(|&w| per_welded[w as usize]).collect()
}

/// Welded positions, face frames and the corners around each welded position.
struct Neighbourhoods {
    weld: Vec<u32>,
    welded: usize,
    face_n: Vec<Vec3>,
    angles: Vec<[f32; 3]>,
    inc: Incidence,
}

impl Neighbourhoods {
    fn new(positions: &[Vec3], triangles: &[[u32; 3]]) -> Neighbourhoods {
        let (weld, welded) = weld::by_position(positions);
        let (face_n, angles) = face_frames(positions, triangles);
        let inc = incidence(&weld, welded, triangles);
        Neighbourhoods {
            weld,
            welded,
            face_n,
            angles,
            inc,
        }
    }

    /// The (triangle, corner) pairs around welded position `w`.
    fn around(&self, w: usize) -> &[(u32, u8)] {
        &self.inc.corners[self.inc.start[w] as usize..self.inc.start[w + 1] as usize]
    }
}

/// Compute normals for a mesh without them, splitting vertices along creases.
/// Returns one unit normal per (possibly new) vertex; `data` gains the split vertices.
pub(crate) fn generate(data: &mut MeshData, crease_angle_deg: f32) -> Vec<Vec3> {
    if crease_angle_deg >= 180.0 {
        return smooth(&data.positions, &data.triangles);
    }
    let n = Neighbourhoods::new(&data.positions, &data.triangles);
    let (weld, face_n, angles) = (&n.weld, &n.face_n, &n.angles);
    let around = |w: usize| n.around(w);

    // Creased: a normal per corner, then one vertex per distinct (vertex, normal) pair.
    let cos_crease = crease_angle_deg.to_radians().cos();
    let mut corner_normal = vec![Vec3::Z; data.triangles.len() * 3];
    for (ti, tri) in data.triangles.iter().enumerate() {
        for k in 0..3 {
            let w = weld[tri[k] as usize] as usize;
            let own = face_n[ti];
            let sum: Vec3 = around(w)
                .iter()
                .filter(|&&(t, _)| own.dot(face_n[t as usize]) >= cos_crease)
                .map(|&(t, kk)| face_n[t as usize] * angles[t as usize][kk as usize])
                .sum();
            corner_normal[ti * 3 + k] = sum
                .try_normalize()
                .unwrap_or(own.try_normalize().unwrap_or(Vec3::Z));
        }
    }
    split_by_corner_normal(data, &corner_normal)
}

/// Give each vertex one copy per distinct corner normal; returns the normals of all vertices.
fn split_by_corner_normal(data: &mut MeshData, corner_normal: &[Vec3]) -> Vec<Vec3> {
    let n = data.positions.len();
    let mut normals: Vec<Option<Vec3>> = vec![None; n];
    // Copies made so far per original vertex, searched linearly (few per vertex).
    let mut copies: Vec<Vec<(Vec3, u32)>> = vec![Vec::new(); n];
    for ti in 0..data.triangles.len() {
        for k in 0..3 {
            let v = data.triangles[ti][k] as usize;
            let nrm = corner_normal[ti * 3 + k];
            let target = match normals[v] {
                None => {
                    normals[v] = Some(nrm);
                    v as u32
                }
                Some(existing) if existing == nrm => v as u32,
                Some(_) => match copies[v].iter().find(|(cn, _)| *cn == nrm) {
                    Some(&(_, idx)) => idx,
                    None => {
                        let idx = data.positions.len() as u32;
                        data.positions.push(data.positions[v]);
                        if let Some(u) = data.uvs.as_mut() {
                            u.push(u[v]);
                        }
                        if let Some(c) = data.colors.as_mut() {
                            c.push(c[v]);
                        }
                        normals.push(Some(nrm));
                        copies[v].push((nrm, idx));
                        idx
                    }
                },
            };
            data.triangles[ti][k] = target;
        }
    }
    normals.into_iter().map(|n| n.unwrap_or(Vec3::Z)).collect()
}

/// Normalise normals given by the file; zero-length ones are replaced by computed smooth normals.
pub(crate) fn normalize_given(
    given: &[Vec3],
    positions: &[Vec3],
    triangles: &[[u32; 3]],
) -> Vec<Vec3> {
    // Unit normals are kept bit for bit, so that rebuilding a mesh from its own data
    // (`Mesh::to_data`) reproduces it exactly.
    let unit = |n: &Vec3| (n.length_squared() - 1.0).abs() <= 4.0 * f32::EPSILON;
    let mut out: Vec<Option<Vec3>> = given
        .iter()
        .map(|n| if unit(n) { Some(*n) } else { n.try_normalize() })
        .collect();
    if out.iter().any(Option::is_none) {
        let computed = smooth(positions, triangles);
        for (o, c) in out.iter_mut().zip(computed) {
            o.get_or_insert(c);
        }
    }
    out.into_iter().map(|n| n.unwrap_or(Vec3::Z)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{Format, Source};

    fn cube_corner() -> MeshData {
        // Three faces of a cube meeting at the origin, each a single right triangle, sharing the
        // origin vertex 0. Outward normals are -X, -Y, -Z.
        MeshData {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
            normals: None,
            uvs: None,
            uvs1: None,
            colors: None,
            triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2]],
            material_ids: vec![],
            materials: vec![],
            lights: Vec::new(),
            source: Source {
                path: Default::default(),
                format: Format::Obj,
                file_vertices: 4,
                file_faces: 3,
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
    fn smooth_normal_at_cube_corner_is_the_diagonal() {
        // Each face has a 90° corner at the origin, so the weights are equal and the average of
        // -X, -Y, -Z normalises to -(1,1,1)/sqrt(3).
        let mut m = cube_corner();
        let n = generate(&mut m, 180.0);
        assert!((n[0] + Vec3::ONE.normalize()).length() < 1e-6, "{:?}", n[0]);
        assert_eq!(m.positions.len(), 4);
    }

    #[test]
    fn crease_splits_the_corner_into_three_flat_normals() {
        // The faces meet at 90°, above a 60° crease, so the origin gets one copy per face (3) and
        // X, Y and Z, each shared by two faces, get two copies: 3 + 3·2 = 9 vertices.
        let mut m = cube_corner();
        let n = generate(&mut m, 60.0);
        assert_eq!(m.positions.len(), 9);
        let origin_normals: Vec<Vec3> = m.triangles.iter().map(|t| n[t[0] as usize]).collect();
        assert_eq!(origin_normals, vec![-Vec3::Z, -Vec3::Y, -Vec3::X]);
    }
}
