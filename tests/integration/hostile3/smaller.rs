//! Smaller losses: the OBJ writer merged materials whose names collide after sanitising (half a
//! LOD wrongly textured); a morph target's base was shown without a word; `remesh` returned fewer
//! vertices than asked at small map sizes without saying so; messages were malformed (a newline
//! from a bless filter split the one error line; a limit printed as a meaningless 0.000000).

use super::{assert_refused, run, s, scratch, spot_copy};
use crate::common::model;

/// BoxTextured drawn twice, by two materials whose names collide in an MTL (`a b` and `a_b`),
/// one red and one green.
fn colliding_box(dir: &std::path::Path) -> std::path::PathBuf {
    let src = model("box_textured");
    for f in ["CesiumLogoFlat.png", "BoxTextured0.bin"] {
        std::fs::copy(src.join(f), dir.join(f)).unwrap();
    }
    let mut doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(src.join("BoxTextured.gltf")).unwrap()).unwrap();
    let prim = doc["meshes"][0]["primitives"][0].clone();
    let mut second = prim.clone();
    second["material"] = 1.into();
    doc["meshes"][0]["primitives"] = serde_json::json!([prim, second]);
    let red = serde_json::json!({ "name": "a b", "pbrMetallicRoughness": { "baseColorFactor": [1, 0, 0, 1] } });
    let green = serde_json::json!({ "name": "a_b", "pbrMetallicRoughness": { "baseColorFactor": [0, 1, 0, 1] } });
    doc["materials"] = serde_json::json!([red, green]);
    let p = dir.join("two.gltf");
    std::fs::write(&p, serde_json::to_vec(&doc).unwrap()).unwrap();
    p
}

#[test]
fn colliding_material_names_stay_two_materials_in_obj() {
    let tmp = scratch("r3-smaller-names");
    let d = tmp.path();
    let input = colliding_box(d);
    let out = d.join("lod.obj");
    let r = run(&["simplify", s(&input), "-o", s(&out), "--ratio", "1"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let mtl = std::fs::read_to_string(d.join("lod.mtl")).unwrap();
    assert_eq!(mtl.matches("newmtl ").count(), 2, "{mtl}");
    let info = run(&["info", s(&out), "--json"]);
    assert_eq!(info.code, 0, "{}", info.stderr);
    let v: serde_json::Value = serde_json::from_str(&info.stdout).unwrap();
    let m = v["materials"].as_array().unwrap();
    assert_eq!(m.len(), 2, "{v}");
    assert_ne!(
        m[0]["base_color"], m[1]["base_color"],
        "the two colours merged: {v}"
    );
    assert_ne!(m[0]["name"], m[1]["name"]);
}

#[test]
fn morph_targets_and_short_remeshes_are_said() {
    let tmp = scratch("r3-smaller-morph");
    let d = tmp.path();
    let src = model("box_textured");
    for f in ["CesiumLogoFlat.png", "BoxTextured0.bin"] {
        std::fs::copy(src.join(f), d.join(f)).unwrap();
    }
    let mut doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(src.join("BoxTextured.gltf")).unwrap()).unwrap();
    // One morph target that moves the positions by the normals (reusing the NORMAL accessor).
    let normals = doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"].clone();
    doc["meshes"][0]["primitives"][0]["targets"] = serde_json::json!([{ "POSITION": normals }]);
    doc["meshes"][0]["weights"] = serde_json::json!([1.0]);
    let p = d.join("morph.gltf");
    std::fs::write(&p, serde_json::to_vec(&doc).unwrap()).unwrap();
    let r = run(&["info", s(&p)]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let said = format!("{}{}", r.stdout, r.stderr);
    assert!(said.contains("morph targets are not applied"), "{said}");
    // A remesh short of its vertex count at a small map size.
    let spot = spot_copy(d);
    let r = run(&[
        "remesh",
        s(&spot),
        "-o",
        s(&d.join("r.obj")),
        "--vertices",
        "1700",
        "--map-size",
        "64",
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(
        r.stderr.contains("short of the 1700 asked for"),
        "{}",
        r.stderr
    );
}

#[test]
fn messages_stay_one_line_and_show_limits_as_numbers() {
    let tmp = scratch("r3-smaller-messages");
    let d = tmp.path();
    let spot = spot_copy(d);
    let cfg = super::config(d, "c.toml", &spot, "out", "");
    let r = run(&["golden", s(&cfg), "--bless", "m\nsecond line"]);
    assert_refused(&r, "bless filter with a newline", &["--bless"]);
    assert_eq!(r.stderr.trim_end().lines().count(), 1, "{}", r.stderr);
    let o = |f: &str| crate::common::root().join("reference/oracles/flip").join(f);
    let r = run(&[
        "diff",
        s(&o("lines_70_ref.png")),
        s(&o("lines_70_test.png")),
        "--fail",
        "1e-320",
    ]);
    assert_eq!(r.code, 1, "{}", r.stderr);
    assert!(
        r.stderr.contains("limit 1e-320") && !r.stderr.contains("0.000000 "),
        "{}",
        r.stderr
    );
}
