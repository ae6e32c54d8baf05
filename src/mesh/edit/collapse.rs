//! Edge collapse: the legality checks (link condition, border rule, fold-over, seam partners)
//! and the collapse itself, undoable or for good.

use super::*;

impl Adjacency {
    pub(super) fn face_normal(p: [Vec3; 3]) -> Vec3 {
        (p[1] - p[0]).cross(p[2] - p[0])
    }

    /// Would moving the corner `v` of the triangles in `ts` to `p` flip or flatten any of them?
    ///
    /// A triangle (v, i, j) has the normal (p_i − v) × (p_j − v); it folds when the new normal is
    /// below 1e-12 of the old one's length (degenerate) or points away from it. Lengths are
    /// compared squared, in f64 (no square roots; no underflow on tiny models).
    pub(super) fn folds(&self, ts: &[u32], v: u32, p: Vec3, skip_with: u32) -> bool {
        let pv = self.positions[v as usize];
        for &t in ts {
            let tri = self.tris[t as usize];
            if tri.contains(&skip_with) {
                continue;
            }
            let k = if tri[0] == v {
                0
            } else if tri[1] == v {
                1
            } else {
                2
            };
            let pi = self.positions[tri[(k + 1) % 3] as usize];
            let pj = self.positions[tri[(k + 2) % 3] as usize];
            let no = (pi - pv).cross(pj - pv);
            let nn = (pi - p).cross(pj - p);
            let (lo2, ln2) = (
                no.as_dvec3().length_squared(),
                nn.as_dvec3().length_squared(),
            );
            if ln2 <= 1e-24 * lo2 || no.dot(nn) <= 0.0 {
                return true;
            }
        }
        false
    }

    /// Check a collapse of `a` into `b` (b moves to `p`) without doing it.
    pub fn can_collapse(&self, a: u32, b: u32, p: Vec3) -> Result<(), Reject> {
        self.check_collapse(a, b, p).map(|_| ())
    }

    /// [`Adjacency::can_collapse`], returning the triangles on the edge and the wedge map.
    pub(super) fn check_collapse(
        &self,
        a: u32,
        b: u32,
        p: Vec3,
    ) -> Result<(Local<u32>, WedgeMap), Reject> {
        self.check_collapse_with(a, b, p, |adj| {
            let na = adj.ring(a);
            adj.ring(b).iter().filter(|x| na.contains(x)).count()
        })
    }

    /// A fresh mark value (every vertex unmarked for it).
    pub(super) fn fresh_mark(&mut self) -> u32 {
        if self.marks.len() < self.positions.len() {
            self.marks.resize(self.positions.len(), 0);
        }
        self.mark = self.mark.wrapping_add(1);
        if self.mark == 0 {
            self.marks.fill(0);
            self.mark = 1;
        }
        self.mark
    }

    /// How many vertices are neighbours of both `a` and `b` (what the link condition counts),
    /// by marking a's neighbours.
    pub(super) fn common_neighbours(&mut self, a: u32, b: u32) -> usize {
        let m = self.fresh_mark();
        for &t in self.vtris.get(a) {
            for x in self.tris[t as usize] {
                self.marks[x as usize] = m;
            }
        }
        // a's own mark goes: only its neighbours count (b's neighbour a does not).
        self.marks[a as usize] = m.wrapping_sub(1);
        let counted = self.fresh_mark();
        let mut n = 0;
        for &t in self.vtris.get(b) {
            for x in self.tris[t as usize] {
                if x != b && self.marks[x as usize] == m {
                    self.marks[x as usize] = counted;
                    n += 1;
                }
            }
        }
        n
    }

    /// `v`'s neighbours into `out` (each once, no particular order), by marking.
    pub(super) fn ring_marked(&mut self, v: u32, out: &mut Local<u32>) {
        out.clear();
        let m = self.fresh_mark();
        self.marks[v as usize] = m;
        for &t in self.vtris.get(v) {
            for x in self.tris[t as usize] {
                if self.marks[x as usize] != m {
                    self.marks[x as usize] = m;
                    out.push(x);
                }
            }
        }
    }

    /// [`Adjacency::check_collapse`] with the link condition's count of common neighbours
    /// from `common` (asked only when the condition applies).
    pub(super) fn check_collapse_with(
        &self,
        a: u32,
        b: u32,
        p: Vec3,
        common: impl FnOnce(&Adjacency) -> usize,
    ) -> Result<(Local<u32>, WedgeMap), Reject> {
        if a == b || self.vtris.get(a).is_empty() || self.vtris.get(b).is_empty() {
            return Err(Reject::NoSuchEdge);
        }
        let shared = self.edge_triangles(a, b);
        if shared.is_empty() {
            return Err(Reject::NoSuchEdge);
        }
        // Where the surface is not a manifold (and that may be collapsed), there is no manifold
        // to protect: edges with more triangles may collapse and the link condition is skipped.
        let non_manifold = self.non_manifold_collapses
            && (self.class[a as usize] == VertexClass::NonManifold
                || self.class[b as usize] == VertexClass::NonManifold);
        if shared.len() > 2 && !non_manifold {
            return Err(Reject::Link);
        }
        if self.is_locked(a) || (self.is_locked(b) && p != self.positions[b as usize]) {
            return Err(Reject::Locked);
        }
        // Link condition.
        if !non_manifold && common(self) != shared.len() {
            return Err(Reject::Link);
        }
        // Two border vertices joined through the interior would pinch the surface.
        if shared.len() == 2
            && self.class[a as usize] == VertexClass::Border
            && self.class[b as usize] == VertexClass::Border
        {
            return Err(Reject::Link);
        }
        // A border vertex may only collapse along the border (else the border moves inwards).
        if shared.len() == 2 && self.class[a as usize] == VertexClass::Border {
            return Err(Reject::Link);
        }
        let map = self.wedge_map(a, b, &shared)?;
        if self.folds(self.vtris.get(a), a, p, b) || self.folds(self.vtris.get(b), b, p, a) {
            return Err(Reject::FoldOver);
        }
        Ok((shared, map))
    }

    /// For each wedge of `a`, its partner wedge of `b` across the edge.
    pub(super) fn wedge_map(&self, a: u32, b: u32, shared: &[u32]) -> Result<WedgeMap, Reject> {
        let mut map = WedgeMap::new();
        if let Some(pair) = self.single_wedges(a, b) {
            // One wedge each: every shared triangle pairs the same two.
            map.push(pair);
            return Ok(map);
        }
        for &t in shared {
            let tri = self.tris[t as usize];
            let ka = tri.iter().position(|&x| x == a).unwrap();
            let kb = tri.iter().position(|&x| x == b).unwrap();
            let (wa, wb) = (self.corners[t as usize][ka], self.corners[t as usize][kb]);
            match map.iter().find(|(x, _)| *x == wa) {
                Some((_, y)) if *y != wb => return Err(Reject::Seam),
                Some(_) => {}
                None => map.push((wa, wb)),
            }
        }
        for &t in self.vtris.get(a) {
            let w = self.corner_wedge(t, a);
            if !map.iter().any(|(x, _)| *x == w) {
                return Err(Reject::Seam);
            }
        }
        Ok(map)
    }

    /// Collapse `a` into `b`, moving `b` to `p`. Returns the undo record.
    pub fn collapse(&mut self, a: u32, b: u32, p: Vec3) -> Result<Undo, Reject> {
        let (shared, map) = self.check_collapse(a, b, p)?;
        let mut undo = self.begin();
        let mut touched: Local<u32> = SmallVec::from_slice(&[a, b]);
        for &t in &shared {
            touched.extend(self.tris[t as usize]);
        }
        touched.sort_unstable();
        touched.dedup();
        for &v in &touched {
            self.snapshot_vert(&mut undo, v);
        }
        for &t in self.vtris.get(a) {
            self.snapshot_tri(&mut undo, t);
        }
        self.apply_collapse(a, b, p, &shared, &map);
        Ok(undo)
    }

    /// Collapse `a` into `b`, moving `b` to `p`, without an undo record (for a simplifier that
    /// never reverts). Returns the wedge map of the collapse and puts b's neighbours afterwards
    /// into `ring` (each once, no particular order); a refused collapse changes nothing.
    pub fn collapse_for_good(
        &mut self,
        a: u32,
        b: u32,
        p: Vec3,
        ring: &mut Local<u32>,
    ) -> Result<WedgeMap, Reject> {
        let common = self.common_neighbours(a, b);
        let (shared, map) = self.check_collapse_with(a, b, p, |_| common)?;
        self.apply_collapse(a, b, p, &shared, &map);
        self.ring_marked(b, ring);
        Ok(map)
    }

    /// The changes of a checked collapse.
    pub(super) fn apply_collapse(
        &mut self,
        a: u32,
        b: u32,
        p: Vec3,
        shared: &[u32],
        map: &[(u32, u32)],
    ) {
        // The triangles on the edge die: the lists of their third vertices lose them here, a's
        // and b's below.
        for &t in shared {
            self.alive[t as usize] = false;
            self.alive_count -= 1;
            for v in self.tris[t as usize] {
                if v != a && v != b {
                    self.vtris.remove(v, t);
                }
            }
        }
        // a's other triangles (ascending) move to b: merged into b's ascending list, which
        // drops the dead ones.
        let mut moved: Local<u32> = Local::new();
        for &t in self.vtris.get(a) {
            if !shared.contains(&t) {
                moved.push(t);
            }
        }
        self.vtris.clear(a);
        for &t in &moved {
            let k = self.tris[t as usize].iter().position(|&x| x == a).unwrap();
            self.tris[t as usize][k] = b;
            let w = self.corners[t as usize][k];
            self.corners[t as usize][k] = map.iter().find(|(x, _)| *x == w).unwrap().1;
        }
        self.vtris.retain_merge(b, shared, &moved);
        self.positions[b as usize] = p;
        let (ca, cb) = (self.class[a as usize], self.class[b as usize]);
        self.class[b as usize] = ca.max(cb);
    }
}
