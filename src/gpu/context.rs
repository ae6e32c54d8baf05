//! Finding a GPU adapter and opening a device.
//!
//! Decision: only the primary native backends (Vulkan, Metal, DX12) are asked, unless the user
//! names others in `WGPU_BACKEND`; the GL backend's headless EGL probing prints noise and its
//! feature set (no storage buffers in vertex shaders on many drivers) cannot run the renderer. On
//! a machine without a GPU, Mesa's software Vulkan driver (lavapipe, package
//! `mesa-vulkan-drivers`) provides an adapter.

use std::sync::Arc;

use crate::error::{Error, Result};

/// The message shown whenever the GPU path cannot run for lack of an adapter.
pub const NO_ADAPTER: &str =
    "GPU path skipped: no adapter (install mesa-vulkan-drivers for the software driver)";

/// Which adapter ran the work: recorded in run headers and reports.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AdapterInfo {
    /// Adapter name, e.g. `llvmpipe (LLVM 15.0.6, 256 bits)`.
    pub name: String,
    /// Driver name and version, e.g. `llvmpipe Mesa 22.3.6 (LLVM 15.0.6)`.
    pub driver: String,
    /// Graphics API backend, e.g. `vulkan`.
    pub backend: String,
    /// `cpu` for software drivers, `discrete-gpu`, `integrated-gpu`, …
    pub device_type: String,
}

impl std::fmt::Display for AdapterInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} ({}, {}, {})",
            self.name, self.driver, self.backend, self.device_type
        )
    }
}

/// An open device and its queue.
#[derive(Debug)]
pub struct Gpu {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    pub(crate) info: AdapterInfo,
    /// The renderer's pipelines, built on first use and shared by every scene.
    render_pipelines: std::sync::OnceLock<super::pipelines::Pipelines>,
}

impl Gpu {
    /// The renderer's pipelines (compiled on the first call; the shaders depend only on the
    /// device, so every scene uses the same ones).
    pub(crate) fn render_pipelines(&self) -> &super::pipelines::Pipelines {
        self.render_pipelines
            .get_or_init(|| super::pipelines::build(&self.device))
    }

    /// Open the best adapter. `Err(Error::Usage(NO_ADAPTER…))` when there is none.
    pub fn new() -> Result<Arc<Gpu>> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = wgpu::Backends::PRIMARY;
        let desc = desc.with_env();
        let instance = wgpu::Instance::new(desc);
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            ..Default::default()
        }))
        .map_err(|e| Error::Usage(format!("{NO_ADAPTER}: {e}")))?;
        let raw = adapter.get_info();
        let info = AdapterInfo {
            name: raw.name.clone(),
            driver: format!("{} {}", raw.driver, raw.driver_info)
                .trim()
                .to_string(),
            backend: raw.backend.to_str().to_string(),
            device_type: match raw.device_type {
                wgpu::DeviceType::Cpu => "cpu",
                wgpu::DeviceType::DiscreteGpu => "discrete-gpu",
                wgpu::DeviceType::IntegratedGpu => "integrated-gpu",
                wgpu::DeviceType::VirtualGpu => "virtual-gpu",
                wgpu::DeviceType::Other => "other",
            }
            .to_string(),
        };
        // The renderer needs large storage buffers (whole meshes, texture pyramids) and large
        // targets (n×n supersampling): ask for what the adapter has.
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("lodeval"),
            required_features: wgpu::Features::empty(),
            required_limits: limits,
            ..Default::default()
        }))
        .map_err(|e| Error::Internal(format!("cannot open the GPU adapter {info}: {e}")))?;
        Ok(Arc::new(Gpu {
            device,
            queue,
            info,
            render_pipelines: std::sync::OnceLock::new(),
        }))
    }

    /// The adapter in use.
    pub fn info(&self) -> &AdapterInfo {
        &self.info
    }

    /// Run `f` with the device's validation and out-of-memory errors captured, so that they
    /// come back as errors rather than wgpu's default panic.
    pub(crate) fn checked<T>(&self, what: &str, f: impl FnOnce() -> Result<T>) -> Result<T> {
        let oom = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let out = f();
        let invalid = pollster::block_on(validation.pop());
        let out_of_memory = pollster::block_on(oom.pop());
        if let Some(e) = out_of_memory {
            return Err(Error::Usage(format!(
                "the GPU {} ran out of memory in {what} ({e}); use smaller images or --backend cpu",
                self.info
            )));
        }
        if let Some(e) = invalid {
            return Err(Error::Internal(format!("GPU {what} on {}: {e}", self.info)));
        }
        out
    }

    /// Wait for all submitted work; a lost device is an internal error.
    pub(crate) fn wait(&self) -> Result<()> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| Error::Internal(format!("GPU {}: {e}", self.info)))
    }

    /// A storage buffer holding `data` (at least 16 bytes: empty arrays cannot be bound).
    pub(crate) fn storage(&self, label: &str, data: &[u8]) -> wgpu::Buffer {
        use wgpu::util::DeviceExt;
        let mut bytes = data.to_vec();
        bytes.resize(bytes.len().max(16).next_multiple_of(4), 0);
        self.device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: &bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            })
    }

    /// A uniform buffer holding `data`.
    pub(crate) fn uniform(&self, label: &str, data: &[u8]) -> wgpu::Buffer {
        use wgpu::util::DeviceExt;
        self.device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: data,
                usage: wgpu::BufferUsages::UNIFORM,
            })
    }

    /// A read-write storage buffer of `size` bytes that can be copied out.
    pub(crate) fn output(&self, label: &str, size: u64) -> wgpu::Buffer {
        self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size.max(16),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        })
    }

    /// Copy `buffers` out of the GPU after `encoder`'s work, in one submission.
    pub(crate) fn read_back(
        &self,
        mut encoder: wgpu::CommandEncoder,
        buffers: &[&wgpu::Buffer],
    ) -> Result<Vec<Vec<u8>>> {
        let staging: Vec<wgpu::Buffer> = buffers
            .iter()
            .map(|b| {
                let s = self.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("read back"),
                    size: b.size(),
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                encoder.copy_buffer_to_buffer(b, 0, &s, 0, b.size());
                s
            })
            .collect();
        self.queue.submit([encoder.finish()]);
        for s in &staging {
            s.slice(..).map_async(wgpu::MapMode::Read, |_| {});
        }
        self.wait()?;
        staging
            .iter()
            .map(|s| {
                let bytes = s
                    .slice(..)
                    .get_mapped_range()
                    .map_err(|e| Error::Internal(format!("GPU {}: read-back: {e}", self.info)))?
                    .to_vec();
                s.unmap();
                Ok(bytes)
            })
            .collect::<Result<Vec<_>>>()
    }

    /// A compute pipeline from WGSL source with entry point `main` and an inferred layout.
    pub(crate) fn compute_pipeline(&self, label: &str, source: &str) -> wgpu::ComputePipeline {
        super::pipelines::compute_pipeline(&self.device, label, source)
    }

    /// Run `pipeline` over `groups` workgroups with `buffers` bound at bindings 0, 1, … of group 0.
    pub(crate) fn dispatch(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        pipeline: &wgpu::ComputePipeline,
        resources: &[wgpu::BindingResource<'_>],
        groups: [u32; 3],
    ) {
        let entries: Vec<wgpu::BindGroupEntry> = resources
            .iter()
            .enumerate()
            .map(|(i, r)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: r.clone(),
            })
            .collect();
        let bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(0),
            entries: &entries,
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups(groups[0], groups[1], groups[2]);
    }

    /// A fresh command encoder.
    pub(crate) fn encoder(&self) -> wgpu::CommandEncoder {
        self.device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None })
    }
}
