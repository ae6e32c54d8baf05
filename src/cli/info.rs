//! `lodeval info MESH`: what a mesh file holds, as text or JSON.

use std::path::PathBuf;

use clap::Args;
use lodeval::{Error, MeshSummary};

use super::args::LoadArgs;
use super::print::{emit, emit_json};

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  lodeval info reference/models/spot/spot_mtl.obj --json\n  lodeval info chain.glb     (an MSFT_lod chain: every level, its triangles and coverage)\n  lodeval info chain.glb#2  (level 2 of the chain)\n\nExit codes: 0 read · 2 the file is bad (the message names the line or element) · 3 internal error"
)]
pub(crate) struct InfoArgs {
    /// The mesh file (.obj, .ply, .gltf, .glb, .off); `FILE.glb#K` for level K of an `MSFT_lod`
    /// chain.
    pub(crate) mesh: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    pub(crate) json: bool,
    #[command(flatten)]
    pub(crate) load: LoadArgs,
}

/// Run `info`.
pub(crate) fn run(a: InfoArgs) -> Result<(), Error> {
    let options = a.load.options()?;
    let mesh = lodeval::mesh::load(&a.mesh, &options)?;
    let summary = MeshSummary::with_levels(&mesh, &options)?;
    if a.json {
        emit_json(&summary)
    } else {
        emit(&summary.to_string())
    }
}
