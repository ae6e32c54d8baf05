//! Undo: the triangles and vertices an operation will touch are snapshotted before it changes
//! anything, and restoring the snapshots gives back the exact previous state.

use super::*;

impl Adjacency {
    pub(super) fn snapshot_tri(&self, undo: &mut Undo, t: u32) {
        undo.tris.push((
            t,
            self.tris[t as usize],
            self.corners[t as usize],
            self.alive[t as usize],
        ));
    }

    pub(super) fn snapshot_vert(&self, undo: &mut Undo, v: u32) {
        undo.verts.push((
            v,
            self.positions[v as usize],
            self.vtris.get(v).to_vec(),
            self.class[v as usize],
        ));
    }

    pub(super) fn begin(&self) -> Undo {
        Undo {
            lens: (self.positions.len(), self.wedges.len(), self.tris.len()),
            alive_count: self.alive_count,
            ..Undo::default()
        }
    }

    /// Restore the state before the operation that returned `undo`.
    pub fn undo(&mut self, undo: Undo) {
        for (t, tri, c, alive) in undo.tris.into_iter().rev() {
            self.tris[t as usize] = tri;
            self.corners[t as usize] = c;
            self.alive[t as usize] = alive;
        }
        for (v, p, vt, class) in undo.verts.into_iter().rev() {
            self.positions[v as usize] = p;
            self.vtris.set(v, &vt);
            self.class[v as usize] = class;
        }
        let (np, nw, nt) = undo.lens;
        self.positions.truncate(np);
        self.vtris.truncate(np);
        self.class.truncate(np);
        self.locked.truncate(np);
        self.only_wedge.truncate(np);
        self.wedges.truncate(nw);
        self.tris.truncate(nt);
        self.corners.truncate(nt);
        self.materials.truncate(nt);
        self.alive.truncate(nt);
        self.alive_count = undo.alive_count;
    }
}
