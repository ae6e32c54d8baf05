//! The structure's invariants, checked (`Adjacency::check`, used by the property tests) and
//! counted (border and non-manifold edges).

use super::*;

impl Adjacency {
    /// Check every invariant; `Err` names the first broken one.
    pub fn check(&self) -> Result<(), String> {
        let mut count = 0;
        for t in 0..self.tris.len() {
            if !self.alive[t] {
                continue;
            }
            count += 1;
            let x = self.tris[t];
            if x[0] == x[1] || x[1] == x[2] || x[0] == x[2] {
                return Err(format!("triangle {t} is degenerate: {x:?}"));
            }
            for (k, (&v, &w)) in x.iter().zip(&self.corners[t]).enumerate() {
                if !self.vtris.get(v).contains(&(t as u32)) {
                    return Err(format!("vertex {v} does not list triangle {t}"));
                }
                if self.wedges[w as usize].vertex != v {
                    return Err(format!(
                        "triangle {t} corner {k}: wedge {w} is not of vertex {v}"
                    ));
                }
            }
        }
        if count != self.alive_count {
            return Err(format!(
                "{count} live triangles, count says {}",
                self.alive_count
            ));
        }
        for (v, ts) in self.vtris.to_vecs().iter().enumerate() {
            if !ts.is_sorted_by(|x, y| x < y) {
                return Err(format!("vertex {v}'s triangles are not strictly ascending"));
            }
            let only = self.only_wedge[v];
            if only != SEVERAL && ts.iter().any(|&t| self.corner_wedge(t, v as u32) != only) {
                return Err(format!(
                    "vertex {v} is recorded with the single wedge {only} but uses others"
                ));
            }
            for &t in ts {
                if !self.alive[t as usize] || !self.tris[t as usize].contains(&(v as u32)) {
                    return Err(format!(
                        "vertex {v} lists triangle {t}, which does not use it"
                    ));
                }
            }
        }
        Ok(())
    }

    /// Edges used by more than two live triangles.
    pub fn non_manifold_edges(&self) -> usize {
        let mut n = 0;
        self.for_each_edge(|_, _, ts| n += usize::from(ts.len() > 2));
        n
    }

    /// Border edges (one live triangle).
    pub fn border_edges(&self) -> usize {
        let mut n = 0;
        self.for_each_edge(|_, _, ts| n += usize::from(ts.len() == 1));
        n
    }
}
