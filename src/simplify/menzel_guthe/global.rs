//! §4.4, global masking: how much the rest of the model's appearance masks a difference at a
//! vertex — from renders of the original over the sphere of view and light directions, each
//! turned into JND-scaled opponent responses and decomposed into frequency bands, the largest
//! local band amplitude at the vertex over the images where it is visible, per band.
//!
//! Based on: Menzel & Guthe 2010, §4.4 ("the object is rendered from different view and lighting
//! positions distributed over the unit sphere ... for each I_k the color space conversion to
//! JND-scaled space is applied ... if a vertex is visible, the maximum local amplitude of all
//! receptive field directions is calculated for each frequency band f. Finally, the maximum
//! amplitude over all images is computed and stored as global masking a_g(f) for the vertex").
//!
//! Decisions:
//! - The renders: the 12 icosahedron views, orthographic (so a pixel spans the same surface
//!   length everywhere), each lit once by a headlight and once by a light 60° off the view; 256²
//!   pixels, one sample, the lighting of the reflectance fields (`field::Lighting`).
//! - The bands are the VDP's Laplacian pyramid (`metric::vdp::bands`), which has no orientation
//!   channels: its band magnitude (the 3 × 3 mean of |band|, the VDP's masker) already pools the
//!   receptive-field directions the paper takes the maximum over.
//! - A band's frequency, ρ_k = 0.375/2^k cycles per pixel, is stored as a surface frequency:
//!   ρ_k divided by the pixel's length in model units, in octave bins. a_g(f) at a point of the
//!   original is the largest of its triangle's corners' values in f's bin.
//! - Visibility: the vertex's depth is within two pixels' lengths of the depth buffer's there.

use std::sync::Arc;

use glam::{Vec3, Vec4Swizzles};
use rayon::prelude::*;

use super::field::Lighting;
use super::response::Response;
use crate::mesh::Mesh;
use crate::metric::vdp::bands::{Plane, laplacian};
use crate::metric::vdp::masking::local_magnitude;
use crate::raster::{self, RenderScene, RenderSettings, SamplePattern, Shading};
use crate::scene::{Camera, Light, Rig, Scene};

/// Octave bins of surface frequency.
const BINS: usize = 24;
/// Render size, pixels.
const SIZE: u32 = 256;

/// Per welded vertex and channel, the largest band amplitude (JND) in each frequency bin.
#[derive(Debug, Clone)]
pub struct GlobalMasking {
    /// Surface frequency of bin 0's lower edge, cycles per model unit.
    f0: f32,
    amplitudes: Vec<[[f32; BINS]; 3]>,
    /// Welded vertices of each triangle of the mesh.
    corners: Vec<[u32; 3]>,
}

impl GlobalMasking {
    /// None: every a_g is 0.
    pub fn none() -> GlobalMasking {
        GlobalMasking {
            f0: 1.0,
            amplitudes: Vec::new(),
            corners: Vec::new(),
        }
    }

    /// Render `mesh` and measure its masking.
    pub fn measure(mesh: &Arc<Mesh>, lighting: &Lighting, response: &Response) -> GlobalMasking {
        let weld = mesh.weld();
        let corners: Vec<[u32; 3]> = mesh
            .triangles()
            .iter()
            .map(|t| t.map(|v| weld[v as usize]))
            .collect();
        let nv = mesh.welded_vertex_count();
        let mut positions = vec![Vec3::ZERO; nv];
        for (v, &w) in weld.iter().enumerate() {
            positions[w as usize] = mesh.positions()[v];
        }
        let sphere = mesh.bounding_sphere();
        let f0 = 1.0 / (8.0 * sphere.radius.max(f32::MIN_POSITIVE));
        let mut settings = RenderSettings::DEFAULT;
        settings.width = SIZE;
        settings.height = SIZE;
        settings.samples = SamplePattern::Rotated(1);
        settings.shading = Shading::Phong;
        let views: Vec<(Camera, Light)> = Rig::Icosahedron
            .directions()
            .into_iter()
            .flat_map(|d| {
                let camera = Camera::frame_sphere_ortho(sphere, d, 1.0, 0.05);
                let right = camera.up.cross(d).normalize_or(Vec3::X);
                let off = (d * 0.5 + right * 0.866).normalize_or(d);
                [
                    (
                        camera,
                        Light::Directional {
                            direction: d,
                            color: lighting.color,
                        },
                    ),
                    (
                        camera,
                        Light::Directional {
                            direction: off,
                            color: lighting.color,
                        },
                    ),
                ]
            })
            .collect();
        // Each image's per-vertex band amplitudes, then the maximum over images in view order.
        let per_image: Vec<Vec<(u32, [[f32; BINS]; 3])>> = views
            .par_iter()
            .map(|(camera, light)| {
                let mut scene = Scene::new(mesh.clone());
                scene.lights = Some(vec![*light]);
                scene.ambient = lighting.ambient;
                let scene = RenderScene::new(scene);
                let Ok(frame) = raster::render(&scene, camera, &settings) else {
                    return Vec::new();
                };
                image_amplitudes(&frame, camera, &positions, f0, response)
            })
            .collect();
        let mut amplitudes = vec![[[0.0f32; BINS]; 3]; nv];
        for image in per_image {
            for (v, a) in image {
                for c in 0..3 {
                    for b in 0..BINS {
                        let slot = &mut amplitudes[v as usize][c][b];
                        *slot = slot.max(a[c][b]);
                    }
                }
            }
        }
        GlobalMasking {
            f0,
            amplitudes,
            corners,
        }
    }

    /// a_g of channel `c` at surface frequency `f` on triangle `t` of the original.
    pub fn at(&self, t: u32, c: usize, f: f32) -> f32 {
        if self.amplitudes.is_empty() || f <= 0.0 {
            return 0.0;
        }
        let bin = (f / self.f0).log2().floor();
        if !(0.0..BINS as f32).contains(&bin) {
            return 0.0;
        }
        self.corners[t as usize]
            .iter()
            .map(|&v| self.amplitudes[v as usize][c][bin as usize])
            .fold(0.0, f32::max)
    }
}

/// The band amplitudes at every vertex visible in `frame`, binned by surface frequency.
fn image_amplitudes(
    frame: &raster::Frame,
    camera: &Camera,
    positions: &[Vec3],
    f0: f32,
    response: &Response,
) -> Vec<(u32, [[f32; BINS]; 3])> {
    let (w, h) = (frame.width() as usize, frame.height() as usize);
    let half = match camera.projection {
        crate::scene::Projection::Orthographic { half_height } => half_height,
        crate::scene::Projection::Perspective { .. } => return Vec::new(),
    };
    let footprint = 2.0 * half / h as f32;
    // The opponent channels' bands and their local magnitudes.
    let mut channels: Vec<Vec<Plane>> = Vec::with_capacity(3);
    let opponent: Vec<Vec3> = frame
        .color()
        .iter()
        .map(|&c| response.opponent(c))
        .collect();
    for c in 0..3 {
        let plane = Plane {
            w,
            h,
            v: opponent.iter().map(|o| o[c]).collect(),
        };
        let (bands, _) = laplacian(&plane, 16);
        channels.push(
            bands
                .into_iter()
                .map(|b| Plane {
                    v: local_magnitude(&b.v, b.w, b.h),
                    ..b
                })
                .collect(),
        );
    }
    let clip = camera.projection(1.0) * camera.view();
    let depth_tolerance = 2.0 * footprint / (camera.far - camera.near);
    let mut out = Vec::new();
    for (v, &p) in positions.iter().enumerate() {
        let q = clip * p.extend(1.0);
        let ndc = q.xyz() / q.w;
        let (x, y) = (
            (ndc.x + 1.0) * 0.5 * w as f32,
            (1.0 - ndc.y) * 0.5 * h as f32,
        );
        if !(x >= 0.0 && y >= 0.0 && (x as usize) < w && (y as usize) < h) {
            continue;
        }
        let (px, py) = (x as usize, y as usize);
        let d = frame.depth()[py * w + px];
        if !(d.is_finite() && (ndc.z - d).abs() <= depth_tolerance) {
            continue;
        }
        let mut a = [[0.0f32; BINS]; 3];
        for (c, bands) in channels.iter().enumerate() {
            for (k, band) in bands.iter().enumerate() {
                let (bx, by) = ((px >> k).min(band.w - 1), (py >> k).min(band.h - 1));
                let f = 0.375 / (1 << k) as f32 / footprint;
                let bin = (f / f0).log2().floor();
                if (0.0..BINS as f32).contains(&bin) {
                    let slot = &mut a[c][bin as usize];
                    *slot = slot.max(band.v[by * band.w + bx]);
                }
            }
        }
        out.push((v as u32, a));
    }
    out
}
