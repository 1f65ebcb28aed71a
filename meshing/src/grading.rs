//! Where a discontinuity mesh should be finer: in partial shadow.
//!
//! Between its discontinuity lines the direct light is smooth, but in a penumbra it bends much
//! faster than in full light, because the whole emitter's light is gained across the penumbra's
//! width. Linear interpolation errs by the element size squared times that curvature, so for a
//! given number of triangles the error is least when penumbra triangles are smaller (for an error
//! measured in L2, the best element area goes as curvature^(-2/3)).
//!
//! A pilot refinement of the constrained triangulation is probed: a pilot triangle is *varying*
//! when some emitter is partly visible from its centroid or from its corners (pulled slightly
//! inward), or when those points disagree. Triangles never cross discontinuity lines, so the
//! varying ones cover the penumbrae closely. Varying triangles ask for `factor` times smaller
//! triangles. (Asking for more where the pilot's triangles are crowded by constraints, as in the
//! thin penumbra at the foot of a blocker, cost more triangles than it saved error on the Cornell
//! box's floor.)

use glam::{DVec2, DVec3};
use rayon::prelude::*;
use spade::{PositionInTriangulation, Triangulation as _};

use crate::cdt::{Cdt, SizeField, SurfaceTriangulation};
use crate::mesh_coordinates::MeshCoordinates;

/// How many times smaller in area triangles in a penumbra are than elsewhere, by default: about
/// the curvature ratio between penumbra and full light in the built-in scenes, to the power 2/3.
pub const DEFAULT_PENUMBRA_DENSITY: f64 = 8.0;
/// Pilot triangles per final triangle.
const PILOT_SHARE: f64 = 0.25;
/// Where the corners of a pilot triangle are probed: this far from each corner to the centroid.
const CORNER_PULL: f64 = 0.1;

/// A piecewise constant density over a surface: how many times smaller in area its triangles
/// should be than the base size.
#[derive(Clone)]
pub(crate) struct Density {
    pilot: Cdt,
    /// By pilot face index.
    factors: Vec<f64>,
    max_factor: f64,
}

impl std::fmt::Debug for Density {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Density")
            .field("pilot_faces", &self.factors.len())
            .field("max_factor", &self.max_factor)
            .finish()
    }
}

impl Density {
    /// Probes a pilot refinement of `triangulation` with about `PILOT_SHARE * target`
    /// triangles. `varies` gets the probe points of one pilot triangle (in 3D) and says whether
    /// the light varies over them.
    pub(crate) fn probe(
        triangulation: &SurfaceTriangulation,
        target: usize,
        factor: f64,
        varies: &(dyn Fn(&[DVec3]) -> bool + Sync),
    ) -> Density {
        let pilot_target = ((target as f64 * PILOT_SHARE) as usize).max(1);
        let pilot_area = triangulation.area_for(pilot_target);
        // Refined once to its share's size: quality refinement around the constraints may take
        // it over that share, which is fine for a probe.
        let pilot = triangulation
            .refined_to_area(
                pilot_area,
                crate::tolerances::CONSTRAINED_MIN_ANGLE_DEG,
                pilot_target,
            )
            .0;
        let coords = &triangulation.coords;
        let mut factors = vec![1.0; pilot.num_all_faces()];
        let factor = factor.max(1.0);
        let probes: Vec<(usize, Vec<DVec3>)> = pilot
            .inner_faces()
            .filter_map(|face| {
                let corners = face.positions().map(|p| DVec2::new(p.x, p.y));
                let centroid = (corners[0] + corners[1] + corners[2]) / 3.0;
                if !penumbra_scenes::polygon::inside_polygon(centroid, &coords.boundary) {
                    return None;
                }
                let mut points = vec![to_3d(coords, centroid)];
                points.extend(
                    corners
                        .iter()
                        .map(|&c| to_3d(coords, c.lerp(centroid, CORNER_PULL))),
                );
                Some((face.fix().index(), points))
            })
            .collect();
        let marked: Vec<usize> = probes
            .par_iter()
            .filter(|(_, points)| varies(points))
            .map(|&(face, _)| face)
            .collect();
        for face in marked {
            factors[face] = factor;
        }
        Density {
            pilot,
            factors,
            max_factor: factor,
        }
    }
}

impl SizeField for Density {
    /// The density at `p` (mesh coordinates); on a pilot edge or vertex, the largest around it.
    fn at(&self, p: DVec2) -> f64 {
        let of_face =
            |f: spade::handles::FixedFaceHandle<spade::handles::InnerTag>| self.factors[f.index()];
        match self.pilot.locate(spade::Point2::new(p.x, p.y)) {
            PositionInTriangulation::OnFace(f) => of_face(f),
            PositionInTriangulation::OnEdge(e) => {
                let e = self.pilot.directed_edge(e);
                [e.face(), e.rev().face()]
                    .into_iter()
                    .filter_map(|f| f.as_inner().map(|f| of_face(f.fix())))
                    .fold(1.0, f64::max)
            }
            PositionInTriangulation::OnVertex(v) => self
                .pilot
                .vertex(v)
                .out_edges()
                .filter_map(|e| e.face().as_inner().map(|f| of_face(f.fix())))
                .fold(1.0, f64::max),
            _ => 1.0,
        }
    }

    /// The largest density anywhere.
    fn max_factor(&self) -> f64 {
        self.max_factor
    }
}

fn to_3d(coords: &MeshCoordinates, p: DVec2) -> DVec3 {
    coords.frame.to_3d(p * coords.scale)
}
