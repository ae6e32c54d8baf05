//! The wall time of one `eval` pair by stage — the demo's work for one view of one LOD: render
//! both meshes at 512² with 4 samples per pixel, prepare and compare with FLIP and the VDP, SSIM,
//! the PSNRs, the heat map — on one thread or all (results/BENCHMARKS.md, "Batch evaluation"):
//!
//! ```sh
//! cargo run --release --example score_phases -- reference/models/bunny/stanford-bunny.obj 0.1 9 1
//! ```
//!
//! Arguments: a mesh, the meshoptimizer ratio of its LOD, the number of runs (default 9), the
//! threads (default: all cores). Prints the minimum and the median of each stage in milliseconds.

use std::sync::Arc;
use std::time::Instant;

use lodeval::LinearImage;
use lodeval::metric::{colormap, flip::Flip, mse, ssim, vdp::Vdp};
use lodeval::raster::{self, RenderScene, RenderSettings};
use lodeval::scene::{Rig, Viewing};
use lodeval::simplify::{self, Goal, Method};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [path, ratio, rest @ ..] = args.as_slice() else {
        return Err("usage: score_phases MESH RATIO [RUNS] [THREADS]".into());
    };
    let mesh = lodeval::mesh::load(std::path::Path::new(path), &Default::default())?;
    let ratio: f64 = ratio.parse()?;
    let runs: usize = rest.first().map_or(Ok(9), |r| r.parse())?;
    let threads: usize = rest.get(1).map_or(Ok(0), |r| r.parse())?;
    let lod = simplify::chain(&mesh, Method::Meshopt, &[Goal::Ratio(ratio)])?
        .remove(0)
        .mesh;
    let camera = Rig::Dodecahedron.cameras(&mesh, 1.0).remove(0);
    let (a, b) = (
        RenderScene::of(Arc::new(mesh)),
        RenderScene::of(Arc::new(lod)),
    );
    let settings = RenderSettings::DEFAULT;
    let viewing = Viewing::default();
    let flip = Flip::new(viewing.ppd() as f32);
    let vdp = Vdp::new(&viewing, Default::default());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let mut stages: Vec<(&str, Vec<f64>)> = Vec::new();
    let mut time = |name: &'static str, f: &mut dyn FnMut()| {
        let t = Instant::now();
        f();
        let s = t.elapsed().as_secs_f64();
        match stages.iter_mut().find(|(n, _)| *n == name) {
            Some((_, v)) => v.push(s),
            None => stages.push((name, vec![s])),
        }
    };
    pool.install(|| -> Result<(), lodeval::Error> {
        for _ in 0..runs.max(1) {
            let mut ia = None;
            let mut ib = None;
            time("render original", &mut || {
                ia = Some(LinearImage::from(
                    &raster::render(&a, &camera, &settings).unwrap(),
                ))
            });
            time("render lod", &mut || {
                ib = Some(LinearImage::from(
                    &raster::render(&b, &camera, &settings).unwrap(),
                ))
            });
            let (ia, ib) = (ia.unwrap(), ib.unwrap());
            let (mut fa, mut fb) = (None, None);
            time("flip prepare", &mut || fa = Some(flip.prepare(&ia)));
            time("flip prepare", &mut || fb = Some(flip.prepare(&ib)));
            let mut map = None;
            time("flip compare", &mut || {
                map = Some(
                    flip.compare_prepared(fa.as_ref().unwrap(), fb.as_ref().unwrap())
                        .unwrap()
                        .map,
                )
            });
            let (mut va, mut vb) = (None, None);
            time("vdp prepare", &mut || va = Some(vdp.prepare(&ia)));
            time("vdp prepare", &mut || vb = Some(vdp.prepare(&ib)));
            time("vdp compare", &mut || {
                vdp.compare_prepared(va.as_ref().unwrap(), vb.as_ref().unwrap())
                    .unwrap();
            });
            time("ssim", &mut || {
                ssim::ssim(&ia, &ib, ssim::SsimInput::SrgbLuma).unwrap();
            });
            time("psnr (8-bit sRGB)", &mut || {
                mse::psnr_srgb8(&ia, &ib).unwrap();
            });
            time("mse (luminance)", &mut || {
                mse::mse(&ia, &ib).unwrap();
            });
            let map = map.unwrap();
            time("heat map", &mut || {
                colormap::heat_map(&map.values, map.width, map.height, 0);
            });
            time("to 8-bit sRGB", &mut || {
                ib.to_srgb8();
            });
        }
        Ok(())
    })?;
    let mut total = 0.0;
    for (name, t) in &mut stages {
        t.sort_by(f64::total_cmp);
        // Stages timed twice per run (both images) report per image.
        let median = t[t.len() / 2];
        total += median * (t.len() / runs.max(1)) as f64;
        println!(
            "{name:18} min {:8.2} ms   median {:8.2} ms",
            t[0] * 1e3,
            median * 1e3
        );
    }
    println!(
        "{:18} {:>28.2} ms (medians, each stage as often as a run does it)",
        "total",
        total * 1e3
    );
    Ok(())
}
