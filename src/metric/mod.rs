//! The perceptual difference stack: every metric takes two linear-RGB images of equal size
//! ([`LinearImage`]), is prepared once per reference where it has per-image work, and returns
//! named results with units. One metric per file, in the order of the maths:
//! `color.rs` (encodings), `mse.rs` (MSE, PSNR, d_MS), `ssim.rs` (SSIM, MS-SSIM), `flip.rs` (ꟻLIP),
//! `pool.rs` (pooling).

pub mod color;
pub mod colormap;
pub mod csf;
pub mod flip;
pub(crate) mod image;
pub mod mse;
pub mod pool;
pub mod ssim;
pub mod vdp;

pub use image::{ErrorMap, LinearImage};
