//! The visible-difference predictor against the behaviour vision science establishes: each test
//! states the psychophysical fact it checks. Stimuli are full-field sine gratings in linear light
//! (equal R, G, B), 256×256 pixels at 64 pixels per degree (4° × 4°).

use std::sync::Arc;

use glam::Vec3;
use lodeval::commands::rig_cameras;
use lodeval::mesh::shapes;
use lodeval::metric::LinearImage;
use lodeval::metric::csf::daly_rushmeier;
use lodeval::metric::vdp::{Display, Vdp};
use lodeval::raster::{self, RenderSettings, with_threads};
use lodeval::scene::{Rig, Scene, Viewing};

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
    // Peak contrast sensitivity of photopic vision is of the order of 100–500, i.e. threshold
    // Michelson contrasts of 0.2–1 %; the model's calibration (one response unit = one luminance
    // JND) should land within a factor of a few of that: between 0.1 % and 3 %.
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
    assert!((0.001..=0.03).contains(&hi), "{hi}");
    // And detection grows with contrast (psychometric function).
    let p = |c| {
        vdp()
            .compare(&image(&flat), &image(&grating(0.5, c, 4.0, true)))
            .unwrap()
            .probability
    };
    assert!(p(hi * 0.5) < 0.5 && p(hi * 2.0) > 0.9);
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
        let scene = Scene::new(Arc::new(shapes::torus(rings, sides, 0.35)));
        let camera = rig_cameras(scene.mesh(), &Rig::Dodecahedron, 1.0)[3];
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
