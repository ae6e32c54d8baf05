//! Best-effort refinement of an MT cut to a triangle budget (Williams et al. 2003 §5.1): the
//! dual-queue algorithm (after Duchaineau et al.'s ROAM), which keeps the cut and both queues from
//! one view to the next (temporal coherence).
//!
//! In the collapse form of the MT: a node is *applied* when its collapse is in the current mesh.
//! *Raising* (refining) a node undoes its collapse; it needs every applied dependent undone first.
//! *Lowering* (simplifying) re-applies it; it needs every prerequisite applied first. Both are
//! forced recursively, as the paper describes ("lifting a node may require lifting parent nodes
//! that are below the cut"). The raise queue R holds the applied nodes directly below the cut — at
//! least one triangle they created is in the mesh — largest error first; the lower queue L holds
//! the unapplied nodes directly above it — at least one triangle they remove is in the mesh —
//! smallest error first.
//!
//! Decision, measured: queues restricted to nodes whose raise (or lower) needs nothing else fail
//! on MTs built from a sequence of edge collapses, whose dependency chains are long: at a budget
//! of 2 % of the bunny, only 12 nodes could be raised directly, all back-facing (key 0), while
//! silhouette nodes with large keys sat behind them; the refinement stalled at an LOD with nothing
//! visible refined.
//!
//! Each frame: keys of both queues are recomputed for the new view; then, as in the paper's
//! `simplifyBudget`, lower the smallest-error node while over budget and raise the largest-error
//! node while within it, until the node just raised is lowered again. A lowering is keyed by the
//! largest key among the nodes it forces (else the cheapest-looking lowering often re-applies the
//! node just raised and the loop ends after one step). Budget left over when the loop ends goes to
//! the largest-error raises that force nothing and fit. The result always fits the budget.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use super::hierarchy::{Hierarchy, NONE};

/// A node's error: (primary, tie-break), compared lexicographically. The perceptual criterion
/// clamps frequencies at the CSF peak, so every large silhouette node has the same distance; the
/// second component (the unclamped distance) orders those by size.
pub type Key = [f64; 2];

fn key_cmp(a: &Key, b: &Key) -> Ordering {
    a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1]))
}

/// A heap entry ordered by key, then node id (so runs are deterministic).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Entry(Key, u32);
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Entry {
    fn cmp(&self, o: &Self) -> Ordering {
        key_cmp(&self.0, &o.0).then(o.1.cmp(&self.1))
    }
}

/// A cut of the MT and its two queues.
#[derive(Debug, Clone)]
pub struct Cut {
    applied: Vec<bool>,
    /// Per node: its created triangles that are in the mesh.
    alive_created: Vec<u32>,
    /// Per node: its removed triangles that are in the mesh.
    alive_removed: Vec<u32>,
    /// Per node: it creates no triangle (a last collapse that removes a surface's final triangles
    /// is adjacent to the source, whatever the cut).
    creates_nothing: Vec<bool>,
    triangles: usize,
    raise: BinaryHeap<Entry>,
    lower: BinaryHeap<std::cmp::Reverse<Entry>>,
    keys: Vec<Key>,
    /// The view (frame) number a node's key was computed for.
    key_frame: Vec<u32>,
    frame: u32,
    /// Nodes raised or lowered during the last `adapt` (for reports and tests).
    pub last_changes: usize,
}

impl Cut {
    /// The coarsest cut (every collapse applied), as the paper starts from the source.
    pub fn coarsest(h: &Hierarchy) -> Cut {
        let n = h.node_count();
        let alive_created = (0..n as u32)
            .map(|i| {
                h.created(i)
                    .iter()
                    .filter(|&&t| h.tris[t as usize].remover == NONE)
                    .count() as u32
            })
            .collect();
        let triangles = h.tris.iter().filter(|t| t.remover == NONE).count();
        Cut {
            applied: vec![true; n],
            alive_created,
            alive_removed: vec![0; n],
            creates_nothing: (0..n as u32).map(|i| h.created(i).is_empty()).collect(),
            triangles,
            raise: BinaryHeap::new(),
            lower: BinaryHeap::new(),
            keys: vec![[0.0; 2]; n],
            key_frame: vec![0; n],
            // Frame 0 is "never keyed": the first `adapt` starts frame 2.
            frame: 1,
            last_changes: 0,
        }
    }

    /// Triangles in the cut's mesh.
    pub fn triangles(&self) -> usize {
        self.triangles
    }

    /// Whether node `n`'s collapse is applied.
    pub fn is_applied(&self, n: u32) -> bool {
        self.applied[n as usize]
    }

    /// Whether MT triangle `t` is in the cut's mesh.
    pub fn is_alive(&self, h: &Hierarchy, t: u32) -> bool {
        let tri = &h.tris[t as usize];
        (tri.creator == NONE || self.applied[tri.creator as usize])
            && (tri.remover == NONE || !self.applied[tri.remover as usize])
    }

    /// Directly below the cut.
    fn raisable(&self, n: u32) -> bool {
        self.applied[n as usize]
            && (self.alive_created[n as usize] > 0 || self.creates_nothing[n as usize])
    }

    /// Directly above the cut.
    fn lowerable(&self, n: u32) -> bool {
        !self.applied[n as usize] && self.alive_removed[n as usize] > 0
    }

    /// Node `n`'s key for the current frame (computed once per frame).
    fn key_of(&mut self, n: u32, key: &dyn Fn(u32) -> Key) -> Key {
        if self.key_frame[n as usize] != self.frame {
            self.key_frame[n as usize] = self.frame;
            self.keys[n as usize] = key(n);
        }
        self.keys[n as usize]
    }

    /// What lowering `n` costs: the largest key among `n` and the unapplied prerequisites its
    /// lowering forces first. Without this, the node with the smallest key is often one whose
    /// lowering re-applies the node just raised, and the loop stops after one step.
    fn lower_key(&mut self, h: &Hierarchy, n: u32, key: &dyn Fn(u32) -> Key) -> Key {
        let mut k = self.key_of(n, key);
        for &p in h.prerequisites(n) {
            if !self.applied[p as usize] {
                let kp = self.key_of(p, key);
                if key_cmp(&kp, &k) == Ordering::Greater {
                    k = kp;
                }
            }
        }
        k
    }

    fn enqueue(&mut self, h: &Hierarchy, n: u32, key: &dyn Fn(u32) -> Key) {
        if self.raisable(n) {
            let k = self.key_of(n, key);
            self.raise.push(Entry(k, n));
        } else if self.lowerable(n) {
            let k = self.lower_key(h, n, key);
            self.lower.push(std::cmp::Reverse(Entry(k, n)));
        }
    }

    /// Flip node `n` (its own constraints must hold) and update the counters and queues.
    fn flip(&mut self, h: &Hierarchy, n: u32, apply: bool, key: &dyn Fn(u32) -> Key) {
        self.applied[n as usize] = apply;
        let delta = h.removed(n).len() as isize - h.created(n).len() as isize;
        self.triangles = (self.triangles as isize + if apply { -delta } else { delta }) as usize;
        // n's removed triangles die (apply) or return; its created ones the reverse. Each one's
        // creator and remover see their counts change.
        let step = |c: &mut u32, up: bool| {
            if up { *c += 1 } else { *c -= 1 }
        };
        let mut touched = vec![n];
        for &t in h.removed(n) {
            let creator = h.tris[t as usize].creator;
            if creator != NONE {
                step(&mut self.alive_created[creator as usize], !apply);
                touched.push(creator);
            }
            step(&mut self.alive_removed[n as usize], !apply);
        }
        for &t in h.created(n) {
            let remover = h.tris[t as usize].remover;
            if remover != NONE {
                step(&mut self.alive_removed[remover as usize], apply);
                touched.push(remover);
            }
            step(&mut self.alive_created[n as usize], apply);
        }
        touched.sort_unstable();
        touched.dedup();
        for m in touched {
            self.enqueue(h, m, key);
        }
        self.last_changes += 1;
    }

    /// Undo node `n`'s collapse, first undoing every applied dependent (recursively).
    pub fn raise(&mut self, h: &Hierarchy, n: u32, key: &dyn Fn(u32) -> Key) {
        let mut stack = vec![n];
        while let Some(&m) = stack.last() {
            if !self.applied[m as usize] {
                stack.pop();
                continue;
            }
            match h.dependents(m).iter().find(|&&d| self.applied[d as usize]) {
                Some(&d) => stack.push(d),
                None => {
                    stack.pop();
                    self.flip(h, m, false, key);
                }
            }
        }
    }

    /// Apply node `n`'s collapse, first applying every missing prerequisite (recursively).
    pub fn lower(&mut self, h: &Hierarchy, n: u32, key: &dyn Fn(u32) -> Key) {
        let mut stack = vec![n];
        while let Some(&m) = stack.last() {
            if self.applied[m as usize] {
                stack.pop();
                continue;
            }
            match h
                .prerequisites(m)
                .iter()
                .find(|&&p| !self.applied[p as usize])
            {
                Some(&p) => stack.push(p),
                None => {
                    stack.pop();
                    self.flip(h, m, true, key);
                }
            }
        }
    }

    fn pop_raise(&mut self) -> Option<u32> {
        while let Some(Entry(k, n)) = self.raise.pop() {
            if self.raisable(n) && k == self.keys[n as usize] {
                return Some(n);
            }
        }
        None
    }

    fn peek_lower(&mut self, h: &Hierarchy, key: &dyn Fn(u32) -> Key) -> Option<u32> {
        while let Some(std::cmp::Reverse(Entry(k, n))) = self.lower.peek().copied() {
            if self.lowerable(n) && k == self.lower_key(h, n, key) {
                return Some(n);
            }
            self.lower.pop();
        }
        None
    }

    /// Re-key the queues with `key` (this view's errors) and refine to `budget` triangles.
    pub fn adapt(&mut self, h: &Hierarchy, budget: usize, key: &dyn Fn(u32) -> Key) {
        self.last_changes = 0;
        // updateErrorKeys: a new frame; every node on either side of the cut is re-keyed (nodes
        // that join a queue later are keyed when they join).
        self.frame = self.frame.wrapping_add(1);
        self.raise.clear();
        self.lower.clear();
        for n in 0..h.node_count() as u32 {
            self.enqueue(h, n, key);
        }
        // The paper's loop: lower the smallest while over budget, raise the largest while within
        // it, until the node just raised is lowered again — directly, or because lowering a node
        // forced it. A step limit guards against longer cycles.
        let limit = 4 * h.node_count() + 16;
        let mut steps = 0;
        let mut lifted = NONE;
        loop {
            while self.triangles > budget {
                let Some(drop) = self.peek_lower(h, key) else {
                    break;
                };
                self.lower.pop();
                self.lower(h, drop, key);
            }
            let dropped_lifted = lifted != NONE && self.applied[lifted as usize];
            if dropped_lifted || steps > limit {
                break;
            }
            let mut raised = false;
            while self.triangles <= budget {
                let Some(lift) = self.pop_raise() else { break };
                self.raise(h, lift, key);
                lifted = lift;
                raised = true;
                steps += 1;
            }
            if !raised || self.triangles <= budget {
                break;
            }
        }
        self.fill(h, budget, key);
    }

    /// Best effort: the loop stops when a raise would only be undone, which can leave part of the
    /// budget unused; spend it on the largest-error raises that need no other raise first (they
    /// add exactly their own triangles) and still fit.
    fn fill(&mut self, h: &Hierarchy, budget: usize, key: &dyn Fn(u32) -> Key) {
        let mut skipped = Vec::new();
        while self.triangles < budget {
            let Some(lift) = self.pop_raise() else { break };
            let grows = h.removed(lift).len().saturating_sub(h.created(lift).len());
            let free = h
                .dependents(lift)
                .iter()
                .all(|&d| !self.applied[d as usize]);
            if free && self.triangles + grows <= budget {
                self.raise(h, lift, key);
            } else {
                skipped.push(lift);
            }
        }
        // Put the skipped nodes back so the queues stay complete for the next frame.
        for n in skipped {
            self.enqueue(h, n, key);
        }
    }

    /// The largest key among the nodes that could be raised (the cut's error: for the
    /// perceptual criterion, the LOD's imperceptibility distance), with this frame's keys.
    pub fn error(&self, h: &Hierarchy, key: &dyn Fn(u32) -> Key) -> f64 {
        (0..h.node_count() as u32)
            .filter(|&n| self.raisable(n))
            .map(|n| key(n)[0])
            .fold(0.0, f64::max)
    }

    /// Refine the coarsest-first until every raisable node's key is at most `threshold` (a static
    /// LOD for a distance: every node that would be visible from `threshold` is refined).
    pub fn refine_above(&mut self, h: &Hierarchy, threshold: f64, key: &dyn Fn(u32) -> Key) {
        self.frame = self.frame.wrapping_add(1);
        self.raise.clear();
        self.lower.clear();
        for n in 0..h.node_count() as u32 {
            self.enqueue(h, n, key);
        }
        while let Some(lift) = self.pop_raise() {
            if self.keys[lift as usize][0] <= threshold {
                break;
            }
            self.raise(h, lift, key);
        }
    }
}
