//! The GPU renderer: a [`RenderScene`] uploaded once, rendered from any camera into a [`Frame`].
//!
//! Upload (once per scene): one storage buffer of 18 floats per vertex (position, the vertex's
//! material for Gouraud, normal, tangent handedness, UV, colour, tangent, second UV — absent
//! attributes are zero/white), one of (i0, i1, i2, material) per triangle in source order, the
//! materials (every slot with its sampler, transform and UV set), and the CPU's mip pyramids
//! (`raster::MipTexture`, each texture once) flattened with a level table into up to eight pages,
//! each within one storage binding's size limit. The `pbr` model's image-based light (the CPU's
//! prefiltered chain, irradiance map and BRDF table, `raster::ibl`) is placed after the textures
//! as further levels, so the GPU shades from exactly the CPU's data.
//!
//! Per frame: stage 1, one draw of 3·T vertices per anti-aliasing sample into that sample's layer
//! of an id and a depth array target (visibility.wgsl); stage 2, one compute dispatch that groups
//! each pixel's samples by triangle, shades each triangle once and resolves (shade.wgsl); one
//! read-back.
//!
//! Decision: jittered single-sample visibility passes rather than MSAA. MSAA's sample positions
//! are fixed by the API (the standard 4× pattern is the CPU's rotated grid mirrored about the
//! diagonal) and its shading point is driver-chosen, and forward shading shades per fragment
//! where the CPU shades per triangle per pixel: measured, forward MSAA shading gave FLIP means up
//! to 0.015 against the CPU on textured models, the deferred mirror ≤ 5e-4. The price is one
//! draw per sample.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use glam::{Vec3, Vec4};

use super::Gpu;
use super::pipelines::{DEPTH_FORMAT, ID_FORMAT};
use crate::error::{Error, Result};
use crate::raster::RenderScene;
use crate::raster::{
    Frame, PbrLight, PreparedSlot, RenderSettings, ResolvedLight, Shading, ToneMapping,
    camera_setup,
};
use crate::scene::Camera;

/// Floats per vertex record (shade.wgsl's and visibility.wgsl's `VSTRIDE`).
const VSTRIDE: usize = 18;

/// Lights a GPU frame can hold (shade.wgsl's `MAX_LIGHTS`).
const MAX_LIGHTS: usize = 8;
/// Samples per pixel a GPU frame can hold (shade.wgsl's `MAX_SAMPLES`; the CPU's largest is 8×8).
const MAX_SAMPLES: usize = 64;
/// Texel pages (shade.wgsl binds `page0`..`page7`).
const PAGES: usize = 8;

/// shade.wgsl's `Globals`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Globals {
    mvp: [[f32; 4]; 4],
    lights: [GpuLight; MAX_LIGHTS],
    offsets: [[f32; 4]; MAX_SAMPLES],
    background: [f32; 4],
    ambient: f32,
    shading: u32,
    light_count: u32,
    flags: u32,
    near: f32,
    far: f32,
    perspective: u32,
    samples: u32,
    width: u32,
    height: u32,
    pad: [u32; 2],
    plights: [GpuPbrLight; MAX_LIGHTS],
    eye: [f32; 4],
    to_eye: [f32; 4],
    env_x: [f32; 4],
    env_y: [f32; 4],
    env_z: [f32; 4],
    env: [f32; 4],
    ibl: [u32; 4],
}

/// shade.wgsl's `PLight`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuPbrLight {
    pos_kind: [f32; 4],
    dir_range: [f32; 4],
    color_inner: [f32; 4],
    outer: [f32; 4],
}

/// shade.wgsl's `Slot`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuSlot {
    tex: [u32; 4],
    m: [f32; 4],
    o: [f32; 4],
}

/// shade.wgsl's `Material`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuMaterial {
    base_color: [f32; 4],
    specular: [f32; 4],
    pbr: [f32; 4],
    emission: [f32; 4],
    slots: [GpuSlot; 5],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuLevel {
    page: u32,
    offset: u32,
    width: u32,
    height: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuLight {
    l: [f32; 4],
    color: [f32; 4],
    h: [f32; 4],
}

/// visibility.wgsl's `Globals` and `Jitter`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Mvp {
    mvp: [[f32; 4]; 4],
}
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Jitter {
    ndc: [f32; 2],
    pad: [f32; 2],
}

/// A scene on the GPU.
#[derive(Debug)]
pub struct GpuScene {
    gpu: Arc<Gpu>,
    vertices: wgpu::Buffer,
    tris: wgpu::Buffer,
    materials: wgpu::Buffer,
    levels: wgpu::Buffer,
    pages: Vec<wgpu::Buffer>,
    triangle_count: u32,
    flags: u32,
    /// The lights of the Blinn–Phong models and of `pbr`.
    lights: [Vec<crate::scene::Light>; 2],
    ambient: f32,
    background: Vec3,
    /// Whether `auto` means `pbr` for this mesh.
    prefers_pbr: bool,
    /// World → environment map rotation, and the environment's intensity.
    to_map: glam::Mat3,
    environment_intensity: f32,
    /// First level of the prefiltered chain (then the irradiance map), and the BRDF table's.
    ibl_levels: [u32; 2],
}

impl GpuScene {
    /// Upload `scene`.
    pub fn new(gpu: Arc<Gpu>, scene: &RenderScene) -> Result<GpuScene> {
        gpu.clone()
            .checked("uploading the scene", || Self::upload(gpu, scene))
    }

    fn upload(gpu: Arc<Gpu>, scene: &RenderScene) -> Result<GpuScene> {
        let mesh = scene.mesh();
        let prepared = scene.prepared();
        let tri_count = mesh.triangles().len();
        if tri_count.saturating_mul(3) > u32::MAX as usize {
            return Err(Error::Usage(format!(
                "{tri_count} triangles are too many for one GPU draw; use --backend cpu"
            )));
        }
        let vertices = vertex_records(mesh, prepared);
        let tris: Vec<[u32; 4]> = mesh
            .triangles()
            .iter()
            .zip(mesh.material_ids())
            .map(|(t, &m)| [t[0], t[1], t[2], m])
            .collect();
        // Texture pyramids, each decoded texture once, packed into pages.
        let mut texels =
            Texels::new((gpu.device.limits().max_storage_buffer_binding_size / 16) as usize);
        let mut materials = Vec::with_capacity(mesh.materials().len());
        for (m, p) in mesh.materials().iter().zip(&prepared.materials) {
            let mut slots = [GpuSlot::zeroed(); 5];
            let prepared_slots = [
                &p.base,
                &p.metallic_roughness,
                &p.normal,
                &p.occlusion,
                &p.emissive,
            ];
            for (out, s) in slots.iter_mut().zip(prepared_slots) {
                if let Some(s) = s {
                    let at = texels.place(Arc::as_ptr(&s.mip), &mut s.mip.levels())?;
                    *out = gpu_slot(s, at);
                }
            }
            materials.push(GpuMaterial {
                base_color: m.base_color.extend(m.base_alpha).to_array(),
                specular: m.specular.extend(m.shininess).to_array(),
                pbr: [
                    m.metallic,
                    m.roughness,
                    m.normal_scale,
                    m.occlusion_strength,
                ],
                emission: m
                    .emission()
                    .extend(if m.double_sided { 1.0 } else { 0.0 })
                    .to_array(),
                slots,
            });
        }
        // The image-based light: nine prefiltered levels, the irradiance map, the BRDF table.
        let ibl = crate::raster::ibl::prepared(&scene.environment);
        let maps = ibl.levels.iter().chain(std::iter::once(&ibl.irradiance));
        let mut chain = maps.map(|m| (m.width(), m.height(), m.texels()));
        let chain_at = texels.place(std::ptr::null(), &mut chain)?;
        let lut: Vec<Vec3> = crate::raster::ibl::BrdfLut::get()
            .entries()
            .iter()
            .map(|e| e.extend(0.0))
            .collect();
        let n = crate::raster::ibl::LUT_SIZE;
        let lut_at = texels.place(
            std::ptr::null(),
            &mut std::iter::once((n, n, lut.as_slice())),
        )?;
        let Texels {
            levels, mut pages, ..
        } = texels;
        let limit = gpu.device.limits().max_storage_buffer_binding_size;
        if (vertices.len() * 4) as u64 > limit || (tris.len() * 16) as u64 > limit {
            return Err(Error::Usage(format!(
                "{} vertices and {tri_count} triangles exceed this GPU's storage-buffer limit of \
                 {limit} bytes; use --backend cpu",
                mesh.vertex_count()
            )));
        }
        let lights = [scene.lights_for(false), scene.lights_for(true)];
        if let Some(too_many) = lights.iter().find(|l| l.len() > MAX_LIGHTS) {
            // Blinn–Phong and pbr lights alike are counted against the frame's slots.
            return Err(Error::Usage(format!(
                "the GPU renderer takes at most {MAX_LIGHTS} lights, the scene has {}; use \
                 --backend cpu",
                too_many.len()
            )));
        }
        pages.resize(PAGES, Vec::new());
        let flags = u32::from(mesh.uvs().is_some())
            | (u32::from(mesh.colors().is_some()) << 1)
            | (u32::from(prepared.tangents.is_some()) << 2)
            | (u32::from(mesh.uvs1().is_some()) << 3);
        Ok(GpuScene {
            vertices: gpu.storage("vertices", bytemuck::cast_slice(&vertices)),
            tris: gpu.storage("triangles", bytemuck::cast_slice(&tris)),
            materials: gpu.storage("materials", bytemuck::cast_slice(&materials)),
            levels: gpu.storage("texture levels", bytemuck::cast_slice(&levels)),
            pages: pages
                .iter()
                .map(|p| gpu.storage("texels", bytemuck::cast_slice(p)))
                .collect(),
            triangle_count: tri_count as u32,
            flags,
            lights,
            ambient: scene.ambient,
            background: scene.background,
            prefers_pbr: mesh.prefers_pbr(),
            to_map: scene.environment_frame(),
            environment_intensity: scene.environment_intensity,
            ibl_levels: [chain_at[0], lut_at[0]],
            gpu,
        })
    }

    /// The device this scene lives on.
    pub fn gpu(&self) -> &Arc<Gpu> {
        &self.gpu
    }

    /// Render from `camera`: the same [`Frame`] as [`crate::raster::render`] within the parity
    /// tolerances of `tests/integration/gpu.rs`.
    pub fn render(&self, camera: &Camera, settings: &RenderSettings) -> Result<Frame> {
        settings.check()?;
        self.gpu
            .checked("rendering", || self.render_unchecked(camera, settings))
    }

    fn render_unchecked(&self, camera: &Camera, settings: &RenderSettings) -> Result<Frame> {
        let gpu = &self.gpu;
        // `auto` becomes the model the mesh's materials call for, as on the CPU.
        let mut settings = *settings;
        if settings.shading == Shading::Auto {
            settings.shading = if self.prefers_pbr {
                Shading::Pbr
            } else {
                Shading::Gouraud
            };
        }
        let settings = &settings;
        let (w, h) = (settings.width, settings.height);
        let limits = gpu.device.limits();
        let offsets = settings.samples.offsets();
        let samples = offsets.len() as u32;
        if w > limits.max_texture_dimension_2d
            || h > limits.max_texture_dimension_2d
            || samples > limits.max_texture_array_layers
        {
            return Err(Error::Usage(format!(
                "{w}x{h} pixels with {samples} samples exceeds this GPU's {} pixels per side or \
                 {} layers; use --backend cpu",
                limits.max_texture_dimension_2d, limits.max_texture_array_layers
            )));
        }
        let globals = self.globals(camera, settings, &offsets);
        let mvp = gpu.uniform(
            "visibility globals",
            bytemuck::bytes_of(&Mvp { mvp: globals.mvp }),
        );
        let globals = gpu.uniform("shading globals", bytemuck::bytes_of(&globals));
        let ids = sample_target(gpu, "triangle ids", ID_FORMAT, w, h, samples);
        let depth = sample_target(gpu, "depth", DEPTH_FORMAT, w, h, samples);
        let mut encoder = gpu.encoder();
        self.visibility_passes(&mut encoder, settings, &offsets, &mvp, &ids, &depth);
        self.shade_and_read(encoder, &globals, &ids, &depth, (w, h))
    }

    /// The shading pass's uniforms for `camera`: matrices, lights of both models, sample
    /// offsets, the environment and the display transform.
    fn globals(&self, camera: &Camera, settings: &RenderSettings, offsets: &[[i64; 2]]) -> Globals {
        let (w, h) = (settings.width, settings.height);
        let samples = offsets.len() as u32;
        let to_px = |o: i64| o as f32 / 256.0;
        let (mvp, (near, far, perspective)) = camera_setup(camera, w, h);
        let mut lights = [GpuLight::zeroed(); MAX_LIGHTS];
        let resolved = ResolvedLight::for_camera(&self.lights[0], camera);
        for (out, l) in lights.iter_mut().zip(&resolved) {
            *out = GpuLight {
                l: l.l.extend(0.0).to_array(),
                color: l.color.extend(0.0).to_array(),
                h: l.h.extend(0.0).to_array(),
            };
        }
        let mut sample_offsets = [[0.0f32; 4]; MAX_SAMPLES];
        for (out, o) in sample_offsets.iter_mut().zip(offsets) {
            *out = [to_px(o[0]), to_px(o[1]), 0.0, 0.0];
        }
        let mut plights = [GpuPbrLight::zeroed(); MAX_LIGHTS];
        let pbr_lights = PbrLight::for_camera(&self.lights[1], camera);
        for (out, l) in plights.iter_mut().zip(&pbr_lights) {
            *out = gpu_pbr_light(l);
        }
        let display = settings.display();
        let perspective_eye = matches!(
            camera.projection,
            crate::scene::Projection::Perspective { .. }
        );
        let rows = self.to_map.transpose();
        Globals {
            mvp: mvp.to_cols_array_2d(),
            lights,
            offsets: sample_offsets,
            background: self.background.extend(1.0).to_array(),
            ambient: self.ambient,
            shading: shading_code(settings.shading),
            light_count: resolved.len() as u32,
            flags: self.flags,
            near,
            far,
            perspective: u32::from(perspective),
            samples,
            width: w,
            height: h,
            pad: [0; 2],
            plights,
            eye: camera
                .eye
                .extend(f32::from(u8::from(perspective_eye)))
                .to_array(),
            to_eye: camera.to_eye().extend(0.0).to_array(),
            env_x: rows.x_axis.extend(0.0).to_array(),
            env_y: rows.y_axis.extend(0.0).to_array(),
            env_z: rows.z_axis.extend(0.0).to_array(),
            env: [
                self.environment_intensity,
                f32::from(u8::from(settings.multiple_scattering)),
                display.scale,
                0.0,
            ],
            ibl: [
                self.ibl_levels[0],
                self.ibl_levels[1],
                pbr_lights.len() as u32,
                match display.tone_mapping {
                    ToneMapping::Linear => 0,
                    ToneMapping::Aces => 1,
                    ToneMapping::PbrNeutral => 2,
                },
            ],
        }
    }

    /// Stage 1: one visibility pass per sample, into layer k of `ids` and `depth`.
    fn visibility_passes(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        settings: &RenderSettings,
        offsets: &[[i64; 2]],
        mvp: &wgpu::Buffer,
        ids: &wgpu::Texture,
        depth: &wgpu::Texture,
    ) {
        let gpu = &self.gpu;
        let pipelines = gpu.render_pipelines();
        let (w, h) = (settings.width, settings.height);
        let to_px = |o: i64| o as f32 / 256.0;
        let layer = |t: &wgpu::Texture, k: u32| {
            t.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: k,
                array_layer_count: Some(1),
                ..Default::default()
            })
        };
        let visibility = if settings.cull_backfaces {
            &pipelines.visibility_culled
        } else {
            &pipelines.visibility
        };
        for (k, o) in offsets.iter().enumerate() {
            // Move sample (ox, oy) of every pixel onto the pixel centre.
            let shift = |o: i64| 0.5 - to_px(o);
            let jitter = Jitter {
                ndc: [2.0 * shift(o[0]) / w as f32, -2.0 * shift(o[1]) / h as f32],
                pad: [0.0; 2],
            };
            let jitter = gpu.uniform("jitter", bytemuck::bytes_of(&jitter));
            let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("visibility"),
                layout: &visibility.get_bind_group_layout(0),
                entries: &[(0, mvp), (1, &self.vertices), (2, &self.tris), (3, &jitter)].map(
                    |(binding, b)| wgpu::BindGroupEntry {
                        binding,
                        resource: b.as_entire_binding(),
                    },
                ),
            });
            let (id_view, depth_view) = (layer(ids, k as u32), layer(depth, k as u32));
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("visibility"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &id_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color {
                            r: u32::MAX as f64,
                            ..wgpu::Color::TRANSPARENT
                        }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(visibility);
            pass.set_bind_group(0, &bind, &[]);
            pass.draw(0..self.triangle_count * 3, 0..1);
        }
    }

    /// Stage 2: shade and resolve every pixel from the sample layers, and read the frame back.
    fn shade_and_read(
        &self,
        mut encoder: wgpu::CommandEncoder,
        globals: &wgpu::Buffer,
        ids: &wgpu::Texture,
        depth: &wgpu::Texture,
        (w, h): (u32, u32),
    ) -> Result<Frame> {
        let gpu = &self.gpu;
        let pipelines = gpu.render_pipelines();
        let n = (w * h) as u64;
        let out_color = gpu.output("resolved colour", n * 16);
        let out_aux = gpu.output("resolved depth and id", n * 8);
        let array = |t: &wgpu::Texture| {
            t.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            })
        };
        let (ids_all, depth_all) = (array(ids), array(depth));
        let mut resources = vec![
            globals.as_entire_binding(),
            self.vertices.as_entire_binding(),
            self.tris.as_entire_binding(),
            self.materials.as_entire_binding(),
            self.levels.as_entire_binding(),
        ];
        resources.extend(self.pages.iter().map(|p| p.as_entire_binding()));
        resources.extend([
            wgpu::BindingResource::TextureView(&ids_all),
            wgpu::BindingResource::TextureView(&depth_all),
            out_color.as_entire_binding(),
            out_aux.as_entire_binding(),
        ]);
        gpu.dispatch(
            &mut encoder,
            &pipelines.shade,
            &resources,
            [w.div_ceil(8), h.div_ceil(8), 1],
        );
        let out = gpu.read_back(encoder, &[&out_color, &out_aux])?;
        let px: &[[f32; 4]] = bytemuck::cast_slice(&out[0]);
        let aux: &[[u32; 2]] = bytemuck::cast_slice(&out[1]);
        let n = n as usize;
        Ok(Frame {
            width: w,
            height: h,
            color: px[..n]
                .iter()
                .map(|p| Vec3::new(p[0], p[1], p[2]))
                .collect(),
            depth: aux[..n].iter().map(|a| f32::from_bits(a[0])).collect(),
            coverage: px[..n].iter().map(|p| p[3]).collect(),
            triangle: aux[..n].iter().map(|a| a[1]).collect(),
        })
    }
}

/// One record of `VSTRIDE` floats per vertex: position, material, normal, tangent sign, UV,
/// colour, tangent, second UV set.
fn vertex_records(mesh: &crate::mesh::Mesh, prepared: &crate::raster::PreparedMesh) -> Vec<f32> {
    let mut vertices = vec![0f32; mesh.vertex_count() * VSTRIDE];
    for (v, rec) in vertices.chunks_exact_mut(VSTRIDE).enumerate() {
        rec[0..3].copy_from_slice(&mesh.positions()[v].to_array());
        let m = prepared.vertex_material[v];
        rec[3] = f32::from_bits(if m == u32::MAX { 0 } else { m });
        rec[4..7].copy_from_slice(&mesh.normals()[v].to_array());
        let t = prepared
            .tangents
            .as_ref()
            .map_or(Vec4::new(0.0, 0.0, 0.0, 1.0), |t| t[v]);
        rec[7] = t.w;
        if let Some(uvs) = mesh.uvs() {
            rec[8..10].copy_from_slice(&uvs[v].to_array());
        }
        let c = mesh.colors().map_or(Vec3::ONE, |c| c[v]);
        rec[10..13].copy_from_slice(&c.to_array());
        rec[13..16].copy_from_slice(&t.truncate().to_array());
        if let Some(uvs) = mesh.uvs1() {
            rec[16..18].copy_from_slice(&uvs[v].to_array());
        }
    }
    vertices
}

/// Texture levels packed into pages of at most one storage binding each; each decoded texture
/// placed once (keyed by address; only looked up).
struct Texels {
    page_texels: usize,
    levels: Vec<GpuLevel>,
    pages: Vec<Vec<[f32; 4]>>,
    placed: Vec<(*const crate::raster::MipTexture, [u32; 2])>,
}

impl Texels {
    fn new(page_texels: usize) -> Texels {
        Texels {
            page_texels,
            levels: Vec::new(),
            pages: vec![Vec::new()],
            placed: Vec::new(),
        }
    }

    /// Place a pyramid's levels (or find where `key`'s were placed); returns (first level,
    /// level count). A null `key` is never looked up.
    fn place(
        &mut self,
        key: *const crate::raster::MipTexture,
        all: &mut dyn Iterator<Item = (usize, usize, &[Vec3])>,
    ) -> Result<[u32; 2]> {
        if let Some((_, at)) = self.placed.iter().find(|(p, _)| *p == key) {
            return Ok(*at);
        }
        let first = self.levels.len() as u32;
        for (w, h, px) in all {
            if px.len() > self.page_texels {
                return Err(too_big(w, h));
            }
            if self.pages.last().map_or(0, Vec::len) + px.len() > self.page_texels {
                self.pages.push(Vec::new());
            }
            if self.pages.len() > PAGES {
                return Err(too_big(w, h));
            }
            let index = (self.pages.len() - 1) as u32;
            let page = self.pages.last_mut().expect("one page at least");
            self.levels.push(GpuLevel {
                page: index,
                offset: page.len() as u32,
                width: w as u32,
                height: h as u32,
            });
            page.extend(px.iter().map(|c| c.extend(1.0).to_array()));
        }
        let at = [first, self.levels.len() as u32 - first];
        if !key.is_null() {
            self.placed.push((key, at));
        }
        Ok(at)
    }
}

/// A render target of `samples` layers at `w` × `h`.
fn sample_target(
    gpu: &Gpu,
    label: &str,
    format: wgpu::TextureFormat,
    w: u32,
    h: u32,
    samples: u32,
) -> wgpu::Texture {
    gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: samples,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    })
}

/// shade.wgsl's `Slot` for a prepared slot placed at levels `at` (first, count).
fn gpu_slot(s: &PreparedSlot, at: [u32; 2]) -> GpuSlot {
    use crate::mesh::Wrap;
    let st = s.sampler;
    let wrap = |w: Wrap| match w {
        Wrap::Repeat => 0u32,
        Wrap::ClampToEdge => 1,
        Wrap::MirroredRepeat => 2,
    };
    let mip = match st.mip {
        None => 0u32,
        Some(false) => 1,
        Some(true) => 2,
    };
    let bits = wrap(st.wrap[0])
        | (wrap(st.wrap[1]) << 2)
        | (u32::from(st.mag_linear) << 4)
        | (u32::from(st.min_linear) << 5)
        | (mip << 6);
    // The transform as an affine map in lodeval's UV convention.
    let (m, o) = match &s.transform {
        None => ([1.0, 0.0, 0.0, 1.0], [0.0; 4]),
        Some(t) => {
            let o = t.apply(glam::Vec2::ZERO);
            let (c0, c1) = (t.apply_vector(glam::Vec2::X), t.apply_vector(glam::Vec2::Y));
            ([c0.x, c0.y, c1.x, c1.y], [o.x, o.y, 1.0, 0.0])
        }
    };
    GpuSlot {
        tex: [at[0], at[1], s.set as u32, bits],
        m,
        o,
    }
}

/// shade.wgsl's `PLight` for a light of the `pbr` model.
fn gpu_pbr_light(l: &PbrLight) -> GpuPbrLight {
    let (kind, position, direction, intensity, range, inner, outer) = match *l {
        PbrLight::Directional { l, irradiance } => (0.0, Vec3::ZERO, l, irradiance, None, 1.0, 1.0),
        PbrLight::Point {
            position,
            intensity,
            range,
        } => (1.0, position, Vec3::ZERO, intensity, range, 1.0, 1.0),
        PbrLight::Spot {
            position,
            direction,
            intensity,
            range,
            cos_inner,
            cos_outer,
        } => (
            2.0, position, direction, intensity, range, cos_inner, cos_outer,
        ),
    };
    GpuPbrLight {
        pos_kind: position.extend(kind).to_array(),
        dir_range: direction.extend(range.unwrap_or(0.0)).to_array(),
        color_inner: intensity.extend(inner).to_array(),
        outer: [outer, 0.0, 0.0, 0.0],
    }
}

fn too_big(w: usize, h: usize) -> Error {
    Error::Usage(format!(
        "a {w}x{h} texture level does not fit this GPU's storage-buffer limit (with the scene's \
         other textures); use --backend cpu"
    ))
}

fn shading_code(s: Shading) -> u32 {
    match s {
        Shading::Unlit => 0,
        Shading::Gouraud => 1,
        Shading::Phong => 2,
        Shading::NormalMapped => 3,
        Shading::Normals => 4,
        Shading::Depth => 5,
        // `auto` is resolved before a frame is shaded.
        Shading::Pbr | Shading::Auto => 6,
    }
}
