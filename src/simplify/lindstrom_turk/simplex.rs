//! The downhill simplex method (Nelder & Mead 1965, in the form of Press et al., Numerical
//! Recipes §10.4), Lindstrom & Turk §5.1's continuous optimizer: it needs only function values,
//! which is all an image-difference energy offers.
//!
//! The initial simplex is p₀ and p₀ + δ_i·ê_i (the canonical basis with per-coordinate steps from
//! the local geometry, as in the paper). Moves: reflection (factor −1), expansion (−2),
//! contraction (½) and shrink towards the best vertex (½). The simplex's hyper-volume changes only
//! by powers of two (expansion doubles it, a contraction halves it, a shrink divides it by 2ⁿ), so
//! it is tracked exactly as a base-2 logarithm; the search stops when the function values at all
//! vertices agree, when the volume has fallen to 2^(−3n) of the initial one (every edge about ⅛ of
//! its initial length), or at the evaluation limit (the paper's 32·n).

/// The outcome of a minimisation.
#[derive(Debug, Clone, PartialEq)]
pub struct Minimum {
    /// The best point found.
    pub point: Vec<f64>,
    /// Its function value.
    pub value: f64,
    /// Function evaluations spent (not counting p₀, whose value is given).
    pub evals: usize,
}

/// Minimise `f` from `p0` (with known value `f0`), initial steps `steps` (one per coordinate,
/// non-zero), spending at most `max_evals` evaluations.
pub fn minimize(
    p0: &[f64],
    f0: f64,
    steps: &[f64],
    max_evals: usize,
    mut f: impl FnMut(&[f64]) -> f64,
) -> Minimum {
    let n = p0.len();
    assert_eq!(steps.len(), n, "one step per coordinate");
    let mut evals = 0usize;
    let mut pts: Vec<Vec<f64>> = vec![p0.to_vec()];
    let mut vals: Vec<f64> = vec![f0];
    for i in 0..n {
        if evals >= max_evals {
            break;
        }
        let mut p = p0.to_vec();
        p[i] += steps[i];
        vals.push(f(&p));
        pts.push(p);
        evals += 1;
    }
    if pts.len() < n + 1 || n == 0 {
        let (point, value) = best_of(&pts, &vals);
        return Minimum {
            point,
            value,
            evals,
        };
    }
    let mut log2_volume = 0i64;
    let floor = -3 * n as i64;
    let mut centroid = vec![0.0; n];
    let mut trial = vec![0.0; n];
    while evals < max_evals {
        // Order: best (lowest), worst, second worst; ties by index keep it deterministic.
        let mut order: Vec<usize> = (0..=n).collect();
        order.sort_by(|&a, &b| vals[a].total_cmp(&vals[b]).then(a.cmp(&b)));
        let (lo, hi, next) = (order[0], order[n], order[n - 1]);
        if vals[hi] == vals[lo] || log2_volume <= floor {
            break;
        }
        centroid_without(&pts, hi, &mut centroid);
        // Reflect.
        along(&centroid, &pts[hi], -1.0, &mut trial);
        let fr = f(&trial);
        evals += 1;
        if fr < vals[lo] {
            // Try expanding further.
            let reflected = trial.clone();
            if evals < max_evals {
                along(&centroid, &pts[hi], -2.0, &mut trial);
                let fe = f(&trial);
                evals += 1;
                if fe < fr {
                    pts[hi].clone_from(&trial);
                    vals[hi] = fe;
                    log2_volume += 1;
                    continue;
                }
            }
            pts[hi] = reflected;
            vals[hi] = fr;
            continue;
        }
        if fr < vals[next] {
            pts[hi].clone_from(&trial);
            vals[hi] = fr;
            continue;
        }
        if evals >= max_evals {
            break;
        }
        // Contract: outside when the reflection beat the worst, inside otherwise.
        let t = if fr < vals[hi] { -0.5 } else { 0.5 };
        along(&centroid, &pts[hi], t, &mut trial);
        let fc = f(&trial);
        evals += 1;
        if fc < vals[hi].min(fr) {
            pts[hi].clone_from(&trial);
            vals[hi] = fc;
            log2_volume -= 1;
            continue;
        }
        // Shrink everything towards the best vertex.
        let best = pts[lo].clone();
        for k in 0..=n {
            if k == lo || evals >= max_evals {
                continue;
            }
            for (x, b) in pts[k].iter_mut().zip(&best) {
                *x = b + 0.5 * (*x - b);
            }
            vals[k] = f(&pts[k]);
            evals += 1;
        }
        log2_volume -= n as i64;
    }
    let (point, value) = best_of(&pts, &vals);
    Minimum {
        point,
        value,
        evals,
    }
}

/// The vertex with the lowest value (the first on ties) and its value.
fn best_of(pts: &[Vec<f64>], vals: &[f64]) -> (Vec<f64>, f64) {
    let k = (0..vals.len())
        .min_by(|&a, &b| vals[a].total_cmp(&vals[b]).then(a.cmp(&b)))
        .unwrap_or(0);
    (pts[k].clone(), vals[k])
}

/// The point on the line through the worst vertex and the centroid of the others:
/// c + t·(worst − c), into `out`.
fn along(c: &[f64], worst: &[f64], t: f64, out: &mut Vec<f64>) {
    out.clear();
    out.extend(c.iter().zip(worst).map(|(c, w)| c + t * (w - c)));
}

/// The centroid of every vertex but `hi` (of n + 1), into `out`.
fn centroid_without(pts: &[Vec<f64>], hi: usize, out: &mut [f64]) {
    let n = out.len();
    out.iter_mut().for_each(|c| *c = 0.0);
    for (k, p) in pts.iter().enumerate() {
        if k != hi {
            out.iter_mut().zip(p).for_each(|(c, x)| *c += x / n as f64);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_minimum_of_a_quadratic_bowl() {
        // f = Σ (x_i − i)², minimum 0 at (0, 1, 2, 3).
        let f = |p: &[f64]| {
            p.iter()
                .enumerate()
                .map(|(i, x)| (x - i as f64).powi(2))
                .sum::<f64>()
        };
        let p0 = [0.5, 0.5, 0.5, 0.5];
        let m = minimize(&p0, f(&p0), &[1.0; 4], 2000, f);
        // One run stops when the simplex has shrunk to about ⅛ of its initial size (the point is
        // a coarse optimum cheaply); restarts with smaller steps refine it.
        assert!(m.value < 0.01 && m.value < f(&p0) / 50.0, "{m:?}");
        let mut m = m;
        for k in 0..6 {
            let v = m.value;
            m = minimize(&m.point.clone(), v, &[0.5f64.powi(k + 2); 4], 2000, f);
        }
        assert!(m.value < 1e-4, "{m:?}");
        for (i, x) in m.point.iter().enumerate() {
            assert!((x - i as f64).abs() < 0.05, "{m:?}");
        }
    }

    #[test]
    fn minimises_rosenbrock_in_two_dimensions() {
        let f = |p: &[f64]| (1.0 - p[0]).powi(2) + 100.0 * (p[1] - p[0] * p[0]).powi(2);
        let p0 = [-1.2, 1.0];
        let m = minimize(&p0, f(&p0), &[0.5, 0.5], 5000, f);
        // The volume floor (edges ≈ ⅛ of the initial step) stops well short of full precision,
        // so restart from the result, as one would with Nelder–Mead.
        let mut m = m;
        for k in 0..60 {
            let v = m.value;
            let step = [0.05, 0.01, 0.002][k % 3];
            m = minimize(&m.point.clone(), v, &[step, step], 5000, f);
        }
        assert!(m.value < 1e-4, "{m:?}");
    }

    #[test]
    fn respects_the_evaluation_limit_and_never_returns_worse_than_the_start() {
        let mut calls = 0;
        let f = |p: &[f64]| {
            calls += 1;
            (p[0] - 10.0).powi(2) + (p[1] + 3.0).powi(2) + p[2].abs()
        };
        let m = minimize(&[0.0; 3], 109.0, &[1.0; 3], 17, f);
        assert_eq!(m.evals, 17);
        assert_eq!(calls, 17);
        assert!(m.value <= 109.0);
    }

    #[test]
    fn stops_on_a_flat_function() {
        let m = minimize(&[1.0, 2.0], 5.0, &[0.1, 0.1], 1000, |_| 5.0);
        assert_eq!(m.evals, 2);
        assert_eq!(m.point, vec![1.0, 2.0]);
    }
}
