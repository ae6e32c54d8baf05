//! `cargo bench --bench raster`: the rasterizer benchmark of `lodeval bench raster` (1M-triangle
//! torus, 20 views, 1024², 1 and 4 samples), printed as a table.
//! Figures go to results/BENCHMARKS.md; the side-by-side run with llvmpipe is
//! benches/raster_vs_llvmpipe.sh.

use lodeval::app::bench::{RasterBench, bench_raster};
use lodeval::raster::Shading;

fn main() {
    let job = RasterBench {
        rings: 1000,
        sides: 500,
        size: 1024,
        views: 20,
        samples: vec![1, 4],
        shading: Shading::Gouraud,
        export: None,
        backend: lodeval::backend::Backend::Cpu,
    };
    let rows = bench_raster(&job).expect("benchmark runs");
    print!("{}", lodeval::app::bench::raster_bench_table(&rows));
}
