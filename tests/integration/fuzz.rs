//! Mutation fuzzing with proptest. The text and binary loaders: valid seed files are truncated,
//! have bytes overwritten and have random tokens spliced in. Whatever the bytes, loading must
//! return `Ok` or an input error — never panic. The unguarded entry point is used so that a panic in
//! our code or in a parser crate fails the test instead of being turned into an error. glTF JSON
//! structure: indices, counts, offsets and node children rewritten (cycles, shared children,
//! ranges past the end), with a time limit, since a cycle used to hang. Configs: values replaced
//! by hostile tokens, lines dropped or repeated; planning never panics, and what it accepts lies
//! within `src/limits.rs`.
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

// Structural fuzzing of glTF JSON: instead of bytes, the document's numbers, indices and arrays
// are rewritten (node children pointing anywhere, so cycles and shared children; counts, offsets,
// strides and lengths from -1 to 2^64; keys removed). Loading must end — a hang fails the test
// after 20 s instead of stalling the suite — with `Ok` or an input error, never a panic.

/// The square of `hostile::gltf` (a node tree, two buffer views, two accessors), buffer inline.
fn gltf_json_seed() -> serde_json::Value {
    use crate::hostile::gltf::{square_bin, square_document};
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64_encode(&square_bin())
    );
    square_document(&uri)
}

/// Standard base64 (the seed's inline buffer); a dozen lines rather than a dependency for a test.
fn base64_encode(bytes: &[u8]) -> String {
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                out.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Every place in `v` a mutation can hit: numbers, arrays and object keys, as JSON pointers.
fn pointers(v: &serde_json::Value, at: String, out: &mut Vec<String>) {
    match v {
        serde_json::Value::Object(m) => {
            for (k, x) in m {
                let p = format!("{at}/{k}");
                out.push(p.clone());
                pointers(x, p, out);
            }
        }
        serde_json::Value::Array(a) => {
            out.push(at.clone());
            for (i, x) in a.iter().enumerate() {
                pointers(x, format!("{at}/{i}"), out);
            }
        }
        serde_json::Value::Number(_) => out.push(at),
        _ => {}
    }
}

#[derive(Debug, Clone)]
enum JsonMutation {
    /// Set the value at a place to a hostile number.
    Number(usize, i128),
    /// Set it to an array of indices (node children, scene roots: cycles and sharing).
    Indices(usize, Vec<u8>),
    /// Remove it.
    Remove(usize),
    /// Set one of the structural fields below (created if absent) to a hostile number or, for
    /// node lists, to indices: the fields a reader follows, where most mutations that matter
    /// land (random places mostly break the document before anything walks it).
    Structural(usize, i128, Vec<u8>),
}

/// The fields a glTF reader follows: node lists (a cycle hung the loader) and the numbers that
/// place accessors, views and buffers.
const STRUCTURAL: &[&str] = &[
    "/nodes/0/children",
    "/nodes/1/children",
    "/nodes/2/children",
    "/scenes/0/nodes",
    "/scene",
    "/nodes/1/mesh",
    "/accessors/0/count",
    "/accessors/1/count",
    "/accessors/0/byteOffset",
    "/accessors/1/byteOffset",
    "/accessors/1/bufferView",
    "/bufferViews/0/byteLength",
    "/bufferViews/1/byteLength",
    "/bufferViews/1/byteOffset",
    "/bufferViews/0/byteStride",
    "/buffers/0/byteLength",
    "/meshes/0/primitives/0/indices",
];

fn json_mutation() -> impl Strategy<Value = JsonMutation> {
    let number = prop_oneof![
        Just(-1i128),
        Just(0),
        Just(1),
        Just(2),
        Just(3),
        Just(7),
        Just(u32::MAX as i128),
        Just(u64::MAX as i128),
        Just(1 << 40),
        0i128..100,
    ];
    prop_oneof![
        1 => (any::<usize>(), number.clone()).prop_map(|(i, n)| JsonMutation::Number(i, n)),
        1 => (any::<usize>(), prop::collection::vec(0u8..4, 0..4))
            .prop_map(|(i, v)| JsonMutation::Indices(i, v)),
        1 => any::<usize>().prop_map(JsonMutation::Remove),
        6 => (any::<usize>(), number, prop::collection::vec(0u8..4, 0..4))
            .prop_map(|(i, n, v)| JsonMutation::Structural(i, n, v)),
    ]
}

fn apply_json(seed: &serde_json::Value, muts: &[JsonMutation]) -> serde_json::Value {
    let mut v = seed.clone();
    for m in muts {
        let mut places = Vec::new();
        pointers(&v, String::new(), &mut places);
        if places.is_empty() {
            break;
        }
        let (i, new) = match m {
            JsonMutation::Number(i, n) => (*i, Some(serde_json::json!(n))),
            JsonMutation::Indices(i, ix) => (*i, Some(serde_json::json!(ix))),
            JsonMutation::Remove(i) => (*i, None),
            JsonMutation::Structural(i, n, ix) => {
                let place = STRUCTURAL[i % STRUCTURAL.len()];
                let value = if place.ends_with("children") || place.ends_with("/nodes") {
                    serde_json::json!(ix)
                } else {
                    serde_json::json!(n)
                };
                let (parent, key) = place.rsplit_once('/').unwrap();
                if let Some(serde_json::Value::Object(m)) = v.pointer_mut(parent) {
                    m.insert(key.to_string(), value);
                }
                continue;
            }
        };
        let place = &places[i % places.len()];
        match new {
            Some(n) => {
                if let Some(slot) = v.pointer_mut(place) {
                    *slot = n;
                }
            }
            None => {
                let (parent, key) = place.rsplit_once('/').unwrap();
                match v.pointer_mut(parent) {
                    Some(serde_json::Value::Object(m)) => {
                        m.remove(key);
                    }
                    Some(serde_json::Value::Array(a)) => {
                        if let Ok(k) = key.parse::<usize>()
                            && k < a.len()
                        {
                            a.remove(k);
                        }
                    }
                    _ => {}
                }
            }
        }
    }
    v
}

/// Load `bytes` as `name` on a thread; a load that does not end within the hang limit for 20 s
/// of work is a hang.
fn load_within(name: &str, bytes: Vec<u8>) {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join(name);
    std::fs::write(&p, &bytes).unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    let path = p.clone();
    std::thread::spawn(move || {
        let _ = load_unguarded(&path, &LoadOptions::DEFAULT);
        let _ = tx.send(());
    });
    let limit = crate::common::hang_limit(20);
    match rx.recv_timeout(limit) {
        Ok(()) => {}
        Err(std::sync::mpsc::RecvTimeoutError::Timeout) => panic!(
            "loading did not end within {limit:?} (a hang):\n{}",
            String::from_utf8_lossy(&bytes)
        ),
        // The thread panicked: proptest reports the panic message it printed.
        Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
            panic!("loading panicked:\n{}", String::from_utf8_lossy(&bytes))
        }
    }
}

// Config fuzzing: a valid config with every section, its values replaced by hostile tokens and
// its lines dropped or repeated. Parsing and planning must return `Ok` or an input error, never
// panic; and whatever is accepted must lie within lodeval's limits.

const CONFIG_SEED: &str = r#"out = "out"
metrics = ["flip", "ssim", "psnr", "vdp"]
geometry_samples = 1000
flip_pixel_threshold = 0.1
[render]
size = 64
samples = 4
rig = "icosahedron"
shading = "gouraud"
background = [0.5, 0.5, 0.5]
[viewing]
display_width_m = 0.7
display_px = 3840
distance_m = 0.7
[images]
heatmaps = "worst"
sheet_views = 6
[distance]
probability = 0.5
max_diameter_px = 64
views = 2
[thresholds]
flip_mean = 0.05
[gate]
tolerance = 0.1
[[asset]]
name = "a"
mesh = "a.obj"
meters_per_unit = 0.1
generate = { method = "meshopt", ratios = [0.5, 0.25], switch_m = [8.0] }
lods = [{ mesh = "b.obj", name = "b", switch_m = 3.0, thresholds = { ssim_min = 0.9 } }]
"#;

#[derive(Debug, Clone)]
enum ConfigMutation {
    /// Replace the value of line `i` (after its `=`) with a hostile token.
    Value(usize, String),
    /// Drop line `i`.
    Drop(usize),
    /// Repeat line `i`.
    Repeat(usize),
}

fn config_mutation() -> impl Strategy<Value = ConfigMutation> {
    let token = prop_oneof![
        Just("nan".to_string()),
        Just("inf".to_string()),
        Just("-inf".to_string()),
        Just("-1".to_string()),
        Just("0".to_string()),
        Just("1e400".to_string()),
        Just("1e-30".to_string()),
        Just("4294967296".to_string()),
        Just("18446744073709551616".to_string()),
        Just("\"\"".to_string()),
        Just("\"fibonacci:0\"".to_string()),
        Just("\"fibonacci:4000000000\"".to_string()),
        Just("[]".to_string()),
        Just("[0.25, 0.5]".to_string()),
        Just("{}".to_string()),
        "[ -~]{0,6}",
    ];
    prop_oneof![
        (any::<usize>(), token).prop_map(|(i, t)| ConfigMutation::Value(i, t)),
        any::<usize>().prop_map(ConfigMutation::Drop),
        any::<usize>().prop_map(ConfigMutation::Repeat),
    ]
}

fn apply_config(muts: &[ConfigMutation]) -> String {
    let mut lines: Vec<String> = CONFIG_SEED.lines().map(str::to_string).collect();
    for m in muts {
        if lines.is_empty() {
            break;
        }
        match m {
            ConfigMutation::Value(i, t) => {
                let n = lines.len();
                let l = &mut lines[i % n];
                if let Some((k, _)) = l.split_once('=') {
                    *l = format!("{k}= {t}");
                }
            }
            ConfigMutation::Drop(i) => {
                let n = lines.len();
                lines.remove(i % n);
            }
            ConfigMutation::Repeat(i) => {
                let n = lines.len();
                let l = lines[i % n].clone();
                lines.insert(i % n, l);
            }
        }
    }
    lines.join("\n") + "\n"
}

proptest! {
    #![proptest_config(ProptestConfig { failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn gltf_structure_never_panics_or_hangs(muts in prop::collection::vec(json_mutation(), 1..5)) {
        let doc = apply_json(&gltf_json_seed(), &muts);
        load_within("f.gltf", serde_json::to_vec(&doc).unwrap());
    }

    #[test]
    fn configs_never_panic_and_accepted_ones_are_within_limits(
        muts in prop::collection::vec(config_mutation(), 1..5)
    ) {
        use lodeval::limits;
        let text = apply_config(&muts);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.toml");
        if let Ok(plan) = lodeval::eval::Plan::from_text(text.clone(), &path) {
            let c = &plan.config;
            prop_assert!(limits::IMAGE_SIDE.contains(c.render.size.0 as u64), "{text}");
            prop_assert!(limits::VIEWS.contains(c.render.rig.0.count() as u64), "{text}");
            prop_assert!(limits::PPD.contains(c.viewing.viewing().ppd()), "{text}");
            prop_assert!(c.viewing.viewing().check().is_ok(), "{text}");
            prop_assert!(limits::SURFACE_SAMPLES.contains(c.geometry_samples as u64), "{text}");
            prop_assert!(limits::SHEET_VIEWS.contains(c.images.sheet_views as u64), "{text}");
            prop_assert!(!plan.assets.is_empty(), "{text}");
            for a in &plan.assets {
                prop_assert!(a.meters_per_unit.is_finite() && a.meters_per_unit > 0.0, "{text}");
                for l in &a.lods {
                    prop_assert!(l.switch_m.is_none_or(|s| s.is_finite() && s > 0.0), "{text}");
                    for limit in &l.limits {
                        prop_assert!(limit.value.is_finite(), "{text}");
                    }
                }
            }
        }
    }
}

#[test]
fn structural_seeds_are_valid() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("s.gltf");
    std::fs::write(&p, serde_json::to_vec(&gltf_json_seed()).unwrap()).unwrap();
    let m = load_unguarded(&p, &LoadOptions::DEFAULT).unwrap();
    assert_eq!(m.triangle_count(), 2);
    lodeval::eval::Plan::from_text(CONFIG_SEED.to_string(), &dir.path().join("c.toml")).unwrap();
}

#[test]
fn the_structural_fuzzer_reaches_cycles_and_out_of_range_views() {
    // A fuzzer that never builds the inputs it is for would pass on a broken loader: check that
    // its default case count builds node cycles and accessors past their views, and that the
    // known cycle is refused (it hung the loader).
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;
    let mut runner = TestRunner::deterministic();
    let strat = prop::collection::vec(json_mutation(), 1..5);
    let (mut cycles, mut bounds) = (0, 0);
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("f.gltf");
    for _ in 0..256 {
        let doc = apply_json(
            &gltf_json_seed(),
            &strat.new_tree(&mut runner).unwrap().current(),
        );
        std::fs::write(&p, serde_json::to_vec(&doc).unwrap()).unwrap();
        if let Err(e) = load_unguarded(&p, &LoadOptions::DEFAULT) {
            let e = e.to_string();
            cycles += usize::from(e.contains("cycle") || e.contains("its own child"));
            bounds += usize::from(e.contains("past the end") || e.contains("needs"));
        }
    }
    assert!(
        cycles >= 5 && bounds >= 5,
        "{cycles} cycles, {bounds} out-of-range views"
    );
    let mut doc = gltf_json_seed();
    doc["nodes"][2]["children"] = serde_json::json!([0]);
    std::fs::write(&p, serde_json::to_vec(&doc).unwrap()).unwrap();
    let e = load_unguarded(&p, &LoadOptions::DEFAULT).unwrap_err();
    assert!(e.to_string().contains("cycle"), "{e}");
}

#[test]
fn the_config_fuzzer_reaches_both_accepted_and_refused_configs() {
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;
    let mut runner = TestRunner::deterministic();
    let strat = prop::collection::vec(config_mutation(), 1..5);
    let dir = tempfile::tempdir().unwrap();
    let (mut ok, mut refused) = (0, 0);
    for _ in 0..256 {
        let text = apply_config(&strat.new_tree(&mut runner).unwrap().current());
        match lodeval::eval::Plan::from_text(text, &dir.path().join("c.toml")) {
            Ok(_) => ok += 1,
            Err(_) => refused += 1,
        }
    }
    assert!(
        ok >= 20 && refused >= 20,
        "{ok} accepted, {refused} refused"
    );
}
