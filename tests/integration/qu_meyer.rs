//! `lodeval remesh` (Qu & Meyer) end to end: the remesh and its maps, JSON, thread independence,
//! the eval generator, the experiment on a small config, and bad requests. The stages have unit
//! tests in `src/simplify/qu_meyer/` (the plane, closed seams, Lloyd, masking).

use std::path::Path;

use crate::common::{files, lodeval, model};

fn remesh(mesh: &Path, out: &Path, args: &[&str]) -> crate::common::Run {
    let mut all = vec![
        "remesh".to_string(),
        mesh.display().to_string(),
        "-o".into(),
        out.display().to_string(),
    ];
    all.extend(args.iter().map(|s| s.to_string()));
    lodeval(all)
}

#[test]
fn a_remesh_has_its_vertices_maps_and_json() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("spot.obj");
    let maps = dir.path().join("maps");
    let r = remesh(
        &model("spot/spot_mtl.obj"),
        &out,
        &[
            "--vertices",
            "900",
            "--map-size",
            "256",
            "--maps",
            maps.to_str().unwrap(),
            "--json",
        ],
    );
    assert_eq!(r.code, 0, "{}", r.stderr);
    let j: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    let v = j["vertices"].as_u64().unwrap();
    assert!((860..=900).contains(&v), "{j}");
    assert!(j["triangles"].as_u64().unwrap() > v, "{j}");
    assert_eq!(j["charts"].as_u64().unwrap(), 13, "{j}");
    assert_eq!(j["iterations"].as_u64().unwrap(), 20, "{j}");
    for stage in ["maps", "masking", "sampling", "lloyd", "triangulation"] {
        assert!(j["seconds"][stage].as_f64().unwrap() >= 0.0, "{stage}: {j}");
    }
    // The written mesh loads, keeps the texture, and has the reported size.
    let info = lodeval(["info", out.to_str().unwrap()]);
    assert_eq!(info.code, 0, "{}", info.stderr);
    assert!(
        info.stdout.contains(&format!("welded vertices      {v}")),
        "{}",
        info.stdout
    );
    assert!(
        info.stdout.contains("uvs: yes") && info.stdout.contains("baseColorTexture"),
        "{}",
        info.stdout
    );
    for name in ["signal", "masking", "curvature", "density", "samples"] {
        let img = image::open(maps.join(format!("{name}.png"))).unwrap();
        assert_eq!((img.width(), img.height()), (256, 256), "{name}");
    }
    // The perceptual density moves vertices out of the masked quarter; uniform does not.
    let uniform = dir.path().join("uniform.obj");
    let r = remesh(
        &model("spot/spot_mtl.obj"),
        &uniform,
        &[
            "--vertices",
            "900",
            "--map-size",
            "256",
            "--method",
            "uniform",
            "--json",
        ],
    );
    let u: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    let (masked_qm, masked_u) = (
        j["masked_share"].as_f64().unwrap(),
        u["masked_share"].as_f64().unwrap(),
    );
    assert!(
        masked_qm < 0.5 * masked_u,
        "qu-meyer {masked_qm}, uniform {masked_u}"
    );
}

#[test]
fn the_remesh_is_identical_for_1_2_and_8_threads() {
    let dir = tempfile::tempdir().unwrap();
    let mut outputs = Vec::new();
    for threads in ["1", "2", "8"] {
        let sub = dir.path().join(format!("t{threads}"));
        std::fs::create_dir(&sub).unwrap();
        let r = lodeval([
            "--threads",
            threads,
            "remesh",
            model("bob/bob_tri.obj").to_str().unwrap(),
            "-o",
            sub.join("bob.obj").to_str().unwrap(),
            "--vertices",
            "800",
            "--map-size",
            "256",
            "--maps",
            sub.join("maps").to_str().unwrap(),
        ]);
        assert_eq!(r.code, 0, "{}", r.stderr);
        outputs.push(files(&sub));
    }
    assert!(outputs[0] == outputs[1] && outputs[0] == outputs[2]);
}

#[test]
fn bad_requests_exit_2_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let spot = model("spot/spot_mtl.obj");
    // Every face of a cube on the same UV square: overlapping charts.
    let cube = dir.path().join("cube.obj");
    let mut obj = String::from(
        "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n",
    );
    obj.push_str("vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n");
    for f in [
        [1, 4, 3, 2],
        [5, 6, 7, 8],
        [1, 2, 6, 5],
        [2, 3, 7, 6],
        [3, 4, 8, 7],
        [4, 1, 5, 8],
    ] {
        obj.push_str(&format!(
            "f {}/1 {}/2 {}/3\nf {}/1 {}/3 {}/4\n",
            f[0], f[1], f[2], f[0], f[2], f[3]
        ));
    }
    std::fs::write(&cube, obj).unwrap();
    let bunny = model("bunny/bunny_odedstein_3k.obj");
    let cases: Vec<(&Path, Vec<&str>, &str)> = vec![
        (&bunny, vec!["--vertices", "500"], "no texture coordinates"),
        (&spot, vec!["--vertices", "3"], "4 to 10000000 vertices"),
        (&spot, vec!["--vertices", "200000"], "more than the"),
        (
            &spot,
            vec!["--vertices", "500", "--perceptual-gamma", "NaN"],
            "a gamma is a number",
        ),
        (
            &spot,
            vec!["--vertices", "500", "--curvature-gamma", "-1"],
            "a gamma is a number",
        ),
        (
            &spot,
            vec!["--vertices", "500", "--map-size", "4"],
            "--map-size 4",
        ),
        (&spot, vec!["--vertices", "8"], "seams alone"),
        (
            &cube,
            vec!["--vertices", "100"],
            "covered by more than one triangle",
        ),
    ];
    for (mesh, args, words) in cases {
        let out = dir.path().join("out.obj");
        let maps = dir.path().join("maps");
        let mut a = args.clone();
        a.extend(["--maps", maps.to_str().unwrap()]);
        let r = remesh(mesh, &out, &a);
        assert_eq!(r.code, 2, "{args:?}: {}", r.stderr);
        assert!(r.stderr.contains(words), "{args:?}: {}", r.stderr);
        assert_eq!(r.stderr.lines().count(), 1, "{args:?}: {}", r.stderr);
        assert!(!out.exists() && !maps.exists(), "{args:?} wrote something");
    }
    // -o onto the input is refused before anything is written.
    let copy = dir.path().join("spot.obj");
    std::fs::copy(&spot, &copy).unwrap();
    std::fs::copy(spot.with_file_name("spot.mtl"), dir.path().join("spot.mtl")).unwrap();
    std::fs::copy(
        spot.with_file_name("spot_texture.png"),
        dir.path().join("spot_texture.png"),
    )
    .unwrap();
    let before = std::fs::read(&copy).unwrap();
    let r = remesh(&copy, &copy, &["--vertices", "500"]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert_eq!(std::fs::read(&copy).unwrap(), before);
}

#[test]
fn eval_generates_remeshes_by_vertex_count() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("qm.toml");
    let write = |generate: &str, out: &str| {
        std::fs::write(
            &cfg,
            format!(
                "out = \"{out}\"\nmetrics = [\"flip\"]\n[render]\nsize = 64\nrig = \"icosahedron\"\n\
                 [distance]\nenabled = false\n[[asset]]\nname = \"spot\"\nmesh = \"{}\"\n\
                 generate = {generate}\n",
                model("spot/spot_mtl.obj").display()
            ),
        )
        .unwrap();
    };
    write("{ method = \"qu-meyer\", vertices = [1200, 600] }", "out");
    let r = lodeval(["eval", cfg.to_str().unwrap(), "-q"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let lods = std::fs::read_to_string(dir.path().join("out/lods.csv")).unwrap();
    for name in ["qu-meyer-v1200", "qu-meyer-v600", "qu-meyer 600 vertices"] {
        assert!(lods.contains(name), "{name}: {lods}");
    }
    for (generate, words) in [
        (
            "{ method = \"qu-meyer\", vertices = [600, 1200] }",
            "vertex counts must decrease",
        ),
        (
            "{ method = \"qu-meyer\", ratios = [0.5] }",
            "remeshes to vertex counts only",
        ),
        (
            "{ method = \"qem\", vertices = [500] }",
            "those are for qu-meyer",
        ),
        ("{ method = \"qu-meyer\", vertices = [2] }", "at least 4"),
    ] {
        write(generate, "out2");
        let r = lodeval(["eval", cfg.to_str().unwrap()]);
        assert_eq!(r.code, 2, "{generate}: {}", r.stderr);
        assert!(r.stderr.contains(words), "{generate}: {}", r.stderr);
    }
}

#[test]
fn the_paper_experiment_runs_from_a_config() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("qm.toml");
    std::fs::write(
        &cfg,
        format!(
            "paper = \"qu-meyer\"\nout = \"out\"\nsize = 64\npattern_only = true\n\
             [[model]]\nname = \"spot\"\nmesh = \"{}\"\nvertices = [400]\n",
            model("spot/spot_mtl.obj").display()
        ),
    )
    .unwrap();
    let r = lodeval(["remesh", "--experiment", cfg.to_str().unwrap(), "-q"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let out = dir.path().join("out");
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    assert_eq!(csv.lines().count(), 5, "{csv}");
    for method in ["uniform", "curvature", "qu-meyer", "qu-meyer-pattern"] {
        assert!(
            csv.contains(&format!("spot,400,{method},")),
            "{method}: {csv}"
        );
    }
    assert!(out.join("maps/spot/masking.png").exists());
    assert!(out.join("eval/summary.csv").exists());
    // A config for another paper is refused.
    std::fs::write(&cfg, "paper = \"williams2003\"\nout = \"o\"\nmodel = []\n").unwrap();
    let r = lodeval(["remesh", "--experiment", cfg.to_str().unwrap()]);
    assert_eq!(r.code, 2, "{}", r.stderr);
}
