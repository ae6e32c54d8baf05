//! How well predicted thresholds agree with measured ones, per dataset, in dB of sensitivity
//! (20·log10: 2 dB = 0.1 log10 units), the way castleCSF's authors report their fits (Ashraf,
//! Mantiuk, Chapiro, Wuerger 2024, "comparison-1"): the RMS error as predicted, and after a
//! per-dataset sensitivity factor (one multiplicative gain per dataset, which absorbs what differs
//! between laboratories — display, observers, protocol, presentation time — and leaves the shape:
//! how sensitivity changes with frequency, luminance, size and masker). The least-squares factor
//! in dB is the mean residual; the RMSE after it is the residuals' standard deviation.

/// Agreement on one dataset.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct DatasetAgreement {
    /// The dataset's name.
    pub dataset: String,
    /// Rows with a measured prediction (rows whose prediction is a bound are left out).
    pub n: usize,
    /// Rows whose prediction stopped at a bound of the search, or that were not rendered.
    pub left_out: usize,
    /// Mean of predicted − observed, dB: the per-dataset factor's size.
    pub factor_db: f64,
    /// RMS of predicted − observed, dB.
    pub rmse_db: f64,
    /// RMS after the per-dataset factor, dB.
    pub rmse_adjusted_db: f64,
}

/// Per dataset (in first-seen order) from (dataset, residual in dB or `None` when left out).
pub fn per_dataset<'a>(
    rows: impl Iterator<Item = (&'a str, Option<f64>)>,
) -> Vec<DatasetAgreement> {
    let mut groups: Vec<(String, Vec<f64>, usize)> = Vec::new();
    for (name, residual) in rows {
        let i = match groups.iter().position(|g| g.0 == name) {
            Some(i) => i,
            None => {
                groups.push((name.to_string(), Vec::new(), 0));
                groups.len() - 1
            }
        };
        match residual {
            Some(r) => groups[i].1.push(r),
            None => groups[i].2 += 1,
        }
    }
    groups
        .into_iter()
        .map(|(dataset, r, left_out)| {
            let n = r.len();
            let mean = r.iter().sum::<f64>() / n.max(1) as f64;
            let rms = |shift: f64| {
                (r.iter().map(|x| (x - shift).powi(2)).sum::<f64>() / n.max(1) as f64).sqrt()
            };
            DatasetAgreement {
                dataset,
                n,
                left_out,
                factor_db: mean,
                rmse_db: rms(0.0),
                rmse_adjusted_db: rms(mean),
            }
        })
        .collect()
}

/// The mean over datasets of a per-dataset figure (castleCSF's "average error").
pub fn average(datasets: &[DatasetAgreement], figure: impl Fn(&DatasetAgreement) -> f64) -> f64 {
    let used: Vec<f64> = datasets.iter().filter(|d| d.n > 0).map(figure).collect();
    used.iter().sum::<f64>() / used.len().max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_constant_offset_is_the_factor_and_leaves_no_adjusted_error() {
        let rows = [
            ("a", Some(3.0)),
            ("a", Some(3.0)),
            ("b", Some(1.0)),
            ("b", Some(-1.0)),
            ("b", None),
        ];
        let d = per_dataset(rows.into_iter());
        assert_eq!(d[0].factor_db, 3.0);
        assert_eq!(d[0].rmse_db, 3.0);
        assert_eq!(d[0].rmse_adjusted_db, 0.0);
        assert_eq!((d[1].n, d[1].left_out), (2, 1));
        assert_eq!(d[1].rmse_adjusted_db, 1.0);
        assert_eq!(average(&d, |x| x.rmse_adjusted_db), 0.5);
    }
}
