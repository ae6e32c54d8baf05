//! The facts `lodeval info` prints about a loaded mesh, as a serialisable struct.

use serde::Serialize;

use super::{Aabb, ColorSpace, Format, Mesh, Sphere};

/// One texture as `info` reports it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TextureSummary {
    /// The slot, by its glTF name (`baseColorTexture`, `metallicRoughnessTexture`,
    /// `normalTexture`, `occlusionTexture`, `emissiveTexture`).
    pub role: &'static str,
    /// The texture coordinate set it reads.
    pub tex_coord: u32,
    /// File path or embedded-image label.
    pub source: String,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Colour space of the stored values.
    pub color_space: ColorSpace,
}

/// One material as `info` reports it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MaterialSummary {
    /// Material name.
    pub name: String,
    /// Triangles that use it.
    pub triangles: usize,
    /// The reflectance model the file described.
    pub model: super::Model,
    /// Linear RGB base colour.
    pub base_color: [f32; 3],
    /// Metallic factor.
    pub metallic: f32,
    /// Roughness factor.
    pub roughness: f32,
    /// Emitted radiance factor (emissive × strength).
    pub emission: [f32; 3],
    /// Alpha mode.
    pub alpha_mode: super::AlphaMode,
    /// Double-sided.
    pub double_sided: bool,
    /// Textures it uses.
    pub textures: Vec<TextureSummary>,
}

/// Which per-vertex attributes the mesh has.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Attributes {
    /// Normals were in the file (otherwise lodeval computed them).
    pub normals_from_file: bool,
    /// Texture coordinates.
    pub uvs: bool,
    /// A second texture coordinate set.
    pub uvs1: bool,
    /// Vertex colours.
    pub colors: bool,
}

/// Everything `lodeval info` prints.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeshSummary {
    /// The file.
    pub path: String,
    /// Its format.
    pub format: Format,
    /// Vertex records in the file.
    pub file_vertices: usize,
    /// Face records in the file.
    pub file_faces: usize,
    /// Vertices after seam splitting (what the renderer draws).
    pub vertices: usize,
    /// Distinct positions (what simplifiers weld to).
    pub welded_vertices: usize,
    /// Vertices in the file that no face used (dropped).
    pub unreferenced_vertices: usize,
    /// Triangles.
    pub triangles: usize,
    /// Zero-area triangles (counted, not fatal).
    pub degenerate_triangles: usize,
    /// Attributes present.
    pub attributes: Attributes,
    /// Materials with their textures.
    pub materials: Vec<MaterialSummary>,
    /// Axis-aligned bounds in model units.
    pub aabb: Aabb,
    /// Bounding-box diagonal in model units.
    pub diagonal: f32,
    /// Bounding sphere in model units.
    pub bounding_sphere: Sphere,
    /// glTF `MSFT_lod`: the chain the file holds and the level this summary describes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lod_chain: Option<super::LodChain>,
    /// Every level of that chain ([`MeshSummary::with_levels`]), finest first.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub lod_levels: Vec<LevelSummary>,
    /// Non-fatal problems met while loading.
    pub warnings: Vec<String>,
}

/// One level of an `MSFT_lod` chain.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LevelSummary {
    /// Its number: `FILE#level` loads it.
    pub level: usize,
    /// Its triangles.
    pub triangles: usize,
    /// Its vertices (after seam splits).
    pub vertices: usize,
    /// The `MSFT_screencoverage` down to which it is used, where the file gives one.
    pub coverage: Option<f64>,
}

impl MeshSummary {
    /// Summarise a mesh.
    pub fn of(mesh: &Mesh) -> MeshSummary {
        let mut per_material = vec![0usize; mesh.materials().len()];
        for &m in mesh.material_ids() {
            per_material[m as usize] += 1;
        }
        let materials = mesh
            .materials()
            .iter()
            .zip(per_material)
            .map(|(m, triangles)| {
                let textures = m
                    .slots()
                    .into_iter()
                    .filter_map(|(role, slot)| {
                        slot.map(|s| TextureSummary {
                            role,
                            tex_coord: s.set(),
                            source: s.texture.label().to_string(),
                            width: s.texture.width(),
                            height: s.texture.height(),
                            color_space: s.texture.color_space(),
                        })
                    })
                    .collect();
                MaterialSummary {
                    name: m.name.clone(),
                    triangles,
                    model: m.model,
                    base_color: m.base_color.to_array(),
                    metallic: m.metallic,
                    roughness: m.roughness,
                    emission: m.emission().to_array(),
                    alpha_mode: m.alpha_mode,
                    double_sided: m.double_sided,
                    textures,
                }
            })
            .collect();
        let src = mesh.source();
        MeshSummary {
            path: src.path.display().to_string(),
            format: src.format,
            file_vertices: src.file_vertices,
            file_faces: src.file_faces,
            vertices: mesh.vertex_count(),
            welded_vertices: mesh.welded_vertex_count(),
            unreferenced_vertices: mesh.unreferenced_removed(),
            triangles: mesh.triangle_count(),
            degenerate_triangles: mesh.degenerate_triangles(),
            attributes: Attributes {
                normals_from_file: mesh.normals_from_file(),
                uvs: mesh.uvs().is_some(),
                uvs1: mesh.uvs1().is_some(),
                colors: mesh.colors().is_some(),
            },
            materials,
            aabb: mesh.aabb(),
            diagonal: mesh.aabb().diagonal(),
            bounding_sphere: mesh.bounding_sphere(),
            lod_chain: src.lod_chain.clone(),
            lod_levels: Vec::new(),
            warnings: mesh.warnings().to_vec(),
        }
    }

    /// [`MeshSummary::of`], and for a file with an `MSFT_lod` chain every level's counts, each
    /// level loaded as `FILE#K` with `options`.
    pub fn with_levels(mesh: &Mesh, options: &super::LoadOptions) -> crate::Result<MeshSummary> {
        let mut summary = MeshSummary::of(mesh);
        if let Some(chain) = &summary.lod_chain {
            let file = mesh.source().path.to_string_lossy().into_owned();
            for level in 0..chain.levels {
                let m = super::load(std::path::Path::new(&format!("{file}#{level}")), options)?;
                summary.lod_levels.push(LevelSummary {
                    level,
                    triangles: m.triangle_count(),
                    vertices: m.vertex_count(),
                    coverage: chain.coverage.as_ref().and_then(|c| c.get(level).copied()),
                });
            }
        }
        Ok(summary)
    }
}

impl std::fmt::Display for MeshSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let yes = |b: bool| if b { "yes" } else { "no" };
        writeln!(f, "file                 {} ({:?})", self.path, self.format)?;
        writeln!(
            f,
            "file records         {} vertices, {} faces",
            self.file_vertices, self.file_faces
        )?;
        writeln!(f, "triangles            {}", self.triangles)?;
        writeln!(f, "degenerate triangles {}", self.degenerate_triangles)?;
        writeln!(
            f,
            "vertices             {} (after seam splits)",
            self.vertices
        )?;
        writeln!(f, "welded vertices      {}", self.welded_vertices)?;
        if self.unreferenced_vertices > 0 {
            writeln!(
                f,
                "unreferenced         {} vertices dropped",
                self.unreferenced_vertices
            )?;
        }
        writeln!(
            f,
            "attributes           normals from file: {}, uvs: {}{}, colours: {}",
            yes(self.attributes.normals_from_file),
            yes(self.attributes.uvs),
            if self.attributes.uvs1 {
                " (+ a second set)"
            } else {
                ""
            },
            yes(self.attributes.colors)
        )?;
        let (lo, hi) = (self.aabb.min, self.aabb.max);
        writeln!(
            f,
            "bounds               [{:.6}, {:.6}, {:.6}] .. [{:.6}, {:.6}, {:.6}]",
            lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
        )?;
        writeln!(f, "diagonal             {:.6}", self.diagonal)?;
        let c = self.bounding_sphere.center;
        writeln!(
            f,
            "bounding sphere      centre [{:.6}, {:.6}, {:.6}], radius {:.6}",
            c.x, c.y, c.z, self.bounding_sphere.radius
        )?;
        writeln!(f, "materials            {}", self.materials.len())?;
        for m in &self.materials {
            writeln!(f, "  {:<18} {} triangles", m.name, m.triangles)?;
            let c = m.base_color;
            match m.model {
                super::Model::MetallicRoughness => writeln!(
                    f,
                    "    metallic–roughness: base [{:.3}, {:.3}, {:.3}], metallic {:.3}, roughness {:.3}",
                    c[0], c[1], c[2], m.metallic, m.roughness
                )?,
                super::Model::BlinnPhong => writeln!(
                    f,
                    "    Blinn–Phong: diffuse [{:.3}, {:.3}, {:.3}]",
                    c[0], c[1], c[2]
                )?,
            }
            if m.emission.iter().any(|&e| e > 0.0) {
                let e = m.emission;
                writeln!(f, "    emission [{:.3}, {:.3}, {:.3}]", e[0], e[1], e[2])?;
            }
            if m.alpha_mode != super::AlphaMode::Opaque || m.double_sided {
                writeln!(
                    f,
                    "    alpha {:?}{}",
                    m.alpha_mode,
                    if m.double_sided { ", double-sided" } else { "" }
                )?;
            }
            for t in &m.textures {
                writeln!(
                    f,
                    "    {:<24} {}x{} TEXCOORD_{} {}",
                    t.role, t.width, t.height, t.tex_coord, t.source
                )?;
            }
        }
        if let Some(chain) = &self.lod_chain {
            let loaded = chain.level.unwrap_or(0);
            writeln!(
                f,
                "MSFT_lod chain       {} levels on node '{}'; this is level #{loaded}{} (FILE#K \
                 loads level K)",
                chain.levels,
                chain.node,
                if loaded == 0 { ", the finest" } else { "" }
            )?;
            for l in &self.lod_levels {
                let coverage = match l.coverage {
                    Some(c) => format!("used down to {c:.6} screen coverage"),
                    None => "no screen coverage given".into(),
                };
                writeln!(
                    f,
                    "  #{:<3} {:>10} triangles {:>10} vertices   {coverage}",
                    l.level, l.triangles, l.vertices
                )?;
            }
        }
        for w in &self.warnings {
            writeln!(f, "warning: {w}")?;
        }
        Ok(())
    }
}
