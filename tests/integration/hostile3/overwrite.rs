//! Inputs overwritten through a path that does not exist yet: every "is this output one of my
//! inputs?" guard looked at the output path's metadata, and `missing/../in.obj` has none, so the
//! writer created `missing` and replaced the input (`simplify in.obj -o nd/../in.obj` exited 0
//! with `in.obj` replaced by its LOD). All guards now compare where the write would land.

use super::{assert_refused, config, run, s, scratch, spot_copy};
use crate::common::files;

#[test]
fn no_command_writes_over_an_input_through_a_missing_folder() {
    let tmp = scratch("r3-overwrite");
    let d = tmp.path();
    let spot = spot_copy(d);
    let before = files(d);
    let via = |name: &str| d.join("nd").join("..").join(name);
    let cases: Vec<(&str, Vec<String>, &str)> = vec![
        (
            "simplify",
            vec![
                "simplify".into(),
                s(&spot).into(),
                "-o".into(),
                s(&via("spot_mtl.obj")).into(),
                "--ratio".into(),
                "0.5".into(),
            ],
            "spot_mtl.obj",
        ),
        (
            "render",
            vec![
                "render".into(),
                s(&spot).into(),
                "-o".into(),
                s(&via("spot_texture.png")).into(),
                "--size".into(),
                "32".into(),
            ],
            "spot_texture.png",
        ),
        (
            "optimize",
            vec![
                "optimize".into(),
                s(&spot).into(),
                s(&spot).into(),
                "-o".into(),
                s(&via("spot_mtl.obj")).into(),
                "--evals".into(),
                "10".into(),
            ],
            "spot_mtl.obj",
        ),
        (
            "remesh",
            vec![
                "remesh".into(),
                s(&spot).into(),
                "-o".into(),
                s(&via("spot_mtl.obj")).into(),
                "--vertices".into(),
                "500".into(),
            ],
            "spot_mtl.obj",
        ),
    ];
    for (what, args, culprit) in cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let r = run(&args);
        assert_refused(&r, what, &[culprit, "is an input of this run"]);
        assert!(!d.join("nd").exists(), "{what}: created the missing folder");
    }
    assert_eq!(files(d), before, "an input changed");
}

#[test]
fn eval_and_merge_folder_guards_see_through_a_missing_folder() {
    let tmp = scratch("r3-overwrite-eval");
    let d = tmp.path();
    let spot = spot_copy(d);
    std::fs::create_dir(d.join("models")).unwrap();
    std::fs::write(d.join("models/keep.obj"), "v 0 0 0\n").unwrap();
    let cfg = config(d, "c.toml", &spot, "out", "");
    let before = files(d);
    // --out through a missing folder onto someone else's folder: refused as not lodeval's.
    let out = d.join("nd/../models");
    let r = run(&["eval", s(&cfg), "--out", s(&out), "-q"]);
    assert_refused(
        &r,
        "eval --out nd/../models",
        &["keep.obj", "did not write"],
    );
    assert_eq!(files(d), before);
    // A shard, then merge --out through a missing folder onto the shard.
    let shard = d.join("s0");
    let r = run(&["eval", s(&cfg), "--out", s(&shard), "-q"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let shard_files = files(&shard);
    let r = run(&["merge", s(&shard), "--out", s(&d.join("nd/../s0"))]);
    assert_refused(&r, "merge --out nd/../s0", &["shard folder"]);
    assert_eq!(files(&shard), shard_files);
    assert!(!d.join("nd").exists());
}
