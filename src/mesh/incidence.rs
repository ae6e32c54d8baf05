//! Per-vertex lists of incident triangles, kept sorted ascending and packed into one arena: the
//! vertex → triangle side of [`super::edit::Adjacency`].
//!
//! Decision: one `Vec<u32>` for every list, with a start, a length and a capacity per vertex,
//! instead of one `Vec<u32>` per vertex. A mesh of 36 000 vertices then builds with one counting
//! sort instead of 36 000 allocations, clones with four copies (the edge-collapse engine keeps the
//! start structure of its progressive record), and the lists of neighbouring vertices sit near
//! each other in memory. A list that outgrows its room moves to the end of the arena with twice
//! the room; the room it leaves is garbage, and the arena is repacked when garbage is more than
//! half of it (so a list moves O(log valence) times, and memory stays within twice what is used).
//!
//! # Guarantees
//! - Each list is sorted ascending and holds no duplicates, as long as callers only insert ids
//!   the list does not hold (every caller in `mesh/edit/` does).
//! - Equality ([`PartialEq`]) compares the lists, not where they sit in the arena.

/// Room given to each list beyond its length when the lists are built, so that the first
/// collapses into a vertex (which add a few triangles) do not move its list.
const SLACK: u32 = 2;
/// The least room a moved or new list gets.
const MIN_ROOM: u32 = 8;

/// Sorted per-vertex triangle lists in one arena.
#[derive(Debug, Clone, Default)]
pub struct Incidence {
    start: Vec<u32>,
    len: Vec<u32>,
    room: Vec<u32>,
    data: Vec<u32>,
    /// Arena entries no list owns (left behind by moved lists and dropped vertices).
    garbage: usize,
}

impl PartialEq for Incidence {
    fn eq(&self, other: &Incidence) -> bool {
        self.len() == other.len() && (0..self.len() as u32).all(|v| self.get(v) == other.get(v))
    }
}

impl Incidence {
    /// The lists of `vertices` vertices over the triangles `tris` whose `alive` flag is set,
    /// each list ascending (a counting sort over the triangles in order).
    pub fn build(vertices: usize, tris: &[[u32; 3]], alive: &[bool]) -> Incidence {
        let mut len = vec![0u32; vertices];
        for (t, tri) in tris.iter().enumerate() {
            if alive[t] {
                for &v in tri {
                    len[v as usize] += 1;
                }
            }
        }
        let mut start = Vec::with_capacity(vertices);
        let mut room = Vec::with_capacity(vertices);
        let mut total = 0u32;
        for &l in &len {
            start.push(total);
            let r = l + SLACK;
            room.push(r);
            total += r;
        }
        let mut data = vec![u32::MAX; total as usize];
        let mut fill = vec![0u32; vertices];
        for (t, tri) in tris.iter().enumerate() {
            if alive[t] {
                for &v in tri {
                    let v = v as usize;
                    data[(start[v] + fill[v]) as usize] = t as u32;
                    fill[v] += 1;
                }
            }
        }
        Incidence {
            start,
            len,
            room,
            data,
            garbage: 0,
        }
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.start.len()
    }

    /// The triangles of vertex `v`, ascending.
    #[inline]
    pub fn get(&self, v: u32) -> &[u32] {
        let v = v as usize;
        let s = self.start[v] as usize;
        &self.data[s..s + self.len[v] as usize]
    }

    /// The arena slots of `v`'s list, for a hint to the cache.
    pub fn first(&self, v: u32) -> Option<&u32> {
        self.data.get(self.start[v as usize] as usize)
    }

    /// Add a vertex with an empty list; returns its id.
    pub fn push_vertex(&mut self) -> u32 {
        let v = self.start.len() as u32;
        self.start.push(self.data.len() as u32);
        self.len.push(0);
        self.room.push(MIN_ROOM);
        self.data
            .resize(self.data.len() + MIN_ROOM as usize, u32::MAX);
        v
    }

    /// Drop the vertices from `n` on.
    pub fn truncate(&mut self, n: usize) {
        if n < self.start.len() {
            self.garbage += self.room[n..].iter().map(|&r| r as usize).sum::<usize>();
            self.start.truncate(n);
            self.len.truncate(n);
            self.room.truncate(n);
        }
    }

    /// Make room for `n` entries in `v`'s list (moving it to the end of the arena if needed).
    fn reserve(&mut self, v: u32, n: u32) {
        let vi = v as usize;
        if n <= self.room[vi] {
            return;
        }
        let room = (2 * n).max(MIN_ROOM);
        // Repack first when the move would leave more garbage than half the arena (repacking
        // after the move would take the new room away again).
        if 2 * (self.garbage + self.room[vi] as usize) > self.data.len() + room as usize {
            self.repack();
            if n <= self.room[vi] {
                return;
            }
        }
        let (s, l) = (self.start[vi] as usize, self.len[vi] as usize);
        let new_start = self.data.len();
        self.data.extend_from_within(s..s + l);
        self.data.resize(new_start + room as usize, u32::MAX);
        self.garbage += self.room[vi] as usize;
        self.start[vi] = new_start as u32;
        self.room[vi] = room;
    }

    /// Copy every list into a fresh arena with `SLACK` room beyond its length (none for an empty
    /// list, as a collapsed vertex's is), dropping the garbage.
    fn repack(&mut self) {
        let mut data = Vec::with_capacity(self.data.len() - self.garbage);
        for v in 0..self.start.len() {
            let (s, l) = (self.start[v] as usize, self.len[v] as usize);
            self.start[v] = data.len() as u32;
            data.extend_from_slice(&self.data[s..s + l]);
            let room = if l == 0 { 0 } else { l as u32 + SLACK };
            data.resize(data.len() + (room as usize - l), u32::MAX);
            self.room[v] = room;
        }
        self.garbage = 0;
        self.data = data;
    }

    /// Replace `v`'s list with `items` (ascending).
    pub fn set(&mut self, v: u32, items: &[u32]) {
        debug_assert!(items.is_sorted());
        self.reserve(v, items.len() as u32);
        let s = self.start[v as usize] as usize;
        self.data[s..s + items.len()].copy_from_slice(items);
        self.len[v as usize] = items.len() as u32;
    }

    /// Insert `t` into `v`'s list at its sorted place (`t` must not be in it).
    pub fn insert(&mut self, v: u32, t: u32) {
        let l = self.len[v as usize];
        self.reserve(v, l + 1);
        let s = self.start[v as usize] as usize;
        let list = &mut self.data[s..s + l as usize + 1];
        let at = list[..l as usize].partition_point(|&x| x < t);
        debug_assert!(
            list.get(at) != Some(&t) || at == l as usize,
            "{t} is already listed"
        );
        list.copy_within(at..l as usize, at + 1);
        list[at] = t;
        self.len[v as usize] = l + 1;
    }

    /// Remove `t` from `v`'s list, keeping the order (nothing happens if it is not there).
    pub fn remove(&mut self, v: u32, t: u32) {
        let (s, l) = (
            self.start[v as usize] as usize,
            self.len[v as usize] as usize,
        );
        let list = &mut self.data[s..s + l];
        if let Some(at) = list.iter().position(|&x| x == t) {
            list.copy_within(at + 1.., at);
            self.len[v as usize] -= 1;
        }
    }

    /// Empty `v`'s list.
    pub fn clear(&mut self, v: u32) {
        self.len[v as usize] = 0;
    }

    /// Merge the ascending `items` (none already in the list) into `v`'s list.
    pub fn merge(&mut self, v: u32, items: &[u32]) {
        debug_assert!(items.is_sorted());
        let l = self.len[v as usize] as usize;
        self.reserve(v, (l + items.len()) as u32);
        let s = self.start[v as usize] as usize;
        let list = &mut self.data[s..s + l + items.len()];
        // Merge from the back, so nothing is overwritten before it is read.
        let (mut i, mut j, mut k) = (l, items.len(), l + items.len());
        while j > 0 {
            if i > 0 && list[i - 1] > items[j - 1] {
                list[k - 1] = list[i - 1];
                i -= 1;
            } else {
                list[k - 1] = items[j - 1];
                j -= 1;
            }
            k -= 1;
        }
        self.len[v as usize] = (l + items.len()) as u32;
    }

    /// Drop the items of `drop` from `v`'s list, then merge the ascending `items` into it.
    pub fn retain_merge(&mut self, v: u32, drop: &[u32], items: &[u32]) {
        let (s, l) = (
            self.start[v as usize] as usize,
            self.len[v as usize] as usize,
        );
        let list = &mut self.data[s..s + l];
        let mut kept = 0;
        for i in 0..l {
            let t = list[i];
            if !drop.contains(&t) {
                list[kept] = t;
                kept += 1;
            }
        }
        self.len[v as usize] = kept as u32;
        self.merge(v, items);
    }

    /// Every list as its own vector (for tests and comparisons).
    pub fn to_vecs(&self) -> Vec<Vec<u32>> {
        (0..self.len() as u32)
            .map(|v| self.get(v).to_vec())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        // Any sequence of inserts, removes, merges, sets, new vertices and truncations leaves the
        // same lists as plain sorted vectors would, through any number of moves and repacks.
        #[test]
        fn behaves_like_sorted_vectors(
            ops in proptest::collection::vec((0u8..6, 0u32..12, 0u32..40, 0u32..8), 0..300),
        ) {
            let tris: Vec<[u32; 3]> = (0..10).map(|i| [i % 6, (i + 1) % 6, (i + 3) % 6]).collect();
            let alive = vec![true; tris.len()];
            let mut inc = Incidence::build(6, &tris, &alive);
            let mut reference: Vec<Vec<u32>> = vec![Vec::new(); 6];
            for (t, tri) in tris.iter().enumerate() {
                for &v in tri {
                    reference[v as usize].push(t as u32);
                }
            }
            prop_assert_eq!(inc.to_vecs(), reference.clone());
            for (op, v, t, n) in ops {
                let v = v % inc.len().max(1) as u32;
                match op {
                    0 if !reference[v as usize].contains(&t) => {
                        inc.insert(v, t);
                        reference[v as usize].push(t);
                        reference[v as usize].sort_unstable();
                    }
                    1 => {
                        inc.remove(v, t);
                        reference[v as usize].retain(|&x| x != t);
                    }
                    2 => {
                        let extra: Vec<u32> = (0..n)
                            .map(|k| 100 + t + 3 * k)
                            .filter(|x| !reference[v as usize].contains(x))
                            .collect();
                        inc.merge(v, &extra);
                        reference[v as usize].extend(extra);
                        reference[v as usize].sort_unstable();
                    }
                    3 => {
                        let items: Vec<u32> = (0..n).map(|k| t + 2 * k).collect();
                        inc.set(v, &items);
                        reference[v as usize] = items;
                    }
                    4 => {
                        inc.push_vertex();
                        reference.push(Vec::new());
                    }
                    5 if inc.len() > 3 => {
                        inc.truncate(inc.len() - 1);
                        reference.pop();
                    }
                    _ => {}
                }
                prop_assert_eq!(inc.to_vecs(), reference.clone());
            }
        }
    }
}
