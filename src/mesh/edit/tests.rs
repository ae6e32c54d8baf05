//! The editable mesh under random operation sequences, and tiny meshes with a stated reason.

use super::*;
use crate::mesh::shapes;
use proptest::prelude::*;

/// A cube of 3×3 grids with one normal per face: every vertex on a cube edge has two or three
/// wedges (normal seams along the cube's edges).
fn faceted_cube() -> Mesh {
    let mut data = shapes::cube_grid(3).to_data();
    let (mut positions, mut normals) = (Vec::new(), Vec::new());
    let mut index = std::collections::HashMap::new();
    for t in data.triangles.iter_mut() {
        let p = t.map(|v| data.positions[v as usize]);
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize().round();
        for v in t.iter_mut() {
            let key = (*v, n.to_array().map(|c| c as i32));
            *v = *index.entry(key).or_insert_with(|| {
                positions.push(data.positions[*v as usize]);
                normals.push(n);
                positions.len() as u32 - 1
            });
        }
    }
    data.positions = positions;
    data.normals = Some(normals);
    Mesh::new(data, &crate::mesh::LoadOptions::DEFAULT).unwrap()
}

/// An icosphere with every fifth face doubled back to back (non-manifold edges, as in scans).
fn with_fins() -> Mesh {
    let mut data = shapes::icosphere(2).to_data();
    let extra: Vec<[u32; 3]> = data
        .triangles
        .iter()
        .step_by(5)
        .map(|&[a, b, c]| [a, c, b])
        .collect();
    data.triangles.extend(extra);
    data.material_ids.clear();
    Mesh::new(data, &crate::mesh::LoadOptions::DEFAULT).unwrap()
}

/// Each triangle of `adj` as its three corners' (position, normal, uv, colour) bits, sorted:
/// the surface regardless of numbering.
fn corner_set(adj: &Adjacency) -> Vec<[[u32; 11]; 3]> {
    let mut out: Vec<[[u32; 11]; 3]> = adj
        .live_triangles()
        .map(|t| {
            adj.corners(t).map(|w| {
                let wd = adj.wedges[w as usize];
                let p = adj.positions[wd.vertex as usize];
                let mut k = [0u32; 11];
                for (i, x) in p
                    .to_array()
                    .into_iter()
                    .chain(wd.normal.to_array())
                    .chain(wd.uv.to_array())
                    .chain(wd.color.to_array())
                    .enumerate()
                {
                    k[i] = x.to_bits();
                }
                k
            })
        })
        .collect();
    out.sort_unstable();
    out
}

#[test]
fn the_spatial_numbering_is_the_same_surface_with_neighbours_close() {
    // The shipped bunny's file order puts many edges' ends thousands of vertices apart; the
    // Morton numbering must keep the surface (every triangle's corners and attributes, the
    // classes and seams) and bring an edge's ends close: the median index gap over the
    // edges falls from 135 (file order) to a handful.
    let bunny = crate::mesh::load(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("reference/models/bunny/stanford-bunny.obj"),
        &crate::mesh::LoadOptions::default(),
    )
    .unwrap();
    let median_gap = |adj: &Adjacency| {
        let mut gaps: Vec<u32> = adj.edges().iter().map(|&(a, b)| b.abs_diff(a)).collect();
        gaps.sort_unstable();
        gaps[gaps.len() / 2]
    };
    for m in [bunny, faceted_cube(), with_fins()] {
        let (plain, spatial) = (Adjacency::new(&m), Adjacency::new_spatial(&m));
        spatial.check().unwrap();
        assert_eq!(corner_set(&plain), corner_set(&spatial));
        assert_eq!(plain.border_edges(), spatial.border_edges());
        assert_eq!(plain.non_manifold_edges(), spatial.non_manifold_edges());
        let classes = |adj: &Adjacency| {
            let mut c = adj.class.clone();
            c.sort_unstable();
            c
        };
        assert_eq!(classes(&plain), classes(&spatial));
        // Each vertex's wedges are consecutive and in vertex order.
        let owners: Vec<u32> = spatial.wedges.iter().map(|w| w.vertex).collect();
        assert!(owners.windows(2).all(|p| p[0] <= p[1]));
        if m.triangle_count() > 10_000 {
            let (before, after) = (median_gap(&plain), median_gap(&spatial));
            assert!(before > 100 && after * 10 < before, "{before} -> {after}");
        }
    }
}

#[test]
fn collapse_and_undo_restore_exactly() {
    let m = shapes::icosphere(2);
    let mut adj = Adjacency::new(&m);
    let before = adj.clone();
    let (a, b) = adj.edges()[7];
    let p = adj.positions[b as usize];
    let undo = adj.collapse(a, b, p).unwrap();
    assert_eq!(adj.triangle_count(), m.triangle_count() - 2);
    adj.check().unwrap();
    adj.undo(undo);
    assert_eq!(adj.tris, before.tris);
    assert_eq!(adj.vtris, before.vtris);
    assert_eq!(adj.positions, before.positions);
    assert_eq!(adj.alive, before.alive);
}

#[test]
fn split_and_swap_keep_the_surface_and_undo() {
    let m = shapes::icosphere(1);
    let mut adj = Adjacency::new(&m);
    let before = adj.clone();
    let (a, b) = adj.edges()[3];
    let (v, undo) = adj.split(a, b).unwrap();
    adj.check().unwrap();
    assert_eq!(adj.triangle_count(), m.triangle_count() + 2);
    assert_eq!(adj.neighbours(v).len(), 4);
    assert_eq!(adj.border_edges(), 0);
    adj.undo(undo);
    assert_eq!(
        (adj.tris.clone(), adj.vtris.clone()),
        (before.tris.clone(), before.vtris.clone())
    );
    let undo = adj.swap(a, b).unwrap();
    adj.check().unwrap();
    assert!(adj.edge_triangles(a, b).is_empty());
    assert_eq!(adj.border_edges(), 0);
    adj.undo(undo);
    assert_eq!(adj.tris, before.tris);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn random_operations_keep_the_invariants(
        kind in 0u8..3,
        ops in proptest::collection::vec((0u8..3, 0usize..10_000, any::<bool>()), 1..60),
    ) {
        // A closed sphere (smooth, or a cube whose faces meet at normal seams) stays closed and
        // manifold under any accepted operation, and undoing an operation restores the state.
        // A sphere with back-to-back duplicate faces, with non-manifold collapses allowed, keeps
        // the structure's invariants.
        let seams = kind == 1;
        let m = match kind {
            0 => shapes::icosphere(2),
            1 => faceted_cube(),
            _ => with_fins(),
        };
        let mut adj = Adjacency::new(&m);
        if kind == 2 {
            prop_assert!(adj.non_manifold_edges() > 0);
            adj.allow_non_manifold_collapses();
        }
        let several = (0..adj.positions.len() as u32).filter(|&v| adj.vertex_wedges(v).len() > 1);
        prop_assert_eq!(several.count() > 0, seams);
        for (op, pick, keep) in ops {
            let edges = adj.edges();
            let (a, b) = edges[pick % edges.len()];
            let snapshot = (adj.tris.clone(), adj.alive.clone(), adj.positions.clone());
            // The shortcut wedge look-ups agree with the general ones.
            prop_assert_eq!(adj.edge_wedge_map(a, b), adj.collapse_wedge_map(a, b));
            let mid = 0.5 * (adj.positions[a as usize] + adj.positions[b as usize]);
            if op == 0 && keep {
                // Collapsing for good leaves the same structure as a collapse with an undo record.
                let mut other = adj.clone();
                let mut ring = Local::new();
                let (x, y) = (other.collapse_for_good(a, b, mid, &mut ring), adj.clone().collapse(a, b, mid));
                prop_assert_eq!(x.is_ok(), y.is_ok());
                if x.is_ok() {
                    let mut with_undo = adj.clone();
                    with_undo.collapse(a, b, mid).unwrap();
                    prop_assert_eq!(&other.tris, &with_undo.tris);
                    prop_assert_eq!(&other.corners, &with_undo.corners);
                    prop_assert_eq!(&other.vtris, &with_undo.vtris);
                    prop_assert_eq!(&other.positions, &with_undo.positions);
                    // The ring handed back is b's neighbours afterwards.
                    ring.sort_unstable();
                    prop_assert_eq!(ring, other.neighbours(b));
                }
            }
            let result = match op {
                0 => adj.collapse(a, b, mid),
                1 => adj.split(a, b).map(|x| x.1),
                _ => adj.swap(a, b),
            };
            if let Ok(undo) = result {
                prop_assert!(adj.check().is_ok(), "{:?}", adj.check());
                if kind < 2 {
                    prop_assert_eq!(adj.border_edges(), 0);
                    prop_assert_eq!(adj.non_manifold_edges(), 0);
                }
                if !keep {
                    adj.undo(undo);
                    prop_assert_eq!(&adj.tris, &snapshot.0);
                    prop_assert_eq!(&adj.alive, &snapshot.1);
                    prop_assert_eq!(&adj.positions, &snapshot.2);
                }
            }
        }
    }
}
