//! §4.2: the difference of two points' signals — the rotation between their tangent frames as the
//! angles α_t, α_b, α_n, the phase shift it causes at each frequency, and the largest difference
//! δ_max of two oscillations whose phases differ by up to that shift.
//!
//! Based on: Menzel & Guthe 2010, §4.2. The rotation angles from the quaternion q of the rotation
//! between the frames: α_{t,b,n} = q_{x,y,z}/|q_xyz| · 2·arcsin|q_xyz| (the rotation vector in the
//! first frame's coordinates: tangent, bitangent, normal).
//!
//! Decisions where the text is garbled in the project's copy:
//! - The phase shift. The copy prints φ² = α_t²/ω_t² + …, a shift that would shrink as the
//!   frequency grows. A phase is an angle turned times the oscillation's wave number, so φ is
//!   read as √((ω_t·α_t)² + (ω_b·α_b)² + (ω_n·α_n)²). For a spherical harmonic of degree l the
//!   wave number of a tilt is √(l(l+1)) whatever the tilt's axis (a rotation keeps a function
//!   within its degree; √(l(l+1)) is the degree's eigenvalue of the Laplacian), so the two
//!   tangential terms combine to l(l+1)·(α_t² + α_b²); along α_n the wave number is the DFT's
//!   frequency ω_n (cycles per turn).
//! - δ_max. The copy prints δ_max = min(a₁, a₂) + |a₁ − a₂|·√(2 − 2cos φ_max) with
//!   φ_max = max(φ + φ_s, π). Two oscillations of amplitudes a₁, a₂ with phases φ apart differ by
//!   |a₁e^{iφ} − a₂| ≤ min(a₁, a₂)·|e^{iφ} − 1| + |a₁ − a₂| = min(a₁, a₂)·√(2 − 2cos φ) +
//!   |a₁ − a₂|, and "the maximum difference of the two signals with any phase shift up to the
//!   computed one" grows with the shift up to π and no further: so δ_max = min(a₁, a₂)·√(2 − 2cos
//!   φ_max) + |a₁ − a₂| with φ_max = min(φ + φ_s, π). (Taken literally, max(·, π) would make every
//!   pair of signals differ by the full 2·min(a₁, a₂), even two identical ones.)
//! - φ_s, "the phase shift between the two signals in their local coordinate systems", is the
//!   angle between the two slots' coefficient vectors (`spectrum.rs`).

use glam::{Mat3, Quat, Vec3};

/// A point's tangent frame: tangent, bitangent, normal (orthonormal, right-handed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Tangent (the direction of minimal curvature where there is one).
    pub t: Vec3,
    /// Bitangent, n × t.
    pub b: Vec3,
    /// Normal.
    pub n: Vec3,
}

impl Frame {
    /// The frame of normal `n` with tangent along `t` projected onto its plane (any
    /// perpendicular when `t` is parallel to `n` or zero).
    pub fn new(n: Vec3, t: Vec3) -> Frame {
        let n = n.normalize_or(Vec3::Z);
        let mut t = t - n * n.dot(t);
        if t.length_squared() < 1e-12 {
            t = n.any_orthonormal_vector();
        }
        let t = t.normalize();
        Frame {
            t,
            b: n.cross(t),
            n,
        }
    }

    fn matrix(&self) -> Mat3 {
        Mat3::from_cols(self.t, self.b, self.n)
    }
}

/// The rotation taking frame `a` to frame `b`, as angles (α_t, α_b, α_n) about `a`'s tangent,
/// bitangent and normal, radians. A tangent that is only defined up to sign (a principal
/// direction) is taken in the orientation that turns less.
pub fn angles(a: &Frame, b: &Frame) -> Vec3 {
    let flipped = Frame {
        t: -b.t,
        b: -b.b,
        n: b.n,
    };
    let one = rotation_vector(a, b);
    let two = rotation_vector(a, &flipped);
    if two.length_squared() < one.length_squared() {
        two
    } else {
        one
    }
}

/// The rotation vector (axis × angle) from `a` to `b` in `a`'s coordinates.
fn rotation_vector(a: &Frame, b: &Frame) -> Vec3 {
    // Local rotation R = Aᵀ·B maps a's coordinates of b's axes.
    let r = a.matrix().transpose() * b.matrix();
    let q = Quat::from_mat3(&r).normalize();
    // q and −q are one rotation: take w ≥ 0 (angle ≤ π).
    let q = if q.w < 0.0 { -q } else { q };
    let v = Vec3::new(q.x, q.y, q.z);
    let s = v.length();
    if s < 1e-12 {
        return Vec3::ZERO;
    }
    v / s * (2.0 * s.min(1.0).asin())
}

/// The phase shift of a slot of degree `l` and α_n frequency `w` under rotation `alpha`.
#[inline]
pub fn phase(alpha: Vec3, l: usize, w: usize) -> f32 {
    let ll = (l * (l + 1)) as f32;
    (ll * (alpha.x * alpha.x + alpha.y * alpha.y) + (w as f32 * alpha.z).powi(2)).sqrt()
}

/// δ_max of amplitudes `a1`, `a2` whose phases differ by up to `phi` (radians).
#[inline]
pub fn delta_max(a1: f32, a2: f32, phi: f32) -> f32 {
    let p = phi.min(std::f32::consts::PI);
    a1.min(a2) * (2.0 - 2.0 * p.cos()).max(0.0).sqrt() + (a1 - a2).abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angles_of_known_rotations() {
        let a = Frame::new(Vec3::Z, Vec3::X);
        // 30° about the normal.
        let r = Quat::from_rotation_z(30f32.to_radians());
        let b = Frame::new(r * Vec3::Z, r * Vec3::X);
        let g = angles(&a, &b);
        assert!((g.z - 30f32.to_radians()).abs() < 1e-5 && g.x.abs() < 1e-5 && g.y.abs() < 1e-5);
        // 10° about the tangent: the normal tilts towards −bitangent.
        let r = Quat::from_rotation_x(10f32.to_radians());
        let b = Frame::new(r * Vec3::Z, r * Vec3::X);
        let g = angles(&a, &b);
        assert!((g.x - 10f32.to_radians()).abs() < 1e-5, "{g}");
        // A principal direction's sign does not count: a half turn of the tangent is no turn.
        let b = Frame::new(Vec3::Z, -Vec3::X);
        assert!(angles(&a, &b).length() < 1e-5);
        // Identical frames: nothing.
        assert_eq!(angles(&a, &a), Vec3::ZERO);
    }

    #[test]
    fn delta_max_bounds_the_difference_of_shifted_oscillations() {
        // Equal amplitudes in phase: no difference; half a turn apart: twice the amplitude.
        assert_eq!(delta_max(2.0, 2.0, 0.0), 0.0);
        assert!((delta_max(2.0, 2.0, std::f32::consts::PI) - 4.0).abs() < 1e-6);
        // The shift saturates at π.
        assert_eq!(
            delta_max(2.0, 2.0, 10.0),
            delta_max(2.0, 2.0, std::f32::consts::PI)
        );
        // An amplitude change alone is the change.
        assert!((delta_max(3.0, 2.0, 0.0) - 1.0).abs() < 1e-6);
        // It bounds the true difference |a1·e^{iφ} − a2| for any φ up to the shift.
        for (a1, a2, phi) in [(1.0f32, 0.3f32, 0.7f32), (0.2, 2.0, 2.5), (1.5, 1.4, 0.1)] {
            let exact = (a1 * a1 + a2 * a2 - 2.0 * a1 * a2 * phi.cos()).sqrt();
            assert!(delta_max(a1, a2, phi) >= exact - 1e-6);
        }
        // Phase: degree l tilted by α shifts by √(l(l+1))·α.
        let p = phase(Vec3::new(0.1, 0.0, 0.0), 3, 0);
        assert!((p - 12f32.sqrt() * 0.1).abs() < 1e-6);
        assert!((phase(Vec3::new(0.0, 0.0, 0.2), 0, 4) - 0.8).abs() < 1e-6);
    }
}
