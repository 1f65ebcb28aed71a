//! Uniform meshes: a surface's constrained Delaunay triangulation refined (minimum angle 25
//! degrees) until its triangles reach a target size, the same size everywhere.

use penumbra_scenes::{Surface, SurfaceId};

use crate::cdt::SurfaceTriangulation;
use crate::error::MeshError;
use crate::mesh::SurfaceMesh;
use crate::tolerances::MIN_ANGLE_DEG;

/// Meshes one surface with about `target` triangles (never more, unless the polygon itself needs
/// more than `target` to be triangulated at all).
pub fn mesh_surface_uniform(
    id: SurfaceId,
    surface: &Surface,
    target: usize,
) -> Result<SurfaceMesh, MeshError> {
    Ok(SurfaceTriangulation::of_surface(id, surface)?
        .refined(target, MIN_ANGLE_DEG)
        .into_mesh(id, surface))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;
    use penumbra_scenes::Rgb;

    fn l_shape() -> Surface {
        let p = [
            (-1.0, -1.0),
            (1.0, -1.0),
            (1.0, 0.0),
            (0.0, 0.0),
            (0.0, 1.0),
            (-1.0, 1.0),
        ];
        Surface::new(
            "l",
            p.iter().map(|&(x, y)| DVec3::new(x, 0.3 * y, y)).collect(),
            Rgb::splat(0.5),
        )
    }

    #[test]
    fn uniform_mesh_is_sane_and_near_its_target() {
        let s = l_shape();
        for target in [4, 10, 100, 1000, 5000] {
            let m = mesh_surface_uniform(0, &s, target).expect("the L shape meshes");
            m.sanity_check().expect("sane mesh");
            assert!(
                m.triangle_count() <= target.max(4),
                "{} > {target}",
                m.triangle_count()
            );
            if target >= 100 {
                assert!(
                    m.triangle_count() as f64 >= 0.75 * target as f64,
                    "{} for {target}",
                    m.triangle_count()
                );
                assert!(m.quality().min_angle_deg >= MIN_ANGLE_DEG - 1e-9);
            }
            // The mesh covers the surface's own polygon up to the snap.
            assert!((m.area() - s.area()).abs() <= 1e-9 * s.area());
        }
    }

    #[test]
    fn moved_rotated_and_scaled_surfaces_mesh_identically() {
        let s = l_shape();
        let reference = mesh_surface_uniform(0, &s, 500).expect("meshes");
        let map = glam::DAffine3::from_scale_rotation_translation(
            DVec3::splat(1e-3),
            glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0),
            DVec3::new(5.0, -7.0, 3.0),
        );
        let mut moved = s.clone();
        moved
            .polygon
            .iter_mut()
            .for_each(|p| *p = map.transform_point3(*p));
        let m = mesh_surface_uniform(0, &moved, 500).expect("meshes");
        assert_eq!(m.local, reference.local);
        assert_eq!(m.triangles, reference.triangles);
        for (a, b) in m.points3.iter().zip(&reference.points3) {
            assert!((*a - map.transform_point3(*b)).length() < 1e-12);
        }
    }
}
