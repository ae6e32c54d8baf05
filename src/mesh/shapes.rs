//! Procedural meshes with known properties, for tests and benchmarks: an icosphere (closed,
//! convex, near-uniform triangles), a torus (closed, not convex, genus 1) and a "bumpy" sphere of
//! any size (closed, non-convex, millions of small triangles for the rasterizer benchmark).

use std::collections::HashMap;
use std::path::PathBuf;

use glam::Vec3;

use super::{Format, LoadOptions, Mesh, MeshData, Source};

fn finish(name: &str, positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Mesh {
    let n = positions.len();
    let f = triangles.len();
    let data = MeshData {
        positions,
        normals: None,
        uvs: None,
        uvs1: None,
        colors: None,
        triangles,
        material_ids: vec![],
        materials: vec![],
        lights: Vec::new(),
        source: Source {
            path: PathBuf::from(format!("<{name}>")),
            format: Format::Obj,
            file_vertices: n,
            file_faces: f,
            file_unreferenced: 0,
            edited: false,
            files: Vec::new(),
            nodes: Vec::new(),
            lod_chain: None,
        },
        warnings: vec![],
    };
    Mesh::new(data, &LoadOptions::DEFAULT).expect("procedural meshes are valid by construction")
}

/// An n×n grid of unit squares in the plane z = 0 (two triangles each), corners (0, 0) and
/// (n, n): an open mesh with a border.
pub fn grid_plane(n: u32) -> Mesh {
    let n = n.max(1);
    let positions = (0..=n)
        .flat_map(|y| (0..=n).map(move |x| Vec3::new(x as f32, y as f32, 0.0)))
        .collect();
    let id = |x: u32, y: u32| y * (n + 1) + x;
    let triangles = (0..n)
        .flat_map(|y| (0..n).map(move |x| (x, y)))
        .flat_map(|(x, y)| {
            [
                [id(x, y), id(x + 1, y), id(x + 1, y + 1)],
                [id(x, y), id(x + 1, y + 1), id(x, y + 1)],
            ]
        })
        .collect();
    finish("plane", positions, triangles)
}

/// The cube [−1, 1]³ with each face an n×n grid of squares (two triangles each), vertices shared
/// along the cube's edges, counter-clockwise seen from outside.
pub fn cube_grid(n: u32) -> Mesh {
    let n = n.max(1);
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    // Each face: outward axis, and two in-plane axes (u, v) with u × v = outward.
    let faces: [(Vec3, Vec3, Vec3); 6] = [
        (Vec3::X, Vec3::Y, Vec3::Z),
        (-Vec3::X, Vec3::Z, Vec3::Y),
        (Vec3::Y, Vec3::Z, Vec3::X),
        (-Vec3::Y, Vec3::X, Vec3::Z),
        (Vec3::Z, Vec3::X, Vec3::Y),
        (-Vec3::Z, Vec3::Y, Vec3::X),
    ];
    for (w, u, v) in faces {
        let mut id = |i: u32, j: u32| {
            let p =
                w + u * (2.0 * i as f32 / n as f32 - 1.0) + v * (2.0 * j as f32 / n as f32 - 1.0);
            let key = p.to_array().map(|c| (c * 1e6).round() as i64);
            *index.entry(key).or_insert_with(|| {
                positions.push(p);
                positions.len() as u32 - 1
            })
        };
        for j in 0..n {
            for i in 0..n {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            }
        }
    }
    finish("cube", positions, triangles)
}

/// A unit icosphere: the icosahedron with each triangle split into 4, `subdivisions` times
/// (20·4^s triangles), vertices projected to the sphere, counter-clockwise seen from outside.
pub fn icosphere(subdivisions: u32) -> Mesh {
    let (positions, triangles) = icosphere_parts(subdivisions);
    finish("icosphere", positions, triangles)
}

fn icosphere_parts(subdivisions: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut positions: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut midpoint: HashMap<(u32, u32), u32> = HashMap::new();
        let mut mid = |a: u32, b: u32, positions: &mut Vec<Vec3>| {
            *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
                positions.push(((positions[a as usize] + positions[b as usize]) * 0.5).normalize());
                positions.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(triangles.len() * 4);
        for [a, b, c] in triangles {
            let (ab, bc, ca) = (
                mid(a, b, &mut positions),
                mid(b, c, &mut positions),
                mid(c, a, &mut positions),
            );
            next.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = next;
    }
    (positions, triangles)
}

/// A torus around the Y axis with major radius 1 and minor radius `minor`, `rings` × `sides`
/// quads split into triangles (2·rings·sides triangles), counter-clockwise seen from outside.
pub fn torus(rings: u32, sides: u32, minor: f32) -> Mesh {
    let (rings, sides) = (rings.max(3), sides.max(3));
    let mut positions = Vec::with_capacity((rings * sides) as usize);
    for i in 0..rings {
        let u = i as f32 / rings as f32 * std::f32::consts::TAU;
        for j in 0..sides {
            let v = j as f32 / sides as f32 * std::f32::consts::TAU;
            let r = 1.0 + minor * v.cos();
            positions.push(Vec3::new(r * u.cos(), minor * v.sin(), r * u.sin()));
        }
    }
    let idx = |i: u32, j: u32| (i % rings) * sides + (j % sides);
    let mut triangles = Vec::with_capacity((2 * rings * sides) as usize);
    for i in 0..rings {
        for j in 0..sides {
            let (a, b, c, d) = (idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1));
            triangles.push([a, c, b]);
            triangles.push([a, d, c]);
        }
    }
    finish("torus", positions, triangles)
}

/// A closed, non-convex "bumpy" icosphere with 20·4^s triangles: radius modulated by a sum of
/// sines so that triangles overlap in depth from every view (realistic overdraw for benchmarks).
pub fn bumpy_sphere(subdivisions: u32) -> Mesh {
    let (mut positions, triangles) = icosphere_parts(subdivisions);
    for p in &mut positions {
        let bump = 0.08 * (7.0 * p.x).sin() * (9.0 * p.y).sin() * (5.0 * p.z + 1.0).sin();
        *p *= 1.0 + bump;
    }
    finish("bumpy-sphere", positions, triangles)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_are_closed_with_expected_counts() {
        // Closed 2-manifolds satisfy V − E + F = 2 − 2g with E = 3F/2.
        let s = icosphere(3);
        assert_eq!(s.triangle_count(), 20 * 64);
        assert_eq!(
            s.vertex_count() as i64 - 3 * s.triangle_count() as i64 / 2 + s.triangle_count() as i64,
            2
        );
        let t = torus(24, 12, 0.3);
        assert_eq!(t.triangle_count(), 2 * 24 * 12);
        assert_eq!(
            t.vertex_count() as i64 - 3 * t.triangle_count() as i64 / 2 + t.triangle_count() as i64,
            0
        );
    }

    #[test]
    fn icosphere_faces_point_outward() {
        let s = icosphere(1);
        for t in s.triangles() {
            let [a, b, c] = t.map(|i| s.positions()[i as usize]);
            assert!((b - a).cross(c - a).dot(a + b + c) > 0.0);
        }
    }
}
