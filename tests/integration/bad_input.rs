//! Crafted broken files across the formats. Each must exit 2 with one message on stderr that names
//! the file and says what is wrong, print nothing on stdout, and never panic.

use std::path::{Path, PathBuf};

use crate::common::{lodeval, model};

/// A tetrahedron every case starts from, so each case differs from a valid file in one way.
const TETRA_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";

fn ply_ascii(vertices: &str, faces: &str, nv: usize, nf: usize) -> String {
    format!(
        "ply\nformat ascii 1.0\nelement vertex {nv}\nproperty float x\nproperty float y\nproperty float z\nelement face {nf}\nproperty list uchar int vertex_indices\nend_header\n{vertices}{faces}"
    )
}

fn ply_binary_tetra() -> Vec<u8> {
    let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n".to_vec();
    for p in [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]] {
        for c in p {
            b.extend_from_slice(&c.to_le_bytes());
        }
    }
    for f in [[0i32, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]] {
        b.push(3);
        for i in f {
            b.extend_from_slice(&i.to_le_bytes());
        }
    }
    b
}

/// A one-triangle glTF whose index buffer is `indices`, with its .bin beside it.
fn gltf_triangle(dir: &Path, name: &str, indices: [u16; 3], write_bin: bool) -> PathBuf {
    let mut bin = Vec::new();
    for c in [0f32, 0., 0., 1., 0., 0., 0., 1., 0.] {
        bin.extend_from_slice(&c.to_le_bytes());
    }
    for i in indices {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    bin.extend_from_slice(&[0, 0]);
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
"buffers":[{{"uri":"{name}.bin","byteLength":{len}}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
{{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}]}}"#,
        len = bin.len()
    );
    let path = dir.join(format!("{name}.gltf"));
    std::fs::write(&path, json).unwrap();
    if write_bin {
        std::fs::write(dir.join(format!("{name}.bin")), bin).unwrap();
    }
    path
}

/// Run `info` on `path` and check the failure contract; `expect` are substrings of the message.
#[track_caller]
fn assert_bad(path: &Path, expect: &[&str]) {
    assert_bad_in(path, path, expect);
}

/// As [`assert_bad`], where the file at fault (`culprit`, e.g. an MTL library) is not the one named
/// on the command line.
#[track_caller]
fn assert_bad_in(path: &Path, culprit: &Path, expect: &[&str]) {
    let r = lodeval(["info".as_ref(), path.as_os_str()]);
    let file = culprit.file_name().unwrap().to_string_lossy();
    assert_eq!(
        r.code,
        2,
        "{}: expected exit 2, got {}: {}",
        path.display(),
        r.code,
        r.stderr
    );
    assert!(
        r.stdout.is_empty(),
        "{file}: stdout should be empty: {}",
        r.stdout
    );
    assert!(
        !r.stderr.contains("panicked"),
        "{file}: panicked: {}",
        r.stderr
    );
    assert_eq!(
        r.stderr.trim_end().lines().count(),
        1,
        "{file}: one message: {}",
        r.stderr
    );
    assert!(
        r.stderr.contains(&*file),
        "{file}: message must name the file: {}",
        r.stderr
    );
    for e in expect {
        assert!(
            r.stderr.contains(e),
            "{file}: message lacks '{e}': {}",
            r.stderr
        );
    }
}

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn the_tetrahedron_itself_is_valid() {
    // Guards the cases below: each one breaks this valid file in exactly one way.
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in [
        ("t.obj", TETRA_OBJ.as_bytes().to_vec()),
        ("t.ply", ply_binary_tetra()),
    ] {
        let p = write(dir.path(), name, bytes);
        let r = lodeval(["info".as_ref(), p.as_os_str()]);
        assert_eq!(r.code, 0, "{name}: {}", r.stderr);
        assert!(
            r.stdout.contains("triangles            4"),
            "{name}: {}",
            r.stdout
        );
    }
    let g = gltf_triangle(dir.path(), "ok", [0, 1, 2], true);
    assert_eq!(lodeval(["info".as_ref(), g.as_os_str()]).code, 0);
}

#[test]
fn missing_file_and_unknown_extension() {
    let dir = tempfile::tempdir().unwrap();
    assert_bad(&dir.path().join("nowhere.obj"), &["file not found"]);
    assert_bad(
        &write(dir.path(), "mesh.stl", "solid x"),
        &["unknown mesh file extension '.stl'"],
    );
    std::fs::create_dir(dir.path().join("folder.obj")).unwrap();
    assert_bad(&dir.path().join("folder.obj"), &["directory"]);
}

#[test]
fn obj_syntax_and_range_errors_name_the_line() {
    let d = tempfile::tempdir().unwrap();
    let d = d.path();
    assert_bad(&write(d, "empty.obj", ""), &["no triangles"]);
    assert_bad(
        &write(d, "points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"),
        &["no triangles"],
    );
    assert_bad(
        &write(d, "range.obj", TETRA_OBJ.replace("f 2 3 4", "f 2 3 9")),
        &["line 7", "vertex 9", "only 4 vertices"],
    );
    assert_bad(
        &write(d, "zero.obj", TETRA_OBJ.replace("f 1 3 2", "f 0 3 2")),
        &["line 5", "start at 1"],
    );
    assert_bad(
        &write(d, "nan.obj", TETRA_OBJ.replace("v 1 0 0", "v 1 nan 0")),
        &["line 2", "non-finite"],
    );
    assert_bad(
        &write(d, "inf.obj", TETRA_OBJ.replace("v 0 0 1", "v 0 0 inf")),
        &["line 4", "non-finite"],
    );
    assert_bad(
        &write(d, "garbled.obj", TETRA_OBJ.replace("v 0 1 0", "v 0 one 0")),
        &["line 3", "'one'"],
    );
    assert_bad(
        &write(d, "short.obj", TETRA_OBJ.replace("v 0 1 0", "v 0 1")),
        &["line 3", "needs 3"],
    );
    assert_bad(
        &write(d, "twocorner.obj", TETRA_OBJ.replace("f 1 2 4", "f 1 2")),
        &["line 6", "at least 3"],
    );
    assert_bad(
        &write(d, "badtoken.obj", TETRA_OBJ.replace("f 1 2 4", "f 1 2 x/y")),
        &["line 6", "x/y"],
    );
    assert_bad(
        &write(
            d,
            "uvrange.obj",
            "vt 0 0\n".to_string() + &TETRA_OBJ.replace("f 1 3 2", "f 1/1 3/2 2/1"),
        ),
        &["line 6", "texture coordinate 2"],
    );
    let mut binary = b"v 0 0 0\n".to_vec();
    binary.extend_from_slice(&[0xff, 0xfe, 0x00, 0x12, 0x80]);
    assert_bad(&write(d, "binary.obj", binary), &["line 2", "not text"]);
}

#[test]
fn obj_missing_or_broken_assets() {
    let d = tempfile::tempdir().unwrap();
    let d = d.path();
    let with_mtl = format!("mtllib m.mtl\nusemtl a\n{TETRA_OBJ}");
    assert_bad(
        &write(d, "nomtl.obj", &with_mtl),
        &["line 1", "material library 'm.mtl' not found"],
    );
    write(
        d,
        "m.mtl",
        "newmtl a\nKd 1 1 1\nmap_Kd missing_texture.png\n",
    );
    assert_bad(
        &write(d, "notex.obj", &with_mtl),
        &["material 'a'", "missing_texture.png"],
    );
    // With the documented escape hatch the same file loads and warns.
    let p = d.join("notex.obj");
    let r = lodeval([
        "info".as_ref(),
        p.as_os_str(),
        "--missing-assets".as_ref(),
        "warn".as_ref(),
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(
        r.stdout.contains("warning:") && r.stdout.contains("missing_texture.png"),
        "{}",
        r.stdout
    );
    // Regression (found by fuzz::mtl_never_panics): a colour with two numbers made tobj panic.
    write(d, "m.mtl", "newmtl a\nKd 0.5 0.5\n");
    assert_bad_in(
        &write(d, "shortkd.obj", &with_mtl),
        &d.join("m.mtl"),
        &["line 2", "needs 3", ".mtl file"],
    );
    // A texture that exists but is not an image.
    write(d, "m.mtl", "newmtl a\nmap_Kd garbage.png\n");
    write(d, "garbage.png", b"\x89PNG\r\n\x1a\nthis is not a png");
    assert_bad(
        &write(d, "badtex.obj", &with_mtl),
        &["garbage.png", "cannot be decoded"],
    );
    // A zero-size image: a PNG header claiming 0 x 0 pixels.
    let mut zero = b"\x89PNG\r\n\x1a\n\x00\x00\x00\x0dIHDR".to_vec();
    zero.extend_from_slice(&[0, 0, 0, 0, 0, 0, 0, 0, 8, 6, 0, 0, 0, 0, 0, 0, 0]);
    write(d, "zero.png", zero);
    write(d, "m.mtl", "newmtl a\nmap_Kd zero.png\n");
    assert_bad(&write(d, "zerotex.obj", &with_mtl), &["zero.png"]);
}

#[test]
fn ply_errors_name_the_element() {
    let d = tempfile::tempdir().unwrap();
    let d = d.path();
    let verts = "0 0 0\n1 0 0\n0 1 0\n";
    assert_bad(
        &write(d, "range.ply", ply_ascii(verts, "3 0 1 7\n", 3, 1)),
        &["face 0", "index 7"],
    );
    // ASCII "nan" is already refused by the PLY parser (with the line); binary NaN reaches the
    // validator, which names the vertex.
    assert_bad(
        &write(
            d,
            "nan.ply",
            ply_ascii("0 0 0\n1 nan 0\n0 1 0\n", "3 0 1 2\n", 3, 1),
        ),
        &["line 11", "1 nan 0"],
    );
    let mut bin = ply_binary_tetra();
    let x_of_vertex_2 = bin.len() - 4 * 13 - 4 * 12 + 2 * 12;
    bin[x_of_vertex_2..x_of_vertex_2 + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    assert_bad(&write(d, "nanbin.ply", &bin), &["vertex 2", "NaN"]);
    assert_bad(
        &write(
            d,
            "header.ply",
            "ply\nformat ascii 1.0\nelement vertex three\nend_header\n",
        ),
        &["not a valid PLY"],
    );
    assert_bad(
        &write(d, "notply.ply", "hello world\n"),
        &["not a valid PLY"],
    );
    assert_bad(
        &write(d, "nofaces.ply", ply_ascii(verts, "", 3, 0)),
        &["no triangles"],
    );
    assert_bad(
        &write(d, "fewer.ply", ply_ascii(verts, "3 0 1 2\n", 3, 2)),
        &["not a valid PLY"],
    );
    let bin = ply_binary_tetra();
    assert_bad(
        &write(d, "truncated.ply", &bin[..bin.len() - 7]),
        &["not a valid PLY"],
    );
    assert_bad(
        &write(
            d,
            "novertex.ply",
            "ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n",
        ),
        &["no 'vertex' element"],
    );
}

#[test]
fn off_errors_name_the_line() {
    let d = tempfile::tempdir().unwrap();
    let d = d.path();
    let ok = "OFF\r\n4 4 6\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n0 0 1\r\n3 0 2 1\r\n3 0 1 3\r\n3 1 2 3\r\n3 0 3 2\r\n";
    assert_eq!(
        lodeval(["info".as_ref(), write(d, "ok.off", ok).as_os_str()]).code,
        0,
        "CRLF is accepted"
    );
    assert_bad(
        &write(d, "truncated.off", &ok[..ok.len() - 20]),
        &["ends before face 2 of 4", "truncated"],
    );
    assert_bad(
        &write(d, "keyword.off", ok.replace("OFF", "PLY")),
        &["line 1", "'OFF' keyword"],
    );
    assert_bad(
        &write(d, "range.off", ok.replace("3 1 2 3", "3 1 2 4")),
        &["line 9", "index 4"],
    );
    assert_bad(
        &write(d, "nan.off", ok.replace("0 1 0", "0 NaN 0")),
        &["line 5", "non-finite"],
    );
}

#[test]
fn gltf_errors_name_the_problem() {
    let d = tempfile::tempdir().unwrap();
    let d = d.path();
    assert_bad(
        &write(d, "json.gltf", "{\"asset\": "),
        &["not a valid glTF"],
    );
    assert_bad(
        &gltf_triangle(d, "nobin", [0, 1, 2], false),
        &["buffer 0", "nobin.bin", "missing"],
    );
    assert_bad(
        &gltf_triangle(d, "range", [0, 1, 5], true),
        &["mesh 0", "index 5"],
    );
    // Regression (found by fuzz::glb_never_panics): a primitive naming an accessor that does not
    // exist made the gltf crate's validator index out of bounds and panic.
    let no_accessors = r#"{"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"accessors":[]}"#;
    assert_bad(
        &write(d, "noaccessor.gltf", no_accessors),
        &["mesh 0 primitive 0", "accessor 0"],
    );
    // Regression (found by fuzz::glb_never_panics): float indices hit `unreachable!` in the gltf
    // crate's index reader.
    let float_indices =
        std::fs::read_to_string(gltf_triangle(d, "floatidx", [0, 1, 2], true)).unwrap();
    let float_indices = float_indices.replace(r#""componentType":5123"#, r#""componentType":5126"#);
    assert_bad(
        &write(d, "floatidx.gltf", float_indices),
        &["indices accessor 1", "F32"],
    );
    let glb = std::fs::read(model("barrel/barrel.glb")).unwrap();
    assert_bad(&write(d, "cut.glb", &glb[..glb.len() / 2]), &["cut.glb"]);
    assert_bad(
        &write(d, "junk.glb", b"glTF\x02\x00\x00\x00junkjunkjunk"),
        &["not a valid glTF"],
    );
}
