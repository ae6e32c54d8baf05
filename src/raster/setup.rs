//! Vertex transform and triangle setup: clip space → clipped → perspective divide → viewport →
//! fixed-point screen triangles with a consistent orientation.
//!
//! `bin.rs` calls [`setup_one`] for fixed chunks of triangles in parallel.
//!
//! Conventions: screen x grows right, y grows down, pixel (x, y) covers [x, x+1) × [y, y+1) and its
//! centre is (x + ½, y + ½). Front faces are counter-clockwise in NDC (OpenGL/glTF convention);
//! in y-down screen space they have negative signed area under [`edge`](super::edge)'s edge function,
//! so set-up swaps two corners of every front face to make all areas positive (the corner code
//! records the swap).

use glam::{Mat4, Vec3, Vec4};
use rayon::prelude::*;

use super::clip::{ClipPlanes, ClipVertex};
use super::fixed::Fx24_8;

/// A triangle ready for rasterization.
///
/// The record is 64 bytes, one cache line: set-up writes one per visible triangle and the scan
/// reads them back, so its size is the rasterizer's memory traffic (a 64-byte larger record
/// doubled the set-up time of a 1M-triangle frame). Twice the area is recomputed from the corners
/// rather than stored, and the box is stored in 16 bits ([`RenderSettings::MAX_SIZE`] < 2^16).
///
/// # Guarantees
/// - [`SetupTri::area`] > 0 (corners reordered to positive area).
/// - [`SetupTri::bbox`] is within the viewport and non-empty.
///
/// [`RenderSettings::MAX_SIZE`]: super::RenderSettings::MAX_SIZE
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(64))]
pub(crate) struct SetupTri {
    /// Fixed-point screen positions.
    pub v: [[i32; 2]; 3],
    /// NDC depth (0 near .. 1 far) per corner.
    pub z: [f32; 3],
    /// 1/w per corner (perspective-correct interpolation).
    pub inv_w: [f32; 3],
    /// Barycentrics of the corners with respect to the source triangle's vertices, coded (a
    /// clipped corner set would triple the record): [`CORNERS_SOURCE`], [`CORNERS_SWAPPED`], or
    /// `CORNERS_CLIPPED + k` for entry k of the owner's clipped-corner table
    /// ([`SetupOut::clipped`]).
    pub corners: u32,
    /// Source triangle index.
    pub tri: u32,
    /// Covered pixel rectangle `[x0, y0, x1, y1)`.
    bbox: [u16; 4],
}

const _: () = assert!(std::mem::size_of::<SetupTri>() == 64);
const _: () = assert!(super::RenderSettings::MAX_SIZE <= u16::MAX as u32);

impl SetupTri {
    /// Twice the signed area in Fx24_8² units, > 0.
    #[inline]
    pub fn area(&self) -> i64 {
        doubled_area(self.v)
    }

    /// Covered pixel rectangle `[x0, y0, x1, y1)`.
    #[inline]
    pub fn bbox(&self) -> [i32; 4] {
        self.bbox.map(i32::from)
    }
}

/// Twice the signed area of fixed-point triangle `v` under [`edge`](super::edge)'s edge function
/// (negative for front faces before set-up reorders them).
#[inline]
fn doubled_area(v: [[i32; 2]; 3]) -> i64 {
    let [a, b, c] = v.map(|q| [q[0] as i64, q[1] as i64]);
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// The corners are the source triangle's vertices 0, 1, 2.
pub(crate) const CORNERS_SOURCE: u32 = 0;
/// The corners are the source triangle's vertices 0, 2, 1 (reordered to positive area).
pub(crate) const CORNERS_SWAPPED: u32 = 1;
/// First code of a clipped corner set.
pub(crate) const CORNERS_CLIPPED: u32 = 2;

/// Where a set-up triangle's corners lie on its source triangle, decoded from
/// [`SetupTri::corners`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Corners {
    /// Corners 0, 1, 2 are the source vertices 0, 1, 2.
    Source,
    /// Corners 0, 1, 2 are the source vertices 0, 2, 1.
    Swapped,
    /// Clipped corners, as barycentrics of the source triangle.
    Clipped([Vec3; 3]),
}

impl Corners {
    /// Decode `code` given the owner's clipped-corner table.
    pub fn decode(code: u32, clipped: &[[Vec3; 3]]) -> Corners {
        match code {
            CORNERS_SOURCE => Corners::Source,
            CORNERS_SWAPPED => Corners::Swapped,
            k => Corners::Clipped(clipped[(k - CORNERS_CLIPPED) as usize]),
        }
    }

    /// Source-triangle barycentrics of the point with corner weights `mu`. For the unclipped
    /// codes this is a permutation, not the weighted sum of unit vectors it equals (the same
    /// values; a sum could differ only in the sign of a zero).
    #[inline]
    pub fn apply(&self, mu: [f32; 3]) -> Vec3 {
        match self {
            Corners::Source => Vec3::new(mu[0], mu[1], mu[2]),
            Corners::Swapped => Vec3::new(mu[0], mu[2], mu[1]),
            Corners::Clipped(c) => c[0] * mu[0] + c[1] * mu[1] + c[2] * mu[2],
        }
    }
}

/// Where set-up writes: the triangles and the corner barycentrics of clipped ones.
#[derive(Debug, Clone, Default)]
pub(crate) struct SetupOut {
    pub tris: Vec<SetupTri>,
    pub clipped: Vec<[Vec3; 3]>,
}

/// Viewport parameters for set-up.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Viewport {
    pub width: u32,
    pub height: u32,
    pub cull_backfaces: bool,
    /// The sample positions' extent within a pixel, Fx24_8: [min x, min y, max x, max y].
    pub sample_span: [i32; 4],
}

/// A vertex after transformation: its clip-space position, the clip planes it is outside of and,
/// computed once per vertex rather than once per triangle corner, its snapped projection.
#[derive(Debug, Clone, Copy)]
pub(crate) struct XfVertex {
    clip: Vec4,
    outcode: u8,
    projected: Projected,
}

/// A projected vertex: Fx24_8 screen position, NDC depth and 1/w.
#[derive(Debug, Clone, Copy, Default)]
struct Projected {
    v: [i32; 2],
    z: f32,
    inv_w: f32,
}

/// Perspective divide and viewport mapping; `None` behind the eye or for non-finite input.
fn project(p: Vec4, vp: Viewport) -> Option<Projected> {
    if p.w <= 0.0 || !p.is_finite() {
        return None;
    }
    let iw = 1.0 / p.w;
    let (nx, ny) = (p.x * iw, p.y * iw);
    Some(Projected {
        v: [
            Fx24_8::from_px((nx * 0.5 + 0.5) * vp.width as f32).0,
            Fx24_8::from_px((0.5 - ny * 0.5) * vp.height as f32).0,
        ],
        // `+ 0.0` turns a -0.0 into +0.0: depths are then never negative zero, whose bits would
        // order after every positive depth in `edge::depth_key`.
        z: (p.z * iw).clamp(0.0, 1.0) + 0.0,
        inv_w: iw,
    })
}

/// Transform every position to clip space, classify it against the clip planes and project the
/// ones inside all of them.
pub(crate) fn transform(
    positions: &[Vec3],
    mvp: Mat4,
    planes: &ClipPlanes,
    vp: Viewport,
) -> Vec<XfVertex> {
    positions
        .par_iter()
        .with_min_len(4096)
        .map(|&p| transform_one(p, mvp, planes, vp))
        .collect()
}

/// Transform, classify and (if inside all planes) project one position.
pub(crate) fn transform_one(p: Vec3, mvp: Mat4, planes: &ClipPlanes, vp: Viewport) -> XfVertex {
    let clip = mvp * p.extend(1.0);
    let outcode = planes.outcode(clip);
    let projected = if outcode == 0 {
        project(clip, vp).unwrap_or_default()
    } else {
        Projected::default()
    };
    XfVertex {
        clip,
        outcode,
        projected,
    }
}

/// Set up one source triangle, pushing zero or more screen triangles.
pub(crate) fn setup_one(
    index: u32,
    t: [u32; 3],
    xf: &[XfVertex],
    planes: &ClipPlanes,
    vp: Viewport,
    out: &mut SetupOut,
) {
    let [a, b, c] = t.map(|i| &xf[i as usize]);
    if a.outcode & b.outcode & c.outcode != 0 {
        return; // entirely outside one plane
    }
    const CORNERS: [Vec3; 3] = [Vec3::X, Vec3::Y, Vec3::Z];
    if a.outcode | b.outcode | c.outcode == 0 {
        emit(
            index,
            [a.projected, b.projected, c.projected],
            None,
            vp,
            out,
        );
        return;
    }
    let corners = [a, b, c].map(|v| v.clip);
    let poly = planes.clip_polygon([0, 1, 2].map(|i| ClipVertex {
        pos: corners[i],
        bary: CORNERS[i],
    }));
    let projected: Option<Vec<Projected>> = poly.iter().map(|p| project(p.pos, vp)).collect();
    let Some(projected) = projected else { return };
    for k in 1..poly.len().saturating_sub(1) {
        let bary = [poly[0].bary, poly[k].bary, poly[k + 1].bary];
        emit(
            index,
            [projected[0], projected[k], projected[k + 1]],
            Some(bary),
            vp,
            out,
        );
    }
}

/// The set-up triangle (if any) of fixed-point screen corners `v` at depths `z`, for one sample
/// at each pixel's centre of a `width` × `height` viewport: what set-up makes of an unclipped
/// triangle, for the rasterizers' tests.
#[cfg(test)]
pub(crate) fn screen_triangle(
    v: [[i32; 2]; 3],
    z: [f32; 3],
    width: u32,
    height: u32,
) -> Option<SetupTri> {
    let half = (super::fixed::ONE_PIXEL / 2) as i32;
    let vp = Viewport {
        width,
        height,
        cull_backfaces: false,
        sample_span: [half; 4],
    };
    let mut out = SetupOut::default();
    let p = [0, 1, 2].map(|i| Projected {
        v: v[i],
        z: z[i],
        inv_w: 1.0,
    });
    emit(0, p, None, vp, &mut out);
    out.tris.pop()
}

/// Orient and bound one projected triangle; `bary` are its corners' barycentrics when clipped.
fn emit(
    index: u32,
    p: [Projected; 3],
    mut bary: Option<[Vec3; 3]>,
    vp: Viewport,
    out: &mut SetupOut,
) {
    let mut v = p.map(|q| q.v);
    let mut z = p.map(|q| q.z);
    let mut inv_w = p.map(|q| q.inv_w);
    let area = doubled_area(v);
    if area == 0 {
        return;
    }
    let front = area < 0;
    if !front && vp.cull_backfaces {
        return;
    }
    if area < 0 {
        v.swap(1, 2);
        z.swap(1, 2);
        inv_w.swap(1, 2);
        if let Some(b) = bary.as_mut() {
            b.swap(1, 2);
        }
    }
    let min_x = v.iter().map(|p| p[0]).min().unwrap_or(0);
    let max_x = v.iter().map(|p| p[0]).max().unwrap_or(0);
    let min_y = v.iter().map(|p| p[1]).min().unwrap_or(0);
    let max_y = v.iter().map(|p| p[1]).max().unwrap_or(0);
    // The pixels that have a sample inside the vertices' bounding box: pixel x has samples at
    // x·256 + o for o in [span min, span max], so it can only be covered if
    // x·256 + max ≥ min_x and x·256 + min ≤ max_x. A triangle between sample positions (common
    // for sub-pixel triangles at one sample per pixel) gets an empty box and is dropped here,
    // before binning; coverage is exactly the same.
    let one = super::fixed::ONE_PIXEL as i32;
    let [sx0, sy0, sx1, sy1] = vp.sample_span;
    let ceil_div = |a: i32| -((-a).div_euclid(one));
    let bbox = [
        ceil_div(min_x - sx1).max(0),
        ceil_div(min_y - sy1).max(0),
        ((max_x - sx0).div_euclid(one) + 1).min(vp.width as i32),
        ((max_y - sy0).div_euclid(one) + 1).min(vp.height as i32),
    ];
    if bbox[0] >= bbox[2] || bbox[1] >= bbox[3] {
        return;
    }
    let corners = match bary {
        None if front => CORNERS_SWAPPED,
        None => CORNERS_SOURCE,
        Some(b) => {
            out.clipped.push(b);
            CORNERS_CLIPPED + out.clipped.len() as u32 - 1
        }
    };
    out.tris.push(SetupTri {
        v,
        z,
        inv_w,
        corners,
        tri: index,
        // In range: 0 ≤ box ≤ the viewport size ≤ MAX_SIZE < 2^16.
        bbox: bbox.map(|b| b as u16),
    });
}
