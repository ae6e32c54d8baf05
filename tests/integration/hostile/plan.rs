//! A config the gate cannot judge is refused before the first render: it used to render and score
//! everything, write CSVs and heat maps, and only then exit 2, without `junit.xml`.

use super::{assert_refused, scratch, write};
use crate::common::{lodeval, model};

fn config(dir: &std::path::Path, body: &str) -> std::path::PathBuf {
    let mesh = model("bunny/bunny_odedstein_3k.obj");
    write(
        dir,
        "gate.toml",
        &format!(
            "out = \"out\"\n{body}\n[[asset]]\nname = \"bunny\"\nmesh = \"{}\"\ngenerate = {{ method = \"meshopt\", ratios = [0.5]{} }}\n",
            mesh.display(),
            if body.contains("switch") {
                ", switch_m = [2.0]"
            } else {
                ""
            }
        ),
    )
}

#[test]
fn a_threshold_on_a_metric_not_computed_fails_before_rendering() {
    let tmp = scratch("plan-metric");
    let d = tmp.path();
    for (body, words) in [
        (
            "metrics = [\"flip\"]\n[thresholds]\nssim_min = 0.9",
            &["gate.toml", "ssim_min", "'ssim'"][..],
        ),
        (
            "metrics = [\"ssim\"]\n[thresholds]\nvdp_probability = 0.5",
            &["vdp_probability", "'vdp'"][..],
        ),
        (
            "metrics = [\"psnr\"]\n[thresholds]\nflip_p95 = 0.2",
            &["flip_p95", "'flip'"][..],
        ),
    ] {
        let r = lodeval(["eval".as_ref(), config(d, body).as_os_str()]);
        assert_refused(&r, body, words);
        assert!(!d.join("out").exists(), "{body}: rendered before refusing");
    }
}

#[test]
fn switch_distances_without_the_distance_search_fail_before_rendering() {
    let tmp = scratch("plan-switch");
    let d = tmp.path();
    let body = "metrics = [\"flip\"]\n# switch\n[distance]\nenabled = false";
    let r = lodeval(["eval".as_ref(), config(d, body).as_os_str()]);
    assert_refused(
        &r,
        body,
        &["gate.toml", "switch_m", "distances are disabled"],
    );
    assert!(!d.join("out").exists(), "rendered before refusing");
}

#[test]
fn more_switch_distances_than_lods_is_refused() {
    let tmp = scratch("plan-extra-switch");
    let d = tmp.path();
    let mesh = model("bunny/bunny_odedstein_3k.obj");
    let path = write(
        d,
        "extra.toml",
        &format!(
            "out = \"out\"\n[[asset]]\nname = \"bunny\"\nmesh = \"{}\"\ngenerate = {{ method = \"meshopt\", ratios = [0.5], switch_m = [2.0, 4.0] }}\n",
            mesh.display()
        ),
    );
    let r = lodeval(["eval".as_ref(), path.as_os_str()]);
    assert_refused(
        &r,
        "extra switch_m",
        &["extra.toml", "2 switch_m values for 1 LODs"],
    );
    assert!(!d.join("out").exists());
}
