//! Scan conversion of one set-up triangle into a tile's sample buffers with integer edge
//! functions and the top-left fill rule.
//!
//! Based on: Juan Pineda. A Parallel Algorithm for Polygon Rasterization. SIGGRAPH 1988 (edge
//! functions, incremental stepping); the Direct3D 10 / OpenGL top-left rule for samples exactly on
//! an edge; Nicolas Capens, Advanced Rasterization, 2004 (fixed-point setup, bias instead of branches).
//!
//! For corner order v0, v1, v2 with positive area, edge i runs from v(i+1) to v(i+2) and
//! E_i(p) = (b.x−a.x)(p.y−a.y) − (b.y−a.y)(p.x−a.x) is positive inside. A sample exactly on an edge
//! (E_i = 0) belongs to the triangle only if the edge is a *top* edge (horizontal, interior below in
//! y-down screen space: d.y = 0, d.x > 0) or a *left* edge (d.y < 0); subtracting 1 from the other
//! edges' values turns the test into one `>= 0` per edge. Two triangles sharing an edge see it with
//! opposite directions, so exactly one of them owns each on-edge sample: no gaps, no double hits.
//! E_i / area is also the barycentric weight of corner i, which gives the depth.
//!
//! At four samples per pixel a small triangle (corners within 16 pixels along each axis: every
//! triangle of a dense mesh) takes a vector scan (`avx2`): its edge values fit in 32 bits, so two
//! pixels' eight samples are tested in one compare and their depths computed in 64-bit float lanes
//! with the scalar scan's operations in the scalar scan's order, which keeps every depth bit and id
//! the same (tested against the scalar scan).

use super::setup::SetupTri;

/// The sample buffers of one tile: `samples` entries per pixel, row-major within `rect`.
#[derive(Debug)]
pub(crate) struct TileSamples {
    /// Tile pixel rectangle `[x0, y0, x1, y1)`.
    pub rect: [i32; 4],
    /// Samples per pixel.
    pub samples: usize,
    /// Nearest depth per sample (NDC 0..1), `f32::INFINITY` where empty.
    pub depth: Vec<f32>,
    /// Set-up triangle index per sample, [`EMPTY`] where empty.
    pub ids: Vec<u32>,
    /// Coverage counts per sample (diagnostic mode only: every covering triangle counts, no depth test).
    pub counts: Option<Vec<u16>>,
}

/// Marker for an uncovered sample.
pub(crate) const EMPTY: u32 = u32::MAX;

/// Spare entries after a tile's last sample: the vector scan reads and writes two pixels' samples
/// at once, and on a row's last pixel the second pair of four lies past it (it writes back what it
/// read there; plain loads and stores are much faster than masked ones).
const PAD: usize = 4;

impl TileSamples {
    pub fn new(rect: [i32; 4], samples: usize, count_coverage: bool) -> TileSamples {
        let n = ((rect[2] - rect[0]) * (rect[3] - rect[1])) as usize * samples;
        TileSamples {
            rect,
            samples,
            // `PAD` spare entries after the last sample, never covered.
            depth: vec![f32::INFINITY; n + PAD],
            ids: vec![EMPTY; n + PAD],
            counts: count_coverage.then(|| vec![0; n]),
        }
    }
}

/// Which scans [`rasterize`] may use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Scans {
    /// The vector scan for small triangles where the build has one (what renders use).
    Fastest,
    /// The 64-bit scalar scans only (the tests' reference: the same coverage and depths).
    #[cfg_attr(not(test), allow(dead_code))]
    Scalar,
}

/// Rasterize set-up triangle `st` (index `id`) into `buf`, restricted to `clip` (a sub-rectangle
/// of the tile, `[x0, y0, x1, y1)`). `offsets` are the sample positions within a pixel in Fx24_8.
/// `scratch` must hold at least `offsets.len()` entries.
pub(crate) fn rasterize(
    st: &SetupTri,
    id: u32,
    offsets: &[[i64; 2]],
    clip: [i32; 4],
    buf: &mut TileSamples,
    scratch: &mut [[i64; 3]],
    scans: Scans,
) {
    let bbox = st.bbox();
    let x0 = bbox[0].max(clip[0]);
    let y0 = bbox[1].max(clip[1]);
    let x1 = bbox[2].min(clip[2]);
    let y1 = bbox[3].min(clip[3]);
    if x0 >= x1 || y0 >= y1 {
        return;
    }
    let rect = [x0, y0, x1, y1];
    let s = offsets.len();
    let edges = edges_at(st, x0, y0);
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    if scans == Scans::Fastest && s == 4 && buf.counts.is_none() && small(st) {
        // SAFETY: this build targets AVX2 (cfg); the triangle is small (`small`, which bounds
        // every edge value the lanes reach, so the narrowed edges are exact), `rect` lies within
        // the triangle's box and the tile's rectangle, `buf.rect`, and there are 4 offsets.
        unsafe { avx2::scan_four(st, id, rect, &avx2::Edges32::narrow(&edges), offsets, buf) };
        return;
    }
    // Builds without AVX2 have only the scalar scans.
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
    let _ = scans;
    if s == 1 && buf.counts.is_none() {
        // One sample per pixel (a dense mesh's triangles cover a pixel or two): the sample offset
        // and bias go straight into the start values, with no per-sample table.
        let edges = edges.at_sample(offsets[0]);
        scan_one_sample(st, rect, buf.rect, &edges, |pixel, depth| {
            depth_test(buf, pixel, id, depth)
        });
        return;
    }
    let Edges { origin, coef, bias } = edges;
    // Per-sample offsets of each edge value from the pixel corner, bias folded in, written into the
    // caller's scratch (a zero-initialised array per triangle cost more than the rasterization).
    let sample_off = &mut scratch[..s];
    for (so, &o) in sample_off.iter_mut().zip(offsets) {
        *so = sample_offset(&coef, &bias, o);
    }
    // Four samples get a loop the compiler can unroll.
    let edges = Edges { origin, coef, bias };
    // Coverage counting (a diagnostic) gets its own instance, so the render path has no
    // per-sample branch for it.
    match (s, buf.counts.is_some()) {
        (4, false) => scan::<4, false>(st, id, rect, &edges, sample_off, buf),
        (_, false) => scan::<0, false>(st, id, rect, &edges, sample_off, buf),
        (_, true) => scan::<0, true>(st, id, rect, &edges, sample_off, buf),
    }
}

/// Call `f(x, y, depth)` for every pixel of `clip` whose centre `st` covers: one sample at the
/// pixel centre, with the same coverage and depth as [`rasterize`] with that one offset (for a
/// caller that keeps its own per-pixel state, such as the luminance images' two layers).
// Never inlined (each caller's closure is inlined into its own copy): inlined into the optimizer's
// trial render, its loop shared registers with the render's and ran 0.4-1.5 % slower (in-process
// A/B alternating every 64 trials, 2 threads, the variant in each mode in turn against an A/A of
// the same partition); whether it was inlined had changed from build to build with unrelated
// code.
#[inline(never)]
pub(crate) fn rasterize_each(st: &SetupTri, clip: [i32; 4], mut f: impl FnMut(i32, i32, f32)) {
    let bbox = st.bbox();
    let (x0, y0) = (bbox[0].max(clip[0]), bbox[1].max(clip[1]));
    let (x1, y1) = (bbox[2].min(clip[2]), bbox[3].min(clip[3]));
    if x0 >= x1 || y0 >= y1 {
        return;
    }
    let Edges {
        mut origin,
        coef,
        bias,
    } = edges_at(st, x0, y0);
    let half = super::fixed::ONE_PIXEL / 2;
    let off = sample_offset(&coef, &bias, [half, half]);
    for i in 0..3 {
        origin[i] += off[i];
    }
    let one = super::fixed::ONE_PIXEL;
    let step_x = coef.map(|c| c[0] * one);
    let step_y = coef.map(|c| c[1] * one);
    // 1/area before the scan (the same value as the one-sample scan's, which works it out on the
    // first covered sample): the callers' triangles cover pixels, and the check per pixel cost
    // more than the division.
    let inv_area = 1.0 / st.area() as f64;
    let mut row = origin;
    for y in y0..y1 {
        let mut e = row;
        // A triangle covers one run of each row (it is convex): the row ends where the run does.
        let mut inside = false;
        for x in x0..x1 {
            if (e[0] | e[1] | e[2]) >= 0 {
                inside = true;
                let w = [0, 1, 2].map(|i| (e[i] - bias[i]) as f64);
                f(x, y, interpolated_depth(st, w, inv_area));
            } else if inside {
                break;
            }
            for i in 0..3 {
                e[i] += step_x[i];
            }
        }
        for i in 0..3 {
            row[i] += step_y[i];
        }
    }
}

/// The edge functions of `st` at the corner of pixel (x0, y0), their x and y coefficients and the
/// top-left bias.
fn edges_at(st: &SetupTri, x0: i32, y0: i32) -> Edges {
    let one = super::fixed::ONE_PIXEL;
    let p = st.v.map(|q| [q[0] as i64, q[1] as i64]);
    // Edge i: from p[i+1] to p[i+2]; E = a_x·(x − ax) + b_y·(y − ay) with a_x = −d.y, b_y = d.x.
    let mut coef = [[0i64; 2]; 3];
    let mut origin = [0i64; 3];
    let mut bias = [0i64; 3];
    for i in 0..3 {
        let a = p[(i + 1) % 3];
        let b = p[(i + 2) % 3];
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        coef[i] = [-dy, dx];
        // Value at the corner of pixel (x0, y0).
        origin[i] = -dy * (x0 as i64 * one - a[0]) + dx * (y0 as i64 * one - a[1]);
        let top_left = (dy == 0 && dx > 0) || dy < 0;
        bias[i] = if top_left { 0 } else { -1 };
    }
    Edges { origin, coef, bias }
}

/// How much each edge value at sample offset `o` (Fx24_8, within the pixel) exceeds the value at
/// the pixel corner, with the top-left bias folded in.
#[inline(always)]
fn sample_offset(coef: &[[i64; 2]; 3], bias: &[i64; 3], o: [i64; 2]) -> [i64; 3] {
    // An index loop, not `[0, 1, 2].map`: that was left as an out-of-line call here (4 % of a
    // frame).
    let mut off = [0i64; 3];
    for i in 0..3 {
        off[i] = coef[i][0] * o[0] + coef[i][1] * o[1] + bias[i];
    }
    off
}

/// A triangle's three edge functions: value at the clip rectangle's first pixel corner (for the
/// one-sample scan: at that pixel's sample, biased), the coefficients of x and y, and the
/// top-left bias.
struct Edges {
    origin: [i64; 3],
    coef: [[i64; 2]; 3],
    bias: [i64; 3],
}

impl Edges {
    /// These edge functions with the sample at `o` (Fx24_8, within the pixel) and the top-left
    /// bias folded into the origin: the one-sample scans' start values.
    #[inline(always)]
    fn at_sample(mut self, o: [i64; 2]) -> Edges {
        let off = sample_offset(&self.coef, &self.bias, o);
        for (e, d) in self.origin.iter_mut().zip(off) {
            *e += d;
        }
        self
    }
}

/// Largest extent of a [`small`] triangle's corners along x and along y, Fx24_8 (16 pixels).
const SMALL_EXTENT: i32 = 16 << super::fixed::SUBPIXEL_BITS;

/// Whether `st` is small enough for the 32-bit vector scan: its corners span at most
/// [`SMALL_EXTENT`] along each axis. Its pixel box is then within a pixel of the corners' box, so
/// an edge value anywhere in the box or up to two pixels past it (where the two-pixel steps end)
/// is a sum of two products of factors of at most 2^12 and 2^13 — below 2^26 — plus a sample
/// offset below 2^21: far inside `i32`.
#[cfg_attr(
    not(all(target_arch = "x86_64", target_feature = "avx2")),
    allow(dead_code)
)]
fn small(st: &SetupTri) -> bool {
    let [a, b, c] = st.v;
    let extent = |k: usize| a[k].max(b[k]).max(c[k]) - a[k].min(b[k]).min(c[k]);
    extent(0) <= SMALL_EXTENT && extent(1) <= SMALL_EXTENT
}

/// The pixel loop of [`rasterize`] at one sample per pixel, without coverage counting: `edges`
/// origin holds the biased edge values at the first pixel's sample. Calls `test(pixel, depth)`
/// for every covered pixel of `rect` (`pixel` indexes the rectangle `frame` row-major) with the
/// same tests and depths as [`scan`] with `S = 1`.
#[inline(always)]
fn scan_one_sample(
    st: &SetupTri,
    rect: [i32; 4],
    frame: [i32; 4],
    edges: &Edges,
    mut test: impl FnMut(usize, f32),
) {
    let bias = edges.bias;
    // 1/area on the first covered sample: a third of a dense mesh's triangles cover none.
    let mut inv_area = 0.0f64;
    for_each_pixel(rect, frame, edges, |pixel, e| {
        if (e[0] | e[1] | e[2]) >= 0 {
            if inv_area == 0.0 {
                inv_area = 1.0 / st.area() as f64;
            }
            let w = [0, 1, 2].map(|i| (e[i] - bias[i]) as f64);
            test(pixel, interpolated_depth(st, w, inv_area));
        }
    });
}

/// Sort-last scan (`sort_last.rs`): rasterize set-up triangle `st` (index `id`) at one sample
/// per pixel, offset `offset` (Fx24_8), into the `width`-pixel-wide frame of depth-and-id keys
/// `keys` (row-major), keeping the smaller [`depth_key`] per pixel. For every pixel the result
/// is the nearest depth, ties to the smaller id: what [`rasterize`] gives when triangles arrive
/// in id order, whatever order they arrive in here.
pub(crate) fn rasterize_keys(
    st: &SetupTri,
    id: u32,
    offset: [i64; 2],
    [width, height]: [i32; 2],
    keys: &mut [u64],
) {
    let bbox = st.bbox();
    let x1 = bbox[2].min(width);
    let y1 = bbox[3].min(height);
    if bbox[0] >= x1 || bbox[1] >= y1 {
        return;
    }
    let rect = [bbox[0], bbox[1], x1, y1];
    let edges = edges_at(st, rect[0], rect[1]).at_sample(offset);
    scan_one_sample(st, rect, [0, 0, width, height], &edges, |pixel, depth| {
        let key = depth_key(depth, id);
        if key < keys[pixel] {
            keys[pixel] = key;
        }
    });
}

/// A sample's depth and triangle id as one number whose order is (depth, id): depths are
/// non-negative (NDC 0..1, weights ≥ 0), and a non-negative `f32`'s bits order as its value.
/// No key is `u64::MAX`, which marks an empty sample.
#[inline(always)]
pub(crate) fn depth_key(depth: f32, id: u32) -> u64 {
    ((depth.to_bits() as u64) << 32) | id as u64
}

/// Call `f(pixel, e)` for the pixels of `rect` in row-major order, with the pixel's index in the
/// tile `tile` and the edge functions at it (stepped from `edges.origin`, the values at `rect`'s
/// first pixel).
#[inline(always)]
fn for_each_pixel(
    [x0, y0, x1, y1]: [i32; 4],
    tile: [i32; 4],
    edges: &Edges,
    mut f: impl FnMut(usize, [i64; 3]),
) {
    let one = super::fixed::ONE_PIXEL;
    let step_x = edges.coef.map(|c| c[0] * one);
    let step_y = edges.coef.map(|c| c[1] * one);
    let tile_w = (tile[2] - tile[0]) as usize;
    let mut row = edges.origin;
    for y in y0..y1 {
        let mut e = row;
        let base_y = (y - tile[1]) as usize * tile_w;
        for x in x0..x1 {
            f(base_y + (x - tile[0]) as usize, e);
            for i in 0..3 {
                e[i] += step_x[i];
            }
        }
        for i in 0..3 {
            row[i] += step_y[i];
        }
    }
}

/// NDC depth at a sample with unbiased edge values `w` (twice the sub-areas, so `w / area` are
/// the barycentric weights).
#[inline(always)]
fn interpolated_depth(st: &SetupTri, w: [f64; 3], inv_area: f64) -> f32 {
    let z = st.z.map(|v| v as f64);
    ((w[0] * z[0] + w[1] * z[1] + w[2] * z[2]) * inv_area) as f32
}

/// Keep `depth` and `id` at sample `slot` if nearer (ties go to the triangle drawn first).
#[inline(always)]
fn depth_test(buf: &mut TileSamples, slot: usize, id: u32, depth: f32) {
    let d = buf.depth[slot];
    if depth < d {
        buf.depth[slot] = depth;
        buf.ids[slot] = id;
    }
}

/// The pixel loop of [`rasterize`]; `S` is the sample count, or 0 for "read it from the slice";
/// `COUNT` says whether `buf.counts` is there to count coverage.
#[inline(always)]
fn scan<const S: usize, const COUNT: bool>(
    st: &SetupTri,
    id: u32,
    rect: [i32; 4],
    edges: &Edges,
    sample_off: &[[i64; 3]],
    buf: &mut TileSamples,
) {
    let bias = edges.bias;
    let s = if S == 0 { sample_off.len() } else { S };
    let sample_off = &sample_off[..s];
    let inv_area = 1.0 / st.area() as f64;
    for_each_pixel(rect, buf.rect, edges, |pixel, e| {
        let base = pixel * s;
        for (k, so) in sample_off.iter().enumerate() {
            let (e0, e1, e2) = (e[0] + so[0], e[1] + so[1], e[2] + so[2]);
            if (e0 | e1 | e2) < 0 {
                continue;
            }
            let slot = base + k;
            if COUNT && let Some(c) = buf.counts.as_mut() {
                c[slot] = c[slot].saturating_add(1);
            }
            // Unbiased values give the barycentric weights.
            let w = [e0 - bias[0], e1 - bias[1], e2 - bias[2]].map(|v| v as f64);
            depth_test(buf, slot, id, interpolated_depth(st, w, inv_area));
        }
    });
}

/// The vector scan of [`small`] triangles at four samples per pixel: two pixels' samples (eight
/// 32-bit lanes) per step, coverage in one compare, depths in 64-bit float lanes with the scalar
/// scan's operations in its order (so the same bits), and a branch-free depth test by blending.
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
mod avx2 {
    use super::{Edges, SetupTri, TileSamples};
    use std::arch::x86_64::*;

    /// A small triangle's edge functions ([`Edges`]) in 32 bits: value at the first pixel's
    /// corner (unbiased), x and y coefficients, top-left bias.
    pub(super) struct Edges32 {
        origin: [i32; 3],
        coef: [[i32; 2]; 3],
        bias: [i32; 3],
    }

    impl Edges32 {
        /// `edges` narrowed to `i32`: exact for a [`super::small`] triangle, whose edge values
        /// and coefficients it bounds far inside that range.
        pub(super) fn narrow(edges: &Edges) -> Edges32 {
            Edges32 {
                origin: edges.origin.map(|v| v as i32),
                coef: edges.coef.map(|c| c.map(|v| v as i32)),
                bias: edges.bias.map(|v| v as i32),
            }
        }
    }

    /// Per-triangle constants of the depth lanes: the corner depths and 1/area.
    struct Depth {
        z: [__m256d; 3],
        inv_area: __m256d,
    }

    impl Depth {
        #[target_feature(enable = "avx2")]
        fn of(st: &SetupTri) -> Depth {
            Depth {
                z: [
                    _mm256_set1_pd(st.z[0] as f64),
                    _mm256_set1_pd(st.z[1] as f64),
                    _mm256_set1_pd(st.z[2] as f64),
                ],
                inv_area: _mm256_set1_pd(1.0 / st.area() as f64),
            }
        }

        /// NDC depth of four lanes with unbiased edge values `w` (as `interpolated_depth`).
        #[inline]
        #[target_feature(enable = "avx2")]
        fn four(&self, w: [__m128i; 3]) -> __m128 {
            let [w0, w1, w2] = [
                _mm256_cvtepi32_pd(w[0]),
                _mm256_cvtepi32_pd(w[1]),
                _mm256_cvtepi32_pd(w[2]),
            ];
            let sum = _mm256_add_pd(
                _mm256_add_pd(_mm256_mul_pd(w0, self.z[0]), _mm256_mul_pd(w1, self.z[1])),
                _mm256_mul_pd(w2, self.z[2]),
            );
            _mm256_cvtpd_ps(_mm256_mul_pd(sum, self.inv_area))
        }

        /// NDC depth of eight lanes.
        #[inline]
        #[target_feature(enable = "avx2")]
        fn eight(&self, w: [__m256i; 3]) -> __m256 {
            let low = self.four([
                _mm256_castsi256_si128(w[0]),
                _mm256_castsi256_si128(w[1]),
                _mm256_castsi256_si128(w[2]),
            ]);
            let high = self.four([
                _mm256_extracti128_si256::<1>(w[0]),
                _mm256_extracti128_si256::<1>(w[1]),
                _mm256_extracti128_si256::<1>(w[2]),
            ]);
            _mm256_set_m128(high, low)
        }
    }

    /// Lane-wise `a + b` of three edges. (Helpers like this are written out: closures in a
    /// `target_feature` function are compiled without its features and were called out of line.)
    #[inline]
    #[target_feature(enable = "avx2")]
    fn add(a: [__m256i; 3], b: [__m256i; 3]) -> [__m256i; 3] {
        [
            _mm256_add_epi32(a[0], b[0]),
            _mm256_add_epi32(a[1], b[1]),
            _mm256_add_epi32(a[2], b[2]),
        ]
    }

    /// Each of three values in all lanes.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn splat(v: [i32; 3]) -> [__m256i; 3] {
        [
            _mm256_set1_epi32(v[0]),
            _mm256_set1_epi32(v[1]),
            _mm256_set1_epi32(v[2]),
        ]
    }

    /// `v`, hidden from the optimizer: a blend of a loaded value stored back to where it was
    /// loaded from would otherwise become a masked store (`vmaskmovps`), which is several times
    /// slower on AMD cores than a load, a blend and a store.
    #[inline(always)]
    fn opaque(mut v: __m256) -> __m256 {
        // SAFETY: an empty instruction sequence that only claims to change the register.
        unsafe { std::arch::asm!("/* {0} */", inout(ymm_reg) v, options(pure, nomem, nostack)) };
        v
    }

    /// Four samples per pixel at `offsets`, two pixels of a row (eight samples, contiguous in
    /// the buffer) per step; a depth only where one of them is covered.
    ///
    /// # Safety
    /// The CPU must have AVX2; `super::small(st)` holds and `edges` are its edges at `rect`'s
    /// first pixel corner; `rect` is non-empty, within the triangle's box and within
    /// `buf.rect`; `offsets` has 4 entries, as `buf.samples`.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn scan_four(
        st: &SetupTri,
        id: u32,
        [x0, y0, x1, y1]: [i32; 4],
        edges: &Edges32,
        offsets: &[[i64; 2]],
        buf: &mut TileSamples,
    ) {
        let one = crate::raster::fixed::ONE_PIXEL as i32;
        let o = |k: usize, c: usize| offsets[k][c] as i32;
        // Sample k of lanes 0–3 (the first pixel) and 4–7 (the one to its right).
        let ox = _mm256_setr_epi32(
            o(0, 0),
            o(1, 0),
            o(2, 0),
            o(3, 0),
            o(0, 0) + one,
            o(1, 0) + one,
            o(2, 0) + one,
            o(3, 0) + one,
        );
        let oy = _mm256_setr_epi32(
            o(0, 1),
            o(1, 1),
            o(2, 1),
            o(3, 1),
            o(0, 1),
            o(1, 1),
            o(2, 1),
            o(3, 1),
        );
        // Each lane's offset of each edge value from the first pixel's corner: unbiased (for the
        // depth's weights) and with the top-left bias folded in (for the coverage test).
        let mut weight_off = [_mm256_setzero_si256(); 3];
        for (i, w) in weight_off.iter_mut().enumerate() {
            let [cx, cy] = edges.coef[i];
            *w = _mm256_add_epi32(
                _mm256_mullo_epi32(_mm256_set1_epi32(cx), ox),
                _mm256_mullo_epi32(_mm256_set1_epi32(cy), oy),
            );
        }
        let so = add(weight_off, splat(edges.bias));
        let step_x = [0, 1, 2].map(|i| edges.coef[i][0] * one);
        let step_y = [0, 1, 2].map(|i| edges.coef[i][1] * one);
        let tile = buf.rect;
        let tile_w = (tile[2] - tile[0]) as usize;
        let ids = _mm256_castsi256_ps(_mm256_set1_epi32(id as i32));
        // Lanes of the second pixel, to mask when the row ends after the first.
        let second = _mm256_setr_epi32(0, 0, 0, 0, -1, -1, -1, -1);
        let depth = Depth::of(st);
        let mut row = edges.origin;
        for y in y0..y1 {
            let base_y = (y - tile[1]) as usize * tile_w;
            let mut e = row;
            let mut x = x0;
            while x < x1 {
                let at = splat(e);
                let v = add(at, so);
                let any = _mm256_or_si256(_mm256_or_si256(v[0], v[1]), v[2]);
                let mut covered = _mm256_cmpgt_epi32(any, _mm256_set1_epi32(-1));
                if x + 1 == x1 {
                    covered = _mm256_andnot_si256(second, covered);
                }
                if _mm256_movemask_ps(_mm256_castsi256_ps(covered)) != 0 {
                    let z = depth.eight(add(at, weight_off));
                    let slot = (base_y + (x - tile[0]) as usize) * 4;
                    assert!(slot + 8 <= buf.depth.len() && slot + 8 <= buf.ids.len());
                    // SAFETY: eight entries from the first sample of a pixel of `rect`, in
                    // bounds (asserted: a tile's buffers have `PAD` spare entries). Lanes past
                    // the row's end are not covered and get back the values read from them.
                    unsafe {
                        let dp = buf.depth.as_mut_ptr().add(slot);
                        let ip = buf.ids.as_mut_ptr().add(slot).cast::<f32>();
                        let old = opaque(_mm256_loadu_ps(dp));
                        let keep = _mm256_and_ps(
                            _mm256_cmp_ps::<_CMP_LT_OQ>(z, old),
                            _mm256_castsi256_ps(covered),
                        );
                        _mm256_storeu_ps(dp, _mm256_blendv_ps(old, z, keep));
                        let old_ids = opaque(_mm256_loadu_ps(ip));
                        _mm256_storeu_ps(ip, _mm256_blendv_ps(old_ids, ids, keep));
                    }
                }
                for i in 0..3 {
                    e[i] += 2 * step_x[i];
                }
                x += 2;
            }
            for i in 0..3 {
                row[i] += step_y[i];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::setup::screen_triangle;

    /// Every pixel `rasterize_each` should report, with its depth: each pixel of the clipped box
    /// tested on its own, with edge values computed afresh rather than stepped.
    fn pixel_by_pixel(st: &SetupTri, clip: [i32; 4]) -> Vec<(i32, i32, u32)> {
        let bbox = st.bbox();
        let (x0, y0) = (bbox[0].max(clip[0]), bbox[1].max(clip[1]));
        let (x1, y1) = (bbox[2].min(clip[2]), bbox[3].min(clip[3]));
        let mut out = Vec::new();
        let inv_area = 1.0 / st.area() as f64;
        for y in y0..y1 {
            for x in x0..x1 {
                let Edges { origin, coef, bias } = edges_at(st, x, y);
                let half = crate::raster::fixed::ONE_PIXEL / 2;
                let off = sample_offset(&coef, &bias, [half, half]);
                let e = [0, 1, 2].map(|i| origin[i] + off[i]);
                if e.iter().all(|&v| v >= 0) {
                    let w = [0, 1, 2].map(|i| (e[i] - bias[i]) as f64);
                    out.push((x, y, interpolated_depth(st, w, inv_area).to_bits()));
                }
            }
        }
        out
    }

    #[test]
    fn the_vector_scan_gives_the_scalar_scans_coverage_and_depths() {
        // Random overlapping triangles, from sub-pixel slivers to 40 pixels across (so both
        // scans run), a third of the corners on the sample grid and half the triangles flat at
        // one of three depths (ties keep the earlier triangle), drawn into one tile at 4 samples per pixel with the vector
        // scan of small triangles on and off: every sample's depth (to the bit) and id agree.
        let rect = [64, 128, 128, 192];
        let offsets = crate::raster::SamplePattern::Rotated(2).offsets();
        let mut next = crate::raster::xorshift(0x0dd_5eed);
        let one = crate::raster::fixed::ONE_PIXEL as i32;
        let (mut on, mut off) = (
            TileSamples::new(rect, 4, false),
            TileSamples::new(rect, 4, false),
        );
        let mut scratch = [[0i64; 3]; 4];
        let (mut small_ones, mut covered) = (0, 0);
        for id in 0..3000u32 {
            let size = [2, 40, 400, 4000, 10_000][id as usize % 5];
            let centre = [0; 2].map(|k| {
                (rect[k] * one + (next() % (66 * one as u64)) as i32 - one).clamp(0, 1024 * one)
            });
            let v = [0; 3].map(|_| {
                [0, 1].map(|k| {
                    let c = centre[k] + (next() % (2 * size + 1)) as i32 - size as i32;
                    // A third of the corners on a sample position's grid.
                    if next().is_multiple_of(3) {
                        c - c.rem_euclid(64)
                    } else {
                        c
                    }
                })
            });
            let z = if id % 2 == 0 {
                [[0.25; 3], [0.5; 3], [0.75; 3]][next() as usize % 3]
            } else {
                [0; 3].map(|_| (next() % 1000) as f32 / 1000.0)
            };
            let Some(st) = screen_triangle(v, z, 1024, 1024) else {
                continue;
            };
            small_ones += small(&st) as u32;
            rasterize(
                &st,
                id,
                &offsets,
                rect,
                &mut on,
                &mut scratch,
                Scans::Fastest,
            );
            rasterize(
                &st,
                id,
                &offsets,
                rect,
                &mut off,
                &mut scratch,
                Scans::Scalar,
            );
        }
        for (k, (a, b)) in on.depth.iter().zip(&off.depth).enumerate() {
            assert_eq!(
                (a.to_bits(), on.ids[k]),
                (b.to_bits(), off.ids[k]),
                "sample {k}"
            );
            covered += (on.ids[k] != EMPTY) as usize;
        }
        assert!(small_ones > 500, "{small_ones} small triangles");
        assert!(covered > on.ids.len() / 2, "{covered} samples covered");
    }

    #[test]
    fn rasterize_each_covers_exactly_the_pixels_tested_one_by_one() {
        // Random triangles from sub-pixel slivers to larger than the viewport, with corners on
        // pixel centres and edges (the top-left rule decides those), clipped by random
        // rectangles: the stepped scan must give the same pixels, in the same order, with the
        // same depths to the bit. The tile rasterizer's one-sample scan (the full renderer's)
        // must agree on coverage and depth: the optimizer's trials and its full frames see the
        // same pixels.
        let (w, h) = (64u32, 48u32);
        let mut next = crate::raster::xorshift(0x5eed_1234);
        let one = crate::raster::fixed::ONE_PIXEL as i32;
        let mut covered = 0;
        for case in 0..4000 {
            let scale = [4, 64, 1024, 24 * 256][case % 4];
            let mut coord = |size: u32| {
                let r = next();
                let c = (r % (scale as u64 * 3)) as i32 - scale;
                // A quarter of the corners land on a pixel centre or a pixel edge exactly.
                let base = (size as i32 * one) / 2 + c;
                match (r >> 40) % 8 {
                    0 => base - base.rem_euclid(one) + one / 2,
                    1 => base - base.rem_euclid(one),
                    _ => base,
                }
            };
            let v = [0; 3].map(|_| [coord(w), coord(h)]);
            let z = [0; 3].map(|_| (next() % 1000) as f32 / 1000.0);
            let Some(st) = screen_triangle(v, z, w, h) else {
                continue;
            };
            let clip = if case % 3 == 0 {
                [0, 0, w as i32, h as i32]
            } else {
                let a = [0; 4].map(|_| (next() % 70) as i32 - 3);
                [
                    a[0].min(a[2]),
                    a[1].min(a[3]),
                    a[0].max(a[2]),
                    a[1].max(a[3]),
                ]
            };
            let mut got = Vec::new();
            rasterize_each(&st, clip, |x, y, d| got.push((x, y, d.to_bits())));
            let want = pixel_by_pixel(&st, clip);
            assert_eq!(got, want, "triangle {v:?} clip {clip:?}");
            covered += got.len();
            if clip == [0, 0, w as i32, h as i32] {
                let mut buf = TileSamples::new(clip, 1, false);
                let half = crate::raster::fixed::ONE_PIXEL / 2;
                rasterize(
                    &st,
                    7,
                    &[[half, half]],
                    clip,
                    &mut buf,
                    &mut [[0; 3]; 1],
                    Scans::Fastest,
                );
                let tile: Vec<(i32, i32, u32)> = (0..(w * h) as usize)
                    .filter(|&i| buf.ids[i] == 7)
                    .map(|i| {
                        (
                            (i % w as usize) as i32,
                            (i / w as usize) as i32,
                            buf.depth[i].to_bits(),
                        )
                    })
                    .collect();
                assert_eq!(got, tile, "triangle {v:?}");
            }
        }
        assert!(covered > 100_000, "{covered}");
    }
}
