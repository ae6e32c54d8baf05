//! The GPU path (cargo feature `gpu`): a headless wgpu renderer and metric kernels that mirror the
//! CPU reference in `raster/` and `metric/`, and are held to it by tests (`tests/integration/gpu.rs`).
//!
//! - `context.rs` — finding an adapter and opening a device; the adapter's name and driver, which
//!   every run that used the GPU records.
//! - `render.rs` — the renderer: a scene uploaded once ([`GpuScene`]), rendered from any camera
//!   into the same [`Frame`](crate::raster::Frame) the CPU rasterizer returns (linear RGB `f32`,
//!   depth, coverage, triangle id). It has the CPU's structure — a visibility buffer, then shading
//!   once per triangle per pixel — in two passes: `shaders/visibility.wgsl` (a render pass per
//!   anti-aliasing sample, the projection shifted so that the CPU's sample position falls on the
//!   pixel centre; writes triangle id and depth) and `shaders/shade.wgsl` (a compute pass: the
//!   CPU's resolve and shading models line for line, with its mip pyramids and trilinear formula).
//! - `pipelines.rs` — the renderer's two passes as pipelines, built from the device alone (the
//!   device caches them, the renderer records with them).
//! - `metric.rs` — MSE (`shaders/mse.wgsl`) and ꟻLIP (`shaders/flip_*.wgsl`, one pass per file),
//!   returning the CPU's [`MseScore`](crate::metric::mse::MseScore) and
//!   [`FlipScore`](crate::metric::flip::FlipScore).
//!
//! What is mirrored exactly and what is not (`tests/integration/gpu.rs` states the tolerances):
//! - The same camera matrices, sample positions and order, lights (resolved on the CPU),
//!   materials, vertex lighting, Blinn–Phong terms, texture pyramids and filter, background and
//!   resolve rules (shade at the first covered sample of each triangle, majority triangle id).
//! - From the driver: the rasterization rule on exact ties (both are top-left with 1/256-pixel
//!   vertex snapping on lavapipe) and `f32` barycentrics solved from clip space where the CPU uses
//!   snapped screen positions in `f64`. Measured on lavapipe: FLIP mean ≤ 5e-4 between the
//!   frames, ≤ 0.03 % of triangle ids differ.
//! - GPU results are deterministic on one driver, not promised identical across drivers.

mod context;
mod metric;
mod pipelines;
mod render;

pub use context::{AdapterInfo, Gpu, NO_ADAPTER};
pub use metric::{GpuFlipPrepared, GpuMetrics};
pub use render::GpuScene;
