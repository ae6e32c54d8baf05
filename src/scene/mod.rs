//! What is rendered and from where: cameras framed on the model, view rigs, lights, viewing
//! conditions. `raster/` (and later `gpu/`) consume these types; nothing here rasterizes.

mod camera;
mod light;
mod rig;
mod viewing;

pub use camera::{Camera, Projection};
pub use light::{HEADLIGHT_OFFSET, Light};
pub use rig::Rig;
pub use viewing::Viewing;

use std::sync::Arc;

use glam::Vec3;

use crate::color::srgb_to_linear;
use crate::mesh::Mesh;

/// What is seen: a mesh, its lights and the background. Renderers keep their own prepared form
/// beside it (`raster::RenderScene`, the GPU mirror's `GpuScene`).
#[derive(Debug, Clone)]
pub struct Scene {
    mesh: Arc<Mesh>,
    /// Lights. Default value: one [`Light::HEADLIGHT`].
    pub lights: Vec<Light>,
    /// Linear RGB background. Default value: mid-grey, sRGB 0.5 (≈ 0.214 linear).
    pub background: Vec3,
    /// Ambient term k_a of the Blinn–Phong models. Default value: 0.15.
    pub ambient: f32,
}

impl Scene {
    /// Default ambient term.
    pub const DEFAULT_AMBIENT: f32 = 0.15;

    /// A scene with the defaults of the README's architecture section: one headlight, mid-grey background.
    pub fn new(mesh: Arc<Mesh>) -> Scene {
        Scene {
            mesh,
            lights: vec![Light::HEADLIGHT],
            background: Vec3::splat(srgb_to_linear(0.5)),
            ambient: Self::DEFAULT_AMBIENT,
        }
    }
    /// The mesh.
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }
    /// The mesh, shared.
    pub fn mesh_arc(&self) -> &Arc<Mesh> {
        &self.mesh
    }
}
