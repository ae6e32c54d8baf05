//! Lights for the Blinn–Phong shading models: fixed directional lights and the "headlight" that
//! follows the camera (the default; Lindstrom & Turk §4.1 place "a light near each viewer").
//!
//! Decision: the headlight comes from slightly above and to the left of the eye
//! ([`HEADLIGHT_OFFSET`], camera space), so that shading is not flat and silhouettes darken; with a
//! light exactly at the eye, N·L equals N·V and folds reveal nothing.

use glam::{Vec2, Vec3};

use super::Camera;

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
}

impl Light {
    /// The default light: a white headlight of intensity 0.85 (with the default ambient 0.15 a
    /// surface facing the light reaches exactly its base colour).
    pub const HEADLIGHT: Light = Light::Headlight {
        offset: HEADLIGHT_OFFSET,
        color: Vec3::splat(0.85),
    };

    /// World-space unit direction towards the light, and its colour, for a camera.
    pub fn resolve(&self, camera: &Camera) -> (Vec3, Vec3) {
        match *self {
            Light::Directional { direction, color } => (direction.normalize_or(Vec3::Y), color),
            Light::Headlight { offset, color } => {
                // Camera basis: back = towards the eye, right, up (as look_at_rh builds it).
                let back = camera.to_eye();
                let right = camera.up.cross(back).normalize_or(Vec3::X);
                let up = back.cross(right);
                ((right * offset.x + up * offset.y + back).normalize(), color)
            }
        }
    }
}
