//! Build script: one cfg, for the tests. `shared_models` is set when the developers' shared model
//! collection (`../shared/models/MANIFEST.md`) is beside the checkout; in a user's clone it is
//! not, and the tests that read the collection are then marked ignored — so `cargo test` says in
//! its normal output that they did not run, instead of passing them silently.

fn main() {
    println!("cargo::rustc-check-cfg=cfg(shared_models)");
    // Decided once per build directory (a missing path would rerun this, and rebuild the crate,
    // on every build).
    println!("cargo::rerun-if-changed=build.rs");
    if std::path::Path::new("../shared/models/MANIFEST.md").exists() {
        println!("cargo::rustc-cfg=shared_models");
    }
}
