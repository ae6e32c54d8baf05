//! Fits the VDP's four free constants (`src/metric/vdp/fitted.rs`) on ModelFest: Nelder–Mead on
//! the RMS error of predicted against observed log10 contrast sensitivity over the 43 stimuli,
//! each prediction the threshold search that `lodeval calibrate modelfest` runs. Prints the fit;
//! the values are then written into `fitted.rs` by hand (nothing is fitted at run time).
//!
//! Run from the repository root: `cargo run --release --example fit_vdp [-- --evals N]
//! [--from-published] [--beta B] [--check]`. Parameters are searched as (ln P, ε, ob, β), from the
//! current constants or from Daly's published ones (P = 250, ε = 0.9, ob = 0.78, β = 3.5).
//! `--beta B` holds β (spatial summation) at B and fits the other three; `--check` then scores
//! the fit on the castleCSF subset (mean over datasets after a per-dataset factor, dB), the data
//! that constrain spatial summation across sizes, which ModelFest alone does not.

use std::path::Path;

use lodeval::metric::csf::DalyCsf;
use lodeval::metric::vdp::agreement::{average, per_dataset};
use lodeval::metric::vdp::castle::{self, CastleCsf};
use lodeval::metric::vdp::foley::{self, Foley};
use lodeval::metric::vdp::modelfest::{Condition, ModelFest, calibrate};
use lodeval::metric::vdp::{HighLuminanceLoss, VdpParams, fitted};
use lodeval::simplify::lindstrom_turk::simplex::minimize;

fn params(x: &[f64]) -> Option<VdpParams> {
    VdpParams::new(DalyCsf::new(x[0].exp(), x[1], x[2])?, x[3])
}

fn main() {
    let evals: usize = std::env::args()
        .skip_while(|a| a != "--evals")
        .nth(1)
        .and_then(|v| v.parse().ok())
        .unwrap_or(200);
    let beta: Option<f64> = std::env::args()
        .skip_while(|a| a != "--beta")
        .nth(1)
        .and_then(|v| v.parse().ok());
    let data = ModelFest::load(Path::new("reference/oracles/modelfest")).expect("oracle folder");
    let full = |x: &[f64]| -> Vec<f64> {
        let mut v = x.to_vec();
        if let Some(b) = beta {
            v.push(b);
        }
        v
    };
    let rmse = |x: &[f64]| -> f64 {
        match params(&full(x)) {
            Some(p) => calibrate(&data, p, Condition::MODELFEST)
                .map(|c| c.rmse_log10)
                .unwrap_or(f64::INFINITY),
            None => f64::INFINITY,
        }
    };
    let mut x = if std::env::args().any(|a| a == "--from-published") {
        vec![250f64.ln(), 0.9, 0.78, 3.5]
    } else {
        vec![
            fitted::PEAK_SENSITIVITY.ln(),
            fitted::FREQUENCY_SCALE,
            fitted::OBLIQUE,
            fitted::BETA,
        ]
    };
    if let Some(b) = beta {
        x[3] = b;
        x.truncate(3);
    }
    let mut fx = rmse(&x);
    eprintln!("start {x:?}: RMSE {fx:.5}");
    // Restart the simplex from its best point until a restart no longer improves the fit.
    let mut steps = vec![0.05, 0.05, 0.05, 0.1];
    steps.truncate(x.len());
    for round in 0..20 {
        let m = minimize(&x, fx, &steps, evals, &rmse);
        eprintln!(
            "round {round}: RMSE {:.5} at {:?} ({} evaluations)",
            m.value, m.point, m.evals
        );
        let gain = fx - m.value;
        x = m.point;
        fx = m.value;
        if gain < 1e-5 {
            break;
        }
        steps.iter_mut().for_each(|s| *s *= 0.5);
    }
    let x = full(&x);
    println!(
        "P = {:.4}, epsilon = {:.5}, ob = {:.5}, beta = {:.5}: RMSE {:.5} log10",
        x[0].exp(),
        x[1],
        x[2],
        x[3],
        fx
    );
    if std::env::args().any(|a| a == "--check") {
        check(params(&x).expect("fitted"));
    }
}

/// Score `p` on castleCSF and Foley, and fit the high-luminance loss on castleCSF's residuals
/// without it. The fit is exact, not an approximation: every castleCSF stimulus sits on a uniform
/// background, so the loss scales every band by the same factor and the threshold by its
/// inverse — the residual in dB moves by −20·log10(factor(L) / factor(L_ref)).
fn check(p: VdpParams) {
    let castle = CastleCsf::load(Path::new("reference/oracles/castlecsf")).expect("castleCSF");
    let bare = castle::calibrate(&castle, p.with_high_luminance(None), None).expect("castleCSF");
    let score = |loss: Option<HighLuminanceLoss>| {
        let rows = bare.conditions.iter().map(|r| {
            let shift = loss.map_or(0.0, |h| {
                20.0 * (h.factor(r.luminance) / h.factor(fitted::REFERENCE_LUMINANCE)).log10()
            });
            (r.dataset.as_str(), r.residual_db.map(|d| d + shift))
        });
        average(&per_dataset(rows), |d| d.rmse_adjusted_db)
    };
    // Knee on a 1/10-decade grid from 30 to 10^5 cd/m², exponent from 0.1 to 3.
    let mut best = (score(None), None);
    for k in 15..=50 {
        for n in 1..=30 {
            let loss = HighLuminanceLoss {
                knee_cd_m2: 10f64.powf(k as f64 / 10.0),
                exponent: n as f64 / 10.0,
            };
            let s = score(Some(loss));
            if s < best.0 - 1e-9 {
                best = (s, Some(loss));
            }
        }
    }
    println!(
        "castleCSF without the loss: {:.3} dB after a factor per dataset; with the best loss \
         {:?}: {:.3} dB",
        score(None),
        best.1,
        best.0
    );
    let with = castle::calibrate(&castle, p.with_high_luminance(best.1), None).expect("castleCSF");
    println!(
        "castleCSF recomputed with it: {:.3} dB as predicted, {:.3} dB after the factor",
        with.rmse_db, with.rmse_adjusted_db
    );
    for d in &with.datasets {
        println!("  {:<14} {:.2} dB", d.dataset, d.rmse_adjusted_db);
    }
    let data = Foley::load(Path::new("reference/oracles/foley1994")).expect("Foley");
    let f = foley::calibrate(&data, p.with_high_luminance(best.1)).expect("Foley");
    println!(
        "Foley: {:.3} dB after a factor",
        f.agreement.rmse_adjusted_db
    );
}
