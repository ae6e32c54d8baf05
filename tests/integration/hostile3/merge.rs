//! `merge` mixed shards that ran on different meshes (or on a mesh edited between shards), and
//! did not check that each case had its rows. The manifests now record the inputs' content
//! hashes; a merge across different inputs is refused.

use super::{assert_refused, config, run, s, scratch, spot_copy};

#[test]
fn shards_of_edited_inputs_are_not_merged() {
    let tmp = scratch("r3-merge");
    let d = tmp.path();
    let spot = spot_copy(d);
    let cfg = config(d, "c.toml", &spot, "out", "");
    let shard = |i: usize| d.join(format!("s{i}"));
    let eval = |i: usize| {
        run(&[
            "eval",
            s(&cfg),
            "-q",
            "--shard",
            &format!("{i}/2"),
            "--out",
            s(&shard(i)),
        ])
    };
    let r = eval(0);
    assert_eq!(r.code, 0, "{}", r.stderr);
    // The mesh is edited between the shards (one vertex moved).
    let text = std::fs::read_to_string(&spot).unwrap();
    let start = text.find("\nv ").unwrap() + 1;
    let end = start + text[start..].find('\n').unwrap();
    let v: Vec<f32> = text[start + 2..end]
        .split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect();
    let moved = format!("v {} {} {}", v[0] + 0.01, v[1], v[2]);
    std::fs::write(&spot, format!("{}{moved}{}", &text[..start], &text[end..])).unwrap();
    let r = eval(1);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(shard(0).join("shard.json")).unwrap()).unwrap();
    let inputs = json["inputs"].as_array().expect("inputs recorded");
    assert!(
        inputs
            .iter()
            .any(|x| x["path"].as_str().unwrap().ends_with("spot_mtl.obj"))
    );
    assert!(
        inputs
            .iter()
            .any(|x| x["path"].as_str().unwrap().ends_with("spot_texture.png"))
    );
    let r = run(&[
        "merge",
        s(&shard(0)),
        s(&shard(1)),
        "--out",
        s(&d.join("m")),
    ]);
    assert_refused(
        &r,
        "edited mesh",
        &["spot_mtl.obj", "different or edited inputs"],
    );
    assert!(!d.join("m").exists());
}
