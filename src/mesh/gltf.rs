//! glTF 2.0 loader, `.gltf` (external or embedded buffers) and `.glb` (parsing by `gltf`).
//!
//! Every mesh primitive reachable from the default scene (or the first scene; or, in a file with
//! no scenes, every mesh once) is loaded with its node's world transform applied; positions by the
//! matrix, normals by its inverse transpose, and triangle winding flipped under mirroring
//! transforms. Triangle strips and fans are converted; point and line primitives are skipped with
//! a warning. Only the images a material actually uses are decoded (base colour and normal map),
//! each once.
//!
//! Decisions: the metallic–roughness material is reduced to Blinn–Phong for lodeval's shading
//! models by [`Material::specular_from_metallic_roughness`], with the mean of the
//! metallic-roughness texture standing in for the texture (one specular colour per material).
//! Only `TEXCOORD_0` is read; a material that samples another set gets a warning.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use glam::{Mat3, Mat4, Vec2, Vec3};

use super::texture::{ColorSpace, Texture};
use super::{Format, LoadOptions, Material, MeshData, MissingAssets, Source, read_file};
use crate::error::{Error, Location, Result};

pub(super) const REEXPORT: &str =
    "re-export the glTF file (e.g. from Blender) or check it with the Khronos glTF validator";

/// Accumulates primitives into one indexed mesh.
#[derive(Default)]
struct Builder {
    positions: Vec<Vec3>,
    normals: Vec<Option<Vec3>>,
    uvs: Vec<Option<Vec2>>,
    colors: Vec<Option<Vec3>>,
    triangles: Vec<[u32; 3]>,
    material_ids: Vec<u32>,
    file_vertices: usize,
    any_without_normals: bool,
    warnings: Vec<String>,
}

fn rgba8_from(data: gltf::image::Data) -> std::result::Result<(u32, u32, Vec<u8>), String> {
    use gltf::image::Format as F;
    let px = &data.pixels;
    let rgba: Vec<u8> = match data.format {
        F::R8 => px.iter().flat_map(|&r| [r, r, r, 255]).collect(),
        F::R8G8 => px
            .chunks_exact(2)
            .flat_map(|c| [c[0], c[1], 0, 255])
            .collect(),
        F::R8G8B8 => px
            .chunks_exact(3)
            .flat_map(|c| [c[0], c[1], c[2], 255])
            .collect(),
        F::R8G8B8A8 => px.clone(),
        // 16-bit channels: keep the high byte (native little-endian order as `image` produces).
        F::R16 => px
            .chunks_exact(2)
            .flat_map(|c| [c[1], c[1], c[1], 255])
            .collect(),
        F::R16G16 => px
            .chunks_exact(4)
            .flat_map(|c| [c[1], c[3], 0, 255])
            .collect(),
        F::R16G16B16 => px
            .chunks_exact(6)
            .flat_map(|c| [c[1], c[3], c[5], 255])
            .collect(),
        F::R16G16B16A16 => px
            .chunks_exact(8)
            .flat_map(|c| [c[1], c[3], c[5], c[7]])
            .collect(),
        other => return Err(format!("unsupported texel format {other:?}")),
    };
    Ok((data.width, data.height, rgba))
}

/// Mean of the R, G and B channels of RGBA8 texels, in 0..1.
fn mean_channels(rgba: &[u8]) -> [f32; 3] {
    let mut sum = [0u64; 3];
    for px in rgba.chunks_exact(4) {
        for c in 0..3 {
            sum[c] += px[c] as u64;
        }
    }
    let n = (rgba.len() / 4).max(1) as f64 * 255.0;
    sum.map(|s| (s as f64 / n) as f32)
}

/// An external image must be a regular file within [`crate::limits::IMAGE_BYTES`] before the
/// `gltf` crate reads it (a FIFO or `/dev/zero` would block or read without end).
fn check_image_uri(base: &Path, source: gltf::image::Source) -> std::result::Result<(), String> {
    match source {
        gltf::image::Source::Uri { uri, .. } if !uri.starts_with("data:") && !uri.contains('%') => {
            crate::io::check_input(&base.join(uri), "image", crate::limits::IMAGE_BYTES, "")
                .map(|_| ())
                .map_err(|e| match e {
                    Error::Input { problem, .. } => problem,
                    other => other.to_string(),
                })
        }
        _ => Ok(()),
    }
}

/// Load a glTF or GLB file.
pub(crate) fn load(path: &Path, options: &LoadOptions) -> Result<MeshData> {
    let bytes = read_file(path)?;
    let invalid =
        |e: gltf::Error| Error::input(path, format!("not a valid glTF file: {e}"), REEXPORT);
    let gltf::Gltf { document, blob } =
        gltf::Gltf::from_slice_without_validation(&bytes).map_err(invalid)?;
    let root = document.into_json();
    // Wrong accessor types first: they say more than the byte ranges they make wrong.
    check_primitive_accessors(path, &root)?;
    super::gltf_check::check(path, &root)?;
    let document = gltf::Document::from_json(root).map_err(invalid)?;
    let base = path.parent().unwrap_or(Path::new("."));
    // Every file the document reads, besides itself (never to be overwritten by an output).
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
    // Name a missing external buffer ourselves; the import error would only say "not found".
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
            // A FIFO or /dev/zero named as a buffer would block or read without end.
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
    let buffers = gltf::import_buffers(&document, Some(base), blob).map_err(|e| {
        Error::input(
            path,
            format!("cannot load its binary buffers: {e}"),
            "put the .bin files named in the file next to it, or re-export as a single .glb",
        )
    })?;

    // Materials, decoding each used image once per colour space.
    let mut images: BTreeMap<(usize, bool), Arc<Texture>> = BTreeMap::new();
    let mut warnings = Vec::new();
    let mut materials = Vec::new();
    for (mi, m) in document.materials().enumerate() {
        let name = m
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| format!("material {mi}"));
        let pbr = m.pbr_metallic_roughness();
        let [r, g, b, _] = pbr.base_color_factor();
        let base_color = Vec3::new(r, g, b);
        // The metallic-roughness texture (G = roughness, B = metallic) scales the factors; lodeval's
        // Blinn–Phong material has one specular colour and exponent, so the texture's mean is used.
        let (mut metallic, mut roughness) = (pbr.metallic_factor(), pbr.roughness_factor());
        if let Some(info) = pbr.metallic_roughness_texture() {
            let source = info.texture().source().source();
            let mean = check_image_uri(base, source.clone())
                .ok()
                .and_then(|()| gltf::image::Data::from_source(source, Some(base), &buffers).ok())
                .and_then(|d| rgba8_from(d).ok())
                .map(|(_, _, px)| mean_channels(&px));
            match mean {
                Some([_, g, b]) => {
                    roughness *= g;
                    metallic *= b;
                }
                None => warnings.push(format!(
                    "material '{name}': metallic-roughness texture unreadable; using the factors"
                )),
            }
        }
        let (specular, shininess) =
            Material::specular_from_metallic_roughness(base_color, metallic, roughness);
        let mut mat = Material {
            name: name.clone(),
            base_color,
            base_color_texture: None,
            normal_texture: None,
            specular,
            shininess,
        };
        let wanted = [
            pbr.base_color_texture()
                .map(|t| (t.texture(), t.tex_coord(), ColorSpace::Srgb)),
            m.normal_texture()
                .map(|t| (t.texture(), t.tex_coord(), ColorSpace::Linear)),
        ];
        for (slot, want) in wanted.into_iter().enumerate() {
            let Some((tex, set, space)) = want else {
                continue;
            };
            if set != 0 {
                warnings.push(format!(
                    "material '{name}' samples TEXCOORD_{set}; lodeval reads TEXCOORD_0 only"
                ));
            }
            let image = tex.source();
            let key = (image.index(), space == ColorSpace::Srgb);
            let decoded = match images.get(&key) {
                Some(t) => Ok(t.clone()),
                None => {
                    let label = match image.source() {
                        gltf::image::Source::Uri { uri, .. } if !uri.starts_with("data:") => {
                            base.join(uri).display().to_string()
                        }
                        _ => format!("{} image {}", path.display(), image.index()),
                    };
                    check_image_uri(base, image.source())
                        .and_then(|()| {
                            gltf::image::Data::from_source(image.source(), Some(base), &buffers)
                                .map_err(|e| e.to_string())
                        })
                        .and_then(rgba8_from)
                        .and_then(|(w, h, px)| {
                            Texture::new(label.clone(), w, h, px, space)
                                .ok_or_else(|| format!("the image has zero size ({w}x{h})"))
                        })
                        .map(Arc::new)
                        .map_err(|e| format!("image {} ('{label}'): {e}", image.index()))
                }
            };
            match decoded {
                Ok(t) => {
                    images.insert(key, t.clone());
                    if slot == 0 {
                        mat.base_color_texture = Some(t);
                    } else {
                        mat.normal_texture = Some(t);
                    }
                }
                Err(e) => match options.missing_assets {
                    MissingAssets::Error => {
                        return Err(Error::input_at(
                            path,
                            Location::Element(format!("material '{name}'")),
                            format!("texture cannot be loaded: {e}"),
                            "put the image next to the file, or pass --missing-assets warn to render with the base colour",
                        ));
                    }
                    MissingAssets::Warn => warnings.push(format!("material '{name}': {e}")),
                },
            }
        }
        materials.push(mat);
    }
    let default_id = materials.len() as u32;

    // Geometry: walk the scene graph, accumulating world transforms.
    let mut b = Builder::default();
    let roots: Vec<(gltf::Node, Mat4)> = match document
        .default_scene()
        .or_else(|| document.scenes().next())
    {
        Some(scene) => scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect(),
        None => Vec::new(),
    };
    if roots.is_empty() {
        for mesh in document.meshes() {
            add_mesh(path, &mut b, &mesh, Mat4::IDENTITY, &buffers, default_id)?;
        }
    }
    let mut stack = roots;
    stack.reverse();
    while let Some((node, parent)) = stack.pop() {
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(mesh) = node.mesh() {
            add_mesh(path, &mut b, &mesh, world, &buffers, default_id)?;
        }
        // Children pushed in reverse so they are visited in file order (deterministic numbering).
        let children: Vec<_> = node.children().collect();
        for child in children.into_iter().rev() {
            stack.push((child, world));
        }
    }
    if b.material_ids.contains(&default_id) {
        materials.push(Material::default_material());
    }
    warnings.append(&mut b.warnings);
    let has_uv = b.uvs.iter().any(Option::is_some);
    let has_c = b.colors.iter().any(Option::is_some);
    let file_faces = b.triangles.len();
    Ok(MeshData {
        normals: (!b.any_without_normals)
            .then(|| b.normals.iter().map(|n| n.unwrap_or(Vec3::ZERO)).collect()),
        uvs: has_uv.then(|| b.uvs.iter().map(|u| u.unwrap_or(Vec2::ZERO)).collect()),
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
        },
        warnings,
    })
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
        match reader.read_normals() {
            Some(n) => {
                let n: Vec<Option<Vec3>> = n.map(|n| Some(normal_matrix * Vec3::from(n))).collect();
                attr_len(n.len(), "NORMAL")?;
                b.normals.extend(n);
            }
            None => {
                b.any_without_normals = true;
                b.normals.extend(std::iter::repeat_n(None, count));
            }
        }
        match reader.read_tex_coords(0) {
            Some(t) => {
                // glTF puts v = 0 at the top of the image; lodeval uses the OpenGL convention (bottom).
                let t: Vec<Option<Vec2>> = t
                    .into_f32()
                    .map(|t| Some(Vec2::new(t[0], 1.0 - t[1])))
                    .collect();
                attr_len(t.len(), "TEXCOORD_0")?;
                b.uvs.extend(t);
            }
            None => b.uvs.extend(std::iter::repeat_n(None, count)),
        }
        match reader.read_colors(0) {
            Some(c) => {
                let c: Vec<Option<Vec3>> = c.into_rgb_f32().map(|c| Some(Vec3::from(c))).collect();
                attr_len(c.len(), "COLOR_0")?;
                b.colors.extend(c);
            }
            None => b.colors.extend(std::iter::repeat_n(None, count)),
        }
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
        let tris: Vec<[u32; 3]> = match prim.mode() {
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
        };
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
