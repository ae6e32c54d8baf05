//! Clipping in homogeneous clip space (Sutherland–Hodgman) against the near and far planes and a
//! guard band around the viewport.
//!
//! Based on: Ivan Sutherland, Gary Hodgman. Reentrant Polygon Clipping. CACM 1974. Jim Blinn,
//! Martin Newell. Clipping Using Homogeneous Coordinates. SIGGRAPH 1978.
//!
//! Only triangles that cross a plane are clipped; the rest pass untouched (trivial accept) or are
//! dropped (trivial reject). The guard band is wide (see `fixed.rs`), so x/y clipping is rare and
//! exists only to keep fixed-point coordinates in range. Every output vertex carries its
//! barycentric coordinates with respect to the original triangle, so attributes are interpolated
//! from the original vertices whatever the clipping did.

use glam::{Vec3, Vec4};

/// A clip-space vertex with barycentrics relative to the source triangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ClipVertex {
    pub pos: Vec4,
    pub bary: Vec3,
}

/// Plane set for one viewport: each plane keeps points with `dot(plane, pos) >= 0`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ClipPlanes {
    planes: [Vec4; 6],
    guard: [f32; 2],
}

impl ClipPlanes {
    /// Near (z ≥ 0), far (z ≤ w) and guard band |x| ≤ gx·w, |y| ≤ gy·w, where gx, gy are the
    /// guard-band extents in NDC units (for depth range 0..1).
    pub fn new(guard_ndc_x: f32, guard_ndc_y: f32) -> ClipPlanes {
        ClipPlanes {
            planes: [
                Vec4::new(0.0, 0.0, 1.0, 0.0),
                Vec4::new(0.0, 0.0, -1.0, 1.0),
                Vec4::new(-1.0, 0.0, 0.0, guard_ndc_x),
                Vec4::new(1.0, 0.0, 0.0, guard_ndc_x),
                Vec4::new(0.0, -1.0, 0.0, guard_ndc_y),
                Vec4::new(0.0, 1.0, 0.0, guard_ndc_y),
            ],
            guard: [guard_ndc_x, guard_ndc_y],
        }
    }

    /// The planes for a viewport of `width` × `height` pixels with the guard band of `fixed.rs`.
    pub fn for_viewport(width: u32, height: u32) -> ClipPlanes {
        let g = super::fixed::GUARD_BAND_PX;
        ClipPlanes::new(1.0 + 2.0 * g / width as f32, 1.0 + 2.0 * g / height as f32)
    }

    /// Bit mask of the planes a point is outside of.
    /// (The planes' dot products written out: every vertex of every frame goes through this.)
    pub fn outcode(&self, p: Vec4) -> u8 {
        let (gx, gy) = (self.guard[0] * p.w, self.guard[1] * p.w);
        (p.z < 0.0) as u8
            | ((p.w - p.z < 0.0) as u8) << 1
            | ((gx - p.x < 0.0) as u8) << 2
            | ((p.x + gx < 0.0) as u8) << 3
            | ((gy - p.y < 0.0) as u8) << 4
            | ((p.y + gy < 0.0) as u8) << 5
    }

    /// Clip a triangle given as three vertices whose outcodes are not all zero and share no bit.
    /// Returns the clipped convex polygon (possibly empty), at most 9 vertices.
    pub fn clip_polygon(&self, tri: [ClipVertex; 3]) -> Vec<ClipVertex> {
        let mut poly: Vec<ClipVertex> = tri.to_vec();
        let mut next = Vec::with_capacity(9);
        for plane in &self.planes {
            if poly.is_empty() {
                break;
            }
            next.clear();
            for i in 0..poly.len() {
                let a = poly[i];
                let b = poly[(i + 1) % poly.len()];
                let (da, db) = (plane.dot(a.pos), plane.dot(b.pos));
                if da >= 0.0 {
                    next.push(a);
                }
                if (da >= 0.0) != (db >= 0.0) {
                    let t = da / (da - db);
                    next.push(ClipVertex {
                        pos: a.pos.lerp(b.pos, t),
                        bary: a.bary.lerp(b.bary, t),
                    });
                }
            }
            std::mem::swap(&mut poly, &mut next);
        }
        poly
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_crossing_near_plane_becomes_a_quad_with_consistent_barycentrics() {
        // One vertex behind the near plane (z < 0): cutting a corner off a triangle leaves a quad.
        let planes = ClipPlanes::new(100.0, 100.0);
        let v = |x: f32, z: f32, b: Vec3| ClipVertex {
            pos: Vec4::new(x, 0.0, z, 1.0),
            bary: b,
        };
        let tri = [
            v(0.0, -0.5, Vec3::X),
            v(1.0, 0.5, Vec3::Y),
            v(-1.0, 0.5, Vec3::Z),
        ];
        let poly = planes.clip_polygon(tri);
        assert_eq!(poly.len(), 4);
        for p in &poly {
            assert!(p.pos.z >= -1e-6);
            // Barycentrics reproduce the position from the original corners.
            // Corner x coordinates are 0, 1 and -1.
            let x = p.bary.y - p.bary.z;
            assert!((x - p.pos.x).abs() < 1e-6);
            assert!((p.bary.x + p.bary.y + p.bary.z - 1.0).abs() < 1e-6);
        }
    }
}
