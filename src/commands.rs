//! Orchestration behind the CLI subcommands that do more than call one library function. `main.rs`
//! parses arguments into these job structs and maps the `Result` to an exit code; everything that
//! touches meshes, frames or files happens here, so it is testable without a process.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::error::{Error, Result};
use crate::mesh::{self, LoadOptions, Mesh};
use crate::raster::{self, Frame, RenderSettings};
use crate::scene::{Camera, Rig, Scene};

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
}

/// Cameras for every view of `rig`, each framing the mesh's bounding sphere.
pub fn rig_cameras(mesh: &Mesh, rig: &Rig, aspect: f32) -> Vec<Camera> {
    rig.directions()
        .into_iter()
        .map(|d| {
            Camera::frame_sphere(
                mesh.bounding_sphere(),
                d,
                Camera::DEFAULT_FOV_Y_DEG,
                aspect,
                Camera::DEFAULT_MARGIN,
            )
        })
        .collect()
}

fn write_frame(path: &Path, frame: &Frame, exr: bool) -> Result<()> {
    crate::io::write_image(path, &image::DynamicImage::ImageRgb8(frame.to_srgb8()))?;
    if exr {
        crate::io::write_image(
            &path.with_extension("exr"),
            &image::DynamicImage::ImageRgb32F(frame.to_rgb32f()),
        )?;
    }
    Ok(())
}

/// Run a render job; returns the files written.
pub fn render(job: &RenderJob) -> Result<Vec<PathBuf>> {
    let mesh = Arc::new(mesh::load(&job.mesh, &job.load)?);
    let scene = Scene::new(mesh.clone());
    let aspect = job.settings.width as f32 / job.settings.height as f32;
    let cameras = rig_cameras(&mesh, &job.rig, aspect);
    let mut written = Vec::new();
    match &job.views {
        ViewSelection::One { view, out } => {
            let camera = cameras.get(*view).ok_or_else(|| {
                Error::Usage(format!(
                    "--view {view} does not exist: the rig has views 0..{}",
                    cameras.len() - 1
                ))
            })?;
            write_frame(
                out,
                &raster::render(&scene, camera, &job.settings)?,
                job.exr,
            )?;
            written.push(out.clone());
        }
        ViewSelection::All { out_dir } => {
            for (k, camera) in cameras.iter().enumerate() {
                let out = out_dir.join(format!("view-{k:02}.png"));
                write_frame(
                    &out,
                    &raster::render(&scene, camera, &job.settings)?,
                    job.exr,
                )?;
                written.push(out);
            }
        }
        ViewSelection::Sheet { out } => {
            let frames = cameras
                .iter()
                .map(|c| raster::render(&scene, c, &job.settings).map(|f| f.to_srgb8()))
                .collect::<Result<Vec<_>>>()?;
            let columns = (frames.len() as f32).sqrt().ceil() as u32;
            let sheet = raster::contact_sheet(&frames, columns, 4, [32, 32, 32]);
            crate::io::write_image(out, &image::DynamicImage::ImageRgb8(sheet))?;
            written.push(out.clone());
        }
    }
    Ok(written)
}
