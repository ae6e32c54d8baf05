//! lodeval: does a simplified mesh (a level of detail) still look like the original, and from how
//! far away can nobody tell them apart?
//!
//! Data flow (DESIGN.md):
//!
//! ```text
//! configs/*.toml ─► eval::Plan  (assets × LODs × views × lights, metrics, viewing, gates)
//!                      │
//!  mesh::load ─────────┤  OBJ+MTL · PLY · glTF 2.0 · OFF — validated, textures decoded once
//!                      ▼
//!  raster::render(&Scene, &Camera, &RenderSettings) ─► Frame (linear RGB f32, depth, coverage, id)
//!                      ▼
//!  metric::{mse, ssim, flip, vdp, ...}(&reference, &test, &Viewing) ─► Score {value, map}
//!                      ▼
//!  eval::Row ─► metrics.csv · summary.csv · distances.csv · heatmaps · junit.xml · report.html
//!                      ▼
//!  eval::gate ─► exit code
//! ```
//!
//! Built so far: [`mesh`] (loading, validation, normals, welding, bounds) and the colour
//! encodings in [`metric::color`]. The other stages arrive with their issues.

#![warn(missing_docs, missing_debug_implementations)]

pub mod app;
pub mod backend;
pub mod color;
pub mod cpu;
pub mod error;
pub mod eval;
pub mod experiments;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod image;
pub mod io;
#[cfg(test)]
mod layers;
pub mod mesh;
pub mod metric;
pub(crate) mod prefetch;
pub mod progress;
pub mod raster;
pub mod scene;
pub mod simplify;

pub use error::{Error, Location, Result};
pub use mesh::{LoadOptions, Mesh, MeshSummary, MissingAssets};
