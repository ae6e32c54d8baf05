//! Edge-collapse simplification with a pluggable cost, and its first cost: Garland & Heckbert 1997
//! quadric error metrics ("Surface Simplification Using Quadric Error Metrics").
//!
//! - Quadrics: per triangle the plane quadric K_p = p pᵀ weighted by the triangle's area (§5 of
//!   the paper's area weighting); per border edge a constraint plane through the edge,
//!   perpendicular to its triangle, weighted by `BORDER_WEIGHT` × edge length² (§4's "preserving
//!   boundaries"); the same for UV/normal seam edges with `SEAM_WEIGHT`, so seams are kept in
//!   place as well as never torn (the adjacency's wedge rule does the latter).
//! - Placement: the optimum v̄ = −A⁻¹b when A is well conditioned (|det| above 1e-9 of the scale),
//!   else the best of the two endpoints and the midpoint (§4 fallback).
//! - Queue: a radix heap over the costs' f32 bits (`queue.rs`) of (cost, edge) with lazy
//!   invalidation by per-vertex version stamps (stale entries are skipped when they pop, or
//!   dropped when the queue spreads their bucket); ties are broken by a hash of the vertex ids
//!   (equal-cost collapses spread over a flat region instead of growing one fan), so the
//!   collapse sequence is deterministic. A few entries are popped ahead of their turn so their vertices'
//!   data is fetched while the collapses before them are made (each collapse starts with cache
//!   misses: the cheapest edge can be anywhere on the mesh). The adjacency numbers vertices
//!   along a Morton curve ([`Adjacency::new_spatial`]), so an edge's neighbours sit close
//!   together in every per-vertex and per-wedge array.
//! - The work per collapse is what the engine's speed is: the edges around the kept vertex are
//!   costed again (a 3×3 solve for the place and a Schur complement for the attributes, about 9
//!   edges), the link condition and the fold test read the two fans once (the adjacency marks
//!   vertices instead of sorting neighbour lists), and the collapse edits only the lists it must.
//! - The record of every accepted collapse (a progressive mesh, Hoppe 1996) lets any LOD of a
//!   chain be extracted by replaying a prefix; the perceptual simplifiers plug their own cost in
//!   through [`CollapseCost`].
//! - The reported error of a collapse is √(Q(v̄)/w), the area-weighted RMS distance of v̄ to the
//!   planes its quadric holds (model units). Error targets are relative to the bounding-box
//!   diagonal.
//! - Non-manifold parts (edges with more than two triangles, common in scans) are simplified too
//!   ([`progressive`] allows non-manifold collapses; see `mesh/edit/`): Garland and
//!   Heckbert's vertex-pair contraction needs no manifold, and with them fixed the Stanford dragon
//!   could not go below 5 %.
//!
//! Attributes: with [`QemCost::with_attributes`] (what `simplify` and `eval` use) every wedge also
//! carries a Garland–Heckbert 1998 generalized quadric over (position, normal, UV, colour)
//! (`attributes.rs`); it adds to the cost, and the surviving wedges get the attribute values that
//! minimise it. Without it ([`QemCost::new`]) a surviving corner keeps its partner wedge's values.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::attributes::AttributeQuadrics;
use super::queue::{Keyed, Lookahead};
use crate::error::Result;
use crate::mesh::Mesh;
use crate::mesh::edit::{Adjacency, Local, VertexClass, Wedge};

/// Weight of border constraint planes (× edge length²).
pub const BORDER_WEIGHT: f64 = 1000.0;
/// Weight of seam constraint planes (× edge length²).
pub const SEAM_WEIGHT: f64 = 100.0;

/// A symmetric quadric Q(v) = vᵀAv + 2bᵀv + c, with the total weight of its planes.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Quadric {
    a: [f64; 6],
    b: [f64; 3],
    c: f64,
    w: f64,
}

impl Quadric {
    /// The quadric of the plane n·x + d = 0 (n unit length), with weight `w`.
    pub fn plane(n: DVec3, d: f64, w: f64) -> Quadric {
        Quadric {
            a: [
                w * n.x * n.x,
                w * n.x * n.y,
                w * n.x * n.z,
                w * n.y * n.y,
                w * n.y * n.z,
                w * n.z * n.z,
            ],
            b: [w * d * n.x, w * d * n.y, w * d * n.z],
            c: w * d * d,
            w,
        }
    }

    /// Sum of two quadrics.
    #[inline]
    pub fn add(&self, o: &Quadric) -> Quadric {
        let mut r = *self;
        for i in 0..6 {
            r.a[i] += o.a[i];
        }
        for i in 0..3 {
            r.b[i] += o.b[i];
        }
        r.c += o.c;
        r.w += o.w;
        r
    }

    /// Q(v), the weighted sum of squared plane distances.
    #[inline]
    pub fn eval(&self, v: DVec3) -> f64 {
        let a = &self.a;
        let q = a[0] * v.x * v.x
            + 2.0 * a[1] * v.x * v.y
            + 2.0 * a[2] * v.x * v.z
            + a[3] * v.y * v.y
            + 2.0 * a[4] * v.y * v.z
            + a[5] * v.z * v.z
            + 2.0 * (self.b[0] * v.x + self.b[1] * v.y + self.b[2] * v.z)
            + self.c;
        q.max(0.0)
    }

    /// The minimiser −A⁻¹b, if A is well conditioned (|det A| above 1e-9 of trace³).
    #[inline]
    pub fn optimum(&self) -> Option<DVec3> {
        // A is symmetric: six cofactors give the determinant and A⁻¹ = C/det.
        let [a0, a1, a2, a3, a4, a5] = self.a;
        let c00 = a3 * a5 - a4 * a4;
        let c01 = a2 * a4 - a1 * a5;
        let c02 = a1 * a4 - a2 * a3;
        let c11 = a0 * a5 - a2 * a2;
        let c12 = a1 * a2 - a0 * a4;
        let c22 = a0 * a3 - a1 * a1;
        let det = a0 * c00 + a1 * c01 + a2 * c02;
        let trace = a0 + a3 + a5;
        let scale = (trace * trace * trace).max(1e-300);
        if det.abs() <= 1e-9 * scale {
            return None;
        }
        let [b0, b1, b2] = self.b;
        let k = -1.0 / det;
        let x = DVec3::new(
            k * (c00 * b0 + c01 * b1 + c02 * b2),
            k * (c01 * b0 + c11 * b1 + c12 * b2),
            k * (c02 * b0 + c12 * b1 + c22 * b2),
        );
        x.is_finite().then_some(x)
    }

    /// √(Q(v)/w): RMS distance to the quadric's planes.
    pub fn rms(&self, v: DVec3) -> f64 {
        if self.w > 0.0 {
            (self.eval(v) / self.w).sqrt()
        } else {
            0.0
        }
    }
}

/// A collapse cost: the engine asks it for the cost and placement of collapsing `a` into `b`,
/// and tells it about accepted collapses.
pub trait CollapseCost: Sync {
    /// Cost (lower collapses first), the new position, and the error to record (model units).
    fn evaluate(&self, adj: &Adjacency, a: u32, b: u32) -> (f64, Vec3, f64);
    /// The cost part of [`CollapseCost::evaluate`] alone (what the queue needs); a cost whose
    /// position or error take extra work overrides it.
    fn cost(&self, adj: &Adjacency, a: u32, b: u32) -> f64 {
        self.evaluate(adj, a, b).0
    }
    /// Vertex `v` is about to be evaluated: ask for its data's cache lines, so that the misses of
    /// a collapse's whole ring of re-evaluated edges overlap. A hint only.
    fn prefetch(&self, _adj: &Adjacency, _v: u32) {}
    /// The new position and the error of collapsing `a` into `b` (what [`CollapseCost::evaluate`]
    /// returns besides the cost). The engine asks for this when it applies a queued collapse;
    /// a cost whose placement is cheaper than its full cost overrides it.
    fn placement(&self, adj: &Adjacency, a: u32, b: u32) -> (Vec3, f64) {
        let (_, p, err) = self.evaluate(adj, a, b);
        (p, err)
    }
    /// `a` was collapsed into `b` (already applied to `adj`; `map` pairs each wedge of `a` with
    /// the wedge of `b` it merged into). The cost may set new wedge attributes in `adj`; it
    /// returns them so the progressive record can replay them.
    fn collapsed(&mut self, adj: &mut Adjacency, a: u32, b: u32, map: &[(u32, u32)])
    -> WedgeValues;
}

/// New attribute values of wedges (most collapses change one: no allocation then).
pub type WedgeValues = smallvec::SmallVec<[(u32, Wedge); 1]>;

/// Garland–Heckbert quadrics: geometric (1997) for placement, and per-wedge attribute quadrics
/// (1998, `attributes.rs`) for the attribute values and their share of the cost.
#[derive(Debug, Clone)]
pub struct QemCost {
    quadrics: Vec<Quadric>,
    attributes: Option<AttributeQuadrics>,
}

impl QemCost {
    /// Quadrics of every vertex of `adj`.
    pub fn new(adj: &Adjacency) -> QemCost {
        let mut q = vec![Quadric::default(); adj.positions.len()];
        let pos = |v: u32| adj.positions[v as usize].as_dvec3();
        for t in adj.live_triangles() {
            let [a, b, c] = adj.triangle(t);
            let n = (pos(b) - pos(a)).cross(pos(c) - pos(a));
            let area = 0.5 * n.length();
            if area > 0.0 {
                let n = n.normalize();
                let k = Quadric::plane(n, -n.dot(pos(a)), area);
                for v in [a, b, c] {
                    q[v as usize] = q[v as usize].add(&k);
                }
            }
        }
        // Border and seam edges join two vertices of those classes (or non-manifold ones), so
        // only their edges are walked (in edge order, as every other walk).
        let special = |v: u32| adj.class(v) != VertexClass::Interior;
        adj.for_each_edge_from(special, |x, y, ts| {
            let weight = match ts.len() {
                1 => BORDER_WEIGHT,
                2 if adj.is_seam(x, y, ts) => SEAM_WEIGHT,
                _ => return,
            };
            let [a, b, c] = adj.triangle(ts[0]);
            let face = (pos(b) - pos(a)).cross(pos(c) - pos(a));
            let e = pos(y) - pos(x);
            let n = e.cross(face);
            if n.length_squared() <= 0.0 {
                return;
            }
            let n = n.normalize();
            let k = Quadric::plane(n, -n.dot(pos(x)), weight * e.length_squared());
            q[x as usize] = q[x as usize].add(&k);
            q[y as usize] = q[y as usize].add(&k);
        });
        QemCost {
            quadrics: q,
            attributes: None,
        }
    }

    /// The same with attribute quadrics (normals, and UVs and colours where the mesh has them).
    pub fn with_attributes(adj: &Adjacency, diagonal: f64) -> QemCost {
        let mut c = QemCost::new(adj);
        c.attributes = Some(AttributeQuadrics::new(
            adj,
            adj.has_uvs(),
            adj.has_colors(),
            diagonal,
        ));
        c
    }

    /// The wedge groups after collapsing `a` into `b`: each wedge of `b` with the wedges of `a`
    /// that merge into it, handed to `f` one by one (no allocation: this runs for every queued edge).
    fn for_groups(adj: &Adjacency, b: u32, map: &[(u32, u32)], mut f: impl FnMut(u32, &[u32])) {
        let mut g: Local<u32> = Local::new();
        for wb in adj.vertex_wedges(b) {
            g.clear();
            g.push(wb);
            g.extend(map.iter().filter(|(_, y)| *y == wb).map(|(x, _)| *x));
            f(wb, &g);
        }
    }

    /// The geometric part: the quadric of the merged vertex and where it goes.
    #[inline(always)]
    fn place(&self, adj: &Adjacency, a: u32, b: u32) -> (Quadric, DVec3) {
        let q = self.quadrics[a as usize].add(&self.quadrics[b as usize]);
        let (pa, pb) = (
            adj.positions[a as usize].as_dvec3(),
            adj.positions[b as usize].as_dvec3(),
        );
        // b stays put when it may not move; otherwise the optimum (if it lies within twice the
        // edge's length of the edge's midpoint) or the best fallback.
        let p = if adj.is_locked(b) {
            pb
        } else {
            let reach = 2.0 * (pa - pb).length() + 1e-12;
            match q.optimum() {
                Some(x) if (x - 0.5 * (pa + pb)).length_squared() <= reach * reach => x,
                _ => [pa, pb, 0.5 * (pa + pb)]
                    .into_iter()
                    .min_by(|x, y| q.eval(*x).total_cmp(&q.eval(*y)))
                    .unwrap(),
            }
        };
        (q, p)
    }
}

impl QemCost {
    /// The cost of collapsing `a` into `b` and where the merged vertex goes, with its quadric.
    fn cost_at(&self, adj: &Adjacency, a: u32, b: u32) -> (f64, DVec3, Quadric) {
        let (q, p) = self.place(adj, a, b);
        let mut cost = q.eval(p);
        let Some(attrs) = &self.attributes else {
            return (cost, p, q);
        };
        if let Some((wa, wb)) = adj.single_wedges(a, b) {
            // The common case, one wedge each: the one group `for_groups` would make, without
            // looking at b's triangles.
            cost += attrs.cost(&[wb, wa], p, &adj.wedges[wb as usize]);
        } else if let Ok(map) = adj.edge_wedge_map(a, b) {
            Self::for_groups(adj, b, &map, |wb, group| {
                cost += attrs.cost(group, p, &adj.wedges[wb as usize]);
            });
        }
        (cost, p, q)
    }
}

impl QemCost {
    /// The attribute values `b`'s wedges would take if `a` were collapsed into `b` at `p` —
    /// what [`CollapseCost::collapsed`] would set — without changing anything (a perceptual test
    /// looks at the LOD before the engine makes it). Empty without attribute quadrics, or when
    /// the wedges cannot be paired (the collapse is illegal then).
    pub fn proposed_wedges(&self, adj: &Adjacency, a: u32, b: u32, p: Vec3) -> WedgeValues {
        let mut out = WedgeValues::new();
        let (Some(attrs), Ok(map)) = (&self.attributes, adj.edge_wedge_map(a, b)) else {
            return out;
        };
        let x = p.as_dvec3();
        Self::for_groups(adj, b, &map, |wb, group| {
            out.push((wb, attrs.optimal(group, x, &adj.wedges[wb as usize]).0));
        });
        out
    }
}

impl CollapseCost for QemCost {
    fn evaluate(&self, adj: &Adjacency, a: u32, b: u32) -> (f64, Vec3, f64) {
        let (cost, p, q) = self.cost_at(adj, a, b);
        (cost, p.as_vec3(), q.rms(p))
    }

    fn cost(&self, adj: &Adjacency, a: u32, b: u32) -> f64 {
        self.cost_at(adj, a, b).0
    }

    fn prefetch(&self, adj: &Adjacency, v: u32) {
        let q = &self.quadrics[v as usize];
        crate::prefetch::prefetch(q);
        crate::prefetch::prefetch(&q.w);
        crate::prefetch::prefetch_at(&adj.positions, v);
        if let (Some(attrs), Some(w)) = (&self.attributes, adj.single_wedge(v)) {
            attrs.prefetch(w);
            crate::prefetch::prefetch_at(&adj.wedges, w);
        }
    }

    fn placement(&self, adj: &Adjacency, a: u32, b: u32) -> (Vec3, f64) {
        let (q, p) = self.place(adj, a, b);
        (p.as_vec3(), q.rms(p))
    }

    fn collapsed(
        &mut self,
        adj: &mut Adjacency,
        a: u32,
        b: u32,
        map: &[(u32, u32)],
    ) -> WedgeValues {
        self.quadrics[b as usize] = self.quadrics[b as usize].add(&self.quadrics[a as usize]);
        let Some(attrs) = &mut self.attributes else {
            return WedgeValues::new();
        };
        let mut changes = WedgeValues::new();
        let x = adj.positions[b as usize].as_dvec3();
        Self::for_groups(adj, b, map, |wb, group| {
            let (w, _) = attrs.optimal(group, x, &adj.wedges[wb as usize]);
            for &wa in &group[1..] {
                attrs.merge(wb, wa);
            }
            changes.push((wb, w));
        });
        for &(wb, w) in &changes {
            adj.wedges[wb as usize] = w;
        }
        changes
    }
}

/// When to stop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stop {
    /// At or below this many triangles.
    Triangles(usize),
    /// Before the first collapse whose error exceeds this fraction of the bounding-box diagonal.
    RelativeError(f64),
}

/// One accepted collapse.
#[derive(Debug, Clone, PartialEq)]
pub struct Collapse {
    /// The vertex removed.
    pub from: u32,
    /// The vertex kept.
    pub to: u32,
    /// Where `to` moved.
    pub position: Vec3,
    /// The collapse's error (model units).
    pub error: f64,
    /// Triangles after it.
    pub triangles: usize,
    /// New attribute values of the surviving wedges.
    pub attributes: WedgeValues,
}

/// The start mesh and the collapse sequence: any prefix is a LOD.
#[derive(Debug, Clone)]
pub struct Progressive {
    /// The full-resolution structure.
    pub base: Adjacency,
    /// Accepted collapses in order.
    pub collapses: Vec<Collapse>,
    /// The structure after the last collapse (the coarsest LOD, without a replay).
    pub last: Adjacency,
}

impl Progressive {
    /// How many of the first collapses it takes to reach at most `triangles` triangles: the
    /// shortest such prefix, or every collapse when the run stopped above the count (it
    /// could not go further, or `triangles` is 0).
    fn prefix(&self, triangles: usize) -> usize {
        self.collapses
            .iter()
            .position(|c| c.triangles <= triangles)
            .map_or(self.collapses.len(), |k| k + 1)
    }

    /// The structure after the shortest prefix of collapses that leaves at most `triangles`
    /// triangles (all collapses if none does).
    pub fn extract(&self, triangles: usize) -> Adjacency {
        self.replay(self.prefix(triangles))
    }

    /// The structure after the first `n` collapses (all of them when `n` is larger).
    pub fn replay(&self, n: usize) -> Adjacency {
        if n >= self.collapses.len() {
            return self.last.clone();
        }
        let mut adj = self.base.clone();
        for c in &self.collapses[..n] {
            adj.collapse(c.from, c.to, c.position)
                .expect("a recorded collapse replays");
            for (w, v) in &c.attributes {
                adj.wedges[*w as usize] = *v;
            }
        }
        adj
    }

    /// The largest error among the collapses [`Progressive::extract`] makes for `triangles`.
    pub fn error_at(&self, triangles: usize) -> f64 {
        self.collapses[..self.prefix(triangles)]
            .iter()
            .map(|c| c.error)
            .fold(0.0, f64::max)
    }
}

/// Queue entry, ordered by cost, then a hash of the vertex ids, then the ids (then the stamp):
/// the smallest pops first.
///
/// 16 bytes, so a node's four children fill one cache line of the 4-ary queue, which holds
/// millions of entries on large meshes and whose pops are mostly cache misses. The cost is
/// rounded to f32 for this (a relative step of 6e-8): collapses whose costs agree to seven
/// digits are ordered by [`tie_order`].
///
/// Why a hash and not the ids themselves: on a flat or evenly curved region every collapse
/// costs the same (zero on a plane), and ordered by id the survivor of one collapse, which keeps
/// the smaller id, is an end of the next one again. The collapses then grow one vertex across the
/// whole region, a fan whose star holds most of it; Williams' hierarchy built from such a record
/// is a chain, and its preprocessing moves every sample at every node (quadratic: a 30 k-triangle
/// grid took 222 s, 11 s hashed). Hashed, equal-cost collapses spread over the region as a
/// random order would spread them, and the result is still the same for any thread count.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Entry {
    /// The cost's bits as f32 (a non-negative float orders like its bits).
    cost: u32,
    a: u32,
    b: u32,
    /// version[a] + version[b] when queued. Versions only grow, so the sum is unchanged exactly
    /// when neither vertex has changed since.
    stamp: u32,
}

/// The order of equal-cost collapses: a 32-bit mix of both vertex ids (MurmurHash3's
/// finalizer), so that neighbouring edges land far apart in the order.
#[inline]
fn tie_order(a: u32, b: u32) -> u32 {
    let mut h = a.wrapping_mul(0x9E37_79B1) ^ b.rotate_left(16).wrapping_mul(0x85EB_CA77);
    h ^= h >> 16;
    h = h.wrapping_mul(0x85EB_CA6B);
    h ^= h >> 13;
    h = h.wrapping_mul(0xC2B2_AE35);
    h ^ (h >> 16)
}

impl Ord for Entry {
    #[inline]
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.cost.cmp(&other.cost).then_with(|| {
            tie_order(self.a, self.b)
                .cmp(&tie_order(other.a, other.b))
                .then((self.a, self.b, self.stamp).cmp(&(other.a, other.b, other.stamp)))
        })
    }
}

impl PartialOrd for Entry {
    #[inline]
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Entry {
    fn current(&self, version: &[u32]) -> bool {
        version[self.a as usize].wrapping_add(version[self.b as usize]) == self.stamp
    }
}

impl Keyed for Entry {
    #[inline]
    fn key(&self) -> u32 {
        self.cost
    }
    #[inline]
    fn raise_key(&mut self, k: u32) {
        self.cost = self.cost.max(k);
    }
}

/// Queue entries popped ahead of their turn, so their vertices' data is fetched while earlier
/// collapses are made.
const LOOKAHEAD: usize = 4;

/// Vertices per task when the first costs are evaluated in parallel.
const INITIAL_CHUNK: u32 = 512;

/// Run the edge-collapse engine on `adj` with `cost` until `stop`.
pub fn run(adj: Adjacency, cost: &mut dyn CollapseCost, stop: Stop, diagonal: f64) -> Progressive {
    let base = adj.clone();
    let mut adj = adj;
    let mut version = vec![0u32; adj.positions.len()];
    let initial = first_entries(&adj, &*cost, &version);
    let mut heap = Lookahead::new(initial, LOOKAHEAD);
    let mut collapses = Vec::new();
    let limit = match stop {
        Stop::RelativeError(e) => e * diagonal,
        Stop::Triangles(_) => f64::INFINITY,
    };
    let mut ring = Local::new();
    // Every collapse leaves the old entries of the edges around the kept vertex behind (their
    // stamps no longer match); the queue drops them when it sorts their bucket, or they pop and
    // are skipped here.
    while let Some(e) = heap.pop(
        |e| e.current(&version),
        |e| {
            for v in [e.a, e.b] {
                cost.prefetch(&adj, v);
                adj.prefetch_triangles(v);
            }
        },
    ) {
        if let Stop::Triangles(n) = stop
            && adj.triangle_count() <= n
        {
            break;
        }
        if !e.current(&version) {
            continue;
        }
        // The entries popped ahead had their triangle lists asked for then: the one after next
        // now has its triangles asked for, the next its ring's positions (each stage reads what
        // the one before fetched, a collapse earlier).
        if let Some(n) = heap.ahead(1) {
            adj.prefetch_triangle_data(n.a);
            adj.prefetch_triangle_data(n.b);
        }
        if let Some(n) = heap.ahead(0) {
            adj.prefetch_ring_positions(n.a);
            adj.prefetch_ring_positions(n.b);
        }
        let (a, b) = (e.a, e.b);
        let (p, err) = cost.placement(&adj, a, b);
        if err > limit {
            break;
        }
        // A refused collapse changes nothing, so each direction is checked and applied in one go.
        let (from, to, map) = match adj.collapse_for_good(a, b, p, &mut ring) {
            Ok(map) => (a, b, map),
            Err(_) if !adj.is_locked(b) && adj.class(b) <= adj.class(a) => {
                match adj.collapse_for_good(b, a, p, &mut ring) {
                    Ok(map) => (b, a, map),
                    Err(_) => continue,
                }
            }
            Err(_) => continue,
        };
        let attributes = cost.collapsed(&mut adj, from, to, &map);
        version[from as usize] += 1;
        version[to as usize] += 1;
        collapses.push(Collapse {
            from,
            to,
            position: p,
            error: err,
            triangles: adj.triangle_count(),
            attributes,
        });
        // Only the edges around `to` changed (its quadric and position); their old entries
        // carry `to`'s old version and are skipped when popped.
        for &n in &ring {
            cost.prefetch(&adj, n);
        }
        for &n in &ring {
            if let Some(e) = entry(&adj, cost, &version, to, n) {
                heap.push(e);
            }
        }
    }
    Progressive {
        base,
        collapses,
        last: adj,
    }
}

/// The queue entry of edge (u, v): the lower class collapses into the higher (the vertex that
/// may move moves); `None` where neither end may move.
#[inline]
fn entry(
    adj: &Adjacency,
    cost: &dyn CollapseCost,
    version: &[u32],
    u: u32,
    v: u32,
) -> Option<Entry> {
    let (a, b) = adj.collapse_direction(u, v)?;
    Some(Entry {
        cost: (cost.cost(adj, a, b).max(0.0) as f32).to_bits(),
        a,
        b,
        stamp: version[a as usize].wrapping_add(version[b as usize]),
    })
}

/// The first costs of all edges are independent: evaluated in parallel, then heapified in one
/// go. Entries are totally ordered (cost, then vertex ids), so the pop order — and the result
/// — does not depend on the thread count.
/// Each vertex costs its edges to higher vertices (each edge once), in chunks of vertices.
/// (Each chunk fills its own vector, and the chunks are joined in order: a flattened
/// parallel iterator's bookkeeping took 14 M instructions on the bunny, a fifth of the
/// 65 M the first costs themselves take.)
fn first_entries(adj: &Adjacency, cost: &dyn CollapseCost, version: &[u32]) -> Vec<Entry> {
    let vertices = adj.positions.len() as u32;
    let chunks: Vec<Vec<Entry>> = (0..vertices.div_ceil(INITIAL_CHUNK))
        .into_par_iter()
        .map(|c| {
            let range = c * INITIAL_CHUNK..((c + 1) * INITIAL_CHUNK).min(vertices);
            // About three edges per vertex start at the lower end.
            let mut out = Vec::with_capacity(4 * range.len());
            for u in range {
                for v in adj.ring(u) {
                    if v > u
                        && let Some(e) = entry(adj, cost, version, u, v)
                    {
                        out.push(e);
                    }
                }
            }
            out
        })
        .collect();
    chunks.concat()
}

/// The progressive record of `mesh` down to `stop`, with attribute-aware quadrics.
pub fn progressive(mesh: &Mesh, stop: Stop) -> Progressive {
    let mut adj = Adjacency::new_spatial(mesh);
    adj.allow_non_manifold_collapses();
    let diagonal = mesh.aabb().diagonal() as f64;
    let mut cost = QemCost::with_attributes(&adj, diagonal);
    run(adj, &mut cost, stop, diagonal)
}

/// Simplify a mesh with QEM to `stop`; returns the LOD and the largest collapse error (model units).
pub fn simplify(mesh: &Mesh, stop: Stop) -> Result<(Mesh, f64)> {
    let pm = progressive(mesh, stop);
    let target = match stop {
        Stop::Triangles(n) => n,
        Stop::RelativeError(_) => 0,
    };
    let lod = pm.extract(target);
    Ok((lod.to_mesh(mesh)?, pm.error_at(target)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{LoadOptions, shapes};

    #[test]
    fn a_tessellated_plane_collapses_to_two_triangles_with_zero_error() {
        // Every plane quadric is the same plane and the border constraint planes pass through
        // the border, so interior and border vertices collapse at zero cost until only the four
        // corners (where two border planes meet, so moving them costs) remain.
        let m = shapes::grid_plane(8);
        let (lod, err) = simplify(&m, Stop::Triangles(2)).unwrap();
        assert_eq!(lod.triangle_count(), 2);
        assert!(err < 1e-9, "{err}");
        let mut corners: Vec<[i32; 2]> = lod
            .positions()
            .iter()
            .map(|p| [p.x.round() as i32, p.y.round() as i32])
            .collect();
        corners.sort();
        corners.dedup();
        assert_eq!(corners, vec![[0, 0], [0, 8], [8, 0], [8, 8]]);
    }

    #[test]
    fn a_closed_mesh_stays_closed_and_a_cube_keeps_its_corners() {
        // A subdivided sphere at 10 %: no border edges appear (link condition), no non-manifold edges.
        let s = shapes::icosphere(4);
        let adj = Adjacency::new(&s);
        let mut cost = QemCost::new(&adj);
        let pm = run(
            adj,
            &mut cost,
            Stop::Triangles(s.triangle_count() / 10),
            2.0,
        );
        let lod = pm.extract(s.triangle_count() / 10);
        lod.check().unwrap();
        assert_eq!(lod.border_edges(), 0);
        assert_eq!(lod.non_manifold_edges(), 0);
        assert!(lod.triangle_count() <= s.triangle_count() / 10);
        // A cube of 2×2 grids per face simplifies to 12 triangles on its 8 corners: corners
        // are where three face planes meet, the only zero-error positions.
        let cube = shapes::cube_grid(2);
        let (lod, err) = simplify(&cube, Stop::Triangles(12)).unwrap();
        assert_eq!(lod.triangle_count(), 12);
        assert!(err < 1e-6, "{err}");
        for p in lod.positions() {
            assert!(
                p.abs().cmpge(Vec3::splat(0.999)).all(),
                "{p} is not a corner"
            );
        }
    }

    /// The shipped Spot (UV seams: several wedges per vertex).
    fn spot() -> Mesh {
        crate::mesh::load(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("reference/models/spot/spot_mtl.obj"),
            &LoadOptions::default(),
        )
        .unwrap()
    }

    #[test]
    fn seams_are_not_torn() {
        // Spot has UV seams; after simplification every position still has, for each of its
        // corners, a UV that came from a wedge of the original seam structure: the number of
        // border edges (seen on the welded mesh) stays zero.
        let spot = spot();
        let (lod, _) = simplify(&spot, Stop::Triangles(spot.triangle_count() / 4)).unwrap();
        let adj = Adjacency::new(&lod);
        assert_eq!(adj.border_edges(), 0, "a seam opened into a hole");
        assert!(lod.triangle_count() <= spot.triangle_count() / 4);
        assert!(lod.uvs().is_some());
    }

    #[test]
    fn the_collapse_sequence_does_not_depend_on_the_thread_count() {
        // The first edge costs are evaluated in parallel; the queue's total order makes the
        // sequence the same for any pool size (Spot: UV seams, so several wedges per vertex).
        let spot = spot();
        let run_with = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| progressive(&spot, Stop::Triangles(spot.triangle_count() / 20)))
                .collapses
        };
        let one = run_with(1);
        assert!(one.len() > spot.triangle_count() / 3);
        assert_eq!(one, run_with(2));
        assert_eq!(one, run_with(8));
    }

    #[test]
    fn a_triangle_target_is_an_upper_bound() {
        // A grid whose triangles are all doubled back to back: a collapse inside it removes
        // four triangles, one on its border two. Whatever the order of equal costs, every
        // target the chain can reach is met from below (the run used to stop above a target
        // when the next collapse would have jumped past it), by the shortest prefix that does.
        let mut data = shapes::grid_plane(3).to_data();
        let back: Vec<[u32; 3]> = data.triangles.iter().map(|&[a, b, c]| [a, c, b]).collect();
        data.triangles.extend(back);
        data.material_ids.clear();
        let doubled = Mesh::new(data, &LoadOptions::default()).unwrap();
        let pm = progressive(&doubled, Stop::Triangles(0));
        let floor = pm.last.triangle_count();
        assert!(floor < 10, "{floor}");
        for t in floor..=doubled.triangle_count() {
            let k = pm.prefix(t);
            assert!(pm.extract(t).triangle_count() <= t, "target {t}");
            assert!(k == 0 || pm.collapses[k - 1].triangles <= t);
            assert!(
                k < 2 || pm.collapses[k - 2].triangles > t,
                "target {t}: not the shortest"
            );
        }
        let (lod, _) = simplify(&doubled, Stop::Triangles(12)).unwrap();
        assert!(lod.triangle_count() <= 12);
    }

    #[test]
    fn quadric_optimum_and_fallback() {
        let q = Quadric::plane(DVec3::X, -1.0, 1.0)
            .add(&Quadric::plane(DVec3::Y, -2.0, 1.0))
            .add(&Quadric::plane(DVec3::Z, -3.0, 1.0));
        let x = q.optimum().unwrap();
        assert!((x - DVec3::new(1.0, 2.0, 3.0)).length() < 1e-12);
        assert!(q.eval(x) < 1e-20);
        // One plane only: singular.
        assert!(Quadric::plane(DVec3::Z, 0.0, 1.0).optimum().is_none());
    }
}
