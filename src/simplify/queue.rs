//! The edge-collapse engine's priority queue: a radix heap over the costs' float bits, with a
//! 4-ary min-heap for the entries that tie with the last key popped.
//!
//! Based on: Ahuja, Mehlhorn, Orlin, Tarjan. Faster Algorithms for the Shortest Path Problem.
//! JACM 1990 (the radix heap).
//!
//! Why a radix heap: on meshes of a few hundred thousand triangles the queue holds millions of
//! entries, and a comparison heap pays a cache miss per level on every pop (about 9 of them for
//! 100 000 entries), plus a linear purge of the stale entries now and then. A radix heap keeps
//! its entries in 33 buckets by the highest bit in which their key differs from the last key
//! popped: a push appends to a bucket, and a pop that finds bucket 0 empty takes the first
//! non-empty bucket, finds its least key and spreads its entries over the lower buckets,
//! dropping the stale ones on the way (the purge comes free). Each entry moves at most 32
//! times, and all moves are sequential.
//!
//! A radix heap needs keys that never fall below the last key popped. A collapse can make a
//! neighbouring edge cheaper than the collapse just made (rarely); such an entry is queued at
//! the last key instead, which is where a comparison heap would pop it too (next), except among
//! entries that tie at that key. Entries with equal keys pop in their full order (a 4-ary
//! min-heap holds bucket 0), so the pop sequence is deterministic.

/// An entry of a [`RadixQueue`]: its key (smaller pops first), which the queue may raise.
pub(crate) trait Keyed {
    /// The key.
    fn key(&self) -> u32;
    /// Raise the key to `k` (never lowers it).
    fn raise_key(&mut self, k: u32);
}

/// A monotone priority queue: [`RadixQueue::pop`] returns the entry with the least key (then the
/// least in `T`'s order), among entries whose keys are at least the last key popped.
#[derive(Debug, Clone)]
pub(crate) struct RadixQueue<T> {
    last: u32,
    /// Entries whose key equals `last`.
    low: MinQueue<T>,
    /// Bucket i holds the entries whose key's highest bit differing from `last` is bit i.
    buckets: [Vec<T>; 32],
}

impl<T: Keyed + Ord + Copy> RadixQueue<T> {
    /// A queue of `items`.
    pub fn from_vec(items: Vec<T>) -> RadixQueue<T> {
        let mut q = RadixQueue {
            last: 0,
            low: MinQueue { items: Vec::new() },
            buckets: std::array::from_fn(|_| Vec::new()),
        };
        for x in items {
            q.push(x);
        }
        q
    }

    /// Number of entries.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.low.len() + self.buckets.iter().map(Vec::len).sum::<usize>()
    }

    /// Add an entry (a key below the last one popped is raised to it).
    #[inline]
    pub fn push(&mut self, mut x: T) {
        if x.key() < self.last {
            x.raise_key(self.last);
        }
        let differ = x.key() ^ self.last;
        if differ == 0 {
            self.low.push(x);
        } else {
            self.buckets[31 - differ.leading_zeros() as usize].push(x);
        }
    }

    /// Remove and return the least entry for which `keep` holds; entries for which it fails
    /// may be dropped on the way (never returned).
    pub fn pop(&mut self, keep: impl Fn(&T) -> bool) -> Option<T> {
        loop {
            while let Some(x) = self.low.pop() {
                if keep(&x) {
                    return Some(x);
                }
            }
            let i = self.buckets.iter().position(|b| !b.is_empty())?;
            let mut items = std::mem::take(&mut self.buckets[i]);
            items.retain(&keep);
            let Some(least) = items.iter().map(Keyed::key).min() else {
                // All stale: give the emptied vector back for its room.
                self.buckets[i] = items;
                continue;
            };
            self.last = least;
            for x in items.drain(..) {
                let differ = x.key() ^ least;
                if differ == 0 {
                    self.low.push(x);
                } else {
                    self.buckets[31 - differ.leading_zeros() as usize].push(x);
                }
            }
            self.buckets[i] = items;
        }
    }
}

/// A [`RadixQueue`] that pops a few entries ahead of time, so that the caller can ask for their
/// data's cache lines while it works on the current one (the engine's collapses are spread over
/// the whole mesh, so each one starts with cache misses).
///
/// Entries pushed below the last key taken from the radix queue wait in a small heap of their
/// own, so every entry comes out in key order (entries with equal keys in the order they reach
/// the front).
#[derive(Debug, Clone)]
pub(crate) struct Lookahead<T> {
    queue: RadixQueue<T>,
    early: MinQueue<T>,
    ahead: std::collections::VecDeque<T>,
    depth: usize,
}

impl<T: Keyed + Ord + Copy> Lookahead<T> {
    /// A queue of `items` that keeps `depth` entries popped ahead.
    pub fn new(items: Vec<T>, depth: usize) -> Lookahead<T> {
        Lookahead {
            queue: RadixQueue::from_vec(items),
            early: MinQueue { items: Vec::new() },
            ahead: std::collections::VecDeque::with_capacity(depth),
            depth,
        }
    }

    /// Add an entry.
    #[inline]
    pub fn push(&mut self, x: T) {
        if x.key() < self.queue.last {
            self.early.push(x);
        } else {
            self.queue.push(x);
        }
    }

    /// The `i`-th entry popped ahead (0: the one that comes out next, unless an entry pushed
    /// since beats it).
    pub fn ahead(&self, i: usize) -> Option<&T> {
        self.ahead.get(i)
    }

    /// Remove and return the least entry for which `keep` holds (others may be dropped on the
    /// way). Entries newly popped ahead are handed to `fetch` first.
    pub fn pop(&mut self, keep: impl Fn(&T) -> bool, mut fetch: impl FnMut(&T)) -> Option<T> {
        loop {
            // Refilled on every turn: the entries popped ahead may all have gone stale since,
            // and the queue is only empty when the radix queue is too (it once ended a run
            // early when `depth` stale entries in a row were dropped here).
            while self.ahead.len() < self.depth {
                match self.queue.pop(&keep) {
                    Some(x) => {
                        fetch(&x);
                        self.ahead.push_back(x);
                    }
                    None => break,
                }
            }
            let take_early = match (self.early.peek(), self.ahead.front()) {
                (Some(e), Some(a)) => e < a,
                (Some(_), None) => true,
                (None, Some(_)) => false,
                (None, None) => return None,
            };
            let x = if take_early {
                self.early.pop()
            } else {
                self.ahead.pop_front()
            };
            match x {
                Some(x) if keep(&x) => return Some(x),
                _ => {}
            }
        }
    }
}

/// Children per node.
const D: usize = 4;

/// A min-heap: [`MinQueue::pop`] returns the smallest entry.
#[derive(Debug, Clone)]
pub(crate) struct MinQueue<T> {
    items: Vec<T>,
}

impl<T: Ord + Copy> MinQueue<T> {
    /// Number of entries.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Add an entry.
    pub fn push(&mut self, x: T) {
        self.items.push(x);
        self.sift_up(self.items.len() - 1);
    }

    /// The smallest entry.
    pub fn peek(&self) -> Option<&T> {
        self.items.first()
    }

    /// Remove and return the smallest entry.
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
        // Any interleaving of pushes and pops gives the same pops as std's BinaryHeap.
        #[test]
        fn pops_like_a_binary_heap(
            start in proptest::collection::vec(0u32..1000, 0..200),
            ops in proptest::collection::vec((0u8..2, 0u32..1000), 0..400),
        ) {
            let mut q = MinQueue { items: Vec::new() };
            for &x in &start {
                q.push(x);
            }
            let mut reference: BinaryHeap<Reverse<u32>> = start.into_iter().map(Reverse).collect();
            for (op, x) in ops {
                match op {
                    0 => {
                        q.push(x);
                        reference.push(Reverse(x));
                    }
                    _ => prop_assert_eq!(q.pop(), reference.pop().map(|r| r.0)),
                }
                prop_assert_eq!(q.len(), reference.len());
            }
            while let Some(r) = reference.pop() {
                prop_assert_eq!(q.pop(), Some(r.0));
            }
            prop_assert_eq!(q.pop(), None);
        }

        // Pushes that never go below the last key popped, pops and dropped entries: the radix
        // queue pops what a comparison heap pops (the least kept entry), in the same order.
        #[test]
        fn radix_pops_like_a_binary_heap(
            start in proptest::collection::vec((0u32..1 << 20, 0u32..4), 0..200),
            ops in proptest::collection::vec((0u8..2, 0u32..1 << 20, 0u32..4), 0..400),
        ) {
            let keep = |x: &(u32, u32)| x.1 != 3;
            let mut q = RadixQueue::from_vec(start.clone());
            let mut reference: BinaryHeap<Reverse<(u32, u32)>> = start.into_iter().map(Reverse).collect();
            let mut last = 0;
            for (op, k, tag) in ops {
                if op == 0 {
                    // Keys below the last pop are raised to it, as the queue documents.
                    let x = (k.max(last), tag);
                    q.push(x);
                    reference.push(Reverse(x));
                } else {
                    let mut want = None;
                    while let Some(Reverse(x)) = reference.pop() {
                        if keep(&x) {
                            want = Some(x);
                            break;
                        }
                    }
                    let got = q.pop(keep);
                    prop_assert_eq!(got, want);
                    if let Some(x) = got {
                        last = x.0;
                    }
                }
            }
        }
    }

    impl Keyed for (u32, u32) {
        fn key(&self) -> u32 {
            self.0
        }
        fn raise_key(&mut self, k: u32) {
            self.0 = self.0.max(k);
        }
    }

    #[test]
    fn a_key_below_the_last_pop_comes_next() {
        let mut q = RadixQueue::from_vec(vec![(5u32, 0u32), (9, 0)]);
        assert_eq!(q.pop(|_| true), Some((5, 0)));
        q.push((2, 1));
        assert_eq!(q.pop(|_| true), Some((5, 1)));
        assert_eq!(q.pop(|_| true), Some((9, 0)));
        assert_eq!(q.len(), 0);
    }

    #[test]
    fn entries_popped_ahead_that_went_stale_do_not_end_the_queue() {
        // Depth 4: the first pop takes 0 and pops 1..=4 ahead. Those then go stale (as a
        // collapse makes its neighbours' entries stale); the queue still holds 5..10, and the
        // next pop must return 5, not report an empty queue.
        let mut q = Lookahead::new((0u32..10).map(|k| (k, 0u32)).collect(), 4);
        assert_eq!(q.pop(|_| true, |_| {}), Some((0, 0)));
        let fresh = |x: &(u32, u32)| x.0 >= 5;
        assert_eq!(q.pop(fresh, |_| {}), Some((5, 0)));
        let rest: Vec<u32> = std::iter::from_fn(|| q.pop(fresh, |_| {}).map(|x| x.0)).collect();
        assert_eq!(rest, vec![6, 7, 8, 9]);
    }
}
