//! The edge-collapse engine's priority queue: a 4-ary min-heap.
//!
//! Why not `std::collections::BinaryHeap`: on meshes of a few hundred thousand triangles the
//! queue holds millions of entries, and popping from a binary heap is one cache miss per level
//! (about 20 of them). Four children per node halve the depth, and the four candidates of a level
//! sit next to each other in memory. Pops use Floyd's trick (walk the hole down to a leaf by the
//! smaller child, then sift the last element up), which saves a comparison per level.
//!
//! Entries are totally ordered and unique in the engine, so the pop sequence — and with it the
//! collapse sequence — is the same as any other correct priority queue would give.

/// Children per node.
const D: usize = 4;

/// A min-heap: [`MinQueue::pop`] returns the smallest entry.
#[derive(Debug, Clone, Default)]
pub(crate) struct MinQueue<T> {
    items: Vec<T>,
}

impl<T: Ord + Copy> MinQueue<T> {
    /// A queue of `items` (heapified in linear time).
    pub fn from_vec(items: Vec<T>) -> MinQueue<T> {
        let mut q = MinQueue { items };
        let n = q.items.len();
        if n > 1 {
            for i in (0..=(n - 2) / D).rev() {
                q.sift_down(i);
            }
        }
        q
    }

    /// Number of entries.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Add an entry.
    pub fn push(&mut self, x: T) {
        self.items.push(x);
        self.sift_up(self.items.len() - 1);
    }

    /// Remove and return the smallest entry.
    #[inline(never)]
    pub fn pop(&mut self) -> Option<T> {
        let last = self.items.pop()?;
        if self.items.is_empty() {
            return Some(last);
        }
        let top = self.items[0];
        // Floyd: move the smaller child up until the hole reaches a leaf, then put `last` there
        // and sift it up (it usually stays near the bottom).
        let mut hole = 0;
        while let Some(best) = self.smallest_child(hole) {
            self.items[hole] = self.items[best];
            hole = best;
        }
        self.items[hole] = last;
        self.sift_up(hole);
        Some(top)
    }

    /// Keep only the entries for which `keep` holds (linear time).
    pub fn retain(&mut self, keep: impl FnMut(&T) -> bool) {
        let mut items = std::mem::take(&mut self.items);
        items.retain(keep);
        *self = MinQueue::from_vec(items);
    }

    fn sift_up(&mut self, mut i: usize) {
        let x = self.items[i];
        while i > 0 {
            let parent = (i - 1) / D;
            if self.items[parent] <= x {
                break;
            }
            self.items[i] = self.items[parent];
            i = parent;
        }
        self.items[i] = x;
    }

    fn sift_down(&mut self, mut i: usize) {
        let x = self.items[i];
        while let Some(best) = self.smallest_child(i) {
            if x <= self.items[best] {
                break;
            }
            self.items[i] = self.items[best];
            i = best;
        }
        self.items[i] = x;
    }

    /// The index of node `i`'s smallest child, if it has children.
    #[inline(always)]
    fn smallest_child(&self, i: usize) -> Option<usize> {
        let n = self.items.len();
        let first = D * i + 1;
        if first >= n {
            return None;
        }
        let mut best = first;
        for c in first + 1..(first + D).min(n) {
            if self.items[c] < self.items[best] {
                best = c;
            }
        }
        Some(best)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;

    proptest! {
        // Any interleaving of pushes, pops and retains gives the same pops as std's BinaryHeap.
        #[test]
        fn pops_like_a_binary_heap(
            start in proptest::collection::vec(0u32..1000, 0..200),
            ops in proptest::collection::vec((0u8..3, 0u32..1000), 0..400),
        ) {
            let mut q = MinQueue::from_vec(start.clone());
            let mut reference: BinaryHeap<Reverse<u32>> = start.into_iter().map(Reverse).collect();
            for (op, x) in ops {
                match op {
                    0 => {
                        q.push(x);
                        reference.push(Reverse(x));
                    }
                    1 => prop_assert_eq!(q.pop(), reference.pop().map(|r| r.0)),
                    _ => {
                        q.retain(|&y| y % 7 != x % 7);
                        reference.retain(|r| r.0 % 7 != x % 7);
                    }
                }
                prop_assert_eq!(q.len(), reference.len());
            }
            while let Some(r) = reference.pop() {
                prop_assert_eq!(q.pop(), Some(r.0));
            }
            prop_assert_eq!(q.pop(), None);
        }
    }
}
