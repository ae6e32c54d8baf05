//! glTF 2.0 loader, `.gltf` (external or embedded buffers) and `.glb` (parsing by `gltf`).
//!
//! Every mesh primitive reachable from the default scene (or the first scene; or, in a file with
//! no scenes, every mesh once) is loaded with its node's world transform applied; positions by the
//! matrix, normals by its inverse transpose, and triangle winding flipped under mirroring
//! transforms. Triangle strips and fans are converted; point and line primitives are skipped with
//! a warning. Materials are loaded whole by `gltf_material.rs` (every slot, sampler and
//! transform; each image decoded once per colour space). `TEXCOORD_0` and `TEXCOORD_1`, `COLOR_0`
//! (RGB; an alpha below 1 is a warning) and `KHR_lights_punctual` lights (at their nodes' world
//! transforms) are read.
//!
//! `MSFT_lod` chains: a node with the extension is loaded as its level 0 (its own mesh and
//! children) unless a level K is asked for (`FILE.glb#K`), which loads the node its `ids` list
//! K-th instead, under the same parent transform. Either way the chain (levels, the
//! `extras.MSFT_screencoverage` values) is recorded in the mesh's `Source`, so a caller can tell
//! "the original of a chain" from "a plain mesh".

use std::path::Path;

use glam::{Mat3, Mat4, Vec2, Vec3};

mod check;

use crate::error::{Error, Location, Result};
use crate::mesh::{
    FileLight, Format, LightKind, LoadOptions, LodChain, Material, MeshData, Source, SourceNode,
    read_file,
};

pub(super) const REEXPORT: &str =
    "re-export the glTF file (e.g. from Blender) or check it with the Khronos glTF validator";

/// Accumulates primitives into one indexed mesh.
#[derive(Default)]
struct Builder {
    positions: Vec<Vec3>,
    normals: Vec<Option<Vec3>>,
    uvs: Vec<Option<Vec2>>,
    uvs1: Vec<Option<Vec2>>,
    colors: Vec<Option<Vec3>>,
    /// A vertex colour alpha below 1 was met (glTF COLOR_0 as VEC4).
    color_alpha: bool,
    lights: Vec<FileLight>,
    nodes: Vec<SourceNode>,
    /// The first `MSFT_lod` chain met, and how many nodes carried one.
    chain: Option<LodChain>,
    chains: usize,
    triangles: Vec<[u32; 3]>,
    material_ids: Vec<u32>,
    file_vertices: usize,
    any_without_normals: bool,
    warnings: Vec<String>,
}

/// Load a glTF or GLB file; with `level`, level K of its `MSFT_lod` chain.
pub(crate) fn load(path: &Path, options: &LoadOptions, level: Option<usize>) -> Result<MeshData> {
    let bytes = read_file(path)?;
    check::check_glb_header(path, &bytes)?;
    let invalid =
        |e: gltf::Error| Error::input(path, format!("not a valid glTF file: {e}"), REEXPORT);
    let gltf::Gltf { document, blob } =
        gltf::Gltf::from_slice_without_validation(&bytes).map_err(invalid)?;
    let root = document.into_json();
    // Wrong accessor types first: they say more than the byte ranges they make wrong.
    check_primitive_accessors(path, &root)?;
    check::check(path, &root)?;
    let document = gltf::Document::from_json(root).map_err(invalid)?;
    let base = path.parent().unwrap_or(Path::new("."));
    let files = input_files(path, base, &document);
    check_external_buffers(path, base, &document)?;
    let buffers = gltf::import_buffers(&document, Some(base), blob).map_err(|e| {
        Error::input(
            path,
            format!("cannot load its binary buffers: {e}"),
            "put the .bin files named in the file next to it, or re-export as a single .glb",
        )
    })?;

    // Materials, every slot, decoding each used image once per colour space.
    let mut images = crate::mesh::gltf_material::Images::new(path, base, &buffers, options);
    let mut materials = Vec::new();
    for (mi, m) in document.materials().enumerate() {
        materials.push(crate::mesh::gltf_material::load(&m, mi, &mut images)?);
    }
    let mut warnings = std::mem::take(&mut images.warnings);
    let default_id = materials.len() as u32;
    check::check_tex_coords(path, document.as_json())?;

    let mut b = Builder::default();
    walk_scene(path, &document, &buffers, default_id, level, &mut b)?;
    if let (Some(k), None) = (level, &b.chain) {
        return Err(Error::input(
            path,
            format!("has no MSFT_lod chain, so it has no level #{k}"),
            "name the file without '#…'",
        ));
    }
    if b.chains > 1 {
        b.warnings.push(format!(
            "{} nodes carry MSFT_lod chains; the level is taken from each",
            b.chains
        ));
    }
    if b.material_ids.contains(&default_id) {
        materials.push(Material::default_material());
    }
    warnings.append(&mut b.warnings);
    if b.color_alpha {
        warnings.push(
            "COLOR_0 has alpha below 1; lodeval keeps vertex colours as RGB (the alpha is not \
             rendered or exported)"
                .into(),
        );
    }
    Ok(b.finish(path, files, materials, warnings))
}

/// Every file the document reads, besides itself (never to be overwritten by an output).
fn input_files(path: &Path, base: &Path, document: &gltf::Document) -> Vec<std::path::PathBuf> {
    let mut files = vec![path.to_path_buf()];
    for buffer in document.buffers() {
        if let gltf::buffer::Source::Uri(uri) = buffer.source()
            && !uri.starts_with("data:")
        {
            files.push(base.join(uri));
        }
    }
    for image in document.images() {
        if let gltf::image::Source::Uri { uri, .. } = image.source()
            && !uri.starts_with("data:")
        {
            files.push(base.join(uri));
        }
    }
    files
}

/// Name a missing or unreadable external buffer ourselves: the import error would only say "not
/// found", and a FIFO or /dev/zero named as a buffer would block or read without end.
fn check_external_buffers(path: &Path, base: &Path, document: &gltf::Document) -> Result<()> {
    for buffer in document.buffers() {
        if let gltf::buffer::Source::Uri(uri) = buffer.source() {
            let file = base.join(uri);
            if uri.starts_with("data:") || uri.contains('%') {
                continue;
            }
            let element = Location::Element(format!("buffer {}", buffer.index()));
            let fix = "put the .bin file next to the .gltf, or re-export as a single .glb";
            if !file.exists() {
                return Err(Error::input_at(
                    path,
                    element,
                    format!("its data file '{uri}' is missing"),
                    fix,
                ));
            }
            if let Err(Error::Input { problem, .. }) =
                crate::io::check_input(&file, "buffer", crate::limits::MESH_BYTES, fix)
            {
                return Err(Error::input_at(
                    path,
                    element,
                    format!("'{uri}': {problem}"),
                    fix,
                ));
            }
        }
    }
    Ok(())
}

/// Geometry: walk the default scene's graph (else the first scene's; with no scene, every mesh
/// untransformed), accumulating world transforms, into `b`.
fn walk_scene(
    path: &Path,
    document: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    default_id: u32,
    level: Option<usize>,
    b: &mut Builder,
) -> Result<()> {
    let roots: Vec<(gltf::Node, Mat4)> = match document
        .default_scene()
        .or_else(|| document.scenes().next())
    {
        Some(scene) => scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect(),
        None => Vec::new(),
    };
    if roots.is_empty() {
        for mesh in document.meshes() {
            add_mesh(path, b, &mesh, Mat4::IDENTITY, buffers, default_id)?;
        }
    }
    let mut stack = roots;
    stack.reverse();
    while let Some((node, parent)) = stack.pop() {
        let node = lod_level(path, document, node, level, b)?;
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(mesh) = node.mesh() {
            add_mesh(path, b, &mesh, world, buffers, default_id)?;
            b.nodes.push(SourceNode {
                name: node
                    .name()
                    .map_or_else(|| format!("node {}", node.index()), str::to_string),
                world,
            });
        }
        if let Some(light) = node.light() {
            b.lights.push(file_light(&light, world));
        }
        // Children pushed in reverse so they are visited in file order (deterministic numbering).
        let children: Vec<_> = node.children().collect();
        for child in children.into_iter().rev() {
            stack.push((child, world));
        }
    }
    Ok(())
}

/// The node to load for `node`: itself, or with `level` K ≥ 1 and an `MSFT_lod` extension, the
/// K-th node of its `ids`. Records the chain in `b`.
fn lod_level<'a>(
    path: &Path,
    document: &'a gltf::Document,
    node: gltf::Node<'a>,
    level: Option<usize>,
    b: &mut Builder,
) -> Result<gltf::Node<'a>> {
    let Some(ext) = node.extension_value("MSFT_lod") else {
        return Ok(node);
    };
    let name = node
        .name()
        .map_or_else(|| format!("node {}", node.index()), str::to_string);
    let bad = |what: String| {
        Error::input_at(
            path,
            Location::Element(format!("node '{name}' MSFT_lod")),
            what,
            REEXPORT,
        )
    };
    let ids: Option<Vec<usize>> = ext.get("ids").and_then(|v| v.as_array()).and_then(|ids| {
        ids.iter()
            .map(|v| {
                v.as_u64()
                    .map(|i| i as usize)
                    .filter(|&i| i < document.nodes().len())
            })
            .collect()
    });
    let Some(ids) = ids else {
        let what = "`ids` is missing or names a node that is not in the file";
        // Only a level asked for needs the chain; otherwise the node loads as it always did.
        if level.is_some() {
            return Err(bad(what.into()));
        }
        b.warnings.push(format!(
            "node '{name}': MSFT_lod {what}; the chain is ignored and the node loaded as it is"
        ));
        return Ok(node);
    };
    let coverage = node
        .extras()
        .as_ref()
        .and_then(|raw| serde_json::from_str::<serde_json::Value>(raw.get()).ok())
        .and_then(|v| serde_json::from_value(v.get("MSFT_screencoverage")?.clone()).ok());
    let levels = ids.len() + 1;
    b.chains += 1;
    b.chain.get_or_insert(LodChain {
        node: name.clone(),
        levels,
        coverage,
        level,
    });
    match level {
        None | Some(0) => Ok(node),
        Some(k) if k < levels => Ok(document.nodes().nth(ids[k - 1]).expect("checked above")),
        Some(k) => Err(Error::input(
            path,
            format!(
                "has no level #{k}: node '{name}' has MSFT_lod levels #0 (the finest) to #{}",
                levels - 1
            ),
            "name a level that exists",
        )),
    }
}

impl Builder {
    /// The mesh data of everything accumulated (an attribute only where some vertex had it).
    fn finish(
        self,
        path: &Path,
        files: Vec<std::path::PathBuf>,
        materials: Vec<Material>,
        warnings: Vec<String>,
    ) -> MeshData {
        let b = self;
        let has_uv = b.uvs.iter().any(Option::is_some);
        let has_uv1 = b.uvs1.iter().any(Option::is_some);
        let has_c = b.colors.iter().any(Option::is_some);
        let file_faces = b.triangles.len();
        MeshData {
            normals: (!b.any_without_normals)
                .then(|| b.normals.iter().map(|n| n.unwrap_or(Vec3::ZERO)).collect()),
            uvs: has_uv.then(|| b.uvs.iter().map(|u| u.unwrap_or(Vec2::ZERO)).collect()),
            uvs1: has_uv1.then(|| b.uvs1.iter().map(|u| u.unwrap_or(Vec2::ZERO)).collect()),
            lights: b.lights,
            colors: has_c.then(|| b.colors.iter().map(|c| c.unwrap_or(Vec3::ONE)).collect()),
            positions: b.positions,
            triangles: b.triangles,
            material_ids: b.material_ids,
            materials,
            source: Source {
                path: path.to_path_buf(),
                format: Format::Gltf,
                file_vertices: b.file_vertices,
                file_faces,
                file_unreferenced: 0,
                edited: false,
                files,
                nodes: b.nodes,
                lod_chain: b.chain,
            },
            warnings,
        }
    }
}

/// Check that every primitive names accessors that exist and have types lodeval reads. The `gltf`
/// crate panics on both kinds of file (found by the fuzz tests): its validation indexes the POSITION
/// accessor before checking it exists, and its readers hit `unreachable!` on an index or attribute
/// accessor of a component type the specification does not allow there. So this runs first.
fn check_primitive_accessors(path: &Path, root: &gltf::json::Root) -> Result<()> {
    use gltf::json::accessor::{ComponentType as C, Type as T};
    use gltf::json::mesh::Semantic as S;
    use gltf::json::validation::Checked;
    let count = root.accessors.len();
    for (mi, mesh) in root.meshes.iter().enumerate() {
        for (pi, prim) in mesh.primitives.iter().enumerate() {
            let here = || Location::Element(format!("mesh {mi} primitive {pi}"));
            let attributes = prim.attributes.iter().map(|(s, a)| (Some(s), a));
            for (semantic, accessor) in attributes.chain(prim.indices.iter().map(|a| (None, a))) {
                let Some(acc) = root.accessors.get(accessor.value()) else {
                    return Err(Error::input_at(
                        path,
                        here(),
                        format!(
                            "refers to accessor {}, but the file has {count} accessors",
                            accessor.value()
                        ),
                        REEXPORT,
                    ));
                };
                let (Checked::Valid(ty), Checked::Valid(ct)) = (&acc.type_, &acc.component_type)
                else {
                    continue; // reported by the validation that follows
                };
                let allowed: (&[T], &[C]) = match semantic {
                    None => (&[T::Scalar], &[C::U8, C::U16, C::U32]),
                    Some(Checked::Valid(S::Positions | S::Normals)) => (&[T::Vec3], &[C::F32]),
                    Some(Checked::Valid(S::TexCoords(_))) => (&[T::Vec2], &[C::F32, C::U8, C::U16]),
                    Some(Checked::Valid(S::Colors(_))) => {
                        (&[T::Vec3, T::Vec4], &[C::F32, C::U8, C::U16])
                    }
                    _ => continue, // attributes lodeval does not read
                };
                if !allowed.0.contains(ty) || !allowed.1.contains(&ct.0) {
                    let what = semantic.map_or("indices".to_string(), |s| format!("{s:?}"));
                    return Err(Error::input_at(
                        path,
                        here(),
                        format!(
                            "{what} accessor {} has type {ty:?} of {:?}, which glTF does not allow there",
                            accessor.value(),
                            ct.0
                        ),
                        REEXPORT,
                    ));
                }
            }
        }
    }
    Ok(())
}

/// A `KHR_lights_punctual` light at its node's world transform: position from the translation,
/// direction the node's −Z axis (the extension's convention).
fn file_light(light: &gltf::khr_lights_punctual::Light, world: Mat4) -> FileLight {
    use gltf::khr_lights_punctual::Kind;
    FileLight {
        name: light.name().map(str::to_string),
        kind: match light.kind() {
            Kind::Directional => LightKind::Directional,
            Kind::Point => LightKind::Point,
            Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => LightKind::Spot {
                inner_cone: inner_cone_angle,
                outer_cone: outer_cone_angle,
            },
        },
        position: world.transform_point3(Vec3::ZERO),
        direction: world.transform_vector3(-Vec3::Z).normalize_or(-Vec3::Z),
        color: Vec3::from(light.color()),
        intensity: light.intensity(),
        range: light.range(),
    }
}

fn add_mesh(
    path: &Path,
    b: &mut Builder,
    mesh: &gltf::Mesh,
    world: Mat4,
    buffers: &[gltf::buffer::Data],
    default_material: u32,
) -> Result<()> {
    let normal_matrix = Mat3::from_mat4(world).inverse().transpose();
    let mirrored = world.determinant() < 0.0;
    for prim in mesh.primitives() {
        let here = || {
            Location::Element(format!(
                "mesh {} ('{}') primitive {}",
                mesh.index(),
                mesh.name().unwrap_or(""),
                prim.index()
            ))
        };
        use gltf::mesh::Mode;
        if !matches!(
            prim.mode(),
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            b.warnings.push(format!(
                "mesh {} primitive {}: {:?} primitives are skipped",
                mesh.index(),
                prim.index(),
                prim.mode()
            ));
            continue;
        }
        let targets = prim.morph_targets().len();
        if targets > 0 {
            b.warnings.push(format!(
                "mesh {} ('{}') primitive {}: {targets} morph targets are not applied; the \
                 base shape is drawn and simplified (its default weights ignored)",
                mesh.index(),
                crate::error::quote(mesh.name().unwrap_or("")),
                prim.index()
            ));
        }
        let reader = prim.reader(|buf| buffers.get(buf.index()).map(|d| &d.0[..]));
        let Some(positions) = reader.read_positions() else {
            return Err(Error::input_at(
                path,
                here(),
                "has no POSITION attribute",
                REEXPORT,
            ));
        };
        let first = b.positions.len() as u32;
        let before = b.positions.len();
        b.positions
            .extend(positions.map(|p| world.transform_point3(Vec3::from(p))));
        let count = b.positions.len() - before;
        b.file_vertices += count;
        let attr_len = |len: usize, what: &str| -> Result<()> {
            if len != count {
                return Err(Error::input_at(
                    path,
                    here(),
                    format!("{what} has {len} entries for {count} positions"),
                    REEXPORT,
                ));
            }
            Ok(())
        };
        read_attributes(b, &reader, normal_matrix, count, &attr_len)?;
        let indices: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..count as u32).collect(),
        };
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= count) {
            return Err(Error::input_at(
                path,
                here(),
                format!("index {bad} is out of range ({count} vertices)"),
                REEXPORT,
            ));
        }
        let tris = triangles_of(prim.mode(), &indices);
        let material = prim
            .material()
            .index()
            .map_or(default_material, |m| m as u32);
        for t in tris {
            let t = t.map(|i| i + first);
            b.triangles
                .push(if mirrored { [t[0], t[2], t[1]] } else { t });
            b.material_ids.push(material);
        }
    }
    Ok(())
}

/// A primitive's NORMAL, TEXCOORD_0/1 and COLOR_0 appended to `b` (placeholders where it has
/// none); `check(len, name)` refuses an attribute whose length is not the positions' `count`.
fn read_attributes<'a, 's, F>(
    b: &mut Builder,
    reader: &gltf::mesh::Reader<'a, 's, F>,
    normal_matrix: Mat3,
    count: usize,
    check: &dyn Fn(usize, &str) -> Result<()>,
) -> Result<()>
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    match reader.read_normals() {
        Some(n) => {
            let n: Vec<Option<Vec3>> = n.map(|n| Some(normal_matrix * Vec3::from(n))).collect();
            check(n.len(), "NORMAL")?;
            b.normals.extend(n);
        }
        None => {
            b.any_without_normals = true;
            b.normals.extend(std::iter::repeat_n(None, count));
        }
    }
    for (set, out) in [(0, &mut b.uvs), (1, &mut b.uvs1)] {
        match reader.read_tex_coords(set) {
            Some(t) => {
                // glTF puts v = 0 at the top of the image; lodeval uses the OpenGL
                // convention (bottom).
                let t: Vec<Option<Vec2>> = t
                    .into_f32()
                    .map(|t| Some(Vec2::new(t[0], 1.0 - t[1])))
                    .collect();
                check(t.len(), &format!("TEXCOORD_{set}"))?;
                out.extend(t);
            }
            None => out.extend(std::iter::repeat_n(None, count)),
        }
    }
    match reader.read_colors(0) {
        Some(c) => {
            let c: Vec<[f32; 4]> = c.into_rgba_f32().collect();
            check(c.len(), "COLOR_0")?;
            b.color_alpha |= c.iter().any(|c| c[3] < 1.0);
            b.colors
                .extend(c.iter().map(|c| Some(Vec3::new(c[0], c[1], c[2]))));
        }
        None => b.colors.extend(std::iter::repeat_n(None, count)),
    }
    Ok(())
}

/// Triangles from a primitive's indices: lists, strips (every other one flipped to keep the
/// winding) or fans.
fn triangles_of(mode: gltf::mesh::Mode, indices: &[u32]) -> Vec<[u32; 3]> {
    use gltf::mesh::Mode;
    match mode {
        Mode::Triangles => indices
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect(),
        Mode::TriangleStrip => (0..indices.len().saturating_sub(2))
            .map(|k| {
                let (a, bb, c) = (indices[k], indices[k + 1], indices[k + 2]);
                if k % 2 == 0 { [a, bb, c] } else { [bb, a, c] }
            })
            .collect(),
        _ => (1..indices.len().saturating_sub(1))
            .map(|k| [indices[0], indices[k], indices[k + 1]])
            .collect(),
    }
}
