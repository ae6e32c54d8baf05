//! §3.1: the Hausdorff test — the geometric deviation of a proposed collapse from the original
//! model (not only from the previous level, whose differences could add up), both ways, on the
//! part of the surface the collapse changes.
//!
//! Based on: Menzel & Guthe 2010, §3.1 ("the Hausdorff distance is computed to preserve the
//! silhouettes ... we additionally compute the difference to the original model") and Figure 4
//! (the deviation becomes a distance through the silhouette frequency, `distance.rs`).
//!
//! Decision: the local two-sided distance, as progressive simplifiers with error bounds track it
//! (Klein, Liebich, Straßer 1996), kept an upper bound of the true one:
//! - The original's side: every vertex of the original stays attached to the simplified vertex
//!   it collapsed into, and is kept within the limit of that vertex's triangles. A collapse
//!   replaces the triangles around the two collapsing vertices and their neighbours by the new
//!   fan, so the vertices attached to all of them are measured again, each against the fan and
//!   its own vertex's other triangles (any triangle of the mesh bounds the distance to it).
//! - The simplified side: the distance of the new fan to the original surface, through its BVH,
//!   refined until it answers the test's question, "is any point of the fan farther than the
//!   limit?". Two bounds hold for a (sub-)triangle whose centroid lies at d from the original,
//!   nearest to original triangle T: the distance to a surface changes by at most the distance
//!   moved, so every point within r of the centroid is within d + r; and the distance to T alone
//!   bounds the distance to the surface and is convex, so over the piece it is largest at a
//!   corner. A piece whose smaller bound is within the limit is accepted; otherwise it is split
//!   into four, down to 4⁴ pieces (edges 1/16 of the triangle's), where the last centroid's
//!   distance is taken as the piece's. A child whose corners lie within the limit of its
//!   parent's T is accepted without a search of its own.
//!
//! Measured on the bunny (69 451 triangles to 10 %): counting the finest pieces with their
//! bound instead of their centroid doubled the tests per collapse (the bound is loose at that
//! size); stopping one level earlier was 1.7× faster but let the 3 000-triangle bunny end 14 %
//! past a 1 % bound (the integration test).
//!
//! The first build sampled a few centroids and edge midpoints and measured only the vertices
//! attached to the collapsing pair: large, flat triangles bulged past the limit between the
//! samples, and original vertices attached to a neighbour drifted away unmeasured; on the
//! 3 000-triangle bunny at 1 % of the diagonal the LOD ended 1.5 % from the original.
//!
//! Past the limit the test has failed, and refining on would only sharpen the estimate the
//! postponed collapse returns to the queue with: the pieces already split are measured at their
//! centroids, and the largest of those (at least the limit, so the collapse comes back later)
//! is its new estimate. Without a limit (the measurement of an applied collapse) the refinement
//! is a branch and bound for the maximum: a piece is split while it could exceed the largest
//! distance found. Each closest-point search starts from the parent piece's nearest triangle.

use glam::Vec3;

use smallvec::SmallVec;

use super::proposal::{Proposal, fan_distance};
use super::surface::Original;
use crate::mesh::edit::Adjacency;
use crate::mesh::surface_distance::point_triangle_distance2;

/// For each vertex of the simplified mesh, the original vertices it stands for.
#[derive(Debug, Clone)]
pub struct Attached {
    lists: Vec<Vec<u32>>,
}

impl Attached {
    /// Each of `n` vertices stands for itself.
    pub fn new(n: usize) -> Attached {
        Attached {
            lists: (0..n as u32).map(|v| vec![v]).collect(),
        }
    }

    /// `from` was collapsed into `to`.
    pub fn merge(&mut self, from: u32, to: u32) {
        let moved = std::mem::take(&mut self.lists[from as usize]);
        self.lists[to as usize].extend(moved);
    }

    /// The original vertices `v` stands for.
    pub fn of(&self, v: u32) -> &[u32] {
        &self.lists[v as usize]
    }
}

/// Splits of a fan triangle into four, at most, before a piece's centroid's distance is taken
/// as its own.
const MAX_DEPTH: u32 = 4;

/// The two-sided local deviation (model units) of `proposal` on `adj` from the original, whose
/// welded vertex positions are `original_positions`. At most `limit`: the largest distance
/// measured, and the fan is within the limit (to the finest pieces' size). Past it: a lower
/// bound of the deviation, measured where the test failed. Without a limit: the branch and
/// bound for the largest distance.
pub fn deviation(
    proposal: &Proposal,
    adj: &Adjacency,
    attached: &Attached,
    original: &Original,
    original_positions: &[Vec3],
    limit: Option<f32>,
) -> f32 {
    let fan = &proposal.fan;
    let (a, b) = (proposal.a, proposal.b);
    let mut worst = 0.0f32;
    // The original's side.
    for v in [a, b] {
        for &o in attached.of(v) {
            worst = worst.max(fan_distance(fan, original_positions[o as usize]));
        }
    }
    for &w in &proposal.ring_ids {
        // w's triangles the collapse keeps.
        let own: SmallVec<[[Vec3; 3]; 16]> = adj
            .vertex_triangles(w)
            .iter()
            .map(|&t| adj.triangle(t))
            .filter(|t| !t.contains(&a) && !t.contains(&b))
            .map(|t| t.map(|v| adj.positions[v as usize]))
            .collect();
        for &o in attached.of(w) {
            let q = original_positions[o as usize];
            let to_fan = fan_distance(fan, q);
            if to_fan <= worst {
                continue;
            }
            let d2 = own
                .iter()
                .map(|t| point_triangle_distance2(q, t))
                .fold(to_fan * to_fan, f32::min);
            worst = worst.max(d2.sqrt());
        }
    }
    // The new surface's side: the merged vertex, then each fan triangle refined where it could
    // exceed the limit.
    let Some((first, d)) = original.nearest_from(proposal.position, original.at_vertex(proposal.b))
    else {
        return worst;
    };
    worst = worst.max(d);
    // The distance to a single original triangle bounds the distance to the surface, and is
    // convex, so over a piece it is largest at a corner.
    let corner_bound = |piece: &[Vec3; 3], t: u32| {
        let near = original.triangle(t);
        piece
            .map(|x| point_triangle_distance2(x, near))
            .into_iter()
            .fold(0.0f32, f32::max)
            .sqrt()
    };
    // The test's current question: can a piece still exceed this? Past the limit the test has
    // failed: no piece is split any more, the rest are measured at their centroids only, for
    // the postponed collapse's estimate.
    let bound = |worst: f32| match limit {
        Some(limit) if worst > limit => (worst, false),
        Some(limit) => (limit.max(worst), true),
        None => (worst, true),
    };
    // Pieces with the triangle nearest to their parent's centroid.
    let mut stack: Vec<([Vec3; 3], u32, u32)> =
        fan.iter().map(|p| (p.positions(), 0, first)).collect();
    while let Some((piece, depth, parent)) = stack.pop() {
        // Within what the parent's nearest triangle allows, a piece can change nothing, and
        // needs no search.
        if corner_bound(&piece, parent) <= bound(worst).0 {
            continue;
        }
        let [p, q, r] = piece;
        let c = (p + q + r) / 3.0;
        let Some((t, d)) = original.nearest_from(c, parent) else {
            continue;
        };
        worst = worst.max(d);
        let reach = c.distance(p).max(c.distance(q)).max(c.distance(r));
        let farthest = (d + reach).min(corner_bound(&piece, t));
        let (bound, split) = bound(worst);
        if split && depth < MAX_DEPTH && farthest > bound {
            let (pq, qr, rp) = ((p + q) * 0.5, (q + r) * 0.5, (r + p) * 0.5);
            for piece in [[p, pq, rp], [pq, q, qr], [rp, qr, r], [pq, qr, rp]] {
                stack.push((piece, depth + 1, t));
            }
        }
    }
    worst
}
