//! Sizes, counts and values a user can give, far out of range: `--threads 100000` hung, huge
//! view counts, pixels per degree, sample counts and benchmark meshes aborted on allocation, a
//! contact sheet of 400 views at 16 384² allocated without a check, and `--ppd 1e-30` gave FLIP
//! NaN. Each is refused at once with the bound (`src/limits.rs`) named, in a flag or in a config
//! key with its line, before anything is rendered.

use super::{assert_refused, scratch, write};
use crate::common::{lodeval_within, model, root};

const LIMITS: &str = "outside lodeval's limits";

/// `lodeval ARGS` is refused within 20 s, naming the limit and `words`.
#[track_caller]
fn refused(args: &[&str], words: &[&str]) {
    let r = lodeval_within(20, args);
    assert_refused(&r, &args.join(" "), words);
    assert!(r.stderr.contains(LIMITS), "{args:?}: {}", r.stderr);
}

#[test]
fn out_of_range_flags_are_refused_with_their_bound() {
    let spot = model("spot/spot_mtl.obj");
    let spot = spot.to_str().unwrap();
    let png = root().join("reference/oracles/flip/black_white_16_ref.png");
    let png = png.to_str().unwrap();
    refused(
        &["--threads", "100000", "info", spot],
        &["--threads", "1024"],
    );
    refused(&["info", spot, "--threads", "0"], &["worker threads"]);
    refused(
        &[
            "render",
            spot,
            "-o",
            "/nonexistent/x.png",
            "--rig",
            "fibonacci:4000000000",
        ],
        &["4000000000", "views"],
    );
    refused(
        &["diff", png, png, "--ppd", "1e30"],
        &["1e30", "pixels per degree"],
    );
    refused(
        &["diff", png, png, "--ppd", "1e-30"],
        &["1e-30", "pixels per degree"],
    );
    refused(&["diff", png, png, "--ppd", "NaN"], &["pixels per degree"]);
    refused(
        &["diff", png, png, "--distance-m", "1e-9"],
        &["the display", "pixels per degree"],
    );
    refused(
        &["geometry", spot, spot, "--samples", "2000000000"],
        &["face samples"],
    );
    refused(
        &["bench", "raster", "--rings", "4000000000"],
        &["triangles"],
    );
    refused(
        &["bench", "simplify", "--bumpy", "40"],
        &["--bumpy", "triangles"],
    );
    refused(&["bench", "raster", "--views", "0"], &["views"]);
    refused(
        &[
            "optimize",
            spot,
            spot,
            "-o",
            "/nonexistent/x.obj",
            "--evals",
            "0",
        ],
        &["evaluations"],
    );
    refused(
        &[
            "render",
            spot,
            "-o",
            "/nonexistent/x.png",
            "--size",
            "100000",
        ],
        &["pixels"],
    );
    refused(
        &["calibrate", "modelfest", "--ppd", "0.5"],
        &["pixels per degree"],
    );
    // Jobs whose estimated memory is beyond the stated cap (src/limits.rs MEMORY_GIB).
    refused(
        &[
            "optimize",
            spot,
            spot,
            "-o",
            "/nonexistent/x.obj",
            "--views",
            "10000",
            "--size",
            "4096",
        ],
        &["10000 views", "GiB of memory"],
    );
}

#[test]
fn a_contact_sheet_too_large_to_hold_is_refused_before_rendering() {
    let tmp = scratch("bounds-sheet");
    let spot = model("spot/spot_mtl.obj");
    let out = tmp.path().join("sheet.png");
    let r = lodeval_within(
        20,
        [
            "render".as_ref(),
            spot.as_os_str(),
            "--sheet".as_ref(),
            "-o".as_ref(),
            out.as_os_str(),
            "--rig".as_ref(),
            "fibonacci:400".as_ref(),
            "--size".as_ref(),
            "16384".as_ref(),
        ],
    );
    assert_refused(
        &r,
        "render --sheet",
        &["contact sheet", "400 images", LIMITS],
    );
    assert!(!out.exists());
}

#[test]
fn out_of_range_config_values_name_the_key_and_line() {
    let tmp = scratch("bounds-config");
    let d = tmp.path();
    let mesh = model("spot/spot_mtl.obj");
    for (section, seen) in [
        (
            "[render]\nsize = 4096\n[images]\nsheet_views = 100\n",
            "sheet_views",
        ),
        ("[render]\nrig = \"fibonacci:4000000000\"\n", "views"),
        ("[viewing]\nppd = 1e-30\n", "pixels per degree"),
        ("[viewing]\ndistance_m = 1e-12\n", "pixels per degree"),
        ("geometry_samples = 2000000000\n", "geometry_samples"),
        ("[images]\nsheet_views = 0\n", "sheet_views"),
        ("[distance]\nviews = 100000\n", "views"),
        ("[render]\nsize = 8192\n", "GiB of memory"),
        (
            "[render]\nsize = 2048\nrig = \"fibonacci:2000\"\n",
            "2000 views",
        ),
    ] {
        let config = write(
            d,
            "bad.toml",
            &format!(
                "out = \"out\"\n{section}[[asset]]\nname = \"spot\"\nmesh = \"{}\"\ngenerate = {{ method = \"meshopt\", ratios = [0.5] }}\n",
                mesh.display()
            ),
        );
        let r = lodeval_within(20, ["eval".as_ref(), config.as_os_str()]);
        assert_refused(&r, section, &["bad.toml", "line", seen, LIMITS]);
        assert!(!d.join("out").exists(), "{section}: the run wrote outputs");
    }
}
