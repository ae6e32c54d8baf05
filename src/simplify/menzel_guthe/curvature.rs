//! §4.3: the curvatures that map a field's angular frequencies to frequencies on the surface —
//! the principal curvatures κ_min, κ_max and direction of minimal curvature of a local patch, and
//! the mean torsial curvature κ_n (how fast the tangent frame turns about the normal as one moves
//! across the surface).
//!
//! Based on: Menzel & Guthe 2010, §4.3 (κ_n = √((∂τ/∂u)² + (∂τ/∂v)²), "the mean absolute
//! derivative of the torsion"). Gabriel Taubin. Estimating the Tensor of Curvature of a Surface
//! from a Polyhedral Approximation. ICCV 1995 — the normal curvature along the edge to a
//! neighbour q, κ(t) = −2·n·(q − p)/|q − p|² (positive where the surface bends away from its
//! normal, as on a sphere with outward normals), here fitted in the least-squares sense by the
//! shape operator's quadratic form κ(t) = a·c² + 2b·c·s + e·s² in the tangent plane (three
//! unknowns; its eigenvalues are κ_min ≤ κ_max, in absolute value as the frequency mapping needs
//! magnitudes).
//!
//! Decision: the torsion gradient is the least-squares gradient of the angle by which the
//! neighbours' minimal-curvature directions, carried into the vertex's tangent plane, are turned
//! from its own (an angle modulo π: principal directions have no sign). Where a patch is nearly
//! umbilic (the two curvatures within 10 % of each other, a sphere or a plane) the directions are
//! undefined and κ_n is 0.

use glam::Vec3;

/// Curvatures of a local patch.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Curvature {
    /// Smaller principal curvature magnitude, 1/model unit.
    pub k_min: f32,
    /// Larger principal curvature magnitude, 1/model unit.
    pub k_max: f32,
    /// Direction of minimal curvature (unit, in the tangent plane; any where umbilic).
    pub dir_min: Vec3,
    /// Mean torsial curvature κ_n, radians per model unit.
    pub torsion: f32,
}

impl Curvature {
    /// Whether the principal directions are meaningful (not umbilic).
    pub fn anisotropic(&self) -> bool {
        self.k_max - self.k_min > 0.1 * self.k_max.max(1e-30)
    }
}

/// The shape operator at `p` with normal `n` from its neighbours `ring` (at least three).
pub fn at(p: Vec3, n: Vec3, ring: &[Vec3]) -> Curvature {
    let n = n.normalize_or(Vec3::Z);
    let e1 = n.any_orthonormal_vector();
    let e2 = n.cross(e1);
    // Normal equations of κ_j = a·c² + 2b·c·s + e·s², rows (c², 2cs, s²).
    let mut ata = [[0.0f64; 3]; 3];
    let mut atb = [0.0f64; 3];
    let mut rows = 0;
    for &q in ring {
        let d = q - p;
        let len2 = d.length_squared();
        if len2 <= 0.0 {
            continue;
        }
        let tangent = d - n * n.dot(d);
        let tl = tangent.length();
        if tl <= 0.0 {
            continue;
        }
        let (c, s) = ((tangent.dot(e1) / tl) as f64, (tangent.dot(e2) / tl) as f64);
        let kappa = (-2.0 * n.dot(d) / len2) as f64;
        let row = [c * c, 2.0 * c * s, s * s];
        for i in 0..3 {
            for j in 0..3 {
                ata[i][j] += row[i] * row[j];
            }
            atb[i] += row[i] * kappa;
        }
        rows += 1;
    }
    let Some([a, b, e]) = (rows >= 3).then(|| solve3(ata, atb)).flatten() else {
        return Curvature {
            dir_min: e1,
            ..Curvature::default()
        };
    };
    // Eigen-decomposition of [[a, b], [b, e]].
    let mean = 0.5 * (a + e);
    let radius = (0.25 * (a - e) * (a - e) + b * b).sqrt();
    let (l1, l2) = (mean - radius, mean + radius);
    // Eigenvector of l1: (b, l1 − a) or (l1 − e, b).
    let v = if b.abs() > 1e-12 * radius.max(1e-300) {
        (b, l1 - a)
    } else if a <= e {
        (1.0, 0.0)
    } else {
        (0.0, 1.0)
    };
    let (k1, k2) = (l1.abs() as f32, l2.abs() as f32);
    // The direction of the smaller magnitude.
    let dir1 = (e1 * v.0 as f32 + e2 * v.1 as f32).normalize_or(e1);
    let dir2 = n.cross(dir1);
    let (k_min, k_max, dir_min) = if k1 <= k2 {
        (k1, k2, dir1)
    } else {
        (k2, k1, dir2)
    };
    Curvature {
        k_min,
        k_max,
        dir_min,
        torsion: 0.0,
    }
}

/// Solve a 3 × 3 system by Cramer's rule (`None` when singular).
fn solve3(m: [[f64; 3]; 3], r: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(m);
    let scale = m.iter().flatten().map(|x| x.abs()).fold(0.0, f64::max);
    if d.abs() <= 1e-12 * scale.powi(3) {
        return None;
    }
    let mut out = [0.0; 3];
    for (k, o) in out.iter_mut().enumerate() {
        let mut mk = m;
        for i in 0..3 {
            mk[i][k] = r[i];
        }
        *o = det(mk) / d;
    }
    Some(out)
}

/// κ_n at a vertex (position `p`, normal `n`, curvature `own`) from its neighbours' positions and
/// curvatures.
pub fn torsion(p: Vec3, n: Vec3, own: &Curvature, ring: &[(Vec3, Curvature)]) -> f32 {
    if !own.anisotropic() {
        return 0.0;
    }
    let n = n.normalize_or(Vec3::Z);
    let e1 = own.dir_min;
    let e2 = n.cross(e1);
    // Least squares Δψ_j ≈ g·(x_j, y_j) over the anisotropic neighbours.
    let (mut sxx, mut sxy, mut syy, mut sx, mut sy) = (0.0f64, 0.0, 0.0, 0.0, 0.0);
    let mut count = 0;
    for (q, c) in ring {
        if !c.anisotropic() {
            continue;
        }
        let d = *q - p;
        let (x, y) = (d.dot(e1) as f64, d.dot(e2) as f64);
        let carried = c.dir_min - n * n.dot(c.dir_min);
        if carried.length_squared() < 1e-12 {
            continue;
        }
        let mut psi = (carried.dot(e2) as f64).atan2(carried.dot(e1) as f64);
        // Modulo π into (−π/2, π/2].
        while psi > std::f64::consts::FRAC_PI_2 {
            psi -= std::f64::consts::PI;
        }
        while psi <= -std::f64::consts::FRAC_PI_2 {
            psi += std::f64::consts::PI;
        }
        sxx += x * x;
        sxy += x * y;
        syy += y * y;
        sx += x * psi;
        sy += y * psi;
        count += 1;
    }
    let det = sxx * syy - sxy * sxy;
    if count < 2 || det.abs() <= 1e-24 * (sxx + syy).powi(2) {
        return 0.0;
    }
    let gx = (syy * sx - sxy * sy) / det;
    let gy = (sxx * sy - sxy * sx) / det;
    (gx * gx + gy * gy).sqrt() as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points of a ring of radius `r` (tangent distance) around `p` on a surface given by the
    /// height function `h(x, y)` (the surface z = h, normal +z at the origin).
    fn ring(h: impl Fn(f32, f32) -> f32, r: f32) -> Vec<Vec3> {
        (0..8)
            .map(|k| {
                let a = std::f32::consts::TAU * k as f32 / 8.0 + 0.1;
                let (x, y) = (r * a.cos(), r * a.sin());
                Vec3::new(x, y, h(x, y))
            })
            .collect()
    }

    #[test]
    fn principal_curvatures_of_a_sphere_and_a_cylinder() {
        // A sphere of radius 2 seen from outside: the surface bends away from the normal +z.
        let radius = 2.0f32;
        let sphere = |x: f32, y: f32| (radius * radius - x * x - y * y).sqrt() - radius;
        let c = at(Vec3::ZERO, Vec3::Z, &ring(sphere, 0.05));
        assert!(
            (c.k_min - 0.5).abs() < 0.01 && (c.k_max - 0.5).abs() < 0.01,
            "{c:?}"
        );
        assert!(!c.anisotropic());
        // A cylinder of radius 0.5 along y: 0 along the axis, 2 around it.
        let cylinder = |x: f32, _y: f32| (0.25 - x * x).sqrt() - 0.5;
        let c = at(Vec3::ZERO, Vec3::Z, &ring(cylinder, 0.02));
        assert!(
            c.k_min.abs() < 0.02 && (c.k_max - 2.0).abs() < 0.05,
            "{c:?}"
        );
        assert!(c.dir_min.dot(Vec3::Y).abs() > 0.999, "{:?}", c.dir_min);
        // A plane: none.
        let c = at(Vec3::ZERO, Vec3::Z, &ring(|_, _| 0.0, 0.1));
        assert!(c.k_max.abs() < 1e-6);
    }

    #[test]
    fn torsion_is_the_turning_rate_of_the_principal_directions() {
        // Neighbours whose minimal-curvature directions turn by 0.3 rad per unit along x.
        let own = Curvature {
            k_min: 0.0,
            k_max: 1.0,
            dir_min: Vec3::X,
            torsion: 0.0,
        };
        let ring: Vec<(Vec3, Curvature)> = (0..8)
            .map(|k| {
                let a = std::f32::consts::TAU * k as f32 / 8.0;
                let q = Vec3::new(0.1 * a.cos(), 0.1 * a.sin(), 0.0);
                let psi = 0.3 * q.x;
                let c = Curvature {
                    dir_min: Vec3::new(psi.cos(), psi.sin(), 0.0),
                    ..own
                };
                (q, c)
            })
            .collect();
        let t = torsion(Vec3::ZERO, Vec3::Z, &own, &ring);
        assert!((t - 0.3).abs() < 1e-3, "{t}");
        // No turning, no torsion.
        let still: Vec<(Vec3, Curvature)> = ring.iter().map(|(q, _)| (*q, own)).collect();
        assert!(torsion(Vec3::ZERO, Vec3::Z, &own, &still) < 1e-6);
    }
}
