//! `lodeval remesh MESH -o OUT.obj --vertices N`: Qu & Meyer's perceptually driven remeshing, and
//! the paper's experiment (`--experiment`).

use std::path::PathBuf;

use clap::Args;
use lodeval::Error;
use lodeval::simplify::qu_meyer::{Method, Options};

use super::print::{emit, emit_json};

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  lodeval remesh reference/models/spot/spot_mtl.obj -o spot-2k.obj \
    --vertices 2000 --maps spot-maps\n\nExit codes: 0 written · 2 bad input or usage (no UVs, \
    overlapping UV charts, a bad value) · 3 internal error"
)]
pub(crate) struct RemeshArgs {
    /// The mesh to remesh (it must have texture coordinates).
    #[arg(required_unless_present = "experiment")]
    pub(crate) mesh: Option<PathBuf>,
    /// Output .obj (its .mtl and textures are written beside it).
    #[arg(short, long, required_unless_present = "experiment")]
    pub(crate) out: Option<PathBuf>,
    /// Run the paper's experiment from its config (configs/papers/qu-meyer.toml).
    #[arg(long, conflicts_with_all = ["mesh", "out"])]
    pub(crate) experiment: Option<PathBuf>,
    /// Vertices of the result (3D points; a seam vertex counts once), 4 or more.
    #[arg(long, required_unless_present = "experiment")]
    pub(crate) vertices: Option<usize>,
    /// The density: qu-meyer (curvature and masking), curvature, or uniform.
    #[arg(long, value_enum, default_value_t = Method::QuMeyer)]
    pub(crate) method: Method,
    /// Weight of the curvature map (0 to 10; the paper's figures use 1.2).
    #[arg(long, default_value_t = 1.2, allow_negative_numbers = true)]
    pub(crate) curvature_gamma: f64,
    /// Weight of the visual masking map (0 to 10; the paper's figures use 1 and 2).
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub(crate) perceptual_gamma: f64,
    /// Lloyd iterations (the paper: 10–20).
    #[arg(long, default_value_t = 20)]
    pub(crate) lloyd_iterations: usize,
    /// Texels per side of the maps.
    #[arg(long, default_value_t = 512)]
    pub(crate) map_size: usize,
    /// Pixels per degree the maps are seen at (default: the default display's, about 67).
    #[arg(long)]
    pub(crate) ppd: Option<f64>,
    /// Write the signal, masking, curvature, density and sample maps as PNG into this folder.
    #[arg(long)]
    pub(crate) maps: Option<PathBuf>,
    /// Print JSON (vertices, triangles, iterations, seconds per stage).
    #[arg(long)]
    pub(crate) json: bool,
}

/// Run `remesh`.
pub(crate) fn run(a: RemeshArgs, quiet: bool) -> Result<(), Error> {
    if let Some(config) = &a.experiment {
        let report = lodeval::experiments::qu_meyer::run(config, &mut |line| {
            if !quiet {
                note!("{line}")
            }
        })?;
        return emit(&format!(
            "{} remeshes scored, written to {}\n",
            report.rows.len(),
            report.out.display()
        ));
    }
    let (Some(mesh), Some(out), Some(vertices)) = (a.mesh, a.out, a.vertices) else {
        return Err(Error::Usage(
            "remesh needs MESH, -o OUT.obj and --vertices N".into(),
        ));
    };
    let mut options = Options::new(vertices);
    options.method = a.method;
    options.curvature_gamma = a.curvature_gamma;
    options.perceptual_gamma = a.perceptual_gamma;
    options.lloyd_iterations = a.lloyd_iterations;
    options.map_size = a.map_size;
    if let Some(ppd) = a.ppd {
        options.ppd = ppd;
    }
    let mut job = lodeval::app::RemeshJob::new(mesh, out, options);
    job.maps = a.maps;
    let report = lodeval::app::remesh(&job)?;
    super::print::warnings(&report.warnings);
    if a.json {
        return emit_json(&report);
    }
    let s = &report.seconds;
    emit(&format!(
        "{}  {} vertices ({} on seams), {} triangles, {} charts, from {} vertices; {:.0} % of the \
         vertices in the most masked quarter\nseconds: maps {:.2}, masking {:.2}, sampling {:.2}, \
         Lloyd {:.2} ({} iterations), triangulation {:.2}\n",
        report.file.display(),
        report.vertices,
        report.boundary_vertices,
        report.triangles,
        report.charts,
        report.input_vertices,
        100.0 * report.masked_share,
        s.maps,
        s.masking,
        s.sampling,
        s.lloyd,
        report.iterations,
        s.triangulation
    ))
}
