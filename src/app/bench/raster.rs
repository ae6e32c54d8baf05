//! `lodeval bench raster`: the rasterizer on a large torus, and the scene export for the llvmpipe
//! side-by-side script.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::error::{Error, Result};
use crate::raster::{self, RenderScene, RenderSettings};
use crate::scene::{Camera, Rig, Scene};

/// A `lodeval bench raster` request.
#[derive(Debug, Clone)]
pub struct RasterBench {
    /// Torus resolution: `rings × sides × 2` triangles (1000 × 500 gives exactly 1 M).
    pub rings: u32,
    /// See `rings`.
    pub sides: u32,
    /// Image edge in pixels.
    pub size: u32,
    /// Views (Fibonacci rig), rendered once each per sample setting.
    pub views: u32,
    /// Sample counts to measure (each a square).
    pub samples: Vec<u32>,
    /// Shading model.
    pub shading: raster::Shading,
    /// Also write the scene (mesh and per-view matrices) here, for rendering the identical scene
    /// with another renderer (`benches/llvmpipe_raster.py`).
    pub export: Option<PathBuf>,
    /// Where the frames are rendered.
    pub backend: crate::backend::Backend,
}

/// One line of the benchmark table.
#[derive(Debug, Clone, serde::Serialize)]
pub struct RasterBenchRow {
    /// Triangles in the mesh.
    pub triangles: usize,
    /// Image edge, pixels.
    pub size: u32,
    /// Samples per pixel.
    pub samples: u32,
    /// Views rendered.
    pub views: u32,
    /// Worker threads.
    pub threads: usize,
    /// Mean milliseconds per frame.
    pub ms_per_frame: f64,
    /// Frames per second.
    pub frames_per_s: f64,
    /// Millions of triangles per second.
    pub mtri_per_s: f64,
    /// The renderer timed (`cpu` or `gpu: ADAPTER …`).
    pub backend: String,
}

/// Render a procedural torus from every view and time it. Timing is for reporting only: nothing
/// asserts on it.
pub fn bench_raster(b: &RasterBench) -> Result<Vec<RasterBenchRow>> {
    let triangles = 2 * b.rings.max(3) as u64 * b.sides.max(3) as u64;
    crate::limits::GENERATED_TRIANGLES
        .check("the benchmark torus (2 × rings × sides):", triangles)
        .map_err(Error::Usage)?;
    crate::limits::VIEWS
        .check("--views", b.views as u64)
        .map_err(Error::Usage)?;
    crate::limits::check_memory(
        &format!("rendering {0}x{0} pixels", b.size),
        (b.size as u64).pow(2) * crate::limits::BYTES_PER_RENDERED_PIXEL,
    )
    .map_err(Error::Usage)?;
    let mesh = Arc::new(crate::mesh::shapes::torus(b.rings, b.sides, 0.35));
    let scene = RenderScene::of(mesh.clone());
    let cameras = Rig::Fibonacci(b.views).cameras(&mesh, 1.0);
    if let Some(dir) = &b.export {
        export_scene(dir, &scene, &cameras)?;
        // View 0 at 1 sample, to compare pictures with the other renderer's.
        let mut one = RenderSettings::DEFAULT;
        (one.width, one.height, one.shading) = (b.size, b.size, b.shading);
        one.samples = raster::SamplePattern::Ordered(1);
        crate::app::render::write_frame(
            &dir.join("lodeval-view0.png"),
            &raster::render(&scene, &cameras[0], &one)?,
            false,
        )?;
    }
    let engine = crate::backend::Engine::new(b.backend)?;
    let timed = engine.scene(&scene)?;
    let mut rows = Vec::new();
    for &samples in &b.samples {
        let n = raster::SamplePattern::side_for(samples).ok_or_else(|| {
            Error::Usage(format!(
                "--samples {samples}: use 1, 4, 9, 16, 25, 36, 49 or 64 samples per pixel"
            ))
        })?;
        let mut settings = RenderSettings::DEFAULT;
        settings.width = b.size;
        settings.height = b.size;
        settings.shading = b.shading;
        settings.samples = raster::SamplePattern::Rotated(n);
        // Warm-up frame (page faults, allocator), not timed.
        timed.render(&cameras[0], &settings)?;
        let start = std::time::Instant::now();
        for c in &cameras {
            std::hint::black_box(timed.render(c, &settings)?);
        }
        let secs = start.elapsed().as_secs_f64() / cameras.len() as f64;
        rows.push(RasterBenchRow {
            triangles: mesh.triangle_count(),
            size: b.size,
            samples: n * n,
            views: b.views,
            threads: rayon::current_num_threads(),
            ms_per_frame: secs * 1e3,
            frames_per_s: 1.0 / secs,
            mtri_per_s: mesh.triangle_count() as f64 / secs / 1e6,
            backend: engine.describe(),
        });
    }
    Ok(rows)
}

/// The rows of `lodeval bench raster` as a Markdown table.
pub fn raster_bench_table(rows: &[RasterBenchRow]) -> String {
    let mut text = String::from(
        "| triangles | size | samples | views | threads | ms/frame | frames/s | Mtri/s | backend |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        text.push_str(&format!(
            "| {} | {} | {} | {} | {} | {:.1} | {:.2} | {:.1} | {} |\n",
            r.triangles,
            r.size,
            r.samples,
            r.views,
            r.threads,
            r.ms_per_frame,
            r.frames_per_s,
            r.mtri_per_s,
            r.backend
        ));
    }
    text
}

/// Write a scene as raw little-endian arrays plus a JSON list of views: `positions.f32`,
/// `normals.f32` (xyz per vertex), `indices.u32` (three per triangle) and `views.json` with each
/// view's column-major model-view-projection matrix (depth 0..1), unit light direction, light
/// colour, direction towards the eye, ambient term and the material's Blinn–Phong parameters.
pub fn export_scene(dir: &Path, scene: &Scene, cameras: &[Camera]) -> Result<()> {
    let mesh = scene.mesh();
    let floats = |v: &[glam::Vec3]| {
        v.iter()
            .flat_map(|p| p.to_array())
            .flat_map(f32::to_le_bytes)
            .collect::<Vec<u8>>()
    };
    crate::io::write_atomic(&dir.join("positions.f32"), &floats(mesh.positions()))?;
    crate::io::write_atomic(&dir.join("normals.f32"), &floats(mesh.normals()))?;
    let idx: Vec<u8> = mesh
        .triangles()
        .iter()
        .flatten()
        .flat_map(|i| i.to_le_bytes())
        .collect();
    crate::io::write_atomic(&dir.join("indices.u32"), &idx)?;
    let m = &mesh.materials()[0];
    let views: Vec<serde_json::Value> = cameras
        .iter()
        .map(|c| {
            let mvp = c.projection(1.0) * c.view();
            let (l, color) = scene.lights_for(false)[0]
                .resolve(c)
                .expect("the bench scene's light is the headlight");
            serde_json::json!({
                "mvp": mvp.to_cols_array(),
                "eye": c.eye.to_array(),
                "metallic": m.metallic,
                "roughness": m.roughness,
                "light_dir": l.to_array(),
                "light_color": color.to_array(),
                "to_eye": c.to_eye().to_array(),
                "ambient": scene.ambient,
                "base_color": m.base_color.to_array(),
                "specular": m.specular.to_array(),
                "shininess": m.shininess,
                "background": scene.background.to_array(),
            })
        })
        .collect();
    let json = serde_json::to_string_pretty(&views).map_err(|e| Error::Internal(e.to_string()))?;
    crate::io::write_atomic(&dir.join("views.json"), json.as_bytes())?;
    export_ibl(dir, scene)
}

/// The `pbr` model's prepared environment for the peer: each prefiltered level and the irradiance
/// map as raw little-endian RGB f32 (`ibl-N.f32`, row 0 at the top), the BRDF table as RG f32
/// (`brdf.f32`), and their sizes in `ibl.json`.
fn export_ibl(dir: &Path, scene: &Scene) -> Result<()> {
    let ibl = crate::raster::ibl::prepared(&scene.environment);
    let mut maps = Vec::new();
    for (k, m) in ibl.levels.iter().chain([&ibl.irradiance]).enumerate() {
        let bytes: Vec<u8> = m
            .texels()
            .iter()
            .flat_map(|t| t.to_array())
            .flat_map(f32::to_le_bytes)
            .collect();
        crate::io::write_atomic(&dir.join(format!("ibl-{k}.f32")), &bytes)?;
        maps.push([m.width(), m.height()]);
    }
    let lut: Vec<u8> = crate::raster::ibl::BrdfLut::get()
        .entries()
        .iter()
        .flat_map(|e| e.to_array())
        .flat_map(f32::to_le_bytes)
        .collect();
    crate::io::write_atomic(&dir.join("brdf.f32"), &lut)?;
    let json = serde_json::json!({
        "levels": crate::raster::ibl::LEVELS,
        "maps": maps,
        "lut_size": crate::raster::ibl::LUT_SIZE,
    });
    crate::io::write_atomic(&dir.join("ibl.json"), json.to_string().as_bytes())
}
