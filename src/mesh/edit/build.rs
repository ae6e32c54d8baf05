//! Building the editable mesh from a `Mesh` (welded positions, wedges, incidence lists, vertex
//! classes; optionally in spatial order) and turning it back into one.

use super::*;

/// Mesh vertex `v` as the wedge of welded vertex `vertex`.
pub(super) fn wedge_of(mesh: &Mesh, v: usize, vertex: u32) -> Wedge {
    Wedge {
        vertex,
        normal: mesh.normals()[v],
        uv: mesh.uvs().map_or(Vec2::ZERO, |u| u[v]),
        color: mesh.colors().map_or(Vec3::ONE, |c| c[v]),
    }
}

/// The position of each welded vertex (`weld` maps mesh vertices to welded ones).
pub(super) fn welded_positions(mesh: &Mesh, weld: &[u32]) -> Vec<Vec3> {
    let mut positions = vec![Vec3::ZERO; mesh.welded_vertex_count()];
    for (v, &w) in weld.iter().enumerate() {
        positions[w as usize] = mesh.positions()[v];
    }
    positions
}

/// The bits of a 10-bit `x` spread to every third bit (one axis of a 30-bit Morton code).
pub(super) fn spread_bits(x: u32) -> u32 {
    let mut x = x & 0x3ff;
    x = (x | x << 16) & 0x030000ff;
    x = (x | x << 8) & 0x0300f00f;
    x = (x | x << 4) & 0x030c30c3;
    (x | x << 2) & 0x09249249
}

/// The new position of each item when items are ordered by `keys` (each below `buckets`),
/// stably (a counting sort).
pub(super) fn counting_order(buckets: usize, keys: impl Iterator<Item = u32> + Clone) -> Vec<u32> {
    let mut start = vec![0u32; buckets + 1];
    for k in keys.clone() {
        start[k as usize + 1] += 1;
    }
    for i in 0..buckets {
        start[i + 1] += start[i];
    }
    keys.map(|k| {
        let r = start[k as usize];
        start[k as usize] += 1;
        r
    })
    .collect()
}

impl Adjacency {
    /// Build from a mesh: weld by position, wedges from the split vertices.
    pub fn new(mesh: &Mesh) -> Adjacency {
        let weld = mesh.weld();
        let positions = welded_positions(mesh, weld);
        let wedges: Vec<Wedge> = (0..mesh.vertex_count())
            .map(|v| wedge_of(mesh, v, weld[v]))
            .collect();
        let corners: Vec<[u32; 3]> = mesh.triangles().to_vec();
        Self::from_parts(
            mesh,
            positions,
            wedges,
            corners,
            mesh.material_ids().to_vec(),
        )
    }

    /// Build like [`Adjacency::new`], with the welded vertices numbered along a Morton
    /// (Z-order) curve through the bounding box, each vertex's wedges next to each other in
    /// that order, and the triangles ordered by their first vertex in it. Vertices near each
    /// other on the surface then sit near each other in every per-vertex and per-wedge array:
    /// an engine that works around one edge after another, wherever they lie (the QEM queue),
    /// finds an edge's neighbourhood in a few cache lines instead of scattered over the arrays
    /// in file order. The mesh is the same; only the numbering differs, and
    /// [`Adjacency::to_mesh`] renumbers its output anyway.
    pub fn new_spatial(mesh: &Mesh) -> Adjacency {
        let weld = mesh.weld();
        let nv = mesh.welded_vertex_count();
        let old_positions = welded_positions(mesh, weld);
        // Vertices by Morton code (10 bits per axis), ties by their old number.
        let (lo, hi) = old_positions
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        let scale = 1023.0 / (hi - lo).max_element().max(f32::MIN_POSITIVE);
        let mut keys: Vec<u64> = old_positions
            .iter()
            .enumerate()
            .map(|(i, &p)| {
                let q = ((p - lo) * scale).clamp(Vec3::ZERO, Vec3::splat(1023.0));
                let code = spread_bits(q.x as u32)
                    | spread_bits(q.y as u32) << 1
                    | spread_bits(q.z as u32) << 2;
                (code as u64) << 32 | i as u64
            })
            .collect();
        keys.sort_unstable();
        let mut vrank = vec![0u32; nv];
        for (new, &k) in keys.iter().enumerate() {
            vrank[k as u32 as usize] = new as u32;
        }
        let positions: Vec<Vec3> = keys
            .iter()
            .map(|&k| old_positions[k as u32 as usize])
            .collect();
        // Wedges grouped by their vertex's new number (a counting sort keeps file order within
        // a vertex); triangles by the smallest new number of their corners.
        let wrank = counting_order(
            nv,
            (0..mesh.vertex_count()).map(|v| vrank[weld[v] as usize]),
        );
        let blank = Wedge {
            vertex: 0,
            normal: Vec3::ZERO,
            uv: Vec2::ZERO,
            color: Vec3::ONE,
        };
        let mut wedges = vec![blank; mesh.vertex_count()];
        for v in 0..mesh.vertex_count() {
            wedges[wrank[v] as usize] = wedge_of(mesh, v, vrank[weld[v] as usize]);
        }
        let first = |t: &[u32; 3]| {
            t.map(|v| vrank[weld[v as usize] as usize])
                .into_iter()
                .min()
        };
        let trank = counting_order(nv, mesh.triangles().iter().map(|t| first(t).unwrap()));
        let mut corners = vec![[0u32; 3]; mesh.triangle_count()];
        let mut materials = vec![0u32; mesh.triangle_count()];
        for (t, c) in mesh.triangles().iter().enumerate() {
            corners[trank[t] as usize] = c.map(|v| wrank[v as usize]);
            materials[trank[t] as usize] = mesh.material_ids()[t];
        }
        Self::from_parts(mesh, positions, wedges, corners, materials)
    }

    /// The structure over welded `positions`, `wedges` (whose `vertex` index `positions`), and
    /// triangles as wedge triples `corners` with their `materials`.
    pub(super) fn from_parts(
        mesh: &Mesh,
        positions: Vec<Vec3>,
        wedges: Vec<Wedge>,
        corners: Vec<[u32; 3]>,
        materials: Vec<u32>,
    ) -> Adjacency {
        let tris: Vec<[u32; 3]> = corners
            .iter()
            .map(|c| c.map(|w| wedges[w as usize].vertex))
            .collect();
        let mut adj = Adjacency {
            alive: tris
                .iter()
                .map(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
                .collect(),
            vtris: Incidence::default(),
            class: vec![VertexClass::Interior; positions.len()],
            locked: vec![false; positions.len()],
            only_wedge: Vec::new(),
            non_manifold_collapses: false,
            materials,
            positions,
            wedges,
            tris,
            corners,
            alive_count: 0,
            has_uvs: mesh.uvs().is_some(),
            has_colors: mesh.colors().is_some(),
            marks: Vec::new(),
            mark: 0,
        };
        adj.alive_count = adj.alive.iter().filter(|&&a| a).count();
        adj.vtris = Incidence::build(adj.positions.len(), &adj.tris, &adj.alive);
        // Each vertex's wedge if all its corners share one (one pass over the corners).
        const UNSEEN: u32 = SEVERAL - 1;
        let mut only = vec![UNSEEN; adj.positions.len()];
        for (t, (tri, corners)) in adj.tris.iter().zip(&adj.corners).enumerate() {
            if adj.alive[t] {
                for (&v, &w) in tri.iter().zip(corners) {
                    let o = &mut only[v as usize];
                    if *o == UNSEEN {
                        *o = w;
                    } else if *o != w {
                        *o = SEVERAL;
                    }
                }
            }
        }
        for o in &mut only {
            if *o == UNSEEN {
                *o = SEVERAL;
            }
        }
        adj.only_wedge = only;
        adj.classify();
        adj
    }

    pub(super) fn classify(&mut self) {
        // Per vertex a, its edges to higher vertices b, from a's own triangles: how many
        // triangles each has, and the wedges of a and b in the first two (a seam is an edge of
        // two triangles whose sides differ in a's or b's wedge). Valences are small, so a scan
        // of the few edges found so far finds b.
        struct Seen {
            b: u32,
            count: u32,
            wedges: [[u32; 2]; 2],
        }
        let mut seen: SmallVec<[Seen; 16]> = SmallVec::new();
        for a in 0..self.positions.len() as u32 {
            seen.clear();
            for &t in self.vtris.get(a) {
                let (tri, corners) = (self.tris[t as usize], self.corners[t as usize]);
                let ka = if tri[0] == a {
                    0
                } else if tri[1] == a {
                    1
                } else {
                    2
                };
                for kb in [(ka + 1) % 3, (ka + 2) % 3] {
                    let b = tri[kb];
                    if b < a {
                        continue;
                    }
                    let pair = [corners[ka], corners[kb]];
                    match seen.iter_mut().find(|s| s.b == b) {
                        Some(s) => {
                            if s.count == 1 {
                                s.wedges[1] = pair;
                            }
                            s.count += 1;
                        }
                        None => seen.push(Seen {
                            b,
                            count: 1,
                            wedges: [pair, pair],
                        }),
                    }
                }
            }
            for s in &seen {
                let c = match s.count {
                    1 => VertexClass::Border,
                    2 if s.wedges[0] != s.wedges[1] => VertexClass::Seam,
                    2 => VertexClass::Interior,
                    _ => VertexClass::NonManifold,
                };
                for v in [a, s.b] {
                    let cur = &mut self.class[v as usize];
                    *cur = (*cur).max(c);
                }
            }
        }
    }

    /// The current mesh: one output vertex per used wedge, at its welded vertex's position.
    pub fn to_mesh(&self, original: &Mesh) -> crate::error::Result<Mesh> {
        let mut data = original.to_data();
        let mut remap = vec![u32::MAX; self.wedges.len()];
        let (mut pos, mut nor, mut uv, mut col) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut tris = Vec::new();
        let mut mats = Vec::new();
        for t in self.live_triangles() {
            let c = self.corners[t as usize];
            let out = c.map(|w| {
                if remap[w as usize] == u32::MAX {
                    remap[w as usize] = pos.len() as u32;
                    let wd = self.wedges[w as usize];
                    pos.push(self.positions[wd.vertex as usize]);
                    nor.push(wd.normal);
                    uv.push(wd.uv);
                    col.push(wd.color);
                }
                remap[w as usize]
            });
            tris.push(out);
            mats.push(self.materials[t as usize]);
        }
        data.positions = pos;
        data.normals = Some(nor);
        data.uvs = self.has_uvs.then_some(uv);
        data.colors = self.has_colors.then_some(col);
        data.triangles = tris;
        data.material_ids = mats;
        Mesh::new(data, &crate::mesh::LoadOptions::default())
    }
}
