//! GPU metric kernels: MSE and ꟻLIP as compute passes, returning the CPU's score types.
//!
//! MSE (`shaders/mse.wgsl`): per-row compensated `f32` sums of squared luminance differences,
//! added in row order in `f64` on the host. ꟻLIP (`shaders/flip_color.wgsl`, `flip_filter_x.wgsl`,
//! `flip_filter_y.wgsl`, `flip_compare.wgsl`): the four steps of `metric::flip`, with the filter
//! taps and cmax computed by the CPU code and uploaded, so both paths use identical constants; the
//! error map is read back and pooled by `metric::pool::mean`, as on the CPU. Tested against the
//! CPU on the oracle pairs of `reference/oracles/` (`tests/integration/gpu.rs`).

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};

use super::Gpu;
use crate::error::Result;
use crate::metric::flip::{Flip, FlipScore};
use crate::metric::mse::MseScore;
use crate::metric::{ErrorMap, LinearImage};

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Dims {
    width: u32,
    height: u32,
    radius: u32,
    feature_radius: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct CompareParams {
    count: u32,
    cmax: f32,
    pad: [u32; 2],
}

/// The metric kernels on one device.
#[derive(Debug)]
pub struct GpuMetrics {
    gpu: Arc<Gpu>,
    mse: wgpu::ComputePipeline,
    flip_color: wgpu::ComputePipeline,
    flip_x: wgpu::ComputePipeline,
    flip_y: wgpu::ComputePipeline,
    flip_compare: wgpu::ComputePipeline,
}

/// One image after ꟻLIP's per-image passes, still on the GPU.
#[derive(Debug)]
pub struct GpuFlipPrepared {
    width: usize,
    height: usize,
    lab: wgpu::Buffer,
    features: wgpu::Buffer,
}

impl GpuMetrics {
    /// Compile the kernels.
    pub fn new(gpu: Arc<Gpu>) -> Result<GpuMetrics> {
        gpu.clone().checked("compiling the metric kernels", || {
            Ok(GpuMetrics {
                mse: gpu.compute_pipeline("mse.wgsl", include_str!("shaders/mse.wgsl")),
                flip_color: gpu.compute_pipeline(
                    "flip_color.wgsl",
                    concat!(
                        include_str!("shaders/flip_common.wgsl"),
                        include_str!("shaders/flip_color.wgsl")
                    ),
                ),
                flip_x: gpu.compute_pipeline(
                    "flip_filter_x.wgsl",
                    include_str!("shaders/flip_filter_x.wgsl"),
                ),
                flip_y: gpu.compute_pipeline(
                    "flip_filter_y.wgsl",
                    concat!(
                        include_str!("shaders/flip_common.wgsl"),
                        include_str!("shaders/flip_filter_y.wgsl")
                    ),
                ),
                flip_compare: gpu.compute_pipeline(
                    "flip_compare.wgsl",
                    include_str!("shaders/flip_compare.wgsl"),
                ),
                gpu,
            })
        })
    }

    fn upload(&self, image: &LinearImage) -> wgpu::Buffer {
        let px: Vec<[f32; 4]> = image
            .pixels()
            .iter()
            .map(|c| c.extend(0.0).to_array())
            .collect();
        self.gpu.storage("image", bytemuck::cast_slice(&px))
    }

    /// MSE, RMSE and PSNR, as [`crate::metric::mse::mse`].
    pub fn mse(&self, reference: &LinearImage, test: &LinearImage) -> Result<MseScore> {
        crate::image::same_size(reference, test)?;
        let gpu = &self.gpu;
        gpu.checked("MSE", || {
            let (w, h) = (reference.width(), reference.height());
            let dims = Dims {
                width: w as u32,
                height: h as u32,
                radius: 0,
                feature_radius: 0,
            };
            let dims = gpu.uniform("dims", bytemuck::bytes_of(&dims));
            let (a, b) = (self.upload(reference), self.upload(test));
            let rows = gpu.output("row sums", h as u64 * 4);
            let mut encoder = gpu.encoder();
            gpu.dispatch(
                &mut encoder,
                &self.mse,
                &[
                    dims.as_entire_binding(),
                    a.as_entire_binding(),
                    b.as_entire_binding(),
                    rows.as_entire_binding(),
                ],
                [(h as u32).div_ceil(64), 1, 1],
            );
            let out = gpu.read_back(encoder, &[&rows])?;
            let rows: &[f32] = bytemuck::cast_slice(&out[0]);
            let sum: f64 = rows[..h].iter().map(|&r| r as f64).sum();
            Ok(MseScore::from_mse(sum / (w * h) as f64))
        })
    }

    /// ꟻLIP's per-image work for `flip`'s viewing condition, as [`Flip::prepare`].
    pub fn flip_prepare(&self, flip: &Flip, image: &LinearImage) -> Result<GpuFlipPrepared> {
        let gpu = &self.gpu;
        gpu.checked("FLIP", || {
            let (w, h) = (image.width(), image.height());
            let (spatial, features, _) = flip.kernels();
            let dims = Dims {
                width: w as u32,
                height: h as u32,
                radius: (spatial.len() / 2) as u32,
                feature_radius: (features.len() / 2) as u32,
            };
            let dims = gpu.uniform("dims", bytemuck::bytes_of(&dims));
            let spatial = gpu.storage("spatial taps", bytemuck::cast_slice(&spatial));
            let features = gpu.storage("feature taps", bytemuck::cast_slice(&features));
            let n = (w * h) as u64;
            let image = self.upload(image);
            let ycxcz = gpu.output("YCxCz", n * 16);
            let mid_color = gpu.output("filtered rows", n * 16);
            let mid_features = gpu.output("feature rows", n * 16);
            let lab = gpu.output("Hunt-adjusted Lab", n * 16);
            let feat = gpu.output("features", n * 8);
            let groups = [(w as u32).div_ceil(8), (h as u32).div_ceil(8), 1];
            let mut encoder = gpu.encoder();
            gpu.dispatch(
                &mut encoder,
                &self.flip_color,
                &[
                    dims.as_entire_binding(),
                    image.as_entire_binding(),
                    ycxcz.as_entire_binding(),
                ],
                [(n as u32).div_ceil(64), 1, 1],
            );
            gpu.dispatch(
                &mut encoder,
                &self.flip_x,
                &[
                    dims.as_entire_binding(),
                    ycxcz.as_entire_binding(),
                    spatial.as_entire_binding(),
                    features.as_entire_binding(),
                    mid_color.as_entire_binding(),
                    mid_features.as_entire_binding(),
                ],
                groups,
            );
            gpu.dispatch(
                &mut encoder,
                &self.flip_y,
                &[
                    dims.as_entire_binding(),
                    mid_color.as_entire_binding(),
                    mid_features.as_entire_binding(),
                    spatial.as_entire_binding(),
                    features.as_entire_binding(),
                    lab.as_entire_binding(),
                    feat.as_entire_binding(),
                ],
                groups,
            );
            gpu.queue.submit([encoder.finish()]);
            Ok(GpuFlipPrepared {
                width: w,
                height: h,
                lab,
                features: feat,
            })
        })
    }

    /// Compare two prepared images, as [`Flip::compare_prepared`].
    pub fn flip_compare(
        &self,
        flip: &Flip,
        reference: &GpuFlipPrepared,
        test: &GpuFlipPrepared,
    ) -> Result<FlipScore> {
        crate::image::same_dims(
            (reference.width, reference.height),
            (test.width, test.height),
        )?;
        let gpu = &self.gpu;
        gpu.checked("FLIP", || {
            let n = reference.width * reference.height;
            let params = CompareParams {
                count: n as u32,
                cmax: flip.kernels().2,
                pad: [0; 2],
            };
            let params = gpu.uniform("compare", bytemuck::bytes_of(&params));
            let map = gpu.output("FLIP map", n as u64 * 4);
            let mut encoder = gpu.encoder();
            gpu.dispatch(
                &mut encoder,
                &self.flip_compare,
                &[
                    params.as_entire_binding(),
                    reference.lab.as_entire_binding(),
                    reference.features.as_entire_binding(),
                    test.lab.as_entire_binding(),
                    test.features.as_entire_binding(),
                    map.as_entire_binding(),
                ],
                [(n as u32).div_ceil(64), 1, 1],
            );
            let out = gpu.read_back(encoder, &[&map])?;
            let values: Vec<f32> = bytemuck::cast_slice::<u8, f32>(&out[0])[..n].to_vec();
            Ok(FlipScore {
                mean: crate::metric::pool::mean(&values, reference.width),
                map: ErrorMap {
                    width: reference.width,
                    height: reference.height,
                    values,
                },
            })
        })
    }

    /// ꟻLIP of two images, as [`Flip::compare`].
    pub fn flip(
        &self,
        flip: &Flip,
        reference: &LinearImage,
        test: &LinearImage,
    ) -> Result<FlipScore> {
        crate::image::same_size(reference, test)?;
        let a = self.flip_prepare(flip, reference)?;
        let b = self.flip_prepare(flip, test)?;
        self.flip_compare(flip, &a, &b)
    }
}
