//! Best-effort refinement of an MT cut to a triangle budget (Williams et al. 2003 §5.1): the
//! dual-queue algorithm (after Duchaineau et al.'s ROAM), which keeps the cut and both queues from
//! one view to the next (temporal coherence).
//!
//! In the collapse form of the MT: a node is *applied* when its collapse is in the current mesh.
//! *Raising* (refining) a node undoes its collapse; it needs every applied dependent undone first.
//! *Lowering* (simplifying) re-applies it; it needs every prerequisite applied first. Both are
//! forced recursively, as the paper describes. The raise queue R holds applied nodes none of whose
//! dependents is applied (directly below the cut, largest error first); the lower queue L holds
//! unapplied nodes all of whose prerequisites are applied (directly above, smallest error first).
//!
//! Each frame: keys of both queues are recomputed for the new view; then, as in the paper's
//! `simplifyBudget`, lower the smallest-error node while over budget and raise the largest-error
//! node while within it, until the node just raised is the next to be lowered. The result always fits the budget.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use super::hierarchy::{Hierarchy, NONE};

/// A heap entry ordered by key, then node id (so runs are deterministic).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Entry(f64, u32);
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Entry {
    fn cmp(&self, o: &Self) -> Ordering {
        self.0.total_cmp(&o.0).then(o.1.cmp(&self.1))
    }
}

/// A cut of the MT and its two queues.
#[derive(Debug, Clone)]
pub struct Cut {
    applied: Vec<bool>,
    /// Per node: applied dependents.
    applied_dependents: Vec<u32>,
    /// Per node: unapplied prerequisites.
    missing_prerequisites: Vec<u32>,
    triangles: usize,
    raise: BinaryHeap<Entry>,
    lower: BinaryHeap<std::cmp::Reverse<Entry>>,
    keys: Vec<f64>,
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
        let applied_dependents = (0..n as u32)
            .map(|i| h.dependents(i).len() as u32)
            .collect();
        let triangles = h.tris.iter().filter(|t| t.remover == NONE).count();
        Cut {
            applied: vec![true; n],
            applied_dependents,
            missing_prerequisites: vec![0; n],
            triangles,
            raise: BinaryHeap::new(),
            lower: BinaryHeap::new(),
            keys: vec![0.0; n],
            key_frame: vec![0; n],
            frame: 0,
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

    fn raisable(&self, n: u32) -> bool {
        self.applied[n as usize] && self.applied_dependents[n as usize] == 0
    }

    fn lowerable(&self, n: u32) -> bool {
        !self.applied[n as usize] && self.missing_prerequisites[n as usize] == 0
    }

    /// Node `n`'s key for the current frame (computed once per frame).
    fn key_of(&mut self, n: u32, key: &dyn Fn(u32) -> f64) -> f64 {
        if self.key_frame[n as usize] != self.frame {
            self.key_frame[n as usize] = self.frame;
            self.keys[n as usize] = key(n);
        }
        self.keys[n as usize]
    }

    fn enqueue(&mut self, n: u32, key: &dyn Fn(u32) -> f64) {
        if self.raisable(n) || self.lowerable(n) {
            self.key_of(n, key);
        }
        if self.raisable(n) {
            self.raise.push(Entry(self.keys[n as usize], n));
        } else if self.lowerable(n) {
            self.lower
                .push(std::cmp::Reverse(Entry(self.keys[n as usize], n)));
        }
    }

    /// Flip node `n` (its own constraints must hold) and update the counters and queues.
    fn flip(&mut self, h: &Hierarchy, n: u32, apply: bool, key: &dyn Fn(u32) -> f64) {
        self.applied[n as usize] = apply;
        let delta = h.removed(n).len() as isize - h.created(n).len() as isize;
        self.triangles = (self.triangles as isize + if apply { -delta } else { delta }) as usize;
        for &p in h.prerequisites(n) {
            if apply {
                self.applied_dependents[p as usize] += 1;
            } else {
                self.applied_dependents[p as usize] -= 1;
                self.enqueue(p, key);
            }
        }
        for &d in h.dependents(n) {
            if apply {
                self.missing_prerequisites[d as usize] -= 1;
                self.enqueue(d, key);
            } else {
                self.missing_prerequisites[d as usize] += 1;
            }
        }
        self.enqueue(n, key);
        self.last_changes += 1;
    }

    /// Undo node `n`'s collapse, first undoing every applied dependent (recursively).
    pub fn raise(&mut self, h: &Hierarchy, n: u32, key: &dyn Fn(u32) -> f64) {
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
    pub fn lower(&mut self, h: &Hierarchy, n: u32, key: &dyn Fn(u32) -> f64) {
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

    fn peek_lower(&mut self) -> Option<u32> {
        while let Some(std::cmp::Reverse(Entry(k, n))) = self.lower.peek().copied() {
            if self.lowerable(n) && k == self.keys[n as usize] {
                return Some(n);
            }
            self.lower.pop();
        }
        None
    }

    /// Re-key the queues with `key` (this view's errors) and refine to `budget` triangles.
    pub fn adapt(&mut self, h: &Hierarchy, budget: usize, key: &dyn Fn(u32) -> f64) {
        self.last_changes = 0;
        // updateErrorKeys: a new frame; every node on either side of the cut is re-keyed (nodes
        // that join a queue later are keyed when they join).
        self.frame = self.frame.wrapping_add(1);
        self.raise.clear();
        self.lower.clear();
        for n in 0..h.node_count() as u32 {
            self.enqueue(n, key);
        }
        // The paper's loop: lower the smallest while over budget, raise the largest while within
        // it, until the node just raised is lowered again. A step limit guards against cycles
        // among equal keys.
        let limit = 4 * h.node_count() + 16;
        let mut steps = 0;
        let mut lifted = NONE;
        loop {
            let mut dropped_lifted = false;
            while self.triangles > budget {
                let Some(drop) = self.peek_lower() else { break };
                self.lower.pop();
                dropped_lifted |= drop == lifted;
                self.lower(h, drop, key);
            }
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
    }

    /// Refine the coarsest-first until every raisable node's key is at most `threshold` (a static
    /// LOD for a distance: every node that would be visible from `threshold` is refined).
    pub fn refine_above(&mut self, h: &Hierarchy, threshold: f64, key: &dyn Fn(u32) -> f64) {
        self.frame = self.frame.wrapping_add(1);
        self.raise.clear();
        self.lower.clear();
        for n in 0..h.node_count() as u32 {
            self.enqueue(n, key);
        }
        while let Some(lift) = self.pop_raise() {
            if self.keys[lift as usize] <= threshold {
                break;
            }
            self.raise(h, lift, key);
        }
    }
}
