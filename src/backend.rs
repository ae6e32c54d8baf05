//! Where frames are rendered and images scored: `--backend cpu|gpu|auto`.
//!
//! `cpu` is the reference rasterizer (`raster/`) and metric stack (`metric/`); `gpu` is the wgpu
//! mirror (`gpu/`, cargo feature `gpu`); `auto` takes the GPU when the feature is built and an
//! adapter exists, the CPU otherwise — and says so on stderr when it falls back, never silently.
//! Every run records [`Engine::describe`] (CSV `renderer` column, report header). In `eval` the
//! backend renders; scores are computed on the CPU. `diff` runs FLIP, MSE and PSNR on it.

use crate::error::Result;
use crate::image::LinearImage;
use crate::metric::flip::{Flip, FlipScore};
use crate::metric::mse::MseScore;
use crate::raster::RenderScene;
use crate::raster::{self, Frame, RenderSettings};
use crate::scene::Camera;

/// The user's choice.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Backend {
    /// The CPU reference (default: byte-identical results on every machine).
    #[default]
    #[value(help = "The CPU reference rasterizer and metrics")]
    Cpu,
    /// The GPU mirror; an error without an adapter or without the `gpu` feature.
    #[value(help = "The wgpu mirror (cargo feature `gpu`)")]
    Gpu,
    /// The GPU where possible, else the CPU.
    #[value(help = "The GPU when built and an adapter exists, else the CPU")]
    Auto,
}

/// The chosen backend, opened.
#[derive(Debug, Clone)]
pub struct Engine {
    /// Why `auto` fell back to the CPU, for the caller to tell the user.
    fallback: Option<String>,
    #[cfg(feature = "gpu")]
    gpu: Option<(
        std::sync::Arc<crate::gpu::Gpu>,
        std::sync::Arc<crate::gpu::GpuMetrics>,
    )>,
}

/// The CPU renderer's name in run records.
pub const CPU_RENDERER: &str = "cpu";

impl Engine {
    /// The CPU reference.
    pub fn cpu() -> Engine {
        Engine {
            fallback: None,
            #[cfg(feature = "gpu")]
            gpu: None,
        }
    }

    /// Open `choice`.
    pub fn new(choice: Backend) -> Result<Engine> {
        match choice {
            Backend::Cpu => Ok(Engine::cpu()),
            #[cfg(not(feature = "gpu"))]
            Backend::Gpu => Err(crate::error::Error::Usage(
                "this lodeval was built without the GPU path: rebuild with `cargo build \
                 --release --features gpu`, or use --backend cpu"
                    .into(),
            )),
            #[cfg(not(feature = "gpu"))]
            Backend::Auto => {
                let mut e = Engine::cpu();
                e.fallback = Some(
                    "GPU path skipped: built without the `gpu` feature; rendering on the CPU"
                        .into(),
                );
                Ok(e)
            }
            #[cfg(feature = "gpu")]
            Backend::Gpu => Self::open_gpu(),
            #[cfg(feature = "gpu")]
            Backend::Auto => match Self::open_gpu() {
                Ok(e) => Ok(e),
                Err(e) => Ok(Engine {
                    fallback: Some(format!("{e}; rendering on the CPU")),
                    ..Engine::cpu()
                }),
            },
        }
    }

    #[cfg(feature = "gpu")]
    fn open_gpu() -> Result<Engine> {
        let gpu = crate::gpu::Gpu::new()?;
        let metrics = crate::gpu::GpuMetrics::new(gpu.clone())?;
        Ok(Engine {
            fallback: None,
            gpu: Some((gpu, std::sync::Arc::new(metrics))),
        })
    }

    /// Why `auto` rendered on the CPU (no adapter, or a build without the GPU path), if it did.
    pub fn fallback(&self) -> Option<&str> {
        self.fallback.as_deref()
    }

    /// `cpu`, or `gpu: ADAPTER (DRIVER, API, TYPE)`.
    pub fn describe(&self) -> String {
        #[cfg(feature = "gpu")]
        if let Some((gpu, _)) = &self.gpu {
            return format!("gpu: {}", gpu.info());
        }
        CPU_RENDERER.to_string()
    }

    /// Make `scene` renderable (uploads it for the GPU).
    pub fn scene<'a>(&self, scene: &'a RenderScene) -> Result<SceneRenderer<'a>> {
        #[cfg(feature = "gpu")]
        if let Some((gpu, _)) = &self.gpu {
            return Ok(SceneRenderer::Gpu(Box::new(crate::gpu::GpuScene::new(
                gpu.clone(),
                scene,
            )?)));
        }
        Ok(SceneRenderer::Cpu(scene))
    }

    /// ꟻLIP on this backend.
    pub fn flip(
        &self,
        flip: &Flip,
        reference: &LinearImage,
        test: &LinearImage,
    ) -> Result<FlipScore> {
        #[cfg(feature = "gpu")]
        if let Some((_, m)) = &self.gpu {
            return m.flip(flip, reference, test);
        }
        flip.compare(reference, test)
    }

    /// MSE on this backend.
    pub fn mse(&self, reference: &LinearImage, test: &LinearImage) -> Result<MseScore> {
        #[cfg(feature = "gpu")]
        if let Some((_, m)) = &self.gpu {
            return m.mse(reference, test);
        }
        crate::metric::mse::mse(reference, test)
    }
}

/// A scene ready to render on the chosen backend.
#[derive(Debug)]
#[non_exhaustive]
pub enum SceneRenderer<'a> {
    /// The CPU rasterizer.
    Cpu(&'a RenderScene),
    /// Uploaded to the GPU.
    #[cfg(feature = "gpu")]
    Gpu(Box<crate::gpu::GpuScene>),
}

impl SceneRenderer<'_> {
    /// Render from `camera`.
    pub fn render(&self, camera: &Camera, settings: &RenderSettings) -> Result<Frame> {
        match self {
            SceneRenderer::Cpu(scene) => raster::render(scene, camera, settings),
            #[cfg(feature = "gpu")]
            SceneRenderer::Gpu(g) => g.render(camera, settings),
        }
    }
}
