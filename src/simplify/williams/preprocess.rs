//! Per-node preprocessing of Williams et al. 2003 §4: for every MT node, the bounds of the patch of
//! the *original* surface it affects — bounding sphere, silhouette normal cone (face normals of the
//! original triangles and of the node's own triangles, §5.3), shading normal cone (vertex normals,
//! widened by the normal map's tilt, §5.4), intrinsic luminance range of the texels covered (§5.2,
//! through `texels.rs`) — and its texture deviation.
//!
//! Cumulative, not incremental (§5.2): a node's bounds are those of the *original* triangles its
//! patch corresponds to. Every original triangle is tracked, by its centroid, on the current
//! triangle that holds it (the same correspondence as the texture deviation below); a node's bounds
//! merge the original triangles on the triangles it removes, plus the face normals of its own
//! removed and created triangles (§5.3: "a simplified surface may well contain sharper dihedral
//! angles than the original").
//!
//! Texture deviation (§2.2; Cohen, Olano, Manocha 1998): the 3D distance between a point of the
//! original surface and the point of the simplified surface with the same texture coordinate.
//! Decision: measured at the original vertices. Each vertex is tracked on the current triangle
//! holding it; when a node replaces a patch, its vertices are placed on the new triangle whose UV
//! triangle contains their UV (the parametric correspondence) or, where none does (untextured
//! meshes, points across a UV seam), on the closest new triangle (the geometric correspondence the
//! paper falls back to). The node's deviation is the largest distance so found, and at least its
//! prerequisites' (deviation never shrinks going coarser).

use glam::{Vec2, Vec3};

use super::bounds::{Ball, Cone, Range};
use super::hierarchy::Hierarchy;
use super::texels::{LuminancePyramid, normal_map_tilt};
use crate::color::luminance;
use crate::mesh::surface_distance::point_triangle_distance2;

/// What the run-time evaluation needs of one node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeData {
    /// Bounds of the original triangles under the node and of its own triangles.
    pub ball: Ball,
    /// Face normals (silhouette test).
    pub silhouette: Cone,
    /// Shading normals (lighting contrast).
    pub shading: Cone,
    /// Intrinsic (unlit) luminance range, linear 0..1.
    pub luminance: Range,
    /// Texture deviation, model units.
    pub deviation: f32,
    /// The material of its first removed triangle (for the highlight's colour and exponent).
    pub material: u32,
}

/// Per-material shading facts.
#[derive(Debug, Clone)]
pub struct MaterialFacts {
    /// Luminance of the specular colour.
    pub specular: f32,
    /// Blinn–Phong exponent.
    pub shininess: f32,
    /// Largest tilt of the normal map, radians (0 without one).
    pub tilt: f32,
    pub(crate) pyramid: Option<LuminancePyramid>,
    pub(crate) base: f32,
}

/// The preprocessed hierarchy data.
#[derive(Debug, Clone)]
pub struct Preprocessed {
    /// One entry per node.
    pub nodes: Vec<NodeData>,
    /// One entry per material of the original.
    pub materials: Vec<MaterialFacts>,
    /// Whether any material has a base-colour texture.
    pub textured: bool,
}

/// Bounds of one triangle on its own.
fn triangle_data(h: &Hierarchy, materials: &[MaterialFacts], t: u32) -> NodeData {
    let tri = &h.tris[t as usize];
    let c = tri.corners.map(|k| h.corners[k as usize]);
    let p = c.map(|k| k.position);
    let m = &materials[tri.material as usize];
    let face = (p[1] - p[0]).cross(p[2] - p[0]);
    let shading = c
        .iter()
        .fold(Cone::EMPTY, |acc, k| acc.merge(Cone::of(k.normal)))
        .widen(m.tilt);
    let texture = match &m.pyramid {
        Some(pyr) => pyr.triangle_range(c.map(|k| k.uv)),
        None => Range::of(m.base),
    };
    let tint = c
        .iter()
        .fold(Range::EMPTY, |r, k| r.merge(Range::of(luminance(k.color))));
    NodeData {
        ball: Ball::of_points(&p),
        silhouette: Cone::of(face),
        shading,
        luminance: Range {
            lo: texture.lo * tint.lo,
            hi: texture.hi * tint.hi,
        },
        deviation: 0.0,
        material: tri.material,
    }
}

/// The cone around the mean axis of `cones` that holds them all (pairwise merging drifts and
/// widens over many inputs; the mean axis keeps a flat patch's cone narrow). A patch whose normals
/// cancel out gets the full sphere.
fn cone_around_mean(cones: impl Iterator<Item = Cone> + Clone) -> Cone {
    let Some(axis) = cones
        .clone()
        .filter(|c| !c.is_empty())
        .map(|c| c.axis)
        .sum::<Vec3>()
        .try_normalize()
    else {
        return Cone::ALL;
    };
    let half = cones
        .filter(|c| !c.is_empty())
        .map(|c| c.axis.dot(axis).clamp(-1.0, 1.0).acos() + c.half_angle)
        .fold(0.0f32, f32::max);
    Cone {
        axis,
        half_angle: (half + 1e-5).min(std::f32::consts::PI),
    }
}

/// Bounds of a node from its items: the patch's original triangles, then (from `own_from` on) the
/// node's own triangles, whose texels do not count (§5.2: cumulative, from the original). The
/// sphere is centred on the middle of the items' box.
fn bound(items: &[NodeData], own_from: usize) -> NodeData {
    let (lo, hi) = items.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), d| (lo.min(d.ball.center), hi.max(d.ball.center)),
    );
    let center = 0.5 * (lo + hi);
    let radius = items
        .iter()
        .map(|d| d.ball.center.distance(center) + d.ball.radius.max(0.0))
        .fold(0.0f32, f32::max);
    let mut luminance = items[..own_from]
        .iter()
        .fold(Range::EMPTY, |r, d| r.merge(d.luminance));
    if luminance.is_empty() {
        luminance = items[own_from..]
            .iter()
            .fold(Range::EMPTY, |r, d| r.merge(d.luminance));
    }
    NodeData {
        ball: Ball {
            center,
            radius: radius * (1.0 + 1e-6),
        },
        silhouette: cone_around_mean(items.iter().map(|d| d.silhouette)),
        shading: cone_around_mean(items.iter().map(|d| d.shading)),
        luminance,
        deviation: 0.0,
        material: items[own_from].material,
    }
}

/// Where a point lands on a new patch: the point with the same UV on a triangle whose UV triangle
/// holds `uv`, else the closest point; returns (triangle index in `patch`, distance).
fn place(p: Vec3, uv: Option<Vec2>, patch: &[[(Vec3, Vec2); 3]]) -> (usize, f32) {
    if let Some(uv) = uv {
        for (i, t) in patch.iter().enumerate() {
            let (a, b, c) = (t[0].1, t[1].1, t[2].1);
            let den = (b - a).perp_dot(c - a);
            if den.abs() <= f32::EPSILON * 1e-3 {
                continue;
            }
            let l1 = (uv - a).perp_dot(c - a) / den;
            let l2 = (b - a).perp_dot(uv - a) / den;
            let l0 = 1.0 - l1 - l2;
            const SLACK: f32 = -1e-4;
            if l0 >= SLACK && l1 >= SLACK && l2 >= SLACK {
                let q = t[0].0 * l0 + t[1].0 * l1 + t[2].0 * l2;
                return (i, q.distance(p));
            }
        }
    }
    patch
        .iter()
        .enumerate()
        .map(|(i, t)| (i, point_triangle_distance2(p, &t.map(|k| k.0)).sqrt()))
        .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
        .unwrap_or((0, 0.0))
}

/// Preprocess every node of `h`.
pub fn preprocess(h: &Hierarchy) -> Preprocessed {
    let materials: Vec<MaterialFacts> = h
        .original
        .materials()
        .iter()
        .map(|m| MaterialFacts {
            specular: luminance(m.specular),
            shininess: m.shininess,
            tilt: m
                .normal_texture
                .as_ref()
                .map_or(0.0, |s| normal_map_tilt(&s.texture)),
            pyramid: m
                .base_color_texture
                .as_ref()
                .map(|s| LuminancePyramid::new(&s.texture, m.base_color)),
            base: luminance(m.base_color),
        })
        .collect();
    let textured = h.original.uvs().is_some() && materials.iter().any(|m| m.pyramid.is_some());

    // Samples: the original vertices (texture deviation only) and the original triangles'
    // centroids (deviation, and the triangle's bounds), each on the current triangle holding it.
    let mut samples: Vec<(Vec3, Vec2, Option<NodeData>)> = Vec::new();
    let mut on_tri: Vec<Vec<u32>> = vec![Vec::new(); h.tris.len()];
    let mut seen: std::collections::HashSet<[u32; 3]> = std::collections::HashSet::new();
    for (t, held) in on_tri.iter_mut().enumerate().take(h.original_triangles) {
        let c = h.tris[t].corners.map(|k| h.corners[k as usize]);
        for k in c {
            if seen.insert(k.position.to_array().map(f32::to_bits)) {
                held.push(samples.len() as u32);
                samples.push((k.position, k.uv, None));
            }
        }
        held.push(samples.len() as u32);
        samples.push((
            (c[0].position + c[1].position + c[2].position) / 3.0,
            (c[0].uv + c[1].uv + c[2].uv) / 3.0,
            Some(triangle_data(h, &materials, t as u32)),
        ));
    }

    let mut nodes: Vec<NodeData> = Vec::with_capacity(h.node_count());
    for n in 0..h.node_count() as u32 {
        let removed = h.removed(n);
        let created = h.created(n);
        // Deviation never shrinks going coarser: start from the prerequisites'.
        let mut deviation = h
            .prerequisites(n)
            .iter()
            .map(|&p| nodes[p as usize].deviation)
            .fold(0.0, f32::max);
        let moving: Vec<u32> = removed
            .iter()
            .flat_map(|&t| std::mem::take(&mut on_tri[t as usize]))
            .collect();
        // The patch's original triangles, and the node's own triangles (their geometry and
        // normals, not their texels).
        let mut items: Vec<NodeData> = moving
            .iter()
            .filter_map(|&q| samples[q as usize].2)
            .collect();
        let own_from = items.len();
        for &t in removed.iter().chain(created) {
            items.push(triangle_data(h, &materials, t));
        }
        let mut data = bound(&items, own_from);
        data.material = h.tris[removed[0] as usize].material;
        // Texture deviation: move the patch's samples onto the new triangles.
        let patch: Vec<[(Vec3, Vec2); 3]> = created
            .iter()
            .map(|&t| {
                h.tris[t as usize].corners.map(|k| {
                    let c = h.corners[k as usize];
                    (c.position, c.uv)
                })
            })
            .collect();
        if !patch.is_empty() {
            for q in moving {
                let (p, uv, _) = samples[q as usize];
                let (i, d) = place(p, textured.then_some(uv), &patch);
                deviation = deviation.max(d);
                on_tri[created[i] as usize].push(q);
            }
        }
        data.deviation = deviation;
        nodes.push(data);
    }
    Preprocessed {
        nodes,
        materials,
        textured,
    }
}
