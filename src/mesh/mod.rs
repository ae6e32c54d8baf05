//! The in-memory triangle mesh every stage of lodeval works on, and the loaders that produce it.
//!
//! Data flow: a format loader (`obj.rs`, `ply.rs`, `gltf.rs`, `off.rs`) turns a file into a raw
//! [`MeshData`]; [`Mesh::new`] runs the one validator (`validate.rs`), drops unreferenced vertices,
//! fills in missing normals (`normals.rs`), welds positions (`weld.rs`) and computes bounds
//! (`bounds.rs`). A [`Mesh`] therefore always holds a valid mesh; see its `# Guarantees`.
//!
//! Decisions taken where the architecture contract (ARCHITECTURE.md) is silent:
//! - Vertices are split wherever the file gives different UVs, normals or colours at one position
//!   ("seams"); [`Mesh::weld`] maps every vertex back to its welded position. Welding is by exact
//!   coordinate equality (−0 and +0 are equal), the same rule meshoptimizer's position remap uses, so
//!   it is format independent and does not merge vertices that merely lie close together.
//! - Colours (material base colour, vertex colours) are stored in linear RGB. 8-bit vertex colours
//!   (PLY, OBJ `v x y z r g b`) are sRGB-decoded on load; MTL `Kd`/`Ks` and glTF factors are taken as
//!   linear, which is what glTF specifies and what most OBJ exporters mean.
//! - Textures stay as decoded 8-bit RGBA with their colour space tagged ([`Texture`]); the renderer
//!   converts to linear light once when it builds the mip pyramid. This keeps a 2048² texture at
//!   16 MiB instead of 64 MiB.
//! - Missing or undecodable textures and material libraries are an error by default: a mesh that
//!   silently renders without its texture gives scores that look fine and are meaningless. With
//!   [`MissingAssets::Warn`] the material keeps its base colour and a warning is recorded in
//!   [`Mesh::warnings`].

mod bounds;
pub mod edit;
mod enclosing;
mod gltf;
mod gltf_material;
mod incidence;
mod material;
mod material_check;
mod mtl;
mod normals;
mod obj;
mod off;
mod ply;
pub mod shapes;
mod summary;
pub mod surface_distance;
pub mod tangents;
mod texture;
mod validate;
mod weld;
pub mod write_gltf;
mod write_gltf_material;
pub mod write_obj;

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

use crate::error::{Error, Result};

pub use bounds::{Aabb, EngineBounds, Sphere};
pub use enclosing::minimal_sphere;
pub use material::{
    AlphaMode, Filter, Material, Model, Sampler, TextureSlot, TextureTransform, Wrap,
};
pub use summary::{Attributes, MaterialSummary, MeshSummary, TextureSummary};
pub use texture::{ColorSpace, EncodedImage, Texture};

/// The file formats lodeval reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
#[non_exhaustive]
pub enum Format {
    /// Wavefront OBJ with optional MTL material libraries.
    Obj,
    /// Stanford PLY, ASCII or binary.
    Ply,
    /// glTF 2.0, `.gltf` (JSON with external or embedded buffers) or `.glb`.
    Gltf,
    /// Object File Format.
    Off,
}

impl Format {
    /// The format for a path's extension (case-insensitive), or a usage error listing the known ones.
    pub fn from_path(path: &Path) -> Result<Format> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        match ext.as_deref() {
            Some("obj") => Ok(Format::Obj),
            Some("ply") => Ok(Format::Ply),
            Some("gltf") | Some("glb") => Ok(Format::Gltf),
            Some("off") => Ok(Format::Off),
            other => Err(Error::input(
                path,
                match other {
                    Some(e) => format!("unknown mesh file extension '.{e}'"),
                    None => "the file name has no extension, so its format is unknown".into(),
                },
                "lodeval reads .obj (with .mtl), .ply, .gltf, .glb and .off files",
            )),
        }
    }
}

/// What to do when a referenced texture or material library is missing or cannot be decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
#[non_exhaustive]
pub enum MissingAssets {
    /// Fail with an input error naming the file (the default).
    #[default]
    #[value(help = "Fail with a message naming the file")]
    Error,
    /// Keep the material's base colour and record a warning in [`Mesh::warnings`].
    #[value(help = "Warn and render with the material's base colour")]
    Warn,
}

/// Options for [`load`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct LoadOptions {
    /// Policy for missing or undecodable textures and MTL files. Default value: `Error`.
    pub missing_assets: MissingAssets,
    /// For meshes without normals: faces meeting at a vertex at a dihedral angle above this many
    /// degrees get separate normals (a crease). 180 means smooth everywhere. Default value: 180.
    pub crease_angle_deg: f32,
}

impl LoadOptions {
    /// The defaults.
    pub const DEFAULT: LoadOptions = LoadOptions {
        missing_assets: MissingAssets::Error,
        crease_angle_deg: 180.0,
    };
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// The kind of a light a file declares (`KHR_lights_punctual`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum LightKind {
    /// Infinitely far, along `direction`; intensity in lux.
    Directional,
    /// At `position`, in every direction; intensity in candela.
    Point,
    /// At `position`, a cone about `direction`; intensity in candela.
    Spot {
        /// Angle from the axis, radians, inside which the intensity is full.
        inner_cone: f32,
        /// Angle from the axis, radians, outside which there is no light.
        outer_cone: f32,
    },
}

/// A light a file declares, in world space (its node's transform applied).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FileLight {
    /// The light's name in the file.
    pub name: Option<String>,
    /// Its kind.
    pub kind: LightKind,
    /// Position (point and spot lights).
    pub position: Vec3,
    /// The direction the light travels (directional and spot lights): the node's −Z.
    pub direction: Vec3,
    /// Linear RGB colour.
    pub color: Vec3,
    /// Intensity (lux or candela, by kind).
    pub intensity: f32,
    /// Distance beyond which the light is zero, if given.
    pub range: Option<f32>,
}

/// Where a mesh came from and what the file itself declared.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Source {
    /// The file that was loaded.
    pub path: PathBuf,
    /// Its format.
    pub format: Format,
    /// Vertex records in the file (OBJ `v` lines, PLY/OFF vertex count, glTF POSITION counts of
    /// every primitive instance), before seam splitting or removal of unreferenced vertices.
    pub file_vertices: usize,
    /// Face records in the file (polygons, strips count as their triangles).
    pub file_faces: usize,
    /// Vertex records no face uses, where the loader dropped them before [`Mesh::new`] could
    /// count them (OBJ); [`Mesh::unreferenced_removed`] adds the ones dropped later.
    pub file_unreferenced: usize,
    /// True for a mesh built in code from a loaded one (a LOD, an edited copy): its triangles
    /// are not the file's, and messages about them say so.
    pub edited: bool,
    /// Every file read to build the mesh: the mesh file, its material libraries, textures, glTF
    /// buffers and images. Nothing lodeval writes may be one of them.
    pub files: Vec<PathBuf>,
    /// The scene nodes whose meshes were merged into this one (glTF), with the world transforms
    /// the loader applied to their vertices; empty for formats without nodes.
    pub nodes: Vec<SourceNode>,
    /// glTF: the `MSFT_lod` chain the file holds, if any, and which level was loaded.
    pub lod_chain: Option<LodChain>,
}

/// A glTF node's `MSFT_lod` chain: level 0 is the node's own mesh (the finest), levels 1 … N−1
/// the nodes its `ids` list, coarser in turn. `FILE.glb#K` loads level K.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LodChain {
    /// The node that carries the extension (its name, or `node N`).
    pub node: String,
    /// Levels, the node's own included.
    pub levels: usize,
    /// `extras.MSFT_screencoverage`, one value per level, where the file gives it.
    pub coverage: Option<Vec<f64>>,
    /// The level loaded: `Some(K)` for `FILE#K`, `None` when the path named no level (level 0
    /// was loaded).
    pub level: Option<usize>,
}

/// `FILE.glb#K` or `FILE.gltf#K`: the file and level K of its `MSFT_lod` chain. A path that
/// exists as written is a file, '#' and all; anything else is the path itself and no level.
pub fn split_level(path: &Path) -> (PathBuf, Option<usize>) {
    if path.exists() {
        return (path.to_path_buf(), None);
    }
    let text = path.to_string_lossy();
    if let Some((file, level)) = text.rsplit_once('#')
        && let Ok(level) = level.parse::<usize>()
        && matches!(Format::from_path(Path::new(file)), Ok(Format::Gltf))
    {
        return (PathBuf::from(file), Some(level));
    }
    (path.to_path_buf(), None)
}

/// A glTF node whose mesh the loader merged, and the world transform it applied.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SourceNode {
    /// The node's name, or `node N` where it has none.
    pub name: String,
    /// Its world transform (column-major), applied to the vertices on load.
    pub world: glam::Mat4,
}

/// A mesh as a loader produced it, before validation. Every field is plain data; [`Mesh::new`]
/// checks it.
#[derive(Debug, Clone)]
pub struct MeshData {
    /// Vertex positions in model units.
    pub positions: Vec<Vec3>,
    /// Per-vertex normals, if the file has them (need not be unit length).
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates (`TEXCOORD_0`; OBJ `vt`).
    pub uvs: Option<Vec<Vec2>>,
    /// A second texture coordinate set (`TEXCOORD_1`), for slots that name it.
    pub uvs1: Option<Vec<Vec2>>,
    /// Per-vertex linear RGB colours.
    pub colors: Option<Vec<Vec3>>,
    /// Triangles as vertex indices, counter-clockwise front faces.
    pub triangles: Vec<[u32; 3]>,
    /// Material index per triangle; empty means material 0 everywhere.
    pub material_ids: Vec<u32>,
    /// Materials; if empty, one default material is added.
    pub materials: Vec<Material>,
    /// Lights the file declares (glTF `KHR_lights_punctual`).
    pub lights: Vec<FileLight>,
    /// Provenance.
    pub source: Source,
    /// Non-fatal problems the loader met (e.g. a missing texture under [`MissingAssets::Warn`]).
    pub warnings: Vec<String>,
}

/// A validated, indexed triangle mesh.
///
/// # Guarantees
/// - At least one triangle; every index is `< vertex_count()`.
/// - Every position is finite; every normal present is finite and unit length; UVs and colours
///   are finite. Attribute arrays have exactly `vertex_count()` entries.
/// - Every vertex is used by some triangle.
/// - `material_ids().len() == triangle_count()` and every id indexes `materials()`.
/// - `weld()[v]` is the index of `v`'s position in the welded position list, `< welded_vertex_count()`.
/// - Normals are always present (computed angle-weighted where the file had none).
#[derive(Debug, Clone)]
pub struct Mesh {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Option<Vec<Vec2>>,
    uvs1: Option<Vec<Vec2>>,
    colors: Option<Vec<Vec3>>,
    triangles: Vec<[u32; 3]>,
    material_ids: Vec<u32>,
    materials: Vec<Material>,
    lights: Vec<FileLight>,
    weld: Vec<u32>,
    welded_count: usize,
    degenerate: usize,
    normals_from_file: bool,
    unreferenced_removed: usize,
    aabb: Aabb,
    sphere: Sphere,
    engine_bounds: EngineBounds,
    source: Source,
    warnings: Vec<String>,
}

impl Mesh {
    /// Validate raw loader output and complete it into a [`Mesh`].
    pub fn new(mut data: MeshData, options: &LoadOptions) -> Result<Mesh> {
        // Check every structural and numeric rule; bad data is an input error naming the element.
        let report = validate::check(&data)?;
        if data.materials.is_empty() {
            data.materials.push(Material::default_material());
        }
        if data.material_ids.is_empty() {
            data.material_ids = vec![0; data.triangles.len()];
        }
        // Drop vertices no triangle uses, so every later stage can rely on "every vertex is used".
        let unreferenced_removed =
            validate::compact_unreferenced(&mut data) + data.source.file_unreferenced;
        // Normals: keep the file's (normalised), or compute angle-weighted ones with creases.
        let normals_from_file = data.normals.is_some();
        let normals = match data.normals.take() {
            Some(n) => normals::normalize_given(&n, &data.positions, &data.triangles),
            None => normals::generate(&mut data, options.crease_angle_deg),
        };
        // Weld by exact position so simplifiers can see through seams.
        let (weld, welded_count) = weld::by_position(&data.positions);
        let aabb = Aabb::of(&data.positions);
        let sphere = enclosing::minimal_sphere(&data.positions);
        let engine_bounds = EngineBounds::of(&data.positions);
        Ok(Mesh {
            positions: data.positions,
            normals,
            uvs: data.uvs,
            uvs1: data.uvs1,
            colors: data.colors,
            triangles: data.triangles,
            material_ids: data.material_ids,
            materials: data.materials,
            lights: data.lights,
            weld,
            welded_count,
            degenerate: report.degenerate_triangles,
            normals_from_file,
            unreferenced_removed,
            aabb,
            sphere,
            engine_bounds,
            source: data.source,
            warnings: data.warnings,
        })
    }

    /// The mesh as plain data, for building an edited copy with [`Mesh::new`]. Normals are included
    /// only if they came from the file, so generated ones are generated again for the new shape.
    pub fn to_data(&self) -> MeshData {
        MeshData {
            positions: self.positions.clone(),
            normals: self.normals_from_file.then(|| self.normals.clone()),
            uvs: self.uvs.clone(),
            uvs1: self.uvs1.clone(),
            colors: self.colors.clone(),
            triangles: self.triangles.clone(),
            material_ids: self.material_ids.clone(),
            materials: self.materials.clone(),
            lights: self.lights.clone(),
            source: Source {
                edited: true,
                lod_chain: None,
                ..self.source.clone()
            },
            warnings: self.warnings.clone(),
        }
    }

    /// Vertex positions in model units.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }
    /// Unit vertex normals (from the file, or generated; see [`Mesh::normals_from_file`]).
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }
    /// Texture coordinates, if the file has them.
    pub fn uvs(&self) -> Option<&[Vec2]> {
        self.uvs.as_deref()
    }
    /// The second texture coordinate set (`TEXCOORD_1`), if the file has it.
    pub fn uvs1(&self) -> Option<&[Vec2]> {
        self.uvs1.as_deref()
    }
    /// Texture coordinate set `set` (0 or 1), if the mesh has it.
    pub fn uv_set(&self, set: u32) -> Option<&[Vec2]> {
        match set {
            0 => self.uvs(),
            1 => self.uvs1(),
            _ => None,
        }
    }
    /// Linear RGB vertex colours, if the file has them.
    pub fn colors(&self) -> Option<&[Vec3]> {
        self.colors.as_deref()
    }
    /// Triangles (counter-clockwise front faces).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }
    /// Material index of each triangle.
    pub fn material_ids(&self) -> &[u32] {
        &self.material_ids
    }
    /// Materials (at least one).
    pub fn materials(&self) -> &[Material] {
        &self.materials
    }
    /// Whether any material is metallic–roughness (what the `auto` shading draws with `pbr`).
    pub fn prefers_pbr(&self) -> bool {
        self.materials
            .iter()
            .any(|m| m.model == Model::MetallicRoughness)
    }
    /// Lights the file declares, world space.
    pub fn lights(&self) -> &[FileLight] {
        &self.lights
    }
    /// Number of vertices (after seam splitting).
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }
    /// Map from vertex to welded position index.
    pub fn weld(&self) -> &[u32] {
        &self.weld
    }
    /// Number of distinct positions.
    pub fn welded_vertex_count(&self) -> usize {
        self.welded_count
    }
    /// Triangles with zero area (repeated or collinear corners). Counted, not fatal.
    pub fn degenerate_triangles(&self) -> usize {
        self.degenerate
    }
    /// Whether the normals came from the file.
    pub fn normals_from_file(&self) -> bool {
        self.normals_from_file
    }
    /// Vertex records of the file that no triangle used (dropped).
    pub fn unreferenced_removed(&self) -> usize {
        self.unreferenced_removed
    }
    /// Axis-aligned bounding box.
    pub fn aabb(&self) -> Aabb {
        self.aabb
    }
    /// The minimal enclosing sphere of the vertices (Welzl 1991): what renders are framed by and
    /// on-screen sizes are measured by.
    pub fn bounding_sphere(&self) -> Sphere {
        self.sphere
    }
    /// The bounds Unity, Unreal and glTF `MSFT_lod` readers measure LOD switches by.
    pub fn engine_bounds(&self) -> EngineBounds {
        self.engine_bounds
    }
    /// Provenance.
    pub fn source(&self) -> &Source {
        &self.source
    }
    /// Non-fatal problems met while loading.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }
}

/// Load a mesh file, picking the loader by extension.
///
/// Every failure is an [`Error::Input`] naming the file and, where known, the line or element.
/// A loader crate that panics on malformed data is caught and reported the same way, so bad input
/// never aborts the process.
pub fn load(path: &Path, options: &LoadOptions) -> Result<Mesh> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        load_unguarded(path, options)
    })) {
        Ok(result) => result,
        Err(_) => Err(Error::input(
            path,
            "the file is malformed (the parser gave up on it)",
            "re-export the file from its authoring tool",
        )),
    }
}

/// [`load`] without the panic guard. Exists for the fuzz tests, which must see a panic in our code
/// or a parser crate as the bug it is rather than as a handled error.
#[doc(hidden)]
pub fn load_unguarded(path: &Path, options: &LoadOptions) -> Result<Mesh> {
    let (path, level) = split_level(path);
    let path = path.as_path();
    let format = Format::from_path(path)?;
    if !path.exists() {
        return Err(Error::input(path, "file not found", "check the path"));
    }
    if path.is_dir() {
        return Err(Error::input(
            path,
            "is a directory, not a mesh file",
            "name a mesh file",
        ));
    }
    let data = match format {
        Format::Obj => obj::load(path, options),
        Format::Ply => ply::load(path),
        Format::Gltf => gltf::load(path, options, level),
        Format::Off => off::load(path),
    }?;
    Mesh::new(data, options)
}

/// Read a whole file, mapping I/O failures to an input error naming it.
pub(crate) fn read_file(path: &Path) -> Result<Vec<u8>> {
    crate::io::read_input(
        path,
        "mesh",
        crate::limits::MESH_BYTES,
        "check that it exists and is a readable mesh file",
    )
}

/// [`read_file`] for a text format (OBJ, OFF): read in pieces, and refused at the first NUL
/// byte, which no text mesh holds. A binary file, or a sparse one of gigabytes of zeros, is
/// refused after its first megabyte instead of being read whole.
pub(crate) fn read_text_file(path: &Path) -> Result<Vec<u8>> {
    use std::io::Read as _;
    let fix =
        "give a text mesh file (this one is binary, or holds zeros: a sparse or damaged file)";
    let len = crate::io::check_input(path, "mesh", crate::limits::MESH_BYTES, fix)?;
    let cannot = |e: std::io::Error| Error::input(path, format!("cannot read the mesh: {e}"), fix);
    let mut file = std::fs::File::open(path).map_err(cannot)?;
    let mut bytes: Vec<u8> = Vec::with_capacity(len.min(1 << 20) as usize);
    let mut chunk = vec![0u8; 1 << 20];
    loop {
        let n = file.read(&mut chunk).map_err(cannot)?;
        if n == 0 {
            break;
        }
        if let Some(k) = chunk[..n].iter().position(|&b| b == 0) {
            let lines = bytes
                .iter()
                .chain(&chunk[..k])
                .filter(|&&b| b == b'\n')
                .count();
            return Err(Error::input_at(
                path,
                crate::error::Location::Line(lines + 1),
                format!(
                    "byte {} is a NUL byte: the file is not text (a text mesh holds none)",
                    bytes.len() + k
                ),
                fix,
            ));
        }
        if (bytes.len() + n) as u64 > crate::limits::MESH_BYTES {
            return Err(Error::input(
                path,
                format!(
                    "the mesh grew past lodeval's limit of {} bytes while it was read",
                    crate::limits::MESH_BYTES
                ),
                fix,
            ));
        }
        bytes.extend_from_slice(&chunk[..n]);
    }
    Ok(bytes)
}
