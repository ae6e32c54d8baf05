//! Mergeable bounds of a patch of surface, as Williams et al. 2003 keep them per Multi-Triangulation
//! node (§4, §5.3): a bounding sphere, normal cones (the silhouette cone of face normals and the
//! shading cone of vertex or normal-map normals), and an intrinsic luminance range.
//!
//! Based on: the normal cones of David Luebke and Carl Erikson, View-Dependent Simplification of
//! Arbitrary Polygonal Environments, SIGGRAPH 1997 (a cone = axis + half-angle bounding a set of
//! unit normals; merging two cones gives the smallest cone holding both), used by Williams et al.
//! for the silhouette test and the lighting contrast.
//!
//! Every merge is conservative: the merged bound holds everything either input held.

use glam::Vec3;

/// A bounding sphere; an empty sphere has a negative radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ball {
    /// Centre.
    pub center: Vec3,
    /// Radius (< 0: empty).
    pub radius: f32,
}

impl Ball {
    /// Holds nothing.
    pub const EMPTY: Ball = Ball {
        center: Vec3::ZERO,
        radius: -1.0,
    };

    /// A sphere holding `points`: centre at their mean, radius to the farthest.
    pub fn of_points(points: &[Vec3]) -> Ball {
        if points.is_empty() {
            return Ball::EMPTY;
        }
        let c = points.iter().copied().sum::<Vec3>() / points.len() as f32;
        let r = points.iter().map(|p| p.distance(c)).fold(0.0, f32::max);
        Ball {
            center: c,
            radius: r,
        }
    }

    /// The smallest sphere holding both spheres.
    pub fn merge(self, o: Ball) -> Ball {
        if self.radius < 0.0 {
            return o;
        }
        if o.radius < 0.0 {
            return self;
        }
        let d = o.center - self.center;
        let dist = d.length();
        if dist + o.radius <= self.radius {
            return self;
        }
        if dist + self.radius <= o.radius {
            return o;
        }
        let radius = 0.5 * (dist + self.radius + o.radius);
        let center = self.center + d * ((radius - self.radius) / dist.max(f32::MIN_POSITIVE));
        // Round-off grows the radius by a hair so containment survives f32 arithmetic.
        Ball {
            center,
            radius: radius * (1.0 + 1e-6),
        }
    }
}

/// A cone of unit normals: every normal n in it has angle(n, axis) ≤ half_angle. An empty cone
/// has a negative half-angle; a cone with half_angle ≥ π holds every direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cone {
    /// Unit axis.
    pub axis: Vec3,
    /// Half opening angle in radians.
    pub half_angle: f32,
}

impl Cone {
    /// Holds nothing.
    pub const EMPTY: Cone = Cone {
        axis: Vec3::Z,
        half_angle: -1.0,
    };
    /// Holds every direction.
    pub const ALL: Cone = Cone {
        axis: Vec3::Z,
        half_angle: std::f32::consts::PI,
    };

    /// The cone of one direction (zero-length vectors give the empty cone).
    pub fn of(n: Vec3) -> Cone {
        match n.try_normalize() {
            Some(axis) => Cone {
                axis,
                half_angle: 0.0,
            },
            None => Cone::EMPTY,
        }
    }

    /// Whether nothing is in the cone.
    pub fn is_empty(&self) -> bool {
        self.half_angle < 0.0
    }

    /// The cone grown by `angle` radians (every normal may tilt by up to `angle`).
    pub fn widen(self, angle: f32) -> Cone {
        if self.is_empty() {
            return self;
        }
        Cone {
            axis: self.axis,
            half_angle: (self.half_angle + angle).min(std::f32::consts::PI),
        }
    }

    /// The smallest cone holding both cones.
    pub fn merge(self, o: Cone) -> Cone {
        if self.is_empty() {
            return o;
        }
        if o.is_empty() {
            return self;
        }
        let between = self.axis.dot(o.axis).clamp(-1.0, 1.0).acos();
        if between + o.half_angle <= self.half_angle {
            return self;
        }
        if between + self.half_angle <= o.half_angle {
            return o;
        }
        let half = 0.5 * (between + self.half_angle + o.half_angle);
        if half >= std::f32::consts::PI {
            return Cone::ALL;
        }
        // Rotate self's axis towards o's by (half − self.half_angle) in their common plane.
        let turn = half - self.half_angle;
        let ortho = (o.axis - self.axis * self.axis.dot(o.axis)).try_normalize();
        let axis = match ortho {
            Some(u) => (self.axis * turn.cos() + u * turn.sin()).normalize(),
            // Opposite axes: any perpendicular plane works; the result holds every direction
            // within `half` of the new axis, and `half` ≥ π/2 here.
            None => self.axis.any_orthonormal_vector(),
        };
        Cone {
            axis,
            // A small allowance keeps containment through f32 round-off.
            half_angle: (half + 1e-5).min(std::f32::consts::PI),
        }
    }

    /// The range of cos(angle to `d`) over the cone: (min, max), for unit `d`.
    pub fn cos_range(&self, d: Vec3) -> (f32, f32) {
        if self.is_empty() {
            return (0.0, 0.0);
        }
        let theta = self.axis.dot(d).clamp(-1.0, 1.0).acos();
        let lo = (theta + self.half_angle).min(std::f32::consts::PI).cos();
        let hi = (theta - self.half_angle).max(0.0).cos();
        (lo, hi)
    }
}

/// A closed range of luminance; empty when lo > hi.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// Smallest value.
    pub lo: f32,
    /// Largest value.
    pub hi: f32,
}

impl Range {
    /// Holds nothing.
    pub const EMPTY: Range = Range {
        lo: f32::INFINITY,
        hi: f32::NEG_INFINITY,
    };

    /// One value.
    pub fn of(v: f32) -> Range {
        Range { lo: v, hi: v }
    }

    /// Whether nothing is in the range.
    pub fn is_empty(&self) -> bool {
        self.lo > self.hi
    }

    /// The range holding both.
    pub fn merge(self, o: Range) -> Range {
        Range {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn merged_cones_hold_both_inputs() {
        // Random cones, merged pairwise: every axis direction and every rim direction of each
        // input lies inside the result (the smallest-enclosing construction must not lose any).
        let dirs = crate::scene::Rig::Fibonacci(40).directions();
        for (i, &a) in dirs.iter().enumerate() {
            let b = dirs[(i * 7 + 3) % dirs.len()];
            let ca = Cone::of(a).widen(0.1 * (i % 5) as f32);
            let cb = Cone::of(b).widen(0.05 * (i % 3) as f32);
            let m = ca.merge(cb);
            for c in [ca, cb] {
                let ortho = c.axis.any_orthonormal_vector();
                for k in 0..16 {
                    let phi = k as f32 * std::f32::consts::TAU / 16.0;
                    let side = glam::Quat::from_axis_angle(c.axis, phi) * ortho;
                    let rim =
                        glam::Quat::from_axis_angle(side.cross(c.axis).normalize(), -c.half_angle)
                            * c.axis;
                    let ang = rim.dot(m.axis).clamp(-1.0, 1.0).acos();
                    assert!(ang <= m.half_angle + 1e-4, "{ang} > {}", m.half_angle);
                }
            }
            assert!(m.half_angle <= ca.half_angle.max(cb.half_angle) + std::f32::consts::PI);
        }
        // Opposite normals need the whole sphere's half.
        let m = Cone::of(Vec3::Z).merge(Cone::of(-Vec3::Z));
        assert!(m.half_angle >= std::f32::consts::FRAC_PI_2 - 1e-5);
    }

    #[test]
    fn merged_balls_hold_both_inputs() {
        let a = Ball {
            center: Vec3::ZERO,
            radius: 1.0,
        };
        let b = Ball {
            center: Vec3::new(3.0, 0.0, 0.0),
            radius: 0.5,
        };
        let m = a.merge(b);
        assert!((m.radius - 2.25).abs() < 1e-4);
        assert!(m.center.distance(Vec3::ZERO) + 1.0 <= m.radius + 1e-4);
        assert!(m.center.distance(b.center) + 0.5 <= m.radius + 1e-4);
        assert_eq!(a.merge(Ball::EMPTY), a);
        // Nested: the bigger one.
        let small = Ball {
            center: Vec3::new(0.2, 0.0, 0.0),
            radius: 0.1,
        };
        assert_eq!(a.merge(small), a);
    }

    #[test]
    fn cos_range_of_a_cone() {
        let c = Cone::of(Vec3::Z).widen(0.5);
        let (lo, hi) = c.cos_range(Vec3::Z);
        assert!((hi - 1.0).abs() < 1e-6 && (lo - 0.5f32.cos()).abs() < 1e-6);
        let (lo, hi) = c.cos_range(Vec3::X);
        assert!((hi - (std::f32::consts::FRAC_PI_2 - 0.5).cos()).abs() < 1e-5);
        assert!((lo - (std::f32::consts::FRAC_PI_2 + 0.5).cos()).abs() < 1e-5);
    }
}
