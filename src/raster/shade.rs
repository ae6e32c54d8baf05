//! Shading models evaluated at a sample of a set-up triangle.
//!
//! Based on: James Blinn. Models of Light Reflection for Computer Synthesized Pictures.
//! SIGGRAPH 1977 (the half-vector highlight); the OpenGL 1.x fixed-function lighting equation for an
//! infinite light and infinite viewer (`GL_LIGHT_MODEL_LOCAL_VIEWER = false`), which Williams et al.
//! 2003 use for vertex-lit models; Williams et al. 2003 §5.4, the luminance model
//! Y = k_a·T + k_d·T·(N·L) + (N·H)^n, where texture modulates ambient and diffuse but not the
//! highlight (separate specular colour).
//!
//! Colour = T ∘ K_d ∘ C_vertex ∘ (k_a + Σ_l c_l·max(N·L_l, 0)) + K_s ∘ Σ_l c_l·max(N·H_l, 0)^n
//! (highlight only where N·L_l > 0). `gouraud` evaluates the bracketed light terms at vertices and
//! interpolates them; `phong` and `normal-mapped` evaluate them per sample with the interpolated
//! (and, for normal maps, perturbed) normal. Normals are not flipped for back faces: a flipped LOD
//! triangle turns dark, which is how it should show up. `pbr` gathers the material's textures
//! here (metallic–roughness G and B, occlusion R, emissive, the normal map with its scale; every
//! slot through its own sampler, transform and UV set) and evaluates `pbr.rs`; the back of a
//! double-sided material is lit with its normal reversed (glTF §3.9.6). Every shaded colour then
//! passes the display transform (`tonemap.rs`); the debug views do not.
//!
//! Interpolation is perspective-correct: screen-space barycentrics λ_i are weighted by 1/w_i and
//! renormalised, then mapped through the set-up triangle's corner barycentrics to the source
//! triangle. Texture derivatives come from the same mapping evaluated one pixel to the right and
//! one pixel down (analytic finite differences; no 2×2 quad needed).

use std::sync::Arc;

use glam::{Mat3, Vec3};

use super::bin::Binned;
use super::ibl::PreparedEnvironment;
use super::pbr::{self, ImageLight, PbrLight, SurfacePoint};
use super::prepare::UvFrames;
use super::setup::{Corners, SetupTri};
use super::tonemap::DisplayTransform;
use super::{PreparedMesh, Shading};
use crate::mesh::Mesh;

/// Everything shading needs for one frame.
#[derive(Debug)]
pub(crate) struct ShadeContext<'a> {
    pub mesh: &'a Mesh,
    pub prepared: &'a PreparedMesh,
    pub setup: &'a Binned,
    pub shading: Shading,
    /// Lights resolved for this camera, world space.
    pub lights: Vec<ResolvedLight>,
    pub ambient: f32,
    /// Per-vertex (diffuse light, specular) terms for `gouraud` (borrowed by region updates).
    pub vertex_light: std::borrow::Cow<'a, [(Vec3, Vec3)]>,
    /// Near and far distances and whether the projection is perspective (for the depth view).
    pub depth_range: (f32, f32, bool),
    /// The `pbr` model's frame state (for `Pbr` only).
    pub pbr: Option<&'a PbrFrame>,
    /// Exposure and tone mapping, applied to every shaded colour but the debug views'.
    pub display: DisplayTransform,
}

/// Light terms at a normal: (k_a + Σ c·max(N·L,0), K_s ∘ Σ c·max(N·H,0)^n).
pub(crate) fn light_terms(
    n: Vec3,
    lights: &[ResolvedLight],
    ambient: f32,
    ks: Vec3,
    shininess: f32,
) -> (Vec3, Vec3) {
    let mut diffuse = Vec3::splat(ambient);
    let mut spec = Vec3::ZERO;
    for light in lights {
        let ndl = n.dot(light.l);
        if ndl > 0.0 {
            diffuse += light.color * ndl;
            spec += light.color * highlight(n.dot(light.h).max(0.0), shininess);
        }
    }
    (diffuse, ks * spec)
}

/// x^n for the Blinn–Phong highlight; integer exponents (the common case: MTL `Ns`, the default
/// 32) by repeated multiplication, which is several times cheaper than `powf`.
fn highlight(x: f32, n: f32) -> f32 {
    if n.fract() == 0.0 && (0.0..=4096.0).contains(&n) {
        x.powi(n as i32)
    } else {
        x.powf(n)
    }
}

/// A light resolved for one camera: direction towards it, colour, and the Blinn half vector
/// (constant per frame for a directional light and an infinite viewer).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ResolvedLight {
    pub l: Vec3,
    pub color: Vec3,
    pub h: Vec3,
}

impl ResolvedLight {
    /// The scene's lights resolved for `camera`.
    pub fn for_camera(lights: &[crate::scene::Light], camera: &crate::scene::Camera) -> Vec<Self> {
        lights
            .iter()
            .filter_map(|l| l.resolve(camera))
            .map(|(dir, color)| ResolvedLight::new(dir, color, camera.to_eye()))
            .collect()
    }

    pub fn new(l: Vec3, color: Vec3, to_eye: Vec3) -> ResolvedLight {
        ResolvedLight {
            l,
            color,
            h: (l + to_eye).normalize_or_zero(),
        }
    }
}

/// The three edge functions of set-up triangle `st` at screen point (x, y) in pixels, in px²
/// (twice the sub-triangle areas): divided by twice the triangle's area ([`SetupTri::area`]),
/// they are the screen-space barycentric weights of the corners.
fn edge_values(st: &SetupTri, x: f64, y: f64) -> [f64; 3] {
    let p =
        st.v.map(|q| [q[0] as f64 * (1.0 / 256.0), q[1] as f64 * (1.0 / 256.0)]);
    let edge = |a: [f64; 2], b: [f64; 2]| (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]);
    [edge(p[1], p[2]), edge(p[2], p[0]), edge(p[0], p[1])]
}

/// Screen-space barycentrics λ of set-up triangle `st` at screen point (x, y) in pixels.
fn screen_barycentrics(st: &SetupTri, x: f64, y: f64) -> [f64; 3] {
    // `area()` is in Fx24_8² units: 65536 per px².
    let inv_area = 65536.0 / st.area() as f64;
    edge_values(st, x, y).map(|e| e * inv_area)
}

/// Source-triangle barycentrics at screen point (x, y) in pixels of set-up triangle `st` whose
/// corners have source barycentrics `corners`.
///
/// Perspective correction weights the screen-space barycentrics by 1/w and renormalises; the
/// common 1/area factor cancels in the renormalisation, so the edge values are used unscaled, and
/// the renormalisation is one reciprocal (this runs for every shaded pixel, and the four
/// divisions it had were a third of its time). Both are f64 rounded once to f32 at the end.
pub(crate) fn source_barycentrics(st: &SetupTri, corners: &Corners, x: f64, y: f64) -> Vec3 {
    let e = edge_values(st, x, y);
    let mu = [0, 1, 2].map(|i| e[i] * st.inv_w[i] as f64);
    let sum = mu[0] + mu[1] + mu[2];
    let mu = if sum != 0.0 {
        let r = 1.0 / sum;
        mu.map(|m| (m * r) as f32)
    } else {
        [1.0 / 3.0; 3]
    };
    corners.apply(mu)
}

/// The `pbr` model's per-frame state: its lights, the image light, and the viewer.
#[derive(Debug)]
pub(crate) struct PbrFrame {
    pub lights: Vec<PbrLight>,
    pub lut: &'static super::ibl::BrdfLut,
    pub environment: Arc<PreparedEnvironment>,
    /// World → environment map frame.
    pub to_map: Mat3,
    pub intensity: f32,
    pub multiple_scattering: bool,
    /// The eye, for a perspective camera; `None`: orthographic, looking along −`to_eye`.
    pub eye: Option<Vec3>,
    pub to_eye: Vec3,
}

impl PbrFrame {
    /// The state for `scene` seen from `camera`.
    pub fn new(
        scene: &crate::scene::Scene,
        camera: &crate::scene::Camera,
        multiple_scattering: bool,
    ) -> PbrFrame {
        PbrFrame {
            lights: PbrLight::for_camera(&scene.lights_for(true), camera),
            lut: super::ibl::BrdfLut::get(),
            environment: super::ibl::prepared(&scene.environment),
            to_map: scene.environment_frame(),
            intensity: scene.environment_intensity,
            multiple_scattering,
            eye: matches!(
                camera.projection,
                crate::scene::Projection::Perspective { .. }
            )
            .then_some(camera.eye),
            to_eye: camera.to_eye(),
        }
    }
}

impl ShadeContext<'_> {
    /// Shade set-up triangle `id` at screen point (x, y) (pixels): the display colour (after
    /// exposure and tone mapping; the debug views as they are).
    pub fn shade(&self, id: u32, x: f64, y: f64) -> Vec3 {
        let st = self.setup.get(id);
        let corners = self.setup.corners(id);
        let tri = self.mesh.triangles()[st.tri as usize].map(|i| i as usize);
        let b = source_barycentrics(st, &corners, x, y);
        let lerp3 = |a: &[Vec3]| a[tri[0]] * b.x + a[tri[1]] * b.y + a[tri[2]] * b.z;

        match self.shading {
            Shading::Normals => return lerp3(self.mesh.normals()).normalize_or_zero() * 0.5 + 0.5,
            Shading::Depth => {
                let (near, far, perspective) = self.depth_range;
                let lambda = screen_barycentrics(st, x, y);
                let t = if perspective {
                    let inv_w: f64 = (0..3).map(|i| lambda[i] * st.inv_w[i] as f64).sum();
                    ((1.0 / inv_w) as f32 - near) / (far - near)
                } else {
                    (0..3).map(|i| lambda[i] as f32 * st.z[i]).sum()
                };
                return Vec3::splat(1.0 - t.clamp(0.0, 1.0));
            }
            _ => {}
        }

        // Texture coordinates of every set a slot reads, with their steps one pixel right and
        // one down (for mip selection).
        let used = self.prepared.sets_used;
        let mut frames = UvFrames::default();
        if used.iter().any(|&u| u) && (self.mesh.uvs().is_some() || self.mesh.uvs1().is_some()) {
            let bx = source_barycentrics(st, &corners, x + 1.0, y);
            let by = source_barycentrics(st, &corners, x, y + 1.0);
            for (set, (frame, &wanted)) in frames.0.iter_mut().zip(&used).enumerate() {
                if let (true, Some(uvs)) = (wanted, self.mesh.uv_set(set as u32)) {
                    let uv_at =
                        |bb: Vec3| uvs[tri[0]] * bb.x + uvs[tri[1]] * bb.y + uvs[tri[2]] * bb.z;
                    let uv = uv_at(b);
                    *frame = Some((uv, uv_at(bx) - uv, uv_at(by) - uv));
                }
            }
        }
        let surface = Surface {
            mesh: self.mesh,
            prepared: self.prepared,
            shading: self.shading,
            lights: &self.lights,
            ambient: self.ambient,
            vertex_light: &self.vertex_light,
            pbr: self.pbr,
        };
        self.display
            .apply(surface.color(st.tri as usize, b, &frames))
    }
}

/// The one shading equation (the module comment's), for any pass that knows which source
/// triangle it sees and where: the screen pass above, and the texture-space pass.
pub(crate) struct Surface<'a> {
    pub mesh: &'a Mesh,
    pub prepared: &'a PreparedMesh,
    /// `Unlit`, `Gouraud`, `Phong`, `NormalMapped` or `Pbr` (the debug views are the screen
    /// pass's).
    pub shading: Shading,
    /// Lights, world space, resolved for the viewer of this sample.
    pub lights: &'a [ResolvedLight],
    pub ambient: f32,
    /// Per-vertex (diffuse, specular) terms, for `Gouraud` only.
    pub vertex_light: &'a [(Vec3, Vec3)],
    /// The `pbr` model's frame; `Pbr` without one shades as `Phong`.
    pub pbr: Option<&'a PbrFrame>,
}

impl Surface<'_> {
    /// The scene-linear colour of source triangle `t` at barycentrics `b`, with the texture
    /// coordinates and their steps one pixel right and one down (`frames`, for mip selection)
    /// where the mesh has UVs.
    pub fn color(&self, t: usize, b: Vec3, frames: &UvFrames) -> Vec3 {
        let tri = self.mesh.triangles()[t].map(|i| i as usize);
        let lerp3 = |a: &[Vec3]| a[tri[0]] * b.x + a[tri[1]] * b.y + a[tri[2]] * b.z;
        let material_id = self.mesh.material_ids()[t] as usize;
        let material = &self.mesh.materials()[material_id];
        let textures = &self.prepared.materials[material_id];
        // Surface colour: base colour × vertex colour × texture.
        let mut albedo = material.base_color;
        if let Some(colors) = self.mesh.colors() {
            albedo *= lerp3(colors);
        }
        if let Some(texel) = textures.base.as_ref().and_then(|s| s.sample(frames)) {
            albedo *= texel;
        }
        if self.shading == Shading::Unlit {
            return albedo;
        }
        if let (Shading::Pbr, Some(frame)) = (self.shading, self.pbr) {
            return self.pbr_color(t, b, frames, albedo, frame);
        }

        let (diffuse, spec) = match self.shading {
            Shading::Gouraud => {
                let vl = &self.vertex_light;
                let d = vl[tri[0]].0 * b.x + vl[tri[1]].0 * b.y + vl[tri[2]].0 * b.z;
                let s = vl[tri[0]].1 * b.x + vl[tri[1]].1 * b.y + vl[tri[2]].1 * b.z;
                (d, s)
            }
            _ => {
                let mut n = lerp3(self.mesh.normals()).normalize_or_zero();
                if self.shading == Shading::NormalMapped {
                    n = self.normal_mapped(t, b, frames, n);
                }
                light_terms(
                    n,
                    self.lights,
                    self.ambient,
                    material.specular,
                    material.shininess,
                )
            }
        };
        albedo * diffuse + spec
    }

    /// The interpolated normal `n` of triangle `t` perturbed by its material's normal map (with
    /// the map's scale), or `n` where there is none.
    fn normal_mapped(&self, t: usize, b: Vec3, frames: &UvFrames, n: Vec3) -> Vec3 {
        let tri = self.mesh.triangles()[t].map(|i| i as usize);
        let material_id = self.mesh.material_ids()[t] as usize;
        let scale = self.mesh.materials()[material_id].normal_scale;
        let slot = &self.prepared.materials[material_id].normal;
        let (Some(slot), Some(tangents)) = (slot, &self.prepared.tangents) else {
            return n;
        };
        let Some(texel) = slot.sample(frames) else {
            return n;
        };
        let t4 = tangents[tri[0]] * b.x + tangents[tri[1]] * b.y + tangents[tri[2]] * b.z;
        let tangent = (t4.truncate() - n * n.dot(t4.truncate())).normalize_or_zero();
        let bitangent = n.cross(tangent) * if t4.w < 0.0 { -1.0 } else { 1.0 };
        let mut m = texel * 2.0 - 1.0;
        if scale != 1.0 {
            // glTF: the map's x and y scaled, then renormalised.
            m = (m * Vec3::new(scale, scale, 1.0)).normalize_or(Vec3::Z);
        }
        (tangent * m.x + bitangent * m.y + n * m.z).normalize_or(n)
    }

    /// The `pbr` model's radiance at triangle `t`, barycentrics `b`, base colour `base`.
    fn pbr_color(
        &self,
        t: usize,
        b: Vec3,
        frames: &UvFrames,
        base: Vec3,
        frame: &PbrFrame,
    ) -> Vec3 {
        let tri = self.mesh.triangles()[t].map(|i| i as usize);
        let p = self.mesh.positions();
        let position = p[tri[0]] * b.x + p[tri[1]] * b.y + p[tri[2]] * b.z;
        let v = frame.eye.map_or(frame.to_eye, |eye| {
            (eye - position).normalize_or(frame.to_eye)
        });
        let material_id = self.mesh.material_ids()[t] as usize;
        let material = &self.mesh.materials()[material_id];
        let textures = &self.prepared.materials[material_id];
        let n = self.mesh.normals();
        let mut normal = (n[tri[0]] * b.x + n[tri[1]] * b.y + n[tri[2]] * b.z).normalize_or_zero();
        // The back of a double-sided material is lit as its front (glTF §3.9.6).
        if material.double_sided
            && (p[tri[1]] - p[tri[0]]).cross(p[tri[2]] - p[tri[0]]).dot(v) < 0.0
        {
            normal = -normal;
        }
        normal = self.normal_mapped(t, b, frames, normal);
        let (mut metallic, mut roughness) = (material.metallic, material.roughness);
        if let Some(mr) = textures
            .metallic_roughness
            .as_ref()
            .and_then(|s| s.sample(frames))
        {
            roughness *= mr.y;
            metallic *= mr.z;
        }
        let occlusion = textures
            .occlusion
            .as_ref()
            .and_then(|s| s.sample(frames))
            .map_or(1.0, |ao| 1.0 + material.occlusion_strength * (ao.x - 1.0));
        let mut emission = material.emission();
        if let Some(e) = textures.emissive.as_ref().and_then(|s| s.sample(frames)) {
            emission *= e;
        }
        let point = SurfacePoint {
            base,
            metallic: metallic.clamp(0.0, 1.0),
            roughness: roughness.clamp(0.0, 1.0),
            n: normal,
            v,
            position,
            occlusion,
            emission,
        };
        let image = ImageLight {
            prepared: &frame.environment,
            lut: frame.lut,
            to_map: frame.to_map,
            intensity: frame.intensity,
            multiple_scattering: frame.multiple_scattering,
        };
        pbr::shade(&point, &image, &frame.lights)
    }
}
