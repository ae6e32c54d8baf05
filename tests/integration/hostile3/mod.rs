//! Hostile input, round three: the surfaces the first two rounds did not reach, one module per
//! class of failure. Each failure here lost data or gave a different answer with exit 0; each
//! crafted input must now be refused (exit 2, one message naming the culprit), warned about, or
//! handled, with every input byte-identical afterwards.
//!
//! - `overwrite`: inputs replaced through an output path that does not exist yet
//!   (`missing/../in.obj`), in every command that writes.
//! - `writers`: writers that never asked (glTF images over an input texture, `diff --map` and
//!   `--csv` over a compared image, orphan images of a failed export, OBJ text in a `.glb`).
//! - `cache`: a render cache trusted blindly (swapped, linked, forged entries; a cache inside
//!   the output folder; a cache that cannot be written).
//! - `merge`: shards that ran on different or edited inputs, shards missing a case's rows.
//! - `folder`: two runs into one `--out`, SIGTERM mid-run, a planted `shard.json`, a person's
//!   file among the outputs.
//! - `work`: unbounded messages, allocations and quadratic paths (sparse giant files, 100 000
//!   materials, planar grids for Williams and QEM).
//! - `meaning`: values outside their meaning (gates that can never fail, exposures of ±1e30)
//!   and flags that do nothing.
//! - `smaller`: colliding material names in OBJ output, morph targets, short remeshes, malformed
//!   messages.
//! - `leftovers`: round two's leftovers (PLY 2.0, glTF 3.0, a missing `TEXCOORD_n`, a short GLB
//!   header length, NaN in an EXR, `--rings 0`).

mod cache;
mod folder;
mod leftovers;
mod meaning;
mod merge;
mod overwrite;
mod smaller;
mod work;
mod writers;

use std::path::{Path, PathBuf};

pub use crate::hostile::{assert_refused, scratch, write};

/// A copy of the shipped Spot (OBJ, MTL, texture) in `dir`.
pub fn spot_copy(dir: &Path) -> PathBuf {
    let src = crate::common::model("spot");
    for f in ["spot_mtl.obj", "spot.mtl", "spot_texture.png"] {
        std::fs::copy(src.join(f), dir.join(f)).unwrap();
    }
    dir.join("spot_mtl.obj")
}

/// `lodeval ARGS` (strings), killed after two minutes.
pub fn run(args: &[&str]) -> crate::common::Run {
    crate::common::lodeval_within(120, args)
}

/// A path as `&str` (test paths are UTF-8).
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A small eval config in `dir` on `mesh`, writing to `out`, with `extra` top-level keys.
pub fn config(dir: &Path, name: &str, mesh: &Path, out: &str, extra: &str) -> PathBuf {
    write(
        dir,
        name,
        &format!(
            "out = \"{out}\"\nmetrics = [\"flip\"]\n{extra}\n[render]\nsize = 32\n\
             rig = \"icosahedron\"\n[distance]\nenabled = false\n[[asset]]\nname = \"m\"\n\
             mesh = \"{}\"\ngenerate = {{ method = \"meshopt\", ratios = [0.5, 0.25] }}\n",
            mesh.display()
        ),
    )
}
