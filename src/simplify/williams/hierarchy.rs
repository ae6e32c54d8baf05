//! The multiresolution hierarchy of Williams et al. 2003 (§2.3): a Multi-Triangulation (De Floriani,
//! Magillo, Puppo 1997/1998) built from the edge-collapse engine's progressive record.
//!
//! Every collapse is a node. It removes the triangles around the collapsed edge's two vertices (the
//! star of the surviving vertex changes too, because that vertex moves) and creates the new star of
//! the survivor; both stars have the same boundary (the edge's link), so the node is a local
//! replacement of one patch by another. A triangle is created by one node (or is original) and
//! removed by at most one later node; that pair is the MT's arc. A node *depends on* the nodes that
//! created the triangles it removes ("prerequisites"); its *dependents* are the nodes that remove
//! the triangles it creates.
//!
//! A *cut* is a set of applied collapses closed under prerequisites. Its mesh is every triangle
//! whose creator is applied (or that is original) and whose remover is not. Because each node swaps
//! patches with equal boundaries, the mesh of every cut is a crack-free triangulation of the same
//! surface topology (tested on random cuts).
//!
//! Decision (the issue asks for collapses ordered by texture deviation on textured models): the
//! collapse order is our QEM engine's, with Garland–Heckbert 1998 attribute quadrics over UVs and
//! normals (`qem.rs`), which keeps texture coordinates in place as a parametric-deviation order
//! would, but is not Cohen et al.'s successive mapping. The texture deviation each node causes is
//! then *measured* (`preprocess.rs`) and is what the run-time keys use.

use std::collections::HashMap;
use std::sync::Arc;

use glam::{Vec2, Vec3};

use crate::error::Result;
use crate::mesh::Mesh;
use crate::mesh::edit::Adjacency;
use crate::simplify::qem;

/// No node: the triangle is original (as creator) or in the coarsest mesh (as remover).
pub const NONE: u32 = u32::MAX;

/// One corner record: a vertex position with the wedge attributes it had.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corner {
    /// Position (model units).
    pub position: Vec3,
    /// Normal.
    pub normal: Vec3,
    /// Texture coordinate.
    pub uv: Vec2,
    /// Linear RGB vertex colour.
    pub color: Vec3,
}

/// One triangle of the MT.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tri {
    /// Corner records.
    pub corners: [u32; 3],
    /// Material index (into the original mesh's materials).
    pub material: u32,
    /// The node that created it ([`NONE`]: original).
    pub creator: u32,
    /// The node that removes it ([`NONE`]: in the coarsest mesh).
    pub remover: u32,
}

/// Compressed lists, one per node.
#[derive(Debug, Clone, Default)]
struct Lists {
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Lists {
    fn push(&mut self, items: impl IntoIterator<Item = u32>) {
        if self.start.is_empty() {
            self.start.push(0);
        }
        self.items.extend(items);
        self.start.push(self.items.len() as u32);
    }
    fn get(&self, i: u32) -> &[u32] {
        &self.items[self.start[i as usize] as usize..self.start[i as usize + 1] as usize]
    }
}

/// The Multi-Triangulation.
#[derive(Debug, Clone)]
pub struct Hierarchy {
    /// The mesh it was built from (materials, provenance).
    pub original: Arc<Mesh>,
    /// Corner records.
    pub corners: Vec<Corner>,
    /// Triangles: the first `original_triangles` are the original mesh's.
    pub tris: Vec<Tri>,
    /// How many triangles the original has.
    pub original_triangles: usize,
    removed: Lists,
    created: Lists,
    prerequisites: Lists,
    dependents: Lists,
}

impl Hierarchy {
    /// Build the MT of `mesh` by collapsing with QEM as far as the engine goes.
    pub fn build(mesh: &Arc<Mesh>) -> Result<Hierarchy> {
        let pm = qem::progressive(mesh, qem::Stop::Triangles(0));
        Ok(Self::from_progressive(mesh, &pm))
    }

    /// The MT of a progressive record of `mesh`.
    pub fn from_progressive(mesh: &Arc<Mesh>, pm: &qem::Progressive) -> Hierarchy {
        let mut adj: Adjacency = pm.base.clone();
        let mut vertex_version = vec![0u32; adj.positions.len()];
        let mut wedge_version = vec![0u32; adj.wedges.len()];
        let mut corner_ids: HashMap<[u32; 4], u32> = HashMap::new();
        let mut corners: Vec<Corner> = Vec::new();
        let mut tris: Vec<Tri> = Vec::new();
        let mut slot_tri = vec![NONE; adj.triangle_slots()];

        // The current triangle in adjacency slot `t` as an MT triangle created by `creator`.
        let mut record = |adj: &Adjacency,
                          vv: &[u32],
                          wv: &[u32],
                          t: u32,
                          creator: u32,
                          tris: &mut Vec<Tri>|
         -> u32 {
            let c = adj.corners(t).map(|w| {
                let wedge = adj.wedges[w as usize];
                let v = wedge.vertex;
                let key = [v, vv[v as usize], w, wv[w as usize]];
                *corner_ids.entry(key).or_insert_with(|| {
                    corners.push(Corner {
                        position: adj.positions[v as usize],
                        normal: wedge.normal,
                        uv: wedge.uv,
                        color: wedge.color,
                    });
                    corners.len() as u32 - 1
                })
            });
            tris.push(Tri {
                corners: c,
                material: adj.material(t),
                creator,
                remover: NONE,
            });
            tris.len() as u32 - 1
        };

        for t in adj.live_triangles().collect::<Vec<_>>() {
            slot_tri[t as usize] =
                record(&adj, &vertex_version, &wedge_version, t, NONE, &mut tris);
        }
        let original_triangles = tris.len();
        let (mut removed, mut created) = (Lists::default(), Lists::default());
        for (node, c) in pm.collapses.iter().enumerate() {
            let node = node as u32;
            let mut star: Vec<u32> = adj
                .vertex_triangles(c.from)
                .iter()
                .chain(adj.vertex_triangles(c.to))
                .copied()
                .collect();
            star.sort_unstable();
            star.dedup();
            let gone: Vec<u32> = star.iter().map(|&s| slot_tri[s as usize]).collect();
            for &g in &gone {
                tris[g as usize].remover = node;
            }
            removed.push(gone);
            adj.collapse(c.from, c.to, c.position)
                .expect("a recorded collapse replays");
            for (w, value) in &c.attributes {
                adj.wedges[*w as usize] = *value;
                wedge_version[*w as usize] += 1;
            }
            vertex_version[c.to as usize] += 1;
            let mut made = Vec::new();
            for &s in adj.vertex_triangles(c.to) {
                let id = record(&adj, &vertex_version, &wedge_version, s, node, &mut tris);
                slot_tri[s as usize] = id;
                made.push(id);
            }
            created.push(made);
        }
        // Prerequisites: creators of removed triangles; dependents: removers of created ones.
        let nodes = pm.collapses.len() as u32;
        let (mut prerequisites, mut dependents) = (Lists::default(), Lists::default());
        let distinct = |ts: &[u32], node_of: fn(&Tri) -> u32| {
            let mut v: Vec<u32> = ts
                .iter()
                .map(|&t| node_of(&tris[t as usize]))
                .filter(|&c| c != NONE)
                .collect();
            v.sort_unstable();
            v.dedup();
            v
        };
        for n in 0..nodes {
            prerequisites.push(distinct(removed.get(n), |t| t.creator));
            dependents.push(distinct(created.get(n), |t| t.remover));
        }
        Hierarchy {
            original: mesh.clone(),
            corners,
            tris,
            original_triangles,
            removed,
            created,
            prerequisites,
            dependents,
        }
    }

    /// Number of nodes (collapses).
    pub fn node_count(&self) -> usize {
        self.removed.start.len().saturating_sub(1)
    }

    /// Triangles node `n` removes.
    pub fn removed(&self, n: u32) -> &[u32] {
        self.removed.get(n)
    }

    /// Triangles node `n` creates.
    pub fn created(&self, n: u32) -> &[u32] {
        self.created.get(n)
    }

    /// Nodes that must be applied before `n` (they created what `n` removes).
    pub fn prerequisites(&self, n: u32) -> &[u32] {
        self.prerequisites.get(n)
    }

    /// Nodes that must be undone before `n` is (they remove what `n` created).
    pub fn dependents(&self, n: u32) -> &[u32] {
        self.dependents.get(n)
    }

    /// The three corner positions of triangle `t`.
    pub fn positions(&self, t: u32) -> [Vec3; 3] {
        self.tris[t as usize]
            .corners
            .map(|c| self.corners[c as usize].position)
    }

    /// The mesh of the triangles for which `alive` holds, in triangle order.
    pub fn mesh_of(&self, alive: impl Fn(u32) -> bool) -> Result<Mesh> {
        let mut data = self.original.to_data();
        let mut remap = vec![u32::MAX; self.corners.len()];
        let (mut pos, mut nor, mut uv, mut col) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let (mut out, mut mats) = (Vec::new(), Vec::new());
        for (t, tri) in self.tris.iter().enumerate() {
            if !alive(t as u32) {
                continue;
            }
            out.push(tri.corners.map(|c| {
                if remap[c as usize] == u32::MAX {
                    remap[c as usize] = pos.len() as u32;
                    let k = self.corners[c as usize];
                    pos.push(k.position);
                    nor.push(k.normal);
                    uv.push(k.uv);
                    col.push(k.color);
                }
                remap[c as usize]
            }));
            mats.push(tri.material);
        }
        data.uvs = data.uvs.is_some().then_some(uv);
        data.colors = data.colors.is_some().then_some(col);
        data.positions = pos;
        data.normals = Some(nor);
        data.triangles = out;
        data.material_ids = mats;
        Mesh::new(data, &crate::mesh::LoadOptions::default())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    #[test]
    fn a_flat_grid_gives_a_spread_hierarchy_not_a_chain() {
        // Every collapse of a plane costs the same. Ordered by vertex id, the survivor of each
        // collapse was an end of the next, so each node depended on the one before: a chain as
        // long as the record, and a preprocessing pass that moved every sample at every node.
        let mesh = Arc::new(shapes::grid_plane(96));
        let h = Hierarchy::build(&mesh).unwrap();
        // The work of preprocessing: every node moves the original triangles under the
        // triangles it removes (shared out evenly over the ones it creates). A balanced
        // hierarchy moves each about log(n) times; a chain moves most of them at every node.
        let mut under = vec![0f64; h.tris.len()];
        under[..h.original_triangles].fill(1.0);
        let mut moved = 0.0;
        for n in 0..h.node_count() as u32 {
            let patch: f64 = h.removed(n).iter().map(|&t| under[t as usize]).sum();
            moved += patch;
            let created = h.created(n);
            for &t in created {
                under[t as usize] = patch / created.len() as f64;
            }
        }
        let per_triangle = moved / h.original_triangles as f64;
        assert!(h.node_count() > 9000, "{}", h.node_count());
        // Measured: 330 with equal costs in hashed order, 868 in id order (and growing with the
        // grid's size as a chain's does: 465 on a 48² grid).
        assert!(
            per_triangle < 500.0,
            "{per_triangle} moves per original triangle"
        );
    }
}
