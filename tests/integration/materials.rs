//! Materials, loaded whole and exported whole: every glTF material slot, factor, sampler, texture
//! coordinate set and texture transform of an input comes back from the chain `simplify -o
//! X.glb|.gltf` writes (read back with lodeval's own loader), the images byte for byte; what
//! cannot be carried is a warning that names it. MTL's PBR keys map to the metallic–roughness
//! model. Set `LODEVAL_GLTF_EXPORTS=DIR` to keep the chains for Khronos' validator (`.ci/run`).

use std::path::{Path, PathBuf};

use lodeval::mesh::{self, AlphaMode, Filter, Material, Model, TextureSlot, Wrap};

use crate::common::{lodeval, model, simplify};

fn load(path: &Path) -> mesh::Mesh {
    mesh::load(path, &mesh::LoadOptions::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Where to keep an exported chain: `LODEVAL_GLTF_EXPORTS` if set, else a temporary folder.
fn export_dir(tmp: &Path) -> PathBuf {
    match std::env::var_os("LODEVAL_GLTF_EXPORTS") {
        Some(d) => {
            std::fs::create_dir_all(&d).unwrap();
            PathBuf::from(d)
        }
        None => tmp.to_path_buf(),
    }
}

/// Two slots are alike: the same image (decoded texels, and the same file bytes where the input's
/// were kept), set, sampler, transform and name.
#[track_caller]
fn assert_slot_eq(what: &str, a: Option<&TextureSlot>, b: Option<&TextureSlot>) {
    match (a, b) {
        (None, None) => {}
        (Some(a), Some(b)) => {
            assert_eq!(a.tex_coord, b.tex_coord, "{what}: texCoord");
            assert_eq!(a.sampler, b.sampler, "{what}: sampler");
            assert_eq!(a.transform, b.transform, "{what}: KHR_texture_transform");
            assert_eq!(a.name, b.name, "{what}: texture name");
            let (ta, tb) = (&a.texture, &b.texture);
            assert_eq!(
                (ta.width(), ta.height(), ta.color_space()),
                (tb.width(), tb.height(), tb.color_space()),
                "{what}: image"
            );
            assert!(ta.rgba() == tb.rgba(), "{what}: texels differ");
            if let Some(e) = ta.encoded() {
                let out = tb
                    .encoded()
                    .unwrap_or_else(|| panic!("{what}: no file bytes"));
                assert!(
                    e.bytes == out.bytes,
                    "{what}: the image file was re-encoded"
                );
                assert_eq!(e.mime, out.mime, "{what}: MIME type");
            }
        }
        (a, b) => panic!(
            "{what}: {} in the input, {} in the output",
            if a.is_some() { "present" } else { "absent" },
            if b.is_some() { "present" } else { "absent" }
        ),
    }
}

/// Every material property of `a` is in `b` (the model aside: glTF has only one).
#[track_caller]
fn assert_material_eq(a: &Material, b: &Material) {
    let n = &a.name;
    assert_eq!(a.name, b.name);
    assert_eq!(a.base_color, b.base_color, "{n}: baseColorFactor");
    assert_eq!(a.base_alpha, b.base_alpha, "{n}: baseColorFactor alpha");
    assert_eq!(a.metallic, b.metallic, "{n}: metallicFactor");
    assert_eq!(a.roughness, b.roughness, "{n}: roughnessFactor");
    assert_eq!(a.normal_scale, b.normal_scale, "{n}: normalTexture.scale");
    assert_eq!(
        a.occlusion_strength, b.occlusion_strength,
        "{n}: occlusion strength"
    );
    assert_eq!(a.emissive, b.emissive, "{n}: emissiveFactor");
    assert_eq!(
        a.emissive_strength, b.emissive_strength,
        "{n}: emissive strength"
    );
    assert_eq!(a.alpha_mode, b.alpha_mode, "{n}: alphaMode");
    if a.alpha_mode == AlphaMode::Mask {
        assert_eq!(a.alpha_cutoff, b.alpha_cutoff, "{n}: alphaCutoff");
    }
    assert_eq!(a.double_sided, b.double_sided, "{n}: doubleSided");
    assert_eq!(a.other_extensions, b.other_extensions, "{n}: extensions");
    assert_eq!(a.extras, b.extras, "{n}: extras");
    for ((slot, x), (_, y)) in a.slots().into_iter().zip(b.slots()) {
        assert_slot_eq(&format!("{n}: {slot}"), x, y);
    }
}

/// Whether a run's warnings say an output lost something of the input.
fn drops_something(stderr: &str) -> bool {
    ["not written", "not kept", "merged", "is written as"]
        .iter()
        .any(|w| stderr.contains(w))
}

/// Simplify `input` into a chain at `out` and check that its LOD 0 has every material of the
/// input; returns the run's stderr (its warnings).
fn round_trip(input: &Path, out: &Path) -> String {
    let r = simplify(input, out, &["--method", "meshopt", "--chain", "0.5", "-q"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let (a, b) = (load(input), load(out));
    assert_eq!(
        a.materials().len(),
        b.materials().len(),
        "{}: materials",
        input.display()
    );
    for (x, y) in a.materials().iter().zip(b.materials()) {
        assert_material_eq(x, y);
    }
    assert_eq!(a.uvs1().is_some(), b.uvs1().is_some(), "TEXCOORD_1");
    assert_eq!(a.colors().is_some(), b.colors().is_some(), "COLOR_0");
    assert_eq!(a.lights(), b.lights(), "KHR_lights_punctual");
    r.stderr
}

#[test]
fn the_shipped_gltf_assets_keep_every_material_slot_through_a_chain() {
    let dir = tempfile::tempdir().unwrap();
    let keep = export_dir(dir.path());
    for (rel, stem) in [
        ("damaged_helmet/DamagedHelmet.gltf", "DamagedHelmet"),
        ("avocado/Avocado.gltf", "Avocado"),
        ("barrel/barrel.glb", "Barrel"),
        ("box_textured/BoxTextured.gltf", "BoxTextured"),
    ] {
        for ext in ["glb", "gltf"] {
            let out = keep.join(format!("{stem}.{ext}"));
            let warnings = round_trip(&model(rel), &out);
            assert!(!drops_something(&warnings), "{rel}: {warnings}");
        }
    }
    // The helmet's node (a rotation) is written back around the chain, by name.
    let doc = gltf::Gltf::open(keep.join("DamagedHelmet.glb")).unwrap();
    let root = doc.scenes().next().unwrap().nodes().next().unwrap();
    assert_eq!(root.name(), Some("node_damagedHelmet_-6514"));
    assert_eq!(root.children().next().unwrap().name(), Some("original"));
}

#[test]
fn spot_with_pbr_mtl_keys_maps_to_the_metallic_roughness_model_and_back() {
    let dir = tempfile::tempdir().unwrap();
    // nvdiffrec's `bsdf pbr` (Ks = occlusion, roughness, metallic) and Blender's Pr/Pm keys.
    let spot = model("spot/spot_mtl.obj");
    let src = load(&spot);
    let m = &src.materials()[0];
    assert_eq!(m.model, Model::MetallicRoughness);
    assert_eq!((m.metallic, m.roughness), (0.0, 0.25));
    let keep = export_dir(dir.path());
    let warnings = round_trip(&spot, &keep.join("Spot.glb"));
    assert!(!drops_something(&warnings), "{warnings}");
    // A Blender-style MTL with every PBR key, read back as glTF PBR.
    let d = dir.path();
    for f in ["spot_mtl.obj", "spot_texture.png"] {
        std::fs::copy(model(&format!("spot/{f}")), d.join(f)).unwrap();
    }
    std::fs::write(
        d.join("spot.mtl"),
        "newmtl initialShadingGroup\nKd 0.9 0.8 0.7\nPr 0.4\nPm 0.6\nKe 0.1 0.2 0.3\n\
         map_Kd spot_texture.png\nmap_Pr spot_texture.png\nmap_Pm spot_texture.png\n\
         map_Ke spot_texture.png\nnorm spot_texture.png\n",
    )
    .unwrap();
    let pbr = load(&d.join("spot_mtl.obj"));
    let m = &pbr.materials()[0];
    assert_eq!(m.model, Model::MetallicRoughness);
    assert_eq!((m.metallic, m.roughness), (0.6, 0.4));
    assert_eq!(m.emissive.to_array(), [0.1, 0.2, 0.3]);
    assert!(m.emissive_texture.is_some() && m.normal_texture.is_some());
    // map_Pr and map_Pm are packed into glTF's layout: G = roughness, B = metalness.
    let mr = &m.metallic_roughness_texture.as_ref().unwrap().texture;
    let base = &m.base_color_texture.as_ref().unwrap().texture;
    assert_eq!(mr.rgba()[1], base.rgba()[0]);
    assert_eq!(mr.rgba()[2], base.rgba()[0]);
    round_trip(&d.join("spot_mtl.obj"), &d.join("pbr.glb"));
    // And back to OBJ: the PBR keys are written, the model survives.
    let r = simplify(
        &d.join("spot_mtl.obj"),
        &d.join("lod.obj"),
        &["--ratio", "0.5"],
    );
    assert_eq!(r.code, 0, "{}", r.stderr);
    let back = load(&d.join("lod.obj"));
    let b = &back.materials()[0];
    assert_eq!(b.model, Model::MetallicRoughness);
    assert_eq!((b.metallic, b.roughness), (0.6, 0.4));
    assert_eq!(
        b.metallic_roughness_texture
            .as_ref()
            .unwrap()
            .texture
            .rgba(),
        mr.rgba()
    );
}

/// BoxTextured with every feature lodeval carries added to its JSON: a second UV set read by the
/// occlusion map, a texture transform, a named sampler, emissive strength, an alpha mask,
/// double-sidedness, extras, a kept extension, one that names a texture, and a spot light.
pub(crate) fn everything_box(dir: &Path) -> PathBuf {
    let src = model("box_textured");
    for f in ["BoxTextured0.bin", "CesiumLogoFlat.png"] {
        std::fs::copy(src.join(f), dir.join(f)).unwrap();
    }
    let mut doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(src.join("BoxTextured.gltf")).unwrap()).unwrap();
    doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_1"] = serde_json::json!(3);
    doc["samplers"][0]["name"] = serde_json::json!("mirror-clamp");
    doc["materials"][0] = serde_json::json!({
        "name": "Everything",
        "pbrMetallicRoughness": {
            "baseColorFactor": [0.9, 0.8, 0.7, 0.6],
            "baseColorTexture": { "index": 0, "extensions": { "KHR_texture_transform": {
                "offset": [0.25, 0.5], "rotation": 0.3, "scale": [2.0, 3.0] } } },
            "metallicFactor": 0.3, "roughnessFactor": 0.7,
            "metallicRoughnessTexture": { "index": 1 }
        },
        "normalTexture": { "index": 1, "scale": 0.5 },
        "occlusionTexture": { "index": 1, "texCoord": 1, "strength": 0.8 },
        "emissiveTexture": { "index": 0 },
        "emissiveFactor": [0.2, 0.4, 0.6],
        "alphaMode": "MASK", "alphaCutoff": 0.3, "doubleSided": true,
        "extras": { "author": "lodeval test" },
        "extensions": {
            "KHR_materials_emissive_strength": { "emissiveStrength": 4.0 },
            "KHR_materials_ior": { "ior": 1.4 },
            "KHR_materials_clearcoat": { "clearcoatFactor": 1.0, "clearcoatTexture": { "index": 0 } }
        }
    });
    doc["textures"] = serde_json::json!([
        { "sampler": 0, "source": 0, "name": "logo" },
        { "source": 0 }
    ]);
    doc["extensionsUsed"] = serde_json::json!([
        "KHR_texture_transform",
        "KHR_materials_emissive_strength",
        "KHR_materials_ior",
        "KHR_materials_clearcoat",
        "KHR_lights_punctual"
    ]);
    doc["extensions"] = serde_json::json!({ "KHR_lights_punctual": { "lights": [
        { "type": "spot", "name": "key", "color": [1.0, 0.9, 0.8], "intensity": 40.0, "range": 9.0,
          "spot": { "innerConeAngle": 0.2, "outerConeAngle": 0.6 } }
    ] } });
    doc["nodes"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({
            "name": "key light", "translation": [0.0, 2.0, 3.0],
            "extensions": { "KHR_lights_punctual": { "light": 0 } }
        }));
    doc["scenes"][0]["nodes"] = serde_json::json!([0, 2]);
    let path = dir.join("everything.gltf");
    std::fs::write(&path, serde_json::to_vec_pretty(&doc).unwrap()).unwrap();
    path
}

#[test]
fn every_carried_feature_survives_and_what_cannot_be_carried_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let input = everything_box(dir.path());
    let m = load(&input);
    let mat = &m.materials()[0];
    // Loaded whole.
    assert_eq!(mat.alpha_mode, AlphaMode::Mask);
    assert!(mat.double_sided && mat.emissive_strength == 4.0 && mat.normal_scale == 0.5);
    let base = mat.base_color_texture.as_ref().unwrap();
    assert_eq!(base.sampler.wrap_s, Wrap::MirroredRepeat);
    assert_eq!(base.sampler.wrap_t, Wrap::ClampToEdge);
    assert_eq!(base.sampler.min, Some(Filter::NearestMipmapLinear));
    assert_eq!(base.transform.unwrap().rotation, 0.3);
    assert_eq!(mat.occlusion_texture.as_ref().unwrap().set(), 1);
    assert!(m.uvs1().is_some());
    assert_eq!(m.lights().len(), 1);
    // The unmodelled extensions, and the alpha mask drawn opaque, are warned about on load.
    let info = lodeval(["info", input.to_str().unwrap()]);
    assert!(
        info.stdout
            .contains("alpha mode Mask is kept for export, but lodeval draws the material opaque"),
        "{}",
        info.stdout
    );
    assert!(
        info.stdout
            .contains("KHR_materials_clearcoat is kept for export but not rendered"),
        "{}",
        info.stdout
    );
    for ext in ["glb", "gltf"] {
        let out = export_dir(dir.path()).join(format!("Everything.{ext}"));
        let r = simplify(
            &input,
            &out,
            &["--method", "meshopt", "--chain", "0.5", "-q"],
        );
        assert_eq!(r.code, 0, "{}", r.stderr);
        // The clearcoat names a texture: not written, and said so; the IOR is written.
        assert!(
            r.stderr
                .contains("KHR_materials_clearcoat is not written (it names textures"),
            "{}",
            r.stderr
        );
        let back = load(&out);
        let b = &back.materials()[0];
        let mut expected = mat.clone();
        expected
            .other_extensions
            .retain(|(name, _)| name != "KHR_materials_clearcoat");
        assert_material_eq(&expected, b);
        assert!(back.uvs1().is_some(), "TEXCOORD_1");
        let (la, lb) = (&m.lights()[0], &back.lights()[0]);
        assert_eq!(
            (la.kind, la.intensity, la.range),
            (lb.kind, lb.intensity, lb.range)
        );
        assert!(
            la.position.distance(lb.position) < 1e-5 && la.direction.distance(lb.direction) < 1e-5
        );
    }
}
