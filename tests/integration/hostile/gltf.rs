//! glTF documents whose structure the `gltf` crate accepts but that cannot be read through: a
//! node hierarchy with a cycle (the scene walk looped forever while memory grew, in `info` and in
//! `eval`), a node with two parents, a scene listing a child as a root, and accessors or buffer
//! views that reach past their view or buffer (reported as "has no POSITION attribute" or "the
//! parser gave up"). Each must be refused quickly, naming the node, accessor or view at fault.

use std::path::{Path, PathBuf};

use serde_json::{Value, json};

use super::{assert_refused, scratch, write};
use crate::common::lodeval_within;

/// The square's buffer: four positions (f32 × 3) then six u16 indices.
pub fn square_bin() -> Vec<u8> {
    let mut bin = Vec::new();
    for c in [0f32, 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.] {
        bin.extend_from_slice(&c.to_le_bytes());
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    bin
}

/// A two-triangle square as glTF JSON whose buffer is at `uri`. Node 0 holds the mesh; nodes 1
/// and 2 are its children (node 1 moved), so edits can make cycles.
pub fn square_document(uri: &str) -> Value {
    json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "children": [1, 2]}, {"translation": [1, 0, 0]}, {"children": []}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"uri": uri, "byteLength": square_bin().len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 12}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}
        ]
    })
}

/// The square with its `.bin` beside it, edited by `edit` first.
pub fn square(dir: &Path, name: &str, edit: impl FnOnce(&mut Value)) -> PathBuf {
    let mut doc = square_document(&format!("{name}.bin"));
    edit(&mut doc);
    std::fs::write(dir.join(format!("{name}.bin")), square_bin()).unwrap();
    let path = dir.join(format!("{name}.gltf"));
    std::fs::write(&path, serde_json::to_string_pretty(&doc).unwrap()).unwrap();
    path
}

/// `info` on `path` ends within 20 s, refused with every one of `words`.
#[track_caller]
fn refused_by_info(path: &Path, words: &[&str]) {
    let r = lodeval_within(20, ["info".as_ref(), path.as_os_str()]);
    let name = path.file_name().unwrap().to_string_lossy();
    assert_refused(&r, &name, words);
    assert!(
        r.stderr.contains(&*name),
        "the file is not named: {}",
        r.stderr
    );
    assert_eq!(r.stderr.trim_end().lines().count(), 1, "{}", r.stderr);
}

#[test]
fn the_square_itself_loads() {
    let tmp = scratch("gltf-ok");
    let p = square(tmp.path(), "ok", |_| {});
    let r = lodeval_within(20, ["info".as_ref(), p.as_os_str()]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(r.stdout.contains("triangles"), "{}", r.stdout);
}

#[test]
fn a_node_hierarchy_with_a_cycle_is_refused() {
    let tmp = scratch("gltf-cycle");
    let d = tmp.path();
    // Node 1 lists node 0 as its child: 0 → 1 → 0.
    let two = square(d, "two", |v| v["nodes"][1]["children"] = json!([0]));
    refused_by_info(&two, &["node", "cycle"]);
    // Without a scene root, the same loop 0 → 1 → 0 with one parent each.
    let loop2 = square(d, "loop", |v| {
        v["nodes"][1]["children"] = json!([0]);
        v["scenes"] = json!([]);
        v.as_object_mut().unwrap().remove("scene");
    });
    refused_by_info(&loop2, &["node", "cycle"]);
    // A node that is its own child.
    let own = square(d, "own", |v| v["nodes"][2]["children"] = json!([2]));
    refused_by_info(&own, &["node 2", "its own child"]);
    // A longer loop 1 → 2 → 1 hanging below the scene root's subtree.
    let long = square(d, "long", |v| {
        v["nodes"][0]["children"] = json!([]);
        v["nodes"][1]["children"] = json!([2]);
        v["nodes"][2]["children"] = json!([1]);
    });
    refused_by_info(&long, &["cycle"]);
    // The same cycle in a LOD stops `eval` before it writes anything.
    let ok = square(d, "ok", |_| {});
    let config = write(
        d,
        "cycle.toml",
        &format!(
            "out = \"out\"\n[[asset]]\nname = \"loop\"\nmesh = \"{}\"\nlods = [{{ mesh = \"{}\" }}]\n",
            ok.display(),
            long.display()
        ),
    );
    let r = lodeval_within(60, ["eval".as_ref(), config.as_os_str()]);
    assert_refused(&r, "eval of a cyclic glTF", &["long.gltf", "cycle"]);
    assert!(!d.join("out/metrics.csv").exists());
}

#[test]
fn a_node_with_two_parents_or_a_child_as_scene_root_is_refused() {
    let tmp = scratch("gltf-parents");
    let d = tmp.path();
    let twice = square(d, "twice", |v| v["nodes"][1]["children"] = json!([2]));
    refused_by_info(&twice, &["node 2", "node 0", "node 1", "one parent"]);
    let root = square(d, "root", |v| v["scenes"][0]["nodes"] = json!([0, 1]));
    refused_by_info(&root, &["scene 0", "node 1", "child of node 0"]);
    let range = square(d, "range", |v| v["nodes"][0]["children"] = json!([1, 7]));
    refused_by_info(&range, &["node 0", "child node 7", "3 nodes"]);
}

#[test]
fn accessors_and_views_past_their_ends_are_named() {
    let tmp = scratch("gltf-bounds");
    let d = tmp.path();
    // Five positions in a view that holds four.
    let count = square(d, "count", |v| v["accessors"][0]["count"] = json!(5));
    refused_by_info(&count, &["accessor 0", "buffer view 0", "48 bytes"]);
    // An offset that pushes the indices past the view's end.
    let offset = square(d, "offset", |v| v["accessors"][1]["byteOffset"] = json!(2));
    refused_by_info(&offset, &["accessor 1", "buffer view 1"]);
    // A count so large that count × stride overflows 64 bits.
    let huge = square(d, "huge", |v| {
        v["accessors"][0]["count"] = json!(u64::MAX / 4)
    });
    refused_by_info(&huge, &["accessor 0"]);
    // A stride shorter than one element (the `gltf` crate asserted on the short slices).
    let stride = square(d, "stride", |v| {
        v["bufferViews"][0]["byteStride"] = json!(4)
    });
    refused_by_info(&stride, &["buffer view 0", "byteStride 4", "accessor 0"]);
    // A view that reaches past the buffer.
    let view = square(d, "view", |v| {
        v["bufferViews"][1]["byteLength"] = json!(4000)
    });
    refused_by_info(&view, &["buffer view 1", "past the end of buffer 0"]);
    // A view of a buffer that does not exist.
    let buffer = square(d, "buffer", |v| v["bufferViews"][1]["buffer"] = json!(3));
    refused_by_info(&buffer, &["buffer view 1", "buffer 3"]);
    // A buffer that claims more bytes than its file has.
    let short = square(d, "short", |v| v["buffers"][0]["byteLength"] = json!(4000));
    refused_by_info(&short, &["short"]);
}
