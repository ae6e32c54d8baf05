//! LOD chains for engines: `[export] gltf` in `eval` and `simplify -o CHAIN.glb` write one glTF
//! asset whose finest node links the LODs by `MSFT_lod`, with `MSFT_screencoverage` from the
//! measured distances; read back here with the `gltf` crate and lodeval's own loader.

use std::path::Path;

use crate::common::{lodeval, model};

/// The JSON chunk of a `.glb`, after the `gltf` crate has accepted the whole file (document,
/// buffers and images).
fn glb_json(path: &Path) -> serde_json::Value {
    let bytes = std::fs::read(path).unwrap();
    gltf::import_slice(&bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let glb = gltf::binary::Glb::from_slice(&bytes).unwrap();
    serde_json::from_slice(&glb.json).unwrap()
}

fn coverage(doc: &serde_json::Value) -> Vec<f64> {
    doc["nodes"][0]["extras"]["MSFT_screencoverage"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect()
}

#[test]
fn eval_writes_a_chain_whose_switch_points_are_the_measured_distances() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("e.toml");
    let write = |format: &str, distance: bool| {
        std::fs::write(
            &cfg,
            format!(
                "out = \"out\"\nmetrics = [\"flip\", \"vdp\"]\n[render]\nsize = 64\nrig = \"icosahedron\"\n\
                 [distance]\nenabled = {distance}\nmax_diameter_px = 96\nviews = 1\n[export]\ngltf = \"{format}\"\n\
                 [images]\nheatmaps = \"none\"\ncontact_sheets = false\n[[asset]]\nname = \"spot\"\n\
                 mesh = \"{}\"\ngenerate = {{ method = \"qem\", ratios = [0.5, 0.1] }}\n",
                model("spot/spot_mtl.obj").display()
            ),
        )
        .unwrap();
    };
    write("glb", true);
    let r = lodeval(["eval", cfg.to_str().unwrap(), "-q"]);
    assert!(r.code == 0 || r.code == 1, "{}", r.stderr);
    let glb = dir.path().join("out/export/spot.glb");
    let doc = glb_json(&glb);
    assert_eq!(doc["extensionsUsed"], serde_json::json!(["MSFT_lod"]));
    assert_eq!(doc["scenes"][0]["nodes"], serde_json::json!([0]));
    assert_eq!(
        doc["nodes"][0]["extensions"]["MSFT_lod"]["ids"],
        serde_json::json!([1, 2])
    );
    let names: Vec<&str> = doc["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["spot", "qem-r50", "qem-r10"]);
    // One coverage per level: where each LOD was measured invisible by the VDP, then 0.
    let c = coverage(&doc);
    let table = std::fs::read_to_string(dir.path().join("out/distances.csv")).unwrap();
    let measured = |lod: &str| -> f64 {
        let header: Vec<&str> = table.lines().next().unwrap().split(',').collect();
        let col = header.iter().position(|h| *h == "screen_coverage").unwrap();
        table
            .lines()
            .find(|l| l.contains(&format!(",{lod},")) && l.contains(",vdp_p0.5,"))
            .map(|l| l.split(',').nth(col).unwrap().parse().unwrap())
            .unwrap()
    };
    let (r50, r10) = (measured("qem-r50"), measured("qem-r10"));
    assert_eq!(c, vec![r50, r10.min(r50), 0.0], "{table}");
    assert!(c.windows(2).all(|w| w[1] <= w[0]), "{c:?}");
    // Materials and the texture come along; the coarser meshes are smaller.
    assert!(doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"].is_object());
    assert!(doc["meshes"][1]["primitives"][0]["attributes"]["TEXCOORD_0"].is_number());
    // lodeval reads the file back as the original (a reader without MSFT_lod sees LOD 0).
    let info = lodeval(["info", glb.to_str().unwrap()]);
    assert!(
        info.stdout.contains("triangles            5856"),
        "{}",
        info.stdout
    );
    // .gltf: JSON, a .bin and the image beside it, loadable by the gltf crate.
    write("gltf", true);
    let r = lodeval(["eval", cfg.to_str().unwrap(), "-q"]);
    assert!(r.code == 0 || r.code == 1, "{}", r.stderr);
    let gltf_path = dir.path().join("out/export/spot.gltf");
    gltf::import(&gltf_path).unwrap_or_else(|e| panic!("{e}"));
    assert!(dir.path().join("out/export/spot.bin").exists());
    assert!(
        !dir.path().join("out/export/spot.glb").exists(),
        "the earlier run's .glb is cleared"
    );
    // An export needs measured distances.
    write("glb", false);
    let r = lodeval(["eval", cfg.to_str().unwrap()]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("[export] gltf"), "{}", r.stderr);
}

#[test]
fn simplify_writes_a_measured_chain_as_one_glb() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("chain.glb");
    let r = crate::common::simplify(
        &model("bunny/bunny_odedstein_3k.obj"),
        &out,
        &["--chain", "0.5,0.1"],
    );
    assert_eq!(r.code, 0, "{}", r.stderr);
    let doc = glb_json(&out);
    assert_eq!(
        doc["nodes"][0]["extensions"]["MSFT_lod"]["ids"],
        serde_json::json!([1, 2])
    );
    let c = coverage(&doc);
    assert_eq!(c.len(), 3);
    assert!(
        c[0] > 0.0 && c[0] < 1.0 && c[1] <= c[0] && c[2] == 0.0,
        "{c:?}"
    );
    // No OBJ files: the chain is the one file.
    let files: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(files.len(), 1);
}
