//! Vertex transform and triangle setup: clip space → clipped → perspective divide → viewport →
//! fixed-point screen triangles with a consistent orientation.
//!
//! Runs in parallel over fixed chunks of triangles; chunk outputs are concatenated in chunk order,
//! so the list of set-up triangles (and everything downstream) is independent of thread count.
//!
//! Conventions: screen x grows right, y grows down, pixel (x, y) covers [x, x+1) × [y, y+1) and its
//! centre is (x + ½, y + ½). Front faces are counter-clockwise in NDC (OpenGL/glTF convention);
//! in y-down screen space they have negative signed area under [`edge`](super::edge)'s edge function,
//! so set-up swaps two corners of every front face to make all areas positive and records the facing.

use glam::{Mat4, Vec3, Vec4};
use rayon::prelude::*;

use super::clip::{ClipPlanes, ClipVertex};
use super::fixed::{Fx24_8, GUARD_BAND_PX};

/// Triangles per parallel set-up chunk.
const CHUNK: usize = 4096;

/// A triangle ready for rasterization.
///
/// # Guarantees
/// - `area > 0` (twice the signed area in Fx24_8² units, after reordering corners).
/// - `bbox` is within the viewport and non-empty.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SetupTri {
    /// Fixed-point screen positions.
    pub v: [[i32; 2]; 3],
    /// Twice the area, > 0.
    pub area: i64,
    /// NDC depth (0 near .. 1 far) per corner.
    pub z: [f32; 3],
    /// 1/w per corner (perspective-correct interpolation).
    pub inv_w: [f32; 3],
    /// Barycentrics of each corner with respect to the source triangle's vertices.
    pub bary: [Vec3; 3],
    /// Source triangle index.
    pub tri: u32,
    /// Whether the source triangle faces the camera.
    pub front: bool,
    /// Covered pixel rectangle `[x0, y0, x1, y1)`.
    pub bbox: [i32; 4],
}

/// Viewport parameters for set-up.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Viewport {
    pub width: u32,
    pub height: u32,
    pub cull_backfaces: bool,
}

/// Transform every position to clip space.
pub(crate) fn transform(positions: &[Vec3], mvp: Mat4) -> Vec<Vec4> {
    positions
        .par_iter()
        .with_min_len(CHUNK)
        .map(|p| mvp * p.extend(1.0))
        .collect()
}

/// Set up all triangles (in source order; clipped triangles may yield several).
pub(crate) fn setup_all(triangles: &[[u32; 3]], clip: &[Vec4], vp: Viewport) -> Vec<SetupTri> {
    let planes = ClipPlanes::new(
        1.0 + 2.0 * GUARD_BAND_PX / vp.width as f32,
        1.0 + 2.0 * GUARD_BAND_PX / vp.height as f32,
    );
    let chunks: Vec<Vec<SetupTri>> = triangles
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(c, chunk)| {
            let mut out = Vec::with_capacity(chunk.len());
            for (k, t) in chunk.iter().enumerate() {
                setup_one((c * CHUNK + k) as u32, *t, clip, &planes, vp, &mut out);
            }
            out
        })
        .collect();
    chunks.concat()
}

/// Set up one source triangle, pushing zero or more screen triangles.
pub(crate) fn setup_one(
    index: u32,
    t: [u32; 3],
    clip: &[Vec4],
    planes: &ClipPlanes,
    vp: Viewport,
    out: &mut Vec<SetupTri>,
) {
    let corners = [
        ClipVertex {
            pos: clip[t[0] as usize],
            bary: Vec3::X,
        },
        ClipVertex {
            pos: clip[t[1] as usize],
            bary: Vec3::Y,
        },
        ClipVertex {
            pos: clip[t[2] as usize],
            bary: Vec3::Z,
        },
    ];
    let codes = corners.map(|c| planes.outcode(c.pos));
    if codes[0] & codes[1] & codes[2] != 0 {
        return; // entirely outside one plane
    }
    if codes[0] | codes[1] | codes[2] == 0 {
        emit(index, corners, vp, out);
        return;
    }
    let poly = planes.clip_polygon(corners);
    for k in 1..poly.len().saturating_sub(1) {
        emit(index, [poly[0], poly[k], poly[k + 1]], vp, out);
    }
}

/// Project, snap, orient and bound one clipped triangle.
fn emit(index: u32, c: [ClipVertex; 3], vp: Viewport, out: &mut Vec<SetupTri>) {
    let (w, h) = (vp.width as f32, vp.height as f32);
    let mut v = [[0i32; 2]; 3];
    let mut z = [0f32; 3];
    let mut inv_w = [0f32; 3];
    for i in 0..3 {
        let p = c[i].pos;
        if p.w <= 0.0 || !p.is_finite() {
            return;
        }
        let iw = 1.0 / p.w;
        let (nx, ny) = (p.x * iw, p.y * iw);
        v[i] = [
            Fx24_8::from_px((nx * 0.5 + 0.5) * w).0,
            Fx24_8::from_px((0.5 - ny * 0.5) * h).0,
        ];
        z[i] = (p.z * iw).clamp(0.0, 1.0);
        inv_w[i] = iw;
    }
    let mut bary = [c[0].bary, c[1].bary, c[2].bary];
    let e = |a: [i32; 2], b: [i32; 2], p: [i32; 2]| {
        (b[0] as i64 - a[0] as i64) * (p[1] as i64 - a[1] as i64)
            - (b[1] as i64 - a[1] as i64) * (p[0] as i64 - a[0] as i64)
    };
    let mut area = e(v[0], v[1], v[2]);
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
        bary.swap(1, 2);
        area = -area;
    }
    let min_x = v.iter().map(|p| p[0]).min().unwrap_or(0);
    let max_x = v.iter().map(|p| p[0]).max().unwrap_or(0);
    let min_y = v.iter().map(|p| p[1]).min().unwrap_or(0);
    let max_y = v.iter().map(|p| p[1]).max().unwrap_or(0);
    let px = |f: i32| f >> super::fixed::SUBPIXEL_BITS; // floor to pixel
    let bbox = [
        px(min_x).max(0),
        px(min_y).max(0),
        (px(max_x) + 1).min(vp.width as i32),
        (px(max_y) + 1).min(vp.height as i32),
    ];
    if bbox[0] >= bbox[2] || bbox[1] >= bbox[3] {
        return;
    }
    out.push(SetupTri {
        v,
        area,
        z,
        inv_w,
        bary,
        tri: index,
        front,
        bbox,
    });
}
