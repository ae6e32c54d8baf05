//! A bound is not a measured distance. A LOD identical to its original failed the `switch_m`
//! check with "visible until 13.02 m", which was the search's largest size, not a measurement.
//! Now the search takes in the size at the switch distance, an identical LOD passes, every row
//! says whether its distance is measured or which bound it is (`bound` column), and the console
//! and report show bounds as `≤`/`≥`.

use super::{scratch, write};
use crate::common::{lodeval_within, model};

/// A config scoring Spot against itself (named `same`) with the given `switch_m` and extra keys.
fn identical(dir: &std::path::Path, switch_m: f64, extra: &str) -> std::path::PathBuf {
    write(
        dir,
        "same.toml",
        &format!(
            "out = \"out\"\nmetrics = [\"flip\", \"vdp\"]\n[render]\nsize = 48\nrig = \"icosahedron\"\n\
             [images]\nheatmaps = \"none\"\ncontact_sheets = false\n\
             [distance]\nviews = 1\nmax_diameter_px = 16\n{extra}\n\
             [[asset]]\nname = \"spot\"\nmesh = \"{m}\"\n\
             lods = [{{ mesh = \"{m}\", name = \"same\", switch_m = {switch_m} }}]\n",
            m = model("spot/spot_mtl.obj").display()
        ),
    )
}

/// The `distances.csv` row of `criterion`, as (distance, diameter, bound).
fn row(out: &std::path::Path, criterion: &str) -> (f64, f64, String) {
    let text = std::fs::read_to_string(out.join("distances.csv")).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let line = text
        .lines()
        .find(|l| l.contains(&format!(",{criterion}")))
        .unwrap_or_else(|| panic!("no {criterion} row: {text}"));
    let f: Vec<&str> = line.split(',').collect();
    (
        f[col("imperceptible_beyond_m")].parse().unwrap(),
        f[col("diameter_px")].parse().unwrap(),
        f[col("bound")].to_string(),
    )
}

#[test]
fn an_identical_lod_passes_its_switch_distance() {
    let tmp = scratch("distances-identical");
    let d = tmp.path();
    // Spot's sphere (radius ≈ 0.98) at 150 m is about 50 px across: beyond max_diameter_px = 16,
    // so the old search stopped at 16 px (≈ 470 m) and called that "visible until".
    let cfg = identical(d, 150.0, "");
    let r = lodeval_within(120, ["eval".as_ref(), cfg.as_os_str()]);
    assert_eq!(r.code, 0, "{}{}", r.stdout, r.stderr);
    assert!(!r.stderr.contains("visible until"), "{}", r.stderr);
    let (dist, px, bound) = row(&d.join("out"), "vdp_p0.5");
    assert_eq!(
        bound, "at_most",
        "an identical LOD is invisible at every size searched"
    );
    assert!(
        dist <= 150.0 && px >= 50.0,
        "the search took in the switch size: {dist} m, {px} px"
    );
    // The console shows the bound as one.
    assert!(r.stdout.contains("≤ "), "{}", r.stdout);
    let report = std::fs::read_to_string(d.join("out/report.html")).unwrap();
    assert!(report.contains("≤ "), "the report shows the bound");
}

#[test]
fn a_switch_distance_beyond_what_the_search_can_render_cannot_pass_silently() {
    let tmp = scratch("distances-beyond");
    let d = tmp.path();
    // A 40-pixel-high display: at 20 m Spot is about 380 px across, larger than the display, so
    // the search stops at 40 px and the gate says it cannot check, naming no measured distance.
    let cfg = identical(d, 20.0, "[viewing]\ndisplay_height_px = 40\n");
    let r = lodeval_within(120, ["eval".as_ref(), cfg.as_os_str()]);
    assert_eq!(r.code, 1, "{}", r.stderr);
    assert!(r.stderr.contains("cannot check"), "{}", r.stderr);
    assert!(!r.stderr.contains("visible until"), "{}", r.stderr);
    let (_, px, bound) = row(&d.join("out"), "vdp_p0.5");
    assert_eq!((px, bound.as_str()), (40.0, "at_most"));
}
