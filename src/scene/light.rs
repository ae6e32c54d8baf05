//! Lights: fixed directional lights and the "headlight" that follows the camera (the Blinn–Phong
//! models' default; Lindstrom & Turk §4.1 place "a light near each viewer"), and the punctual
//! lights a glTF file declares (`KHR_lights_punctual`: directional, point, spot).
//!
//! Units. Directional lights and the headlight carry a Blinn–Phong colour c: a white Lambertian
//! surface facing one is lit to c. The `pbr` model reads that as an irradiance of π·c (its diffuse
//! lobe is albedo/π), so a headlight lights a matte surface alike in both models. Punctual lights
//! carry the extension's photometric intensity (lux for directional, candela for point and spot),
//! used as the Khronos sample renderer uses it; only the `pbr` model draws them.
//!
//! Decision: the headlight comes from slightly above and to the left of the eye
//! ([`HEADLIGHT_OFFSET`], camera space), so that shading is not flat and silhouettes darken; with a
//! light exactly at the eye, N·L equals N·V and folds reveal nothing.

use glam::{Vec2, Vec3};

use super::Camera;
use crate::mesh::{FileLight, LightKind};

/// Camera-space offset of the default headlight: (x, y) of the direction (x, y, 1).
pub const HEADLIGHT_OFFSET: Vec2 = Vec2::new(-0.25, 0.35);

/// A light.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Light {
    /// Infinitely distant light; `direction` points from the surface towards the light (world).
    Directional {
        /// Towards the light, world space.
        direction: Vec3,
        /// Linear RGB intensity.
        color: Vec3,
    },
    /// A directional light attached to the camera: camera-space direction (offset.x, offset.y, 1).
    Headlight {
        /// Camera-space offset (see [`HEADLIGHT_OFFSET`]).
        offset: Vec2,
        /// Linear RGB intensity.
        color: Vec3,
    },
    /// A `KHR_lights_punctual` light, world space (drawn by the `pbr` model only).
    Punctual(Punctual),
}

/// A `KHR_lights_punctual` light in world space, with its photometric intensity folded into the
/// colour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Punctual {
    /// Directional, point or spot (with its cone angles).
    pub kind: LightKind,
    /// Position (point and spot).
    pub position: Vec3,
    /// Unit direction the light travels (directional and spot).
    pub direction: Vec3,
    /// Colour × intensity (lux or candela by kind).
    pub intensity: Vec3,
    /// Distance beyond which it gives nothing (`None`: unbounded).
    pub range: Option<f32>,
}

impl Punctual {
    /// The light a file declared.
    pub fn from_file(l: &FileLight) -> Punctual {
        Punctual {
            kind: l.kind,
            position: l.position,
            direction: l.direction.normalize_or(-Vec3::Z),
            intensity: l.color * l.intensity,
            range: l.range.filter(|r| *r > 0.0),
        }
    }
}

impl Light {
    /// The default light: a white headlight of intensity 0.85 (with the default ambient 0.15 a
    /// surface facing the light reaches exactly its base colour).
    pub const HEADLIGHT: Light = Light::Headlight {
        offset: HEADLIGHT_OFFSET,
        color: Vec3::splat(0.85),
    };

    /// World-space unit direction towards the light, and its Blinn–Phong colour, for a camera;
    /// `None` for a punctual light (the Blinn–Phong models do not draw them).
    pub fn resolve(&self, camera: &Camera) -> Option<(Vec3, Vec3)> {
        Some(match *self {
            Light::Directional { direction, color } => (direction.normalize_or(Vec3::Y), color),
            Light::Headlight { offset, color } => {
                // Camera basis: back = towards the eye, right, up (as look_at_rh builds it).
                let back = camera.to_eye();
                let right = camera.up.cross(back).normalize_or(Vec3::X);
                let up = back.cross(right);
                ((right * offset.x + up * offset.y + back).normalize(), color)
            }
            Light::Punctual(_) => return None,
        })
    }
}
