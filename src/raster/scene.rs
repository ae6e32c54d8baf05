//! `RenderScene`: a [`Scene`] with the per-mesh data the CPU rasterizer derives once (mip pyramids,
//! tangents, per-vertex materials), the CPU twin of the GPU mirror's `GpuScene`.
//!
//! Decision: the scene layer describes what is seen (mesh, lights, background) and knows nothing
//! of renderers; each renderer keeps its own prepared form beside it. `RenderScene` dereferences
//! to its `Scene`, so lights and background stay editable; the mesh cannot change (the scene
//! holds it privately), so the prepared data always matches it.

use std::ops::{Deref, DerefMut};
use std::sync::Arc;

use super::PreparedMesh;
use crate::mesh::Mesh;
use crate::scene::Scene;

/// A scene ready for the CPU rasterizer.
///
/// # Guarantees
/// The prepared data was derived from this scene's mesh.
#[derive(Debug, Clone)]
pub struct RenderScene {
    scene: Scene,
    prepared: Arc<PreparedMesh>,
}

impl RenderScene {
    /// Prepare `scene` for rendering (the costly part is done here, once).
    pub fn new(scene: Scene) -> RenderScene {
        let prepared = Arc::new(PreparedMesh::new(scene.mesh()));
        RenderScene { scene, prepared }
    }

    /// A scene of `mesh` with the default lights and background, prepared.
    pub fn of(mesh: Arc<Mesh>) -> RenderScene {
        RenderScene::new(Scene::new(mesh))
    }

    /// The per-mesh render data.
    pub fn prepared(&self) -> &PreparedMesh {
        &self.prepared
    }

    /// The scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }
}

impl Deref for RenderScene {
    type Target = Scene;
    fn deref(&self) -> &Scene {
        &self.scene
    }
}

impl DerefMut for RenderScene {
    fn deref_mut(&mut self) -> &mut Scene {
        &mut self.scene
    }
}
