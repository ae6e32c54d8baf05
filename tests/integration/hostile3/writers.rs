//! Writers that never asked: glTF export named its images `STEM-NAME.png` and replaced an input
//! texture of that name; `diff --map` and `--csv` replaced the image they compared; a failed
//! glTF write left orphan images behind; `--method williams -o X.glb` wrote OBJ text into a
//! file named `.glb`.

use super::{assert_refused, run, s, scratch, spot_copy};
use crate::common::{files, model};

/// BoxTextured in `dir` with its texture file renamed `name` (the image keeps the name
/// `CesiumLogoFlat`).
fn box_with_texture(dir: &std::path::Path, name: &str) -> std::path::PathBuf {
    let src = model("box_textured");
    let mut doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(src.join("BoxTextured.gltf")).unwrap()).unwrap();
    doc["images"][0] = serde_json::json!({ "uri": name, "name": "CesiumLogoFlat" });
    std::fs::copy(src.join("CesiumLogoFlat.png"), dir.join(name)).unwrap();
    std::fs::copy(src.join("BoxTextured0.bin"), dir.join("BoxTextured0.bin")).unwrap();
    let p = dir.join("box.gltf");
    std::fs::write(&p, serde_json::to_vec(&doc).unwrap()).unwrap();
    p
}

#[test]
fn gltf_export_never_replaces_an_input_texture_and_leaves_no_orphans() {
    let tmp = scratch("r3-writers-gltf");
    let d = tmp.path();
    let input = box_with_texture(d, "chain-CesiumLogoFlat.png");
    let before = files(d);
    let r = run(&[
        "simplify",
        s(&input),
        "-o",
        s(&d.join("chain.gltf")),
        "--chain",
        "0.5",
    ]);
    assert_refused(
        &r,
        "image over input texture",
        &["chain-CesiumLogoFlat.png", "is an input"],
    );
    assert_eq!(files(d), before, "an input changed");
    // A document that cannot be written (its name is a folder): no image, no buffer is left.
    let out = tempfile::tempdir().unwrap();
    std::fs::create_dir(out.path().join("lod.gltf")).unwrap();
    let r = run(&[
        "simplify",
        s(&input),
        "-o",
        s(&out.path().join("lod.gltf")),
        "--chain",
        "0.5",
    ]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    let left: Vec<_> = std::fs::read_dir(out.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(left, vec!["lod.gltf".to_string()], "orphans: {left:?}");
}

#[test]
fn diff_never_writes_over_the_images_it_compares() {
    let tmp = scratch("r3-writers-diff");
    let d = tmp.path();
    let o = |f: &str| crate::common::root().join("reference/oracles/flip").join(f);
    std::fs::copy(o("lines_70_ref.png"), d.join("ref.png")).unwrap();
    std::fs::copy(o("lines_70_test.png"), d.join("t1.png")).unwrap();
    let before = files(d);
    let (r_, t_) = (d.join("ref.png"), d.join("t1.png"));
    for args in [
        vec!["diff", s(&r_), s(&t_), "--map", s(&r_)],
        vec!["diff", s(&r_), s(&t_), "--csv", s(&t_)],
        vec![
            "diff",
            s(&r_),
            s(&t_),
            "--metric",
            "all",
            "--map",
            s(&d.join("x/../t1.png")),
        ],
    ] {
        let r = run(&args);
        assert_refused(&r, &args.join(" "), &["is an input of this run"]);
    }
    assert_eq!(files(d), before);
}

#[test]
fn williams_writes_a_real_glb() {
    let tmp = scratch("r3-writers-williams");
    let d = tmp.path();
    let spot = spot_copy(d);
    let out = d.join("w.glb");
    let r = run(&[
        "simplify",
        s(&spot),
        "-o",
        s(&out),
        "--method",
        "williams",
        "--budget",
        "2000",
        "--size",
        "32",
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let bytes = std::fs::read(&out).unwrap();
    assert_eq!(&bytes[..4], b"glTF", "not a GLB");
    let (doc, _, _) = gltf::import(&out).unwrap();
    let tris: usize = doc
        .meshes()
        .flat_map(|m| m.primitives())
        .filter_map(|p| p.indices().map(|a| a.count() / 3))
        .sum();
    assert!(tris > 0 && tris <= 2000, "{tris} triangles");
}
