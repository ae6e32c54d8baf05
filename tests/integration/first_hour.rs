//! A new user's first hour (issue 55): what a technical artist does right after the quick start —
//! render a LOD and diff it against its original, read a `.glb` chain, read the report — each
//! checked end to end through the CLI.

use crate::common::{lodeval, model, simplify};

/// A unit cube as OBJ text, plus `extra` lines (more vertices and faces, 1-based after the 8).
fn cube_obj(extra: &str) -> String {
    let mut s = String::new();
    for i in 0..8 {
        let (x, y, z) = ((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32);
        s.push_str(&format!("v {} {} {}\n", x - 0.5, y - 0.5, z - 0.5));
    }
    for f in [
        [1, 3, 4, 2],
        [5, 6, 8, 7],
        [1, 2, 6, 5],
        [3, 7, 8, 4],
        [1, 5, 7, 3],
        [2, 4, 8, 6],
    ] {
        s.push_str(&format!(
            "f {} {} {}\nf {} {} {}\n",
            f[0], f[1], f[2], f[0], f[2], f[3]
        ));
    }
    s + extra
}

#[test]
fn a_lod_and_its_original_get_nearly_the_same_bounding_sphere() {
    // The minimal enclosing sphere is set by a few extreme points, which a simplification keeps;
    // Ritter's approximation put the bunny's and its 50 % LOD's centres 28 % of a radius apart.
    let dir = tempfile::tempdir().unwrap();
    let src = model("bunny/stanford-bunny.obj");
    let lod = dir.path().join("b50.obj");
    let r = simplify(&src, &lod, &["--ratio", "0.5"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let opts = lodeval::mesh::LoadOptions::default();
    let a = lodeval::mesh::load(&src, &opts).unwrap().bounding_sphere();
    let b = lodeval::mesh::load(&lod, &opts).unwrap().bounding_sphere();
    let moved = a.center.distance(b.center) / a.radius;
    assert!(moved < 0.01, "centres {moved} of a radius apart");
    assert!((a.radius - b.radius).abs() / a.radius < 0.01);
}

#[test]
fn render_frames_like_the_original_and_diff_names_misframed_renders() {
    // The "original" has a speck far off to one side, so its sphere is much bigger than the
    // cube's; the "LOD" (the cube alone) framed by itself fills the frame instead.
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name);
    std::fs::write(
        p("original.obj"),
        cube_obj("v 3 0 0\nv 3.01 0 0\nv 3 0.01 0\nf 9 10 11\n"),
    )
    .unwrap();
    std::fs::write(p("lod.obj"), cube_obj("")).unwrap();
    let render = |mesh: &str, out: &str, extra: &[&str]| {
        let mut args = vec!["render", mesh, "-o", out, "--size", "96", "--view", "3"];
        args.extend_from_slice(extra);
        let r = lodeval(args.iter().map(|a| a.to_string()).collect::<Vec<_>>());
        assert_eq!(r.code, 0, "{}", r.stderr);
    };
    let s = |name: &str| p(name).to_str().unwrap().to_string();
    render(&s("original.obj"), &s("a.png"), &[]);
    render(&s("lod.obj"), &s("b.png"), &[]);
    render(
        &s("lod.obj"),
        &s("b-like.png"),
        &["--frame-like", &s("original.obj")],
    );
    let misframed = lodeval(["diff", &s("a.png"), &s("b.png")]);
    assert_eq!(misframed.code, 0, "{}", misframed.stderr);
    assert!(
        misframed.stderr.contains("framed differently")
            && misframed.stderr.contains("--frame-like"),
        "{}",
        misframed.stderr
    );
    let json = lodeval(["diff", &s("a.png"), &s("b.png"), "--json"]);
    assert!(json.stdout.contains("\"framing\""), "{}", json.stdout);
    let aligned = lodeval(["diff", &s("a.png"), &s("b-like.png")]);
    assert_eq!(aligned.code, 0, "{}", aligned.stderr);
    assert!(
        !aligned.stderr.contains("framed differently"),
        "{}",
        aligned.stderr
    );
    let flip = |out: &str| -> f64 { out.split_whitespace().nth(1).unwrap().parse().unwrap() };
    assert!(flip(&aligned.stdout) < 0.05 && flip(&misframed.stdout) > 0.1);
    // The frame-like mesh is an input too: no output may replace it.
    let r = lodeval([
        "render",
        &s("lod.obj"),
        "--frame-like",
        &s("original.obj"),
        "-o",
        &s("original.obj"),
    ]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(
        std::fs::read_to_string(p("original.obj"))
            .unwrap()
            .starts_with("v ")
    );
}

#[test]
fn diff_says_what_the_worst_pixel_value_is() {
    // SSIM's per-pixel map is 1 − SSIM (larger is worse); the line says so.
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
    let mut img = image::RgbImage::from_pixel(32, 32, image::Rgb([90, 90, 90]));
    img.save(&a).unwrap();
    img.put_pixel(10, 12, image::Rgb([250, 250, 250]));
    img.save(&b).unwrap();
    let r = lodeval([
        "diff",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--metric",
        "all",
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let ssim = r.stdout.lines().find(|l| l.starts_with("ssim ")).unwrap();
    assert!(
        ssim.contains("worst pixel") && ssim.contains("1 − SSIM"),
        "{ssim}"
    );
    let flip = r.stdout.lines().find(|l| l.starts_with("flip ")).unwrap();
    assert!(flip.contains("ꟻLIP error"), "{flip}");
}

#[test]
fn a_glb_chain_shows_its_levels_and_each_level_can_be_named() {
    let dir = tempfile::tempdir().unwrap();
    let src = model("bunny/bunny_odedstein_3k.obj");
    let chain = dir.path().join("chain.glb");
    let c = chain.to_str().unwrap();
    let level = |k: usize| format!("{c}#{k}");
    // `simplify -o chain.glb` says where each level switches in, as text and as JSON.
    let r = simplify(&src, &chain, &["--chain", "0.5,0.25"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(
        r.stdout.contains(&format!("{}  ", level(1))),
        "{}",
        r.stdout
    );
    assert_eq!(
        r.stdout.matches("switches in below").count(),
        2,
        "{}",
        r.stdout
    );
    assert!(r.stdout.contains("MSFT_screencoverage"), "{}", r.stdout);
    let r = simplify(&src, &chain, &["--chain", "0.5,0.25", "--json"]);
    let rows: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    for (k, row) in rows.as_array().unwrap().iter().enumerate() {
        assert_eq!(row["switch"]["level"], k + 1);
        assert!(row["switch"]["measured"]["diameter_px"].as_f64().unwrap() > 0.0);
    }
    // `info` lists every level with its triangles and coverage.
    let r = lodeval(["info", c]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(
        r.stdout.contains("MSFT_lod chain       3 levels"),
        "{}",
        r.stdout
    );
    for k in 0..3 {
        assert!(r.stdout.contains(&format!("  #{k} ")), "{}", r.stdout);
    }
    let r = lodeval(["info", c, "--json"]);
    let info: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    let levels = info["lod_levels"].as_array().unwrap();
    assert_eq!(levels.len(), 3);
    let triangles: Vec<u64> = levels
        .iter()
        .map(|l| l["triangles"].as_u64().unwrap())
        .collect();
    assert!(
        triangles[0] > triangles[1] && triangles[1] > triangles[2],
        "{triangles:?}"
    );
    let r = lodeval(["info", &level(2), "--json"]);
    let info: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    assert_eq!(info["triangles"].as_u64(), Some(triangles[2]));
    // A level that does not exist, and a '#' on a format without chains.
    let r = lodeval(["info", &level(3)]);
    assert_eq!(r.code, 2);
    assert!(
        r.stderr.contains("has no level #3") && r.stderr.contains("#2"),
        "{}",
        r.stderr
    );
    // `compare` refuses the whole chain as a LOD (it would score level 0, the original itself)
    // and scores a named level.
    let s = src.to_str().unwrap();
    let r = lodeval([
        "compare",
        s,
        c,
        "--views",
        "12",
        "--size",
        "64",
        "--no-distances",
    ]);
    assert_eq!(r.code, 2, "{}{}", r.stdout, r.stderr);
    assert!(
        r.stderr.contains("ambiguous") && r.stderr.contains(&level(1)),
        "{}",
        r.stderr
    );
    let r = lodeval([
        "compare",
        &level(0),
        &level(2),
        "--views",
        "12",
        "--size",
        "64",
        "--no-distances",
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    // `eval` names levels in `lods`, and refuses a chain named whole there.
    let config = |lod: &str| {
        format!(
            "out = \"out\"\n[render]\nsize = 64\n[distance]\nenabled = false\n[[asset]]\n\
             name = \"b\"\nmesh = \"chain.glb\"\nlods = [{{ mesh = \"{lod}\", name = \"l\" }}]\n"
        )
    };
    let cfg = dir.path().join("c.toml");
    std::fs::write(&cfg, config("chain.glb#2")).unwrap();
    let r = lodeval(["eval", cfg.to_str().unwrap(), "-q"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let lods = std::fs::read_to_string(dir.path().join("out/lods.csv")).unwrap();
    assert!(lods.contains(&format!("b,l,{},", triangles[2])), "{lods}");
    std::fs::write(&cfg, config("chain.glb")).unwrap();
    let r = lodeval(["eval", cfg.to_str().unwrap(), "-q"]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("ambiguous"), "{}", r.stderr);
}

/// The lines of the README's first code block after `marker`, comments removed.
fn readme_block(marker: &str) -> Vec<String> {
    let readme = std::fs::read_to_string(crate::common::root().join("README.md")).unwrap();
    let after = readme
        .split(marker)
        .nth(1)
        .expect("the marker is in the README");
    let fenced = after.split("```").nth(1).unwrap();
    // The fence's first line is its language tag (`sh`, or nothing).
    let block = fenced.split_once('\n').unwrap().1;
    block
        .lines()
        .map(|l| l.split(" #").next().unwrap().trim().to_string())
        .filter(|l| !l.is_empty())
        .collect()
}

/// A scratch folder standing in for the repository: the shipped models and configs are
/// reachable under the same relative paths, and whatever the commands write stays there.
fn scratch_checkout() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let root = crate::common::root();
    std::os::unix::fs::symlink(root.join("reference"), dir.path().join("reference")).unwrap();
    std::fs::create_dir(dir.path().join("configs")).unwrap();
    std::fs::copy(
        root.join("configs/demo.toml"),
        dir.path().join("configs/demo.toml"),
    )
    .unwrap();
    dir
}

/// Run one README command line as written: `lodeval …` or `cargo run --release -- …` become the
/// binary under test; the arguments are the line's words.
fn run_readme_line(line: &str, cwd: &std::path::Path) -> crate::common::Run {
    let args = line
        .strip_prefix("lodeval ")
        .or_else(|| line.strip_prefix("cargo run --release -- "))
        .unwrap_or_else(|| panic!("not a lodeval command: {line}"));
    crate::common::lodeval_in(cwd, args.split_whitespace())
}

#[test]
fn the_readme_quick_start_runs_as_written_and_writes_its_example_row() {
    let quick = readme_block("## Quick start");
    assert!(
        quick[0].starts_with("cargo run --release -- eval configs/demo.toml"),
        "{quick:?}"
    );
    let dir = scratch_checkout();
    let r = run_readme_line(&quick[0], dir.path());
    assert_eq!(r.code, 0, "{}{}", r.stdout, r.stderr);
    // The row the README reads is in the demo's distances.csv as printed.
    let row = readme_block("Reading one row of the demo")[0].clone();
    let csv = std::fs::read_to_string(dir.path().join("results/demo/distances.csv")).unwrap();
    assert!(
        csv.lines().any(|l| l == row),
        "README row {row} not in\n{csv}"
    );
    // And the table leads with the same quantity under the same name, the close-up columns
    // labelled with the render size.
    let header = r.stdout.lines().find(|l| l.starts_with("asset")).unwrap();
    let below = header.find("imperceptible_below_px").expect(header);
    assert!(below < header.find("flip").unwrap(), "{header}");
    assert!(
        header.contains("vdp@512px") && header.contains("jnd@512px"),
        "{header}"
    );
    // The report's first table answers the same question, before any asset's details.
    let report = std::fs::read_to_string(dir.path().join("results/demo/report.html")).unwrap();
    let glance = report.find("At a glance").expect("an at-a-glance table");
    assert!(glance < report.find("<h2 id=\"bunny\">").unwrap());
    assert!(report[glance..].contains("imperceptible below (px on screen)"));
    assert!(report.contains("VDP p worst at 512 px"));
}

#[test]
fn the_readme_first_steps_run_as_written() {
    let steps = readme_block("**The `lodeval` command.**");
    // `cargo install --path .` installs the package's binary, which is named `lodeval`: the
    // command every other line types (Cargo built that binary for this test).
    assert_eq!(steps[0], "cargo install --path .");
    let manifest = std::fs::read_to_string(crate::common::root().join("Cargo.toml")).unwrap();
    assert!(manifest.contains("name = \"lodeval\""));
    let dir = scratch_checkout();
    for line in &steps[1..] {
        let r = run_readme_line(line, dir.path());
        assert_eq!(r.code, 0, "{line}: {}{}", r.stdout, r.stderr);
        if line.starts_with("lodeval simplify") {
            assert_eq!(
                r.stdout.matches("switches in below").count(),
                2,
                "{}",
                r.stdout
            );
        }
        if line.starts_with("lodeval info bunny-lods.glb") {
            assert!(
                r.stdout.contains("MSFT_lod chain       3 levels"),
                "{}",
                r.stdout
            );
        }
        if line.starts_with("lodeval compare") {
            assert!(r.stdout.contains("imperceptible"), "{}", r.stdout);
        }
    }
}

#[test]
fn levels_of_one_chain_are_different_originals_to_the_render_cache() {
    // Two assets whose originals are levels 0 and 1 of one file: every file they read is the
    // same, so the cache must key on the level too, or the second asset's reference frames are
    // the first's.
    let dir = tempfile::tempdir().unwrap();
    let src = model("bunny/bunny_odedstein_3k.obj");
    let r = simplify(&src, &dir.path().join("chain.glb"), &["--chain", "0.5,0.1"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let config = "[render]\nsize = 64\n[distance]\nenabled = false\n[images]\nheatmaps = \"none\"\n\
                  contact_sheets = false\n[[asset]]\nname = \"a\"\nmesh = \"chain.glb#0\"\n\
                  lods = [{ mesh = \"chain.glb#2\", name = \"l\" }]\n[[asset]]\nname = \"b\"\n\
                  mesh = \"chain.glb#1\"\nlods = [{ mesh = \"chain.glb#2\", name = \"l\" }]\n";
    let cfg = dir.path().join("c.toml");
    std::fs::write(&cfg, format!("out = \"plain\"\n{config}")).unwrap();
    let r = lodeval(["eval", cfg.to_str().unwrap(), "-q"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    std::fs::write(&cfg, format!("out = \"cached\"\n{config}")).unwrap();
    let cache = dir.path().join("cache");
    let r = lodeval([
        "eval",
        cfg.to_str().unwrap(),
        "-q",
        "--cache",
        cache.to_str().unwrap(),
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let read = |d: &str| std::fs::read_to_string(dir.path().join(d).join("metrics.csv")).unwrap();
    assert_eq!(read("plain"), read("cached"));
}

#[test]
fn a_broken_msft_lod_list_is_named_when_a_level_is_asked_for_and_ignored_otherwise() {
    let dir = tempfile::tempdir().unwrap();
    let chain = dir.path().join("chain.gltf");
    let r = simplify(
        &model("bunny/bunny_odedstein_3k.obj"),
        &chain,
        &["--chain", "0.5"],
    );
    assert_eq!(r.code, 0, "{}", r.stderr);
    let text = std::fs::read_to_string(&chain).unwrap();
    let mut doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    doc["nodes"][0]["extensions"]["MSFT_lod"]["ids"] = serde_json::json!([99]);
    std::fs::write(&chain, serde_json::to_string(&doc).unwrap()).unwrap();
    let c = chain.to_str().unwrap();
    let r = lodeval(["info", c]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(r.stdout.contains("the chain is ignored"), "{}", r.stdout);
    let r = lodeval(["info", &format!("{c}#1")]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(
        r.stderr.contains("MSFT_lod") && r.stderr.contains("not in the file"),
        "{}",
        r.stderr
    );
}
