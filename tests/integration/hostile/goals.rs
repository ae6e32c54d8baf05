//! Goals the simplifier cannot take: refused before it runs (meshoptimizer asserts, and an
//! assertion aborts the process with exit 134, on a target above its input).

use super::{assert_refused, scratch, write};
use crate::common::{lodeval, model, simplify};

#[test]
fn a_chain_that_does_not_get_coarser_is_refused() {
    let tmp = scratch("chain");
    let d = tmp.path();
    let spot = model("spot/spot_mtl.obj");
    for (chain, seen) in [
        ("0.25,0.5", "ratio 0.25 then ratio 0.5"),
        ("0.501,0.502", "ratio 0.501 then ratio 0.502"),
        ("0.5,0.5", "ratio 0.5 then ratio 0.5"),
    ] {
        for method in ["meshopt", "meshopt-update", "qem"] {
            let r = simplify(
                &spot,
                &d.join("lod.obj"),
                &["--method", method, "--chain", chain],
            );
            assert_refused(&r, chain, &[seen, "coarser"]);
        }
    }
    assert!(
        std::fs::read_dir(d).unwrap().next().is_none(),
        "a refused chain wrote files"
    );
}

#[test]
fn more_triangles_than_the_mesh_has_is_refused() {
    let tmp = scratch("triangles");
    let d = tmp.path();
    let spot = model("spot/spot_mtl.obj"); // 5 856 triangles
    for method in ["meshopt", "meshopt-update", "qem", "cluster"] {
        let r = simplify(
            &spot,
            &d.join("lod.obj"),
            &["--method", method, "--triangles", "5857"],
        );
        assert_refused(&r, method, &["5857", "5856"]);
    }
    // The whole mesh is a goal it can meet.
    let r = simplify(&spot, &d.join("lod.obj"), &["--triangles", "5856"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
}

#[test]
fn a_config_chain_that_does_not_get_coarser_names_the_file_and_line() {
    let tmp = scratch("config-chain");
    let d = tmp.path();
    let mesh = model("spot/spot_mtl.obj");
    for (generate, seen) in [
        ("ratios = [0.25, 0.5]", "ratio 0.25 then ratio 0.5"),
        ("ratios = [0.501, 0.502]", "ratio 0.501 then ratio 0.502"),
        ("errors = [0.05, 0.01]", "error 0.05 then error 0.01"),
    ] {
        let config = write(
            d,
            "bad.toml",
            &format!(
                "out = \"out\"\n[[asset]]\nname = \"spot\"\nmesh = \"{}\"\ngenerate = {{ method = \"meshopt\", {generate} }}\n",
                mesh.display()
            ),
        );
        let r = lodeval(["eval".as_ref(), config.as_os_str()]);
        assert_refused(&r, generate, &["bad.toml", "line 3", seen]);
        assert!(!d.join("out").exists(), "{generate}: the run wrote outputs");
    }
}
