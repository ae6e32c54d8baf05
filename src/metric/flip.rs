//! ꟻLIP for low-dynamic-range images: a per-pixel perceptual difference in [0, 1] for images
//! viewed alternately ("flipped") at a given number of pixels per degree.
//!
//! Based on: Pontus Andersson, Jim Nilsson, Tomas Akenine-Möller, Magnus Oskarsson, Kalle Åström,
//! Mark D. Fairchild. FLIP: A Difference Evaluator for Alternating Images. HPG 2020 — §3 (colour
//! pipeline: YCxCz, contrast-sensitivity filtering with the sum-of-Gaussians CSFs of Table 1 —
//! a1 = (1, 1, 34.1), b1 = (0.0047, 0.0053, 0.04), a2 = (0, 0, 13.5), b2 = (1e-5, 1e-5, 0.025) —
//! Hunt adjustment, HyAB distance, qc = 0.7, pc = 0.4, pt = 0.95), §4 (edge and point features
//! from first and second derivatives of a Gaussian of width w = 0.082°, qf = 0.5) and eq. 11
//! (error = ΔE_c^(1 − ΔE_f)). The published reference implementation (NVlabs/flip, v1.7) defines
//! the details the paper leaves open, and this file follows those facts so that results agree
//! with it (tests: `reference/oracles/flip/`): filters are separable (the blue–yellow sum of two
//! Gaussians as two separable passes with √-weights, normalised to unit total), image borders are
//! clamped, the spatial filter radius is ⌈3·√(max b / 2π²)·ppd⌉, the feature filter's Gaussian sums
//! to 1 and the positive and negative lobes of its derivatives to ±1, arithmetic is `f32`.
//!
//! Prepare once, compare many (ARCHITECTURE.md): [`Flip::prepare`] does each image's filtering; the
//! comparison is per pixel. Rows run in parallel; every pixel's arithmetic is independent of the
//! schedule, and the mean is a fixed-order sum of per-row `f64` sums, so results do not depend on
//! the thread count.

use glam::Vec3;
use rayon::prelude::*;

use super::runs::map_runs;
use crate::color::{rgb_to_xyz, xyz_to_lab, xyz_to_rgb, xyz_to_ycxcz, ycxcz_to_xyz};
use crate::error::Result;
use crate::image::{ErrorMap, LinearImage, same_dims, same_size};

/// π in `f32` (the reference's literal 3.14159265358979f rounds to the same value).
const PI: f32 = std::f32::consts::PI;
/// Colour-difference exponent qc.
const QC: f32 = 0.7;
/// Error-remapping knee pc.
const PC: f32 = 0.4;
/// Error-remapping knee value pt.
const PT: f32 = 0.95;
/// Feature-detector width w, degrees.
const W: f32 = 0.082;
/// Feature-difference exponent qf.
const QF: f32 = 0.5;
/// CSF sum-of-Gaussians parameters per channel (Y, Cx, Cz), paper Table 1.
const A1: [f32; 3] = [1.0, 1.0, 34.1];
const B1: [f32; 3] = [0.0047, 0.0053, 0.04];
const A2: [f32; 3] = [0.0, 0.0, 13.5];
const B2: [f32; 3] = [1.0e-5, 1.0e-5, 0.025];

/// Hunt-adjusted CIELAB: chroma scaled by 0.01·L (paper §3.2).
fn hunt(lab: Vec3) -> Vec3 {
    Vec3::new(lab.x, 0.01 * lab.x * lab.y, 0.01 * lab.x * lab.z)
}

/// HyAB distance: |ΔL| + ‖Δ(a, b)‖ (Abasi et al. 2020; paper §3.2).
fn hyab(a: Vec3, b: Vec3) -> f32 {
    (a.x - b.x).abs() + ((a.y - b.y) * (a.y - b.y) + (a.z - b.z) * (a.z - b.z)).sqrt()
}

/// The largest colour difference, green vs blue, raised to qc (paper §3.2).
fn max_distance() -> f32 {
    let green = hunt(xyz_to_lab(rgb_to_xyz(Vec3::Y)));
    let blue = hunt(xyz_to_lab(rgb_to_xyz(Vec3::Z)));
    hyab(green, blue).powf(QC)
}

/// 1D Gaussian a·√(π/b)·exp(−π²x²/b) (paper eq. 2) and its square-root-weighted variant used to
/// separate a sum of two Gaussians into two separable passes.
fn gaussian(x2: f32, a: f32, b: f32) -> f32 {
    a * (PI / b).sqrt() * (-(PI * PI) * x2 / b).exp()
}
fn gaussian_sqrt(x2: f32, a: f32, b: f32) -> f32 {
    (a * (PI / b).sqrt()).sqrt() * (-(PI * PI) * x2 / b).exp()
}

/// The separable spatial filters: per tap (Y, Cx) and (Cz first Gaussian, Cz second Gaussian).
fn spatial_filters(ppd: f32) -> Vec<([f32; 2], [f32; 2])> {
    let max_b = B1.iter().chain(&B2).fold(0.0f32, |m, &b| m.max(b));
    let radius = (3.0 * (max_b / (2.0 * PI * PI)).sqrt() * ppd).ceil() as i32;
    let dx = 1.0 / ppd;
    let mut taps: Vec<([f32; 2], [f32; 2])> = (-radius..=radius)
        .map(|i| {
            let x = i as f32 * dx;
            let x2 = x * x;
            (
                [gaussian(x2, A1[0], B1[0]), gaussian(x2, A1[1], B1[1])],
                [
                    gaussian_sqrt(x2, A1[2], B1[2]),
                    gaussian_sqrt(x2, A2[2], B2[2]),
                ],
            )
        })
        .collect();
    let mut sum_ycx = [0.0f32; 2];
    let mut sum_cz = [0.0f32; 2];
    for (ycx, cz) in &taps {
        sum_ycx[0] += ycx[0];
        sum_ycx[1] += ycx[1];
        sum_cz[0] += cz[0];
        sum_cz[1] += cz[1];
    }
    let norm_cz = 1.0 / (sum_cz[0] * sum_cz[0] + sum_cz[1] * sum_cz[1]).sqrt();
    for (ycx, cz) in &mut taps {
        ycx[0] *= 1.0 / sum_ycx[0];
        ycx[1] *= 1.0 / sum_ycx[1];
        cz[0] *= norm_cz;
        cz[1] *= norm_cz;
    }
    taps
}

/// The separable feature filter: per tap (Gaussian, 1st derivative, 2nd derivative) (paper §4).
fn feature_filter(ppd: f32) -> Vec<[f32; 3]> {
    let sd = 0.5 * W * ppd;
    let radius = (3.0 * sd).ceil() as i32;
    let mut taps = Vec::with_capacity(2 * radius as usize + 1);
    let (mut g_sum, mut dg_pos, mut dg_neg, mut ddg_pos, mut ddg_neg) =
        (0.0f32, 0.0f32, 0.0f32, 0.0f32, 0.0f32);
    for i in -radius..=radius {
        let x = i as f32;
        let g = (-(x * x) / (2.0 * sd * sd)).exp();
        g_sum += g;
        let dg = -x * g;
        if dg > 0.0 {
            dg_pos += dg
        } else {
            dg_neg -= dg
        }
        let ddg = (x * x / (sd * sd) - 1.0) * g;
        if ddg > 0.0 {
            ddg_pos += ddg
        } else {
            ddg_neg -= ddg
        }
        taps.push([g, dg, ddg]);
    }
    for t in &mut taps {
        t[0] /= g_sum;
        t[1] /= if t[1] > 0.0 { dg_pos } else { dg_neg };
        t[2] /= if t[2] > 0.0 { ddg_pos } else { ddg_neg };
    }
    taps
}

/// One output plane of a separable pass: the input plane it reads and its taps, in order.
type Pass<'a> = (usize, &'a [f32]);

/// The horizontal pass of a separable filter with clamped borders: for each of `passes`,
/// out[x] = Σ_k taps[k] · in[clamp(x + k − r)], summed in tap order (the order the reference
/// implementation sums in). Returns the rows of every output plane interleaved: row y of pass p
/// at `(y · passes.len() + p) · width`. Rows run in parallel; each tap is one vectorised sweep
/// over a border-padded copy of the row.
fn filter_rows(width: usize, height: usize, planes: &[Vec<f32>], passes: &[Pass]) -> Vec<f32> {
    let n = passes.len();
    let mut out = vec![0.0f32; width * height * n];
    out.par_chunks_mut(width * n).enumerate().for_each_init(
        Vec::new,
        |pad: &mut Vec<f32>, (y, rows)| {
            for ((plane, taps), o) in passes.iter().zip(rows.chunks_exact_mut(width)) {
                let r = taps.len() / 2;
                let row = &planes[*plane][y * width..(y + 1) * width];
                pad.clear();
                pad.extend(
                    (0..width + 2 * r).map(|i| row[clamp_index(i as isize - r as isize, width)]),
                );
                for (k, &t) in taps.iter().enumerate() {
                    for (o, &v) in o.iter_mut().zip(&pad[k..k + width]) {
                        *o += t * v;
                    }
                }
            }
        },
    );
    out
}

/// The vertical pass over [`filter_rows`]' output (`planes_in` planes interleaved by row): for
/// each of `passes` the column sums with clamped borders, in tap order, then `finish` turns the
/// row's sums (pass p's at column x in `sums[p · width + x]`) into the row's output pixels. Rows
/// in parallel.
fn filter_columns<O: Send + Copy + Default>(
    width: usize,
    height: usize,
    mid: &[f32],
    planes_in: usize,
    passes: &[Pass],
    finish: impl Fn(&[f32], &mut [O]) + Sync,
) -> Vec<O> {
    let mut out = vec![O::default(); width * height];
    out.par_chunks_mut(width).enumerate().for_each_init(
        || vec![0.0f32; width * passes.len()],
        |sums: &mut Vec<f32>, (y, row)| {
            sums.fill(0.0);
            for ((plane, taps), s) in passes.iter().zip(sums.chunks_exact_mut(width)) {
                let r = taps.len() / 2;
                for (k, &t) in taps.iter().enumerate() {
                    let src = clamp_index(y as isize + k as isize - r as isize, height);
                    let start = (src * planes_in + plane) * width;
                    for (s, &v) in s.iter_mut().zip(&mid[start..start + width]) {
                        *s += t * v;
                    }
                }
            }
            finish(sums, row);
        },
    );
    out
}

/// Clamp-to-edge index.
#[inline]
fn clamp_index(i: isize, n: usize) -> usize {
    i.clamp(0, n as isize - 1) as usize
}

/// FLIP at one viewing condition.
#[derive(Debug, Clone)]
pub struct Flip {
    ppd: f32,
    spatial: Vec<([f32; 2], [f32; 2])>,
    features: Vec<[f32; 3]>,
    cmax: f32,
}

/// One image after FLIP's per-image work.
#[derive(Debug, Clone)]
pub struct FlipPrepared {
    width: usize,
    height: usize,
    /// Spatially filtered, Hunt-adjusted CIELAB.
    lab: Vec<Vec3>,
    /// Edge and point feature magnitudes.
    features: Vec<[f32; 2]>,
}

/// The result of a FLIP comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct FlipScore {
    /// Mean of the error map (f64 sum of the f32 map in row order), in [0, 1].
    pub mean: f64,
    /// The per-pixel error in [0, 1].
    pub map: ErrorMap,
}

impl Flip {
    /// FLIP for `ppd` pixels per degree of visual angle (default: 67.02, the README's office display).
    pub fn new(ppd: f32) -> Flip {
        Flip {
            ppd,
            spatial: spatial_filters(ppd),
            features: feature_filter(ppd),
            cmax: max_distance(),
        }
    }

    /// The separable filters and the largest colour difference, for the GPU kernels:
    /// (spatial taps (Y, Cx, Cz₁, Cz₂), feature taps (Gaussian, 1st, 2nd derivative), cmax).
    #[cfg(feature = "gpu")]
    pub(crate) fn kernels(&self) -> (Vec<[f32; 4]>, Vec<[f32; 4]>, f32) {
        (
            self.spatial
                .iter()
                .map(|(ycx, cz)| [ycx[0], ycx[1], cz[0], cz[1]])
                .collect(),
            self.features
                .iter()
                .map(|f| [f[0], f[1], f[2], 0.0])
                .collect(),
            self.cmax,
        )
    }

    /// Pixels per degree this evaluator was built for.
    pub fn ppd(&self) -> f32 {
        self.ppd
    }

    /// Filter one image (linear RGB) into what the comparison needs.
    pub fn prepare(&self, image: &LinearImage) -> FlipPrepared {
        let (w, h) = (image.width(), image.height());
        let ycxcz: Vec<Vec3> = image
            .pixels()
            .par_iter()
            .map(|&c| xyz_to_ycxcz(rgb_to_xyz(c)))
            .collect();
        let planes: Vec<Vec<f32>> = (0..3)
            .map(|c| ycxcz.iter().map(|v| v[c]).collect())
            .collect();
        // Colour: CSF filtering in YCxCz (Y, Cx, and Cz as the sum of two Gaussians), back to
        // linear RGB (clamped), CIELAB, Hunt.
        let tap = |f: fn(&([f32; 2], [f32; 2])) -> f32| self.spatial.iter().map(f).collect();
        let (y, cx, cz1, cz2): (Vec<f32>, Vec<f32>, Vec<f32>, Vec<f32>) = (
            tap(|t| t.0[0]),
            tap(|t| t.0[1]),
            tap(|t| t.1[0]),
            tap(|t| t.1[1]),
        );
        let mid = filter_rows(w, h, &planes, &[(0, &y), (1, &cx), (2, &cz1), (2, &cz2)]);
        let lab = filter_columns(
            w,
            h,
            &mid,
            4,
            &[(0, &y), (1, &cx), (2, &cz1), (3, &cz2)],
            |s, row| {
                // Runs of equal filtered values (a flat background) convert once.
                let filtered =
                    (0..row.len()).map(|x| Vec3::new(s[x], s[w + x], s[2 * w + x] + s[3 * w + x]));
                let labs = map_runs(filtered, |f| {
                    let rgb = xyz_to_rgb(ycxcz_to_xyz(f)).clamp(Vec3::ZERO, Vec3::ONE);
                    hunt(xyz_to_lab(rgb_to_xyz(rgb)))
                });
                for (o, lab) in row.iter_mut().zip(labs) {
                    *o = lab;
                }
            },
        );
        // Features: edges and points on the normalised achromatic channel.
        let gray = vec![
            ycxcz
                .iter()
                .map(|c| c.x * (1.0 / 116.0) + 16.0 / 116.0)
                .collect(),
        ];
        let tap = |i: usize| -> Vec<f32> { self.features.iter().map(|f| f[i]).collect() };
        let (g, dg, ddg) = (tap(0), tap(1), tap(2));
        // Rows: d/dx, d²/dx², Gaussian; columns: their Gaussian (x derivatives) and the y
        // derivatives of the Gaussian row.
        let mid = filter_rows(w, h, &gray, &[(0, &dg), (0, &ddg), (0, &g)]);
        let features = filter_columns(
            w,
            h,
            &mid,
            3,
            &[(0, &g), (1, &g), (2, &dg), (2, &ddg)],
            |s, row| {
                for (x, o) in row.iter_mut().enumerate() {
                    let (dx, ddx, dy, ddy) = (s[x], s[w + x], s[2 * w + x], s[3 * w + x]);
                    *o = [(dx * dx + dy * dy).sqrt(), (ddx * ddx + ddy * ddy).sqrt()];
                }
            },
        );
        FlipPrepared {
            width: w,
            height: h,
            lab,
            features,
        }
    }

    /// Compare two prepared images.
    pub fn compare_prepared(
        &self,
        reference: &FlipPrepared,
        test: &FlipPrepared,
    ) -> Result<FlipScore> {
        same_dims(
            (reference.width, reference.height),
            (test.width, test.height),
        )?;
        let cmax = self.cmax;
        let pccmax = PC * cmax;
        let inv_sqrt2 = 1.0 / 2f32.sqrt();
        let values: Vec<f32> = (0..reference.lab.len())
            .into_par_iter()
            .with_min_len(4096)
            .map(|i| {
                // Colour difference, remapped to [0, 1] with the knee at pc·cmax (paper §3.2).
                let mut dc = hyab(reference.lab[i], test.lab[i]).powf(QC);
                dc = if dc < pccmax {
                    dc * (PT / pccmax)
                } else {
                    PT + ((dc - pccmax) / (cmax - pccmax)) * (1.0 - PT)
                };
                // Feature difference (paper §4).
                let [er, pr] = reference.features[i];
                let [et, pt] = test.features[i];
                let feature = inv_sqrt2 * (er - et).abs().max((pr - pt).abs());
                if feature == 0.0 {
                    // ΔE_f = 0: ΔE_c^1 (what the powers give, exactly).
                    return dc;
                }
                dc.powf(1.0 - feature.powf(QF))
            })
            .collect();
        let mean = super::pool::mean(&values, reference.width);
        Ok(FlipScore {
            mean,
            map: ErrorMap {
                width: reference.width,
                height: reference.height,
                values,
            },
        })
    }

    /// Compare two images (prepares both).
    pub fn compare(&self, reference: &LinearImage, test: &LinearImage) -> Result<FlipScore> {
        same_size(reference, test)?;
        self.compare_prepared(&self.prepare(reference), &self.prepare(test))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_images_score_zero_and_filters_are_normalised() {
        let img = LinearImage::new(
            7,
            5,
            (0..35).map(|i| Vec3::splat(i as f32 / 35.0)).collect(),
        )
        .unwrap();
        let f = Flip::new(67.02);
        let s = f.compare(&img, &img).unwrap();
        assert_eq!(s.mean, 0.0);
        let sum_y: f32 = f.spatial.iter().map(|t| t.0[0]).sum();
        assert!((sum_y - 1.0).abs() < 1e-5);
        let g: f32 = f.features.iter().map(|t| t[0]).sum();
        assert!((g - 1.0).abs() < 1e-5);
    }

    #[test]
    fn black_versus_white_is_near_maximal() {
        // The largest achromatic difference: ΔE_c is remapped above pt.
        let black = LinearImage::new(4, 4, vec![Vec3::ZERO; 16]).unwrap();
        let white = LinearImage::new(4, 4, vec![Vec3::ONE; 16]).unwrap();
        let s = Flip::new(67.02).compare(&black, &white).unwrap();
        assert!(s.mean > 0.9, "{}", s.mean);
    }
}
