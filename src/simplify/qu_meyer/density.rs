//! §5.2: the sampling density — how many vertices each part of the surface should get, from the
//! curvature map and the masking map, each with its gamma, compensated for the area distortion
//! of the parameterisation — and each chart's share of the budget.
//!
//! Based on: Qu & Meyer §5.2 ("high curvature areas and low visual masking texture areas require
//! denser sampling ... the curvature gamma adjusts the relative importance of the curvature map,
//! the visual perceptual gamma that of the visual perceptual map"); Alliez et al. 2002 §3.3 (the
//! density in the parametric domain is the 3D one times the area distortion, so that samples
//! per 3D area follow the 3D density).
//!
//! Per texel: ρ₃ = (1 + κ/κ̄)^γ_c · M^(−γ_p), and in the domain ρ = ρ₃ · (3D area / UV area),
//! where κ̄ is the area-weighted mean curvature and M ≥ 0 the masking map (1: no masking).
//! Both gammas 0 give a uniform density on the surface (the paper's baseline). The exponent form
//! for M follows from the error a linear interpolation makes: its deviation grows with h²κ, and
//! a threshold raised M times allows M times the deviation, so at γ_c = γ_p = 1 the vertex
//! density goes with κ/M. The paper's figures use γ_c = 1.2 and γ_p = 1 or 2; the "1 +" keeps
//! flat parts sampled at all (the paper does not say how it treats κ = 0).

/// The density maps.
#[derive(Debug, Clone)]
pub struct Density {
    /// ρ₃ per texel: relative vertex density on the surface (0 where uncovered).
    pub surface: Vec<f32>,
    /// ρ per texel: the density in the parametric domain (0 where uncovered).
    pub domain: Vec<f32>,
    /// Per chart, Σ ρ₃ · (3D area of the texel): its share of the surface's "mass".
    pub chart_mass: Vec<f64>,
}

impl Density {
    /// The density from the curvature map, the masking map, the area distortion and the 3D area
    /// of each texel, over `charts` charts.
    pub fn new(
        curvature: &[f32],
        masking: &[f32],
        maps: &super::maps::Maps,
        charts: usize,
        gammas: (f64, f64),
    ) -> Density {
        let (gc, gp) = (gammas.0 as f32, gammas.1 as f32);
        let total_area: f64 = maps.area.iter().map(|&a| a as f64).sum();
        let mean_k = if total_area > 0.0 {
            (curvature
                .iter()
                .zip(&maps.area)
                .map(|(&k, &a)| k as f64 * a as f64)
                .sum::<f64>()
                / total_area) as f32
        } else {
            0.0
        };
        let n = curvature.len();
        let mut surface = vec![0.0f32; n];
        let mut domain = vec![0.0f32; n];
        let mut chart_mass = vec![0.0f64; charts];
        for i in 0..n {
            let c = maps.chart[i];
            if c == u32::MAX {
                continue;
            }
            let k = if mean_k > 0.0 {
                1.0 + curvature[i] / mean_k
            } else {
                1.0
            };
            let r = k.powf(gc) * masking[i].max(1e-3).powf(-gp);
            surface[i] = r;
            domain[i] = r * maps.distortion[i];
            chart_mass[c as usize] += r as f64 * maps.area[i] as f64;
        }
        Density {
            surface,
            domain,
            chart_mass,
        }
    }

    /// The total mass.
    pub fn mass(&self) -> f64 {
        self.chart_mass.iter().sum()
    }
}

/// Split `total` into whole parts proportional to `weights` (largest remainders, ties to the
/// lower index), so the parts add up to `total` exactly.
pub fn apportion(total: usize, weights: &[f64]) -> Vec<usize> {
    let sum: f64 = weights.iter().sum();
    if sum <= 0.0 || weights.is_empty() {
        return vec![0; weights.len()];
    }
    let exact: Vec<f64> = weights.iter().map(|w| w / sum * total as f64).collect();
    let mut parts: Vec<usize> = exact.iter().map(|e| e.floor() as usize).collect();
    let given: usize = parts.iter().sum();
    let mut order: Vec<usize> = (0..weights.len()).collect();
    order.sort_by(|&a, &b| {
        let (ra, rb) = (exact[a] - exact[a].floor(), exact[b] - exact[b].floor());
        rb.total_cmp(&ra).then(a.cmp(&b))
    });
    for &i in order.iter().take(total.saturating_sub(given)) {
        parts[i] += 1;
    }
    parts
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn apportion_adds_up_and_follows_the_weights() {
        assert_eq!(apportion(10, &[1.0, 1.0]), vec![5, 5]);
        assert_eq!(apportion(10, &[3.0, 1.0]), vec![8, 2]);
        assert_eq!(apportion(7, &[1.0, 1.0, 1.0]), vec![3, 2, 2]);
        assert_eq!(apportion(5, &[0.0, 0.0]), vec![0, 0]);
        let p = apportion(1000, &[0.1, 0.25, 0.65]);
        assert_eq!(p.iter().sum::<usize>(), 1000);
        assert_eq!(p, vec![100, 250, 650]);
    }
}
