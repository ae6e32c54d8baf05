//! The perceptual difference stack (`catalog.rs` names every reported value): every metric takes two linear-RGB images of equal size
//! ([`LinearImage`]), is prepared once per reference where it has per-image work, and returns
//! named results with units. One metric per file, in the order of the maths:
//! `mse.rs` (MSE, PSNR, d_MS), `ssim.rs` (SSIM, MS-SSIM), `flip.rs` (ꟻLIP),
//! `pool.rs` (pooling), `runs.rs` (maps evaluated once per run of equal values), `csf.rs`
//! (contrast sensitivity), `tvi.rs` (threshold versus intensity), `vdp/` (the visible-difference
//! predictor, one stage per file).

pub mod catalog;
pub mod colormap;
pub mod csf;
pub mod flip;
pub mod hdr_flip;
pub mod mse;
pub mod pool;
pub(crate) mod runs;
pub mod ssim;
pub mod tvi;
pub mod vdp;

// The metrics' input and output types live below the metric layer (`crate::image`); re-exported
// here because every metric signature uses them.
pub use crate::image::{ErrorMap, LinearImage};
pub use catalog::{Metric, MetricFamily};
