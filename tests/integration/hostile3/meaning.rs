//! Values outside their meaning were accepted: HDR-FLIP with exposures of ±1e30 scored two
//! different images 0 and the gate passed; `diff --fail 2` on FLIP (never above 1), SSIM limits
//! of 1.5 or −1, percentages of 101 or −1 made gates that can never fail (or always do). Flags
//! that do nothing here (`--start-exposure` on PNG images, `--camera` and `--criterion` outside
//! Williams) were ignored without a word.

use super::{assert_refused, run, s, scratch, spot_copy};

fn flip_pair() -> (std::path::PathBuf, std::path::PathBuf) {
    let o = |f: &str| crate::common::root().join("reference/oracles/flip").join(f);
    (o("lines_70_ref.png"), o("lines_70_test.png"))
}

#[test]
fn gates_that_cannot_mean_anything_are_refused() {
    let (a, b) = flip_pair();
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["--fail", "2"],
            &["--fail 2", "flip lies in [0, 1]", "never fail"],
        ),
        (&["--fail", "1"], &["--fail 1", "never fail"]),
        (&["--warn=-0.5"], &["--warn -0.5", "always fail"]),
        (
            &["--metric", "ssim", "--fail", "1.5"],
            &["--fail 1.5", "ssim", "always fail"],
        ),
        (
            &["--metric", "ssim", "--fail=-1"],
            &["--fail -1", "ssim", "never fail"],
        ),
        (
            &["--metric", "psnr", "--fail", "0"],
            &["--fail 0", "psnr", "never fail"],
        ),
        (
            &["--fail-percent", "101", "--fail-pixel", "0.1"],
            &["--fail-percent 101"],
        ),
        (
            &["--fail-percent=-1", "--fail-pixel", "0.1"],
            &["--fail-percent -1"],
        ),
        (
            &["--fail-percent", "5", "--fail-pixel", "1"],
            &["--fail-pixel 1"],
        ),
    ];
    for (flags, words) in cases {
        let mut args = vec!["diff", s(&a), s(&b)];
        args.extend_from_slice(flags);
        assert_refused(&run(&args), &flags.join(" "), words);
    }
    // Meaningful limits still work: FLIP 0.01 fails these lines, 0.99 passes.
    assert_eq!(run(&["diff", s(&a), s(&b), "--fail", "0.01"]).code, 1);
    assert_eq!(run(&["diff", s(&a), s(&b), "--fail", "0.99"]).code, 0);
}

#[test]
fn hdr_flip_exposures_beyond_any_range_are_refused_and_useless_flags_warned() {
    let tmp = scratch("r3-meaning-hdr");
    let d = tmp.path();
    let (a, b) = (d.join("a.exr"), d.join("b.exr"));
    let img = |v: f32| image::Rgb32FImage::from_fn(16, 16, |x, _| image::Rgb([v * x as f32; 3]));
    image::DynamicImage::ImageRgb32F(img(0.1)).save(&a).unwrap();
    image::DynamicImage::ImageRgb32F(img(0.3)).save(&b).unwrap();
    let r = run(&[
        "diff",
        s(&a),
        s(&b),
        "--start-exposure",
        "-1e30",
        "--stop-exposure",
        "1e30",
        "--num-exposures",
        "4",
        "--fail",
        "0.05",
    ]);
    assert_refused(&r, "±1e30 stops", &["-1e30", "stops"]);
    let r = run(&[
        "diff",
        s(&a),
        s(&b),
        "--start-exposure",
        "-2",
        "--stop-exposure",
        "2",
        "--num-exposures",
        "4",
        "--fail",
        "0.05",
    ]);
    assert_eq!(r.code, 1, "different images must fail: {}", r.stderr);
    // On PNG images the exposures do nothing: said.
    let (p, q) = flip_pair();
    let r = run(&[
        "diff",
        s(&p),
        s(&q),
        "--start-exposure",
        "-2",
        "--stop-exposure",
        "2",
        "--num-exposures",
        "4",
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(
        r.stderr.contains("warning") && r.stderr.contains("do nothing here"),
        "{}",
        r.stderr
    );
}

#[test]
fn williams_only_flags_on_other_methods_are_warned() {
    let tmp = scratch("r3-meaning-flags");
    let d = tmp.path();
    let spot = spot_copy(d);
    let r = run(&[
        "simplify",
        s(&spot),
        "-o",
        s(&d.join("l.obj")),
        "--ratio",
        "0.5",
        "--criterion",
        "object-space",
        "--camera",
        "0,0,5",
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert!(
        r.stderr.contains("--criterion") && r.stderr.contains("--camera"),
        "{}",
        r.stderr
    );
    assert!(r.stderr.contains("do nothing"), "{}", r.stderr);
}
