//! The deterministic, multi-threaded CPU rasterizer: lodeval's reference renderer.
//!
//! `render` reads as the pipeline, one stage per file:
//! 1. `setup.rs` — transform vertices, clip (`clip.rs`), project and snap to fixed point
//!    (`fixed.rs`), orient every triangle; parallel over fixed chunks, concatenated in order.
//! 2. `bin.rs` — bin set-up triangles into 64×64-pixel tiles, each list in triangle order.
//! 3. `edge.rs` — per tile, in parallel: scan-convert its triangles into per-sample depth and
//!    triangle-id buffers (a visibility buffer) with integer edge functions and the top-left rule;
//!    small triangles at 4 samples per pixel in 32-bit vector lanes.
//!
//! `pass.rs` holds one frame's set-up state (stages 1–3 run from it); `render` below calls
//! the stages in this order.
//! 4. `resolve.rs` — per pixel: shade (`shade.rs`, textures from `texture.rs`) once per distinct
//!    triangle among its samples, at that triangle's first covered sample, and average the samples in
//!    linear light.
//!
//! At one sample per pixel (within a memory budget) stages 2 and 3 are replaced by
//! `sort_last.rs`: each worker scans its chunks right after setting them up, into its own
//! full-frame buffer of (depth, id) keys, and each tile takes the smallest key per pixel over the
//! workers' buffers before its resolve. Same frames as the tiled path (tested), for any thread
//! count.
//!
//! Frames' channel buffers are reused from one render to the next (`recycle.rs`); every pixel is
//! written by exactly one tile, so a reused buffer's old contents never show.
//!
//! Rules: every tile owns its pixels and processes triangles in index order with a strict
//! depth test (ties keep the earlier triangle), and no reduction depends on completion order, so
//! frames are byte-identical for any thread count. Shading once per pixel per triangle (rather
//! than per sample) is the MSAA trade-off: visibility and edges are supersampled, while texture
//! aliasing is handled by mip-mapping; it costs ¼ of per-sample shading at 4 samples per pixel.

mod bin;
mod clip;

mod edge;
mod fixed;
mod frame;
pub mod ibl;
#[doc(hidden)] // Williams et al.'s per-frame renderer, public for tests and benches
pub mod incremental;
mod pass;
mod pbr;

mod prepare;
mod recycle;
mod resolve;
mod scene;
mod setup;
pub(crate) mod shade;
mod sort_last;
mod texture;
pub mod texture_space;
mod tonemap;

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::scene::{Camera, Projection};

pub use frame::{Frame, NO_TRIANGLE};
use pass::{Pass, Visibility};
#[cfg(feature = "gpu")]
pub(crate) use pbr::PbrLight;
pub use prepare::PreparedMesh;
#[cfg(feature = "gpu")]
pub(crate) use prepare::PreparedSlot;
pub use scene::RenderScene;
#[cfg(feature = "gpu")]
pub(crate) use shade::ResolvedLight;
pub use texture::MipTexture;
pub use texture_space::{TextureSpace, texture_space};
pub use tonemap::{DisplayTransform, ToneMapping};

/// Shading models, by the names a config or the CLI uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Shading {
    /// Base colour × vertex colour × texture, no lighting.
    Unlit,
    /// Per-vertex Blinn–Phong, interpolated (OpenGL fixed function; Williams et al. 2003).
    Gouraud,
    /// Per-sample Blinn–Phong with the interpolated normal.
    Phong,
    /// Per-sample Blinn–Phong with a tangent-space normal map (Phong where a material has none).
    NormalMapped,
    /// Debug: world normal mapped to colour (n·½ + ½).
    Normals,
    /// Debug: linear depth, white near, black far.
    Depth,
    /// glTF 2.0 metallic–roughness under image-based lighting and punctual lights (`pbr.rs`).
    Pbr,
    /// `Pbr` for meshes with a metallic–roughness material (glTF; MTL with PBR keys), `Gouraud`
    /// otherwise ([`Shading::resolve`]).
    Auto,
}

impl Shading {
    /// All models, in the order the CLI lists them.
    pub const ALL: [Shading; 8] = [
        Shading::Auto,
        Shading::Pbr,
        Shading::Unlit,
        Shading::Gouraud,
        Shading::Phong,
        Shading::NormalMapped,
        Shading::Normals,
        Shading::Depth,
    ];
    /// The config/CLI name.
    pub fn name(self) -> &'static str {
        match self {
            Shading::Unlit => "unlit",
            Shading::Gouraud => "gouraud",
            Shading::Phong => "phong",
            Shading::NormalMapped => "normal-mapped",
            Shading::Normals => "normals",
            Shading::Depth => "depth",
            Shading::Pbr => "pbr",
            Shading::Auto => "auto",
        }
    }

    /// The model `Auto` stands for on `mesh` (any other model is itself).
    pub fn resolve(self, mesh: &Mesh) -> Shading {
        match self {
            Shading::Auto if mesh.prefers_pbr() => Shading::Pbr,
            Shading::Auto => Shading::Gouraud,
            s => s,
        }
    }

    /// The tone mapper this model uses when none is set: Khronos PBR Neutral for `pbr`, `linear`
    /// (a clamp) for the others.
    pub fn default_tone_mapping(self) -> ToneMapping {
        if self == Shading::Pbr {
            ToneMapping::PbrNeutral
        } else {
            ToneMapping::Linear
        }
    }
    /// Parse a config/CLI name.
    pub fn parse(name: &str) -> Option<Shading> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }
}

/// Sample positions within a pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum SamplePattern {
    /// n × n samples on a regular grid (n² samples).
    Ordered(u32),
    /// n × n samples on a rotated ("n-rooks") grid: every sample has its own row and column, which
    /// resolves near-horizontal and near-vertical edges into n² levels instead of n.
    Rotated(u32),
}

impl SamplePattern {
    /// Largest grid side n (n × n = 64 samples per pixel).
    pub const MAX_SIDE: u32 = 8;

    /// The grid side n of `samples` per pixel: `Some(n)` when samples = n² with 1 ≤ n ≤
    /// [`MAX_SIDE`](Self::MAX_SIDE). The one place the square-sample rule is checked.
    pub fn side_for(samples: u32) -> Option<u32> {
        (1..=Self::MAX_SIDE).find(|n| n * n == samples)
    }

    /// Samples per pixel.
    pub fn count(self) -> usize {
        let n = match self {
            SamplePattern::Ordered(n) | SamplePattern::Rotated(n) => n as usize,
        };
        n * n
    }

    /// Sample offsets within the pixel, in Fx24_8 units (0..256), in sample order.
    pub(crate) fn offsets(self) -> Vec<[i64; 2]> {
        let to_fx = |v: f64| (v * fixed::ONE_PIXEL as f64).round() as i64;
        match self {
            SamplePattern::Ordered(n) => {
                let n = n as usize;
                (0..n * n)
                    .map(|k| {
                        let (i, j) = (k % n, k / n);
                        [
                            to_fx((i as f64 + 0.5) / n as f64),
                            to_fx((j as f64 + 0.5) / n as f64),
                        ]
                    })
                    .collect()
            }
            SamplePattern::Rotated(n) => {
                let nf = n as f64;
                let n = n as usize;
                (0..n * n)
                    .map(|k| {
                        let (i, j) = ((k / n) as f64, (k % n) as f64);
                        let x = (i + (j + 0.5) / nf) / nf;
                        let y = (j + (nf - 1.0 - i + 0.5) / nf) / nf;
                        [to_fx(x), to_fx(y)]
                    })
                    .collect()
            }
        }
    }
}

/// How to render.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct RenderSettings {
    /// Image width in pixels. Default value: 512.
    pub width: u32,
    /// Image height in pixels. Default value: 512.
    pub height: u32,
    /// Anti-aliasing samples. Default value: `Rotated(2)` (4 samples per pixel).
    pub samples: SamplePattern,
    /// Shading model. Default value: `Auto`.
    pub shading: Shading,
    /// Skip triangles facing away from the camera. Default value: false (flipped LOD triangles
    /// must show up).
    pub cull_backfaces: bool,
    /// Exposure in stops (radiance × 2^exposure before tone mapping). Default value: 0.
    pub exposure: f32,
    /// Tone mapper; `None` = the shading model's ([`Shading::default_tone_mapping`]). Default
    /// value: `None`.
    pub tone_mapping: Option<ToneMapping>,
    /// The `pbr` model's multiple-scattering energy compensation (Fdez-Agüera 2019). Default
    /// value: true.
    pub multiple_scattering: bool,
}

impl RenderSettings {
    /// The defaults.
    pub const DEFAULT: RenderSettings = RenderSettings {
        width: 512,
        height: 512,
        samples: SamplePattern::Rotated(2),
        shading: Shading::Auto,
        cull_backfaces: false,
        exposure: 0.0,
        tone_mapping: None,
        multiple_scattering: true,
    };
    /// Largest accepted image edge, pixels ([`crate::limits::IMAGE_SIDE`]).
    pub const MAX_SIZE: u32 = crate::limits::IMAGE_SIDE.max as u32;

    /// Exposure and the tone mapper (the shading model's where none is set).
    pub fn display(&self) -> DisplayTransform {
        DisplayTransform {
            scale: self.exposure.exp2(),
            tone_mapping: self
                .tone_mapping
                .unwrap_or(self.shading.default_tone_mapping()),
        }
    }

    pub(crate) fn check(&self) -> Result<()> {
        if self.width == 0
            || self.height == 0
            || self.width > Self::MAX_SIZE
            || self.height > Self::MAX_SIZE
        {
            return Err(Error::Usage(format!(
                "image size {}x{} is outside 1..{} pixels per side",
                self.width,
                self.height,
                Self::MAX_SIZE
            )));
        }
        let n = match self.samples {
            SamplePattern::Ordered(n) | SamplePattern::Rotated(n) => n,
        };
        if let Some(e) = crate::limits::EXPOSURE_STOPS.refuse(self.exposure as f64) {
            return Err(Error::Usage(format!("exposure {e}")));
        }
        if SamplePattern::side_for(n.saturating_mul(n)) != Some(n) {
            return Err(Error::Usage(format!(
                "{} samples per pixel: use 1, 4, 9, ..., 64 (n×n with n ≤ 8)",
                n.saturating_mul(n)
            )));
        }
        Ok(())
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Render `scene` from `camera`: the pipeline of the module comment, stage by stage.
pub fn render(scene: &RenderScene, camera: &Camera, settings: &RenderSettings) -> Result<Frame> {
    settings.check()?;
    // Stages 1 and 2: transform, clip and set up every triangle, and bin it into tiles (or, at
    // one sample per pixel, scan it into the workers' key buffers there and then).
    let pass = Pass::new(scene, camera, settings, Visibility::Fastest);
    let shading = pass.context(None);
    Ok(draw(&pass, &shading))
}

/// Stages 3 and 4, per tile in parallel, each straight into its pixels of a recycled frame:
/// scan-convert the tile's triangles into samples, then resolve its samples into pixels.
fn draw(pass: &Pass, shading: &shade::ShadeContext) -> Frame {
    let (w, h) = (pass.settings.width, pass.settings.height);
    let mut frame = Frame::recycled(w, h);
    let tiles = resolve::frame_tiles(&mut frame, bin::TILE as usize);
    debug_assert_eq!(tiles.len(), bin::tile_count(w, h));
    tiles
        .into_par_iter()
        .enumerate()
        .for_each(|(t, mut pixels)| pass.resolve(shading, &pass.raster_tile(t), &mut pixels));
    frame
}

/// Diagnostic: for every sample, how many triangles cover it (no depth test). A closed mesh seen
/// from outside covers every interior sample an even number of times (front and back), an open
/// surface seen whole exactly once; with back faces culled a closed mesh covers each sample at most once.
/// Returned row-major per pixel, `samples.count()` entries per pixel.
pub fn coverage_counts(
    scene: &RenderScene,
    camera: &Camera,
    settings: &RenderSettings,
) -> Result<Vec<u16>> {
    settings.check()?;
    let pass = Pass::new(scene, camera, settings, Visibility::Counts);
    Ok(pass.counts())
}

/// The smallest pixel rectangle `[x0, y0, x1, y1)` holding `a` (if any) and `b`.
pub(crate) fn rect_union(a: Option<[i32; 4]>, b: [i32; 4]) -> [i32; 4] {
    match a {
        None => b,
        Some(a) => [
            a[0].min(b[0]),
            a[1].min(b[1]),
            a[2].max(b[2]),
            a[3].max(b[3]),
        ],
    }
}

/// Camera matrices and depth range for a frame of the given size.
pub(crate) fn camera_setup(
    camera: &Camera,
    width: u32,
    height: u32,
) -> (glam::Mat4, (f32, f32, bool)) {
    let aspect = width as f32 / height as f32;
    let mvp = camera.projection(aspect) * camera.view();
    let perspective = matches!(camera.projection, Projection::Perspective { .. });
    (mvp, (camera.near, camera.far, perspective))
}

/// Run `f` in a dedicated pool of `threads` workers (for determinism tests and `--threads`).
pub fn with_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> Result<T> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::Internal(format!("cannot start {threads} threads: {e}")))?;
    Ok(pool.install(f))
}

/// Compute the per-vertex light terms for Gouraud shading.
fn vertex_lighting(ctx: &shade::ShadeContext) -> Vec<(glam::Vec3, glam::Vec3)> {
    let mesh = ctx.mesh;
    let materials = mesh.materials();
    mesh.normals()
        .par_iter()
        .enumerate()
        .with_min_len(4096)
        .map(|(v, &n)| {
            let m = &materials[ctx.prepared.vertex_material[v] as usize];
            shade::light_terms(n, &ctx.lights, ctx.ambient, m.specular, m.shininess)
        })
        .collect()
}

/// A xorshift64 generator from `seed` (non-zero), for the raster tests' reproducible random cases.
#[cfg(test)]
pub(crate) fn xorshift(mut seed: u64) -> impl FnMut() -> u64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    }
}
