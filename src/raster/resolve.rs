//! One render pass: runs set-up and binning, rasterizes every tile in parallel, and resolves each
//! tile's samples into pixels (shading once per distinct triangle per pixel, averaging in linear
//! light).

use std::borrow::Cow;

use glam::Vec3;
use rayon::prelude::*;

use super::RenderScene;
use super::bin::{self, Binned};
use super::clip::ClipPlanes;
use super::edge::{self, EMPTY, TileSamples};
use super::frame::{Frame, NO_TRIANGLE};
use super::recycle;
use super::setup::{self, Viewport};
use super::shade::{PbrFrame, ResolvedLight, ShadeContext};
use super::sort_last::{self, FrameKeys};
use super::{RenderSettings, Shading, camera_setup, vertex_lighting};
use crate::scene::Camera;

/// How a pass finds what each sample sees.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Visibility {
    /// Renders: sort-last where it applies (one sample per pixel, within its memory budget),
    /// tiles otherwise.
    Fastest,
    /// Tiles only (the tests' reference for the sort-last path: the same frames).
    #[cfg_attr(not(test), allow(dead_code))]
    Tiled,
    /// Tiles, counting every triangle that covers a sample instead of depth testing.
    Counts,
}

/// Set-up state of one frame.
#[derive(Debug)]
pub(crate) struct Pass {
    pub scene: RenderScene,
    pub settings: RenderSettings,
    pub binned: Binned,
    /// The frame's visibility where it was found sort-last (`sort_last.rs`); `None`: each tile
    /// is scanned from its list in `binned`.
    keys: Option<FrameKeys>,
    pub offsets: Vec<[i64; 2]>,
    count_coverage: bool,
    /// Lights resolved for the camera.
    pub lights: Vec<ResolvedLight>,
    depth_range: (f32, f32, bool),
    /// The `pbr` model's frame state, where the (resolved) shading is `Pbr`.
    pbr: Option<PbrFrame>,
}

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
fn frame_tiles(frame: &mut Frame, tile: usize) -> Vec<RectMut<'_>> {
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
    pub fn new(
        scene: &RenderScene,
        camera: &Camera,
        settings: &RenderSettings,
        visibility: Visibility,
    ) -> Pass {
        let count_coverage = visibility == Visibility::Counts;
        let mesh = scene.mesh();
        // `auto` becomes the model the mesh's materials call for.
        let mut settings = *settings;
        settings.shading = settings.shading.resolve(mesh);
        let (mvp, depth_range) = camera_setup(camera, settings.width, settings.height);
        let offsets = settings.samples.offsets();
        let span = |k: usize, f: fn(i64, i64) -> i64| {
            offsets.iter().map(|o| o[k]).reduce(f).unwrap_or(0) as i32
        };
        let vp = Viewport {
            width: settings.width,
            height: settings.height,
            cull_backfaces: settings.cull_backfaces,
            sample_span: [
                span(0, i64::min),
                span(1, i64::min),
                span(0, i64::max),
                span(1, i64::max),
            ],
        };
        let planes = ClipPlanes::for_viewport(settings.width, settings.height);
        // Stage 1: transform, classify and project vertices.
        let xf = setup::transform(mesh.positions(), mvp, &planes, vp);
        // Stage 2: set up triangles and bin them into tiles (fused, per chunk); or, for a
        // one-sample frame that fits the budget, set up and scan them there and then, sort-last.
        let found_sort_last = offsets.len() == 1
            && visibility == Visibility::Fastest
            && sort_last::fits(
                settings.width,
                settings.height,
                rayon::current_num_threads(),
            );
        let (binned, keys) = if found_sort_last {
            let (binned, keys) =
                sort_last::setup_and_scan(mesh.triangles(), &xf, &planes, vp, offsets[0]);
            (binned, Some(keys))
        } else {
            (bin::setup_and_bin(mesh.triangles(), &xf, &planes, vp), None)
        };
        let pbr = (settings.shading == Shading::Pbr)
            .then(|| PbrFrame::new(scene, camera, settings.multiple_scattering));
        Pass {
            scene: scene.clone(),
            settings,
            binned,
            keys,
            offsets,
            count_coverage,
            lights: ResolvedLight::for_camera(&scene.lights_for(false), camera),
            depth_range,
            pbr,
        }
    }

    /// Whether this pass found its visibility sort-last.
    #[cfg(test)]
    pub fn is_sort_last(&self) -> bool {
        self.keys.is_some()
    }

    /// The shading context; for Gouraud, `vertex_light` is used if given, computed otherwise.
    pub fn context<'a>(&'a self, vertex_light: Option<&'a [(Vec3, Vec3)]>) -> ShadeContext<'a> {
        let mut ctx = ShadeContext {
            mesh: self.scene.mesh(),
            prepared: self.scene.prepared(),
            setup: &self.binned,
            shading: self.settings.shading,
            lights: self.lights.clone(),
            ambient: self.scene.ambient,
            vertex_light: Cow::Borrowed(&[]),
            depth_range: self.depth_range,
            pbr: self.pbr.as_ref(),
            display: self.settings.display(),
        };
        if ctx.shading == Shading::Gouraud {
            ctx.vertex_light = match vertex_light {
                Some(v) => Cow::Borrowed(v),
                None => Cow::Owned(vertex_lighting(&ctx)),
            };
        }
        ctx
    }

    /// Stage 3: scan-convert every triangle of tile `t` (in source-triangle order), or take the
    /// tile's share of the sort-last visibility.
    fn raster_tile(&self, t: usize) -> TileSamples {
        let rect = bin::tile_rect(t, self.settings.width, self.settings.height);
        if let Some(keys) = &self.keys {
            return keys.tile(rect);
        }
        let mut buf = TileSamples::new(rect, self.offsets.len(), self.count_coverage);
        let mut scratch = vec![[0i64; 3]; self.offsets.len()];
        for (id, tri) in self.binned.tile(t) {
            edge::rasterize(
                tri,
                id,
                &self.offsets,
                rect,
                &mut buf,
                &mut scratch,
                edge::Scans::Fastest,
            );
        }
        buf
    }

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

    /// Rasterize and resolve every tile, in parallel, each straight into its pixels of the frame.
    pub fn resolve_frame(&self, ctx: &ShadeContext) -> Frame {
        let (w, h) = (self.settings.width as usize, self.settings.height as usize);
        let n = w * h;
        // Every pixel is written by exactly one tile, so the channels' previous contents (fill
        // values, or an earlier frame's pixels when recycled) are never seen.
        let mut frame = Frame {
            width: w as u32,
            height: h as u32,
            color: recycle::take(n, Vec3::ZERO),
            depth: recycle::take(n, 0.0),
            coverage: recycle::take(n, 0.0),
            triangle: recycle::take(n, 0),
        };
        let targets = frame_tiles(&mut frame, bin::TILE as usize);
        debug_assert_eq!(
            targets.len(),
            bin::tile_count(self.settings.width, self.settings.height)
        );
        targets
            .into_par_iter()
            .enumerate()
            .for_each(|(t, mut out)| self.resolve(ctx, &self.raster_tile(t), &mut out));
        frame
    }

    /// Per-sample coverage counts over the whole image, row-major per pixel.
    pub fn counts(&self) -> Vec<u16> {
        let tiles: Vec<TileSamples> =
            (0..bin::tile_count(self.settings.width, self.settings.height))
                .into_par_iter()
                .map(|t| self.raster_tile(t))
                .collect();
        let (w, h) = (self.settings.width as usize, self.settings.height as usize);
        let s = self.offsets.len();
        let mut out = vec![0u16; w * h * s];
        for tile in tiles {
            let [x0, y0, x1, y1] = tile.rect;
            let tw = (x1 - x0) as usize * s;
            let counts = tile.counts.as_deref().unwrap_or(&[]);
            for (r, y) in (y0..y1).enumerate() {
                let dst = (y as usize * w + x0 as usize) * s;
                out[dst..dst + tw].copy_from_slice(&counts[r * tw..(r + 1) * tw]);
            }
        }
        out
    }
}
