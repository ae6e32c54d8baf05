//! The command line end to end: exit codes, output shapes, and usage errors.

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
        roles.contains(&"baseColorTexture".to_string())
            && roles.contains(&"normalTexture".to_string()),
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

#[test]
fn readme_main_job_is_the_demo_config_and_it_plans_what_the_readme_says() {
    // The quick start's first command runs configs/demo.toml; the config must load (models
    // shipped, keys valid) and plan what the README describes: bunny and Spot × five LODs,
    // the avocado × two.
    let readme = std::fs::read_to_string(crate::common::root().join("README.md")).unwrap();
    assert!(readme.contains("cargo run --release -- eval configs/demo.toml"));
    let plan = lodeval::eval::Plan::load(&crate::common::root().join("configs/demo.toml")).unwrap();
    let cases = plan.case_ids();
    assert_eq!(cases.len(), 12, "{cases:?}");
    assert!(
        cases.iter().any(|c| c == "avocado/meshopt-r10"),
        "{cases:?}"
    );
    for a in &plan.assets {
        assert!(a.mesh.exists(), "{}", a.mesh.display());
    }
    assert_eq!(plan.config.render.rig.0.directions().len(), 20);
    assert_eq!(plan.config.render.size.0, 512);
}

#[test]
fn diff_reports_every_metric_as_json_and_writes_maps() {
    let dir = tempfile::tempdir().unwrap();
    let o = |f: &str| crate::common::root().join("reference/oracles/flip").join(f);
    let (r, t) = (o("lines_70_ref.png"), o("lines_70_test.png"));
    let map = dir.path().join("err.png");
    let run = lodeval([
        "diff".as_ref(),
        r.as_os_str(),
        t.as_os_str(),
        "--metric".as_ref(),
        "all".as_ref(),
        "--json".as_ref(),
        "--map".as_ref(),
        map.as_os_str(),
        "--ppd".as_ref(),
        "40".as_ref(),
    ]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let v: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    let names: Vec<&str> = v
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["metric"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        [
            "flip",
            "ssim",
            "msssim",
            "psnr",
            "psnr_luminance",
            "mse",
            "vdp"
        ]
    );
    assert!(v[6]["jnd"].as_f64().unwrap() > 0.0 && v[6]["value"].as_f64().unwrap() <= 1.0);
    for m in v.as_array().unwrap() {
        assert_eq!(m["ppd"], 40.0);
        assert_eq!(
            (m["width"].as_u64(), m["height"].as_u64()),
            (Some(70), Some(70))
        );
    }
    assert!(v[0]["percentiles"]["p95"].as_f64().unwrap() > 0.0);
    // 70×70 is too small for MS-SSIM's five scales: no value, a note, and still exit 0.
    assert!(v[2]["value"].is_null() && v[2]["note"].as_str().unwrap().contains("176x176"));
    for m in ["flip", "ssim", "vdp"] {
        assert!(dir.path().join(format!("err-{m}.png")).exists(), "{m}");
    }
}

#[test]
fn diff_rejects_bad_requests_with_exit_2() {
    let o = |f: &str| crate::common::root().join("reference/oracles/flip").join(f);
    let (a, b) = (o("lines_70_ref.png"), o("noise_64x48_ref.png"));
    let r = lodeval(["diff".as_ref(), a.as_os_str(), b.as_os_str()]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(
        r.stderr.contains("noise_64x48_ref.png") && r.stderr.contains("64x48"),
        "{}",
        r.stderr
    );
    let r = lodeval([
        "diff".as_ref(),
        a.as_os_str(),
        a.as_os_str(),
        "--metric".as_ref(),
        "nope".as_ref(),
    ]);
    // clap names the flag, the value and the metrics there are.
    assert!(
        r.code == 2
            && r.stderr.contains("--metric")
            && r.stderr.contains("'nope'")
            && r.stderr
                .contains("flip, ssim, msssim, psnr, psnr-luminance, mse, vdp, all"),
        "{}",
        r.stderr
    );
    let r = lodeval(["diff".as_ref(), a.as_os_str(), "missing.png".as_ref()]);
    assert!(
        r.code == 2 && r.stderr.contains("missing.png"),
        "{}",
        r.stderr
    );
    // SSIM needs an 11×11 window: a 3×2 pair is a usage error, FLIP is fine.
    let (t1, t2) = (o("tiny_3x2_ref.png"), o("tiny_3x2_test.png"));
    let r = lodeval([
        "diff".as_ref(),
        t1.as_os_str(),
        t2.as_os_str(),
        "--metric".as_ref(),
        "ssim".as_ref(),
    ]);
    assert!(r.code == 2 && r.stderr.contains("11x11"), "{}", r.stderr);
    assert_eq!(
        lodeval(["diff".as_ref(), t1.as_os_str(), t2.as_os_str()]).code,
        0
    );
}

#[test]
fn compare_scores_what_eval_scores_for_the_same_views() {
    let dir = tempfile::tempdir().unwrap();
    let original = model("bunny/bunny_odedstein_3k.obj");
    let lod = dir.path().join("lod.obj");
    let r = crate::common::simplify(&original, &lod, &["--ratio", "0.3"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let r = lodeval([
        "compare",
        original.to_str().unwrap(),
        lod.to_str().unwrap(),
        "--views",
        "12",
        "--size",
        "96",
        "--no-distances",
        "--json",
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let j: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    let views = j["views"].as_array().unwrap();
    assert_eq!(views.iter().filter(|v| v["metric"] == "flip").count(), 12);
    // The same plan as a config file: the same values, view by view.
    let cfg = dir.path().join("c.toml");
    std::fs::write(
        &cfg,
        format!(
            "out = \"out\"\n[render]\nsize = 96\nrig = \"icosahedron\"\n[distance]\nenabled = false\n\
             [images]\nheatmaps = \"none\"\ncontact_sheets = false\n[[asset]]\nname = \"a\"\nmesh = \"{}\"\n\
             lods = [{{ mesh = \"{}\", name = \"l\" }}]\n",
            original.display(),
            lod.display()
        ),
    )
    .unwrap();
    let r = lodeval(["eval", cfg.to_str().unwrap(), "-q"]);
    assert!(r.code == 0 || r.code == 1, "{}", r.stderr);
    let csv = std::fs::read_to_string(dir.path().join("out/metrics.csv")).unwrap();
    let mut checked = 0;
    for line in csv.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let (view, metric, value): (u64, &str, f64) =
            (f[3].parse().unwrap(), f[4], f[5].parse().unwrap());
        let mine = views
            .iter()
            .find(|v| v["view"].as_u64() == Some(view) && v["metric"] == metric)
            .unwrap_or_else(|| panic!("{metric} of view {view} missing"))["value"]
            .as_f64()
            .unwrap();
        assert_eq!(mine, value, "{metric}, view {view}");
        checked += 1;
    }
    assert!(checked >= 12 * 4, "{checked}");
    // The text table names every view, the mean and the worst.
    let r = lodeval([
        "compare",
        original.to_str().unwrap(),
        lod.to_str().unwrap(),
        "--views",
        "3",
        "--size",
        "64",
        "--no-distances",
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(
        r.stdout.contains(" mean ") && r.stdout.contains("worst"),
        "{}",
        r.stdout
    );
    // A missing mesh is an input error naming the argument, not a config nobody wrote.
    let r = lodeval(["compare", original.to_str().unwrap(), "/nonexistent/x.obj"]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(
        r.stderr.contains("/nonexistent/x.obj")
            && r.stderr.contains("LOD is not there")
            && !r.stderr.contains("<compare>"),
        "{}",
        r.stderr
    );
    // Any file name works: the plan is built as a value, not as TOML text.
    let odd = dir.path().join("a \"quoted\" name.obj");
    std::fs::copy(&lod, &odd).unwrap();
    let r = lodeval([
        "compare",
        original.to_str().unwrap(),
        odd.to_str().unwrap(),
        "--views",
        "1",
        "--size",
        "32",
        "--no-distances",
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(r.stdout.contains("view"), "{}", r.stdout);
}

#[test]
fn diff_gates_grade_exit_codes_and_report_the_worst_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let o = |f: &str| crate::common::root().join("reference/oracles/flip").join(f);
    let (r, t) = (o("lines_70_ref.png"), o("lines_70_test.png"));
    let (r, t) = (r.to_str().unwrap(), t.to_str().unwrap());
    let run = |extra: &[&str]| {
        let mut args = vec!["diff", r, t, "--ppd", "40"];
        args.extend_from_slice(extra);
        lodeval(args)
    };
    // The pair's mean FLIP is about 0.1: a loose limit passes, a tight one fails with exit 1.
    let pass = run(&["--fail", "0.9"]);
    assert_eq!(pass.code, 0, "{}", pass.stderr);
    assert!(pass.stdout.contains("worst pixel ("), "{}", pass.stdout);
    let fail = run(&["--fail", "0.001"]);
    assert_eq!(fail.code, 1, "{}", fail.stderr);
    assert!(
        fail.stderr.contains("above the fail limit 0.001"),
        "{}",
        fail.stderr
    );
    // A warning is exit 0 with a line.
    let warn = run(&["--warn", "0.001"]);
    assert_eq!(warn.code, 0, "{}", warn.stderr);
    assert!(
        warn.stderr.contains("warning:") && warn.stderr.contains("warn limit"),
        "{}",
        warn.stderr
    );
    // The share of pixels over a per-pixel threshold.
    let share = run(&["--fail-percent", "0.5", "--fail-pixel", "0.05", "--json"]);
    assert_eq!(share.code, 1, "{}", share.stderr);
    let v: serde_json::Value = serde_json::from_str(&share.stdout).unwrap();
    let s = v[0]["share_over"].as_f64().unwrap();
    assert!(s > 0.005 && s <= 1.0, "{s}");
    let w = &v[0]["worst_pixel"];
    assert!(
        w["x"].as_u64().unwrap() < 70 && w["y"].as_u64().unwrap() < 70,
        "{w}"
    );
    assert!(
        (w["value"].as_f64().unwrap() - v[0]["percentiles"]["max"].as_f64().unwrap()).abs() < 1e-6
    );
    // PSNR gates the other way: below the limit fails. Past its 100 dB ceiling a limit could
    // only ever fail, and is refused.
    assert_eq!(run(&["--metric", "psnr", "--fail", "99"]).code, 1);
    let never = run(&["--metric", "psnr", "--fail", "200"]);
    assert_eq!(never.code, 2, "{}", never.stderr);
    assert!(never.stderr.contains("always fail"), "{}", never.stderr);
    assert_eq!(run(&["--metric", "psnr", "--fail", "1"]).code, 0);
    // Percentage gates need a metric with a per-pixel map.
    let bad = run(&[
        "--metric",
        "psnr",
        "--fail-percent",
        "1",
        "--fail-pixel",
        "0.1",
    ]);
    assert_eq!(bad.code, 2, "{}", bad.stderr);
    // A gate must be a finite number.
    for (flag, v) in [("--fail", "nan"), ("--fail-pixel", "inf")] {
        let bad = run(&[flag, v, "--fail-percent", "1"]);
        assert_eq!(bad.code, 2, "{}", bad.stderr);
        assert!(
            bad.stderr.contains(flag) && bad.stderr.contains("finite"),
            "{}",
            bad.stderr
        );
    }
    // Several test images in one call, with CSV: the identical one passes, the other fails.
    let csv = dir.path().join("d.csv");
    let many = lodeval([
        "diff",
        r,
        r,
        t,
        "--ppd",
        "40",
        "--fail",
        "0.01",
        "--csv",
        csv.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(many.code, 1, "{}", many.stderr);
    let v: serde_json::Value = serde_json::from_str(&many.stdout).unwrap();
    assert_eq!(v.as_array().unwrap().len(), 2);
    assert_eq!(
        (v[0]["verdict"].as_str(), v[1]["verdict"].as_str()),
        (Some("pass"), Some("fail"))
    );
    let table = std::fs::read_to_string(&csv).unwrap();
    assert!(
        table.starts_with(
            "reference,test,metric,value,jnd,worst_x,worst_y,worst_value,share_over,verdict"
        ),
        "{table}"
    );
    assert_eq!(table.lines().count(), 3, "{table}");
    assert!(table.lines().nth(2).unwrap().ends_with(",fail"), "{table}");
}

#[test]
fn completions_man_pages_and_help_with_examples_and_exit_codes() {
    let dir = tempfile::tempdir().unwrap();
    for shell in ["bash", "zsh", "fish"] {
        let r = lodeval(["completions", shell]);
        assert_eq!(r.code, 0, "{}", r.stderr);
        assert!(
            r.stdout.contains("remesh") && r.stdout.contains("compare"),
            "{shell}"
        );
    }
    let r = lodeval(["man"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(
        r.stdout.starts_with(".ie") && r.stdout.contains(".TH lodeval 1"),
        "{}",
        &r.stdout[..200]
    );
    let r = lodeval(["man", "--out-dir", dir.path().to_str().unwrap()]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    for page in [
        "lodeval.1",
        "lodeval-eval.1",
        "lodeval-diff.1",
        "lodeval-remesh.1",
    ] {
        let text = std::fs::read_to_string(dir.path().join(page)).unwrap();
        assert!(text.contains(".TH"), "{page}");
    }
    // Every command's --help has an example and its exit codes.
    for cmd in [
        "eval",
        "golden",
        "simplify",
        "optimize",
        "render",
        "diff",
        "compare",
        "info",
        "geometry",
        "bench",
        "merge",
        "calibrate",
        "remesh",
        "completions",
        "man",
    ] {
        let r = lodeval([cmd, "--help"]);
        assert_eq!(r.code, 0, "{cmd}: {}", r.stderr);
        assert!(
            r.stdout.contains("Example:") && r.stdout.contains("Exit codes: 0"),
            "{cmd}: {}",
            r.stdout
        );
    } // The top-level help and the README say how to get the `lodeval` command they type.
    let r = lodeval(["--help"]);
    assert!(r.stdout.contains("cargo install --path ."), "{}", r.stdout);
    let readme = std::fs::read_to_string(crate::common::root().join("README.md")).unwrap();
    assert!(
        readme.contains("`cargo install --path .`") && readme.contains("target/release/lodeval"),
        "the README does not say how to get the lodeval command"
    );
}

#[test]
fn progress_in_a_log_is_a_line_every_few_seconds_and_quiet_silences_it() {
    // Standard error is a pipe here, as in CI: lines, no bar. LODEVAL_PROGRESS_EVERY_MS makes
    // them come at once for a short run.
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("p.toml");
    std::fs::write(
        &cfg,
        format!(
            "out = \"out\"\nmetrics = [\"flip\"]\n[render]\nsize = 48\nrig = \"icosahedron\"\n\
             [distance]\nenabled = false\n[images]\nheatmaps = \"none\"\ncontact_sheets = false\n\
             [[asset]]\nname = \"bunny3k\"\nmesh = \"{}\"\ngenerate = {{ method = \"meshopt\", ratios = [0.5] }}\n",
            model("bunny/bunny_odedstein_3k.obj").display()
        ),
    )
    .unwrap();
    let every = [("LODEVAL_PROGRESS_EVERY_MS", Some("0"))];
    let r = crate::common::lodeval_env(["eval", cfg.to_str().unwrap()], &every);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let err = &r.stderr;
    let lines: Vec<&str> = err.lines().filter(|l| l.contains(" renders")).collect();
    assert!(lines.len() >= 2, "{err}");
    // `[hh:mm:ss] done/total renders  message`, ending at 12/12.
    assert!(lines.iter().all(|l| l.starts_with("[00:00:")), "{err}");
    assert!(lines.last().unwrap().contains("12/12 renders"), "{err}");
    assert!(
        !err.contains('\r') && !err.contains("\u{1b}["),
        "no terminal control codes: {err}"
    );
    let quiet = crate::common::lodeval_env(["eval", cfg.to_str().unwrap(), "--quiet"], &every);
    assert!(!quiet.stderr.contains(" renders"));
}

#[test]
fn diff_on_exr_images_is_hdr_flip_with_the_automatic_exposures() {
    let o = |f: &str| crate::common::root().join("reference/oracles/hdr").join(f);
    let (r, t) = (o("room_window_ref.exr"), o("room_window_test.exr"));
    let run = lodeval(["diff", r.to_str().unwrap(), t.to_str().unwrap(), "--json"]);
    assert_eq!(run.code, 0, "{}", run.stderr);
    let v: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    let e = &v[0]["exposures"];
    assert_eq!(e["count"].as_u64(), Some(11), "{v}");
    assert!(
        (v[0]["value"].as_f64().unwrap() - 0.5470386).abs() < 1e-5,
        "{v}"
    );
    // Given exposures are used as given; a range that runs backwards is refused.
    let run = lodeval([
        "diff",
        r.to_str().unwrap(),
        t.to_str().unwrap(),
        "--json",
        "--start-exposure",
        "-1",
        "--stop-exposure",
        "1",
        "--num-exposures",
        "2",
    ]);
    let v: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    assert_eq!(v[0]["exposures"]["start"].as_f64(), Some(-1.0));
    let run = lodeval([
        "diff",
        r.to_str().unwrap(),
        t.to_str().unwrap(),
        "--start-exposure",
        "1",
        "--stop-exposure",
        "-1",
        "--num-exposures",
        "2",
    ]);
    assert_eq!(run.code, 2, "{}", run.stderr);
}
