//! The optimizer's mesh state and its one way of trying a change: edit, evaluate ΔE through the
//! incremental images, then accept (commit) or reject (restore exactly). Also the continuous
//! optimization of a vertex set with the downhill simplex (Lindstrom & Turk §5.1).
//!
//! Every write to a position or wedge attribute goes through a logging setter, so a rejected move
//! is undone by replaying the log backwards and then undoing the connectivity operation (the
//! log holds the values from before *our* writes, the operation's undo those from before the
//! operation). Normals are either derived from the geometry (area-weighted face normals per wedge,
//! recomputed around every moved vertex: what a scan's smooth shading does) or free attributes the
//! simplex optimizes, not constrained to unit length (the paper's dragon, §6).

use glam::{Vec2, Vec3};

use super::Options;
use super::simplex;
use crate::mesh::edit::{Adjacency, Undo, Wedge};
use crate::raster::incremental::{Change, LumaViews};

/// How normals are treated.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize, serde::Serialize, clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum Normals {
    /// Recomputed from the geometry after every change (area-weighted, per wedge).
    #[value(help = "Recomputed from the geometry after every change")]
    Derived,
    /// Optimized as free attributes by the simplex.
    #[value(help = "Optimized as free attributes")]
    Free,
}

/// One optimized quantity.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Slot {
    Position(u32),
    Normal(u32),
    Uv(u32),
    Color(u32),
}

impl Slot {
    fn width(self) -> usize {
        match self {
            Slot::Uv(_) => 2,
            _ => 3,
        }
    }
}

/// What a change touches: the vertices whose position may change (moved set and the operation's
/// vertices), the wedges whose attributes may change, the wedges whose normals are re-derived,
/// and every triangle whose rendering may change.
#[derive(Debug, Clone, Default)]
pub(super) struct Affected {
    verts: Vec<u32>,
    wedges: Vec<u32>,
    normal_wedges: Vec<u32>,
    tris: Vec<u32>,
    reshaded: Vec<u32>,
}

/// The optimizer's state.
#[derive(Debug)]
pub(super) struct State {
    pub adj: Adjacency,
    pub views: LumaViews,
    pub normals: Normals,
    pub attributes: bool,
    /// Energy evaluations spent.
    pub evals: u64,
    /// Budget of energy evaluations.
    pub budget: u64,
    /// Current energy (exact, squared 16-bit luminance codes).
    pub energy: i64,
    log_pos: Vec<(u32, Vec3)>,
    log_wedge: Vec<(u32, Wedge)>,
    seen_pos: Vec<u32>,
    seen_wedge: Vec<u32>,
    stamp: u32,
}

/// The mesh as the optimizer starts from it: with derived normals, every wedge's normal is
/// derived from the geometry first, so the initial energy is that of the mesh being optimized.
pub(super) fn prepare(mut adj: Adjacency, normals: Normals) -> Adjacency {
    if normals == Normals::Derived {
        for w in 0..adj.wedges.len() as u32 {
            if let Some(n) = derived_normal(&adj, w) {
                adj.wedges[w as usize].normal = n;
            }
        }
    }
    adj
}

fn sorted(mut v: Vec<u32>) -> Vec<u32> {
    v.sort_unstable();
    v.dedup();
    v
}

impl State {
    /// The state for `adj` (prepared with [`prepare`]) and its images `views`.
    pub fn new(adj: Adjacency, views: LumaViews, opts: &Options) -> State {
        let energy = views.energy();
        State {
            adj,
            views,
            normals: opts.normals,
            attributes: opts.attributes,
            evals: 0,
            budget: opts.evals,
            energy,
            log_pos: Vec::new(),
            log_wedge: Vec::new(),
            seen_pos: Vec::new(),
            seen_wedge: Vec::new(),
            stamp: 1,
        }
    }

    /// Evaluations left in the budget.
    pub fn remaining(&self) -> u64 {
        self.budget.saturating_sub(self.evals)
    }

    /// Start a move: clear the write log.
    pub fn begin(&mut self) {
        self.log_pos.clear();
        self.log_wedge.clear();
        self.stamp = self.stamp.wrapping_add(1).max(1);
    }

    fn set_position(&mut self, v: u32, p: Vec3) {
        let i = v as usize;
        if self.seen_pos.len() <= i {
            self.seen_pos.resize(i + 1, 0);
        }
        if self.seen_pos[i] != self.stamp {
            self.seen_pos[i] = self.stamp;
            self.log_pos.push((v, self.adj.positions[i]));
        }
        self.adj.positions[i] = p;
    }

    fn wedge_mut(&mut self, w: u32) -> &mut Wedge {
        let i = w as usize;
        if self.seen_wedge.len() <= i {
            self.seen_wedge.resize(i + 1, 0);
        }
        if self.seen_wedge[i] != self.stamp {
            self.seen_wedge[i] = self.stamp;
            self.log_wedge.push((w, self.adj.wedges[i]));
        }
        &mut self.adj.wedges[i]
    }

    /// Accept the pending trial: commit the images and the energy.
    pub fn accept(&mut self, delta: i64) {
        self.views.commit(&self.adj);
        self.energy += delta;
        self.begin();
    }

    /// Reject the pending change: restore our writes, then undo the connectivity operation.
    pub fn reject(&mut self, undo: Option<Undo>) {
        self.views.revert();
        for (w, old) in std::mem::take(&mut self.log_wedge).into_iter().rev() {
            if (w as usize) < self.adj.wedges.len() {
                self.adj.wedges[w as usize] = old;
            }
        }
        for (v, old) in std::mem::take(&mut self.log_pos).into_iter().rev() {
            if (v as usize) < self.adj.positions.len() {
                self.adj.positions[v as usize] = old;
            }
        }
        if let Some(u) = undo {
            self.adj.undo(u);
        }
        self.begin();
    }

    /// Vertices of `set` and their neighbours, ascending.
    pub fn ring(&self, set: &[u32]) -> Vec<u32> {
        sorted(
            set.iter()
                .flat_map(|&v| std::iter::once(v).chain(self.adj.neighbours(v)))
                .collect(),
        )
    }

    fn wedges_of(&self, verts: &[u32]) -> Vec<u32> {
        sorted(
            verts
                .iter()
                .flat_map(|&v| self.adj.vertex_wedges(v))
                .collect(),
        )
    }

    /// What moving `moved` after a connectivity operation around `topo` (whose triangles
    /// `op_tris` changed, and which made `new_wedges`) touches.
    pub fn affected(
        &self,
        moved: &[u32],
        topo: &[u32],
        op_tris: &[u32],
        new_wedges: &[u32],
    ) -> Affected {
        let base: Vec<u32> = sorted(moved.iter().chain(topo).copied().collect());
        let shaded = match self.normals {
            Normals::Derived => sorted(
                self.ring(moved)
                    .into_iter()
                    .chain(topo.iter().copied())
                    .collect(),
            ),
            Normals::Free => base.clone(),
        };
        let normal_wedges = match self.normals {
            Normals::Derived => self.wedges_of(&shaded),
            Normals::Free => Vec::new(),
        };
        let wedges = sorted(
            self.wedges_of(&base)
                .into_iter()
                .chain(normal_wedges.iter().copied())
                .chain(new_wedges.iter().copied())
                .collect(),
        );
        let incident = |vs: &[u32]| -> Vec<u32> {
            vs.iter()
                .flat_map(|&v| self.adj.vertex_triangles(v).iter().copied())
                .collect()
        };
        // Triangles with a moved corner (or changed connectivity) change coverage; the others
        // around re-derived normals only change shading.
        let mut tris = incident(&base);
        tris.extend_from_slice(op_tris);
        let tris = sorted(tris);
        let reshaded: Vec<u32> = sorted(incident(&shaded))
            .into_iter()
            .filter(|t| tris.binary_search(t).is_err())
            .collect();
        Affected {
            verts: base,
            wedges,
            normal_wedges,
            tris,
            reshaded,
        }
    }

    /// The slots the simplex optimizes for vertex set `set`.
    fn layout(&self, set: &[u32]) -> Vec<Slot> {
        let mut slots: Vec<Slot> = set.iter().map(|&v| Slot::Position(v)).collect();
        let wedges = self.wedges_of(set);
        if self.normals == Normals::Free {
            slots.extend(wedges.iter().map(|&w| Slot::Normal(w)));
        }
        if self.attributes && self.adj.has_uvs() {
            slots.extend(wedges.iter().map(|&w| Slot::Uv(w)));
        }
        if self.attributes && self.adj.has_colors() {
            slots.extend(wedges.iter().map(|&w| Slot::Color(w)));
        }
        slots
    }

    /// Current values and initial simplex steps of `slots`, sized from the local geometry: a fifth
    /// of the mean length of the edges at the set's vertices (positions), of the same edges in UV
    /// space (UVs), 0.1 for normals and 0.05 for colours.
    fn values(&self, slots: &[Slot], set: &[u32]) -> (Vec<f64>, Vec<f64>) {
        let (mut len, mut uv_len, mut n) = (0.0f64, 0.0f64, 0usize);
        for &v in set {
            for &t in self.adj.vertex_triangles(v) {
                let tri = self.adj.triangle(t);
                let c = self.adj.corners(t);
                let k = tri.iter().position(|&x| x == v).unwrap_or(0);
                for j in [1, 2] {
                    let o = (k + j) % 3;
                    len += (self.adj.positions[tri[o] as usize] - self.adj.positions[v as usize])
                        .length() as f64;
                    uv_len += (self.adj.wedges[c[o] as usize].uv
                        - self.adj.wedges[c[k] as usize].uv)
                        .length() as f64;
                    n += 1;
                }
            }
        }
        let n = n.max(1) as f64;
        let step_pos = (0.2 * len / n).max(1e-6);
        let step_uv = (0.2 * uv_len / n).max(1e-4);
        let (mut vals, mut steps) = (Vec::new(), Vec::new());
        for &s in slots {
            let (x, step): (Vec<f32>, f64) = match s {
                Slot::Position(v) => (self.adj.positions[v as usize].to_array().to_vec(), step_pos),
                Slot::Normal(w) => (self.adj.wedges[w as usize].normal.to_array().to_vec(), 0.1),
                Slot::Uv(w) => (self.adj.wedges[w as usize].uv.to_array().to_vec(), step_uv),
                Slot::Color(w) => (self.adj.wedges[w as usize].color.to_array().to_vec(), 0.05),
            };
            vals.extend(x.iter().map(|&x| x as f64));
            steps.extend(std::iter::repeat_n(step, s.width()));
        }
        (vals, steps)
    }

    fn apply(&mut self, slots: &[Slot], p: &[f64]) {
        let mut k = 0;
        for &s in slots {
            let x = |i: usize| p[k + i] as f32;
            match s {
                Slot::Position(v) => self.set_position(v, Vec3::new(x(0), x(1), x(2))),
                Slot::Normal(w) => self.wedge_mut(w).normal = Vec3::new(x(0), x(1), x(2)),
                Slot::Uv(w) => self.wedge_mut(w).uv = Vec2::new(x(0), x(1)),
                Slot::Color(w) => self.wedge_mut(w).color = Vec3::new(x(0), x(1), x(2)),
            }
            k += s.width();
        }
    }

    fn rederive(&mut self, wedges: &[u32]) {
        for &w in wedges {
            if let Some(n) = derived_normal(&self.adj, w)
                && n != self.adj.wedges[w as usize].normal
            {
                self.wedge_mut(w).normal = n;
            }
        }
    }

    /// One energy evaluation of the current state against the committed images.
    fn eval(&mut self, aff: &Affected) -> i64 {
        self.rederive(&aff.normal_wedges);
        self.evals += 1;
        self.views.trial(
            &self.adj,
            &Change {
                vertices: &aff.verts,
                wedges: &aff.wedges,
                triangles: &aff.tris,
                reshaded: &aff.reshaded,
            },
        )
    }

    /// Evaluate a change: the connectivity operation (if any) is already applied; `set` is the
    /// vertex set to optimize (empty, or `optimize` false, for a level-0 move). Leaves the best
    /// state found applied and its trial pending; returns its ΔE. `known_zero`: the unmodified
    /// state is the committed one (no connectivity change), so its ΔE is 0 without evaluating.
    pub fn evaluate(
        &mut self,
        set: &[u32],
        optimize: bool,
        topo: &[u32],
        op_tris: &[u32],
        new_wedges: &[u32],
        known_zero: bool,
    ) -> i64 {
        let set: Vec<u32> = set
            .iter()
            .copied()
            .filter(|&v| !self.adj.is_locked(v))
            .collect();
        let aff = self.affected(&set, topo, op_tris, new_wedges);
        let slots = if optimize {
            self.layout(&set)
        } else {
            Vec::new()
        };
        if slots.is_empty() {
            return if known_zero { 0 } else { self.eval(&aff) };
        }
        let (p0, steps) = self.values(&slots, &set);
        let f0 = if known_zero {
            0.0
        } else {
            self.eval(&aff) as f64
        };
        let limit = (32 * p0.len()).min(self.remaining().max(1) as usize);
        let best = simplex::minimize(&p0, f0, &steps, limit, |p| {
            self.apply(&slots, p);
            self.eval(&aff) as f64
        });
        self.apply(&slots, &best.point);
        if known_zero && best.value >= 0.0 {
            // Nothing better than the committed state: the caller rejects, which restores it.
            return 0;
        }
        self.eval(&aff)
    }
}

/// The derived normal of wedge `w`: the sum of the (area-weighted) normals of the live triangles
/// whose corner uses it, normalised; `None` if there are none or they cancel.
fn derived_normal(adj: &Adjacency, w: u32) -> Option<Vec3> {
    let v = adj.wedges.get(w as usize)?.vertex;
    if v as usize >= adj.positions.len() {
        return None;
    }
    let mut sum = Vec3::ZERO;
    for &t in adj.vertex_triangles(v) {
        if adj.corner_wedge(t, v) != w {
            continue;
        }
        let p = adj.triangle(t).map(|i| adj.positions[i as usize]);
        sum += (p[1] - p[0]).cross(p[2] - p[0]);
    }
    sum.try_normalize()
}
