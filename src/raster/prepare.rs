//! Per-mesh work done once and reused for every view: mip pyramids of the textures the materials
//! use (each texture once, however many materials share it), tangent frames for normal mapping,
//! and each vertex's material (for per-vertex lighting).

use std::collections::HashMap;
use std::sync::Arc;

use glam::Vec4;

use super::texture::MipTexture;
use crate::mesh::{Mesh, Texture};

/// Mip pyramids of one material.
#[derive(Debug, Clone, Default)]
pub(crate) struct PreparedMaterial {
    pub base: Option<Arc<MipTexture>>,
    pub normal: Option<Arc<MipTexture>>,
}

/// Mesh data derived once for rendering.
#[derive(Debug, Clone)]
pub struct PreparedMesh {
    pub(crate) materials: Vec<PreparedMaterial>,
    pub(crate) tangents: Option<Vec<Vec4>>,
    pub(crate) vertex_material: Vec<u32>,
}

impl PreparedMesh {
    /// Build mip pyramids, tangents and the vertex → material map.
    pub fn new(mesh: &Mesh) -> PreparedMesh {
        // Key by the texture's address: equal Arcs are the same decoded image. Only looked up,
        // never iterated, so the map's order cannot reach an output.
        let mut built: HashMap<*const Texture, Arc<MipTexture>> = HashMap::new();
        let mut pyramid = |t: &Option<crate::mesh::TextureSlot>| {
            t.as_ref().map(|s| &s.texture).map(|t| {
                built
                    .entry(Arc::as_ptr(t))
                    .or_insert_with(|| Arc::new(MipTexture::build(t)))
                    .clone()
            })
        };
        let materials = mesh
            .materials()
            .iter()
            .map(|m| PreparedMaterial {
                base: pyramid(&m.base_color_texture),
                normal: pyramid(&m.normal_texture),
            })
            .collect();
        let has_normal_maps = mesh.materials().iter().any(|m| m.normal_texture.is_some());
        let tangents = match (mesh.uvs(), has_normal_maps) {
            (Some(uvs), true) => Some(crate::mesh::tangents::generate(
                mesh.positions(),
                mesh.normals(),
                uvs,
                mesh.triangles(),
            )),
            _ => None,
        };
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
        }
    }
}
