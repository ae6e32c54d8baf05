//! The minimal enclosing sphere of a point set: the bound lodeval frames renders with and measures
//! on-screen size by.
//!
//! Based on: Emo Welzl. Smallest enclosing disks (balls and ellipsoids). New Results and New
//! Trends in Computer Science, LNCS 555, 1991 — the randomised incremental algorithm in its
//! iterative form: `md(P, R)` (the smallest ball enclosing `P` with `R` on its boundary) unrolled
//! into four nested loops for three dimensions, one per point of `R`, each loop restarting over the
//! points before the one that broke the current ball. With the points in random order it runs in
//! expected linear time. The order is a fixed-seed shuffle, so the result is the same on every run.
//!
//! Why minimal, not Ritter's two-pass approximation: the minimal sphere is unique and moves
//! continuously with the points, so a mesh and a simplification of it (nearly the same extreme
//! points) get nearly the same sphere. Ritter's sphere depends on which point the passes start from
//! and which farthest pair they find; on the Stanford bunny and its 50 % LOD its centres were 28 %
//! of a radius apart, enough to misalign two renders of nearly the same shape.
//!
//! Numerics: the work is in `f64`; the balls through two, three and four boundary points are
//! solved in closed form relative to the first point. Rounding can make a point that is in fact on
//! a ball's surface test as outside, and near-degenerate boundary sets (three nearly collinear or
//! four nearly coplanar points) have no stable circumsphere. The containment test has a relative
//! tolerance of 1e-10, and a degenerate set falls back to the smallest ball through a subset that
//! encloses the rest. The `f32` sphere returned is then grown, if needed, until every point is
//! inside in `f32` arithmetic, so "contains every vertex" holds exactly as the renderer computes it.

use glam::{DVec3, Vec3};
use rand_core::{Rng, SeedableRng};

use super::bounds::Sphere;

/// The minimal sphere enclosing a non-empty point set (Welzl 1991). Deterministic.
pub fn minimal_sphere(points: &[Vec3]) -> Sphere {
    let mut p: Vec<DVec3> = points.iter().map(|q| q.as_dvec3()).collect();
    shuffle(&mut p);
    let mut ball = Ball::through_one(p[0]);
    for i in 1..p.len() {
        if !ball.contains(p[i]) {
            ball = with_one(&p[..i], p[i]);
        }
    }
    // The box's circumscribed sphere bounds the minimal one from above; past it, rounding won.
    let aabb = super::bounds::Aabb::of(points);
    let radius = ball.radius_sq.sqrt();
    if radius.is_nan() || radius > aabb.diagonal() as f64 * 0.5 * (1.0 + 1e-6) {
        ball = Ball {
            center: aabb.center().as_dvec3(),
            radius_sq: (aabb.diagonal() as f64 * 0.5).powi(2),
        };
    }
    let center = ball.center.as_vec3();
    // Containment exactly as f32 arithmetic computes it (the renderer's), plus a few ulps.
    let max_d = points
        .iter()
        .map(|q| q.distance(center))
        .fold(0.0f32, f32::max);
    Sphere {
        center,
        radius: (ball.radius_sq.sqrt() as f32).max(max_d) * (1.0 + 4.0 * f32::EPSILON),
    }
}

/// Fisher–Yates with a fixed seed: the random order Welzl's expected bound needs, same every run.
fn shuffle(p: &mut [DVec3]) {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0x5eed_ba11);
    for i in (1..p.len()).rev() {
        let j = (rng.next_u64() % (i as u64 + 1)) as usize;
        p.swap(i, j);
    }
}

/// Smallest ball enclosing `pts` with `q` on its boundary.
fn with_one(pts: &[DVec3], q: DVec3) -> Ball {
    let mut ball = Ball::through_one(q);
    for j in 0..pts.len() {
        if !ball.contains(pts[j]) {
            ball = with_two(&pts[..j], q, pts[j]);
        }
    }
    ball
}

/// Smallest ball enclosing `pts` with `a` and `b` on its boundary.
fn with_two(pts: &[DVec3], a: DVec3, b: DVec3) -> Ball {
    let mut ball = Ball::through_two(a, b);
    for k in 0..pts.len() {
        if !ball.contains(pts[k]) {
            ball = with_three(&pts[..k], a, b, pts[k]);
        }
    }
    ball
}

/// Smallest ball enclosing `pts` with `a`, `b` and `c` on its boundary.
fn with_three(pts: &[DVec3], a: DVec3, b: DVec3, c: DVec3) -> Ball {
    let mut ball = Ball::through_three(a, b, c);
    for &d in pts {
        if !ball.contains(d) {
            ball = Ball::through_four(a, b, c, d);
        }
    }
    ball
}

/// A ball in `f64`: centre and squared radius.
#[derive(Debug, Clone, Copy)]
struct Ball {
    center: DVec3,
    radius_sq: f64,
}

impl Ball {
    /// Relative slack of the containment test (rounding in the circumsphere solutions).
    const SLACK: f64 = 1e-10;

    fn contains(&self, p: DVec3) -> bool {
        p.distance_squared(self.center) <= self.radius_sq * (1.0 + Self::SLACK)
    }

    /// Whether every point is inside.
    fn encloses(&self, points: &[DVec3]) -> bool {
        points.iter().all(|&p| self.contains(p))
    }

    fn through_one(a: DVec3) -> Ball {
        Ball {
            center: a,
            radius_sq: 0.0,
        }
    }

    fn through_two(a: DVec3, b: DVec3) -> Ball {
        Ball {
            center: (a + b) * 0.5,
            radius_sq: a.distance_squared(b) * 0.25,
        }
    }

    /// The ball whose great circle is the triangle's circumcircle. Nearly collinear corners fall
    /// back to the ball on the farthest pair (it encloses the third).
    fn through_three(a: DVec3, b: DVec3, c: DVec3) -> Ball {
        let (u, v) = (b - a, c - a);
        let n = u.cross(v);
        let denom = 2.0 * n.length_squared();
        let scale = u.length_squared() * v.length_squared();
        if denom <= 1e-24 * scale {
            return Self::smallest_enclosing(&[a, b, c], &[(0, 1), (0, 2), (1, 2)]);
        }
        let offset = (v.length_squared() * n.cross(u) + u.length_squared() * v.cross(n)) / denom;
        Ball {
            center: a + offset,
            radius_sq: offset.length_squared(),
        }
    }

    /// The circumsphere of a tetrahedron. Nearly coplanar corners fall back to the smallest ball
    /// through three of them that encloses the fourth.
    fn through_four(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Ball {
        let (u, v, w) = (b - a, c - a, d - a);
        let det = u.dot(v.cross(w));
        let scale = u.length() * v.length() * w.length();
        let offset = (u.length_squared() * v.cross(w)
            + v.length_squared() * w.cross(u)
            + w.length_squared() * u.cross(v))
            / (2.0 * det);
        // Coplanar within rounding (f32 vertices of a rotated flat part are): the "circumsphere"
        // is far off the plane. No ball through four points needs a radius 1000 × their spread.
        let spread_sq = u
            .length_squared()
            .max(v.length_squared())
            .max(w.length_squared());
        let far = offset.length_squared();
        if det.abs() <= 1e-12 * scale || far.is_nan() || far > 1e6 * spread_sq {
            let all = [a, b, c, d];
            return [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]
                .iter()
                .map(|t| Self::through_three(all[t[0]], all[t[1]], all[t[2]]))
                .filter(|ball| ball.encloses(&all))
                .min_by(|x, y| x.radius_sq.total_cmp(&y.radius_sq))
                .unwrap_or_else(|| Self::smallest_enclosing(&all, &PAIRS_OF_FOUR));
        }
        Ball {
            center: a + offset,
            radius_sq: offset.length_squared(),
        }
    }

    /// The smallest of the balls on the given pairs that encloses every point (the farthest pair
    /// always does for collinear points, the fallback's case).
    fn smallest_enclosing(points: &[DVec3], pairs: &[(usize, usize)]) -> Ball {
        pairs
            .iter()
            .map(|&(i, j)| Self::through_two(points[i], points[j]))
            .filter(|ball| ball.encloses(points))
            .min_by(|x, y| x.radius_sq.total_cmp(&y.radius_sq))
            .unwrap_or_else(|| {
                // Nothing on a pair encloses all (not collinear after all): the widest pair's
                // ball grown to the farthest point, an enclosing ball in any case.
                let center = points.iter().copied().sum::<DVec3>() / points.len() as f64;
                let radius_sq = points
                    .iter()
                    .map(|p| p.distance_squared(center))
                    .fold(0.0, f64::max);
                Ball { center, radius_sq }
            })
    }
}

const PAIRS_OF_FOUR: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

#[cfg(test)]
mod tests {
    use super::*;

    /// The minimal enclosing ball by brute force: the smallest ball through 2, 3 or 4 of the
    /// points that encloses all of them.
    fn brute_force(points: &[Vec3]) -> f64 {
        let p: Vec<DVec3> = points.iter().map(|q| q.as_dvec3()).collect();
        let n = p.len();
        let mut best = f64::INFINITY;
        let mut consider = |ball: Ball| {
            if p.iter()
                .all(|&q| q.distance_squared(ball.center) <= ball.radius_sq * (1.0 + 1e-9))
            {
                best = best.min(ball.radius_sq.sqrt());
            }
        };
        for i in 0..n {
            for j in i + 1..n {
                consider(Ball::through_two(p[i], p[j]));
                for k in j + 1..n {
                    consider(Ball::through_three(p[i], p[j], p[k]));
                    for l in k + 1..n {
                        consider(Ball::through_four(p[i], p[j], p[k], p[l]));
                    }
                }
            }
        }
        best
    }

    fn cloud(seed: u64, n: usize) -> Vec<Vec3> {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let mut unit = || (rng.next_u64() >> 11) as f32 / (1u64 << 53) as f32 * 2.0 - 1.0;
        (0..n)
            .map(|_| Vec3::new(unit(), unit() * 0.5, unit() * 0.25))
            .collect()
    }

    #[test]
    fn the_sphere_is_the_minimal_one_found_by_brute_force() {
        for seed in 0..20 {
            let pts = cloud(seed, 14);
            let s = minimal_sphere(&pts);
            assert!(pts.iter().all(|p| p.distance(s.center) <= s.radius));
            let exact = brute_force(&pts);
            let rel = (s.radius as f64 - exact).abs() / exact;
            assert!(rel < 1e-5, "seed {seed}: {} vs {exact}", s.radius);
        }
    }

    #[test]
    fn cube_corners_give_the_circumscribed_sphere() {
        let pts: Vec<Vec3> = (0..8)
            .map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32))
            .collect();
        let s = minimal_sphere(&pts);
        assert!((s.radius - 3f32.sqrt() / 2.0).abs() < 1e-6, "{}", s.radius);
        assert!(s.center.distance(Vec3::splat(0.5)) < 1e-6);
    }

    #[test]
    fn degenerate_sets_collinear_coplanar_and_repeated_points() {
        // Collinear: the ball on the two ends.
        let line: Vec<Vec3> = (0..50).map(|i| Vec3::new(i as f32, 0.0, 0.0)).collect();
        let s = minimal_sphere(&line);
        assert!((s.radius - 24.5).abs() < 1e-4 && (s.center.x - 24.5).abs() < 1e-4);
        // Coplanar: a regular 12-gon in z = 3 has its circumcircle as the great circle.
        let ring: Vec<Vec3> = (0..12)
            .map(|i| {
                let a = i as f32 * std::f32::consts::TAU / 12.0;
                Vec3::new(a.cos() * 2.0, a.sin() * 2.0, 3.0)
            })
            .collect();
        let s = minimal_sphere(&ring);
        assert!((s.radius - 2.0).abs() < 1e-5 && s.center.distance(Vec3::Z * 3.0) < 1e-5);
        // One point, repeated.
        let same = vec![Vec3::new(1.0, 2.0, 3.0); 10];
        let s = minimal_sphere(&same);
        assert_eq!(s.center, Vec3::new(1.0, 2.0, 3.0));
        assert!(s.radius < 1e-5);
    }

    #[test]
    fn a_rotated_flat_grid_gets_its_circumscribed_circle() {
        // A 21 × 21 grid of side 2 in a tilted plane: f32 rounding makes it not quite coplanar.
        let rot = glam::Quat::from_euler(glam::EulerRot::XYZ, 0.7, 0.3, 1.1);
        let pts: Vec<Vec3> = (0..21 * 21)
            .map(|i| {
                rot * Vec3::new(
                    (i % 21) as f32 * 0.1 - 1.0,
                    (i / 21) as f32 * 0.1 - 1.0,
                    0.0,
                )
            })
            .collect();
        let s = minimal_sphere(&pts);
        assert!((s.radius - 2f32.sqrt()).abs() < 1e-5, "{}", s.radius);
        assert!(s.center.length() < 1e-5);
    }

    #[test]
    fn a_small_change_to_the_points_moves_the_sphere_a_little() {
        // Removing interior points or nudging one changes nothing / little: the sphere is set by
        // its (at most four) support points alone.
        let pts = cloud(99, 2000);
        let s = minimal_sphere(&pts);
        let mut fewer: Vec<Vec3> = pts
            .iter()
            .copied()
            .filter(|p| p.distance(s.center) < 0.9 * s.radius)
            .collect();
        fewer.extend(
            pts.iter()
                .filter(|p| p.distance(s.center) >= 0.9 * s.radius),
        );
        let t = minimal_sphere(&fewer[fewer.len() / 2..]);
        assert!(t.center.distance(s.center) < 1e-5 * s.radius);
        assert!((t.radius - s.radius).abs() < 1e-5 * s.radius);
    }
}
