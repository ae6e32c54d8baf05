//! One render pass: runs set-up and binning, rasterizes every tile in parallel, and resolves each
//! tile's samples into pixels (shading once per distinct triangle per pixel, averaging in linear
//! light). The region re-render (`region.rs`) keeps a pass alive and reuses its pieces.

use std::borrow::Cow;

use glam::{Mat4, Vec3};
use rayon::prelude::*;

use super::bin::{self, Binned};
use super::clip::ClipPlanes;
use super::edge::{self, EMPTY, TileSamples};
use super::frame::{Frame, NO_TRIANGLE};
use super::setup::{self, Viewport, XfVertex};
use super::shade::{ResolvedLight, ShadeContext};
use super::{RenderSettings, Shading, camera_setup, vertex_lighting};
use crate::scene::{Camera, Scene};

/// Set-up state of one frame.
#[derive(Debug)]
pub(crate) struct Pass {
    pub scene: Scene,
    pub settings: RenderSettings,
    pub mvp: Mat4,
    pub vp: Viewport,
    pub planes: ClipPlanes,
    pub xf: Vec<XfVertex>,
    pub binned: Binned,
    pub offsets: Vec<[i64; 2]>,
    count_coverage: bool,
    /// Lights resolved for the camera.
    pub lights: Vec<ResolvedLight>,
    depth_range: (f32, f32, bool),
}

/// Resolved pixels of a rectangle.
#[derive(Debug)]
pub(crate) struct Resolved {
    rect: [i32; 4],
    color: Vec<Vec3>,
    depth: Vec<f32>,
    coverage: Vec<f32>,
    triangle: Vec<u32>,
}

impl Pass {
    pub fn new(
        scene: &Scene,
        camera: &Camera,
        settings: &RenderSettings,
        count_coverage: bool,
    ) -> Pass {
        let mesh = scene.mesh();
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
        // Stage 2: set up triangles and bin them into tiles (fused, per chunk).
        let binned = bin::setup_and_bin(mesh.triangles(), &xf, &planes, vp);
        Pass {
            scene: scene.clone(),
            settings: *settings,
            mvp,
            vp,
            planes,
            xf,
            binned,
            offsets,
            count_coverage,
            lights: ResolvedLight::for_camera(&scene.lights, camera),
            depth_range,
        }
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
        };
        if ctx.shading == Shading::Gouraud {
            ctx.vertex_light = match vertex_light {
                Some(v) => Cow::Borrowed(v),
                None => Cow::Owned(vertex_lighting(&ctx)),
            };
        }
        ctx
    }

    /// Stage 3: scan-convert every triangle of tile `t` (in source-triangle order).
    fn raster_tile(&self, t: usize) -> TileSamples {
        let rect = self
            .binned
            .tile_rect(t, self.settings.width, self.settings.height);
        let mut buf = TileSamples::new(rect, self.offsets.len(), self.count_coverage);
        let mut scratch = vec![[0i64; 3]; self.offsets.len()];
        for (id, tri) in self.binned.tile(t) {
            edge::rasterize(tri, id, &self.offsets, rect, &mut buf, &mut scratch);
        }
        buf
    }

    /// Stage 4: resolve a sample buffer into pixels.
    pub fn resolve(&self, ctx: &ShadeContext, buf: &TileSamples) -> Resolved {
        let [x0, y0, x1, y1] = buf.rect;
        let n = ((x1 - x0) * (y1 - y0)) as usize;
        let s = buf.samples;
        let bg = self.scene.background;
        let mut out = Resolved {
            rect: buf.rect,
            color: Vec::with_capacity(n),
            depth: Vec::with_capacity(n),
            coverage: Vec::with_capacity(n),
            triangle: Vec::with_capacity(n),
        };
        // (set-up id, first sample, sample count) of the distinct triangles in one pixel.
        let mut groups: Vec<(u32, usize, usize)> = Vec::with_capacity(s);
        for y in y0..y1 {
            for x in x0..x1 {
                let base = ((y - y0) * (x1 - x0) + (x - x0)) as usize * s;
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
                    out.color.push(color);
                    out.depth.push(buf.depth[base]);
                    out.coverage.push(if id == EMPTY { 0.0 } else { 1.0 });
                    out.triangle.push(tri);
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
                out.color.push(color / s as f32);
                out.depth.push(depth);
                out.coverage.push((s - empty) as f32 / s as f32);
                out.triangle
                    .push(best.map_or(NO_TRIANGLE, |(id, _)| self.binned.get(id).tri));
            }
        }
        out
    }

    /// Rasterize and resolve every tile (tiles in parallel), then copy each band of tile rows into
    /// the frame (bands in parallel; every pixel written exactly once).
    pub fn resolve_frame(&self, ctx: &ShadeContext) -> Frame {
        let (w, h) = (self.settings.width as usize, self.settings.height as usize);
        let n = w * h;
        let tiles: Vec<Resolved> = (0..self.binned.tile_count())
            .into_par_iter()
            .map(|t| self.resolve(ctx, &self.raster_tile(t)))
            .collect();
        // Every pixel is written below, so the buffers start as zeroed (calloc'd, untouched) pages
        // rather than being filled with their "empty" values first.
        let mut frame = Frame {
            width: w as u32,
            height: h as u32,
            color: vec![Vec3::ZERO; n],
            depth: vec![0.0; n],
            coverage: vec![0.0; n],
            triangle: vec![0; n],
        };
        let band = bin::TILE as usize * w;
        let tiles_x = (w as u32).div_ceil(bin::TILE) as usize;
        frame
            .color
            .par_chunks_mut(band)
            .zip(frame.depth.par_chunks_mut(band))
            .zip(frame.coverage.par_chunks_mut(band))
            .zip(frame.triangle.par_chunks_mut(band))
            .zip(tiles.par_chunks(tiles_x))
            .enumerate()
            .for_each(|(ty, ((((color, depth), coverage), triangle), row))| {
                let y0 = ty as i32 * bin::TILE as i32;
                let mut out = PixelsMut {
                    color,
                    depth,
                    coverage,
                    triangle,
                    width: w,
                    y0,
                };
                row.iter().for_each(|tile| out.put(tile));
            });
        frame
    }

    /// Per-sample coverage counts over the whole image, row-major per pixel.
    pub fn counts(&self) -> Vec<u16> {
        let tiles: Vec<TileSamples> = (0..self.binned.tile_count())
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

/// Mutable frame channels for the rows starting at `y0`.
struct PixelsMut<'a> {
    color: &'a mut [Vec3],
    depth: &'a mut [f32],
    coverage: &'a mut [f32],
    triangle: &'a mut [u32],
    width: usize,
    y0: i32,
}

impl PixelsMut<'_> {
    /// Copy resolved pixels into their place.
    fn put(&mut self, r: &Resolved) {
        let [x0, y0, x1, y1] = r.rect;
        let tw = (x1 - x0) as usize;
        for (row, y) in (y0..y1).enumerate() {
            let dst = (y - self.y0) as usize * self.width + x0 as usize;
            let src = row * tw;
            self.color[dst..dst + tw].copy_from_slice(&r.color[src..src + tw]);
            self.depth[dst..dst + tw].copy_from_slice(&r.depth[src..src + tw]);
            self.coverage[dst..dst + tw].copy_from_slice(&r.coverage[src..src + tw]);
            self.triangle[dst..dst + tw].copy_from_slice(&r.triangle[src..src + tw]);
        }
    }
}

/// Copy resolved pixels into their place in a frame.
pub(crate) fn blit(frame: &mut Frame, r: &Resolved) {
    let width = frame.width as usize;
    PixelsMut {
        color: &mut frame.color,
        depth: &mut frame.depth,
        coverage: &mut frame.coverage,
        triangle: &mut frame.triangle,
        width,
        y0: 0,
    }
    .put(r);
}
