//! The editable mesh the simplifiers and the image-driven optimizer work on: welded vertices,
//! triangles with per-corner attribute vertices ("wedges", Hoppe 1999: where a UV or normal seam
//! splits a vertex, its corners point at different wedges), vertex → incident-triangle lists, vertex
//! classes, and the local operations edge collapse, edge split and edge swap — each returning an
//! [`Undo`] that restores the exact previous state, because the optimizer tries moves and reverts
//! them.
//!
//! Decision: a corner table with per-vertex incidence lists rather than pointer-linked half-edges.
//! Every operation touches a handful of triangles and records them before changing anything, so
//! undo is a restore of snapshots; the structure stays valid by construction instead of by careful
//! pointer surgery. The invariants ([`Adjacency::check`]) are property-tested under random
//! operation sequences.
//!
//! Rules (Hoppe 1996, Garland–Heckbert 1997, Dey et al. 1999 link condition):
//! - A collapse a→b is legal when the link condition holds (the vertices adjacent to both a and b
//!   are exactly the apexes of the triangles on edge ab), it does not join two border vertices
//!   through the interior, no surviving triangle flips (normal turns by more than 90°) or becomes
//!   degenerate, and every wedge of a has a partner wedge of b across the edge (so a seam is only
//!   collapsed along itself, never torn).
//! - Locked and non-manifold vertices never move; an edge with more than two triangles is never
//!   collapsed.
//! - Except after [`Adjacency::allow_non_manifold_collapses`] (what QEM simplification does):
//!   then a collapse that involves a non-manifold vertex may move it, may be along an edge with
//!   more than two triangles, and skips the link condition — the surface there is not a manifold
//!   to protect. Scans often carry such parts (the Stanford dragon's reconstruction has 2 534
//!   edges with four or more triangles, from back-to-back duplicate faces and fins); with them
//!   fixed, QEM stopped at 5 % of the dragon when asked for 1 %. The structure's invariants
//!   ([`Adjacency::check`]) hold either way: triangles on the collapsed edge die, and every edge
//!   that gains triangles ends at the merged vertex, which becomes non-manifold itself.

//!
//! Files: `build.rs` (from a `Mesh` and back: welding, wedges, incidence, classes), this file (the
//! types and the read-only queries), `collapse.rs` (edge collapse and its legality checks),
//! `split_swap.rs` (edge split and edge swap), `undo.rs` (snapshots and their restore),
//! `check.rs` (the invariants, counted and checked).

mod build;
mod check;
mod collapse;
mod split_swap;
#[cfg(test)]
mod tests;
mod undo;

use glam::{Vec2, Vec3};
use smallvec::SmallVec;

use super::Mesh;
use super::incidence::Incidence;

/// A short list of vertices, triangles or wedges: the local operations build these per call, and on
/// the stack (the usual valence fits) they cost no allocation.
pub type Local<T> = SmallVec<[T; 16]>;

/// For a collapse of a into b: each wedge of a with the wedge of b it merges into.
pub type WedgeMap = SmallVec<[(u32, u32); 4]>;

/// Every live edge (a < b) with its live triangles (ascending), in edge order.
pub type EdgeList = Vec<((u32, u32), SmallVec<[u32; 2]>)>;

/// [`Adjacency`]'s marker for a vertex with several wedges.
const SEVERAL: u32 = u32::MAX;

/// How a vertex may be treated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum VertexClass {
    /// Manifold, no border edge, one wedge.
    Interior,
    /// On a UV/normal/colour seam (several wedges).
    Seam,
    /// On a border edge (one incident triangle).
    Border,
    /// On an edge with more than two triangles: never moved, unless non-manifold collapses are
    /// allowed.
    NonManifold,
}

/// Attributes of one wedge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wedge {
    /// The welded vertex it belongs to.
    pub vertex: u32,
    /// Normal.
    pub normal: Vec3,
    /// Texture coordinate (zero where the mesh has none).
    pub uv: Vec2,
    /// Linear RGB colour (one where the mesh has none).
    pub color: Vec3,
}

/// The editable mesh.
#[derive(Debug, Clone)]
pub struct Adjacency {
    /// Welded vertex positions.
    pub positions: Vec<Vec3>,
    /// Wedges (attribute vertices).
    pub wedges: Vec<Wedge>,
    tris: Vec<[u32; 3]>,
    corners: Vec<[u32; 3]>,
    materials: Vec<u32>,
    alive: Vec<bool>,
    vtris: Incidence,
    class: Vec<VertexClass>,
    /// Explicitly locked vertices ([`Adjacency::lock`]).
    locked: Vec<bool>,
    /// Whether collapses may move non-manifold vertices ([`Adjacency::allow_non_manifold_collapses`]).
    non_manifold_collapses: bool,
    /// The vertex's wedge if it had a single one when it was made, else [`SEVERAL`]. Operations
    /// never give a vertex a wedge it did not have (a collapse maps a's wedges onto b's, a swap or
    /// split keeps each vertex's wedges), so it still has exactly that one: the wedge look-ups
    /// read it from here instead of from the vertex's triangles.
    only_wedge: Vec<u32>,
    alive_count: usize,
    has_uvs: bool,
    has_colors: bool,
    /// Scratch for [`Adjacency::collapse_for_good`]: a vertex is marked when its entry equals
    /// `mark` (a fresh value per use, so nothing is cleared between uses). Not part of the state.
    marks: Vec<u32>,
    mark: u32,
}

/// Why an operation was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reject {
    /// The vertices or edge do not exist (any more).
    NoSuchEdge,
    /// A vertex that may not move would move.
    Locked,
    /// The link condition fails (the result would not be a manifold).
    Link,
    /// A triangle would flip or become degenerate.
    FoldOver,
    /// A seam would tear (a wedge has no partner across the edge).
    Seam,
    /// The edge is not between exactly two triangles (swap), or the swapped edge exists.
    Topology,
}

/// What an operation changed, to restore it exactly.
#[derive(Debug, Clone, Default)]
pub struct Undo {
    tris: Vec<(u32, [u32; 3], [u32; 3], bool)>,
    verts: Vec<(u32, Vec3, Vec<u32>, VertexClass)>,
    lens: (usize, usize, usize),
    alive_count: usize,
}

impl Adjacency {
    /// Whether the mesh has texture coordinates (wedge UVs are meaningful).
    pub fn has_uvs(&self) -> bool {
        self.has_uvs
    }

    /// Whether the mesh has vertex colours.
    pub fn has_colors(&self) -> bool {
        self.has_colors
    }

    /// The wedges used by `v`'s corners, ascending.
    pub fn vertex_wedges(&self, v: u32) -> Local<u32> {
        let ts = self.vtris.get(v);
        match self.only_wedge.get(v as usize) {
            Some(&w) if w != SEVERAL && !ts.is_empty() => return Local::from_slice(&[w]),
            _ => {}
        }
        let mut w: Local<u32> = ts.iter().map(|&t| self.corner_wedge(t, v)).collect();
        // Most vertices have one wedge: no sort for them.
        if w.iter().any(|&x| x != w[0]) {
            w.sort_unstable();
            w.dedup();
        } else {
            w.truncate(1);
        }
        w
    }

    /// For a collapse of `a` into `b`: each wedge of `a` with its partner wedge of `b`.
    pub fn collapse_wedge_map(&self, a: u32, b: u32) -> Result<WedgeMap, Reject> {
        let shared = self.edge_triangles(a, b);
        if shared.is_empty() {
            return Err(Reject::NoSuchEdge);
        }
        self.wedge_map(a, b, &shared)
    }

    /// [`Adjacency::collapse_wedge_map`] for an `a`, `b` known to be an edge: two single-wedge
    /// vertices pair their wedges without a look at the triangles.
    pub fn edge_wedge_map(&self, a: u32, b: u32) -> Result<WedgeMap, Reject> {
        match self.single_wedges(a, b) {
            Some(pair) => Ok(SmallVec::from_slice(&[pair])),
            None => self.collapse_wedge_map(a, b),
        }
    }

    /// `v`'s wedge, when it has a single one.
    pub fn single_wedge(&self, v: u32) -> Option<u32> {
        self.only_wedge
            .get(v as usize)
            .copied()
            .filter(|&w| w != SEVERAL)
    }

    /// The wedges of `a` and `b` when each has a single one.
    pub(crate) fn single_wedges(&self, a: u32, b: u32) -> Option<(u32, u32)> {
        let (wa, wb) = (self.only_wedge[a as usize], self.only_wedge[b as usize]);
        (wa != SEVERAL && wb != SEVERAL).then_some((wa, wb))
    }

    /// The wedge of `v`'s corner in triangle `t` (which must use `v`).
    pub fn corner_wedge(&self, t: u32, v: u32) -> u32 {
        let tri = self.tris[t as usize];
        let k = if tri[0] == v {
            0
        } else if tri[1] == v {
            1
        } else {
            debug_assert_eq!(tri[2], v, "triangle {t} does not use vertex {v}");
            2
        };
        self.corners[t as usize][k]
    }

    /// Every live edge (a < b) with its live triangles, in edge order.
    pub fn edge_map(&self) -> EdgeList {
        let mut edges: EdgeList = Vec::with_capacity(3 * self.alive_count / 2 + 1);
        self.for_each_edge(|a, b, ts| edges.push(((a, b), SmallVec::from_slice(ts))));
        edges
    }

    /// Call `f(a, b, triangles)` for every live edge (a < b) with its live triangles (ascending),
    /// in edge order, without collecting them.
    pub fn for_each_edge(&self, f: impl FnMut(u32, u32, &[u32])) {
        self.for_each_edge_from(|_| true, f);
    }

    /// [`Adjacency::for_each_edge`] for the edges whose lower vertex passes `from`.
    pub fn for_each_edge_from(
        &self,
        from: impl Fn(u32) -> bool,
        mut f: impl FnMut(u32, u32, &[u32]),
    ) {
        let mut pairs: Local<(u32, u32)> = Local::new();
        let mut ts: Local<u32> = Local::new();
        for a in (0..self.positions.len() as u32).filter(|&a| from(a)) {
            // a's edges to higher vertices, from a's own triangles: (other end, triangle) sorted
            // is edge order, with each edge's triangles ascending.
            self.higher_ends(a, &mut pairs);
            let mut i = 0;
            while i < pairs.len() {
                let b = pairs[i].0;
                ts.clear();
                while i < pairs.len() && pairs[i].0 == b {
                    ts.push(pairs[i].1);
                    i += 1;
                }
                f(a, b, &ts);
            }
        }
    }

    /// The (b, t) with b > a a vertex of a's triangle t, sorted, into `out`.
    fn higher_ends(&self, a: u32, out: &mut Local<(u32, u32)>) {
        out.clear();
        for &t in self.vtris.get(a) {
            for b in self.tris[t as usize] {
                if b > a {
                    out.push((b, t));
                }
            }
        }
        out.sort_unstable();
    }

    /// Whether the edge ab between triangles `ts` (two of them) is a seam: a or b has different
    /// wedges on its two sides.
    pub fn is_seam(&self, a: u32, b: u32, ts: &[u32]) -> bool {
        let w = |t: u32, v: u32| self.corner_wedge(t, v);
        w(ts[0], a) != w(ts[1], a) || w(ts[0], b) != w(ts[1], b)
    }

    /// Forbid moving vertex `v`.
    pub fn lock(&mut self, v: u32) {
        self.locked[v as usize] = true;
    }

    /// Let collapses move non-manifold vertices and pass through non-manifold edges (module
    /// docs). Replays of a collapse record must be made on a structure with the same setting.
    pub fn allow_non_manifold_collapses(&mut self) {
        self.non_manifold_collapses = true;
    }

    /// Whether `v` may not move: locked, or non-manifold while non-manifold collapses are not
    /// allowed.
    pub fn is_locked(&self, v: u32) -> bool {
        self.locked[v as usize]
            || (self.class[v as usize] == VertexClass::NonManifold && !self.non_manifold_collapses)
    }

    /// Which way edge (u, v) collapses: (the vertex that moves, the one it moves onto). The
    /// lower class collapses into the higher (a vertex that may move moves); `None` where
    /// neither end may move.
    pub fn collapse_direction(&self, u: u32, v: u32) -> Option<(u32, u32)> {
        let (a, b) = if self.is_locked(u) || self.class(u) > self.class(v) {
            (v, u)
        } else {
            (u, v)
        };
        (!self.is_locked(a)).then_some((a, b))
    }

    /// A vertex's class.
    pub fn class(&self, v: u32) -> VertexClass {
        self.class[v as usize]
    }

    /// Live triangles.
    pub fn triangle_count(&self) -> usize {
        self.alive_count
    }

    /// Triangle slots, live or not (triangle ids are below this).
    pub fn triangle_slots(&self) -> usize {
        self.tris.len()
    }

    /// Whether triangle `t` exists and is live.
    pub fn is_alive(&self, t: u32) -> bool {
        self.alive.get(t as usize).copied().unwrap_or(false)
    }

    /// A triangle's material.
    pub fn material(&self, t: u32) -> u32 {
        self.materials[t as usize]
    }

    /// Ids of the live triangles, ascending.
    pub fn live_triangles(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.tris.len() as u32).filter(|&t| self.alive[t as usize])
    }

    /// A triangle's welded vertices.
    pub fn triangle(&self, t: u32) -> [u32; 3] {
        self.tris[t as usize]
    }

    /// A triangle's wedges.
    pub fn corners(&self, t: u32) -> [u32; 3] {
        self.corners[t as usize]
    }

    /// Triangles incident to `v`.
    pub fn vertex_triangles(&self, v: u32) -> &[u32] {
        self.vtris.get(v)
    }

    /// Ask for the cache line where `v`'s triangle list starts. A hint only.
    pub fn prefetch_triangles(&self, v: u32) {
        if let Some(first) = self.vtris.first(v) {
            crate::prefetch::prefetch(first);
        }
    }

    /// Ask for the cache lines of `v`'s triangles (their vertices and corner wedges), once its list
    /// is in the cache ([`Adjacency::prefetch_triangles`] asked for that earlier). A hint only.
    pub fn prefetch_triangle_data(&self, v: u32) {
        for &t in self.vtris.get(v) {
            crate::prefetch::prefetch_at(&self.tris, t);
            crate::prefetch::prefetch_at(&self.corners, t);
        }
    }

    /// Ask for the positions of `v`'s neighbours, once its triangles are in the cache
    /// ([`Adjacency::prefetch_triangle_data`] asked for them earlier). A hint only.
    pub fn prefetch_ring_positions(&self, v: u32) {
        for &t in self.vtris.get(v) {
            for x in self.tris[t as usize] {
                crate::prefetch::prefetch_at(&self.positions, x);
            }
        }
    }

    /// Vertices adjacent to `v`, ascending.
    pub fn neighbours(&self, v: u32) -> Local<u32> {
        let mut n = self.ring(v);
        n.sort_unstable();
        n
    }

    /// Vertices adjacent to `v`, each once, in no particular order (what a caller that only
    /// visits or counts them needs; no sort).
    pub fn ring(&self, v: u32) -> Local<u32> {
        // Valences are small: a scan of what is there beats sorting afterwards, and a plain
        // array beats a small vector's bookkeeping (this runs three times per collapse).
        const ROOM: usize = 32;
        let mut found = [0u32; ROOM];
        let mut n = 0;
        for &t in self.vtris.get(v) {
            for x in self.tris[t as usize] {
                if x != v && !found[..n].contains(&x) {
                    if n == ROOM {
                        return self.ring_large(v);
                    }
                    found[n] = x;
                    n += 1;
                }
            }
        }
        Local::from_slice(&found[..n])
    }

    /// [`Adjacency::ring`] of a vertex with more than 32 neighbours.
    fn ring_large(&self, v: u32) -> Local<u32> {
        let mut n: Local<u32> = Local::new();
        for &t in self.vtris.get(v) {
            for x in self.tris[t as usize] {
                if x != v && !n.contains(&x) {
                    n.push(x);
                }
            }
        }
        n
    }

    /// Live triangles containing both `a` and `b`.
    pub fn edge_triangles(&self, a: u32, b: u32) -> Local<u32> {
        let mut shared = Local::new();
        for &t in self.vtris.get(a) {
            if self.tris[t as usize].contains(&b) {
                shared.push(t);
            }
        }
        shared
    }

    /// Every live edge (a < b), ascending.
    pub fn edges(&self) -> Vec<(u32, u32)> {
        let mut e: Vec<(u32, u32)> = Vec::with_capacity(3 * self.alive_count / 2 + 1);
        let mut pairs: Local<(u32, u32)> = Local::new();
        for a in 0..self.positions.len() as u32 {
            self.higher_ends(a, &mut pairs);
            for &(b, _) in &pairs {
                if e.last() != Some(&(a, b)) {
                    e.push((a, b));
                }
            }
        }
        e
    }
}
