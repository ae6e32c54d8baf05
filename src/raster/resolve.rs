//! Stage 4 of a render: a tile's samples resolved into its pixels — shading once per distinct
//! triangle per pixel, at that triangle's first covered sample, and averaging in linear light —
//! written straight into the frame's rectangle of that tile.

use glam::Vec3;

use super::edge::{EMPTY, TileSamples};
use super::frame::{Frame, NO_TRIANGLE};
use super::pass::Pass;
use super::shade::ShadeContext;

/// Where a resolve writes: one rectangle of a frame, as a row slice of every channel per pixel
/// row, filled in row-major order.
pub(crate) struct RectMut<'a> {
    rows: Vec<RowMut<'a>>,
    row: usize,
    col: usize,
}

/// A run of pixels of a frame: the same slice of every channel.
struct RowMut<'a> {
    color: &'a mut [Vec3],
    depth: &'a mut [f32],
    coverage: &'a mut [f32],
    triangle: &'a mut [u32],
}

impl<'a> RowMut<'a> {
    /// All pixels of `frame`, row-major.
    fn all(frame: &'a mut Frame) -> RowMut<'a> {
        RowMut {
            color: &mut frame.color,
            depth: &mut frame.depth,
            coverage: &mut frame.coverage,
            triangle: &mut frame.triangle,
        }
    }

    /// The run cut into consecutive runs of `n` pixels (the last may be shorter).
    fn split(self, n: usize) -> impl Iterator<Item = RowMut<'a>> {
        self.color
            .chunks_mut(n)
            .zip(self.depth.chunks_mut(n))
            .zip(self.coverage.chunks_mut(n))
            .zip(self.triangle.chunks_mut(n))
            .map(|(((color, depth), coverage), triangle)| RowMut {
                color,
                depth,
                coverage,
                triangle,
            })
    }
}

impl<'a> RectMut<'a> {
    fn new(rows: Vec<RowMut<'a>>) -> RectMut<'a> {
        RectMut {
            rows,
            row: 0,
            col: 0,
        }
    }

    /// Write the next pixel.
    #[inline]
    fn push(&mut self, color: Vec3, depth: f32, coverage: f32, triangle: u32) {
        let r = &mut self.rows[self.row];
        let c = self.col;
        (r.color[c], r.depth[c], r.coverage[c], r.triangle[c]) = (color, depth, coverage, triangle);
        self.col += 1;
        if self.col == r.color.len() {
            (self.row, self.col) = (self.row + 1, 0);
        }
    }
}

/// Software prefetch for a tile's resolve: shading a pixel reads its triangle's set-up record,
/// the source triangle's vertex indices and those vertices' attributes, each found through the
/// one before, and scattered over arrays far larger than the caches (a 1M-triangle frame has 64
/// MB of records). The pixel [`Prefetch::FAR`] ahead gets its record asked for, the one
/// [`Prefetch::NEAR`] ahead (record now cached) its vertex indices, and the one
/// [`Prefetch::NEXT`] ahead its vertices' light terms or normals: by the time a pixel is shaded
/// its loads hit the cache. Hints only: nothing computed depends on them.
struct Prefetch<'a> {
    ctx: &'a ShadeContext<'a>,
    ids: &'a [u32],
    samples: usize,
    pixels: usize,
}

impl<'a> Prefetch<'a> {
    const FAR: usize = 12;
    const NEAR: usize = 8;
    const NEXT: usize = 4;

    fn new(ctx: &'a ShadeContext<'a>, buf: &'a TileSamples) -> Prefetch<'a> {
        let samples = buf.samples;
        let pixels = ((buf.rect[2] - buf.rect[0]) * (buf.rect[3] - buf.rect[1])) as usize;
        Prefetch {
            ctx,
            ids: &buf.ids,
            samples,
            pixels,
        }
    }

    /// The first sample's triangle of pixel `pixel`, if covered.
    fn id(&self, pixel: usize) -> Option<u32> {
        if pixel >= self.pixels {
            return None;
        }
        Some(self.ids[pixel * self.samples]).filter(|&id| id != EMPTY)
    }

    /// Ask for what the pixels ahead of `pixel` will read.
    #[inline]
    fn ahead_of(&self, pixel: usize) {
        use crate::prefetch::{prefetch, prefetch_at};
        let setup = self.ctx.setup;
        let triangles = self.ctx.mesh.triangles();
        if let Some(id) = self.id(pixel + Self::FAR) {
            prefetch(setup.get(id));
        }
        if let Some(id) = self.id(pixel + Self::NEAR) {
            prefetch_at(triangles, setup.get(id).tri);
        }
        if let Some(id) = self.id(pixel + Self::NEXT)
            && let Some(tri) = triangles.get(setup.get(id).tri as usize)
        {
            for &v in tri {
                if self.ctx.vertex_light.is_empty() {
                    prefetch_at(self.ctx.mesh.normals(), v);
                } else {
                    prefetch_at(&self.ctx.vertex_light, v);
                }
            }
        }
    }
}

/// `frame` cut into the resolve targets of its `tile`×`tile` tiles, row-major tile order.
pub(super) fn frame_tiles(frame: &mut Frame, tile: usize) -> Vec<RectMut<'_>> {
    let w = frame.width as usize;
    let tiles_x = w.div_ceil(tile);
    let n_tiles = tiles_x * (frame.height as usize).div_ceil(tile);
    let mut tiles: Vec<RectMut> = (0..n_tiles)
        .map(|_| RectMut::new(Vec::with_capacity(tile)))
        .collect();
    for (y, row) in RowMut::all(frame).split(w).enumerate() {
        for (tx, piece) in row.split(tile).enumerate() {
            tiles[y / tile * tiles_x + tx].rows.push(piece);
        }
    }
    tiles
}

impl Pass {
    /// Stage 4: resolve a sample buffer into pixels, written to `out` (its rectangle is
    /// `buf.rect`).
    pub fn resolve(&self, ctx: &ShadeContext, buf: &TileSamples, out: &mut RectMut) {
        let [x0, y0, x1, y1] = buf.rect;
        let s = buf.samples;
        let bg = self.scene.background;
        // (set-up id, first sample, sample count) of the distinct triangles in one pixel.
        let mut groups: Vec<(u32, usize, usize)> = Vec::with_capacity(s);
        let prefetch = Prefetch::new(ctx, buf);
        for y in y0..y1 {
            for x in x0..x1 {
                let pixel = ((y - y0) * (x1 - x0) + (x - x0)) as usize;
                prefetch.ahead_of(pixel);
                let base = pixel * s;
                if s == 1 {
                    // One sample: no grouping; shade at the sample or show the background.
                    let id = buf.ids[base];
                    let o = self.offsets[0];
                    let (color, tri) = match id {
                        EMPTY => (bg, NO_TRIANGLE),
                        _ => {
                            let (sx, sy) = (
                                x as f64 + o[0] as f64 / 256.0,
                                y as f64 + o[1] as f64 / 256.0,
                            );
                            (ctx.shade(id, sx, sy), self.binned.get(id).tri)
                        }
                    };
                    let coverage = if id == EMPTY { 0.0 } else { 1.0 };
                    out.push(color, buf.depth[base], coverage, tri);
                    continue;
                }
                groups.clear();
                let mut empty = 0usize;
                let mut depth = f32::INFINITY;
                for k in 0..s {
                    let id = buf.ids[base + k];
                    if id == EMPTY {
                        empty += 1;
                        continue;
                    }
                    depth = depth.min(buf.depth[base + k]);
                    match groups.iter_mut().find(|g| g.0 == id) {
                        Some(g) => g.2 += 1,
                        None => groups.push((id, k, 1)),
                    }
                }
                // Shade each triangle once, at its first covered sample (inside the triangle).
                let mut color = bg * (empty as f32);
                for &(id, first, count) in &groups {
                    let o = self.offsets[first];
                    let (sx, sy) = (
                        x as f64 + o[0] as f64 / 256.0,
                        y as f64 + o[1] as f64 / 256.0,
                    );
                    color += ctx.shade(id, sx, sy) * (count as f32);
                }
                // Most samples wins; on a tie the group seen first (earliest sample) stays.
                let best = groups
                    .iter()
                    .fold(None::<(u32, usize)>, |acc, g| match acc {
                        Some((_, c)) if c >= g.2 => acc,
                        _ => Some((g.0, g.2)),
                    });
                out.push(
                    color / s as f32,
                    depth,
                    (s - empty) as f32 / s as f32,
                    best.map_or(NO_TRIANGLE, |(id, _)| self.binned.get(id).tri),
                );
            }
        }
        // Recycled channels rely on this: every pixel of the target has been written.
        assert_eq!(
            (out.row, out.col),
            (out.rows.len(), 0),
            "resolve left pixels unwritten"
        );
    }
}
