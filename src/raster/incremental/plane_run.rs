//! The squared luminance errors of a run of pixels that show one constant-albedo piece: the
//! optimizer's re-shaded pixels (Lindstrom & Turk 2000, eq. 2's Σ (ŷ − y′)² over them), where
//! y′ is the piece's luminance plane ratio N(x, y) / D(x, y) (see `mod.rs`, `LumaPlane`)
//! encoded through the 16-bit sRGB code table.
//!
//! Two implementations with the same result to the bit: four pixels at a time in AVX2 registers
//! where the build targets AVX2 (the default `x86-64-v3` build), and pixel by pixel otherwise.
//! Each vector operation is the scalar one, lane by lane, in the same order (a product and a sum
//! are not fused, the f64 → f32 conversion rounds to nearest, the clamp sends NaN to 0 as
//! `f32::max` does), so the two agree exactly; a test holds them to it.

/// A luminance plane ratio: N = n·(x, y, 1), D = d·(x, y, 1), and `flat` where D = 0.
#[derive(Debug, Clone, Copy)]
pub(super) struct Plane {
    pub n: [f64; 3],
    pub d: [f64; 3],
    pub flat: f32,
}

/// Linear luminance `y` clamped to [0, 1] (NaN to 0) as an index on a 16-bit scale.
#[inline(always)]
pub(super) fn index_of_linear(y: f32) -> usize {
    // `max` returns the other operand for NaN, so the value is a number in [0.5, 65535.5]
    // here and the plain truncating conversion applies (`as` would add the saturation and
    // NaN checks of a general float-to-int cast: this runs for every shaded pixel).
    #[allow(clippy::manual_clamp)] // `clamp` keeps a NaN, and a NaN must give 0 here.
    let v = y.max(0.0).min(1.0) * 65535.0 + 0.5;
    // SAFETY: v is finite and within u32's range, as above.
    (unsafe { v.to_int_unchecked::<u32>() }) as usize
}

impl Plane {
    /// Linear luminance at pixel (x, y).
    #[inline(always)]
    pub fn at(&self, x: f64, y: f64) -> f32 {
        let d = self.d[0] * x + self.d[1] * y + self.d[2];
        if d != 0.0 {
            ((self.n[0] * x + self.n[1] * y + self.n[2]) / d) as f32
        } else {
            self.flat
        }
    }
}

/// (t − y)², exactly.
#[inline(always)]
pub(super) fn sq(t: u16, y: u16) -> i64 {
    let d = t as i64 - y as i64;
    d * d
}

/// A run of pixels: columns, rows and target luminances, of equal lengths.
#[derive(Debug, Clone, Copy)]
pub(super) struct Run<'a> {
    x: &'a [u16],
    y: &'a [u16],
    target: &'a [u16],
}

impl<'a> Run<'a> {
    /// The run of pixels (`x[k]`, `y[k]`) with targets `target[k]`.
    ///
    /// # Panics
    /// If the lengths differ.
    pub fn new(x: &'a [u16], y: &'a [u16], target: &'a [u16]) -> Run<'a> {
        assert!(x.len() == y.len() && y.len() == target.len());
        Run { x, y, target }
    }
}

/// Σ_k (ŷ_k − encode[index(plane at (x_k, y_k))])² over `run`.
pub(super) fn sum_sq(plane: &Plane, encode: &[u16], run: Run) -> i64 {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    {
        // SAFETY: the build targets AVX2 (`target_feature`).
        unsafe { avx2::sum_sq(plane, encode, run) }
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
    {
        sum_sq_scalar(plane, encode, run)
    }
}

/// [`sum_sq`] pixel by pixel (what builds without AVX2 use, and what the vector one is tested
/// against).
#[cfg_attr(all(target_arch = "x86_64", target_feature = "avx2"), allow(dead_code))]
pub(super) fn sum_sq_scalar(plane: &Plane, encode: &[u16], run: Run) -> i64 {
    run.x
        .iter()
        .zip(run.y)
        .zip(run.target)
        .map(|((&x, &y), &t)| sq(t, encode[index_of_linear(plane.at(x as f64, y as f64))]))
        .sum()
}

#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
mod avx2 {
    use super::{Plane, Run, index_of_linear, sq};
    use std::arch::x86_64::*;

    /// [`super::sum_sq`], four pixels at a time.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn sum_sq(plane: &Plane, encode: &[u16], run: Run) -> i64 {
        let Run {
            x: xs,
            y: ys,
            target: targets,
        } = run;
        let n = xs.len();
        let four = n / 4 * 4;
        let [n0, n1, n2] = plane.n.map(|c| _mm256_set1_pd(c));
        let [d0, d1, d2] = plane.d.map(|c| _mm256_set1_pd(c));
        let flat = _mm256_set1_pd(plane.flat as f64);
        let zero_d = _mm256_setzero_pd();
        let (zero, one) = (_mm_setzero_ps(), _mm_set1_ps(1.0));
        let (scale, half) = (_mm_set1_ps(65535.0), _mm_set1_ps(0.5));
        let mut sum = 0i64;
        let mut index = [0i32; 4];
        let mut k = 0;
        while k < four {
            // SAFETY: k + 4 <= n, the length of all three slices (`Run::new`); the loads are
            // unaligned.
            let (x, y) = unsafe {
                let x = _mm_loadl_epi64(xs.as_ptr().add(k).cast());
                let y = _mm_loadl_epi64(ys.as_ptr().add(k).cast());
                (
                    _mm256_cvtepi32_pd(_mm_cvtepu16_epi32(x)),
                    _mm256_cvtepi32_pd(_mm_cvtepu16_epi32(y)),
                )
            };
            // d0·x + d1·y + d2, in that order, as the scalar plane.
            let d = _mm256_add_pd(
                _mm256_add_pd(_mm256_mul_pd(d0, x), _mm256_mul_pd(d1, y)),
                d2,
            );
            let num = _mm256_add_pd(
                _mm256_add_pd(_mm256_mul_pd(n0, x), _mm256_mul_pd(n1, y)),
                n2,
            );
            // D ≠ 0 (true for NaN, as `!=`): N / D, else the flat value (an f32, exact in f64).
            let nonzero = _mm256_cmp_pd::<_CMP_NEQ_UQ>(d, zero_d);
            let v = _mm256_cvtpd_ps(_mm256_blendv_pd(flat, _mm256_div_pd(num, d), nonzero));
            // max(v, 0) returns its second operand, 0, where v is NaN, as `f32::max` does.
            let v = _mm_min_ps(_mm_max_ps(v, zero), one);
            let v = _mm_add_ps(_mm_mul_ps(v, scale), half);
            // SAFETY: `index` has room for four i32.
            unsafe { _mm_storeu_si128(index.as_mut_ptr().cast(), _mm_cvttps_epi32(v)) };
            for j in 0..4 {
                sum += sq(targets[k + j], encode[index[j] as usize]);
            }
            k += 4;
        }
        for j in four..n {
            let v = plane.at(xs[j] as f64, ys[j] as f64);
            sum += sq(targets[j], encode[index_of_linear(v)]);
        }
        sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_vector_and_scalar_sums_agree_to_the_bit() {
        // Planes of every kind a piece makes (steep, flat, D crossing 0 inside the run, values
        // beyond [0, 1] and NaN), over runs of every length modulo four.
        let encode: Vec<u16> = (0..=65535u32).map(|i| (i ^ 0x5a5a) as u16).collect();
        let mut next = crate::raster::xorshift(0x9e37_79b9_7f4a_7c15u64);
        let unit = |r: u64| (r % 200_001) as f64 / 100_000.0 - 1.0;
        for case in 0..400 {
            let mut plane = Plane {
                n: [unit(next()) * 0.01, unit(next()) * 0.01, unit(next())],
                d: [unit(next()) * 0.01, unit(next()) * 0.01, unit(next()) + 1.5],
                flat: unit(next()) as f32,
            };
            match case % 5 {
                // D vanishes at pixel (2, 3).
                1 => plane.d = [1.0, -2.0, 4.0],
                // D = 0 everywhere: the flat value.
                2 => plane.d = [0.0; 3],
                // N / D far outside [0, 1].
                3 => plane.n = [40.0, -35.0, 3.0],
                // NaN: 0 / 0.
                4 => (plane.n, plane.d) = ([0.0; 3], [0.0, 0.0, f64::NAN]),
                _ => {}
            }
            let len = (next() % 40) as usize;
            let xs: Vec<u16> = (0..len).map(|_| (next() % 12) as u16).collect();
            let ys: Vec<u16> = (0..len).map(|_| (next() % 12) as u16).collect();
            let ts: Vec<u16> = (0..len).map(|_| next() as u16).collect();
            let run = Run::new(&xs, &ys, &ts);
            assert_eq!(
                sum_sq(&plane, &encode, run),
                sum_sq_scalar(&plane, &encode, run),
                "case {case}: {plane:?}"
            );
        }
    }
}
