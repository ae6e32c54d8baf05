//! lodeval's integration tests, compiled as one binary (ripgrep's habit). One module per area:
//!
//! - `cli`: the command line end to end (exit codes, output shapes, usage errors).
//! - `bad_input`: crafted broken files across the formats; each must exit 2 with a message naming
//!   the file and the problem, and never panic.
//! - `models`: `lodeval info` on every model of the shared collection against MANIFEST.md's counts
//!   (skipped only when `../shared` is absent) and on the shipped `reference/models`.
//! - `eval`: the batch evaluator (determinism, shards, gate, golden images, bad configs, LOD
//!   chains on every shipped model).
//! - `export`: LOD chains as glTF with `MSFT_lod` and measured `MSFT_screencoverage`, from
//!   `eval` and `simplify`, read back with the `gltf` crate.
//! - `first_hour`: what a new user does after the quick start (issue 55): renders framed alike
//!   and misframed ones named by `diff`, labelled values.
//! - `fuzz`: property-based mutation fuzzing of the OBJ, PLY, OFF and GLB paths.
//! - `hostile`: hostile input by class (`hostile/mod.rs` lists them): refused with exit 2, never
//!   an abort, a hang or a silently wrong pass.
//! - `hostile3`: hostile input, round three (`hostile3/mod.rs` lists the classes): inputs
//!   overwritten through missing folders, writers that never asked, a poisoned render cache,
//!   shards of different inputs, concurrent and interrupted runs, unbounded work, meaningless
//!   gates.
//! - `materials`: glTF materials loaded whole (every slot, sampler, UV set, transform, extension)
//!   and exported whole by `simplify -o X.glb|.gltf`; MTL PBR keys; what cannot be carried is named.
//! - `menzel_guthe`: `lodeval simplify --method menzel-guthe` (Menzel & Guthe 2010): goals and
//!   distances, thread independence, the eval generator, bad requests.
//! - `optimize`: `lodeval optimize` (Lindstrom–Turk): energy goes down, the vertex count stays,
//!   the output is identical for 1, 2 and 8 threads; bad input exits 2.
//! - `pbr`: the `pbr` shading model against known answers (white furnace, mirror sphere, Fresnel,
//!   emission, normal-map handedness on mirrored UVs), the pinned built-in environment, thread
//!   independence, and bad environment files and materials.
//! - `qu_meyer`: `lodeval remesh` (Qu & Meyer): the remesh, its maps and JSON, thread
//!   independence, the eval generator, the experiment on a tiny config, bad requests.
//! - `oracles`: metrics against reference implementations (FLIP: NVIDIA's; SSIM/PSNR: scikit-image).
//! - `raster`: the CPU rasterizer (determinism over thread counts, watertightness, golden images,
//!   the `render` CLI).
//! - `simplify`: `lodeval simplify` and `lodeval geometry`, and the eval generators `qem` and
//!   `cluster`.
//! - `vdp`: the visible-difference predictor against established psychophysics.
//! - `williams`: `lodeval simplify --method williams` (Williams et al. 2003): budget, thread
//!   independence, views, bad requests, and the paper experiment on a tiny config.

mod bad_input;
mod calibration;
mod cli;
mod common;
mod eval;
mod export;
mod first_hour;
mod function_length;
mod fuzz;
#[cfg(feature = "gpu")]
mod gpu;
mod hostile;
mod hostile3;
mod materials;
mod menzel_guthe;
mod models;
mod optimize;
mod oracles;
mod pbr;
mod qu_meyer;
mod raster;
mod simplify;
mod vdp;
mod williams;
