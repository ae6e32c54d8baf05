//! `lodeval info MESH`: what a mesh file holds, as text or JSON.

use std::path::PathBuf;

use clap::Args;
use lodeval::{Error, MeshSummary};

use super::args::LoadArgs;
use super::print::{emit, emit_json};

#[derive(Args, Debug)]
#[command(
    after_help = "Example:\n  lodeval info reference/models/spot/spot_mtl.obj --json\n\nExit codes: 0 read · 2 the file is bad (the message names the line or element) · 3 internal error"
)]
pub(crate) struct InfoArgs {
    /// The mesh file (.obj, .ply, .gltf, .glb, .off).
    pub(crate) mesh: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    pub(crate) json: bool,
    #[command(flatten)]
    pub(crate) load: LoadArgs,
}

/// Run `info`.
pub(crate) fn run(a: InfoArgs) -> Result<(), Error> {
    let mesh = lodeval::mesh::load(&a.mesh, &a.load.options()?)?;
    let summary = MeshSummary::of(&mesh);
    if a.json {
        emit_json(&summary)
    } else {
        emit(&summary.to_string())
    }
}
