//! Edge split (a new vertex at the edge's midpoint) and edge swap (the diagonal of two
//! triangles turned), both undoable.

use super::*;

impl Adjacency {
    /// Split edge ab at its midpoint: a new vertex, and each triangle on the edge becomes two.
    /// Returns the new vertex and the undo record.
    pub fn split(&mut self, a: u32, b: u32) -> Result<(u32, Undo), Reject> {
        let shared = self.edge_triangles(a, b);
        if shared.is_empty() || shared.len() > 2 {
            return Err(Reject::NoSuchEdge);
        }
        let mut undo = self.begin();
        let m = self.positions.len() as u32;
        for v in [a, b] {
            self.snapshot_vert(&mut undo, v);
        }
        for &t in &shared {
            self.snapshot_tri(&mut undo, t);
            for v in self.tris[t as usize] {
                if v != a && v != b {
                    self.snapshot_vert(&mut undo, v);
                }
            }
        }
        self.positions
            .push(0.5 * (self.positions[a as usize] + self.positions[b as usize]));
        self.vtris.push_vertex();
        self.locked.push(false);
        self.only_wedge.push(SEVERAL);
        let border = shared.len() == 1;
        self.class.push(if border {
            VertexClass::Border
        } else {
            VertexClass::Interior
        });
        // New wedges: midpoints of the corner wedges at a and b, shared where both sides agree.
        let mut made: Vec<((u32, u32), u32)> = Vec::new();
        for &t in &shared {
            let tri = self.tris[t as usize];
            let ka = tri.iter().position(|&x| x == a).unwrap();
            let kb = tri.iter().position(|&x| x == b).unwrap();
            let (wa, wb) = (self.corners[t as usize][ka], self.corners[t as usize][kb]);
            let key = (wa.min(wb), wa.max(wb));
            let wm = match made.iter().find(|(k, _)| *k == key) {
                Some((_, w)) => *w,
                None => {
                    let (x, y) = (self.wedges[wa as usize], self.wedges[wb as usize]);
                    self.wedges.push(Wedge {
                        vertex: m,
                        normal: (x.normal + y.normal).normalize_or(x.normal),
                        uv: 0.5 * (x.uv + y.uv),
                        color: 0.5 * (x.color + y.color),
                    });
                    let w = self.wedges.len() as u32 - 1;
                    made.push((key, w));
                    w
                }
            };
            if made.len() > 1 {
                self.class[m as usize] = self.class[m as usize].max(VertexClass::Seam);
            }
            // Triangle t keeps a's side: replace b with m; the new triangle takes b's side.
            let mut t2 = tri;
            let mut c2 = self.corners[t as usize];
            self.tris[t as usize][kb] = m;
            self.corners[t as usize][kb] = wm;
            t2[ka] = m;
            c2[ka] = wm;
            let nt = self.tris.len() as u32;
            self.tris.push(t2);
            self.corners.push(c2);
            self.materials.push(self.materials[t as usize]);
            self.alive.push(true);
            self.alive_count += 1;
            self.vtris.remove(b, t);
            for v in t2 {
                self.vtris.insert(v, nt);
            }
            self.vtris.insert(m, t);
        }
        if let [(_, w)] = made[..] {
            self.only_wedge[m as usize] = w;
        }
        Ok((m, undo))
    }

    /// Swap the edge ab shared by triangles (a, b, c) and (b, a, d) for the edge cd.
    pub fn swap(&mut self, a: u32, b: u32) -> Result<Undo, Reject> {
        let shared = self.edge_triangles(a, b);
        if shared.len() != 2 {
            return Err(Reject::Topology);
        }
        // Orient: t1 has a→b, t2 has b→a.
        let dir = |t: u32| {
            let x = self.tris[t as usize];
            let k = x.iter().position(|&v| v == a).unwrap();
            x[(k + 1) % 3] == b
        };
        let (t1, t2) = if dir(shared[0]) {
            (shared[0], shared[1])
        } else {
            (shared[1], shared[0])
        };
        let apex = |t: u32| {
            let x = self.tris[t as usize];
            x.into_iter().find(|&v| v != a && v != b).unwrap()
        };
        let (c, d) = (apex(t1), apex(t2));
        if c == d || !self.edge_triangles(c, d).is_empty() {
            return Err(Reject::Topology);
        }
        if self.is_seam(a, b, &[t1, t2]) {
            return Err(Reject::Seam);
        }
        let w = |t: u32, v: u32| self.corner_wedge(t, v);
        if self.is_locked(a) || self.is_locked(b) {
            return Err(Reject::Locked);
        }
        let new1 = [a, d, c];
        let new2 = [d, b, c];
        let p = |x: [u32; 3]| x.map(|v| self.positions[v as usize]);
        let (o1, o2) = (
            Self::face_normal(p([a, b, c])),
            Self::face_normal(p([b, a, d])),
        );
        let (n1, n2) = (Self::face_normal(p(new1)), Self::face_normal(p(new2)));
        let avg = o1 + o2;
        if n1.dot(avg) <= 0.0 || n2.dot(avg) <= 0.0 || n1.length() < 1e-20 || n2.length() < 1e-20 {
            return Err(Reject::FoldOver);
        }
        let mut undo = self.begin();
        for v in [a, b, c, d] {
            self.snapshot_vert(&mut undo, v);
        }
        self.snapshot_tri(&mut undo, t1);
        self.snapshot_tri(&mut undo, t2);
        let c1 = [w(t1, a), w(t2, d), w(t1, c)];
        let c2 = [w(t2, d), w(t1, b), w(t1, c)];
        self.tris[t1 as usize] = new1;
        self.corners[t1 as usize] = c1;
        self.tris[t2 as usize] = new2;
        self.corners[t2 as usize] = c2;
        self.vtris.remove(b, t1);
        self.vtris.remove(a, t2);
        self.vtris.insert(d, t1);
        self.vtris.insert(c, t2);
        Ok(undo)
    }
}
