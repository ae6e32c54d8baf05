//! Mutation fuzzing of the text and binary loaders with proptest: valid seed files are truncated,
//! have bytes overwritten and have random tokens spliced in. Whatever the bytes, loading must
//! return `Ok` or an input error — never panic. The unguarded entry point is used so that a panic in
//! our code or in a parser crate fails the test instead of being turned into an error.
//!
//! Run longer with e.g. `PROPTEST_CASES=20000 cargo test --release --test integration fuzz`.

use proptest::prelude::*;

use lodeval::mesh::{LoadOptions, load_unguarded};

const OBJ_SEED: &str = "mtllib m.mtl\nv 0 0 0\nv 1 0 0 0.5 0.5 0.5\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvn 0 0 1\ng a\nusemtl a\nf 1/1/1 3/2/1 2/1/1\nf 1//1 2//1 4//1\nf -3 -2 -1\nf 1 4 3 2\n";
const MTL_SEED: &str = "newmtl a\nKd 0.5 0.5 0.5\nNs 20\n";
const OFF_SEED: &str =
    "OFF\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n4 0 3 2 1\n";

fn ply_seed(binary: bool) -> Vec<u8> {
    let header = |fmt: &str| {
        format!(
            "ply\nformat {fmt} 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face 2\nproperty list uchar int vertex_indices\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n"
        )
    };
    if !binary {
        return (header("ascii") + "0 0 0 255 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n0 0 1 9 9 9\n3 0 2 1\n4 0 1 3 2\n6 0 1 2 -1 3 1\n").into_bytes();
    }
    let mut b = header("binary_little_endian").into_bytes();
    for p in [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]] {
        p.iter().for_each(|c| b.extend_from_slice(&c.to_le_bytes()));
        b.extend_from_slice(&[10, 20, 30]);
    }
    for f in [&[0i32, 2, 1][..], &[0, 1, 3, 2]] {
        b.push(f.len() as u8);
        f.iter().for_each(|i| b.extend_from_slice(&i.to_le_bytes()));
    }
    b.extend_from_slice(&6i32.to_le_bytes());
    [0i32, 1, 2, -1, 3, 1]
        .iter()
        .for_each(|i| b.extend_from_slice(&i.to_le_bytes()));
    b
}

/// A one-triangle binary glTF: JSON chunk and BIN chunk, each padded to 4 bytes.
fn glb_seed() -> Vec<u8> {
    let mut bin = Vec::new();
    [0f32, 0., 0., 1., 0., 0., 0., 1., 0.]
        .iter()
        .for_each(|c| bin.extend_from_slice(&c.to_le_bytes()));
    [0u16, 1, 2, 0]
        .iter()
        .for_each(|i| bin.extend_from_slice(&i.to_le_bytes()));
    let mut json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0,"scale":[1,-1,1]}}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],"buffers":[{{"byteLength":{}}}],"bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},{{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}]}}"#,
        bin.len()
    )
    .into_bytes();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

#[derive(Debug, Clone)]
enum Mutation {
    Truncate(usize),
    Overwrite(usize, u8),
    Splice(usize, String),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let token = prop_oneof![
        Just("nan".to_string()),
        Just("-1".to_string()),
        Just("4294967295".to_string()),
        Just("\n".to_string()),
        Just("/".to_string()),
        Just(" f 1 2 3\n".to_string()),
        Just("1e40".to_string()),
        "[ -~]{0,8}",
    ];
    prop_oneof![
        any::<usize>().prop_map(Mutation::Truncate),
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Mutation::Overwrite(i, b)),
        (any::<usize>(), token).prop_map(|(i, t)| Mutation::Splice(i, t)),
    ]
}

fn apply(seed: &[u8], muts: &[Mutation]) -> Vec<u8> {
    let mut b = seed.to_vec();
    for m in muts {
        match m {
            Mutation::Truncate(i) => b.truncate(i % (b.len() + 1)),
            Mutation::Overwrite(i, v) if !b.is_empty() => {
                let n = b.len();
                b[i % n] = *v;
            }
            Mutation::Splice(i, t) => {
                let at = i % (b.len() + 1);
                b.splice(at..at, t.bytes());
            }
            _ => {}
        }
    }
    b
}

fn load_bytes(name: &str, bytes: &[u8], side: &[(&str, &[u8])]) {
    let dir = tempfile::tempdir().unwrap();
    for (n, b) in side {
        std::fs::write(dir.path().join(n), b).unwrap();
    }
    let p = dir.path().join(name);
    std::fs::write(&p, bytes).unwrap();
    // Ok or Err are both fine; a panic fails the property.
    let _ = load_unguarded(&p, &LoadOptions::DEFAULT);
}

proptest! {
    #![proptest_config(ProptestConfig { failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn obj_never_panics(muts in prop::collection::vec(mutation(), 1..6)) {
        load_bytes("f.obj", &apply(OBJ_SEED.as_bytes(), &muts), &[("m.mtl", MTL_SEED.as_bytes())]);
    }

    #[test]
    fn mtl_never_panics(muts in prop::collection::vec(mutation(), 1..6)) {
        let mtl = apply(MTL_SEED.as_bytes(), &muts);
        load_bytes("f.obj", OBJ_SEED.as_bytes(), &[("m.mtl", &mtl)]);
    }

    #[test]
    fn ply_ascii_never_panics(muts in prop::collection::vec(mutation(), 1..6)) {
        load_bytes("f.ply", &apply(&ply_seed(false), &muts), &[]);
    }

    #[test]
    fn ply_binary_never_panics(muts in prop::collection::vec(mutation(), 1..6)) {
        load_bytes("f.ply", &apply(&ply_seed(true), &muts), &[]);
    }

    #[test]
    fn glb_never_panics(muts in prop::collection::vec(mutation(), 1..6)) {
        load_bytes("f.glb", &apply(&glb_seed(), &muts), &[]);
    }

    #[test]
    fn off_never_panics(muts in prop::collection::vec(mutation(), 1..6)) {
        load_bytes("f.off", &apply(OFF_SEED.as_bytes(), &muts), &[]);
    }
}

#[test]
fn seeds_are_valid() {
    // The fuzzers start from files that load, so mutations explore the edges of valid input.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("m.mtl"), MTL_SEED).unwrap();
    // Expected triangles: OBJ 3 triangles + 1 quad; PLY 1 triangle + 1 quad + a strip of one
    // triangle (the second sub-strip has two indices); OFF 3 triangles + 1 quad; GLB 1 triangle.
    for (name, bytes, tris) in [
        ("s.obj", OBJ_SEED.as_bytes().to_vec(), 5),
        ("a.ply", ply_seed(false), 4),
        ("b.ply", ply_seed(true), 4),
        ("s.off", OFF_SEED.as_bytes().to_vec(), 5),
        ("s.glb", glb_seed(), 1),
    ] {
        let p = dir.path().join(name);
        std::fs::write(&p, bytes).unwrap();
        let m = load_unguarded(&p, &LoadOptions::DEFAULT).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(m.triangle_count(), tris, "{name}");
    }
}
