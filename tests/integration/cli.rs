//! The command line end to end: exit codes, output shapes, and honest "not built yet" answers.

use crate::common::{lodeval, model};

#[test]
fn info_prints_counts_for_the_shipped_bunny() {
    let r = lodeval([
        "info".as_ref(),
        model("bunny/stanford-bunny.obj").as_os_str(),
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(
        r.stdout.contains("triangles            69451"),
        "{}",
        r.stdout
    );
    assert!(r.stdout.contains("1113 vertices dropped"), "{}", r.stdout);
}

#[test]
fn info_json_has_the_documented_keys() {
    let r = lodeval([
        "info",
        "--json",
        model("spot/spot_mtl.obj").to_str().unwrap(),
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let v: serde_json::Value = serde_json::from_str(&r.stdout).expect("valid JSON");
    assert_eq!(v["triangles"], 5856);
    assert_eq!(v["file_vertices"], 2930);
    // Spot's UV seams split 2930 positions into 3225 vertices; welding gives the positions back.
    assert_eq!(v["vertices"], 3225);
    assert_eq!(v["welded_vertices"], 2930);
    assert_eq!(v["materials"][0]["textures"][0]["width"], 1024);
    assert_eq!(v["attributes"]["uvs"], true);
}

#[test]
fn global_flags_work_before_and_after_the_subcommand() {
    let m = model("dragon/dragon_vrip_res4.ply");
    let m = m.to_str().unwrap();
    let a = lodeval(["--threads", "2", "info", "--json", m]);
    let b = lodeval(["info", "--json", m, "--threads", "1", "--quiet"]);
    assert_eq!((a.code, b.code), (0, 0), "{} {}", a.stderr, b.stderr);
    assert_eq!(a.stdout, b.stdout);
}

#[test]
fn zero_threads_is_a_usage_error() {
    let r = lodeval(["--threads", "0", "info", "x.obj"]);
    assert_eq!(r.code, 2);
    assert!(r.stderr.contains("--threads"), "{}", r.stderr);
}

#[test]
fn unbuilt_subcommands_say_so_and_exit_2() {
    for cmd in ["diff", "eval", "golden", "simplify", "optimize", "merge"] {
        let r = lodeval([cmd, "whatever", "--flag"]);
        assert_eq!(r.code, 2, "{cmd}: {}", r.stderr);
        assert!(r.stderr.contains("not built yet"), "{cmd}: {}", r.stderr);
        assert!(r.stdout.is_empty());
    }
}

#[test]
fn unknown_flag_is_a_usage_error() {
    let r = lodeval(["info", "--no-such-flag", "x.obj"]);
    assert_eq!(r.code, 2);
}

#[test]
fn glb_with_normal_map_reports_both_textures() {
    let r = lodeval([
        "info",
        "--json",
        model("barrel/barrel.glb").to_str().unwrap(),
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    let roles: Vec<String> = v["materials"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|m| {
            m["textures"]
                .as_array()
                .unwrap()
                .iter()
                .map(|t| t["role"].as_str().unwrap().to_string())
        })
        .collect();
    assert!(
        roles.contains(&"base_color".to_string()) && roles.contains(&"normal".to_string()),
        "{roles:?}"
    );
}

#[test]
fn ci_runs_the_readme_test_command() {
    // The README's quick start promises that its test command is what CI runs.
    let readme = std::fs::read_to_string(crate::common::root().join("README.md")).unwrap();
    let ci = std::fs::read_to_string(crate::common::root().join(".ci/run")).unwrap();
    let ci_test = ci
        .lines()
        .rev()
        .find(|l| l.starts_with("cargo test"))
        .expect("a cargo test line in .ci/run");
    let quick_start = readme
        .split("## Quick start")
        .nth(1)
        .unwrap()
        .split("\n## ")
        .next()
        .unwrap();
    assert!(
        quick_start.contains(ci_test.trim()),
        "README quick start lacks `{ci_test}`"
    );
}
