//! The facts `lodeval info` prints about a loaded mesh, as a serialisable struct.

use serde::Serialize;

use super::{Aabb, ColorSpace, Format, Mesh, Sphere};

/// One texture as `info` reports it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TextureSummary {
    /// `base_color` or `normal`.
    pub role: &'static str,
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
    /// Linear RGB base colour.
    pub base_color: [f32; 3],
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
    /// Non-fatal problems met while loading.
    pub warnings: Vec<String>,
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
                let textures = [
                    ("base_color", &m.base_color_texture),
                    ("normal", &m.normal_texture),
                ]
                .into_iter()
                .filter_map(|(role, t)| {
                    t.as_ref().map(|t| TextureSummary {
                        role,
                        source: t.label().to_string(),
                        width: t.width(),
                        height: t.height(),
                        color_space: t.color_space(),
                    })
                })
                .collect();
                MaterialSummary {
                    name: m.name.clone(),
                    triangles,
                    base_color: m.base_color.to_array(),
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
                colors: mesh.colors().is_some(),
            },
            materials,
            aabb: mesh.aabb(),
            diagonal: mesh.aabb().diagonal(),
            bounding_sphere: mesh.bounding_sphere(),
            warnings: mesh.warnings().to_vec(),
        }
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
            "attributes           normals from file: {}, uvs: {}, colours: {}",
            yes(self.attributes.normals_from_file),
            yes(self.attributes.uvs),
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
            for t in &m.textures {
                writeln!(
                    f,
                    "    {:<10} {}x{} {}",
                    t.role, t.width, t.height, t.source
                )?;
            }
        }
        for w in &self.warnings {
            writeln!(f, "warning: {w}")?;
        }
        Ok(())
    }
}
