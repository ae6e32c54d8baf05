//! The two surfaces a perception test compares, as points with their shading inputs: the
//! original model (closest points through a BVH, per-vertex curvatures) and the simplified
//! surface around a proposed collapse (its fan).
//!
//! Based on: Menzel & Guthe 2010, §5 ("generate the hemispherical samples for a given vertex and
//! the closest interpolated point on the reference model"): a point's attributes — normal, UV,
//! vertex colour — are interpolated barycentrically, its albedo is base colour × vertex colour ×
//! the base-colour texture at its UV, its normal-map normal the normal texture at its UV (both
//! sampled on the finest mip level, bilinearly: a point has no footprint).
//!
//! Decision: a point's tangent frame is its (interpolated, unit) normal with, as tangent, the UV
//! tangent of its triangle where the material has a normal map (the map's content is oriented in
//! UV space), else the direction of minimal curvature (§4.3 measures the light's angle from it).

use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::curvature::{self, Curvature};
use super::field::Inputs;
use super::rotation::Frame;
use crate::mesh::Mesh;
use crate::mesh::edit::Adjacency;
use crate::mesh::surface_distance::{ClosestPoint, nearest_barycentric};
use crate::raster::MipTexture;

/// A triangle corner's attributes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corner {
    /// Position.
    pub position: Vec3,
    /// Normal (not necessarily unit).
    pub normal: Vec3,
    /// Texture coordinate.
    pub uv: Vec2,
    /// Linear RGB vertex colour (one where the mesh has none).
    pub color: Vec3,
}

/// A triangle with its corners and material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Patch {
    /// Corners.
    pub corners: [Corner; 3],
    /// Material index.
    pub material: u32,
}

impl Patch {
    /// Corner positions.
    pub fn positions(&self) -> [Vec3; 3] {
        self.corners.map(|c| c.position)
    }

    /// The UV tangent (∂p/∂u) of the triangle, zero where its UVs are degenerate.
    pub fn uv_tangent(&self) -> Vec3 {
        let [a, b, c] = self.corners;
        let (e1, e2) = (b.position - a.position, c.position - a.position);
        let (d1, d2) = (b.uv - a.uv, c.uv - a.uv);
        let det = d1.x * d2.y - d2.x * d1.y;
        if det.abs() < 1e-20 {
            return Vec3::ZERO;
        }
        (e1 * d2.y - e2 * d1.y) / det
    }
}

/// The materials' parameters and textures, shared by both surfaces (a LOD keeps its original's
/// materials).
#[derive(Debug, Clone)]
pub struct Materials {
    list: Vec<MaterialParams>,
}

#[derive(Debug, Clone)]
struct MaterialParams {
    base_color: Vec3,
    specular: Vec3,
    shininess: f32,
    base: Option<Arc<MipTexture>>,
    normal: Option<Arc<MipTexture>>,
}

impl Materials {
    /// The materials of `mesh`, with their textures' mip pyramids.
    pub fn of(mesh: &Mesh) -> Materials {
        let prepared = crate::raster::PreparedMesh::new(mesh);
        let list = mesh
            .materials()
            .iter()
            .zip(prepared.materials.iter())
            .map(|(m, p)| MaterialParams {
                base_color: m.base_color,
                specular: m.specular,
                shininess: m.shininess,
                base: p.base.as_ref().map(|s| s.mip.clone()),
                normal: p.normal.as_ref().map(|s| s.mip.clone()),
            })
            .collect();
        Materials { list }
    }

    /// Whether material `m` has a normal map.
    pub fn normal_mapped(&self, m: u32) -> bool {
        self.list
            .get(m as usize)
            .is_some_and(|p| p.normal.is_some())
    }

    /// The shading inputs of material `m` at texture coordinate `uv` with vertex colour `color`.
    pub fn inputs(&self, m: u32, uv: Vec2, color: Vec3) -> Inputs {
        let Some(p) = self.list.get(m as usize) else {
            return Inputs {
                albedo: color,
                specular: Vec3::ZERO,
                shininess: 1.0,
                normal_map: None,
            };
        };
        let mut albedo = p.base_color * color;
        if let Some(t) = &p.base {
            albedo *= t.sample(uv, Vec2::ZERO, Vec2::ZERO);
        }
        let normal_map = p
            .normal
            .as_ref()
            .map(|t| (t.sample(uv, Vec2::ZERO, Vec2::ZERO) * 2.0 - 1.0).normalize_or(Vec3::Z));
        Inputs {
            albedo,
            specular: p.specular,
            shininess: p.shininess,
            normal_map,
        }
    }
}

/// A point on a surface with what a perception test needs of it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// Position.
    pub position: Vec3,
    /// Tangent frame (normal: the interpolated shading normal).
    pub frame: Frame,
    /// Shading inputs.
    pub inputs: Inputs,
    /// Curvature of the surface there.
    pub curvature: Curvature,
}

/// The point of `patch` at barycentric coordinates `b`, with curvature `curvature`.
pub fn point(patch: &Patch, b: Vec3, curvature: Curvature, materials: &Materials) -> Point {
    let c = &patch.corners;
    let lerp3 = |f: &dyn Fn(&Corner) -> Vec3| f(&c[0]) * b.x + f(&c[1]) * b.y + f(&c[2]) * b.z;
    let position = lerp3(&|k| k.position);
    let normal = lerp3(&|k| k.normal).normalize_or_zero();
    let normal = if normal == Vec3::ZERO {
        let [p0, p1, p2] = patch.positions();
        (p1 - p0).cross(p2 - p0).normalize_or(Vec3::Z)
    } else {
        normal
    };
    let uv = c[0].uv * b.x + c[1].uv * b.y + c[2].uv * b.z;
    let color = lerp3(&|k| k.color);
    let inputs = materials.inputs(patch.material, uv, color);
    let tangent = if materials.normal_mapped(patch.material) {
        patch.uv_tangent()
    } else {
        curvature.dir_min
    };
    Point {
        position,
        frame: Frame::new(normal, tangent),
        inputs,
        curvature,
    }
}

/// The original model: its triangles as patches, a BVH for closest points, and per welded vertex
/// its curvature.
#[derive(Debug)]
pub struct Original {
    patches: Vec<Patch>,
    /// Welded vertex of each corner of each triangle.
    welded: Vec<[u32; 3]>,
    closest: ClosestPoint,
    curvature: Vec<Curvature>,
    /// A triangle at each welded vertex: where closest-point searches near it start.
    at_vertex: Vec<u32>,
}

impl Original {
    /// Prepare `mesh` (whose structure `adj` is, built with [`Adjacency::new`], so that its vertex
    /// ids are the mesh's welded ids).
    pub fn new(mesh: &Mesh, adj: &Adjacency) -> Original {
        let corner = |v: u32| {
            let v = v as usize;
            Corner {
                position: mesh.positions()[v],
                normal: mesh.normals()[v],
                uv: mesh.uvs().map_or(Vec2::ZERO, |u| u[v]),
                color: mesh.colors().map_or(Vec3::ONE, |c| c[v]),
            }
        };
        let patches = mesh
            .triangles()
            .iter()
            .zip(mesh.material_ids())
            .map(|(t, &m)| Patch {
                corners: t.map(corner),
                material: m,
            })
            .collect();
        let weld = mesh.weld();
        let welded: Vec<[u32; 3]> = mesh
            .triangles()
            .iter()
            .map(|t| t.map(|v| weld[v as usize]))
            .collect();
        let mut at_vertex = vec![0u32; adj.positions.len()];
        for (t, w) in welded.iter().enumerate().rev() {
            for &v in w {
                at_vertex[v as usize] = t as u32;
            }
        }
        Original {
            patches,
            welded,
            at_vertex,
            closest: ClosestPoint::new(mesh),
            curvature: vertex_curvatures(adj),
        }
    }

    /// The closest point of the original surface to `q`: the patch, barycentric coordinates and
    /// the distance.
    pub fn closest(&self, q: Vec3) -> Option<(u32, Vec3, f32)> {
        let (t, d) = self.closest.closest(q)?;
        let b = nearest_barycentric(q, self.closest.triangle(t));
        Some((t, b, d))
    }

    /// [`Original::closest`] for a point near the original's welded vertex `v` (the search
    /// starts at one of its triangles; of equally near triangles, either may be returned).
    pub fn closest_near(&self, q: Vec3, v: u32) -> Option<(u32, Vec3, f32)> {
        let (t, d) = self.closest.closest_from(q, self.at_vertex(v))?;
        let b = nearest_barycentric(q, self.closest.triangle(t));
        Some((t, b, d))
    }

    /// The distance from `q` to the original surface.
    pub fn distance(&self, q: Vec3) -> f32 {
        self.closest.distance(q)
    }

    /// The nearest triangle to `q` and the distance to it, the search starting from triangle
    /// `hint` (the answer for a nearby point is a good start).
    pub fn nearest_from(&self, q: Vec3, hint: u32) -> Option<(u32, f32)> {
        self.closest.closest_from(q, hint)
    }

    /// A triangle of the original at its welded vertex `v`.
    pub fn at_vertex(&self, v: u32) -> u32 {
        self.at_vertex.get(v as usize).copied().unwrap_or(0)
    }

    /// The corners of the original's triangle `t`.
    pub fn triangle(&self, t: u32) -> &[Vec3; 3] {
        self.closest.triangle(t)
    }

    /// The point of triangle `t` at barycentric `b`, with the corners' curvatures interpolated
    /// (magnitudes and torsion linearly; the direction of the nearest corner).
    pub fn point(&self, t: u32, b: Vec3, materials: &Materials) -> Point {
        let w = self.welded[t as usize];
        let c = w.map(|v| self.curvature[v as usize]);
        let nearest = if b.x >= b.y && b.x >= b.z {
            0
        } else if b.y >= b.z {
            1
        } else {
            2
        };
        let curvature = Curvature {
            k_min: c[0].k_min * b.x + c[1].k_min * b.y + c[2].k_min * b.z,
            k_max: c[0].k_max * b.x + c[1].k_max * b.y + c[2].k_max * b.z,
            dir_min: c[nearest].dir_min,
            torsion: c[0].torsion * b.x + c[1].torsion * b.y + c[2].torsion * b.z,
        };
        point(&self.patches[t as usize], b, curvature, materials)
    }

    /// A welded vertex's curvature.
    pub fn vertex_curvature(&self, v: u32) -> Curvature {
        self.curvature[v as usize]
    }
}

/// The area-weighted face normal at vertex `v` of `adj`.
pub fn face_normal(adj: &Adjacency, v: u32) -> Vec3 {
    let mut n = Vec3::ZERO;
    for &t in adj.vertex_triangles(v) {
        let [a, b, c] = adj.triangle(t).map(|i| adj.positions[i as usize]);
        n += (b - a).cross(c - a);
    }
    n.normalize_or(Vec3::Z)
}

/// Curvature and torsion of every vertex of `adj`.
pub fn vertex_curvatures(adj: &Adjacency) -> Vec<Curvature> {
    use rayon::prelude::*;
    let n = adj.positions.len() as u32;
    let normals: Vec<Vec3> = (0..n)
        .into_par_iter()
        .map(|v| face_normal(adj, v))
        .collect();
    let mut c: Vec<Curvature> = (0..n)
        .into_par_iter()
        .map(|v| {
            let ring: Vec<Vec3> = adj
                .neighbours(v)
                .iter()
                .map(|&q| adj.positions[q as usize])
                .collect();
            curvature::at(adj.positions[v as usize], normals[v as usize], &ring)
        })
        .collect();
    let torsion: Vec<f32> = (0..n)
        .into_par_iter()
        .map(|v| {
            let ring: Vec<(Vec3, Curvature)> = adj
                .neighbours(v)
                .iter()
                .map(|&q| (adj.positions[q as usize], c[q as usize]))
                .collect();
            curvature::torsion(
                adj.positions[v as usize],
                normals[v as usize],
                &c[v as usize],
                &ring,
            )
        })
        .collect();
    for (ci, t) in c.iter_mut().zip(torsion) {
        ci.torsion = t;
    }
    c
}
