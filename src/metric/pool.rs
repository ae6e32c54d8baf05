//! Pooling per-pixel scores into numbers: mean, percentiles, maximum, Minkowski sums, histograms.
//!
//! Determinism: sums run row by row in `f64`, rows combined in row order, so the result never
//! depends on how work was split. Percentiles sort a copy (total order on `f32`), so ties and
//! thread count cannot change them.

use rayon::prelude::*;

/// Mean of `values` (rows of `width`), summed in `f64` per row, rows added in order.
pub fn mean(values: &[f32], width: usize) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let rows: Vec<f64> = values
        .par_chunks(width.max(1))
        .map(|r| r.iter().map(|&v| v as f64).sum())
        .collect();
    rows.iter().sum::<f64>() / values.len() as f64
}

/// The `p`-th percentile (0..=100) by linear interpolation between closest ranks, exactly as
/// NumPy's default (`numpy.percentile`, method "linear", including its two-sided interpolation
/// formula); `None` for no values. The one percentile of lodeval: per-pixel maps (`f32`) and
/// per-view tables (`f64`) both go through it.
pub fn percentile<T: Copy + Into<f64>>(values: &[T], p: f64) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    let mut v: Vec<f64> = values.iter().map(|&x| x.into()).collect();
    let rank = p.clamp(0.0, 100.0) / 100.0 * (v.len() - 1) as f64;
    let (lo, hi) = (rank.floor() as usize, rank.ceil() as usize);
    let t = rank - lo as f64;
    // The lo-th and hi-th values in ascending (total) order, by selection rather than a sort:
    // the hi-th is the lo-th or the smallest of those after it.
    let (_, &mut a, above) = v.select_nth_unstable_by(lo, f64::total_cmp);
    let b = if hi == lo {
        a
    } else {
        above.iter().copied().min_by(f64::total_cmp).unwrap_or(a)
    };
    // NumPy's `_lerp`: from the lower end below the midpoint, from the upper end above it.
    Some(if t < 0.5 {
        a + (b - a) * t
    } else {
        b - (b - a) * (1.0 - t)
    })
}

/// FLIP's weighted percentile (`p` in 0..=1): each value weighted by itself, so larger errors
/// count more — the value at which the running sum of the ascending-sorted values first exceeds
/// `p` × the total (the reference tool's "weighted median" for p = 0.5 and "weighted quartiles").
/// Accumulated in `f32` like the reference (total in pixel order, running sum in sorted order);
/// 0 when no value exceeds the threshold (e.g. an all-zero map).
pub fn weighted_percentile(values: &[f32], p: f64) -> f64 {
    let total: f32 = values.iter().sum();
    let threshold = p as f32 * total;
    let mut sorted = values.to_vec();
    sorted.par_sort_unstable_by(|a, b| a.total_cmp(b));
    let mut running = 0f32;
    for v in sorted {
        running += v;
        if running > threshold {
            return v as f64;
        }
    }
    0.0
}

/// Largest value.
pub fn max(values: &[f32]) -> f64 {
    values.iter().fold(f32::NEG_INFINITY, |m, &v| m.max(v)) as f64
}

/// Minkowski pooling (mean of |v|^β)^(1/β).
pub fn minkowski(values: &[f32], width: usize, beta: f64) -> f64 {
    let powered: Vec<f32> = values
        .iter()
        .map(|&v| (v.abs() as f64).powf(beta) as f32)
        .collect();
    mean(&powered, width).powf(1.0 / beta)
}

/// Histogram of values in [0, 1] with `bins` equal bins (values outside are clamped into the
/// end bins).
pub fn histogram(values: &[f32], bins: usize) -> Vec<u64> {
    let mut h = vec![0u64; bins.max(1)];
    let n = h.len();
    for &v in values {
        let b = ((v.clamp(0.0, 1.0) * n as f32) as usize).min(n - 1);
        h[b] += 1;
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_interpolate_like_numpy() {
        // numpy.percentile([1, 2, 3, 4], 50) = 2.5 and 95 → 3.85.
        let v = [4.0, 1.0, 3.0, 2.0];
        assert_eq!(percentile(&v, 50.0), Some(2.5));
        assert!((percentile(&v, 95.0).unwrap() - 3.85).abs() < 1e-12);
        assert_eq!(percentile::<f32>(&[], 50.0), None);
        assert_eq!(percentile(&[7.0f64], 95.0), Some(7.0));
        assert_eq!(max(&v), 4.0);
        assert_eq!(mean(&v, 2), 2.5);
        assert_eq!(histogram(&[0.0, 0.5, 1.0], 2), vec![1, 2]);
    }
}
