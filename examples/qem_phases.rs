//! The wall time of `lodeval simplify --method qem` by phase, beside meshoptimizer's whole chain,
//! on one thread (results/BENCHMARKS.md, the simplification section, nineteenth session):
//!
//! ```sh
//! cargo run --release --example qem_phases -- reference/models/bunny/stanford-bunny.obj 0.1 9
//! ```
//!
//! Arguments: a mesh, the ratio of triangles to keep, the number of runs (default 9). Each run
//! times meshoptimizer's chain, our QEM chain, and then the QEM chain's phases one by one:
//! the adjacency, the quadrics, the collapse loop, extracting the LOD and making it a mesh.
//! Prints the minimum and the median of each, in milliseconds. (The phases are those of a mesh
//! whose vertices are not split by normals alone, such as the bunny: for one that is, `chain`
//! welds it first and the phases below skip that step.)

use std::time::Instant;

use lodeval::mesh::edit::Adjacency;
use lodeval::mesh::{LoadOptions, Mesh};
use lodeval::simplify::{self, Goal, Method, qem};

const PHASES: [&str; 7] = [
    "meshopt chain",
    "qem chain",
    "adjacency",
    "quadrics",
    "run",
    "extract",
    "to_mesh",
];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [path, ratio, rest @ ..] = args.as_slice() else {
        return Err("usage: qem_phases MESH RATIO [RUNS]".into());
    };
    let mesh = lodeval::mesh::load(std::path::Path::new(path), &LoadOptions::default())?;
    let ratio: f64 = ratio.parse()?;
    let runs: usize = rest.first().map_or(Ok(9), |r| r.parse())?;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let mut times = pool.install(|| time_phases(&mesh, ratio, runs.max(1)))?;
    for (name, t) in PHASES.iter().zip(&mut times) {
        t.sort_by(f64::total_cmp);
        println!(
            "{name:14} min {:8.2} ms   median {:8.2} ms",
            t[0] * 1e3,
            t[t.len() / 2] * 1e3
        );
    }
    Ok(())
}

/// Seconds of each of [`PHASES`] in each run.
fn time_phases(mesh: &Mesh, ratio: f64, runs: usize) -> lodeval::error::Result<Vec<Vec<f64>>> {
    let target = (mesh.triangle_count() as f64 * ratio).round().max(1.0) as usize;
    let mut times = vec![Vec::new(); PHASES.len()];
    for _ in 0..runs {
        let mut clock = Instant::now();
        let mut lap = |k: usize| {
            times[k].push(clock.elapsed().as_secs_f64());
            clock = Instant::now();
        };
        std::hint::black_box(simplify::chain(
            mesh,
            Method::Meshopt,
            &[Goal::Ratio(ratio)],
        )?);
        lap(0);
        std::hint::black_box(simplify::chain(mesh, Method::Qem, &[Goal::Ratio(ratio)])?);
        lap(1);
        // What `qem::progressive` and `simplify::chain` do, one phase at a time.
        let mut adj = Adjacency::new_spatial(mesh);
        adj.allow_non_manifold_collapses();
        lap(2);
        let diagonal = mesh.aabb().diagonal() as f64;
        let mut cost = qem::QemCost::with_attributes(&adj, diagonal);
        lap(3);
        let pm = qem::run(adj, &mut cost, qem::Stop::Triangles(target), diagonal);
        lap(4);
        let lod = pm.extract(target);
        lap(5);
        std::hint::black_box(lod.to_mesh(mesh)?);
        lap(6);
    }
    Ok(times)
}
