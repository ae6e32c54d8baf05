//! §5.3 on real assets: the UV charts of a mesh, their boundary loops, and the seams between them
//! as chains of welded vertices, each sampled once so that twin seam edges get the same 3D points.
//!
//! Based on: Qu & Meyer §3 and §5 (the remesh happens in the parametric domain and is projected
//! back to 3D; the paper's examples are single-chart heads and vases, and it does not say how
//! charts meet). Pierre Alliez, Mark Meyer, Mathieu Desbrun. Interactive Geometry Remeshing.
//! SIGGRAPH 2002, §4.1 (patches cut along feature and seam lines, the cut lines sampled first and
//! shared by the patches on both sides).
//!
//! Decisions:
//! - A chart is a connected set of triangles through shared vertex indices: loaders split a
//!   vertex wherever its texture coordinate (or normal) differs, so the splits are the seams.
//! - A boundary edge is an edge of one triangle only within its chart; the chart's boundary
//!   loops follow those edges in winding order.
//! - Seams are handled on the welded positions (every copy of a seam vertex is one 3D point): the
//!   welded boundary graph's vertices of degree other than 2 are corners, every corner is kept,
//!   and each chain between corners keeps vertices about one target spacing apart (the spacing
//!   the density asks for there), at least one inside a chain and two inside a closed loop, so
//!   that two chains between the same corners never become the same segment. Both sides of a
//!   seam keep the same welded vertices, so the remeshed seam edges are the same 3D segments and
//!   a closed mesh stays closed.

use glam::Vec3;

use crate::mesh::Mesh;

/// The charts and boundaries of a mesh.
#[derive(Debug, Clone)]
pub struct Charts {
    /// Chart index per triangle.
    pub of_triangle: Vec<u32>,
    /// Number of charts.
    pub count: usize,
    /// Per chart, its boundary loops as unwelded vertex indices in winding order.
    pub loops: Vec<Vec<Vec<u32>>>,
    /// The welded seam chains: each starts and ends at a corner (the same one for a closed loop).
    pub chains: Vec<Vec<u32>>,
    /// Per welded vertex, whether it lies on any chart boundary.
    pub on_boundary: Vec<bool>,
}

/// Union–find with path halving; the root is the smaller index, so components are numbered
/// deterministically.
fn find(parent: &mut [u32], mut v: u32) -> u32 {
    while parent[v as usize] != v {
        let p = parent[parent[v as usize] as usize];
        parent[v as usize] = p;
        v = p;
    }
    v
}

impl Charts {
    /// Charts, loops and chains of `mesh`.
    pub fn of(mesh: &Mesh) -> Charts {
        let tris = mesh.triangles();
        let n = mesh.vertex_count();
        let (of_triangle, count) = charts_of_triangles(tris, n);
        let outgoing = boundary_edges(tris, n);
        let loops = boundary_loops(tris, n, &of_triangle, count, &outgoing);
        let (on_boundary, chains) = boundary_chains(mesh, &outgoing);
        Charts {
            of_triangle,
            count,
            loops,
            chains,
            on_boundary,
        }
    }

    /// The welded vertices to keep on the boundaries: every chain's ends, and inside each chain
    /// the vertices where the chain's length measured in target spacings (`spacing(w)` at
    /// welded vertex `w`, model units) passes a whole number. `refine` forces vertices in.
    pub fn keep(
        &self,
        positions: &[Vec3],
        spacing: &dyn Fn(u32) -> f32,
        refine: &[bool],
    ) -> Vec<bool> {
        let mut keep: Vec<bool> = refine.to_vec();
        for chain in &self.chains {
            let (first, last) = (chain[0], chain[chain.len() - 1]);
            keep[first as usize] = true;
            keep[last as usize] = true;
            let inner = chain.len() - 2;
            let mut kept_inside = 0;
            let mut walked = 0.0f32;
            let mut mark = 1.0f32;
            for k in 1..chain.len() - 1 {
                let (a, b) = (chain[k - 1], chain[k]);
                let step = positions[a as usize].distance(positions[b as usize]);
                let h = 0.5 * (spacing(a) + spacing(b));
                walked += step / h.max(f32::MIN_POSITIVE);
                if walked >= mark {
                    keep[b as usize] = true;
                    mark = walked.floor() + 1.0;
                }
                if keep[b as usize] {
                    kept_inside += 1;
                }
            }
            // At least one vertex inside a chain, two inside a closed loop, evenly by index.
            let need = if first == last { 2 } else { 1 }.min(inner);
            if kept_inside < need {
                for j in 1..=need {
                    keep[chain[j * (inner + 1) / (need + 1)] as usize] = true;
                }
            }
        }
        keep
    }
}

/// Each triangle's chart (the connected components of shared vertices), numbered in order of
/// their first triangle, and the number of charts.
fn charts_of_triangles(tris: &[[u32; 3]], n: usize) -> (Vec<u32>, usize) {
    let mut parent: Vec<u32> = (0..n as u32).collect();
    for t in tris {
        for k in 1..3 {
            let (a, b) = (find(&mut parent, t[0]), find(&mut parent, t[k]));
            let (lo, hi) = (a.min(b), a.max(b));
            parent[hi as usize] = lo;
        }
    }
    // Charts numbered in order of their first triangle.
    let mut number = vec![u32::MAX; n];
    let mut count = 0usize;
    let of_triangle: Vec<u32> = tris
        .iter()
        .map(|t| {
            let r = find(&mut parent, t[0]) as usize;
            if number[r] == u32::MAX {
                number[r] = count as u32;
                count += 1;
            }
            number[r]
        })
        .collect();
    (of_triangle, count)
}

/// Each vertex's outgoing boundary edges' ends, sorted. From the directed edges (from, to,
/// triangle) sorted by their undirected key: an undirected edge used by one triangle is a
/// boundary edge (all its triangles are in one chart, since they share its vertices).
fn boundary_edges(tris: &[[u32; 3]], n: usize) -> Vec<Vec<u32>> {
    let mut edges: Vec<(u32, u32, u32, u32)> = Vec::with_capacity(tris.len() * 3);
    for (ti, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.push((a.min(b), a.max(b), a, ti as u32));
        }
    }
    edges.sort_unstable();
    let mut outgoing: Vec<Vec<u32>> = vec![Vec::new(); n];
    let mut i = 0;
    while i < edges.len() {
        let mut j = i + 1;
        while j < edges.len() && edges[j].0 == edges[i].0 && edges[j].1 == edges[i].1 {
            j += 1;
        }
        if j - i == 1 {
            let (lo, hi, from, _) = edges[i];
            let to = if from == lo { hi } else { lo };
            outgoing[from as usize].push(to);
        }
        i = j;
    }
    for o in &mut outgoing {
        o.sort_unstable();
    }
    outgoing
}

/// Each chart's boundary loops: outgoing boundary edges followed, the lowest unused first.
fn boundary_loops(
    tris: &[[u32; 3]],
    n: usize,
    of_triangle: &[u32],
    count: usize,
    outgoing: &[Vec<u32>],
) -> Vec<Vec<Vec<u32>>> {
    let mut loops: Vec<Vec<Vec<u32>>> = vec![Vec::new(); count];
    let mut vertex_chart = vec![u32::MAX; n];
    for (ti, t) in tris.iter().enumerate() {
        for &v in t {
            vertex_chart[v as usize] = of_triangle[ti];
        }
    }
    let mut used: Vec<Vec<bool>> = outgoing.iter().map(|o| vec![false; o.len()]).collect();
    for start in 0..n {
        while let Some(k) = used[start].iter().position(|u| !u) {
            let mut cycle = vec![start as u32];
            used[start][k] = true;
            let mut v = outgoing[start][k];
            while v as usize != start {
                cycle.push(v);
                let Some(k) = used[v as usize].iter().position(|u| !u) else {
                    break;
                };
                used[v as usize][k] = true;
                v = outgoing[v as usize][k];
            }
            if cycle.len() >= 3 {
                loops[vertex_chart[start] as usize].push(cycle);
            }
        }
    }
    loops
}

/// The welded boundary graph: which welded vertices are on it, and its chains from corner to
/// corner (a closed loop without a corner gets its lowest vertex as one).
fn boundary_chains(mesh: &Mesh, outgoing: &[Vec<u32>]) -> (Vec<bool>, Vec<Vec<u32>>) {
    let weld = mesh.weld();
    let wn = mesh.welded_vertex_count();
    let mut wedges: Vec<(u32, u32)> = Vec::new();
    for (from, outs) in outgoing.iter().enumerate() {
        for &to in outs {
            let (a, b) = (weld[from], weld[to as usize]);
            if a != b {
                wedges.push((a.min(b), a.max(b)));
            }
        }
    }
    wedges.sort_unstable();
    wedges.dedup();
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); wn];
    for &(a, b) in &wedges {
        neighbours[a as usize].push(b);
        neighbours[b as usize].push(a);
    }
    let on_boundary: Vec<bool> = neighbours.iter().map(|v| !v.is_empty()).collect();
    let mut corner: Vec<bool> = neighbours
        .iter()
        .map(|v| !v.is_empty() && v.len() != 2)
        .collect();
    let mut done_edge = std::collections::BTreeSet::new();
    let mut chains = Vec::new();
    let walk = |start: u32, corner: &[bool], done: &mut std::collections::BTreeSet<(u32, u32)>| {
        let mut found = Vec::new();
        for &first in &neighbours[start as usize] {
            if done.contains(&(start.min(first), start.max(first))) {
                continue;
            }
            let mut chain = vec![start];
            let (mut prev, mut v) = (start, first);
            loop {
                done.insert((prev.min(v), prev.max(v)));
                chain.push(v);
                if corner[v as usize] {
                    break;
                }
                let next = neighbours[v as usize]
                    .iter()
                    .copied()
                    .find(|&w| w != prev && !done.contains(&(v.min(w), v.max(w))));
                match next {
                    Some(w) => {
                        prev = v;
                        v = w;
                    }
                    None => break,
                }
            }
            found.push(chain);
        }
        found
    };
    for v in 0..wn as u32 {
        if corner[v as usize] {
            chains.extend(walk(v, &corner, &mut done_edge));
        }
    }
    // Closed loops without a corner: their lowest vertex becomes one.
    for v in 0..wn as u32 {
        let open = neighbours[v as usize]
            .iter()
            .any(|&w| !done_edge.contains(&(v.min(w), v.max(w))));
        if open {
            corner[v as usize] = true;
            chains.extend(walk(v, &corner, &mut done_edge));
        }
    }
    (on_boundary, chains)
}
