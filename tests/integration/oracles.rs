//! Metrics against values computed by reference implementations others wrote
//! (reference/oracles/values.json, made by reference/oracles/make_oracles.py).

use lodeval::metric::LinearImage;
use lodeval::metric::flip::Flip;

use crate::common::root;

fn values() -> serde_json::Value {
    let text = std::fs::read_to_string(root().join("reference/oracles/values.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

#[test]
fn flip_matches_nvidias_reference_implementation() {
    // Tolerances from the issue: mean within 1e-4, every pixel within 2e-4. The oracle maps are
    // stored as 16-bit PNGs, which adds at most 0.5/65535 ≈ 7.7e-6 of quantisation.
    let v = values();
    let pairs = v["flip"].as_array().unwrap();
    assert!(pairs.len() >= 10);
    for p in pairs {
        let name = p["name"].as_str().unwrap();
        let load = |k: &str| LinearImage::load(&root().join(p[k].as_str().unwrap())).unwrap();
        let (reference, test) = (load("reference"), load("test"));
        let flip = Flip::new(p["ppd"].as_f64().unwrap() as f32);
        let ours = flip.compare(&reference, &test).unwrap();
        let expected_mean = p["mean_f64"].as_f64().unwrap();
        let oracle = image::open(root().join(p["map"].as_str().unwrap()))
            .unwrap()
            .into_luma16();
        let mut worst = (0.0f64, 0usize);
        for (i, (&o, e)) in ours.map.values.iter().zip(oracle.pixels()).enumerate() {
            let d = (o as f64 - e.0[0] as f64 / 65535.0).abs();
            if d > worst.0 {
                worst = (d, i);
            }
        }
        let w = reference.width();
        eprintln!(
            "{name}: mean {:.6} vs {:.6} (Δ {:.2e}); worst pixel Δ {:.2e} at ({}, {})",
            ours.mean,
            expected_mean,
            (ours.mean - expected_mean).abs(),
            worst.0,
            worst.1 % w,
            worst.1 / w
        );
        assert!(
            (ours.mean - expected_mean).abs() <= 1e-4,
            "{name}: mean {} vs {}",
            ours.mean,
            expected_mean
        );
        assert!(
            worst.0 <= 2e-4 + 7.7e-6,
            "{name}: pixel ({}, {}) differs by {}",
            worst.1 % w,
            worst.1 / w,
            worst.0
        );
    }
}
