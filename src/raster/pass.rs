//! One render pass: the frame's set-up state and the stages that need it — stage 1 and 2
//! (`Pass::new`: transform, set up and bin every triangle, or scan it sort-last), stage 3
//! (`Pass::raster_tile`: one tile's samples) and the coverage diagnostic. Stage 4 is
//! `resolve.rs`; `render` in `mod.rs` runs them in order.

use std::borrow::Cow;

use glam::Vec3;
use rayon::prelude::*;

use super::RenderScene;
use super::bin::{self, Binned};
use super::clip::ClipPlanes;
use super::edge::{self, TileSamples};
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
    pub fn raster_tile(&self, t: usize) -> TileSamples {
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
