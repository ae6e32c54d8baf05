//! Paths that are not regular files: a FIFO (reading blocks for ever), `/dev/zero` and
//! `/dev/urandom` (reading never ends and memory runs out), directly or through a symlink with an
//! innocent name, as a mesh, a material library, a texture, a glTF buffer or image, an image to
//! diff, or a config. Each must be refused at once, saying that lodeval reads only regular files.
#![cfg(unix)]

use std::os::unix::fs::symlink;
use std::path::{Path, PathBuf};

use super::gltf::square;
use super::{assert_refused, scratch, write};
use crate::common::lodeval_within;

/// A FIFO at `dir/name` (nothing ever writes to it: opening it for reading blocks).
pub(crate) fn fifo(dir: &Path, name: &str) -> PathBuf {
    let p = dir.join(name);
    let ok = std::process::Command::new("mkfifo")
        .arg(&p)
        .status()
        .unwrap()
        .success();
    assert!(ok, "mkfifo {}", p.display());
    p
}

/// A symlink `dir/name` to `target`.
fn link(dir: &Path, name: &str, target: &str) -> PathBuf {
    let p = dir.join(name);
    symlink(target, &p).unwrap();
    p
}

/// `lodeval ARGS` ends within 20 s, refused with `words`.
#[track_caller]
fn refused(args: &[&std::ffi::OsStr], words: &[&str]) {
    let r = lodeval_within(20, args);
    assert_refused(&r, &format!("{args:?}"), words);
}

const NOT_REGULAR: &str = "lodeval reads only regular files";

#[test]
fn a_mesh_that_is_a_device_a_fifo_or_a_folder_is_refused() {
    let tmp = scratch("files-mesh");
    let d = tmp.path();
    // Without an extension the format is unknown, which is refused before anything is read.
    for dev in ["/dev/zero", "/dev/urandom"] {
        refused(&["info".as_ref(), dev.as_ref()], &[dev]);
    }
    let cases = [
        fifo(d, "pipe.obj"),
        link(d, "zero.obj", "/dev/zero"),
        link(d, "random.ply", "/dev/urandom"),
        link(d, "pipe.glb", d.join("pipe.obj").to_str().unwrap()),
    ];
    for p in &cases {
        refused(&["info".as_ref(), p.as_os_str()], &[NOT_REGULAR]);
    }
    std::fs::create_dir(d.join("folder.obj")).unwrap();
    refused(
        &["info".as_ref(), d.join("folder.obj").as_os_str()],
        &["folder.obj", "a directory"],
    );
}

#[test]
fn a_material_library_or_texture_that_is_not_a_file_is_refused() {
    let tmp = scratch("files-assets");
    let d = tmp.path();
    let quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
    // The material library is /dev/zero under an innocent name.
    link(d, "zero.mtl", "/dev/zero");
    let obj = write(
        d,
        "mtl.obj",
        &format!("mtllib zero.mtl\n{quad}usemtl a\nf 1/1 2/2 3/3 4/4\n"),
    );
    refused(
        &["info".as_ref(), obj.as_os_str()],
        &["zero.mtl", NOT_REGULAR],
    );
    // The texture is a FIFO, then /dev/urandom.
    fifo(d, "pipe.png");
    link(d, "random.png", "/dev/urandom");
    for tex in ["pipe.png", "random.png"] {
        write(d, "t.mtl", &format!("newmtl a\nKd 1 1 1\nmap_Kd {tex}\n"));
        let obj = write(
            d,
            "tex.obj",
            &format!("mtllib t.mtl\n{quad}usemtl a\nf 1/1 2/2 3/3 4/4\n"),
        );
        refused(&["info".as_ref(), obj.as_os_str()], &[tex, NOT_REGULAR]);
    }
}

#[test]
fn a_gltf_buffer_or_image_that_is_not_a_file_is_refused() {
    let tmp = scratch("files-gltf");
    let d = tmp.path();
    link(d, "zero.bin", "/dev/zero");
    let buffer = square(d, "buffer", |v| v["buffers"][0]["uri"] = "zero.bin".into());
    refused(
        &["info".as_ref(), buffer.as_os_str()],
        &["buffer 0", "zero.bin", NOT_REGULAR],
    );
    fifo(d, "pipe.png");
    let image = square(d, "image", |v| {
        v["images"] = serde_json::json!([{"uri": "pipe.png"}]);
        v["textures"] = serde_json::json!([{"source": 0}]);
        v["materials"] =
            serde_json::json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
        v["meshes"][0]["primitives"][0]["material"] = 0.into();
    });
    refused(&["info".as_ref(), image.as_os_str()], &[NOT_REGULAR]);
}

#[test]
fn an_image_or_config_that_is_not_a_file_is_refused() {
    let tmp = scratch("files-other");
    let d = tmp.path();
    let pipe = fifo(d, "pipe.png");
    let zero = link(d, "zero.png", "/dev/zero");
    let real = crate::common::root().join("reference/oracles/flip/black_white_16_ref.png");
    for bad in [&pipe, &zero] {
        refused(
            &["diff".as_ref(), real.as_os_str(), bad.as_os_str()],
            &[NOT_REGULAR],
        );
    }
    let config = fifo(d, "pipe.toml");
    refused(&["eval".as_ref(), config.as_os_str()], &[NOT_REGULAR]);
    let config = link(d, "zero.toml", "/dev/zero");
    refused(&["eval".as_ref(), config.as_os_str()], &[NOT_REGULAR]);
}
