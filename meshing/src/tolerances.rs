//! The meshing crate's named tolerances and angles, each with why it has its value; every other
//! module reads them from here. Lengths are in mesh units, where the polygon's extent is 1.

/// Constraint endpoints closer than this (in mesh units, where the polygon's extent is 1) are
/// one vertex: 2^-30, about 1e-9.
pub(crate) const MERGE_DISTANCE: f64 = 1.0 / (1u64 << 30) as f64;

/// Relative agreement required between the triangles' total area and the meshed polygon's.
pub(crate) const AREA_CHECK_TOLERANCE: f64 = 1e-12;

/// How far (in mesh units, where the polygon's extent is 1) a vertex that splits a boundary or
/// constraint edge may sit off the exact segment: the rounding of the split point.
pub(crate) const ON_SEGMENT_TOLERANCE: f64 = 1e-12;

/// Smallest angle uniform refinement aims for: unconstrained polygons have no small input
/// angles, and Ruppert's refinement with spade's off-centres terminates well beyond 20.7°.
pub(crate) const MIN_ANGLE_DEG: f64 = 25.0;

/// Smallest angle the refinement of constrained meshes aims for by default: constraints may meet
/// at any angle, and 20 degrees keeps Ruppert's refinement from cascading around them.
pub const CONSTRAINED_MIN_ANGLE_DEG: f64 = 20.0;

/// The largest smallest angle refinement can be asked for: Ruppert's refinement terminates up
/// to about 20.7°, and spade's off-centre variant somewhat beyond; above 30° it may not.
pub const MAX_MIN_ANGLE_DEG: f64 = 30.0;

/// Smallest angle restored after adaptive splits. Longest-edge bisection alone keeps angles from
/// collapsing (to no less than half the smallest one it starts from); a higher bound would spend
/// triangles on shape where the error estimate asks for none. On the Cornell floor, direct light
/// only, 30,000 triangles: RMS error 0.096 % with 5 degrees, 0.099 % with 10, 0.142 % with 25.
pub const SPLIT_MIN_ANGLE_DEG: f64 = 5.0;

/// Wedges between input edges narrower than this force the angles of the corners in them
/// ([`crate::MeshQuality::min_angle_unforced_deg`]): the angle quality refinement aims for.
pub const FORCING_WEDGE_DEG: f64 = CONSTRAINED_MIN_ANGLE_DEG;

#[cfg(test)]
mod tests {
    use super::*;

    /// The angles refinement aims for stay where Ruppert's refinement terminates, and the ones
    /// that depend on each other agree.
    #[test]
    fn the_angles_are_ones_refinement_reaches() {
        const {
            assert!(SPLIT_MIN_ANGLE_DEG < CONSTRAINED_MIN_ANGLE_DEG);
            // Ruppert's bound, 20.7°: constraints meeting at any angle do not make it cascade.
            assert!(CONSTRAINED_MIN_ANGLE_DEG <= 20.7);
            assert!(MIN_ANGLE_DEG <= MAX_MIN_ANGLE_DEG);
        };
    }

    /// Merging is coarser than the rounding a split point may carry, and both are far above
    /// f64's rounding of coordinates of size 1 and far below any feature a mesh keeps.
    #[test]
    fn the_lengths_are_ordered() {
        assert_eq!(MERGE_DISTANCE, 2f64.powi(-30));
        const {
            assert!(ON_SEGMENT_TOLERANCE < MERGE_DISTANCE);
            assert!(ON_SEGMENT_TOLERANCE > 1e3 * f64::EPSILON);
            assert!(AREA_CHECK_TOLERANCE > 1e3 * f64::EPSILON);
        };
    }
}
