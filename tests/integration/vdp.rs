//! The visible-difference predictor against observers and the behaviour vision science
//! establishes: ModelFest's 43 thresholds (the calibration), then each test states the
//! psychophysical fact it checks, and the LOD cases a person would judge. Stimuli are full-field
//! sine gratings in linear light (equal R, G, B), 256×256 pixels at 64 pixels per degree
//! (4° × 4°), unless a test says otherwise.

use std::sync::Arc;

use glam::Vec3;
use lodeval::eval::config::{DistanceConfig, ViewingConfig};
use lodeval::eval::distance::{DistanceJob, search};
use lodeval::mesh::shapes;
use lodeval::metric::LinearImage;
use lodeval::metric::csf::daly_rushmeier;
use lodeval::metric::vdp::modelfest::{Condition, ModelFest, calibrate};
use lodeval::metric::vdp::threshold::threshold;
use lodeval::metric::vdp::{Display, Vdp, VdpParams};
use lodeval::raster::{self, RenderScene, RenderSettings, with_threads};
use lodeval::scene::{Rig, Viewing};
use lodeval::simplify::{Goal, Method, chain};

use crate::common::{lodeval, model, root};

const PPD: f64 = 64.0;
const SIZE: usize = 256;

/// mean · (1 + contrast · sin(2π f x)) with x in degrees along `axis` (0 = vertical bars).
fn grating(mean: f32, contrast: f32, f_cpd: f64, vertical_bars: bool) -> Vec<f32> {
    (0..SIZE * SIZE)
        .map(|i| {
            let t = if vertical_bars { i % SIZE } else { i / SIZE } as f64 / PPD;
            mean * (1.0 + contrast * (2.0 * std::f64::consts::PI * f_cpd * t).sin() as f32)
        })
        .collect()
}

fn image(v: &[f32]) -> LinearImage {
    LinearImage::new(SIZE, SIZE, v.iter().map(|&y| Vec3::splat(y)).collect()).unwrap()
}

fn vdp() -> Vdp {
    Vdp::new(&Viewing::from_ppd(PPD), Display::DEFAULT)
}

fn jnd(reference: &[f32], test: &[f32]) -> f64 {
    vdp().compare(&image(reference), &image(test)).unwrap().jnd
}

#[test]
fn sensitivity_across_frequency_follows_the_csf() {
    // A fixed small contrast is most visible near the CSF peak and less visible at lower and
    // higher frequencies: the ranking of the VDP's JND over frequencies must be the CSF's.
    let flat = vec![0.5f32; SIZE * SIZE];
    let freqs = [1.0, 4.0, 12.0, 24.0];
    let scores: Vec<f64> = freqs
        .iter()
        .map(|&f| jnd(&flat, &grating(0.5, 0.01, f, true)))
        .collect();
    let csf: Vec<f64> = freqs.iter().map(|&f| daly_rushmeier(f)).collect();
    let rank = |v: &[f64]| {
        let mut idx: Vec<usize> = (0..v.len()).collect();
        idx.sort_by(|&a, &b| v[a].total_cmp(&v[b]));
        idx
    };
    eprintln!("JND of a 1 % grating at {freqs:?} cpd: {scores:?}");
    assert_eq!(rank(&scores), rank(&csf), "VDP {scores:?} vs CSF {csf:?}");
}

#[test]
fn threshold_contrast_at_the_peak_is_human_scale() {
    // Peak contrast sensitivity of photopic vision for a large grating is 200–500 (threshold
    // Michelson contrasts of 0.2–0.5 %; Campbell & Robson 1968, Barten 1999). The calibrated model
    // (ModelFest's Gabors are 1–2° across; this grating is 4° × 4°, so it sums over more area)
    // must land there, at 4 cpd on a 50 cd/m² field.
    let flat = vec![0.5f32; SIZE * SIZE];
    let (mut lo, mut hi) = (1e-4f32, 0.2f32);
    for _ in 0..30 {
        let mid = (lo * hi).sqrt();
        if jnd(&flat, &grating(0.5, mid, 4.0, true)) < 1.0 {
            lo = mid
        } else {
            hi = mid
        }
    }
    eprintln!("threshold contrast at 4 cpd: {:.3} %", hi * 100.0);
    assert!((0.002..=0.005).contains(&hi), "{hi}");
    // And detection grows with contrast along the psychometric function: at threshold P = 0.68,
    // half the contrast is rarely seen, twice the contrast almost always.
    let p = |c| {
        vdp()
            .compare(&image(&flat), &image(&grating(0.5, c, 4.0, true)))
            .unwrap()
            .probability
    };
    assert!((p(hi) - 0.68).abs() < 0.01, "{}", p(hi));
    assert!(p(hi * 0.5) < 0.2 && p(hi * 2.0) > 0.99);
}

#[test]
fn a_strong_masker_of_the_same_orientation_raises_the_threshold() {
    // Contrast masking (Legge & Foley 1980): a 2 % target at 4 cpd is harder to see on top of a
    // 30 % grating of similar frequency and orientation than on a uniform field.
    let flat = vec![0.5f32; SIZE * SIZE];
    let target = grating(0.5, 0.02, 4.0, true);
    let alone = jnd(&flat, &target);
    let masker = grating(0.5, 0.3, 5.0, true);
    let masked: Vec<f32> = masker
        .iter()
        .zip(&target)
        .map(|(m, t)| m + t - 0.5)
        .collect();
    let on_masker = jnd(&masker, &masked);
    eprintln!("2 % target: {alone:.2} JND alone, {on_masker:.2} JND on a 30 % masker");
    assert!(on_masker < alone * 0.6, "{on_masker} vs {alone}");
}

#[test]
fn equal_luminance_steps_are_more_visible_on_dark_backgrounds() {
    // Threshold-versus-intensity (Weber's law): the same absolute luminance difference is far more
    // visible on a dark background than on a bright one, while equal *contrast* is about equally
    // visible on mid and bright backgrounds.
    let step = |mean: f32, delta: f32| {
        let r = vec![mean; SIZE * SIZE];
        let t: Vec<f32> = (0..SIZE * SIZE)
            .map(|i| {
                if (i % SIZE) < SIZE / 2 {
                    mean
                } else {
                    mean + delta
                }
            })
            .collect();
        jnd(&r, &t)
    };
    let (dark, bright) = (step(0.05, 0.01), step(0.8, 0.01));
    eprintln!("ΔY = 0.01: {dark:.2} JND on Y = 0.05, {bright:.2} JND on Y = 0.8");
    assert!(dark > 4.0 * bright);
    let (mid_c, bright_c) = (step(0.4, 0.4 * 0.05), step(0.8, 0.8 * 0.05));
    assert!(
        (mid_c / bright_c - 1.0).abs() < 0.25,
        "{mid_c} vs {bright_c}"
    );
}

#[test]
fn coarser_lods_score_higher_and_identical_scores_zero() {
    // Along an LOD chain of a torus (12×6 → 24×12 → 48×24 quads against 192×96), each coarser
    // LOD must be predicted more visible than the next finer one.
    let render = |rings: u32, sides: u32| {
        let scene = RenderScene::of(Arc::new(shapes::torus(rings, sides, 0.35)));
        let camera = Rig::Dodecahedron.cameras(scene.mesh(), 1.0)[3];
        let mut s = RenderSettings::DEFAULT;
        (s.width, s.height) = (128, 128);
        LinearImage::from(&raster::render(&scene, &camera, &s).unwrap())
    };
    let reference = render(192, 96);
    let v = Vdp::new(&Viewing::DEFAULT, Display::DEFAULT);
    let chain: Vec<f64> = [(12, 6), (24, 12), (48, 24)]
        .iter()
        .map(|&(r, s)| v.compare(&reference, &render(r, s)).unwrap().jnd)
        .collect();
    eprintln!("torus LOD chain JND: {chain:?}");
    assert!(chain[0] > chain[1] && chain[1] > chain[2], "{chain:?}");
    let same = v.compare(&reference, &reference).unwrap();
    assert_eq!((same.jnd, same.probability), (0.0, 0.0));
}

#[test]
fn vdp_is_deterministic_across_thread_counts() {
    let a = image(&grating(0.5, 0.05, 6.0, true));
    let b = image(&grating(0.5, 0.05, 6.0, false));
    let run = |t| with_threads(t, || vdp().compare(&a, &b).unwrap()).unwrap();
    let (one, two, eight) = (run(1), run(2), run(8));
    let bits = |s: &lodeval::metric::vdp::VdpScore| {
        (
            s.jnd.to_bits(),
            s.map.values.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
        )
    };
    assert!(bits(&one) == bits(&two) && bits(&one) == bits(&eight));
}

#[test]
fn masking_map_is_high_on_texture_and_one_on_flat_regions() {
    // Qu & Meyer §4.2: busy regions hide errors. Left half a strong grating, right half flat.
    let busy = grating(0.5, 0.4, 8.0, true);
    let v: Vec<f32> = (0..SIZE * SIZE)
        .map(|i| if i % SIZE < SIZE / 2 { busy[i] } else { 0.5 })
        .collect();
    let m = vdp().masking_map(&image(&v));
    let at = |x: usize, y: usize| m.values[y * SIZE + x];
    // A 40 % grating is a masker of several JND per channel (after band gain and orientation
    // split), elevating thresholds by m^0.7, i.e. more than twofold; the flat half not at all.
    assert!(at(SIZE / 4, SIZE / 2) > 2.0, "{}", at(SIZE / 4, SIZE / 2));
    assert!(
        (at(SIZE - 8, SIZE / 2) - 1.0).abs() < 0.05,
        "{}",
        at(SIZE - 8, SIZE / 2)
    );
}

#[test]
fn modelfest_thresholds_are_predicted_to_a_tenth_of_a_log_unit() {
    // The calibration (Watson & Ahumada 2005's figure of merit): RMS error of predicted against
    // observed log10 sensitivity over all 43 stimuli, against the 16 observers' mean. One observer
    // differs from the group by 0.17, so ≤ 0.10 is closer than any single person.
    let data = ModelFest::load(&root().join("reference/oracles/modelfest")).unwrap();
    assert_eq!(data.stimuli.len(), 43);
    let c = calibrate(&data, VdpParams::fitted(), Condition::MODELFEST).unwrap();
    for r in &c.stimuli {
        eprintln!(
            "{:2} {:18} {:.3} {:.3} {:+.3}",
            r.id, r.name, r.observed, r.predicted, r.residual
        );
    }
    eprintln!("ModelFest RMSE {:.4}", c.rmse_log10);
    assert!(c.rmse_log10 <= 0.10, "{}", c.rmse_log10);
    // No stimulus class is missed badly: every residual within 0.2 log units (the noise and the
    // natural scene are the largest, as for Watson & Ahumada's models).
    assert!(
        c.stimuli.iter().all(|r| r.residual.abs() < 0.2),
        "{:?}",
        c.stimuli
    );
    // The CSF's shape: the fixed-size Gabors (1–10) peak at 3–4 cpd (stimuli 3–5).
    let gabors: Vec<f64> = c.stimuli[..10].iter().map(|r| r.predicted).collect();
    let peak = (0..10)
        .max_by(|&a, &b| gabors[a].total_cmp(&gabors[b]))
        .unwrap();
    assert!((2..=4).contains(&peak), "{gabors:?}");
    // The published constants (P = 250, ε = 0.9, ob = 0.78, β = 3.5) fit worse: the fit matters.
    let published = VdpParams::new(lodeval::metric::csf::DalyCsf::published(), 3.5).unwrap();
    let p = calibrate(&data, published, Condition::MODELFEST).unwrap();
    assert!(
        p.rmse_log10 > 1.5 * c.rmse_log10,
        "{} vs {}",
        p.rmse_log10,
        c.rmse_log10
    );
}

#[test]
fn the_calibration_does_not_depend_on_the_thread_count() {
    let data = ModelFest::load(&root().join("reference/oracles/modelfest")).unwrap();
    let run = |t| {
        with_threads(t, || {
            calibrate(&data, VdpParams::fitted(), Condition::MODELFEST).unwrap()
        })
        .unwrap()
    };
    let (one, two, eight) = (run(1), run(2), run(8));
    assert!(one == two && one == eight);
}

#[test]
fn calibrate_refuses_a_missing_or_damaged_oracle_and_nonsense_conditions() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nowhere");
    let r = lodeval([
        "calibrate",
        "modelfest",
        "--data",
        missing.to_str().unwrap(),
    ]);
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(
        r.stderr.contains("nowhere") && r.stderr.contains("does not exist"),
        "{}",
        r.stderr
    );
    // A copy of the oracle, damaged in each of the ways a folder gets damaged.
    let src = root().join("reference/oracles/modelfest");
    let copy = |name: &str| {
        let d = dir.path().join(name);
        std::fs::create_dir_all(&d).unwrap();
        for e in std::fs::read_dir(&src).unwrap() {
            let e = e.unwrap();
            std::fs::copy(e.path(), d.join(e.file_name())).unwrap();
        }
        d
    };
    type Damage = Box<dyn Fn(&std::path::Path)>;
    // Rewrite thresholds.csv through `f`.
    let edit_table = |f: fn(String) -> String| -> Damage {
        Box::new(move |d| {
            let t = std::fs::read_to_string(d.join("thresholds.csv")).unwrap();
            std::fs::write(d.join("thresholds.csv"), f(t)).unwrap();
        })
    };
    let cases: Vec<(&str, Damage, &str)> = vec![
        (
            "truncated-png",
            Box::new(|d| {
                let p = d.join("07-GaborPatch7.png");
                let b = std::fs::read(&p).unwrap();
                std::fs::write(&p, &b[..b.len() / 3]).unwrap();
            }),
            "07-GaborPatch7.png",
        ),
        (
            "missing-png",
            Box::new(|d| std::fs::remove_file(d.join("43-NaturalScene43.png")).unwrap()),
            "43-NaturalScene43.png",
        ),
        (
            "eight-bit-png",
            Box::new(|d| {
                image::GrayImage::new(256, 256)
                    .save(d.join("01-GaborPatch1.png"))
                    .unwrap();
            }),
            "16-bit grey",
        ),
        (
            "nan-threshold",
            edit_table(|t| t.replace("1.8210", "NaN")),
            "line 2",
        ),
        (
            "short-table",
            edit_table(|t| t.lines().take(30).collect::<Vec<_>>().join("\n")),
            "29 stimuli",
        ),
        (
            "path-in-table",
            edit_table(|t| t.replace("02-GaborPatch2.png", "../../etc/passwd")),
            "line 3",
        ),
        (
            "no-table",
            Box::new(|d| std::fs::remove_file(d.join("thresholds.csv")).unwrap()),
            "thresholds.csv",
        ),
    ];
    for (name, damage, needle) in cases {
        let d = copy(name);
        damage(&d);
        let r = lodeval(["calibrate", "modelfest", "--data", d.to_str().unwrap()]);
        assert_eq!(r.code, 2, "{name}: {}", r.stderr);
        assert!(r.stderr.contains(needle), "{name}: {}", r.stderr);
        assert!(!r.stderr.contains("panicked"), "{name}: {}", r.stderr);
        assert_eq!(r.stderr.trim().lines().count(), 1, "{name}: {}", r.stderr);
    }
    for arg in [
        "--ppd=0",
        "--ppd=-3",
        "--ppd=NaN",
        "--ppd=inf",
        "--background-cd-m2=0",
        "--background-cd-m2=-1",
        "--background-cd-m2=NaN",
    ] {
        let r = lodeval(["calibrate", "modelfest", arg]);
        assert_eq!(r.code, 2, "{arg}: {}", r.stderr);
        let flag = arg.split('=').next().unwrap();
        assert!(r.stderr.contains(flag), "{arg}: {}", r.stderr);
        assert_eq!(r.stderr.trim().lines().count(), 1, "{arg}: {}", r.stderr);
    }
}

#[test]
fn calibrate_prints_json_and_writes_the_table_and_plot() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cal");
    let r = lodeval([
        "calibrate",
        "modelfest",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    let v = &v["modelfest"];
    let rmse = v["rmse_log10"].as_f64().unwrap();
    assert!(rmse > 0.0 && rmse <= 0.10);
    let stimuli = v["stimuli"].as_array().unwrap();
    assert_eq!(stimuli.len(), 43);
    for s in stimuli {
        for key in ["id", "observed", "predicted"] {
            assert!(s[key].is_number(), "{s}");
        }
    }
    let csv = std::fs::read_to_string(out.join("modelfest.csv")).unwrap();
    assert!(csv.starts_with("id,name,observed,sd,predicted,residual\n"));
    assert_eq!(csv.lines().count(), 44);
    let svg = std::fs::read_to_string(out.join("modelfest.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.matches("<circle").count() == 43);
}

/// A 512² Gouraud render of the bunny from view 3 at 4 samples per pixel.
fn bunny_frame() -> LinearImage {
    let mesh =
        lodeval::mesh::load(&model("bunny/stanford-bunny.obj"), &Default::default()).unwrap();
    let camera = Rig::Dodecahedron.cameras(&mesh, 1.0)[3];
    LinearImage::from(
        &raster::render(
            &RenderScene::of(Arc::new(mesh)),
            &camera,
            &RenderSettings::DEFAULT,
        )
        .unwrap(),
    )
}

#[test]
fn a_change_confined_to_a_quarter_of_a_pixel_is_imperceptible() {
    // A sliver of a triangle covering a quarter of one pixel changes that pixel's resolved colour
    // by at most a quarter of the colour difference. Worst case: the brightest pixel of a bunny
    // render turned a quarter of the way to black, at the default 67 ppd. A point of 0.9 arcmin
    // at 25 % contrast is far below threshold (ModelFest's 2°-long line of 0.5 arcmin needs
    // 12 %). The old model called any change P = 1.
    let frame = bunny_frame();
    let (i, _) = frame
        .pixels()
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.y.total_cmp(&b.1.y).then(b.0.cmp(&a.0)))
        .unwrap();
    let mut px = frame.pixels().to_vec();
    px[i] *= 0.75;
    let test = LinearImage::new(frame.width(), frame.height(), px.clone()).unwrap();
    let v = Vdp::new(&Viewing::DEFAULT, Display::DEFAULT);
    let s = v.compare(&frame, &test).unwrap();
    eprintln!(
        "quarter-pixel change: P = {:.4}, {:.3} JND",
        s.probability, s.jnd
    );
    assert!(s.probability < 0.1, "{s:?}");
    // The same pixel turned fully black is 4× the contrast: more visible, though still a point.
    px[i] = Vec3::ZERO;
    let full = v
        .compare(
            &frame,
            &LinearImage::new(frame.width(), frame.height(), px).unwrap(),
        )
        .unwrap();
    assert!(full.jnd > 3.0 * s.jnd, "{} vs {}", full.jnd, s.jnd);
}

#[test]
fn half_the_triangles_of_a_dense_scan_is_invisible_at_a_hundred_and_fifty_pixels() {
    // The headline case a person can judge: the 70k-triangle Stanford bunny against meshoptimizer's
    // 50 % LOD (35k triangles), from the default 0.7 m in front of a 4K 0.7 m display. At 150 px
    // on screen the original has about three triangles per covered pixel and the LOD half that:
    // nobody sees the difference. The search must put the visibility threshold above 150 px (the
    // old model said 50 px), and the VDP at 150 px must agree directly.
    let mesh =
        lodeval::mesh::load(&model("bunny/stanford-bunny.obj"), &Default::default()).unwrap();
    let lod = chain(&mesh, Method::Meshopt, &[Goal::Ratio(0.5)])
        .unwrap()
        .remove(0)
        .mesh;
    let directions: Vec<Vec3> = Rig::Dodecahedron.directions().into_iter().take(3).collect();
    let (original, lod) = (
        RenderScene::of(Arc::new(mesh)),
        RenderScene::of(Arc::new(lod)),
    );
    let mut job = DistanceJob::new(&original, &lod, directions);
    job.names = ("bunny", "meshopt-r50", 0);
    let config = DistanceConfig {
        flip_mean: None,
        ..DistanceConfig::default()
    };
    let rows = search(
        &job,
        &config,
        &ViewingConfig::default(),
        &RenderSettings::DEFAULT,
    )
    .unwrap();
    let vdp = &rows[0];
    eprintln!("{vdp:?}");
    assert!(vdp.resolved && vdp.diameter_px >= 150.0, "{vdp:?}");
    assert!(vdp.diameter_px <= 512.0);
    let p = vdp.vdp_probability.unwrap();
    assert!((0.0..=0.5).contains(&p), "{p}");
}

#[test]
fn pooling_is_over_visual_angle_so_resolution_does_not_change_the_verdict() {
    // The same physical grating patch (2° × 2°, 4 cpd, 0.4 %) shown at 32 and at 64 pixels per
    // degree is the same stimulus to the eye: the predictions agree within 10 % in JND. (The old
    // model summed over pixels, so four times the pixels read as a more visible difference.)
    let patch = |ppd: f64| {
        let n = (2.0 * ppd) as usize;
        let v: Vec<Vec3> = (0..n * n)
            .map(|i| {
                let x = (i % n) as f64 / ppd;
                Vec3::splat(
                    0.5 * (1.0 + 0.004 * (2.0 * std::f64::consts::PI * 4.0 * x).sin()) as f32,
                )
            })
            .collect();
        let flat = LinearImage::new(n, n, vec![Vec3::splat(0.5); n * n]).unwrap();
        let vdp = Vdp::new(&Viewing::from_ppd(ppd), Display::DEFAULT);
        vdp.compare(&flat, &LinearImage::new(n, n, v).unwrap())
            .unwrap()
            .jnd
    };
    let (coarse, fine) = (patch(32.0), patch(64.0));
    eprintln!("2° patch: {coarse:.3} JND at 32 ppd, {fine:.3} JND at 64 ppd");
    assert!((coarse / fine - 1.0).abs() < 0.1, "{coarse} {fine}");
}

#[test]
fn the_display_model_is_checked_and_matters() {
    // Nonsense viewing conditions are refused with a usage error.
    assert!(Vdp::checked(&Viewing::from_ppd(0.0), Display::DEFAULT).is_err());
    assert!(Vdp::checked(&Viewing::from_ppd(f64::NAN), Display::DEFAULT).is_err());
    assert!(
        Vdp::checked(
            &Viewing::from_ppd(67.0),
            Display {
                peak_cd_m2: -1.0,
                ..Display::DEFAULT
            }
        )
        .is_err()
    );
    assert!(Vdp::checked(&Viewing::from_ppd(67.0), Display::DEFAULT).is_ok());
    // A dim display shows the same pixel difference at lower luminance: less visible (the CSF
    // falls in the dark), and strong room light on a reflective screen washes dark detail out.
    let dark: Vec<f32> = (0..SIZE * SIZE).map(|_| 0.02).collect();
    let pattern = grating(0.02, 0.2, 4.0, true);
    let score = |d: Display| {
        Vdp::new(&Viewing::from_ppd(PPD), d)
            .compare(&image(&dark), &image(&pattern))
            .unwrap()
            .jnd
    };
    let office = score(Display::DEFAULT);
    let dim = score(Display {
        peak_cd_m2: 10.0,
        black_cd_m2: 0.05,
        ..Display::DEFAULT
    });
    let glare = score(Display {
        ambient_lux: 5000.0,
        reflectivity: 0.05,
        ..Display::DEFAULT
    });
    eprintln!("dark grating: {office:.2} JND office, {dim:.2} dim display, {glare:.2} in glare");
    assert!(
        dim < office && glare < 0.5 * office,
        "{office} {dim} {glare}"
    );
}

/// A `side × side` luminance image (cd/m²) of `background` with a centred `px`-pixel disc (64
/// samples per pixel at the rim) at contrast `c`; `sides` > 0 makes it a regular polygon with that
/// many corners inscribed in the disc.
fn disc_in_crop(side: usize, px: f64, c: f64, sides: u32) -> Vec<f32> {
    let (r, o) = (px / 2.0, side as f64 / 2.0);
    let inside = |x: f64, y: f64| {
        let (dx, dy) = (x - o, y - o);
        let d = dx.hypot(dy);
        if sides == 0 {
            return d <= r;
        }
        // Inscribed polygon: the distance to its edge along this direction.
        let sector = std::f64::consts::TAU / sides as f64;
        let a = dy.atan2(dx).rem_euclid(sector) - sector / 2.0;
        d * a.cos() <= r * (sector / 2.0).cos()
    };
    (0..side * side)
        .map(|i| {
            let (x, y) = ((i % side) as f64, (i / side) as f64);
            let covered = (0..64)
                .filter(|s| {
                    inside(
                        x + (s % 8) as f64 / 8.0 + 1.0 / 16.0,
                        y + (s / 8) as f64 / 8.0 + 1.0 / 16.0,
                    )
                })
                .count() as f64
                / 64.0;
            (50.0 * (1.0 + c * covered)) as f32
        })
        .collect()
}

#[test]
fn padding_with_background_does_not_move_a_verdict() {
    // A detection model must not care how tightly the image around a change was cropped: the
    // distance search scores crops around the object, and before the VDP gave images a surround
    // (`padding.rs`) an 8 px disc needed 0.050 contrast in a crop of its own size against 0.033 in
    // a crop three times as large. Discs of 8, 16 and 32 px at 60 ppd, crops of 1× (the disc
    // plus a pixel each side) and 3× their size: thresholds within 5 %; and a hexagon against
    // the disc it approximates (the change an LOD makes) scores the same JND in both crops.
    let (ppd, bg) = (60.0, 50.0f32);
    let vdp = Vdp::with_params(ppd, Display::DEFAULT, VdpParams::fitted());
    for px in [8usize, 16, 32] {
        let crops = [px + 2, 3 * px];
        let t: Vec<f64> = crops
            .iter()
            .map(|&side| {
                let background = vdp.prepare_luminance(side, side, vec![bg; side * side]);
                threshold(&vdp, &background, |c| disc_in_crop(side, px as f64, c, 0)).contrast
            })
            .collect();
        let j: Vec<f64> = crops
            .iter()
            .map(|&side| {
                let prepare = |sides| {
                    vdp.prepare_luminance(side, side, disc_in_crop(side, px as f64, 0.5, sides))
                };
                let score = vdp.compare_prepared(&prepare(0), &prepare(6)).unwrap();
                score.jnd
            })
            .collect();
        eprintln!(
            "{px} px: threshold {:.4} / {:.4}, hexagon {:.3} / {:.3} JND",
            t[0], t[1], j[0], j[1]
        );
        assert!((t[0] / t[1] - 1.0).abs() < 0.05, "{px} px: {t:?}");
        assert!((j[0] / j[1] - 1.0).abs() < 0.05, "{px} px: {j:?}");
    }
}
