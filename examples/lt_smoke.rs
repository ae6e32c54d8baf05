use lodeval::simplify::lindstrom_turk::{Options, optimize};
use std::sync::Arc;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let o =
        Arc::new(lodeval::mesh::load(std::path::Path::new(&args[1]), &Default::default()).unwrap());
    let s =
        Arc::new(lodeval::mesh::load(std::path::Path::new(&args[2]), &Default::default()).unwrap());
    let mut opts = Options::default();
    opts.evals = args[3].parse().unwrap();
    let out = optimize(&o, &s, &opts, &|_| {}).unwrap();
    for r in &out.log {
        println!("{:?}", r);
    }
    println!(
        "{:?} {:?} evals {} secs {:.2} → {:.0} evals/s",
        out.accepted,
        out.vertices,
        out.evals,
        out.seconds,
        out.evals as f64 / out.seconds
    );
}
