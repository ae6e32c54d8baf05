//! Attribute-aware quadrics: Garland & Heckbert 1998, "Simplifying Surfaces with Color and Texture
//! using Quadric Error Metrics", kept per wedge as Hoppe 1999 does for discontinuities.
//!
//! Every triangle is a plane in R^n, n = 3 + m, over (position, attributes): its generalized
//! quadric (§3 of GH98) is A = I − e₁e₁ᵀ − e₂e₂ᵀ, b = (p·e₁)e₁ + (p·e₂)e₂ − p,
//! c = p·p − (p·e₁)² − (p·e₂)², with e₁, e₂ an orthonormal basis of the triangle's plane in R^n,
//! weighted by the triangle's area. Each corner adds it to its wedge, so the two sides of a seam
//! keep separate quadrics (Hoppe 1999's wedges).
//!
//! Placement: the position comes from the geometric quadric (`qem.rs`); given that position, each
//! surviving wedge's attributes are the minimiser of its summed quadric, a ∗ = −A_aa⁻¹(A_ax·x + b_a)
//! (an m×m LDLᵀ solve), and the collapse costs the sum of the wedges' quadrics at (x, a∗), which is
//! the Schur complement xᵀA_xx·x + 2·b_x·x + c − rᵀA_aa⁻¹r with r = A_ax·x + b_a (a queued edge
//! needs only that value, so no attributes are formed for it). Where A_aa is singular (too few
//! faces) the wedge keeps its attributes.
//!
//! Units. Attributes are scaled into model units before they enter the quadric, so that an
//! attribute error costs like a displacement. For a mesh with bounding-box diagonal D:
//! - UV: 1.0 of texture space counts as `UV_SCALE`·D (0.5·D, so a 1 % slide of a texture costs like a
//!   0.5 %-of-diagonal displacement);
//! - normals: a unit-length change counts as `NORMAL_SCALE`·D (0.005·D; chosen by a sweep of
//!   0.05, 0.02, 0.01 and 0.005 on the shipped bunny and Spot at 50/10/1 %: 0.005 is the largest
//!   weight at which the mean surface distance stays below meshoptimizer's in all six cases, and
//!   FLIP stays below meshoptimizer's too — see results/BENCHMARKS.md);
//! - colours: 1.0 of linear RGB counts as `COLOR_SCALE`·D (0.1·D).

use glam::{DVec3, Vec2, Vec3};

use crate::mesh::edit::{Adjacency, Wedge};

/// Model units per unit of UV, as a fraction of the diagonal.
pub const UV_SCALE: f64 = 0.5;
/// Model units per unit of normal change, as a fraction of the diagonal.
pub const NORMAL_SCALE: f64 = 0.005;
/// Model units per unit of linear RGB, as a fraction of the diagonal.
pub const COLOR_SCALE: f64 = 0.1;

const MAX_M: usize = 8;

/// One generalized quadric per wedge, packed: the upper triangle of A (row-major), then b, then c.
#[derive(Debug, Clone)]
pub struct AttributeQuadrics {
    m: usize,
    stride: usize,
    data: Vec<f64>,
    has_uv: bool,
    has_color: bool,
    uv_s: f64,
    normal_s: f64,
    color_s: f64,
}

const fn tri_index(n: usize, i: usize, j: usize) -> usize {
    let (i, j) = if i <= j { (i, j) } else { (j, i) };
    i * n - i * (i + 1) / 2 + j
}

impl AttributeQuadrics {
    /// Quadrics of every wedge of `adj`; `diagonal` sets the attribute units.
    pub fn new(adj: &Adjacency, has_uv: bool, has_color: bool, diagonal: f64) -> AttributeQuadrics {
        let m = 3 + if has_uv { 2 } else { 0 } + if has_color { 3 } else { 0 };
        let n = 3 + m;
        let stride = n * (n + 1) / 2 + n + 1;
        let mut q = AttributeQuadrics {
            m,
            stride,
            data: vec![0.0; stride * adj.wedges.len()],
            has_uv,
            has_color,
            uv_s: UV_SCALE * diagonal,
            normal_s: NORMAL_SCALE * diagonal,
            color_s: COLOR_SCALE * diagonal,
        };
        // One instance per dimension (constant trip counts and packed indices).
        match n {
            6 => q.fill::<6, 28>(adj),
            8 => q.fill::<8, 45>(adj),
            9 => q.fill::<9, 55>(adj),
            11 => q.fill::<11, 78>(adj),
            n => unreachable!("attribute quadrics of dimension {n}"),
        }
        q
    }

    /// Add every live triangle's generalized quadric to its three wedges (N dimensions, S
    /// packed values: every array has its exact size).
    fn fill<const N: usize, const S: usize>(&mut self, adj: &Adjacency) {
        debug_assert_eq!(S, N * (N + 1) / 2 + N + 1);
        let off = N * (N + 1) / 2;
        let dot = |a: &[f64; N], b: &[f64; N]| (0..N).map(|i| a[i] * b[i]).sum::<f64>();
        for t in adj.live_triangles() {
            let corners = adj.corners(t);
            let pts: [[f64; N]; 3] = corners.map(|w| self.point::<N>(adj, w));
            let (p0, p1, p2) = (&pts[0], &pts[1], &pts[2]);
            let geo = |p: &[f64; N]| DVec3::new(p[0], p[1], p[2]);
            let area = 0.5 * (geo(p1) - geo(p0)).cross(geo(p2) - geo(p0)).length();
            if area <= 0.0 {
                continue;
            }
            // Orthonormal basis of the triangle's plane in R^n (Gram–Schmidt).
            let mut e1 = [0.0; N];
            let mut e2 = [0.0; N];
            for i in 0..N {
                e1[i] = p1[i] - p0[i];
                e2[i] = p2[i] - p0[i];
            }
            let l1 = dot(&e1, &e1).sqrt();
            if l1 <= 0.0 {
                continue;
            }
            e1.iter_mut().for_each(|x| *x /= l1);
            let d = dot(&e1, &e2);
            for i in 0..N {
                e2[i] -= d * e1[i];
            }
            let l2 = dot(&e2, &e2).sqrt();
            if l2 <= 1e-300 {
                continue;
            }
            e2.iter_mut().for_each(|x| *x /= l2);
            let (pe1, pe2) = (dot(p0, &e1), dot(p0, &e2));
            let mut k = [0.0; S];
            let mut at = 0;
            for i in 0..N {
                for j in i..N {
                    let id = if i == j { 1.0 } else { 0.0 };
                    k[at] = area * (id - e1[i] * e1[j] - e2[i] * e2[j]);
                    at += 1;
                }
            }
            for i in 0..N {
                k[off + i] = area * (pe1 * e1[i] + pe2 * e2[i] - p0[i]);
            }
            k[off + N] = area * (dot(p0, p0) - pe1 * pe1 - pe2 * pe2);
            for w in corners {
                let base = w as usize * S;
                for (dst, src) in self.data[base..base + S].iter_mut().zip(&k) {
                    *dst += src;
                }
            }
        }
    }

    fn n(&self) -> usize {
        3 + self.m
    }

    /// A wedge as a point of R^n in model units.
    fn point<const N: usize>(&self, adj: &Adjacency, w: u32) -> [f64; N] {
        let wd = adj.wedges[w as usize];
        let p = adj.positions[wd.vertex as usize].as_dvec3();
        let mut v = [0.0; N];
        v[..3].copy_from_slice(&p.to_array());
        self.attrs_into(&wd, &mut v[3..]);
        v
    }

    fn attrs_into(&self, wd: &Wedge, out: &mut [f64]) {
        let mut k = 0;
        for c in wd.normal.to_array() {
            out[k] = c as f64 * self.normal_s;
            k += 1;
        }
        if self.has_uv {
            for c in wd.uv.to_array() {
                out[k] = c as f64 * self.uv_s;
                k += 1;
            }
        }
        if self.has_color {
            for c in wd.color.to_array() {
                out[k] = c as f64 * self.color_s;
                k += 1;
            }
        }
    }

    /// Ask for the cache lines of wedge `w`'s quadric.
    pub fn prefetch(&self, w: u32) {
        let start = w as usize * self.stride;
        if let Some(d) = self.data.get(start..start + self.stride) {
            for i in (0..d.len()).step_by(8) {
                crate::prefetch::prefetch(&d[i]);
            }
            crate::prefetch::prefetch(&d[d.len() - 1]);
        }
    }

    /// Add wedge `src`'s quadric into wedge `dst`'s.
    pub fn merge(&mut self, dst: u32, src: u32) {
        if dst == src {
            return;
        }
        let stride = self.stride;
        let (d, s) = (dst as usize * stride, src as usize * stride);
        // Two disjoint rows of the one array, zipped (no index checks; the adds vectorize).
        let (dst_row, src_row) = if d < s {
            let (lo, hi) = self.data.split_at_mut(s);
            (&mut lo[d..d + stride], &hi[..stride])
        } else {
            let (lo, hi) = self.data.split_at_mut(d);
            (&mut hi[..stride], &lo[s..s + stride])
        };
        for (x, y) in dst_row.iter_mut().zip(src_row.iter()) {
            *x += y;
        }
    }

    /// For the summed quadric of `wedges` at position `x`: the optimal attributes (as a wedge,
    /// starting from `keep` where the system is singular) and the quadric's value there.
    pub fn optimal(&self, wedges: &[u32], x: DVec3, keep: &Wedge) -> (Wedge, f64) {
        let mut attrs = [0.0; MAX_M];
        let value = self.solve_n::<true>(wedges, x, keep, &mut attrs);
        (self.wedge_from(&attrs, keep), value)
    }

    /// The value part of [`AttributeQuadrics::optimal`] alone (what a queued edge's cost needs).
    pub fn cost(&self, wedges: &[u32], x: DVec3, keep: &Wedge) -> f64 {
        self.solve_n::<false>(wedges, x, keep, &mut [0.0; MAX_M])
    }

    /// The summed quadric's minimum over the attributes at position `x` (the attributes into
    /// `attrs` when `WANT_ATTRS`).
    fn solve_n<const WANT_ATTRS: bool>(
        &self,
        wedges: &[u32],
        x: DVec3,
        keep: &Wedge,
        attrs: &mut [f64; MAX_M],
    ) -> f64 {
        // One instance per dimension, so every loop below has a constant trip count and every
        // packed index is a constant (this runs for every queued edge; the instances unroll).
        // (N, M = N − 3 and the packed size S are all given, so every scratch array has its
        // exact size: nothing larger is cleared per call.)
        match self.n() {
            6 => self.reduced::<6, 3, 28, WANT_ATTRS>(wedges, x, keep, attrs),
            8 => self.reduced::<8, 5, 45, WANT_ATTRS>(wedges, x, keep, attrs),
            9 => self.reduced::<9, 6, 55, WANT_ATTRS>(wedges, x, keep, attrs),
            11 => self.reduced::<11, 8, 78, WANT_ATTRS>(wedges, x, keep, attrs),
            n => unreachable!("attribute quadrics of dimension {n}"),
        }
    }

    /// The sum of the wedges' packed quadrics (`S` values each).
    #[inline(always)]
    fn summed<const S: usize>(&self, wedges: &[u32]) -> [f64; S] {
        let mut q = [0.0f64; S];
        let stride = self.stride;
        let quadric = |w: u32| &self.data[w as usize * stride..(w as usize + 1) * stride];
        // The first two at once (a collapse's usual group; no copy of the first on its own).
        // (Zipped iterators: no bounds checks, so the sums vectorize.)
        let d0 = quadric(wedges[0]);
        match wedges.get(1) {
            Some(&w1) => {
                for ((s, x), y) in q.iter_mut().zip(d0).zip(quadric(w1)) {
                    *s = x + y;
                }
            }
            None => {
                for (s, x) in q.iter_mut().zip(d0) {
                    *s = *x;
                }
            }
        }
        for &w in wedges.iter().skip(2) {
            for (s, x) in q.iter_mut().zip(quadric(w)) {
                *s += x;
            }
        }
        q
    }

    /// The summed quadric's minimum over the attributes with the position held at `x`, by the
    /// Schur complement: with r = A_ax·x + b_a and A_aa = L·D·Lᵀ (L unit lower triangular),
    /// min over a of Q(x, a) = xᵀA_xx·x + 2·b_x·x + c − rᵀA_aa⁻¹r, at a∗ = −A_aa⁻¹r. Where A_aa
    /// is singular (a pivot below 1e-12 of its trace: too few faces) the attributes stay at
    /// `keep`'s and the value is the quadric there.
    // Dense linear algebra on fixed-size arrays: index loops read like the formulas.
    #[allow(clippy::needless_range_loop)]
    fn reduced<const N: usize, const M: usize, const S: usize, const WANT_ATTRS: bool>(
        &self,
        wedges: &[u32],
        x: DVec3,
        keep: &Wedge,
        attrs: &mut [f64; MAX_M],
    ) -> f64 {
        let m = M;
        let stride = S;
        debug_assert_eq!((M, S), (N - 3, N * (N + 1) / 2 + N + 1));
        debug_assert_eq!(stride, self.stride);
        let off = N * (N + 1) / 2;
        let q: [f64; S] = self.summed(wedges);
        let at = |i: usize, j: usize| q[tri_index(N, i, j)];
        let xs = [x.x, x.y, x.z];
        // The position-only part: xᵀA_xx·x + 2·b_x·x + c.
        let mut base = q[off + N];
        for i in 0..3 {
            let mut row = 0.0;
            for j in 0..3 {
                row += at(i, j) * xs[j];
            }
            base += xs[i] * (row + 2.0 * q[off + i]);
        }
        // r = A_ax·x + b_a.
        let mut r = [0.0f64; M];
        for k in 0..m {
            r[k] =
                at(3 + k, 0) * xs[0] + at(3 + k, 1) * xs[1] + at(3 + k, 2) * xs[2] + q[off + 3 + k];
        }
        // A_aa = L·D·Lᵀ (unit lower L, no square roots); a pivot below 1e-12 of the trace counts
        // as singular. Then rᵀA_aa⁻¹r = Σ zᵢ²/dᵢ with z = L⁻¹r, and a∗ = −L⁻ᵀD⁻¹z.
        let mut trace = 0.0;
        for k in 0..m {
            trace += at(3 + k, 3 + k);
        }
        let tiny = 1e-12 * trace.max(1e-300);
        let mut l = [[0.0f64; M]; M];
        let mut inv_d = [0.0f64; M];
        let mut ok = true;
        for i in 0..m {
            // Row i of L·D (w = L[i][j]·d[j]) and the pivot d[i].
            let mut w = [0.0f64; M];
            let mut d = at(3 + i, 3 + i);
            for j in 0..i {
                let mut s = at(3 + i, 3 + j);
                for k in 0..j {
                    s -= w[k] * l[j][k];
                }
                w[j] = s;
                l[i][j] = s * inv_d[j];
                d -= s * l[i][j];
            }
            if d <= tiny {
                ok = false;
                break;
            }
            inv_d[i] = 1.0 / d;
        }
        if ok {
            let mut z = [0.0f64; M];
            let mut quad = 0.0;
            for i in 0..m {
                let mut s = r[i];
                for k in 0..i {
                    s -= l[i][k] * z[k];
                }
                z[i] = s;
                quad += s * s * inv_d[i];
            }
            if WANT_ATTRS {
                for i in (0..m).rev() {
                    let mut s = z[i] * inv_d[i];
                    for k in i + 1..m {
                        s -= l[k][i] * attrs[k];
                    }
                    attrs[i] = s;
                }
                for a in attrs.iter_mut().take(m) {
                    *a = -*a;
                }
            }
            return (base - quad).max(0.0);
        }
        // Singular: the quadric at (x, keep's attributes).
        let mut a = [0.0f64; MAX_M];
        self.attrs_into(keep, &mut a);
        let mut val = base;
        for k in 0..m {
            let mut row = 0.0;
            for j in 0..m {
                row += at(3 + k, 3 + j) * a[j];
            }
            val += a[k] * (row + 2.0 * r[k]);
        }
        if WANT_ATTRS {
            attrs[..m].copy_from_slice(&a[..m]);
        }
        val.max(0.0)
    }

    fn wedge_from(&self, attrs: &[f64], keep: &Wedge) -> Wedge {
        let mut w = *keep;
        let n = Vec3::new(
            (attrs[0] / self.normal_s) as f32,
            (attrs[1] / self.normal_s) as f32,
            (attrs[2] / self.normal_s) as f32,
        );
        w.normal = n.try_normalize().unwrap_or(keep.normal);
        let mut k = 3;
        if self.has_uv {
            w.uv = Vec2::new(
                (attrs[k] / self.uv_s) as f32,
                (attrs[k + 1] / self.uv_s) as f32,
            );
            k += 2;
        }
        if self.has_color {
            w.color = Vec3::new(
                (attrs[k] / self.color_s) as f32,
                (attrs[k + 1] / self.color_s) as f32,
                (attrs[k + 2] / self.color_s) as f32,
            )
            .clamp(Vec3::ZERO, Vec3::splat(f32::MAX));
        }
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn optimal_attributes_interpolate_a_linear_field() {
        // On a flat grid whose UVs are a linear function of position, the generalized quadric of
        // the wedges around a vertex is minimised (at value ≈ 0) by exactly that linear UV.
        let mesh = crate::mesh::shapes::icosphere(2);
        let adj = Adjacency::new(&mesh);
        let q = AttributeQuadrics::new(&adj, false, false, 2.0);
        let v = adj.triangle(0)[0];
        let wedges: Vec<u32> = adj
            .vertex_triangles(v)
            .iter()
            .map(|&t| adj.corner_wedge(t, v))
            .collect();
        let keep = adj.wedges[wedges[0] as usize];
        let (w, val) = q.optimal(&wedges, adj.positions[v as usize].as_dvec3(), &keep);
        // At the vertex itself, with its own normal: the quadric is near zero and the optimal
        // normal is close to the vertex normal.
        assert!(val < 1e-3, "{val}");
        assert!(
            w.normal.dot(keep.normal) > 0.95,
            "{} vs {}",
            w.normal,
            keep.normal
        );
    }
}
