//! §3 and §5.3: the samples triangulated in the parametric domain and projected back to 3D —
//! per chart a Delaunay triangulation constrained by the chart's (sampled) boundary, each vertex
//! placed on the original surface through the parameterisation, with its UV and normal.
//!
//! Based on: Qu & Meyer §3 ("a Delaunay triangulation operation is performed on these samples.
//! These samples and their connectivity are re-projected back to 3D"); Alliez et al. 2002 §3.5
//! (constrained Delaunay in each patch, the patch boundaries as constraints). The triangulation is
//! `spade`'s constrained Delaunay triangulation.
//!
//! Decisions:
//! - Boundary vertices keep their original 3D point, UV and normal (every copy of a seam vertex
//!   is the same point, so both sides of a seam meet); a free sample is placed at the point of
//!   the original triangle under its UV (barycentric position, normal and vertex colour).
//! - Free samples outside the sampled boundary polygon, or within a third of a texel of one of
//!   its segments, are left out (a vertex on a constraint would split it on one side of a seam
//!   only).
//! - A triangle is kept when it lies inside the polygon: an odd number of constraint edges
//!   between it and the outside (so holes stay holes); it takes the material of the original triangle under its
//!   centroid, and its winding follows the chart's (a mirrored chart is wound the other way in
//!   UV, so its triangles are flipped to face out as the original's do).
//! - Where a shortened boundary segment would cross another one (a thin or concave chart), the
//!   caller is told which welded vertex to add, on every side of that seam, and tries again.

use glam::{Vec2, Vec3};
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

use super::charts::Charts;
use crate::error::{Error, Result};
use crate::mesh::{LoadOptions, Mesh, MeshData};
use crate::raster::{NO_TRIANGLE, TextureSpace, texture_space::barycentric_2d};

/// The remeshed surface before validation.
#[derive(Debug, Clone, Default)]
pub struct Built {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    colors: Option<Vec<Vec3>>,
    triangles: Vec<[u32; 3]>,
    material_ids: Vec<u32>,
}

/// Where a triangulation vertex comes from.
#[derive(Debug, Clone, Copy)]
enum Origin {
    /// An original (unwelded) boundary vertex.
    Boundary(u32),
    /// A free sample at this UV.
    Free(Vec2),
}

/// Finds the original triangle under a UV point of one chart.
struct Locator<'a> {
    mesh: &'a Mesh,
    ts: &'a TextureSpace,
    charts: &'a Charts,
}

impl Locator<'_> {
    /// The triangle of chart `c` under `uv` and the barycentrics there (clamped to it), from the
    /// triangles the texture pass found at and around the point's texel.
    fn locate(&self, c: u32, uv: Vec2) -> Option<(u32, Vec3)> {
        let uvs = self.mesh.uvs()?;
        let p = self.ts.texel_of(uv);
        let (x0, y0) = (p.x.floor() as isize, p.y.floor() as isize);
        let size = self.ts.size as isize;
        let mut best: Option<(f32, u32, Vec3)> = None;
        for r in 0..=3isize {
            for y in (y0 - r)..=(y0 + r) {
                for x in (x0 - r)..=(x0 + r) {
                    if x < 0 || y < 0 || x >= size || y >= size {
                        continue;
                    }
                    if r > 0 && (y - y0).abs() != r && (x - x0).abs() != r {
                        continue;
                    }
                    let t = self.ts.triangle[(y * size + x) as usize];
                    if t == NO_TRIANGLE || self.charts.of_triangle[t as usize] != c {
                        continue;
                    }
                    let tri = self.mesh.triangles()[t as usize];
                    let Some(b) = barycentric_2d(uv, tri.map(|i| uvs[i as usize])) else {
                        continue;
                    };
                    let inside = b.min_element();
                    if best.is_none_or(|(m, bt, _)| inside > m || (inside == m && t < bt)) {
                        best = Some((inside, t, b));
                    }
                }
            }
            if best.is_some_and(|(m, _, _)| m >= -1e-4) {
                break;
            }
        }
        best.map(|(_, t, b)| {
            let b = b.max(Vec3::ZERO);
            (t, b / b.element_sum().max(f32::MIN_POSITIVE))
        })
    }
}

/// Whether `p` is inside the polygon made of `segments` (even–odd).
fn inside(p: Vec2, segments: &[(Vec2, Vec2)]) -> bool {
    let mut odd = false;
    for &(a, b) in segments {
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if p.x < x {
                odd = !odd;
            }
        }
    }
    odd
}

/// Distance from `p` to segment `ab`.
fn segment_distance(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 {
        ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + ab * t)
}

/// Triangulate every chart. `keep` marks the welded boundary vertices kept; `free[c]` are chart
/// c's free samples (texel coordinates). `Err(Ok(refine))` lists welded vertices that must be
/// kept too before the boundary can be triangulated.
pub fn triangulate(
    mesh: &Mesh,
    ts: &TextureSpace,
    charts: &Charts,
    keep: &[bool],
    free: &[Vec<Vec2>],
) -> std::result::Result<Built, Result<Vec<u32>>> {
    let uvs = mesh.uvs().ok_or_else(|| {
        Err(Error::Internal(
            "qu-meyer: triangulating a mesh without UVs".into(),
        ))
    })?;
    let weld = mesh.weld();
    let locator = Locator { mesh, ts, charts };
    // The winding of each chart in UV.
    let mut winding = vec![0.0f64; charts.count];
    for (t, tri) in mesh.triangles().iter().enumerate() {
        let [a, b, c] = tri.map(|i| uvs[i as usize]);
        winding[charts.of_triangle[t] as usize] += (b - a).perp_dot(c - a) as f64;
    }
    let mut out = Built {
        colors: mesh.colors().map(|_| Vec::new()),
        ..Built::default()
    };
    let mut refine: Vec<u32> = Vec::new();
    let min_gap = ts.texel / 3.0;
    for c in 0..charts.count {
        let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> =
            ConstrainedDelaunayTriangulation::new();
        let mut origin: Vec<Option<Origin>> = Vec::new();
        let mut segments: Vec<(Vec2, Vec2)> = Vec::new();
        let mut insert =
            |cdt: &mut ConstrainedDelaunayTriangulation<Point2<f64>>, uv: Vec2, o: Origin| {
                let h = cdt
                    .insert(Point2::new(uv.x as f64, uv.y as f64))
                    .map_err(|e| Error::Internal(format!("qu-meyer: triangulation: {e:?}")))?;
                if origin.len() <= h.index() {
                    origin.resize(h.index() + 1, None);
                }
                if origin[h.index()].is_none() {
                    origin[h.index()] = Some(o);
                }
                Ok::<_, Error>(h)
            };
        for lp in &charts.loops[c] {
            let kept: Vec<usize> = (0..lp.len())
                .filter(|&k| keep[weld[lp[k] as usize] as usize])
                .collect();
            if kept.len() < 3 {
                continue;
            }
            let mut handles = Vec::with_capacity(kept.len());
            for &k in &kept {
                let v = lp[k];
                handles.push(insert(&mut cdt, uvs[v as usize], Origin::Boundary(v)).map_err(Err)?);
            }
            for j in 0..kept.len() {
                let (ka, kb) = (kept[j], kept[(j + 1) % kept.len()]);
                let (ha, hb) = (handles[j], handles[(j + 1) % kept.len()]);
                let (ua, ub) = (uvs[lp[ka] as usize], uvs[lp[kb] as usize]);
                segments.push((ua, ub));
                if ha == hb {
                    continue;
                }
                if cdt.can_add_constraint(ha, hb) {
                    cdt.add_constraint(ha, hb);
                } else {
                    // Keep the original vertex halfway along the span between the two.
                    let span = (kb + lp.len() - ka) % lp.len();
                    if span >= 2 {
                        refine.push(weld[lp[(ka + span / 2) % lp.len()] as usize]);
                    }
                }
            }
        }
        if !refine.is_empty() {
            continue;
        }
        for p in &free[c] {
            let uv = ts.uv_at(p.x, p.y);
            if !inside(uv, &segments)
                || segments
                    .iter()
                    .any(|&(a, b)| segment_distance(uv, a, b) < min_gap)
            {
                continue;
            }
            insert(&mut cdt, uv, Origin::Free(uv)).map_err(Err)?;
        }
        let parity = inside_faces(&cdt);
        let flip = winding[c] < 0.0;
        emit_faces(&cdt, &parity, &origin, flip, c as u32, &locator, &mut out).map_err(Err)?;
    }
    if !refine.is_empty() {
        refine.sort_unstable();
        refine.dedup();
        return Err(Ok(refine));
    }
    Ok(out)
}

/// Which faces of `cdt` are inside the chart: crossing a constraint edge toggles between outside
/// and inside, starting outside at the convex hull (exact, where a test of a thin sliver's
/// centroid against the polygon is not).
fn inside_faces(cdt: &ConstrainedDelaunayTriangulation<Point2<f64>>) -> Vec<Option<bool>> {
    let mut parity: Vec<Option<bool>> = vec![None; cdt.num_all_faces()];
    let mut queue = std::collections::VecDeque::new();
    for face in cdt.inner_faces() {
        for e in face.adjacent_edges() {
            if e.rev().face().is_outer() && parity[face.fix().index()].is_none() {
                parity[face.fix().index()] = Some(e.is_constraint_edge());
                queue.push_back(face.fix());
            }
        }
    }
    while let Some(f) = queue.pop_front() {
        let here = parity[f.index()].unwrap_or(false);
        for e in cdt.face(f).adjacent_edges() {
            if let Some(n) = e.rev().face().as_inner()
                && parity[n.fix().index()].is_none()
            {
                parity[n.fix().index()] = Some(here ^ e.is_constraint_edge());
                queue.push_back(n.fix());
            }
        }
    }
    parity
}

/// Append the faces inside chart `chart` to `out`, each vertex once, wound as the chart is in
/// UV (`flip`), each triangle with the material found at its centroid.
fn emit_faces(
    cdt: &ConstrainedDelaunayTriangulation<Point2<f64>>,
    parity: &[Option<bool>],
    origin: &[Option<Origin>],
    flip: bool,
    chart: u32,
    locator: &Locator<'_>,
    out: &mut Built,
) -> Result<()> {
    let mut index: Vec<u32> = vec![u32::MAX; origin.len()];
    for face in cdt.inner_faces() {
        if parity[face.fix().index()] != Some(true) {
            continue;
        }
        let vs = face.vertices();
        let pts = vs.map(|v| {
            let p = v.position();
            Vec2::new(p.x as f32, p.y as f32)
        });
        let centroid = (pts[0] + pts[1] + pts[2]) / 3.0;
        let mut tri = [0u32; 3];
        for (k, v) in vs.iter().enumerate() {
            let h = v.fix().index();
            if index[h] == u32::MAX {
                let Some(o) = origin[h] else {
                    return Err(Error::Internal(
                        "qu-meyer: a triangulation vertex without an origin".into(),
                    ));
                };
                index[h] = out.push_vertex(locator.mesh, locator, chart, o);
            }
            tri[k] = index[h];
        }
        if flip {
            tri.swap(1, 2);
        }
        let material = locator
            .locate(chart, centroid)
            .map_or(0, |(t, _)| locator.mesh.material_ids()[t as usize]);
        out.triangles.push(tri);
        out.material_ids.push(material);
    }
    Ok(())
}

impl Built {
    /// Add the vertex of `o` (of chart `c`); returns its index.
    fn push_vertex(&mut self, mesh: &Mesh, locator: &Locator<'_>, c: u32, o: Origin) -> u32 {
        let uvs = mesh.uvs().unwrap_or_default();
        let (p, n, uv, col) = match o {
            Origin::Boundary(v) => {
                let v = v as usize;
                (
                    mesh.positions()[v],
                    mesh.normals()[v],
                    uvs[v],
                    mesh.colors().map(|c| c[v]),
                )
            }
            Origin::Free(uv) => match locator.locate(c, uv) {
                Some((t, b)) => {
                    let tri = mesh.triangles()[t as usize].map(|i| i as usize);
                    let lerp = |a: &[Vec3]| a[tri[0]] * b.x + a[tri[1]] * b.y + a[tri[2]] * b.z;
                    (
                        lerp(mesh.positions()),
                        lerp(mesh.normals()).normalize_or(mesh.normals()[tri[0]]),
                        uv,
                        mesh.colors().map(lerp),
                    )
                }
                // Unreachable for a sample inside its chart; the chart's first vertex keeps
                // the mesh valid if it ever happens.
                None => (mesh.positions()[0], mesh.normals()[0], uv, None),
            },
        };
        self.positions.push(p);
        self.normals.push(n);
        self.uvs.push(uv);
        if let Some(colors) = &mut self.colors {
            colors.push(col.unwrap_or(Vec3::ONE));
        }
        (self.positions.len() - 1) as u32
    }

    /// Triangles so far.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The remeshed surface as a validated mesh with `mesh`'s materials.
    pub fn into_mesh(self, mesh: &Mesh) -> Result<Mesh> {
        if self.triangles.is_empty() {
            return Err(Error::input(
                &mesh.source().path,
                "the remesh has no triangles (every chart's boundary collapsed)",
                "ask for more vertices or a larger --map-size",
            ));
        }
        let data = MeshData {
            positions: self.positions,
            normals: Some(self.normals),
            uvs: Some(self.uvs),
            uvs1: None,
            colors: self.colors,
            triangles: self.triangles,
            material_ids: self.material_ids,
            materials: mesh.materials().to_vec(),
            lights: Vec::new(),
            source: crate::mesh::Source {
                edited: true,
                lod_chain: None,
                ..mesh.source().clone()
            },
            warnings: Vec::new(),
        };
        Mesh::new(data, &LoadOptions::default())
    }
}
