//! The renderer's pipelines and the formats they write, built from the device alone: the
//! visibility pass (`shaders/visibility.wgsl`, with and without back-face culling) and the shading
//! pass (`shaders/shade.wgsl`), and the one way every compute pipeline here is made. The device
//! (`context.rs`) caches one [`Pipelines`]; the renderer (`render.rs`) records passes with them.

const VISIBILITY_WGSL: &str = include_str!("shaders/visibility.wgsl");
const SHADE_WGSL: &str = include_str!("shaders/shade.wgsl");

/// The visibility pass's triangle-id target.
pub(super) const ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
/// The visibility pass's depth target.
pub(super) const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The visibility pipelines (with and without back-face culling) and the shading pipeline. They
/// depend only on the device: built once per device (`Gpu::render_pipelines`) and shared by
/// every scene (eval uploads one scene per LOD).
#[derive(Debug)]
pub(crate) struct Pipelines {
    pub(super) visibility: wgpu::RenderPipeline,
    pub(super) visibility_culled: wgpu::RenderPipeline,
    pub(super) shade: wgpu::ComputePipeline,
}

/// The visibility pipelines and the shading pipeline.
pub(crate) fn build(device: &wgpu::Device) -> Pipelines {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("visibility.wgsl"),
        source: wgpu::ShaderSource::Wgsl(VISIBILITY_WGSL.into()),
    });
    let visibility = |cull: Option<wgpu::Face>| {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("visibility"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                front_face: wgpu::FrontFace::Ccw,
                cull_mode: cull,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                // Strict: on equal depth the earlier triangle stays, as on the CPU.
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: ID_FORMAT,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        })
    };
    Pipelines {
        visibility: visibility(None),
        visibility_culled: visibility(Some(wgpu::Face::Back)),
        shade: compute_pipeline(device, "shade.wgsl", SHADE_WGSL),
    }
}

/// A compute pipeline from WGSL `source` with entry point `main`.
pub(crate) fn compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    source: &str,
) -> wgpu::ComputePipeline {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    })
}
