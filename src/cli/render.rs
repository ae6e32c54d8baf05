//! `lodeval render MESH`: one view, every view, or a contact sheet, with the CPU rasterizer (or
//! the GPU mirror).

use std::path::PathBuf;

use clap::Args;
use lodeval::Error;
use lodeval::app::{RenderJob, ViewSelection};
use lodeval::backend::Backend;
use lodeval::raster::{RenderSettings, Shading};
use lodeval::scene::Rig;

use super::args::{
    LoadArgs, LookArgs, PatternArg, count, parse_rig, parse_samples, parse_shading, side,
};
use super::print::warnings;

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  lodeval render reference/models/spot/spot_mtl.obj -o spot.png --view 3\n  lodeval render spot.obj --sheet -o sheet.png --size 256\n  lodeval render spot-lod1.obj --frame-like spot.obj -o lod1.png   (aligned with spot's render, for diff)\n\nExit codes: 0 written · 2 bad input or usage · 3 internal error"
)]
pub(crate) struct RenderArgs {
    /// The mesh file.
    pub(crate) mesh: PathBuf,
    /// Output PNG (one view, or the contact sheet with --sheet).
    #[arg(short, long, required_unless_present = "all_views")]
    pub(crate) out: Option<PathBuf>,
    /// Image width and height in pixels.
    #[arg(long, default_value_t = 512, value_parser = count::<u32>(&lodeval::limits::IMAGE_SIDE))]
    pub(crate) size: u32,
    /// View rig: dodecahedron (20 views), icosahedron (12) or fibonacci:N.
    #[arg(long, default_value = "dodecahedron", value_parser = parse_rig)]
    pub(crate) rig: Rig,
    /// Which view of the rig to render.
    #[arg(long, default_value_t = 0, conflicts_with_all = ["all_views", "sheet"])]
    pub(crate) view: usize,
    /// Render every view of the rig into --out-dir as view-NN.png.
    #[arg(long, requires = "out_dir", conflicts_with = "sheet")]
    pub(crate) all_views: bool,
    /// Folder for --all-views.
    #[arg(long)]
    pub(crate) out_dir: Option<PathBuf>,
    /// Write every view as one contact sheet (a grid) to --out.
    #[arg(long)]
    pub(crate) sheet: bool,
    /// Shading model: auto (pbr for metallic–roughness materials, gouraud otherwise), pbr,
    /// unlit, gouraud, phong, normal-mapped, normals, depth.
    #[arg(long, default_value = "auto", value_parser = parse_shading)]
    pub(crate) shading: Shading,
    /// Samples per pixel (a square: 1, 4, 9, ..., 64).
    #[arg(long, default_value = "4", value_parser = parse_samples)]
    pub(crate) samples: u32,
    /// Sample grid: rotated or ordered.
    #[arg(long, value_enum, default_value_t = PatternArg::Rotated)]
    pub(crate) pattern: PatternArg,
    /// Skip back-facing triangles (off by default, so flipped LOD triangles show).
    #[arg(long)]
    pub(crate) cull_backfaces: bool,
    /// Also write linear float EXR beside each PNG.
    #[arg(long)]
    pub(crate) exr: bool,
    /// Also write every view's camera (eye, target, up, field of view, near, far) to this JSON
    /// file, to set the same views up in another renderer.
    #[arg(long, value_name = "FILE.json")]
    pub(crate) cameras: Option<PathBuf>,
    /// Renderer: cpu (the reference), gpu (the wgpu mirror; needs the `gpu` feature and an
    /// adapter) or auto (gpu when available).
    #[arg(long, value_enum, default_value_t = Backend::Cpu)]
    pub(crate) backend: Backend,
    /// Frame the views like this mesh (the original, when rendering one of its LODs): by its
    /// bounding sphere instead of the rendered mesh's own, so `diff` compares aligned images.
    #[arg(long, value_name = "ORIGINAL")]
    pub(crate) frame_like: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) load: LoadArgs,
    #[command(flatten)]
    pub(crate) look: LookArgs,
}

impl RenderArgs {
    pub(crate) fn job(self) -> Result<RenderJob, Error> {
        let mut settings = RenderSettings::DEFAULT;
        settings.width = self.size;
        settings.height = self.size;
        settings.shading = self.shading;
        settings.cull_backfaces = self.cull_backfaces;
        settings.samples = self.pattern.with_side(side(self.samples));
        self.look.apply(&mut settings);
        let lighting = self.look.lighting()?;
        let views = match (self.all_views, self.sheet, self.out, self.out_dir) {
            (true, _, _, Some(out_dir)) => ViewSelection::All { out_dir },
            (_, true, Some(out), _) => ViewSelection::Sheet { out },
            (_, _, Some(out), _) => ViewSelection::One {
                view: self.view,
                out,
            },
            _ => {
                return Err(Error::Usage(
                    "name an output with -o (or --all-views --out-dir DIR)".into(),
                ));
            }
        };
        let mut job = RenderJob::new(self.mesh, views);
        job.load = self.load.options()?;
        job.settings = settings;
        job.rig = self.rig;
        job.exr = self.exr;
        job.backend = self.backend;
        job.lighting = lighting;
        job.cameras_json = self.cameras;
        job.frame_like = self.frame_like;
        Ok(job)
    }
}

/// Run `render`.
pub(crate) fn run(a: RenderArgs, quiet: bool) -> Result<(), Error> {
    let report = lodeval::app::render(&a.job()?)?;
    warnings(&report.warnings);
    if !quiet {
        note!(
            "wrote {} file(s), first {}",
            report.written.len(),
            report.written[0].display()
        );
    }
    Ok(())
}
