//! Sort-last visibility for one-sample frames: every worker scans its chunks of triangles right
//! after setting them up, into its own full-frame buffer, and the buffers are merged per pixel.
//!
//! Why: at one sample per pixel a dense mesh's triangles cover a pixel or two each, and the tiled
//! path (`bin.rs`, then `edge.rs` per tile) spends much of its time moving them — binning, then
//! reading every 64-byte set-up record back from memory in tile order. Here a chunk's records are
//! scanned while they are still in the cache, and nothing is binned: 42.1 → 39.5 ms median per
//! frame of the 1M-triangle torus at 1024² (`lodeval bench raster --samples 1`, 10 alternating
//! rounds, 2 threads). The records are still written, for the resolve: rebuilding a visible
//! triangle's record from its vertices instead cost the resolve more (about 4 ms) than it saved.
//! (Molnar, Cox, Ellsworth, Fuchs. A Sorting Classification of Parallel Rendering. IEEE CG&A
//! 1994: "sort-last" composites full-frame partial images by depth.)
//!
//! Determinism: a pixel keeps the smallest [`edge::depth_key`] — its nearest depth, ties to the smaller
//! set-up id — which is a minimum over all the triangles covering it, so it does not depend on
//! which worker scanned which chunk or in what order, nor on how many buffers there were. It is
//! also exactly what the tiled path keeps (triangles in id order, strict depth test), so both
//! paths give the same frame (tested).
//!
//! Memory: one `u64` per pixel per worker, from a budget ([`MAX_BYTES`]); larger frames take the
//! tiled path.

use std::sync::{Mutex, PoisonError};

use rayon::prelude::*;

use super::bin::{self, Binned};
use super::clip::ClipPlanes;
use super::edge::{self, TileSamples};
use super::recycle;
use super::setup::{SetupOut, Viewport, XfVertex};

/// Largest total size of the workers' buffers of one frame: 64 MB, 1024² pixels with 8 workers.
pub(crate) const MAX_BYTES: usize = 64 << 20;

/// Marks a pixel no triangle covers.
const EMPTY_KEY: u64 = u64::MAX;

/// Whether a one-sample `width` × `height` frame rendered by `workers` threads fits the budget.
pub(crate) fn fits(width: u32, height: u32, workers: usize) -> bool {
    (width as usize * height as usize)
        .saturating_mul(std::mem::size_of::<u64>())
        .saturating_mul(workers)
        <= MAX_BYTES
}

/// The merged visibility of a frame: a full-frame key buffer (row-major) per worker that
/// scanned anything.
#[derive(Debug)]
pub(crate) struct FrameKeys {
    width: usize,
    buffers: Vec<Vec<u64>>,
}

impl Drop for FrameKeys {
    /// The buffers go back to the renderer's pool for the next frame of this size.
    fn drop(&mut self) {
        for b in self.buffers.drain(..) {
            recycle::give(b);
        }
    }
}

impl FrameKeys {
    /// The visibility of the tile rectangle `rect` as one-sample tile buffers: each pixel's
    /// smallest key over the workers' buffers.
    pub fn tile(&self, rect: [i32; 4]) -> TileSamples {
        let mut buf = TileSamples::new(rect, 1, false);
        let [x0, y0, x1, y1] = rect.map(|v| v as usize);
        let mut i = 0;
        for y in y0..y1 {
            for x in y * self.width + x0..y * self.width + x1 {
                let key = self.buffers.iter().map(|b| b[x]).min().unwrap_or(EMPTY_KEY);
                if key != EMPTY_KEY {
                    buf.depth[i] = f32::from_bits((key >> 32) as u32);
                    buf.ids[i] = key as u32;
                }
                i += 1;
            }
        }
        buf
    }
}

/// Set up every triangle (as [`bin::setup_and_bin`] does, with the same ids, but without tile
/// lists) and scan each chunk's triangles straight away into its worker's buffer at one sample
/// per pixel at `offset` (Fx24_8).
pub(crate) fn setup_and_scan(
    triangles: &[[u32; 3]],
    xf: &[XfVertex],
    planes: &ClipPlanes,
    vp: Viewport,
    offset: [i64; 2],
) -> (Binned, FrameKeys) {
    let (w, h) = (vp.width as usize, vp.height as usize);
    // One slot per worker of the pool this runs in; a worker only ever locks its own, so the
    // locks are never contended (a chunk's scan calls nothing that could run another chunk on
    // the same thread while the lock is held).
    let slots: Vec<Mutex<Option<Vec<u64>>>> = (0..rayon::current_num_threads())
        .map(|_| Mutex::new(None))
        .collect();
    let outs: Vec<SetupOut> = triangles
        .par_chunks(bin::CHUNK)
        .enumerate()
        .map(|(c, chunk)| {
            let out = bin::setup_chunk(c, chunk, xf, planes, vp);
            if out.tris.is_empty() {
                return out;
            }
            // Scanned while the chunk's records are still in the cache.
            let slot = rayon::current_thread_index().unwrap_or(0) % slots.len();
            let mut guard = slots[slot].lock().unwrap_or_else(PoisonError::into_inner);
            let keys = guard.get_or_insert_with(|| match recycle::take_kept(w * h) {
                Some(mut kept) => {
                    kept.fill(EMPTY_KEY);
                    kept
                }
                None => vec![EMPTY_KEY; w * h],
            });
            let frame = [vp.width as i32, vp.height as i32];
            for (k, st) in out.tris.iter().enumerate() {
                edge::rasterize_keys(st, bin::setup_id(c, k), offset, frame, keys);
            }
            out
        })
        .collect();
    let buffers = slots
        .into_iter()
        .filter_map(|s| s.into_inner().unwrap_or_else(PoisonError::into_inner))
        .collect();
    let n_tiles = bin::tile_count(vp.width, vp.height);
    (
        bin::unbinned(outs, n_tiles),
        FrameKeys { width: w, buffers },
    )
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use glam::Vec3;

    use super::super::pass::{Pass, Visibility};
    use super::super::{Frame, RenderScene, RenderSettings, SamplePattern, Shading, with_threads};
    use crate::mesh::{Mesh, shapes};
    use crate::scene::{Camera, Rig};

    /// A frame rendered with `visibility`, and whether the pass went sort-last.
    fn frame(
        scene: &RenderScene,
        camera: &Camera,
        settings: &RenderSettings,
        visibility: Visibility,
    ) -> (Frame, bool) {
        let pass = Pass::new(scene, camera, settings, visibility);
        let frame = super::super::draw(&pass, &pass.context(None));
        (frame, pass.is_sort_last())
    }

    /// Every channel as raw bits (−0.0 ≠ +0.0).
    fn bits(f: &Frame) -> Vec<u32> {
        let mut v: Vec<u32> = f
            .color
            .iter()
            .flat_map(|c| c.to_array().map(f32::to_bits))
            .collect();
        v.extend(f.depth.iter().map(|d| d.to_bits()));
        v.extend(f.coverage.iter().map(|c| c.to_bits()));
        v.extend_from_slice(&f.triangle);
        v
    }

    /// An icosphere with every triangle twice (the copy `n` later): each sample is a depth tie
    /// between two ids, which the smaller must win.
    fn doubled_sphere() -> Mesh {
        let mut data = shapes::icosphere(2).to_data();
        let tris = data.triangles.clone();
        data.triangles.extend(tris);
        data.material_ids.extend(data.material_ids.clone());
        Mesh::new(data, &Default::default()).unwrap()
    }

    #[test]
    fn the_sort_last_path_gives_the_tiled_paths_frames_for_any_thread_count() {
        let torus = Arc::new(shapes::torus(300, 200, 0.35));
        let doubled = Arc::new(doubled_sphere());
        let sphere = Arc::new(shapes::icosphere(3));
        let n_doubled = doubled.triangle_count() as u32 / 2;
        let inside = Camera::looking_at(
            sphere.bounding_sphere(),
            Vec3::new(0.1, 0.2, 0.3),
            Vec3::new(1.0, -0.5, -2.0),
            70.0,
        );
        let cases: Vec<(&str, Arc<Mesh>, Camera, Shading)> = vec![
            // 120 000 triangles at 133 × 97: most smaller than a pixel, many between samples.
            (
                "torus",
                torus.clone(),
                Rig::Fibonacci(5).cameras(&torus, 1.0)[3],
                Shading::Gouraud,
            ),
            (
                "doubled sphere",
                doubled.clone(),
                Rig::Dodecahedron.cameras(&doubled, 1.0)[2],
                Shading::Phong,
            ),
            // The eye inside the sphere: triangles cross the near plane and are clipped.
            ("inside the sphere", sphere, inside, Shading::Normals),
        ];
        for (name, mesh, camera, shading) in cases {
            let scene = RenderScene::of(mesh);
            for cull_backfaces in [false, true] {
                let mut s = RenderSettings::DEFAULT;
                (s.width, s.height, s.shading, s.cull_backfaces) =
                    (133, 97, shading, cull_backfaces);
                s.samples = SamplePattern::Ordered(1);
                let (tiled, was) = frame(&scene, &camera, &s, Visibility::Tiled);
                assert!(!was);
                // (From inside, the sphere shows only back faces.)
                assert!(
                    cull_backfaces || tiled.coverage.iter().filter(|&&c| c > 0.0).count() > 2000,
                    "{name}: the view shows the mesh"
                );
                if name == "doubled sphere" {
                    assert!(
                        tiled
                            .triangle
                            .iter()
                            .all(|&t| t < n_doubled || t == u32::MAX),
                        "ties go to the first copy"
                    );
                }
                for threads in [1, 2, 8] {
                    let (fast, was) =
                        with_threads(threads, || frame(&scene, &camera, &s, Visibility::Fastest))
                            .unwrap();
                    assert!(was, "{name}: one sample per pixel goes sort-last");
                    assert!(
                        bits(&fast) == bits(&tiled),
                        "{name} (cull {cull_backfaces}), {threads} threads: the frames differ"
                    );
                }
            }
        }
    }
}
