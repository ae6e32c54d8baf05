//! One file per command: a `*Job` (what the user asked) in, a report (what was done and measured)
//! out; nothing here prints. `main.rs` and `src/cli/` parse the command line into these jobs and
//! print what comes back; everything that touches meshes, frames or files happens here, so it is
//! testable without a process. `eval`, `golden` and `merge` are the batch evaluator's own entry
//! points (`crate::eval`).

pub mod bench;
pub mod calibrate;
pub mod diff;
pub mod optimize;
pub mod remesh;
pub mod render;
pub mod simplify;

pub use calibrate::*;
pub use diff::*;
pub use optimize::*;
pub use remesh::*;
pub use render::*;
pub use simplify::*;
