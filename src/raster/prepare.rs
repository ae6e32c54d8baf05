//! Per-mesh work done once and reused for every view: mip pyramids of the textures the materials
//! use (each texture once, however many materials, slots and meshes share it) with each slot's
//! sampler, transform and UV set, tangent frames for normal mapping, and each vertex's material
//! (for per-vertex lighting).
//!
//! Decision: pyramids are shared across meshes while their texture lives ([`pyramid`]): a LOD
//! keeps its original's decoded textures (`Arc`), so an evaluation of five LODs of an asset with
//! three 2048² maps builds three pyramids, not eighteen (measured on Avocado: 5 s and 700 MB of
//! a demo run). A pyramid is a pure function of its texture, so who built it changes nothing.

use std::sync::{Arc, Mutex, Weak};

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
        let mut sets_used = [false; 2];
        let mut slot = |s: &Option<TextureSlot>| {
            s.as_ref().map(|s| {
                let set = (s.set() as usize).min(1);
                sets_used[set] = true;
                PreparedSlot {
                    mip: pyramid(&s.texture),
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

/// The mip pyramid of `texture`, built once while the texture and a pyramid of it are alive
/// anywhere in the process. Entries are keyed by the texture's address and confirmed by identity
/// (a live `Weak` to the same `Arc`, so a reused address is a miss), built outside the lock (two
/// threads may both build one: the same pyramid). Dead entries are swept when the table has
/// doubled since the last sweep, so each call costs O(1) amortised (65 536 textures in one mesh
/// used to make this quadratic).
fn pyramid(texture: &Arc<Texture>) -> Arc<MipTexture> {
    type Entry = (Weak<Texture>, Weak<MipTexture>);
    #[derive(Default)]
    struct Cache {
        entries: std::collections::HashMap<usize, Entry>,
        sweep_at: usize,
    }
    static CACHE: Mutex<Option<Cache>> = Mutex::new(None);
    let key = Arc::as_ptr(texture) as usize;
    let find = |cache: &Cache| {
        let (t, m) = cache.entries.get(&key)?;
        t.upgrade()
            .filter(|t| Arc::ptr_eq(t, texture))
            .and_then(|_| m.upgrade())
    };
    let lock = || CACHE.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(m) = find(lock().get_or_insert_with(Cache::default)) {
        return m;
    }
    let built = Arc::new(MipTexture::build(texture));
    let mut guard = lock();
    let cache = guard.get_or_insert_with(Cache::default);
    if let Some(m) = find(cache) {
        return m;
    }
    cache
        .entries
        .insert(key, (Arc::downgrade(texture), Arc::downgrade(&built)));
    if cache.entries.len() > cache.sweep_at {
        cache
            .entries
            .retain(|_, (t, m)| t.strong_count() > 0 && m.strong_count() > 0);
        cache.sweep_at = (2 * cache.entries.len()).max(64);
    }
    built
}
