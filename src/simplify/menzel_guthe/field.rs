//! §4.2 and §5: the reflectance field of one surface point — its shaded colour for every view
//! and light direction, in the point's own tangent frame — sampled on the paper's hemispherical
//! grid and turned into JND-scaled opponent responses.
//!
//! Based on: Menzel & Guthe 2010, §4.2 (Figure 5: a hemisphere rendered with its normal parallel
//! to the view direction, with the light elevation varied) and §5 (resolution 16 × 16 × 32 × 16
//! over α_b, α_t, α_n/φ_i, θ_i; "the same shader that is used to render the model").
//!
//! The grid, as built here:
//! - (α_b, α_t): a `side` × `side` orthographic image of a unit hemisphere seen along its axis;
//!   each pixel inside the disc gives a surface normal n = (x, y, √(1 − x² − y²)) relative to the
//!   view direction v = +z (the pixels outside the disc are not samples). Tilting the surface
//!   about its tangent and bitangent moves through this image.
//! - α_n / φ_i: `rotations` turns of the surface's tangent frame about its normal (at every
//!   pixel the frame is x projected onto the tangent plane, turned by α_n). Turning the surface
//!   about its normal is the same as turning the light about it (the paper's one shared
//!   dimension); it matters only for anisotropic shading, here a normal map.
//! - θ_i: `elevations` angles between the light and the view direction, from 0 (a headlight) to
//!   `max_elevation`, the light in the x–z plane.
//!
//! Shading is the rasterizer's own (`raster::shade::light_terms`, Blinn–Phong with an ambient
//! term): colour = albedo ∘ (k_a + c·max(n·l, 0)) + K_s ∘ c·max(n·h, 0)^s, the albedo already the
//! product of base colour, vertex colour and texture at the point, the normal perturbed by the
//! normal map where there is one. A point's field depends only on these material inputs: the
//! orientation of the surface enters the comparison as a rotation between the two points'
//! frames (`rotation.rs`), its curvature as the mapping of angular to spatial frequency
//! (`distance.rs`). So equal inputs give equal fields, which `Fields` caches.

use std::collections::BTreeMap;
use std::sync::Mutex;

use glam::Vec3;

use super::response::Response;
use crate::raster::shade::{ResolvedLight, light_terms};

/// The sampling grid (Default value: the paper's 16 × 16 × 32 × 16, elevations up to 85°).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// Pixels per side of the hemisphere image (α_b, α_t).
    pub side: usize,
    /// Turns about the normal (α_n / φ_i).
    pub rotations: usize,
    /// Light elevations from the view direction (θ_i).
    pub elevations: usize,
    /// Largest light elevation, radians.
    pub max_elevation: f32,
}

impl Grid {
    /// The paper's resolution (§5).
    pub const PAPER: Grid = Grid {
        side: 16,
        rotations: 32,
        elevations: 16,
        max_elevation: 85.0 * std::f32::consts::PI / 180.0,
    };

    /// The normals of the hemisphere image's pixels inside the disc, row by row.
    pub fn normals(&self) -> Vec<Vec3> {
        let s = self.side as f32;
        let mut out = Vec::new();
        for j in 0..self.side {
            for i in 0..self.side {
                let x = 2.0 * (i as f32 + 0.5) / s - 1.0;
                let y = 2.0 * (j as f32 + 0.5) / s - 1.0;
                let r2 = x * x + y * y;
                if r2 < 1.0 {
                    out.push(Vec3::new(x, y, (1.0 - r2).sqrt()));
                }
            }
        }
        out
    }

    /// The light direction of elevation step `m`.
    pub fn light(&self, m: usize) -> Vec3 {
        let t = (m as f32 + 0.5) / self.elevations as f32 * self.max_elevation;
        Vec3::new(t.sin(), 0.0, t.cos())
    }
}

/// What the shading of one surface point needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inputs {
    /// Linear RGB albedo: base colour × vertex colour × texture at the point.
    pub albedo: Vec3,
    /// Linear RGB specular colour.
    pub specular: Vec3,
    /// Blinn–Phong exponent.
    pub shininess: f32,
    /// The normal map's tangent-space normal at the point (unit), if the material has one.
    pub normal_map: Option<Vec3>,
}

impl Inputs {
    /// A cache key: the bit patterns of every input (equal inputs, equal fields).
    fn key(&self) -> [u32; 11] {
        let m = self.normal_map.unwrap_or(Vec3::splat(f32::NAN));
        [
            self.albedo.x.to_bits(),
            self.albedo.y.to_bits(),
            self.albedo.z.to_bits(),
            self.specular.x.to_bits(),
            self.specular.y.to_bits(),
            self.specular.z.to_bits(),
            self.shininess.to_bits(),
            m.x.to_bits(),
            m.y.to_bits(),
            m.z.to_bits(),
            u32::from(self.normal_map.is_some()),
        ]
    }
}

/// The lights of the field: ambient k_a and one directional light of colour c (the renderer's
/// defaults: 0.15 and a white 0.85).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lighting {
    /// Ambient term.
    pub ambient: f32,
    /// Light colour.
    pub color: Vec3,
}

impl Default for Lighting {
    fn default() -> Self {
        Lighting {
            ambient: 0.15,
            color: Vec3::splat(0.85),
        }
    }
}

/// A sampled field: for each channel (W−K, R−G, B−Y), each elevation, each rotation, the
/// responses at the hemisphere pixels.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    /// `values[((c · elevations + m) · rotations + k) · pixels + p]`.
    pub values: Vec<f32>,
    /// Pixels inside the disc.
    pub pixels: usize,
    /// Rotations actually sampled: 1 for isotropic shading (every turn is the same), else the
    /// grid's.
    pub rotations: usize,
    /// Elevations.
    pub elevations: usize,
}

impl Field {
    /// The responses of channel `c` at elevation `m` and rotation `k`.
    pub fn row(&self, c: usize, m: usize, k: usize) -> &[f32] {
        let start = ((c * self.elevations + m) * self.rotations + k) * self.pixels;
        &self.values[start..start + self.pixels]
    }
}

/// Sample the field of `inputs` on `grid`.
pub fn sample(
    grid: &Grid,
    normals: &[Vec3],
    inputs: &Inputs,
    lighting: &Lighting,
    response: &Response,
) -> Field {
    let rotations = if inputs.normal_map.is_some() {
        grid.rotations
    } else {
        1
    };
    let pixels = normals.len();
    let elevations = grid.elevations;
    let mut values = vec![0.0f32; 3 * elevations * rotations * pixels];
    let view = Vec3::Z;
    for m in 0..elevations {
        let l = grid.light(m);
        let light = [ResolvedLight::new(l, lighting.color, view)];
        for k in 0..rotations {
            let turn = std::f32::consts::TAU * k as f32 / rotations as f32;
            let (s, c) = turn.sin_cos();
            for (p, &n) in normals.iter().enumerate() {
                let shading_normal = match inputs.normal_map {
                    Some(mm) => {
                        // The pixel's tangent frame: x projected onto the tangent plane, turned
                        // by α_n about the normal.
                        let t0 = (Vec3::X - n * n.x).normalize_or(Vec3::Y);
                        let b0 = n.cross(t0);
                        let t = t0 * c + b0 * s;
                        let b = n.cross(t);
                        (t * mm.x + b * mm.y + n * mm.z).normalize_or(n)
                    }
                    None => n,
                };
                let (diffuse, spec) = light_terms(
                    shading_normal,
                    &light,
                    lighting.ambient,
                    inputs.specular,
                    inputs.shininess,
                );
                let o = response.opponent(inputs.albedo * diffuse + spec);
                for (ch, v) in o.to_array().into_iter().enumerate() {
                    values[((ch * elevations + m) * rotations + k) * pixels + p] = v;
                }
            }
        }
    }
    Field {
        values,
        pixels,
        rotations,
        elevations,
    }
}

/// A cache of computed values keyed by a point's shading inputs: most meshes have few distinct
/// materials, and an untextured one has a single field. Lookups are by value, so the results do
/// not depend on the order of insertion or on the thread that computed them.
#[derive(Debug, Default)]
pub struct Cache<T> {
    map: Mutex<BTreeMap<[u32; 11], std::sync::Arc<T>>>,
    /// Entries kept at most (a textured mesh has a distinct albedo at every point).
    limit: usize,
}

impl<T> Cache<T> {
    /// A cache of at most `limit` entries.
    pub fn new(limit: usize) -> Cache<T> {
        Cache {
            map: Mutex::new(BTreeMap::new()),
            limit,
        }
    }

    /// The value for `inputs`, computed by `make` when absent.
    pub fn get(&self, inputs: &Inputs, make: impl FnOnce() -> T) -> std::sync::Arc<T> {
        let key = inputs.key();
        if let Some(v) = self.map.lock().ok().and_then(|m| m.get(&key).cloned()) {
            return v;
        }
        let v = std::sync::Arc::new(make());
        if let Ok(mut m) = self.map.lock()
            && m.len() < self.limit
        {
            m.entry(key).or_insert_with(|| v.clone());
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metric::vdp::Display;

    fn grey(shininess: f32) -> Inputs {
        Inputs {
            albedo: Vec3::splat(0.6),
            specular: Vec3::splat(0.3),
            shininess,
            normal_map: None,
        }
    }

    #[test]
    fn the_grid_covers_the_disc_and_the_shading_matches_the_renderer() {
        let grid = Grid::PAPER;
        let normals = grid.normals();
        // π/4 of the 256 pixels lie inside the disc: 208 of them at 16 × 16 (counted).
        assert_eq!(normals.len(), 208);
        assert!(
            normals
                .iter()
                .all(|n| (n.length() - 1.0).abs() < 1e-5 && n.z > 0.0)
        );
        let r = Response::new(&Display::DEFAULT);
        let f = sample(&grid, &normals, &grey(32.0), &Lighting::default(), &r);
        // Isotropic: one rotation sampled.
        assert_eq!(f.rotations, 1);
        // The pixel facing the viewer under the headlight-like first elevation is the brightest
        // (diffuse and highlight both peak there).
        let row = f.row(0, 0, 0);
        let centre = normals
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.z.total_cmp(&b.1.z))
            .unwrap()
            .0;
        let brightest = row
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .unwrap()
            .0;
        assert_eq!(brightest, centre);
        // And that value is the renderer's colour through the response model.
        let n = normals[centre];
        let l = [ResolvedLight::new(
            grid.light(0),
            Vec3::splat(0.85),
            Vec3::Z,
        )];
        let (d, s) = light_terms(n, &l, 0.15, Vec3::splat(0.3), 32.0);
        let expect = r.opponent(Vec3::splat(0.6) * d + s).x;
        assert!((row[centre] - expect).abs() < 1e-4);
    }

    #[test]
    fn a_normal_map_makes_the_field_depend_on_the_turn() {
        let grid = Grid {
            rotations: 8,
            ..Grid::PAPER
        };
        let normals = grid.normals();
        let r = Response::new(&Display::DEFAULT);
        let mut inputs = grey(16.0);
        inputs.normal_map = Some(Vec3::new(0.4, 0.0, 0.9165).normalize());
        let f = sample(&grid, &normals, &inputs, &Lighting::default(), &r);
        assert_eq!(f.rotations, 8);
        let (a, b) = (f.row(0, 3, 0), f.row(0, 3, 4));
        let diff: f32 = a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum();
        assert!(diff > 1.0, "{diff}");
        // A flat normal map (0, 0, 1) is the unmapped surface.
        inputs.normal_map = Some(Vec3::Z);
        let flat = sample(&grid, &normals, &inputs, &Lighting::default(), &r);
        let plain = sample(&grid, &normals, &grey(16.0), &Lighting::default(), &r);
        for k in 0..8 {
            for (x, y) in flat.row(0, 5, k).iter().zip(plain.row(0, 5, 0)) {
                assert!((x - y).abs() < 1e-4);
            }
        }
    }
}
