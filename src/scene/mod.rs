//! What is rendered and from where: cameras framed on the model, view rigs, lights, viewing
//! conditions. `raster/` (and later `gpu/`) consume these types; nothing here rasterizes.

mod camera;
mod environment;
mod light;
mod rig;
mod viewing;

pub use camera::{Camera, Projection};
pub use environment::Environment;
pub use light::{HEADLIGHT_OFFSET, Light, Punctual};
pub use rig::Rig;
pub use viewing::Viewing;

use std::sync::Arc;

use glam::Vec3;

use crate::color::srgb_to_linear;
use crate::mesh::Mesh;

/// The image-based lighting a config or the command line chooses: the environment (loaded once,
/// shared by every scene), its rotation about +Y and its intensity.
#[derive(Debug, Clone)]
pub struct Lighting {
    /// The map. Default value: the built-in neutral room.
    pub environment: Arc<Environment>,
    /// Rotation about +Y, degrees. Default value: 0.
    pub rotation_deg: f32,
    /// Factor on the radiance. Default value: 1.
    pub intensity: f32,
}

impl Default for Lighting {
    fn default() -> Self {
        Lighting {
            environment: Environment::neutral(),
            rotation_deg: 0.0,
            intensity: 1.0,
        }
    }
}

impl Lighting {
    /// The lighting for `environment` (`neutral`, or a `.hdr`/`.exr` file, relative to
    /// `base_dir`), rotated and scaled; the file is read and checked here.
    pub fn new(
        environment: &str,
        base_dir: &std::path::Path,
        rotation_deg: f32,
        intensity: f32,
    ) -> crate::error::Result<Lighting> {
        let environment = match environment {
            "neutral" => Environment::neutral(),
            path => Arc::new(Environment::load(&base_dir.join(path))?),
        };
        Ok(Lighting {
            environment,
            rotation_deg,
            intensity,
        })
    }
}

/// What is seen: a mesh, its lights, the environment that lights it and the background.
/// Renderers keep their own prepared form beside it (`raster::RenderScene`, the GPU mirror's
/// `GpuScene`).
#[derive(Debug, Clone)]
pub struct Scene {
    mesh: Arc<Mesh>,
    /// Lights; `None` = the default of the model that draws the scene
    /// ([`Scene::default_lights`]). Default value: `None`.
    pub lights: Option<Vec<Light>>,
    /// Linear RGB background (a display colour: not tone-mapped). Default value: mid-grey, sRGB
    /// 0.5 (≈ 0.214 linear).
    pub background: Vec3,
    /// Ambient term k_a of the Blinn–Phong models. Default value: 0.15.
    pub ambient: f32,
    /// Image-based lighting of the `pbr` model. Default value: the built-in neutral room.
    pub environment: Arc<Environment>,
    /// Rotation of the environment about +Y, degrees (positive turns it counter-clockwise seen
    /// from above). Default value: 0.
    pub environment_rotation_deg: f32,
    /// Factor on the environment's radiance. Default value: 1.
    pub environment_intensity: f32,
}

impl Scene {
    /// Default ambient term.
    pub const DEFAULT_AMBIENT: f32 = 0.15;

    /// A scene with the defaults of the README's architecture section: the default lights for
    /// the mesh, mid-grey background, the neutral environment.
    pub fn new(mesh: Arc<Mesh>) -> Scene {
        Scene {
            lights: None,
            mesh,
            background: Vec3::splat(srgb_to_linear(0.5)),
            ambient: Self::DEFAULT_AMBIENT,
            environment: Environment::neutral(),
            environment_rotation_deg: 0.0,
            environment_intensity: 1.0,
        }
    }

    /// The lights a scene of `mesh` gets unless told otherwise: for the `pbr` model, the lights
    /// the file declares (the environment is the main light, as in a model viewer); for the
    /// Blinn–Phong models, one [`Light::HEADLIGHT`].
    pub fn default_lights(mesh: &Mesh, pbr: bool) -> Vec<Light> {
        if pbr {
            mesh.lights()
                .iter()
                .map(|l| Light::Punctual(Punctual::from_file(l)))
                .collect()
        } else {
            vec![Light::HEADLIGHT]
        }
    }

    /// The lights the `pbr` model (`pbr`) or a Blinn–Phong model (not `pbr`) draws.
    pub fn lights_for(&self, pbr: bool) -> Vec<Light> {
        match &self.lights {
            Some(l) => l.clone(),
            None => Scene::default_lights(&self.mesh, pbr),
        }
    }

    /// Set the environment and its rotation and intensity from `lighting`.
    pub fn light_with(&mut self, lighting: &Lighting) {
        self.environment = lighting.environment.clone();
        self.environment_rotation_deg = lighting.rotation_deg;
        self.environment_intensity = lighting.intensity;
    }

    /// The rotation taking world directions into the environment map's frame.
    pub fn environment_frame(&self) -> glam::Mat3 {
        glam::Mat3::from_rotation_y(-self.environment_rotation_deg.to_radians())
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
