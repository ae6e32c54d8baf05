//! One render pass: runs set-up and binning, rasterizes every tile in parallel, and resolves each
//! tile's samples into pixels (shading once per distinct triangle per pixel, averaging in linear light).

use glam::Vec3;
use rayon::prelude::*;

use super::bin::{self, Binned};
use super::clip::ClipPlanes;
use super::edge::{self, EMPTY, TileSamples};
use super::frame::{Frame, NO_TRIANGLE};
use super::setup::{self, Viewport};
use super::shade::ShadeContext;
use super::{RenderSettings, camera_setup, vertex_lighting};
use crate::scene::{Camera, Scene};

/// Set-up state of one frame.
pub(crate) struct Pass<'a> {
    scene: &'a Scene,
    settings: RenderSettings,
    binned: Binned,
    offsets: Vec<[i64; 2]>,
    count_coverage: bool,
    /// Resolved lights (direction towards the light, colour).
    lights: Vec<(Vec3, Vec3)>,
    to_eye: Vec3,
    depth_range: (f32, f32, bool),
}

/// A resolved tile.
struct TileOut {
    rect: [i32; 4],
    color: Vec<Vec3>,
    depth: Vec<f32>,
    coverage: Vec<f32>,
    triangle: Vec<u32>,
}

impl<'a> Pass<'a> {
    pub fn new(
        scene: &'a Scene,
        camera: &Camera,
        settings: &RenderSettings,
        count_coverage: bool,
    ) -> Pass<'a> {
        let mesh = scene.mesh();
        let (mvp, depth_range) = camera_setup(camera, settings.width, settings.height);
        // Stage 1: transform and set up triangles.
        let vp = Viewport {
            width: settings.width,
            height: settings.height,
            cull_backfaces: settings.cull_backfaces,
        };
        let planes = ClipPlanes::for_viewport(settings.width, settings.height);
        let xf = setup::transform(mesh.positions(), mvp, &planes, vp);
        // Stage 2 (fused with set-up, per chunk): bin into tiles.
        let binned = bin::setup_and_bin(mesh.triangles(), &xf, &planes, vp);
        let lights = scene.lights.iter().map(|l| l.resolve(camera)).collect();
        Pass {
            scene,
            settings: *settings,
            binned,
            offsets: settings.samples.offsets(),
            count_coverage,
            lights,
            to_eye: camera.to_eye(),
            depth_range,
        }
    }

    fn context(&self) -> ShadeContext<'_> {
        let mut ctx = ShadeContext {
            mesh: self.scene.mesh(),
            prepared: self.scene.prepared(),
            setup: &self.binned,
            shading: self.settings.shading,
            lights: self.lights.clone(),
            to_eye: self.to_eye,
            ambient: self.scene.ambient,
            vertex_light: Vec::new(),
            depth_range: self.depth_range,
        };
        if ctx.shading == super::Shading::Gouraud {
            ctx.vertex_light = vertex_lighting(&ctx);
        }
        ctx
    }

    /// Stage 3: scan-convert every triangle of tile `t` (in index order).
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

    /// Stage 4: resolve one tile's samples into pixels.
    fn resolve_tile(&self, ctx: &ShadeContext, buf: &TileSamples) -> TileOut {
        let [x0, y0, x1, y1] = buf.rect;
        let n = ((x1 - x0) * (y1 - y0)) as usize;
        let s = buf.samples;
        let bg = self.scene.background;
        let mut out = TileOut {
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
                let mut color = bg * (empty as f32);
                for &(id, first, _count) in &groups {
                    let o = self.offsets[first];
                    let (sx, sy) = (
                        x as f64 + o[0] as f64 / 256.0,
                        y as f64 + o[1] as f64 / 256.0,
                    );
                    let c = ctx.shade(id, sx, sy);
                    color += c * (_count as f32);
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

    /// Rasterize and resolve every tile, then assemble the frame.
    pub fn resolve_frame(&self) -> Frame {
        let ctx = self.context();
        let tiles: Vec<TileOut> = (0..self.binned.tile_count())
            .into_par_iter()
            .map(|t| self.resolve_tile(&ctx, &self.raster_tile(t)))
            .collect();
        let (w, h) = (self.settings.width, self.settings.height);
        let n = (w * h) as usize;
        let mut frame = Frame {
            width: w,
            height: h,
            color: vec![Vec3::ZERO; n],
            depth: vec![f32::INFINITY; n],
            coverage: vec![0.0; n],
            triangle: vec![NO_TRIANGLE; n],
        };
        for tile in tiles {
            let [x0, y0, x1, y1] = tile.rect;
            let tw = (x1 - x0) as usize;
            for (r, y) in (y0..y1).enumerate() {
                let dst = y as usize * w as usize + x0 as usize;
                let src = r * tw;
                frame.color[dst..dst + tw].copy_from_slice(&tile.color[src..src + tw]);
                frame.depth[dst..dst + tw].copy_from_slice(&tile.depth[src..src + tw]);
                frame.coverage[dst..dst + tw].copy_from_slice(&tile.coverage[src..src + tw]);
                frame.triangle[dst..dst + tw].copy_from_slice(&tile.triangle[src..src + tw]);
            }
        }
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
