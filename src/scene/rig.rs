//! View rigs: the set of directions a model is rendered from, with a stable numbering.
//!
//! Directions point from the model's centre towards the camera. The numbering is part of the
//! output schemas (`view` column of metrics.csv), so each list below is in a fixed, documented order
//! and never sorted by anything computed.
//!
//! Based on: the regular dodecahedron and icosahedron vertex sets (golden ratio φ coordinates);
//! Lindstrom & Turk §4.1 (20 uniformly distributed views); the Fibonacci sphere as in
//! Álvaro González, Measurement of Areas on a Sphere Using Fibonacci and Latitude–Longitude
//! Lattices, Mathematical Geosciences 2010.

use glam::Vec3;

use super::Camera;
use crate::mesh::Mesh;

const PHI: f32 = 1.618_034;

/// A set of view directions.
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub enum Rig {
    /// The 20 vertices of a regular dodecahedron (the default).
    #[default]
    Dodecahedron,
    /// The 12 vertices of a regular icosahedron.
    Icosahedron,
    /// N points of a Fibonacci lattice on the sphere (N ≥ 1).
    Fibonacci(u32),
    /// Explicit directions (each non-zero; normalised on use).
    Explicit(Vec<Vec3>),
}

impl Rig {
    /// Cameras for every view, in view-number order, each framing `mesh`'s bounding sphere at the
    /// default field of view and margin, for images of width/height `aspect`.
    pub fn cameras(&self, mesh: &Mesh, aspect: f32) -> Vec<Camera> {
        self.cameras_framing(mesh.bounding_sphere(), aspect)
    }

    /// Cameras for every view framing `sphere` (another mesh's, to render a LOD exactly as its
    /// original was framed).
    pub fn cameras_framing(&self, sphere: crate::mesh::Sphere, aspect: f32) -> Vec<Camera> {
        self.directions()
            .into_iter()
            .map(|d| {
                Camera::frame_sphere(
                    sphere,
                    d,
                    Camera::DEFAULT_FOV_Y_DEG,
                    aspect,
                    Camera::DEFAULT_MARGIN,
                )
            })
            .collect()
    }

    /// Unit directions from the model's centre towards each camera, in view-number order.
    pub fn directions(&self) -> Vec<Vec3> {
        let s = [1.0f32, -1.0];
        let dirs: Vec<Vec3> = match self {
            Rig::Dodecahedron => {
                let (a, b) = (1.0 / PHI, PHI);
                let mut v = Vec::with_capacity(20);
                // (±1, ±1, ±1)
                for x in s {
                    for y in s {
                        for z in s {
                            v.push(Vec3::new(x, y, z));
                        }
                    }
                }
                // (0, ±1/φ, ±φ), (±1/φ, ±φ, 0), (±φ, 0, ±1/φ)
                for p in s {
                    for q in s {
                        v.push(Vec3::new(0.0, p * a, q * b));
                    }
                }
                for p in s {
                    for q in s {
                        v.push(Vec3::new(p * a, q * b, 0.0));
                    }
                }
                for p in s {
                    for q in s {
                        v.push(Vec3::new(p * b, 0.0, q * a));
                    }
                }
                v
            }
            Rig::Icosahedron => {
                let mut v = Vec::with_capacity(12);
                // (0, ±1, ±φ), (±1, ±φ, 0), (±φ, 0, ±1)
                for p in s {
                    for q in s {
                        v.push(Vec3::new(0.0, p, q * PHI));
                    }
                }
                for p in s {
                    for q in s {
                        v.push(Vec3::new(p, q * PHI, 0.0));
                    }
                }
                for p in s {
                    for q in s {
                        v.push(Vec3::new(p * PHI, 0.0, q));
                    }
                }
                v
            }
            Rig::Fibonacci(n) => {
                let n = (*n).max(1);
                let golden_angle = std::f32::consts::PI * (3.0 - 5f32.sqrt());
                (0..n)
                    .map(|i| {
                        let y = 1.0 - (2.0 * i as f32 + 1.0) / n as f32;
                        let r = (1.0 - y * y).max(0.0).sqrt();
                        let t = golden_angle * i as f32;
                        Vec3::new(r * t.cos(), y, r * t.sin())
                    })
                    .collect()
            }
            Rig::Explicit(v) => v.clone(),
        };
        dirs.into_iter().map(|d| d.normalize_or(Vec3::Z)).collect()
    }

    /// The number of views, without building them.
    pub fn count(&self) -> usize {
        match self {
            Rig::Dodecahedron => 20,
            Rig::Icosahedron => 12,
            Rig::Fibonacci(n) => (*n).max(1) as usize,
            Rig::Explicit(v) => v.len(),
        }
    }

    /// Parse `dodecahedron`, `icosahedron` or `fibonacci:N` (N within
    /// [`crate::limits::VIEWS`]); the error is the message for the user.
    pub fn parse(text: &str) -> Result<Rig, String> {
        let unknown =
            || format!("unknown rig '{text}': use dodecahedron, icosahedron or fibonacci:N");
        match text {
            "dodecahedron" => Ok(Rig::Dodecahedron),
            "icosahedron" => Ok(Rig::Icosahedron),
            _ => {
                let n = text.strip_prefix("fibonacci:").ok_or_else(unknown)?;
                let n: u64 = n.trim().parse().map_err(|_| unknown())?;
                let n = crate::limits::VIEWS.check("fibonacci:", n)?;
                Ok(Rig::Fibonacci(n as u32))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn platonic_rigs_are_uniform() {
        // Every vertex of a regular polyhedron has the same nearest-neighbour distance; on the
        // unit sphere: dodecahedron edge/circumradius = 4/(sqrt(3)(1+sqrt(5))) ≈ 0.7136,
        // icosahedron ≈ 1.0515.
        for (rig, n, edge) in [
            (Rig::Dodecahedron, 20, 0.713_644),
            (Rig::Icosahedron, 12, 1.051_462),
        ] {
            let d = rig.directions();
            assert_eq!(d.len(), n);
            for (i, a) in d.iter().enumerate() {
                let nearest = d
                    .iter()
                    .enumerate()
                    .filter(|&(j, _)| j != i)
                    .map(|(_, b)| a.distance(*b))
                    .fold(f32::MAX, f32::min);
                assert!((nearest - edge).abs() < 1e-4, "{rig:?} view {i}: {nearest}");
            }
            // Symmetric sets: the directions sum to zero.
            assert!(d.iter().copied().sum::<Vec3>().length() < 1e-5);
        }
    }

    #[test]
    fn fibonacci_has_n_unit_directions_and_parses() {
        let d = Rig::parse("fibonacci:50").unwrap().directions();
        assert_eq!(d.len(), 50);
        assert!(d.iter().all(|v| (v.length() - 1.0).abs() < 1e-6));
        assert!(
            Rig::parse("fibonacci:0")
                .unwrap_err()
                .contains("limits of 1 to 10000")
        );
        let huge = Rig::parse("fibonacci:4000000000").unwrap_err();
        assert!(huge.contains("fibonacci: 4000000000"), "{huge}");
        for rig in [Rig::Dodecahedron, Rig::Icosahedron, Rig::Fibonacci(7)] {
            assert_eq!(rig.count(), rig.directions().len());
        }
        assert!(
            Rig::parse("cube")
                .unwrap_err()
                .contains("unknown rig 'cube'")
        );
    }
}
