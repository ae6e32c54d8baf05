//! The connectivity moves and their optimization levels (Lindstrom & Turk §5.2–5.3, Table 1):
//! no-op, edge swap, and the vertex teleport (edge split, then the cheapest compatible edge
//! collapse found through a priority queue of collapse-energy estimates).
//!
//! Table 1's vertex sets, with e = ab, its triangles' apexes c, d, e′ = cd after a swap, v the new
//! vertex of a split or the survivor of a collapse, and ring(S) = S ∪ its neighbours:
//!
//! | move     | level 0    | level 1 | level 2          | level 3        |
//! |----------|------------|---------|------------------|----------------|
//! | no-op    | –          | {a, b}  | {a, b, c, d}     | ring{a, b}     |
//! | swap     | (none)     | {c, d}  | {c, d, a, b}     | ring{c, d}     |
//! | split    | v at mid   | {v}     | {v, c, d}        | {v} ∪ ring{a, b} |
//! | collapse | v at mid   | {v}     | ring{v}          |                |
//!
//! Our reading of the paper's table: the collapse row has entries for levels 0, 1 and 3 only;
//! its level-3 set ⌊⌈v⌉⌋ is our level 2, and collapses have three levels.
//!
//! Decisions (where the paper leaves a choice): a teleport's split is kept when its ΔE plus the
//! collapse-energy estimate is negative; the estimate is the lowest estimate in the queue when
//! the last collapse completed, attenuated by [`ESTIMATE_DECAY`] per teleport. The collapse search
//! gives up after μ + 3σ attempts, the (attenuated) statistics of the attempts earlier searches
//! needed — the paper's 0.3 % rule — and then performs the cheapest collapse it measured.

use std::collections::{BTreeMap, BTreeSet};

use glam::Vec3;

use super::Optimizer;
use super::stats::Move;

/// Attenuation of the teleport's collapse-energy estimate per teleport attempt.
pub const ESTIMATE_DECAY: f64 = 0.9;
/// Highest collapse optimization level.
const COLLAPSE_MAX_LEVEL: i8 = 2;
/// Collapse attempts allowed in a search before there is any history.
const FIRST_SEARCH_LIMIT: f64 = 32.0;

/// Collapse-energy estimates with their optimization levels; (0, −1) is the default state.
#[derive(Debug, Default)]
pub(super) struct CollapseQueue {
    order: BTreeSet<(i64, i8, u32, u32)>,
    state: BTreeMap<(u32, u32), (i64, i8)>,
}

impl CollapseQueue {
    pub fn new(edges: &[(u32, u32)]) -> CollapseQueue {
        let mut q = CollapseQueue::default();
        for &e in edges {
            q.set(e, 0, -1);
        }
        q
    }

    fn set(&mut self, (a, b): (u32, u32), energy: i64, level: i8) {
        let key = (a.min(b), a.max(b));
        if let Some((e, l)) = self.state.insert(key, (energy, level)) {
            self.order.remove(&(e, l, key.0, key.1));
        }
        self.order.insert((energy, level, key.0, key.1));
    }

    fn remove(&mut self, key: (u32, u32)) {
        if let Some((e, l)) = self.state.remove(&key) {
            self.order.remove(&(e, l, key.0, key.1));
        }
    }

    /// Lowest estimate with a level below the maximum.
    fn pop(&mut self) -> Option<((u32, u32), i64, i8)> {
        let &(e, l, a, b) = self.order.iter().find(|x| x.1 < COLLAPSE_MAX_LEVEL)?;
        self.remove((a, b));
        Some(((a, b), e, l))
    }

    fn min_estimate(&self) -> Option<i64> {
        self.order.first().map(|x| x.0)
    }
}

/// Attenuated mean and variance of the number of attempts collapse searches needed.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct SearchStats {
    weight: f64,
    sum: f64,
    sum_sq: f64,
}

impl SearchStats {
    fn record(&mut self, attempts: usize) {
        let a = attempts as f64;
        self.weight = self.weight * super::stats::DECAY + 1.0;
        self.sum = self.sum * super::stats::DECAY + a;
        self.sum_sq = self.sum_sq * super::stats::DECAY + a * a;
    }
    fn limit(&self) -> f64 {
        if self.weight < 2.0 {
            return FIRST_SEARCH_LIMIT;
        }
        let m = self.sum / self.weight;
        let var = (self.sum_sq / self.weight - m * m).max(0.0);
        (m + 3.0 * var.sqrt()).max(1.0)
    }
}

impl Optimizer {
    fn diamond(&self, a: u32, b: u32) -> Vec<u32> {
        let mut v: Vec<u32> = self
            .st
            .adj
            .edge_triangles(a, b)
            .iter()
            .flat_map(|&t| self.st.adj.triangle(t))
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    /// Triangles incident to any of `verts`.
    fn incident(&self, verts: &[u32]) -> Vec<u32> {
        verts
            .iter()
            .flat_map(|&v| self.st.adj.vertex_triangles(v).iter().copied())
            .collect()
    }

    /// Reset the collapse estimates of the edges around `verts` (the paper's ⌊⌈⌈V⌉⌉⌋).
    fn reset_estimates(&mut self, verts: &[u32]) {
        let mut tris = self.incident(verts);
        tris.sort_unstable();
        tris.dedup();
        for t in tris {
            let x = self.st.adj.triangle(t);
            for k in 0..3 {
                self.queue.set((x[k], x[(k + 1) % 3]), 0, -1);
            }
        }
    }

    /// Accept or reject the pending change; returns the committed ΔE.
    fn settle(&mut self, delta: i64, undo: Option<crate::mesh::edit::Undo>, around: &[u32]) -> i64 {
        if delta < 0 {
            self.st.accept(delta);
            self.reset_estimates(around);
            delta
        } else {
            self.st.reject(undo);
            0
        }
    }

    /// Optimize geometry around edge ab at `level` (1–3). `None` if the edge is gone.
    pub(super) fn no_op(&mut self, (a, b): (u32, u32), level: u8) -> Option<i64> {
        if self.st.adj.edge_triangles(a, b).is_empty() {
            return None;
        }
        let set = match level {
            1 => vec![a, b],
            2 => self.diamond(a, b),
            _ => self.st.ring(&[a, b]),
        };
        self.st.begin();
        let delta = self.st.evaluate(&set, true, &[], &[], &[], true);
        Some(self.settle(delta, None, &set))
    }

    /// Swap edge ab for cd and optimize at `level` (0–3). `None` if the swap is not possible.
    pub(super) fn swap(&mut self, (a, b): (u32, u32), level: u8) -> Option<i64> {
        let apexes: Vec<u32> = self
            .diamond(a, b)
            .into_iter()
            .filter(|&x| x != a && x != b)
            .collect();
        let &[c, d] = apexes.as_slice() else {
            return None;
        };
        let before = self.incident(&[a, b]);
        self.st.begin();
        let undo = self.st.adj.swap(a, b).ok()?;
        let set = match level {
            0 => vec![],
            1 => vec![c, d],
            2 => self.diamond(c, d),
            _ => self.st.ring(&[c, d]),
        };
        let topo = [a, b, c, d];
        let mut op_tris = before;
        op_tris.extend(self.incident(&topo));
        let delta = self
            .st
            .evaluate(&set, level > 0, &topo, &op_tris, &[], false);
        let around: Vec<u32> = set.iter().chain(&topo).copied().collect();
        Some(self.settle(delta, Some(undo), &around))
    }

    /// Vertex teleport at split level `level` (0–3). Returns the committed ΔE (split and
    /// collapse), or `None` if ab cannot be split.
    pub(super) fn teleport(&mut self, (a, b): (u32, u32), level: u8) -> Option<i64> {
        let shared = self.st.adj.edge_triangles(a, b);
        if shared.is_empty() || shared.len() > 2 {
            return None;
        }
        let apexes: Vec<u32> = self
            .diamond(a, b)
            .into_iter()
            .filter(|&x| x != a && x != b)
            .collect();
        let before = self.incident(&[a, b]);
        let wedges_before = self.st.adj.wedges.len() as u32;
        self.st.begin();
        let (v, undo) = self.st.adj.split(a, b).ok()?;
        let new_wedges: Vec<u32> = (wedges_before..self.st.adj.wedges.len() as u32).collect();
        let set: Vec<u32> = match level {
            0 => vec![],
            1 => vec![v],
            2 => std::iter::once(v).chain(apexes.iter().copied()).collect(),
            _ => self.st.ring(&[v, a, b]),
        };
        let topo: Vec<u32> = [v, a, b].into_iter().chain(apexes).collect();
        let mut op_tris = before;
        op_tris.extend(self.incident(&topo));
        let split_delta = self
            .st
            .evaluate(&set, level > 0, &topo, &op_tris, &new_wedges, false);
        self.estimate *= ESTIMATE_DECAY;
        if split_delta as f64 + self.estimate >= 0.0 {
            self.st.reject(Some(undo));
            return Some(0);
        }
        self.st.accept(split_delta);
        let around: Vec<u32> = set.iter().chain(&topo).copied().collect();
        self.reset_estimates(&around);
        let collapse_delta = self.collapse_search(-split_delta, v);
        Some(split_delta + collapse_delta)
    }

    /// Collapse one edge (mesh vertex count back to what it was): the first, in order of the
    /// estimates, whose collapse ΔE is below `threshold`; if the search gives up, the cheapest
    /// one measured. `fresh` is the split's vertex (its edges can always undo the split).
    fn collapse_search(&mut self, threshold: i64, fresh: u32) -> i64 {
        let limit = self.search.limit();
        let mut attempts = 0usize;
        let mut parked: Vec<((u32, u32), i64, i8)> = Vec::new();
        let mut cheapest: Option<((u32, u32), i8, i64)> = None;
        while let Some((e, estimate, level)) = self.queue.pop() {
            if self.st.remaining() == 0 || attempts as f64 >= limit {
                parked.push((e, estimate, level));
                break;
            }
            if self.st.adj.edge_triangles(e.0, e.1).is_empty() {
                continue; // the edge no longer exists
            }
            let level = (level + 1).max(0);
            let Some((delta, undo, around)) = self.try_collapse(e, level as u8, None) else {
                parked.push((e, i64::MAX / 4, COLLAPSE_MAX_LEVEL));
                continue;
            };
            attempts += 1;
            if delta < threshold {
                self.st.accept(delta);
                self.reset_estimates(&around);
                self.search.record(attempts);
                self.requeue(parked);
                self.estimate = self.queue.min_estimate().unwrap_or(0).max(0) as f64;
                return delta;
            }
            self.st.reject(Some(undo));
            if cheapest.is_none_or(|c| delta < c.2) {
                cheapest = Some((e, level, delta));
            }
            if level < COLLAPSE_MAX_LEVEL {
                self.queue.set(e, delta, level);
            } else {
                parked.push((e, delta, level));
            }
        }
        self.search.record(attempts);
        self.requeue(parked);
        // No compatible collapse: take the cheapest measured (an uphill move), or fold the split
        // vertex back into a neighbour.
        if let Some((e, level, _)) = cheapest
            && let Some((delta, _, around)) = self.try_collapse(e, level as u8, None)
        {
            self.st.accept(delta);
            self.reset_estimates(&around);
            return delta;
        }
        // Folding the split vertex into a neighbour, placed at that neighbour, gives back the
        // triangles from before the split, which were legal.
        for n in self.st.adj.neighbours(fresh) {
            let at = self.st.adj.positions[n as usize];
            if let Some((delta, _, around)) = self.try_collapse((fresh, n), 0, Some(at)) {
                self.st.accept(delta);
                self.reset_estimates(&around);
                return delta;
            }
        }
        0
    }

    fn requeue(&mut self, parked: Vec<((u32, u32), i64, i8)>) {
        for (e, energy, level) in parked {
            if !self.st.adj.edge_triangles(e.0, e.1).is_empty() {
                self.queue.set(e, energy, level);
            }
        }
    }

    /// Collapse edge e (either direction) with the survivor at `at` (default: the midpoint),
    /// optimized at `level`. Returns the pending ΔE, the undo and the vertices around; `None` if
    /// neither direction is legal.
    fn try_collapse(
        &mut self,
        (a, b): (u32, u32),
        level: u8,
        at: Option<Vec3>,
    ) -> Option<(i64, crate::mesh::edit::Undo, Vec<u32>)> {
        let mid: Vec3 = at.unwrap_or(
            0.5 * (self.st.adj.positions[a as usize] + self.st.adj.positions[b as usize]),
        );
        let before = self.incident(&[a, b]);
        self.st.begin();
        let (undo, keep) = match self.st.adj.collapse(a, b, mid) {
            Ok(u) => (u, b),
            Err(_) => (self.st.adj.collapse(b, a, mid).ok()?, a),
        };
        let ring = self.st.ring(&[keep]);
        let set = match level {
            0 => vec![],
            1 => vec![keep],
            _ => ring.clone(),
        };
        let mut op_tris = before;
        op_tris.extend(self.incident(&ring));
        let delta = self
            .st
            .evaluate(&set, level > 0, &ring, &op_tris, &[], false);
        Some((delta, undo, ring))
    }

    /// Run operation (move, level) on edge e; the committed ΔE, or `None` if not applicable.
    pub(super) fn run(&mut self, e: (u32, u32), mv: Move, level: u8) -> Option<i64> {
        match mv {
            Move::NoOp => self.no_op(e, level),
            Move::Swap => self.swap(e, level),
            Move::Teleport => self.teleport(e, level),
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::super::{Optimizer, Options, Setup, Targets};
    use super::*;
    use crate::mesh::Mesh;
    use crate::raster::incremental::LumaViews;

    /// The shipped (smooth-shaded) Stanford bunny and a QEM version of about 150 vertices, with a
    /// small optimizer (6 views of 64²). (Not a flat-shaded input: there every edge is an
    /// attribute boundary, where the paper defines no swap.)
    fn optimizer() -> (Optimizer, Setup, Options) {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("reference/models/bunny/stanford-bunny.obj");
        let original = Arc::new(crate::mesh::load(&path, &Default::default()).unwrap());
        let coarse = crate::simplify::chain(
            &original,
            crate::simplify::Method::Qem,
            &[crate::simplify::Goal::Triangles(300)],
        )
        .unwrap();
        let coarse: Arc<Mesh> = Arc::new(coarse.into_iter().next().unwrap().mesh);
        let opts = Options {
            views: 6,
            size: 64,
            evals: 1_000_000,
            ..Options::default()
        };
        let targets = Targets::new(&original, &opts).unwrap();
        let (opt, setup) = Optimizer::new(targets, &coarse, &opts).unwrap();
        (opt, setup, opts)
    }

    fn full_energy(opt: &Optimizer, setup: &Setup, opts: &Options) -> i64 {
        LumaViews::new(
            &opt.st.adj,
            &setup.scene,
            &setup.targets.cameras,
            opts.size,
            opts.size,
            Some(setup.targets.images.clone()),
        )
        .unwrap()
        .energy()
    }

    fn live(opt: &Optimizer) -> usize {
        super::super::live_vertices(&opt.st.adj)
    }

    #[test]
    fn an_accepted_no_op_changes_the_energy_by_exactly_its_delta() {
        let (mut opt, setup, opts) = optimizer();
        let before = full_energy(&opt, &setup, &opts);
        assert_eq!(before, opt.st.energy);
        let mut accepted = 0;
        for e in opt.st.adj.edges().into_iter().take(40) {
            let e0 = full_energy(&opt, &setup, &opts);
            let d = opt.no_op(e, 1).unwrap();
            assert!(d <= 0);
            // ΔE from the incremental images equals the difference of two full-frame energies.
            assert_eq!(full_energy(&opt, &setup, &opts) - e0, d, "edge {e:?}");
            accepted += (d < 0) as usize;
        }
        assert!(accepted > 0, "no geometry move improved anything");
        opt.verify(&setup, &opts).unwrap();
    }

    #[test]
    fn rejected_moves_restore_the_mesh_exactly() {
        let (mut opt, setup, opts) = optimizer();
        let mut rejected = 0;
        for e in opt.st.adj.edges().into_iter().take(60) {
            let before = opt.st.adj.clone();
            let (pos, wedges) = (before.positions.clone(), before.wedges.clone());
            let tris: Vec<[u32; 3]> = before
                .live_triangles()
                .map(|t| before.triangle(t))
                .collect();
            if opt.swap(e, 0) == Some(0) {
                rejected += 1;
                assert_eq!(opt.st.adj.positions, pos);
                assert_eq!(opt.st.adj.wedges, wedges);
                let now: Vec<[u32; 3]> = opt
                    .st
                    .adj
                    .live_triangles()
                    .map(|t| opt.st.adj.triangle(t))
                    .collect();
                assert_eq!(now, tris);
            }
        }
        assert!(rejected > 0);
        opt.verify(&setup, &opts).unwrap();
    }

    #[test]
    fn swaps_and_teleports_keep_the_vertex_count_and_the_invariants() {
        let (mut opt, setup, opts) = optimizer();
        let n = live(&opt);
        let (mut swaps, mut teleports) = (0, 0);
        for (k, e) in opt.st.adj.edges().into_iter().enumerate().take(80) {
            if opt.st.adj.edge_triangles(e.0, e.1).is_empty() {
                continue;
            }
            let level = (k % 4) as u8;
            if let Some(d) = opt.swap(e, level) {
                swaps += (d < 0) as usize;
            }
            if opt.st.adj.edge_triangles(e.0, e.1).is_empty() {
                continue;
            }
            if let Some(d) = opt.teleport(e, level) {
                teleports += (d != 0) as usize;
            }
            assert_eq!(live(&opt), n, "after edge {e:?}");
            opt.st.adj.check().unwrap();
        }
        assert!(
            swaps > 0 && teleports > 0,
            "{swaps} swaps, {teleports} teleports"
        );
        opt.verify(&setup, &opts).unwrap();
    }

    #[test]
    fn the_collapse_queue_orders_by_energy_then_level() {
        let mut q = CollapseQueue::new(&[(0, 1), (1, 2), (2, 3)]);
        q.set((2, 1), 50, 0);
        q.set((3, 2), -5, 1);
        assert_eq!(q.pop(), Some(((2, 3), -5, 1)));
        assert_eq!(q.pop(), Some(((0, 1), 0, -1)));
        assert_eq!(q.pop(), Some(((1, 2), 50, 0)));
        assert_eq!(q.pop(), None);
        // Edges at the highest level are not offered.
        q.set((4, 5), -100, COLLAPSE_MAX_LEVEL);
        assert_eq!(q.pop(), None);
    }
}
