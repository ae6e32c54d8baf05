//! The oracle (Lindstrom & Turk §5.4): edge potentials from blurred difference images.
//!
//! For each view, the absolute luminance difference |ŷ − y| is blurred (a separable box filter
//! of radius [`BLUR_RADIUS`] applied twice, close to a Gaussian of σ ≈ 2.8 px), and an edge's
//! potential is the sum, over views, of the blurred difference at the projections of its two
//! endpoints (the paper projects the vertices "onto the screen and \[sums\] up the pixel
//! differences from blurred versions of the difference images"). Occlusion is ignored, as in the
//! paper: the oracle only ranks candidates.

use glam::Vec3;
use rayon::prelude::*;

use crate::raster::incremental::LumaViews;

/// Box-blur radius in pixels.
pub const BLUR_RADIUS: usize = 3;

/// One pass of a box blur of radius `r` along rows (`stride` 1) or columns.
fn box_pass(src: &[f32], dst: &mut [f32], w: usize, h: usize, r: usize, along_rows: bool) {
    let (lines, len) = if along_rows { (h, w) } else { (w, h) };
    let at = |line: usize, i: usize| {
        if along_rows {
            line * w + i
        } else {
            i * w + line
        }
    };
    let norm = 1.0 / (2 * r + 1) as f32;
    for line in 0..lines {
        let mut sum = 0.0f64;
        // Window [i − r, i + r], clamped at the borders (edge pixels repeat).
        let clamp = |i: isize| i.clamp(0, len as isize - 1) as usize;
        for k in -(r as isize)..=(r as isize) {
            sum += src[at(line, clamp(k))] as f64;
        }
        for i in 0..len {
            dst[at(line, i)] = sum as f32 * norm;
            let out = clamp(i as isize - r as isize);
            let inn = clamp(i as isize + r as isize + 1);
            sum += src[at(line, inn)] as f64 - src[at(line, out)] as f64;
        }
    }
}

/// Blurred absolute difference image of view `h`.
pub fn blurred_difference(views: &LumaViews, h: usize) -> Vec<f32> {
    let (w, hh) = views.size();
    let (w, hh) = (w as usize, hh as usize);
    let mut a: Vec<f32> = views
        .view_pixels(h)
        .map(|(y, t)| (y as f32 - t as f32).abs())
        .collect();
    let mut b = vec![0.0f32; a.len()];
    for _ in 0..2 {
        box_pass(&a, &mut b, w, hh, BLUR_RADIUS, true);
        box_pass(&b, &mut a, w, hh, BLUR_RADIUS, false);
    }
    a
}

/// Potential of each edge: Σ over views of the blurred difference at its endpoints' projections.
///
/// The views' blurred values at the vertices are found in parallel (the blur was 3 % of an
/// optimization's time on one thread while the other waited), then summed in view order, so
/// the potentials are the same for any thread count.
pub fn potentials(views: &LumaViews, positions: &[Vec3], edges: &[(u32, u32)]) -> Vec<f64> {
    let per_view: Vec<Vec<f32>> = (0..views.view_count())
        .into_par_iter()
        .map(|view| vertex_values(views, view, positions))
        .collect();
    let mut pot = vec![0.0f64; edges.len()];
    for value in &per_view {
        for (pe, &(a, b)) in pot.iter_mut().zip(edges) {
            *pe += value[a as usize] as f64 + value[b as usize] as f64;
        }
    }
    pot
}

/// View `view`'s blurred difference at each vertex's projection (0 off screen or behind the eye).
fn vertex_values(views: &LumaViews, view: usize, positions: &[Vec3]) -> Vec<f32> {
    let (w, h) = views.size();
    let blurred = blurred_difference(views, view);
    let mvp = views.view_matrix(view);
    let pixel = |p: Vec3| -> Option<usize> {
        let c = mvp * p.extend(1.0);
        if c.w <= 0.0 {
            return None;
        }
        let (x, y) = (
            (c.x / c.w * 0.5 + 0.5) * w as f32,
            (0.5 - c.y / c.w * 0.5) * h as f32,
        );
        let ok = x >= 0.0 && y >= 0.0 && x < w as f32 && y < h as f32;
        ok.then(|| y as usize * w as usize + x as usize)
    };
    positions
        .iter()
        .map(|&p| pixel(p).map_or(0.0, |i| blurred[i]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_pass_keeps_constants_and_spreads_a_spike() {
        let (w, h) = (9, 3);
        let src = vec![2.0f32; w * h];
        let mut dst = vec![0.0; w * h];
        box_pass(&src, &mut dst, w, h, 2, true);
        assert!(dst.iter().all(|&x| (x - 2.0).abs() < 1e-6));
        let mut spike = vec![0.0f32; w * h];
        spike[w + 4] = 5.0;
        box_pass(&spike, &mut dst, w, h, 2, true);
        for x in 0..w {
            let expect = if (2..=6).contains(&x) { 1.0 } else { 0.0 };
            assert!((dst[w + x] - expect).abs() < 1e-6, "x={x}: {}", dst[w + x]);
        }
        assert_eq!(dst[4], 0.0);
    }
}
