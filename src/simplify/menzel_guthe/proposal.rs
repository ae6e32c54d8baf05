//! A proposed collapse seen before it is made: where the merged vertex goes (the QEM engine's
//! placement), the attributes its wedges would get (Hoppe 1999 / Garland–Heckbert 1998
//! attribute quadrics), the fan of triangles around it, and the three test points of the
//! perception test.
//!
//! Based on: Menzel & Guthe 2010, §3.1 (collapses "sorted into a priority queue ... estimated by
//! the quadric error metric in \[Hop99\]") and §6 ("for each simplification operation three
//! vertices are checked").
//!
//! Decision: the three checked vertices are the merged vertex v̄ and the two vertices the collapse
//! removes, a and b: each is compared where it lies on the new surface (v̄ itself; a and b at their
//! nearest points of the new fan) against the original surface's nearest point. Where v̄ lies on
//! a seam it has several wedges (attribute sets): each is a test point of its own.

use glam::Vec3;
use smallvec::SmallVec;

use super::curvature::{self, Curvature};
use super::surface::{Corner, Patch};
use crate::mesh::edit::Adjacency;
use crate::mesh::surface_distance::{nearest_barycentric, point_triangle_distance2};
use crate::simplify::qem::{CollapseCost, QemCost};

/// A test point on the new surface: a fan triangle and barycentric coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Site {
    /// Index into [`Proposal::fan`].
    pub patch: usize,
    /// Barycentric coordinates in it.
    pub barycentric: Vec3,
}

/// A collapse of `a` into `b`, proposed.
#[derive(Debug, Clone)]
pub struct Proposal {
    /// The vertex removed.
    pub a: u32,
    /// The vertex kept (moved to `position`).
    pub b: u32,
    /// Where `b` goes.
    pub position: Vec3,
    /// The quadric's RMS plane distance there (model units): the queue's estimate.
    pub quadric_error: f64,
    /// The triangles around the merged vertex after the collapse.
    pub fan: Vec<Patch>,
    /// The merged vertex's neighbours after the collapse.
    pub ring: SmallVec<[Vec3; 16]>,
    /// Their vertex ids, in the same order.
    pub ring_ids: SmallVec<[u32; 16]>,
    /// The fan's radius: the farthest neighbour's distance from the merged vertex.
    pub radius: f32,
    /// Curvature of the new patch at the merged vertex (no torsion: see `test.rs`).
    pub curvature: Curvature,
    /// The test points.
    pub sites: SmallVec<[Site; 4]>,
}

/// The collapse of `a` into `b` as the engine would make it, or `None` when it is illegal.
pub fn propose(adj: &Adjacency, cost: &QemCost, a: u32, b: u32) -> Option<Proposal> {
    let (position, quadric_error) = cost.placement(adj, a, b);
    adj.can_collapse(a, b, position).ok()?;
    let map = adj.edge_wedge_map(a, b).ok()?;
    let proposed = cost.proposed_wedges(adj, a, b, position);
    let wedge_after =
        |w: u32| -> u32 { map.iter().find(|(wa, _)| *wa == w).map_or(w, |&(_, wb)| wb) };
    let values = |w: u32| {
        proposed
            .iter()
            .find(|(x, _)| *x == w)
            .map_or(adj.wedges[w as usize], |(_, v)| *v)
    };
    let mut fan = Vec::new();
    let mut corner_at_b = Vec::new();
    let mut ring: SmallVec<[Vec3; 16]> = SmallVec::new();
    let mut ring_ids: SmallVec<[u32; 16]> = SmallVec::new();
    let mut triangles: SmallVec<[u32; 16]> = SmallVec::new();
    triangles.extend_from_slice(adj.vertex_triangles(a));
    triangles.extend_from_slice(adj.vertex_triangles(b));
    triangles.sort_unstable();
    triangles.dedup();
    for &t in &triangles {
        let tri = adj.triangle(t);
        if tri.contains(&a) && tri.contains(&b) {
            continue;
        }
        let wedges = adj.corners(t);
        let mut corners = [Corner {
            position: Vec3::ZERO,
            normal: Vec3::ZERO,
            uv: glam::Vec2::ZERO,
            color: Vec3::ONE,
        }; 3];
        let mut at_b = 0;
        for k in 0..3 {
            let (v, w) = if tri[k] == a || tri[k] == b {
                at_b = k;
                (b, wedge_after(wedges[k]))
            } else {
                (tri[k], wedges[k])
            };
            let wd = values(w);
            corners[k] = Corner {
                position: if v == b {
                    position
                } else {
                    adj.positions[v as usize]
                },
                normal: wd.normal,
                uv: wd.uv,
                color: wd.color,
            };
            if v != b && !ring_ids.contains(&v) {
                ring_ids.push(v);
                ring.push(adj.positions[v as usize]);
            }
        }
        corner_at_b.push((at_b, wedge_after(wedges[at_b])));
        fan.push(Patch {
            corners,
            material: adj.material(t),
        });
    }
    if fan.is_empty() {
        return None;
    }
    let radius = ring
        .iter()
        .map(|q| q.distance(position))
        .fold(0.0f32, f32::max);
    let normal = fan
        .iter()
        .map(|p| {
            let [x, y, z] = p.positions();
            (y - x).cross(z - x)
        })
        .sum::<Vec3>()
        .normalize_or(Vec3::Z);
    let curvature = curvature::at(position, normal, &ring);
    // The merged vertex, once per wedge; then the removed vertices' nearest points.
    let mut sites: SmallVec<[Site; 4]> = SmallVec::new();
    let mut seen: SmallVec<[u32; 4]> = SmallVec::new();
    for (i, &(k, w)) in corner_at_b.iter().enumerate() {
        if !seen.contains(&w) {
            seen.push(w);
            let mut barycentric = Vec3::ZERO;
            barycentric[k] = 1.0;
            sites.push(Site {
                patch: i,
                barycentric,
            });
        }
    }
    for v in [a, b] {
        sites.push(nearest_site(&fan, adj.positions[v as usize]));
    }
    Some(Proposal {
        a,
        b,
        position,
        quadric_error,
        fan,
        ring,
        ring_ids,
        radius,
        curvature,
        sites,
    })
}

/// The point of `fan` nearest to `q` (ties to the lower triangle).
fn nearest_site(fan: &[Patch], q: Vec3) -> Site {
    let mut best = (f32::INFINITY, 0usize);
    for (i, p) in fan.iter().enumerate() {
        let d = point_triangle_distance2(q, &p.positions());
        if d < best.0 {
            best = (d, i);
        }
    }
    Site {
        patch: best.1,
        barycentric: nearest_barycentric(q, &fan[best.1].positions()),
    }
}

/// The distance from `q` to the fan.
pub fn fan_distance(fan: &[Patch], q: Vec3) -> f32 {
    fan.iter()
        .map(|p| point_triangle_distance2(q, &p.positions()))
        .fold(f32::INFINITY, f32::min)
        .sqrt()
}
