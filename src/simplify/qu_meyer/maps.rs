//! §5.1: the map-based representation — per texel of the parametric domain, the chart, the area
//! distortion (3D area over UV area) and the surface's curvature, beside the texture-space pass's
//! 3D points and signal (`raster::texture_space`).
//!
//! Based on: Qu & Meyer §5.1 ("an area distortion map, a curvature map, and a regular sampling
//! of the 2D parametric domain, as was done in [Alliez et al. 2002]"); Alliez, Meyer, Desbrun.
//! Interactive Geometry Remeshing. SIGGRAPH 2002, §3.2 (the maps, interpolated per triangle).
//!
//! Decisions: curvature per welded vertex from the shape operator fitted to its one-ring
//! (`menzel_guthe::curvature`, Taubin's normal curvatures), as the magnitude √(κ₁² + κ₂²), then
//! interpolated across each triangle; the area distortion is per triangle (constant on it, as
//! the parameterisation is linear there).

use glam::Vec3;
use rayon::prelude::*;

use super::charts::Charts;
use crate::mesh::Mesh;
use crate::raster::NO_TRIANGLE;
use crate::raster::TextureSpace;
use crate::simplify::menzel_guthe::curvature;

/// The per-texel maps.
#[derive(Debug, Clone)]
pub struct Maps {
    /// Chart per texel (`u32::MAX` where uncovered).
    pub chart: Vec<u32>,
    /// 3D area per UV area of the texel's triangle (0 where uncovered).
    pub distortion: Vec<f32>,
    /// Curvature magnitude, 1/model unit (0 where uncovered).
    pub curvature: Vec<f32>,
    /// 3D area one texel stands for, model units² (0 where uncovered).
    pub area: Vec<f32>,
}

/// Curvature magnitude per welded vertex.
pub fn vertex_curvature(mesh: &Mesh) -> Vec<f32> {
    let weld = mesh.weld();
    let wn = mesh.welded_vertex_count();
    let mut position = vec![Vec3::ZERO; wn];
    let mut normal = vec![Vec3::ZERO; wn];
    let mut ring: Vec<Vec<u32>> = vec![Vec::new(); wn];
    for (v, &w) in weld.iter().enumerate() {
        position[w as usize] = mesh.positions()[v];
        normal[w as usize] += mesh.normals()[v];
    }
    for t in mesh.triangles() {
        let w = t.map(|v| weld[v as usize]);
        for k in 0..3 {
            for j in 1..3 {
                ring[w[k] as usize].push(w[(k + j) % 3]);
            }
        }
    }
    ring.par_iter_mut()
        .enumerate()
        .map(|(w, r)| {
            r.sort_unstable();
            r.dedup();
            r.retain(|&q| q as usize != w);
            if r.len() < 3 {
                return 0.0;
            }
            let pts: Vec<Vec3> = r.iter().map(|&q| position[q as usize]).collect();
            let c = curvature::at(position[w], normal[w].normalize_or(Vec3::Z), &pts);
            let k = (c.k_min * c.k_min + c.k_max * c.k_max).sqrt();
            if k.is_finite() { k } else { 0.0 }
        })
        .collect()
}

impl Maps {
    /// The maps of `mesh` over its texture-space pass `ts`.
    pub fn new(mesh: &Mesh, ts: &TextureSpace, charts: &Charts) -> Maps {
        let uvs = mesh.uvs().unwrap_or_default();
        let p = mesh.positions();
        let ratio: Vec<f32> = mesh
            .triangles()
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| i as usize);
                let a3 = (p[b] - p[a]).cross(p[c] - p[a]).length();
                let a2 = (uvs[b] - uvs[a]).perp_dot(uvs[c] - uvs[a]).abs();
                if a2 > 0.0 { a3 / a2 } else { 0.0 }
            })
            .collect();
        let kv = vertex_curvature(mesh);
        let weld = mesh.weld();
        let texel_area = ts.texel * ts.texel;
        let n = ts.size * ts.size;
        let (mut chart, mut distortion, mut curv, mut area) = (
            vec![u32::MAX; n],
            vec![0.0f32; n],
            vec![0.0f32; n],
            vec![0.0f32; n],
        );
        chart
            .par_iter_mut()
            .zip(distortion.par_iter_mut())
            .zip(curv.par_iter_mut())
            .zip(area.par_iter_mut())
            .enumerate()
            .for_each(|(i, (((c, d), k), a))| {
                let t = ts.triangle[i];
                if t == NO_TRIANGLE {
                    return;
                }
                let b = ts.barycentric[i];
                let w = mesh.triangles()[t as usize].map(|v| kv[weld[v as usize] as usize]);
                *c = charts.of_triangle[t as usize];
                *d = ratio[t as usize];
                *k = w[0] * b.x + w[1] * b.y + w[2] * b.z;
                *a = ratio[t as usize] * texel_area;
            });
        Maps {
            chart,
            distortion,
            curvature: curv,
            area,
        }
    }
}
