//! Cameras: perspective or orthographic, and framing a model by its bounding sphere.
//!
//! Conventions: right-handed world, camera looking down its −Z, depth mapped to 0..1 (near..far),
//! as glam's `camera::rh::proj::directx` (the DirectX/WebGPU convention wgpu uses). Framing puts the sphere's centre on the optical
//! axis at the distance where the sphere, grown by the margin, just fits the narrower field of view.
//!
//! Decision (the architecture contract is silent): default vertical field of view 30°, margin 5 % of the radius.

use glam::camera::rh::{proj::directx, view::look_at_mat4};
use glam::{Mat4, Vec3};

use crate::mesh::Sphere;

/// How the camera projects.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Projection {
    /// Perspective with this vertical field of view in degrees.
    Perspective {
        /// Vertical field of view, degrees.
        fov_y_deg: f32,
    },
    /// Orthographic, showing this many world units from the centre to the top edge.
    Orthographic {
        /// Half the visible height in world units.
        half_height: f32,
    },
}

/// A camera in world space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Up direction (need not be orthogonal to the view direction).
    pub up: Vec3,
    /// Projection.
    pub projection: Projection,
    /// Near plane distance (> 0).
    pub near: f32,
    /// Far plane distance (> near).
    pub far: f32,
}

impl Camera {
    /// Default vertical field of view for framing, degrees.
    pub const DEFAULT_FOV_Y_DEG: f32 = 30.0;
    /// Default framing margin as a fraction of the bounding radius.
    pub const DEFAULT_MARGIN: f32 = 0.05;

    /// A perspective camera looking at `sphere` from `direction` (from the centre towards the
    /// eye), at the distance where the sphere grown by `margin` fills the narrower field of view.
    pub fn frame_sphere(
        sphere: Sphere,
        direction: Vec3,
        fov_y_deg: f32,
        aspect: f32,
        margin: f32,
    ) -> Camera {
        let dir = direction.try_normalize().unwrap_or(Vec3::Z);
        let r = sphere.radius.max(f32::MIN_POSITIVE) * (1.0 + margin);
        // The narrower of the two half-angles decides the distance.
        let half_y = (fov_y_deg.to_radians() * 0.5).clamp(1e-3, 1.5);
        let half_x = (half_y.tan() * aspect).atan();
        let half = half_y.min(half_x);
        let distance = r / half.sin();
        Camera {
            eye: sphere.center + dir * distance,
            target: sphere.center,
            up: up_for(dir),
            projection: Projection::Perspective { fov_y_deg },
            near: (distance - r).max(distance * 1e-3),
            far: distance + r,
        }
    }

    /// A perspective camera at `eye` looking at `target` (which must differ from `eye`), with its
    /// near and far planes around `sphere` (the near plane at least 1/1000 of the distance).
    pub fn looking_at(sphere: Sphere, eye: Vec3, target: Vec3, fov_y_deg: f32) -> Camera {
        let dir = (eye - target).try_normalize().unwrap_or(Vec3::Z);
        let dist = eye.distance(sphere.center);
        Camera {
            eye,
            target,
            up: up_for(dir),
            projection: Projection::Perspective { fov_y_deg },
            near: (dist - sphere.radius).max(dist * 1e-3),
            far: dist + sphere.radius,
        }
    }

    /// An orthographic camera on the same axis, showing the sphere grown by `margin`.
    pub fn frame_sphere_ortho(sphere: Sphere, direction: Vec3, aspect: f32, margin: f32) -> Camera {
        let dir = direction.try_normalize().unwrap_or(Vec3::Z);
        let r = sphere.radius.max(f32::MIN_POSITIVE) * (1.0 + margin);
        let distance = 2.0 * r;
        Camera {
            eye: sphere.center + dir * distance,
            target: sphere.center,
            up: up_for(dir),
            projection: Projection::Orthographic {
                half_height: if aspect >= 1.0 { r } else { r / aspect },
            },
            near: distance - r,
            far: distance + r,
        }
    }

    /// World → camera transform.
    pub fn view(&self) -> Mat4 {
        look_at_mat4(self.eye, self.target, self.up)
    }

    /// Camera → clip transform for an image of the given aspect (width / height).
    pub fn projection(&self, aspect: f32) -> Mat4 {
        match self.projection {
            Projection::Perspective { fov_y_deg } => {
                directx::perspective(fov_y_deg.to_radians(), aspect, self.near, self.far)
            }
            Projection::Orthographic { half_height } => {
                let hw = half_height * aspect;
                directx::orthographic(-hw, hw, -half_height, half_height, self.near, self.far)
            }
        }
    }

    /// Unit vector from the target towards the eye (the "infinite viewer" direction).
    pub fn to_eye(&self) -> Vec3 {
        (self.eye - self.target).normalize_or(Vec3::Z)
    }
}

/// World +Y is up unless the view direction is (nearly) vertical, then +Z.
fn up_for(dir: Vec3) -> Vec3 {
    if dir.y.abs() > 0.999 {
        Vec3::Z
    } else {
        Vec3::Y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn framed_sphere_touches_the_field_of_view() {
        // A unit sphere framed with no margin: the tangent from the eye makes exactly half the
        // field of view with the axis, i.e. sin(half fov) = r / distance.
        let s = Sphere {
            center: Vec3::new(1.0, 2.0, 3.0),
            radius: 1.0,
        };
        let c = Camera::frame_sphere(s, Vec3::X, 30.0, 1.0, 0.0);
        let d = c.eye.distance(s.center);
        assert!((1.0 / d - 15f32.to_radians().sin()).abs() < 1e-6);
        assert!(c.near < d - 1.0 + 1e-4 && c.far >= d + 1.0 - 1e-4);
        // The sphere's centre projects to the image centre.
        let clip = c.projection(1.0) * c.view() * s.center.extend(1.0);
        assert!((clip.x / clip.w).abs() < 1e-5 && (clip.y / clip.w).abs() < 1e-5);
    }
}
