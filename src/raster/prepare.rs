//! Per-mesh work done once and reused for every view: mip pyramids of the textures the materials
//! use (each texture once, however many materials and slots share it) with each slot's sampler,
//! transform and UV set, tangent frames for normal mapping, and each vertex's material (for
//! per-vertex lighting).

use std::collections::HashMap;
use std::sync::Arc;

use glam::{Vec2, Vec3, Vec4};

use super::texture::{MipTexture, SamplerState};
use crate::mesh::{Mesh, Texture, TextureSlot, TextureTransform};

/// A texture position and its steps one pixel right and one pixel down, for one UV set.
pub(crate) type UvFrame = (Vec2, Vec2, Vec2);

/// The UV frames of a shading point, per set (0 and 1), where the mesh has the set.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct UvFrames(pub [Option<UvFrame>; 2]);

/// One texture slot of a material, ready to sample.
#[derive(Debug, Clone)]
pub(crate) struct PreparedSlot {
    pub mip: Arc<MipTexture>,
    pub sampler: SamplerState,
    pub transform: Option<TextureTransform>,
    /// The UV set it reads (0 or 1).
    pub set: usize,
}

impl PreparedSlot {
    /// The slot's texel at `frames` (its set transformed as the slot says), or `None` where the
    /// mesh lacks the set.
    pub fn sample(&self, frames: &UvFrames) -> Option<Vec3> {
        let (uv, dx, dy) = (*frames.0.get(self.set)?)?;
        Some(match &self.transform {
            None => self.mip.sample_with(&self.sampler, uv, dx, dy),
            Some(t) => self.mip.sample_with(
                &self.sampler,
                t.apply(uv),
                t.apply_vector(dx),
                t.apply_vector(dy),
            ),
        })
    }
}

/// The slots of one material.
#[derive(Debug, Clone, Default)]
pub(crate) struct PreparedMaterial {
    pub base: Option<PreparedSlot>,
    pub metallic_roughness: Option<PreparedSlot>,
    pub normal: Option<PreparedSlot>,
    pub occlusion: Option<PreparedSlot>,
    pub emissive: Option<PreparedSlot>,
}

/// Mesh data derived once for rendering.
#[derive(Debug, Clone)]
pub struct PreparedMesh {
    pub(crate) materials: Vec<PreparedMaterial>,
    pub(crate) tangents: Option<Vec<Vec4>>,
    pub(crate) vertex_material: Vec<u32>,
    /// Which UV sets some slot reads.
    pub(crate) sets_used: [bool; 2],
}

impl PreparedMesh {
    /// Build mip pyramids, tangents and the vertex → material map.
    pub fn new(mesh: &Mesh) -> PreparedMesh {
        // Key by the texture's address: equal Arcs are the same decoded image. Only looked up,
        // never iterated, so the map's order cannot reach an output.
        let mut built: HashMap<*const Texture, Arc<MipTexture>> = HashMap::new();
        let mut sets_used = [false; 2];
        let mut slot = |s: &Option<TextureSlot>| {
            s.as_ref().map(|s| {
                let set = (s.set() as usize).min(1);
                sets_used[set] = true;
                PreparedSlot {
                    mip: built
                        .entry(Arc::as_ptr(&s.texture))
                        .or_insert_with(|| Arc::new(MipTexture::build(&s.texture)))
                        .clone(),
                    sampler: SamplerState::of(&s.sampler),
                    transform: s.transform,
                    set,
                }
            })
        };
        let materials = mesh
            .materials()
            .iter()
            .map(|m| PreparedMaterial {
                base: slot(&m.base_color_texture),
                metallic_roughness: slot(&m.metallic_roughness_texture),
                normal: slot(&m.normal_texture),
                occlusion: slot(&m.occlusion_texture),
                emissive: slot(&m.emissive_texture),
            })
            .collect();
        // Tangents from the UV set the (first) normal map reads.
        let normal_set = mesh
            .materials()
            .iter()
            .find_map(|m| m.normal_texture.as_ref())
            .map(|s| s.set());
        let tangents = normal_set.and_then(|set| mesh.uv_set(set)).map(|uvs| {
            crate::mesh::tangents::generate(mesh.positions(), mesh.normals(), uvs, mesh.triangles())
        });
        let mut vertex_material = vec![u32::MAX; mesh.vertex_count()];
        for (t, tri) in mesh.triangles().iter().enumerate() {
            for &v in tri {
                if vertex_material[v as usize] == u32::MAX {
                    vertex_material[v as usize] = mesh.material_ids()[t];
                }
            }
        }
        PreparedMesh {
            materials,
            tangents,
            vertex_material,
            sets_used,
        }
    }
}
