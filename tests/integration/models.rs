//! `lodeval info` on real models: every model in the shared collection must give the counts
//! MANIFEST.md states (vertex records V and triangles F, checked there with trimesh and raw record
//! counts). Skipped only when `../shared` is absent.

use crate::common::{lodeval, model, shared_models};

/// (path under shared/models, V = vertex records, file faces, triangles). From MANIFEST.md; where
/// the manifest gives polygons (Suzanne: 468 quads + 32 triangles) the triangle count is theirs too.
const MANIFEST: &[(&str, usize, usize, usize)] = &[
    ("textured/spot/spot_triangulated.obj", 2930, 5856, 5856),
    ("textured/spot/spot_mtl.obj", 2930, 5856, 5856),
    ("textured/spot/spot_QEM.obj", 1000, 1996, 1996),
    ("textured/bob/bob_tri.obj", 5344, 10688, 10688),
    ("textured/blub/blub_triangulated.obj", 7106, 14208, 14208),
    ("textured/blub/blub_QEM.obj", 2202, 4396, 4396),
    ("textured/spider/spider.obj", 762, 1368, 1368),
    ("gltf/DamagedHelmet/DamagedHelmet.gltf", 14556, 15452, 15452),
    ("gltf/Avocado/Avocado.gltf", 406, 682, 682),
    ("gltf/Barrel/barrel.glb", 856, 1148, 1148),
    ("gltf/BoxTextured/BoxTextured.gltf", 24, 12, 12),
    (
        "pbr/MetalRoughSpheresNoTextures/glTF/MetalRoughSpheresNoTextures.gltf",
        528291,
        1040409,
        1040409,
    ),
    ("pbr/Suzanne/glTF/Suzanne.gltf", 11808, 3936, 3936),
    ("scans/bunny/stanford-bunny.obj", 35947, 69451, 69451),
    ("scans/bunny/bunny_odedstein_3k.obj", 3301, 6598, 6598),
    (
        "scans/armadillo/armadillo_odedstein_15k.obj",
        14587,
        29170,
        29170,
    ),
    (
        "scans/armadillo/armadillo_cgal_26k.off",
        26002,
        52000,
        52000,
    ),
    ("scans/dragon/dragon_vrip_res2.ply", 100250, 202520, 202520),
    ("scans/dragon/dragon_vrip_res3.ply", 22998, 47794, 47794),
    ("scans/dragon/dragon_vrip_res4.ply", 5205, 11102, 11102),
    (
        "scans/happy_buddha/happy_buddha_13k.off",
        13295,
        26999,
        26999,
    ),
    ("scans/nefertiti/nefertiti.obj", 49971, 99938, 99938),
    ("scans/horse/horse.ply", 48485, 96966, 96966),
    // Stored as one tristrips element; the manifest says "about 268686" because trimesh cannot
    // read it. Strip triangles with a repeated index are stitching and are not counted.
    ("scans/igea/igea.ply", 134345, 268686, 268686),
    ("classic/fandisk/fandisk.obj", 6475, 12946, 12946),
    ("classic/suzanne/suzanne.obj", 507, 500, 968),
    ("classic/teapot/teapot.obj", 3644, 6320, 6320),
    ("classic/cow/cow.obj", 2903, 5804, 5804),
];

fn info_json(path: &std::path::Path) -> serde_json::Value {
    let r = lodeval(["info", "--json", path.to_str().unwrap()]);
    assert_eq!(r.code, 0, "{}: {}", path.display(), r.stderr);
    serde_json::from_str(&r.stdout).unwrap()
}

#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs the developers' model collection (../shared/models), not in a user's clone"
)]
fn every_shared_model_matches_the_manifest() {
    let root = shared_models().expect("../shared/models was there when the tests were built");
    // Every mesh file in the collection is listed above, so a new model cannot go unchecked.
    let mut on_disk = Vec::new();
    let mut stack = vec![root.clone()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap().map(Result::unwrap) {
            let p = e.path();
            let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
            if p.is_dir() {
                stack.push(p);
            } else if ["obj", "ply", "off", "gltf", "glb"].contains(&ext) {
                on_disk.push(
                    p.strip_prefix(&root)
                        .unwrap()
                        .to_string_lossy()
                        .into_owned(),
                );
            }
        }
    }
    on_disk.sort();
    let mut listed: Vec<String> = MANIFEST.iter().map(|m| m.0.to_string()).collect();
    listed.sort();
    assert_eq!(
        on_disk, listed,
        "mesh files on disk vs. the table in this test"
    );

    for &(rel, v, f, tris) in MANIFEST {
        let j = info_json(&root.join(rel));
        assert_eq!(j["file_vertices"], v, "{rel}: vertex records");
        assert_eq!(j["file_faces"], f, "{rel}: face records");
        assert_eq!(j["triangles"], tris, "{rel}: triangles");
        assert!(j["welded_vertices"].as_u64().unwrap() <= v as u64, "{rel}");
    }
}

#[test]
#[cfg_attr(
    not(shared_models),
    ignore = "needs the developers' model collection (../shared/models), not in a user's clone"
)]
fn textured_models_bind_their_textures() {
    let root = shared_models().expect("../shared/models was there when the tests were built");
    // Bob's mtllib line is the last line of the file; the material must still be bound.
    let bob = info_json(&root.join("textured/bob/bob_tri.obj"));
    assert_eq!(bob["materials"][0]["textures"][0]["width"], 2048);
    assert_eq!(bob["materials"][0]["triangles"], 10688);
    // The spider's map_Kd paths are Windows style (.\SpiderTex.jpg).
    let spider = info_json(&root.join("textured/spider/spider.obj"));
    let textured = spider["materials"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| !m["textures"].as_array().unwrap().is_empty())
        .count();
    assert_eq!(textured, 5);
    // DamagedHelmet: every slot decoded (base colour, metallic–roughness, normal, occlusion,
    // emissive).
    let helmet = info_json(&root.join("gltf/DamagedHelmet/DamagedHelmet.gltf"));
    assert_eq!(
        helmet["materials"][0]["textures"].as_array().unwrap().len(),
        5
    );
}

#[test]
fn shipped_models_load_with_their_licences_listed() {
    let licences = std::fs::read_to_string(model("LICENSES.md")).unwrap();
    for rel in [
        "bunny/stanford-bunny.obj",
        "spot/spot_mtl.obj",
        "barrel/barrel.glb",
        "dragon/dragon_vrip_res4.ply",
    ] {
        assert!(licences.contains(rel), "{rel} is missing from LICENSES.md");
        info_json(&model(rel));
    }
}
