//! §3.1: the Hausdorff test — the geometric deviation of a proposed collapse from the original
//! model (not only from the previous level, whose differences could add up), both ways, on the
//! part of the surface the collapse changes.
//!
//! Based on: Menzel & Guthe 2010, §3.1 ("the Hausdorff distance is computed to preserve the
//! silhouettes ... we additionally compute the difference to the original model") and Figure 4
//! (the deviation becomes a distance through the silhouette frequency, `distance.rs`).
//!
//! Decision: the local two-sided distance, as progressive simplifiers with error bounds track it
//! (Klein, Liebich, Straßer 1996): every vertex of the original stays attached to the simplified
//! vertex it collapsed into; the original's side is the distance of the vertices attached to the
//! two collapsing vertices to the new fan, and the simplified side the distance of samples of
//! what the collapse moved (the merged vertex, the midpoints of its edges, the fan's centroids)
//! to the original surface, through its BVH. The larger of the two is the deviation.

use glam::Vec3;

use super::proposal::{Proposal, fan_distance};
use super::surface::Original;

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

/// The two-sided local deviation (model units) of `proposal` from the original, whose welded
/// vertex positions are `original_positions`.
pub fn deviation(
    proposal: &Proposal,
    attached: &Attached,
    original: &Original,
    original_positions: &[Vec3],
) -> f32 {
    let fan = &proposal.fan;
    let mut worst = 0.0f32;
    for v in [proposal.a, proposal.b] {
        for &o in attached.of(v) {
            worst = worst.max(fan_distance(fan, original_positions[o as usize]));
        }
    }
    // The new surface's side: what moved — the merged vertex, the midpoints of its edges and the
    // fan's centroids (the ring's vertices and the edges between them are not changed by the
    // collapse; they were measured when they were made).
    let v = proposal.position;
    worst = worst.max(original.distance(v));
    for patch in fan {
        let [p, q, r] = patch.positions();
        let (x, y) = if p == v {
            (q, r)
        } else if q == v {
            (r, p)
        } else {
            (p, q)
        };
        for s in [(v + x) * 0.5, (v + x + y) / 3.0] {
            worst = worst.max(original.distance(s));
        }
    }
    worst
}
