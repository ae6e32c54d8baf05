//! The texture-space pass: the mesh rendered into its own parametric domain — texture coordinates
//! as positions, everything else as on screen — giving, per texel, the source triangle, the 3D
//! point and normal it stands for (a geometry image), and the surface signal a viewer sees there.
//!
//! Based on: Lijun Qu, Gary Meyer. Perceptually Driven Interactive Geometry Remeshing. I3D 2006,
//! §4.3 ("we render the model into a 2D map by using texture coordinates instead of the original
//! vertices as vertex positions") and §5.1 (the regular sampling of the domain, after Alliez et
//! al. 2002).
//!
//! Visibility is the rasterizer's own (`setup`, `bin`, `edge`): the UV layout becomes a flat mesh
//! seen by an orthographic camera, one sample at each texel's centre, so coverage follows the
//! top-left rule and ties go to the lower triangle index as in every frame. The same geometry
//! also gives each texel's coverage count, which finds overlapping charts.
//!
//! Decisions:
//! - The domain is the square around the UVs' bounding box (half a texel of margin), so tiled or
//!   offset coordinates work; row 0 is the top (largest v), as a texture image is stored.
//! - Shading is the renderer's equation (`shade::Surface`) with per-texel normals and normal maps
//!   (`normal-mapped`, Phong where a material has none), each texel seen head-on: the viewer looks
//!   along the interpolated normal, and camera-attached lights (the headlight) are resolved for
//!   that viewer, world-space lights as they are. The signal is then what the surface shows where
//!   it faces the viewer, independent of any one camera: texture, normal-map relief, vertex
//!   colours, and the diffuse and specular response to fixed lights.
//! - Barycentrics come from the texel centre's UV in the triangle's UV corners (exact in 2D,
//!   clamped to the triangle), not from the set-up's fixed-point edge values.

use std::sync::Arc;

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use super::frame::NO_TRIANGLE;
use super::prepare::UvFrames;
use super::shade::{ResolvedLight, Surface};
use super::{RenderScene, RenderSettings, SamplePattern, Shading};
use crate::error::{Error, Result};
use crate::mesh::{LoadOptions, Mesh, MeshData, Source};
use crate::scene::{Camera, Projection};

/// The mesh in its parametric domain, `size × size` texels, row-major.
#[derive(Debug, Clone)]
pub struct TextureSpace {
    /// Texels per side.
    pub size: usize,
    /// The UV of the domain's top-left corner (u smallest, v largest).
    pub origin: Vec2,
    /// UV units per texel.
    pub texel: f32,
    /// Source triangle per texel ([`NO_TRIANGLE`] where no chart covers the texel's centre).
    pub triangle: Vec<u32>,
    /// Barycentrics of the texel centre in its triangle (zero where uncovered).
    pub barycentric: Vec<Vec3>,
    /// The 3D point per texel (model units; zero where uncovered).
    pub position: Vec<Vec3>,
    /// The interpolated unit normal per texel (zero where uncovered).
    pub normal: Vec<Vec3>,
    /// The surface signal, linear RGB (zero where uncovered).
    pub signal: Vec<Vec3>,
    /// Texels whose centre more than one triangle covers.
    pub overlapping: usize,
    /// Texels covered at all.
    pub covered: usize,
}

impl TextureSpace {
    /// The UV at texel coordinates (x, y) (texel centres at half-integers).
    pub fn uv_at(&self, x: f32, y: f32) -> Vec2 {
        Vec2::new(
            self.origin.x + x * self.texel,
            self.origin.y - y * self.texel,
        )
    }

    /// Texel coordinates (continuous; centres at half-integers) of a UV.
    pub fn texel_of(&self, uv: Vec2) -> Vec2 {
        Vec2::new(
            (uv.x - self.origin.x) / self.texel,
            (self.origin.y - uv.y) / self.texel,
        )
    }
}

/// Barycentrics of `p` in the 2D triangle `t` (unclamped; `None` when it has no area).
pub fn barycentric_2d(p: Vec2, t: [Vec2; 3]) -> Option<Vec3> {
    let (e1, e2, d) = (t[1] - t[0], t[2] - t[0], p - t[0]);
    let det = e1.perp_dot(e2);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let v = d.perp_dot(e2) / det;
    let w = e1.perp_dot(d) / det;
    Some(Vec3::new(1.0 - v - w, v, w))
}

/// Render `scene`'s mesh into its texture domain at `size × size` texels. The mesh must have
/// texture coordinates.
pub fn texture_space(scene: &RenderScene, size: usize) -> Result<TextureSpace> {
    let mesh = scene.mesh();
    let Some(uvs) = mesh.uvs() else {
        return Err(Error::input(
            &mesh.source().path,
            "the mesh has no texture coordinates, and this needs its UV layout",
            "give a mesh with texture coordinates (unwrap it in a modelling tool first)",
        ));
    };
    let side = u32::try_from(size)
        .ok()
        .filter(|&s| (1..=RenderSettings::MAX_SIZE).contains(&s))
        .ok_or_else(|| {
            Error::Usage(format!(
                "texture-space map of {size} texels per side: use 1 to {}",
                RenderSettings::MAX_SIZE
            ))
        })?;
    // The square domain around the UVs, half a texel of margin on every side.
    let (lo, hi) = uvs.iter().fold(
        (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN)),
        |(a, b), &u| (a.min(u), b.max(u)),
    );
    let extent = (hi - lo).max_element().max(f32::MIN_POSITIVE);
    let texel = extent / (size as f32 - 1.0).max(1.0);
    let centre = (lo + hi) * 0.5;
    let half = texel * size as f32 * 0.5;
    let origin = Vec2::new(centre.x - half, centre.y + half);

    let (frame, overlapping) = render_layout(mesh, centre, half, side)?;

    let ids = frame.triangle_ids().to_vec();
    let covered = ids.iter().filter(|&&t| t != NO_TRIANGLE).count();
    let n = size * size;
    let mut out = TextureSpace {
        size,
        origin,
        texel,
        triangle: ids,
        barycentric: vec![Vec3::ZERO; n],
        position: vec![Vec3::ZERO; n],
        normal: vec![Vec3::ZERO; n],
        signal: vec![Vec3::ZERO; n],
        overlapping,
        covered,
    };
    let lights = &scene.scene().lights_for(false);
    let shading = Shading::NormalMapped;
    let (prepared, ambient) = (scene.prepared(), scene.scene().ambient);
    let triangles = &out.triangle;
    let (origin_uv, step) = (out.origin, out.texel);
    out.barycentric
        .par_chunks_mut(size)
        .zip(out.position.par_chunks_mut(size))
        .zip(out.normal.par_chunks_mut(size))
        .zip(out.signal.par_chunks_mut(size))
        .enumerate()
        .for_each(|(y, (((bary, pos), nrm), sig))| {
            let mut resolved: Vec<ResolvedLight> = Vec::with_capacity(lights.len());
            for x in 0..size {
                let t = triangles[y * size + x];
                if t == NO_TRIANGLE {
                    continue;
                }
                let tri = mesh.triangles()[t as usize].map(|i| i as usize);
                let uv = Vec2::new(
                    origin_uv.x + (x as f32 + 0.5) * step,
                    origin_uv.y - (y as f32 + 0.5) * step,
                );
                let b = barycentric_2d(uv, tri.map(|i| uvs[i]))
                    .map(|b| {
                        let b = b.max(Vec3::ZERO);
                        b / b.element_sum().max(f32::MIN_POSITIVE)
                    })
                    .unwrap_or(Vec3::splat(1.0 / 3.0));
                let lerp = |a: &[Vec3]| a[tri[0]] * b.x + a[tri[1]] * b.y + a[tri[2]] * b.z;
                let p = lerp(mesh.positions());
                let normal = lerp(mesh.normals()).normalize_or(Vec3::Z);
                let viewer = head_on(p, normal);
                resolved.clear();
                resolved.extend(
                    lights
                        .iter()
                        .filter_map(|l| l.resolve(&viewer))
                        .map(|(dir, color)| ResolvedLight::new(dir, color, normal)),
                );
                let surface = Surface {
                    mesh,
                    prepared,
                    shading,
                    lights: &resolved,
                    ambient,
                    vertex_light: &[],
                    pbr: None,
                };
                bary[x] = b;
                pos[x] = p;
                nrm[x] = normal;
                sig[x] = surface.color(
                    t as usize,
                    b,
                    &UvFrames([
                        Some((uv, Vec2::new(step, 0.0), Vec2::new(0.0, -step))),
                        None,
                    ]),
                );
            }
        });
    Ok(out)
}

/// The UV layout as a flat mesh in the plane z = 0, centred, seen from +z on a `side`² frame
/// `2·half` wide: its frame (triangle ids per texel) and the number of texels more than one
/// triangle covers.
fn render_layout(
    mesh: &crate::mesh::Mesh,
    centre: Vec2,
    half: f32,
    side: u32,
) -> Result<(super::Frame, usize)> {
    let flat = flat_layout(mesh, centre)?;
    let camera = Camera {
        eye: Vec3::Z,
        target: Vec3::ZERO,
        up: Vec3::Y,
        projection: Projection::Orthographic { half_height: half },
        near: 0.5,
        far: 1.5,
    };
    let settings = RenderSettings {
        width: side,
        height: side,
        samples: SamplePattern::Ordered(1),
        shading: Shading::Unlit,
        ..RenderSettings::DEFAULT
    };
    let flat_scene = RenderScene::of(Arc::new(flat));
    let frame = super::render(&flat_scene, &camera, &settings)?;
    let counts = super::coverage_counts(&flat_scene, &camera, &settings)?;
    let overlapping = counts.iter().filter(|&&c| c > 1).count();
    Ok((frame, overlapping))
}

/// A camera that sees the surface point `p` head-on: looking along `normal`.
fn head_on(p: Vec3, normal: Vec3) -> Camera {
    Camera {
        eye: p + normal,
        target: p,
        up: if normal.y.abs() < 0.99 {
            Vec3::Y
        } else {
            Vec3::Z
        },
        projection: Projection::Orthographic { half_height: 1.0 },
        near: 0.5,
        far: 1.5,
    }
}

/// `mesh`'s UV layout as a mesh in the plane z = 0, centred on `centre`, the same triangles in
/// the same order.
fn flat_layout(mesh: &Mesh, centre: Vec2) -> Result<Mesh> {
    let uvs = mesh.uvs().unwrap_or_default();
    let data = MeshData {
        positions: uvs.iter().map(|&u| (u - centre).extend(0.0)).collect(),
        normals: Some(vec![Vec3::Z; uvs.len()]),
        uvs: None,
        uvs1: None,
        colors: None,
        triangles: mesh.triangles().to_vec(),
        material_ids: Vec::new(),
        materials: Vec::new(),
        lights: Vec::new(),
        source: Source {
            edited: true,
            ..mesh.source().clone()
        },
        warnings: Vec::new(),
    };
    let flat = Mesh::new(data, &LoadOptions::default())?;
    debug_assert_eq!(flat.triangle_count(), mesh.triangle_count());
    Ok(flat)
}
