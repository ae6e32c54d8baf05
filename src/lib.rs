//! lodeval: does a simplified mesh (a level of detail) still look like the original, and from how
//! far away can nobody tell them apart?
//!
//! The crate is built in layers, each using only the layers below it (ARCHITECTURE.md has
//! the whole picture; `src/layers.rs` tests it):
//!
//! ```text
//! error · color · image · io      shared ground: errors, colour encodings, linear images, files
//!   mesh                           loaders (OBJ+MTL, PLY, glTF 2.0, OFF), validation, normals
//!   scene                          what is lit and seen: materials, lights, cameras, rigs
//!   raster · metric                the CPU rasterizer; the perceptual difference stack
//!   gpu · backend                  the wgpu mirror of the rasterizer; the choice between the two
//!   simplify                       QEM engine, Williams et al. 2003, Lindstrom & Turk
//!   eval                           plans, image pairs, scores, distances, gates, reports
//!   experiments · app              the papers' reproductions; one job per CLI command
//! ```
//!
//! One image pair from config to CSV row: [`eval::Plan`] names assets × LODs × views × lights;
//! [`mesh::load`] reads each mesh once; [`raster::render`] turns a [`raster::RenderScene`] and a
//! [`scene::Camera`] into a [`raster::Frame`] (linear RGB, depth, coverage); [`metric`] scores the
//! pair (MSE/PSNR, SSIM, FLIP, the VDP) in [`image::LinearImage`]s built from the frames; `eval`
//! writes `metrics.csv`, `summary.csv`, `distances.csv`, heat maps, plots and `report.html`, and its
//! gate decides the exit code. Colour conversions live in [`color`].

#[doc(hidden)]
// the binary's jobs and the papers' runs, public for the CLI and tests; not a library API
pub mod app;
pub mod backend;
pub mod color;
#[doc(hidden)] // plumbing shared with the binary (files, bounds); not a library API
pub mod cpu;
pub mod error;
pub mod eval;
#[doc(hidden)]
// the binary's jobs and the papers' runs, public for the CLI and tests; not a library API
pub mod experiments;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod image;
#[doc(hidden)] // plumbing shared with the binary (files, bounds); not a library API
pub mod io;
#[cfg(test)]
mod layers;
#[doc(hidden)] // plumbing shared with the binary (files, bounds); not a library API
pub mod limits;
pub mod mesh;
pub mod metric;
pub(crate) mod prefetch;
pub mod progress;
pub mod raster;
pub mod scene;
pub mod simplify;

// What a library user reaches for first, at the crate root: load a mesh, simplify it, render
// both, score the pair, or run a whole config.
pub use error::{Error, Location, Result};
pub use eval::compare::{CompareJob, CompareReport, compare};
pub use eval::{Outcome, Plan, Results, RunOptions, eval};
pub use image::{ErrorMap, LinearImage};
pub use mesh::{LoadOptions, Mesh, MeshSummary, MissingAssets, load};
pub use metric::flip::Flip;
pub use metric::vdp::{Display, Vdp};
pub use metric::{Metric, MetricFamily};
pub use raster::{Frame, RenderScene, RenderSettings, Shading, render};
pub use scene::{Camera, Rig, Viewing};
pub use simplify::{Goal, Lod, Method, chain};
