//! Geometric error between two meshes, Metro-style (Cignoni, Rocchini, Scopigno 1998): sample one
//! surface densely, find each sample's closest point on the other surface, and pool the distances;
//! then the other way round. Closest points come from a BVH (`obvhs` builds the tree; the
//! closest-point traversal and the point–triangle distance are written here).
//!
//! Decisions:
//! - Samples: every vertex of the sampled mesh, plus face samples distributed by area with a
//!   running remainder (a triangle gets ⌊its share + carry⌋ samples) and placed inside each
//!   triangle by a rank-1 lattice folded into the triangle. Deterministic: no random numbers.
//! - Symmetric figures: `hausdorff` is the larger one-sided maximum; `mean` and `rms` are the
//!   larger of the two one-sided values (conservative, as Metro reports the worse side). The
//!   one-sided values are reported too.
//! - Distances are in model units; the `_relative` figures divide by the bounding-box diagonal of
//!   the first mesh (the original), as Metro does.
//! - Exact minimum over triangles: the BVH only prunes boxes farther than the best distance so
//!   far, so the result does not depend on the tree's shape (a test compares with brute force).

use glam::Vec3;
use obvhs::bvh2::Bvh2;
use rayon::prelude::*;
use smallvec::SmallVec;

use super::Mesh;

/// The result of a comparison.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SurfaceDistance {
    /// Symmetric Hausdorff distance, model units.
    pub hausdorff: f64,
    /// Mean surface distance (the larger one-sided mean), model units.
    pub mean: f64,
    /// RMS surface distance (the larger one-sided RMS), model units.
    pub rms: f64,
    /// `hausdorff` over the first mesh's bounding-box diagonal.
    pub hausdorff_relative: f64,
    /// `mean` over the diagonal.
    pub mean_relative: f64,
    /// `rms` over the diagonal.
    pub rms_relative: f64,
    /// Samples taken on each side (vertices plus face samples), A then B.
    pub samples: [usize; 2],
    /// One-sided maxima: A→B, B→A.
    pub one_sided_max: [f64; 2],
    /// One-sided means: A→B, B→A.
    pub one_sided_mean: [f64; 2],
}

/// A mesh's triangles with a BVH over them, for closest-point queries.
pub struct ClosestPoint {
    tris: Vec<[Vec3; 3]>,
    bvh: Bvh2,
}

impl std::fmt::Debug for ClosestPoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ClosestPoint")
            .field("triangles", &self.tris.len())
            .field("nodes", &self.bvh.nodes.len())
            .finish()
    }
}

/// obvhs' PLOC builder over `tris`, each box widened by a tiny, deterministic, per-triangle
/// amount (at most 0.1 % of the triangle's size). PLOC pairs nodes that choose each other by the
/// area of their union; among equal triangles in a row (a regular grid, a strip of copies) every
/// cost ties, each node picks the same side, and only one pair merges per pass: the build grows
/// with the square of the count (100 000 triangles in a row took minutes). Distinct costs break
/// the ties, so each pass merges a fixed share and the build is n log n again. Wider boxes only
/// make the search visit a few more nodes; distances are computed on the exact triangles.
fn build_bvh(tris: &[[Vec3; 3]]) -> Bvh2 {
    use obvhs::aabb::Aabb;
    let boxes: Vec<Aabb> = tris
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let lo = t[0].min(t[1]).min(t[2]);
            let hi = t[0].max(t[1]).max(t[2]);
            // SplitMix64 of the index: a fraction in [0, 1) that is the same on every run.
            let mut z = (i as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            let frac = ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32;
            let size = (hi - lo).max_element().max(f32::MIN_POSITIVE);
            let pad = Vec3::splat(1e-3 * size * frac);
            Aabb::new((lo - pad).into(), (hi + pad).into())
        })
        .collect();
    let params = obvhs::BvhBuildParams::medium_build();
    let mut bvh = obvhs::ploc::PlocBuilder::with_capacity(boxes.len()).build(
        params.ploc_search_distance,
        &boxes,
        (0..boxes.len() as u32).collect::<Vec<_>>(),
        params.sort_precision,
        params.search_depth_threshold,
    );
    let mut reinsertion = obvhs::bvh2::reinsertion::ReinsertionOptimizer::default();
    reinsertion.run(&mut bvh, params.reinsertion_batch_ratio, None);
    obvhs::bvh2::leaf_collapser::collapse(&mut bvh, 2, 1.0);
    reinsertion.run(
        &mut bvh,
        params.reinsertion_batch_ratio * params.post_collapse_reinsertion_batch_ratio_multiplier,
        None,
    );
    bvh
}

impl ClosestPoint {
    /// Build the tree over `mesh`'s triangles.
    pub fn new(mesh: &Mesh) -> ClosestPoint {
        let p = mesh.positions();
        let tris: Vec<[Vec3; 3]> = mesh
            .triangles()
            .iter()
            .map(|t| t.map(|i| p[i as usize]))
            .collect();
        let bvh = build_bvh(&tris);
        ClosestPoint { tris, bvh }
    }

    /// Distance from `q` to the surface.
    pub fn distance(&self, q: Vec3) -> f32 {
        self.closest(q).map_or(f32::INFINITY, |(_, d)| d)
    }

    /// The triangle nearest to `q` (its index in the mesh's triangle list) and the distance to
    /// it; `None` for a mesh without triangles.
    pub fn closest(&self, q: Vec3) -> Option<(u32, f32)> {
        self.search(q, None)
    }

    /// [`ClosestPoint::closest`], starting from triangle `hint` (typically the answer for a
    /// nearby point): the same distance, found sooner because the hint's distance prunes the
    /// tree from the root. Where two triangles are equally near, either may be returned.
    pub fn closest_from(&self, q: Vec3, hint: u32) -> Option<(u32, f32)> {
        self.search(q, Some(hint))
    }

    fn search(&self, q: Vec3, hint: Option<u32>) -> Option<(u32, f32)> {
        let mut best = f32::INFINITY;
        let mut best_tri = None;
        if let Some(h) = hint.filter(|&h| (h as usize) < self.tris.len()) {
            best = point_triangle_distance2(q, &self.tris[h as usize]).sqrt();
            best_tri = Some(h);
        }
        let nodes = &self.bvh.nodes;
        if nodes.is_empty() {
            return None;
        }
        // A BVH of 2^32 triangles is at most a few hundred levels deep in practice; the small
        // vector spills to the heap only beyond 64 pending nodes.
        let mut stack: SmallVec<[u32; 64]> = SmallVec::new();
        stack.push(0);
        while let Some(n) = stack.pop() {
            let node = &nodes[n as usize];
            if box_distance2(q, node.aabb.min.into(), node.aabb.max.into()) >= best * best {
                continue;
            }
            if node.prim_count > 0 {
                let first = node.first_index as usize;
                for &prim in &self.bvh.primitive_indices[first..first + node.prim_count as usize] {
                    let d2 = point_triangle_distance2(q, &self.tris[prim as usize]);
                    // Ties go to the lower triangle index, whatever order the tree visits them.
                    if d2 < best * best || (d2 == best * best && best_tri.is_some_and(|t| prim < t))
                    {
                        best = d2.sqrt();
                        best_tri = Some(prim);
                    }
                }
            } else {
                // Visit the nearer child first (pushed last).
                let (l, r) = (node.first_index, node.first_index + 1);
                let dl = box_distance2(
                    q,
                    nodes[l as usize].aabb.min.into(),
                    nodes[l as usize].aabb.max.into(),
                );
                let dr = box_distance2(
                    q,
                    nodes[r as usize].aabb.min.into(),
                    nodes[r as usize].aabb.max.into(),
                );
                if dl < dr {
                    stack.push(r);
                    stack.push(l);
                } else {
                    stack.push(l);
                    stack.push(r);
                }
            }
        }
        best_tri.map(|t| (t, best))
    }

    /// The corners of triangle `t`.
    pub fn triangle(&self, t: u32) -> &[Vec3; 3] {
        &self.tris[t as usize]
    }

    /// Brute force over every triangle (for tests).
    pub fn distance_brute_force(&self, q: Vec3) -> f32 {
        self.tris
            .iter()
            .map(|t| point_triangle_distance2(q, t))
            .fold(f32::INFINITY, f32::min)
            .sqrt()
    }
}

fn box_distance2(q: Vec3, min: Vec3, max: Vec3) -> f32 {
    let d = (min - q).max(Vec3::ZERO).max(q - max);
    d.length_squared()
}

/// Squared distance from `p` to triangle `t` (Ericson, Real-Time Collision Detection §5.1.5).
pub fn point_triangle_distance2(p: Vec3, t: &[Vec3; 3]) -> f32 {
    (p - Nearest::of(p, t).point(t)).length_squared()
}

/// The barycentric coordinates (of `t`'s corners) of the point of triangle `t` nearest to `p`.
pub fn nearest_barycentric(p: Vec3, t: &[Vec3; 3]) -> Vec3 {
    match Nearest::of(p, t) {
        Nearest::A => Vec3::X,
        Nearest::B => Vec3::Y,
        Nearest::C => Vec3::Z,
        Nearest::Ab(v) => Vec3::new(1.0 - v, v, 0.0),
        Nearest::Ac(w) => Vec3::new(1.0 - w, 0.0, w),
        Nearest::Bc(w) => Vec3::new(0.0, 1.0 - w, w),
        Nearest::Face(v, w) => Vec3::new(1.0 - v - w, v, w),
    }
}

/// Which feature of a triangle (a, b, c) is nearest to a point, with its parameters.
enum Nearest {
    A,
    B,
    C,
    /// a + (b − a)·v.
    Ab(f32),
    /// a + (c − a)·w.
    Ac(f32),
    /// b + (c − b)·w.
    Bc(f32),
    /// a + (b − a)·v + (c − a)·w.
    Face(f32, f32),
}

impl Nearest {
    /// Ericson's region tests (§5.1.5).
    fn of(p: Vec3, t: &[Vec3; 3]) -> Nearest {
        let [a, b, c] = *t;
        let (ab, ac, ap) = (b - a, c - a, p - a);
        let (d1, d2) = (ab.dot(ap), ac.dot(ap));
        if d1 <= 0.0 && d2 <= 0.0 {
            return Nearest::A;
        }
        let bp = p - b;
        let (d3, d4) = (ab.dot(bp), ac.dot(bp));
        if d3 >= 0.0 && d4 <= d3 {
            return Nearest::B;
        }
        let vc = d1 * d4 - d3 * d2;
        if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            return Nearest::Ab(d1 / (d1 - d3));
        }
        let cp = p - c;
        let (d5, d6) = (ab.dot(cp), ac.dot(cp));
        if d6 >= 0.0 && d5 <= d6 {
            return Nearest::C;
        }
        let vb = d5 * d2 - d1 * d6;
        if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            return Nearest::Ac(d2 / (d2 - d6));
        }
        let va = d3 * d6 - d5 * d4;
        if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
            return Nearest::Bc((d4 - d3) / ((d4 - d3) + (d5 - d6)));
        }
        let denom = 1.0 / (va + vb + vc);
        Nearest::Face(vb * denom, vc * denom)
    }

    /// The nearest point, computed as the region test's formula gives it.
    fn point(&self, t: &[Vec3; 3]) -> Vec3 {
        let [a, b, c] = *t;
        match *self {
            Nearest::A => a,
            Nearest::B => b,
            Nearest::C => c,
            Nearest::Ab(v) => a + (b - a) * v,
            Nearest::Ac(w) => a + (c - a) * w,
            Nearest::Bc(w) => b + (c - b) * w,
            Nearest::Face(v, w) => a + (b - a) * v + (c - a) * w,
        }
    }
}

/// Deterministic surface samples of `mesh`: its vertices plus about `face_samples` points spread
/// by area.
pub fn samples(mesh: &Mesh, face_samples: usize) -> Vec<Vec3> {
    let p = mesh.positions();
    let mut out: Vec<Vec3> = p.to_vec();
    let areas: Vec<f64> = mesh
        .triangles()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| p[i as usize]);
            0.5 * (b - a).cross(c - a).length() as f64
        })
        .collect();
    let total: f64 = areas.iter().sum();
    if total <= 0.0 {
        return out;
    }
    let density = face_samples as f64 / total;
    let mut carry = 0.0f64;
    // Rank-1 lattice with the plastic-number generator (R2 sequence), folded into the triangle.
    const G: f64 = 1.324_717_957_244_746;
    let (a1, a2) = (1.0 / G, 1.0 / (G * G));
    for (t, area) in mesh.triangles().iter().zip(&areas) {
        let want = area * density + carry;
        let n = want.floor() as usize;
        carry = want - n as f64;
        let [a, b, c] = t.map(|i| p[i as usize]);
        for k in 0..n {
            let (mut u, mut v) = (
                (0.5 + a1 * (k + 1) as f64).fract(),
                (0.5 + a2 * (k + 1) as f64).fract(),
            );
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            out.push(a + (b - a) * u as f32 + (c - a) * v as f32);
        }
    }
    out
}

/// One direction: distances from `samples` to the surface.
fn one_sided(samples: &[Vec3], to: &ClosestPoint) -> (f64, f64, f64) {
    // Samples come triangle by triangle, so the previous sample's nearest triangle is a close
    // hint for the next (the distance does not depend on the hint, only the search's length).
    let d: Vec<f32> = samples
        .par_chunks(1024)
        .flat_map_iter(|chunk| {
            let mut hint = None;
            chunk
                .iter()
                .map(|&q| {
                    let found = match hint {
                        Some(h) => to.closest_from(q, h),
                        None => to.closest(q),
                    };
                    hint = found.map(|f| f.0);
                    found.map_or(f32::INFINITY, |f| f.1)
                })
                .collect::<Vec<_>>()
        })
        .collect();
    let max = d.iter().copied().fold(0.0f32, f32::max) as f64;
    // Sums in index order (deterministic for any thread count).
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for &x in &d {
        s += x as f64;
        s2 += (x as f64) * (x as f64);
    }
    let n = d.len().max(1) as f64;
    (max, s / n, (s2 / n).sqrt())
}

/// Compare `a` (the original) with `b`, with about `face_samples` face samples on each.
pub fn compare(a: &Mesh, b: &Mesh, face_samples: usize) -> SurfaceDistance {
    Original::new(a, face_samples).compare(b)
}

/// The original's half of a comparison (its tree, samples and diagonal), built once and reused
/// for every LOD of it.
#[derive(Debug)]
pub struct Original {
    tree: ClosestPoint,
    samples: Vec<Vec3>,
    diagonal: f64,
    face_samples: usize,
}

impl Original {
    /// Prepare `a` with about `face_samples` face samples (the same number is taken on each LOD).
    pub fn new(a: &Mesh, face_samples: usize) -> Original {
        Original {
            tree: ClosestPoint::new(a),
            samples: samples(a, face_samples),
            diagonal: a.aabb().diagonal() as f64,
            face_samples,
        }
    }

    /// Compare the original with `b`.
    pub fn compare(&self, b: &Mesh) -> SurfaceDistance {
        let (sa, ta, diagonal) = (&self.samples, &self.tree, self.diagonal);
        let (tb, sb) = (ClosestPoint::new(b), samples(b, self.face_samples));
        let (max_ab, mean_ab, rms_ab) = one_sided(sa, &tb);
        let (max_ba, mean_ba, rms_ba) = one_sided(&sb, ta);
        summarise(
            diagonal,
            [sa.len(), sb.len()],
            [max_ab, mean_ab, rms_ab],
            [max_ba, mean_ba, rms_ba],
        )
    }
}

/// Pool the two one-sided (max, mean, rms) results.
fn summarise(diagonal: f64, n: [usize; 2], ab: [f64; 3], ba: [f64; 3]) -> SurfaceDistance {
    let ([max_ab, mean_ab, rms_ab], [max_ba, mean_ba, rms_ba]) = (ab, ba);
    let (h, mean, rms) = (max_ab.max(max_ba), mean_ab.max(mean_ba), rms_ab.max(rms_ba));
    let rel = |x: f64| if diagonal > 0.0 { x / diagonal } else { 0.0 };
    SurfaceDistance {
        hausdorff: h,
        mean,
        rms,
        hausdorff_relative: rel(h),
        mean_relative: rel(mean),
        rms_relative: rel(rms),
        samples: n,
        one_sided_max: [max_ab, max_ba],
        one_sided_mean: [mean_ab, mean_ba],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    #[test]
    fn point_triangle_regions() {
        let t = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let d = |p: Vec3| point_triangle_distance2(p, &t).sqrt();
        assert!((d(Vec3::new(0.2, 0.2, 1.0)) - 1.0).abs() < 1e-6); // face
        assert!((d(Vec3::new(-1.0, -1.0, 0.0)) - 2f32.sqrt()).abs() < 1e-6); // vertex a
        assert!((d(Vec3::new(0.5, -2.0, 0.0)) - 2.0).abs() < 1e-6); // edge ab
        assert!((d(Vec3::new(1.0, 1.0, 0.0)) - 0.5f32.sqrt()).abs() < 1e-6); // edge bc
    }

    #[test]
    fn bvh_equals_brute_force() {
        let m = shapes::bumpy_sphere(3);
        let cp = ClosestPoint::new(&m);
        for q in samples(&shapes::torus(12, 8, 0.4), 500) {
            assert_eq!(cp.distance(q), cp.distance_brute_force(q), "{q}");
        }
    }

    #[test]
    fn a_hint_changes_the_speed_not_the_distance() {
        let m = shapes::bumpy_sphere(3);
        let cp = ClosestPoint::new(&m);
        let n = m.triangles().len() as u32;
        for (i, q) in samples(&shapes::torus(12, 8, 0.4), 500)
            .into_iter()
            .enumerate()
        {
            let hint = (i as u32 * 7919) % n;
            let (_, d) = cp.closest_from(q, hint).unwrap();
            assert_eq!(d, cp.distance_brute_force(q), "{q} from {hint}");
        }
    }

    #[test]
    fn sphere_versus_inscribed_icosahedron_is_analytic() {
        // The icosahedron's vertices lie on the unit sphere; the farthest sphere point from it is
        // above a face centre, at 1 − r_in with r_in ≈ 0.794654 the inradius for circumradius 1. A subdivision-6 icosphere stands in for the sphere (its own
        // deviation from the sphere is below 3e-4).
        let sphere = shapes::icosphere(6);
        let ico = shapes::icosphere(0);
        // Inradius of the regular icosahedron with circumradius 1, directly: φ²/(√3·√(φ²+1)).
        let phi = (1.0 + 5f64.sqrt()) / 2.0;
        let r_in = phi * phi / (3f64.sqrt() * (phi * phi + 1.0).sqrt());
        let d = compare(&sphere, &ico, 200_000);
        assert!(
            (d.hausdorff - (1.0 - r_in)).abs() < 1e-3,
            "{} vs {}",
            d.hausdorff,
            1.0 - r_in
        );
        // Identical meshes: zero up to f32 rounding of the face samples.
        let same = compare(&ico, &ico, 1000);
        assert!(same.hausdorff < 1e-6 && same.mean < 1e-6, "{same:?}");
    }
}
