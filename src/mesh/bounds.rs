//! Bounding volumes: axis-aligned box and bounding sphere.
//!
//! Based on: Jack Ritter. An Efficient Bounding Sphere. Graphics Gems 1990 — the two-pass
//! approximation (about 5–20 % larger than the minimal sphere), then a final pass that grows the
//! sphere until every vertex is inside even after floating-point rounding.

use glam::Vec3;

/// An axis-aligned bounding box in model units.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Aabb {
    /// Minimum corner.
    pub min: Vec3,
    /// Maximum corner.
    pub max: Vec3,
}

impl Aabb {
    /// The box of a non-empty point set.
    pub fn of(points: &[Vec3]) -> Aabb {
        let init = Aabb {
            min: Vec3::splat(f32::INFINITY),
            max: Vec3::splat(f32::NEG_INFINITY),
        };
        points.iter().fold(init, |b, &p| Aabb {
            min: b.min.min(p),
            max: b.max.max(p),
        })
    }
    /// Length of the box diagonal (the usual scale for relative geometric errors).
    pub fn diagonal(&self) -> f32 {
        (self.max - self.min).length()
    }
    /// Box centre.
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }
}

/// A sphere that contains every vertex.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Sphere {
    /// Centre in model units.
    pub center: Vec3,
    /// Radius in model units.
    pub radius: f32,
}

impl Sphere {
    /// Ritter's bounding sphere of a non-empty point set.
    pub fn ritter(points: &[Vec3]) -> Sphere {
        // Pass 1: from an arbitrary point find the farthest x, then from x the farthest y.
        let farthest = |from: Vec3| {
            points
                .iter()
                .copied()
                .fold((from, -1.0f32), |(best, d), p| {
                    let dp = p.distance_squared(from);
                    if dp > d { (p, dp) } else { (best, d) }
                })
                .0
        };
        let x = farthest(points[0]);
        let y = farthest(x);
        let mut center = (x + y) * 0.5;
        let mut radius = x.distance(y) * 0.5;
        // Pass 2: grow the sphere to include every point outside it.
        for &p in points {
            let d = p.distance(center);
            if d > radius {
                let new_radius = (radius + d) * 0.5;
                center += (p - center) * ((new_radius - radius) / d);
                radius = new_radius;
            }
        }
        // Pass 3: rounding can leave points a few ulps outside; make containment exact.
        let max_d = points
            .iter()
            .map(|p| p.distance(center))
            .fold(0.0f32, f32::max);
        Sphere {
            center,
            radius: radius.max(max_d) * (1.0 + 4.0 * f32::EPSILON),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_contains_every_point_and_is_near_minimal_for_a_cube() {
        // The 8 corners of a unit cube: the minimal sphere has radius sqrt(3)/2.
        let pts: Vec<Vec3> = (0..8)
            .map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32))
            .collect();
        let s = Sphere::ritter(&pts);
        assert!(pts.iter().all(|p| p.distance(s.center) <= s.radius));
        assert!(s.radius < 3f32.sqrt() / 2.0 * 1.2);
        let b = Aabb::of(&pts);
        assert_eq!((b.min, b.max), (Vec3::ZERO, Vec3::ONE));
    }
}
