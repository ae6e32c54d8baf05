//! Bounding volumes: the axis-aligned box, the bounding sphere lodeval frames and sizes objects by
//! (the minimal enclosing sphere, computed in `enclosing.rs`), and the bounds game engines measure their
//! LOD switch parameters by ([`EngineBounds`]: Unity, Unreal, glTF `MSFT_lod` as Babylon.js reads
//! it), each as that engine's source defines it.

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

/// The bound each engine computes its LOD switch parameter from, for the same vertices. Engines
/// do not use the minimal sphere lodeval frames by; an engine value computed from lodeval's
/// sphere would put the switch somewhere else than the engine does.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct EngineBounds {
    /// The box centre: the point every engine below measures the camera distance to (Unity's
    /// `LODGroup.localReferencePoint` after `RecalculateBounds`, Unreal's `Bounds.Origin`,
    /// Babylon's `boundingSphere.centerWorld`).
    pub center: Vec3,
    /// Unity `LODGroup.size`: the largest side of the box (`RecalculateBounds`). Relative screen
    /// height = size / (2 · D · tan(fov/2)) (`LODUtility.DistanceToRelativeHeight`).
    pub unity_size: f32,
    /// Unreal `FBoxSphereBounds::SphereRadius` of a mesh built from its vertices: the farthest
    /// vertex from the box centre (`FBoxSphereBounds(const FVector*, uint32)`). `ScreenSize` =
    /// 2 · max(P₀₀, P₁₁)/2 · R / D (`ComputeBoundsScreenSize`).
    pub unreal_radius: f32,
    /// glTF `MSFT_screencoverage` as Babylon.js, the extension's reference loader, evaluates it:
    /// its `BoundingSphere` from the box is centred on it with half the box diagonal as radius,
    /// and coverage = π (R / D)² / (4 tan²(fov/2) · aspect) (`Mesh.getLOD`, `Camera.screenArea`).
    pub babylon_radius: f32,
}

impl EngineBounds {
    /// The engines' bounds of a non-empty point set.
    pub fn of(points: &[Vec3]) -> EngineBounds {
        let aabb = Aabb::of(points);
        let center = aabb.center();
        let size = aabb.max - aabb.min;
        EngineBounds {
            center,
            unity_size: size.max_element(),
            unreal_radius: points
                .iter()
                .map(|p| p.distance(center))
                .fold(0.0f32, f32::max),
            babylon_radius: aabb.diagonal() * 0.5,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn engine_bounds_of_a_box_with_one_far_corner() {
        // A 4 × 2 × 1 box's corners: Unity's size is the largest side, Babylon's radius half the
        // diagonal; Unreal's radius is the farthest corner from the centre (the same here).
        let mut pts: Vec<Vec3> = (0..8)
            .map(|i| {
                Vec3::new(
                    (i & 1) as f32 * 4.0,
                    ((i >> 1) & 1) as f32 * 2.0,
                    ((i >> 2) & 1) as f32,
                )
            })
            .collect();
        let half_diagonal = (16.0f32 + 4.0 + 1.0).sqrt() / 2.0;
        let b = EngineBounds::of(&pts);
        assert_eq!(b.center, Vec3::new(2.0, 1.0, 0.5));
        assert_eq!(b.unity_size, 4.0);
        assert!((b.babylon_radius - half_diagonal).abs() < 1e-6);
        assert!((b.unreal_radius - half_diagonal).abs() < 1e-6);
        // An octahedron's tips inside that box: Unreal's radius is the farthest vertex, smaller.
        pts = vec![
            Vec3::new(0.0, 1.0, 0.5),
            Vec3::new(4.0, 1.0, 0.5),
            Vec3::new(2.0, 0.0, 0.5),
            Vec3::new(2.0, 2.0, 0.5),
            Vec3::new(2.0, 1.0, 0.0),
            Vec3::new(2.0, 1.0, 1.0),
        ];
        let b = EngineBounds::of(&pts);
        assert_eq!(b.unreal_radius, 2.0);
        assert!((b.babylon_radius - half_diagonal).abs() < 1e-6);
        let s = super::super::enclosing::minimal_sphere(&pts);
        assert!((s.radius - 2.0).abs() < 1e-5);
    }
}
