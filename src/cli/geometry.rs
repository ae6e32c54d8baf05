//! `lodeval geometry A B`: Metro-style surface distances between two meshes.

use std::path::PathBuf;

use clap::Args;
use lodeval::{Error, LoadOptions};

use super::print::{emit, emit_json};

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  lodeval geometry bunny.obj bunny-lod.obj --samples 1000000\n\nExit codes: 0 measured · 2 bad input or usage · 3 internal error"
)]
pub(crate) struct GeometryArgs {
    /// The original mesh (distances are also given relative to its bounding-box diagonal).
    pub(crate) a: PathBuf,
    /// The mesh compared with it.
    pub(crate) b: PathBuf,
    /// Face samples per mesh (every vertex is sampled too).
    #[arg(long, default_value_t = 1_000_000,
          value_parser = super::args::count::<usize>(&lodeval::limits::SURFACE_SAMPLES))]
    pub(crate) samples: usize,
    /// Print JSON.
    #[arg(long)]
    pub(crate) json: bool,
}

/// Run `geometry`.
pub(crate) fn run(a: GeometryArgs) -> Result<(), Error> {
    let opts = LoadOptions::DEFAULT;
    let (ma, mb) = (
        lodeval::mesh::load(&a.a, &opts)?,
        lodeval::mesh::load(&a.b, &opts)?,
    );
    let d = lodeval::mesh::surface_distance::compare(&ma, &mb, a.samples);
    if a.json {
        return emit_json(&d);
    }
    emit(&format!(
        "hausdorff {:.6e} ({:.4} % of the diagonal)\nmean      {:.6e} ({:.4} %)\nrms       {:.6e} ({:.4} %)\nsamples   {} on A, {} on B; one-sided max A→B {:.6e}, B→A {:.6e}\n",
        d.hausdorff,
        d.hausdorff_relative * 100.0,
        d.mean,
        d.mean_relative * 100.0,
        d.rms,
        d.rms_relative * 100.0,
        d.samples[0],
        d.samples[1],
        d.one_sided_max[0],
        d.one_sided_max[1]
    ))
}
