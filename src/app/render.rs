//! `lodeval render`: a mesh framed by its bounding sphere from one view, every view, or a contact
//! sheet of all views, as PNG (and linear EXR).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::error::{Error, Result};
use crate::mesh::{self, LoadOptions};
use crate::raster::{Frame, RenderScene, RenderSettings};
use crate::scene::Rig;

/// Which views `lodeval render` writes.
#[derive(Debug, Clone, PartialEq)]
pub enum ViewSelection {
    /// One view, by number, to one file.
    One {
        /// View number within the rig.
        view: usize,
        /// Output PNG.
        out: PathBuf,
    },
    /// Every view of the rig into a folder as `view-NN.png`.
    All {
        /// Output folder.
        out_dir: PathBuf,
    },
    /// Every view of the rig tiled into one contact-sheet PNG.
    Sheet {
        /// Output PNG.
        out: PathBuf,
    },
}

/// A `lodeval render` request.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct RenderJob {
    /// Mesh file.
    pub mesh: PathBuf,
    /// Loader options.
    pub load: LoadOptions,
    /// Render settings (size, samples, shading, culling).
    pub settings: RenderSettings,
    /// View rig.
    pub rig: Rig,
    /// Views and outputs.
    pub views: ViewSelection,
    /// Also write linear float EXR files beside each PNG.
    pub exr: bool,
    /// Where to render.
    pub backend: crate::backend::Backend,
    /// The `pbr` model's image-based lighting.
    pub lighting: crate::scene::Lighting,
    /// Also write every view's camera here as JSON (eye, target, up, vertical field of view,
    /// near, far), to set the same view up in another renderer.
    pub cameras_json: Option<PathBuf>,
    /// Frame the views by this mesh's bounding sphere instead of the rendered mesh's own, so a
    /// LOD's renders line up pixel for pixel with its original's (`--frame-like ORIGINAL`).
    pub frame_like: Option<PathBuf>,
}

impl RenderJob {
    /// `views` of `mesh`: default loading, settings and lighting, the dodecahedron rig, PNG, the
    /// CPU reference, no cameras file.
    pub fn new(mesh: PathBuf, views: ViewSelection) -> RenderJob {
        RenderJob {
            mesh,
            load: LoadOptions::DEFAULT,
            settings: RenderSettings::DEFAULT,
            rig: Rig::Dodecahedron,
            views,
            exr: false,
            backend: crate::backend::Backend::Cpu,
            lighting: crate::scene::Lighting::default(),
            cameras_json: None,
            frame_like: None,
        }
    }
}

/// One camera as `--cameras` writes it.
#[derive(Debug, Clone, serde::Serialize)]
struct CameraJson {
    view: usize,
    eye: [f32; 3],
    target: [f32; 3],
    up: [f32; 3],
    /// Vertical field of view, degrees (`null` for an orthographic camera).
    fov_y_deg: Option<f32>,
    near: f32,
    far: f32,
}

pub(crate) fn write_frame(path: &Path, frame: &Frame, exr: bool) -> Result<()> {
    crate::io::write_image(path, &image::DynamicImage::ImageRgb8(frame.to_srgb8()))?;
    if exr {
        crate::io::write_image(
            &path.with_extension("exr"),
            &image::DynamicImage::ImageRgb32F(frame.to_rgb32f()),
        )?;
    }
    Ok(())
}

/// What a render job did.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderReport {
    /// The files written, in order.
    pub written: Vec<PathBuf>,
    /// What the user should know: the mesh's load warnings (`--missing-assets warn`) and why
    /// `--backend auto` rendered on the CPU.
    pub warnings: Vec<String>,
}

/// Run a render job.
pub fn render(job: &RenderJob) -> Result<RenderReport> {
    let (w, h) = (job.settings.width as u64, job.settings.height as u64);
    crate::limits::check_memory(
        &format!("rendering {w}x{h} pixels"),
        w * h * crate::limits::BYTES_PER_RENDERED_PIXEL,
    )
    .map_err(Error::Usage)?;
    let mesh = Arc::new(mesh::load(&job.mesh, &job.load)?);
    let mut scene = RenderScene::of(mesh.clone());
    scene.light_with(&job.lighting);
    let aspect = job.settings.width as f32 / job.settings.height as f32;
    let like = match &job.frame_like {
        Some(path) => Some(mesh::load(path, &job.load)?),
        None => None,
    };
    let cameras = match &like {
        Some(like) => job.rig.cameras_framing(like.bounding_sphere(), aspect),
        None => job.rig.cameras(&mesh, aspect),
    };
    let engine = crate::backend::Engine::new(job.backend)?;
    let renderer = engine.scene(&scene)?;
    let warnings = mesh
        .warnings()
        .iter()
        .map(|w| format!("{}: {w}", job.mesh.display()))
        .chain(engine.fallback().map(str::to_string))
        .collect();
    // No output may replace a file the mesh was read from (a texture named as -o, say).
    let pngs: Vec<PathBuf> = match &job.views {
        ViewSelection::One { out, .. } | ViewSelection::Sheet { out } => vec![out.clone()],
        ViewSelection::All { out_dir } => (0..cameras.len())
            .map(|k| out_dir.join(format!("view-{k:02}.png")))
            .collect(),
    };
    let mut outputs: Vec<PathBuf> = pngs
        .iter()
        .flat_map(|p| std::iter::once(p.clone()).chain(job.exr.then(|| p.with_extension("exr"))))
        .collect();
    outputs.extend(job.cameras_json.clone());
    let mut inputs = mesh.source().files.clone();
    inputs.extend(like.iter().flat_map(|m| m.source().files.iter().cloned()));
    crate::io::check_not_inputs(&outputs, &inputs)?;
    let mut written = Vec::new();
    if let Some(path) = &job.cameras_json {
        let json: Vec<CameraJson> = cameras
            .iter()
            .enumerate()
            .map(|(view, c)| CameraJson {
                view,
                eye: c.eye.to_array(),
                target: c.target.to_array(),
                up: c.up.to_array(),
                fov_y_deg: match c.projection {
                    crate::scene::Projection::Perspective { fov_y_deg } => Some(fov_y_deg),
                    _ => None,
                },
                near: c.near,
                far: c.far,
            })
            .collect();
        let text = serde_json::to_vec_pretty(&json)
            .map_err(|e| Error::Internal(format!("cameras as JSON: {e}")))?;
        crate::io::write_atomic(path, &text)?;
        written.push(path.clone());
    }
    match &job.views {
        ViewSelection::One { view, out } => {
            let camera = cameras.get(*view).ok_or_else(|| {
                Error::Usage(format!(
                    "--view {view} does not exist: the rig has views 0..{}",
                    cameras.len() - 1
                ))
            })?;
            write_frame(out, &renderer.render(camera, &job.settings)?, job.exr)?;
            written.push(out.clone());
        }
        ViewSelection::All { out_dir } => {
            for (k, camera) in cameras.iter().enumerate() {
                let out = out_dir.join(format!("view-{k:02}.png"));
                write_frame(&out, &renderer.render(camera, &job.settings)?, job.exr)?;
                written.push(out);
            }
        }
        ViewSelection::Sheet { out } => {
            let (n, side) = (cameras.len() as u64, job.settings.width as u64);
            let columns = (n as f64).sqrt().ceil() as u64;
            crate::io::sheet::check_sheet(n, columns, (side, job.settings.height as u64), 4)?;
            let frames = cameras
                .iter()
                .map(|c| renderer.render(c, &job.settings).map(|f| f.to_srgb8()))
                .collect::<Result<Vec<_>>>()?;
            let sheet = crate::io::sheet::contact_sheet(&frames, columns as u32, 4, [32, 32, 32])?;
            crate::io::write_image(out, &image::DynamicImage::ImageRgb8(sheet))?;
            written.push(out.clone());
        }
    }
    Ok(RenderReport { written, warnings })
}
