//! Round two's leftovers: PLY `format … 2.0` and glTF `asset.version` 3.0 were accepted, a
//! material's missing `TEXCOORD_n` set was accepted, a GLB whose header length is too small was
//! accepted, NaN pixels in an EXR were scored by `diff`, `bench raster --rings 0` was accepted.

use super::{assert_refused, run, s, scratch, write};
use crate::common::model;

#[test]
fn future_format_versions_are_refused() {
    let tmp = scratch("r3-leftovers-versions");
    let d = tmp.path();
    let ply = write(
        d,
        "v2.ply",
        "ply\nformat ascii 2.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
         0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
    );
    assert_refused(
        &run(&["info", s(&ply)]),
        "PLY 2.0",
        &["v2.ply", "2.0", "1.0"],
    );
    let src = model("box_textured");
    for f in ["CesiumLogoFlat.png", "BoxTextured0.bin"] {
        std::fs::copy(src.join(f), d.join(f)).unwrap();
    }
    let mut doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(src.join("BoxTextured.gltf")).unwrap()).unwrap();
    doc["asset"]["version"] = "3.0".into();
    let v3 = d.join("v3.gltf");
    std::fs::write(&v3, serde_json::to_vec(&doc).unwrap()).unwrap();
    assert_refused(
        &run(&["info", s(&v3)]),
        "glTF 3.0",
        &["v3.gltf", "asset.version", "3.0"],
    );
    // A base colour texture reading TEXCOORD_1, which the primitive does not have.
    doc["asset"]["version"] = "2.0".into();
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["texCoord"] = 1.into();
    let tc = d.join("tc1.gltf");
    std::fs::write(&tc, serde_json::to_vec(&doc).unwrap()).unwrap();
    assert_refused(
        &run(&["info", s(&tc)]),
        "missing TEXCOORD_1",
        &["tc1.gltf", "TEXCOORD_1"],
    );
}

#[test]
fn a_glb_header_shorter_than_its_chunks_is_refused() {
    let tmp = scratch("r3-leftovers-glb");
    let d = tmp.path();
    let out = d.join("box.glb");
    let r = run(&[
        "simplify",
        s(&model("box_textured/BoxTextured.gltf")),
        "-o",
        s(&out),
        "--ratio",
        "1",
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let mut bytes = std::fs::read(&out).unwrap();
    let short = (bytes.len() as u32 - 16).to_le_bytes();
    bytes[8..12].copy_from_slice(&short);
    let bad = d.join("short.glb");
    std::fs::write(&bad, &bytes).unwrap();
    assert_refused(
        &run(&["info", s(&bad)]),
        "short GLB length",
        &["short.glb", "length"],
    );
}

#[test]
fn nan_pixels_in_an_exr_are_refused_by_every_metric() {
    let tmp = scratch("r3-leftovers-exr");
    let d = tmp.path();
    let good =
        image::Rgba32FImage::from_fn(16, 16, |x, _| image::Rgba([x as f32 / 16.0, 0.5, 0.5, 1.0]));
    let mut bad = good.clone();
    bad.put_pixel(3, 4, image::Rgba([f32::NAN, 0.5, 0.5, 1.0]));
    let (g, b) = (d.join("good.exr"), d.join("bad.exr"));
    image::DynamicImage::ImageRgba32F(good).save(&g).unwrap();
    image::DynamicImage::ImageRgba32F(bad).save(&b).unwrap();
    for metric in ["flip", "ssim", "psnr", "mse", "vdp"] {
        let r = run(&["diff", s(&g), s(&b), "--metric", metric]);
        assert_refused(&r, metric, &["bad.exr", "pixel (3, 4)", "NaN"]);
    }
}

#[test]
fn bench_raster_needs_rings() {
    let r = run(&["bench", "raster", "--rings", "0"]);
    assert_refused(&r, "--rings 0", &["--rings", "0"]);
}
