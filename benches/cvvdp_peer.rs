//! `cargo bench --bench cvvdp_peer`: lodeval's VDP beside ColorVideoVDP (Mantiuk et al. 2024,
//! the `colorvideovdp` crate, a pure-Rust port of the reference) on the distance search's probes
//! of the demo's bunny and Spot LOD chains (meshoptimizer, 50/25/10/5/2 %).
//!
//! For each LOD and each on-screen size of a √2 ladder from 8 to 256 px, the probe renders of
//! [`lodeval::eval::distance::probe_views`] (the search's own renders: the display's pixel scale,
//! 16 samples per pixel, two views of the dodecahedron rig — the search uses the worst three of a
//! full evaluation; two fixed views keep the peer's run time to minutes) are scored by both:
//! lodeval's worst-view detection probability and JND, and ColorVideoVDP's JOD with each crop
//! pasted into the middle of a 3 840 × 2 160 frame of its own background colour (the peer pools by
//! averaging over the image, so it must see the whole screen), on its `standard_4k` display. A
//! LOD's threshold size is the largest size probed below the first one that is visible: lodeval
//! at detection probability 0.5, ColorVideoVDP at ΔJOD = 10 − JOD of 0.1, 0.25 and 0.5. The
//! ladder stops for a LOD once both models see it at every criterion. Spearman's rank correlation
//! is over every (LOD, size, view) probe scored by both, lodeval's JND against ΔJOD.
//!
//! Display models differ and are stated, not matched: lodeval's default viewing (0.7 m wide
//! 3 840-pixel display seen from 0.7 m, 100 cd/m² peak) against ColorVideoVDP's `standard_4k`.

use std::sync::Arc;

use colorvideovdp::{Color, Cvvdp, DisplayModel, Image, Options};
use lodeval::eval::config::{SampleCount, ViewingConfig};
use lodeval::eval::distance::{DistanceJob, probe_views};
use lodeval::metric::LinearImage;
use lodeval::raster::{RenderScene, RenderSettings};
use lodeval::scene::Rig;
use lodeval::simplify::{Goal, Method, chain};

const SIZES: [u32; 11] = [8, 11, 16, 23, 32, 45, 64, 91, 128, 181, 256];
const SCREEN: (usize, usize) = (3840, 2160);
const JOD_STEPS: [f64; 3] = [0.1, 0.25, 0.5];

/// The crop pasted into the middle of a screen of its corner colour, sRGB-encoded for the peer.
fn on_screen(crop: &LinearImage) -> Image {
    let (w, h) = SCREEN;
    let bg = crop.pixels()[0];
    let enc = |c: glam::Vec3| c.to_array().map(lodeval::color::linear_to_srgb);
    let mut data = Vec::with_capacity(w * h * 3);
    for _ in 0..w * h {
        data.extend_from_slice(&enc(bg));
    }
    let (cw, ch) = (crop.width(), crop.height());
    let (x0, y0) = ((w - cw) / 2, (h - ch) / 2);
    for y in 0..ch {
        for x in 0..cw {
            let at = ((y0 + y) * w + x0 + x) * 3;
            data[at..at + 3].copy_from_slice(&enc(crop.pixels()[y * cw + x]));
        }
    }
    Image::new(w, h, 3, data).expect("a 4K RGB image")
}

/// Spearman's rank correlation (average ranks for ties).
fn spearman(pairs: &[(f64, f64)]) -> f64 {
    let ranks = |v: Vec<f64>| {
        let mut idx: Vec<usize> = (0..v.len()).collect();
        idx.sort_by(|&a, &b| v[a].total_cmp(&v[b]));
        let mut r = vec![0.0; v.len()];
        let mut i = 0;
        while i < idx.len() {
            let mut j = i;
            while j + 1 < idx.len() && v[idx[j + 1]] == v[idx[i]] {
                j += 1;
            }
            for &k in &idx[i..=j] {
                r[k] = (i + j) as f64 / 2.0;
            }
            i = j + 1;
        }
        r
    };
    let a = ranks(pairs.iter().map(|p| p.0).collect());
    let b = ranks(pairs.iter().map(|p| p.1).collect());
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let cov: f64 = a.iter().zip(&b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
    cov / (va * vb).sqrt()
}

/// The largest size below the first visible one (`None`: visible at the smallest; the last size
/// probed with a `>`: never visible on the ladder).
fn threshold(sizes: &[(u32, bool)]) -> String {
    match sizes.iter().position(|s| s.1) {
        Some(0) => "< 8".into(),
        Some(i) => sizes[i - 1].0.to_string(),
        None => format!("> {}", sizes.last().map_or(0, |s| s.0)),
    }
}

fn main() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let display = DisplayModel::from_name("standard_4k").expect("a shipped display");
    let peer = Cvvdp::new(display, Options::default().with_memory_limit_bytes(6 << 30))
        .expect("ColorVideoVDP");
    let (viewing, settings) = (ViewingConfig::default(), RenderSettings::DEFAULT);
    let directions = Rig::Dodecahedron.directions()[..2].to_vec();
    let ratios = [0.5, 0.25, 0.1, 0.05, 0.02];
    let mut all: Vec<(f64, f64)> = Vec::new();
    println!("| asset | LOD | lodeval P ≤ 0.5 (px) | ColorVideoVDP ΔJOD ≤ 0.1 / 0.25 / 0.5 (px) |");
    println!("|---|---|---|---|");
    for (name, path) in [
        ("bunny", "reference/models/bunny/stanford-bunny.obj"),
        ("spot", "reference/models/spot/spot_mtl.obj"),
    ] {
        let mesh = lodeval::mesh::load(&root.join(path), &Default::default()).expect("mesh");
        let goals: Vec<Goal> = ratios.iter().map(|&r| Goal::Ratio(r)).collect();
        let lods = chain(&mesh, Method::Meshopt, &goals).expect("chain");
        let original = RenderScene::of(Arc::new(mesh));
        for (lod, ratio) in lods.into_iter().zip(ratios) {
            let scene = RenderScene::of(Arc::new(lod.mesh));
            let mut job = DistanceJob::new(&original, &scene, directions.clone());
            job.names = (name, "lod", 0);
            let (mut ours, mut theirs) = (Vec::new(), vec![Vec::new(); JOD_STEPS.len()]);
            for size in SIZES {
                let views = probe_views(&job, &viewing, &settings, SampleCount(16), size as f64)
                    .expect("probe");
                let (mut p, mut djod) = (0f64, 0f64);
                for v in &views {
                    let jod = peer
                        .predict_image(&on_screen(&v.lod), &on_screen(&v.original), Color::Srgb)
                        .expect("ColorVideoVDP")
                        .jod as f64;
                    all.push((v.vdp_jnd, 10.0 - jod));
                    p = p.max(v.vdp);
                    djod = djod.max(10.0 - jod);
                }
                ours.push((size, p > 0.5));
                for (t, step) in theirs.iter_mut().zip(JOD_STEPS) {
                    t.push((size, djod > step));
                }
                eprintln!("{name} r{ratio} {size}px: P {p:.3}, ΔJOD {djod:.3}");
                if p > 0.5 && djod > JOD_STEPS[2] {
                    break;
                }
            }
            let peer_sizes: Vec<String> = theirs.iter().map(|t| threshold(t)).collect();
            println!(
                "| {name} | {}% | {} | {} |",
                ratio * 100.0,
                threshold(&ours),
                peer_sizes.join(" / ")
            );
        }
    }
    println!(
        "\nSpearman's ρ, lodeval JND against ΔJOD over {} probes: {:.3}",
        all.len(),
        spearman(&all)
    );
}
