//! Incremental re-render: keep a frame with its set-up and bins, and after a local mesh edit
//! re-render only the screen rectangle the edit can have changed. The Lindstrom–Turk optimizer
//! evaluates every candidate move this way (Lindstrom & Turk, §4.2, eq. 2: the energy change is
//! summed over the screen-space bounding box of the changed triangles in each view).
//!
//! An update re-transforms the vertices of the changed triangles, sets those triangles up again
//! (they go to the bins' overlay, their old entries become stale), takes as dirty rectangle the
//! union of their old and new screen bounding boxes, finds the triangles overlapping it through
//! the tiles it touches (never by scanning all triangles), rasterizes them clipped to the rectangle
//! in the order a full render uses, and resolves its pixels into the kept frame. The result is
//! exactly the frame a full render of the edited mesh gives (tested), provided `changed` lists
//! every triangle whose corners, or whose corners' attributes (normals move with the vertices!),
//! differ.
//!
//! Decision: edits must keep the triangle and vertex counts (vertex moves, attribute changes, edge
//! swaps — everything Lindstrom–Turk's moves need, where a teleport is a split plus a collapse);
//! other edits need a fresh [`RegionRenderer::new`].

use glam::Vec3;

use super::RenderScene;
use super::edge::{self, TileSamples};
use super::frame::Frame;
use super::resolve::{Pass, frame_rect};
use super::setup::{setup_one, transform_one};
use super::{RenderSettings, Shading, rect_union, shade};
use crate::error::{Error, Result};
use crate::scene::Camera;

/// A frame kept together with its set-up state for incremental updates.
#[derive(Debug)]
pub struct RegionRenderer {
    pass: Pass,
    frame: Frame,
    vertex_light: Vec<(Vec3, Vec3)>,
}

impl RegionRenderer {
    /// Render `scene` fully and keep what an update needs.
    pub fn new(
        scene: &RenderScene,
        camera: &Camera,
        settings: &RenderSettings,
    ) -> Result<RegionRenderer> {
        settings.check()?;
        let pass = Pass::new(scene, camera, settings, false);
        let ctx = pass.context(None);
        let frame = pass.resolve_frame(&ctx);
        let vertex_light = ctx.vertex_light.into_owned();
        Ok(RegionRenderer {
            pass,
            frame,
            vertex_light,
        })
    }

    /// The current frame.
    pub fn frame(&self) -> &Frame {
        &self.frame
    }

    /// Replace the scene by `scene`, which differs from the current one only in the source
    /// triangles `changed`, and re-render what that can change. Returns the re-rendered pixel
    /// rectangle `[x0, y0, x1, y1)`, or `None` when none of the triangles is or was on screen.
    pub fn update(&mut self, scene: &RenderScene, changed: &[u32]) -> Result<Option<[i32; 4]>> {
        let (old, new) = (self.pass.scene.mesh(), scene.mesh());
        if old.triangle_count() != new.triangle_count() || old.vertex_count() != new.vertex_count()
        {
            return Err(Error::Usage(
                "a region update must keep the triangle and vertex counts; render anew instead"
                    .into(),
            ));
        }
        if let Some(&bad) = changed
            .iter()
            .find(|&&t| t as usize >= new.triangle_count())
        {
            return Err(Error::Usage(format!(
                "changed triangle {bad} does not exist"
            )));
        }
        let mut dirty: Option<[i32; 4]> = None;
        let mut grow = |b: [i32; 4]| dirty = Some(rect_union(dirty, b));
        // Old footprint of the changed triangles.
        for &t in changed {
            for id in self.pass.binned.ids_of(t) {
                grow(self.pass.binned.get(id).bbox());
            }
        }
        // New vertex data: transform (and, for Gouraud, light) the vertices of changed triangles.
        self.pass.scene = scene.clone();
        let (mvp, planes, vp) = (self.pass.mvp, self.pass.planes, self.pass.vp);
        let gouraud = self.pass.settings.shading == Shading::Gouraud;
        for &t in changed {
            for v in new.triangles()[t as usize] {
                let v = v as usize;
                self.pass.xf[v] = transform_one(new.positions()[v], mvp, &planes, vp);
                if gouraud {
                    let m = &new.materials()[scene.prepared().vertex_material[v] as usize];
                    let lights = &self.pass.lights;
                    self.vertex_light[v] = shade::light_terms(
                        new.normals()[v],
                        lights,
                        scene.ambient,
                        m.specular,
                        m.shininess,
                    );
                }
            }
        }
        // New set-up of the changed triangles, into the overlay.
        for &t in changed {
            let xf = &self.pass.xf;
            let corners = new.triangles()[t as usize];
            self.pass.binned.replace(t, new.triangle_count(), |out| {
                setup_one(t, corners, xf, &planes, vp, out)
            });
            for id in self.pass.binned.ids_of(t) {
                grow(self.pass.binned.get(id).bbox());
            }
        }
        if let Some(rect) = dirty {
            self.render_rect(rect);
        }
        Ok(dirty)
    }

    /// Re-render the pixels of `rect` (`[x0, y0, x1, y1)`, clamped to the image) from the current
    /// state.
    pub fn render_rect(&mut self, rect: [i32; 4]) {
        let (w, h) = (self.pass.settings.width, self.pass.settings.height);
        let rect = [
            rect[0].max(0),
            rect[1].max(0),
            rect[2].min(w as i32),
            rect[3].min(h as i32),
        ];
        if rect[0] >= rect[2] || rect[1] >= rect[3] {
            return;
        }
        let offsets = &self.pass.offsets;
        let mut buf = TileSamples::new(rect, offsets.len(), false);
        let mut scratch = vec![[0i64; 3]; offsets.len()];
        for id in self.pass.binned.candidates(rect, w, h) {
            edge::rasterize(
                self.pass.binned.get(id),
                id,
                offsets,
                rect,
                &mut buf,
                &mut scratch,
            );
        }
        let ctx = self.pass.context(Some(&self.vertex_light));
        self.pass
            .resolve(&ctx, &buf, &mut frame_rect(&mut self.frame, rect));
    }
}
