//! Uniform meshes: a constrained Delaunay triangulation of each surface's polygon (spade),
//! refined (Ruppert/Chew, minimum angle 25 degrees) until its triangles reach a target size.
//!
//! Triangulations are built in *mesh coordinates*: the surface's plane-frame coordinates divided
//! by the polygon's extent and snapped to a grid of 2^-36. The input to spade then depends only on
//! the polygon's shape, so a scene that is moved, rotated or scaled is meshed identically.

use glam::DVec2;
use penumbra_scenes::polygon::signed_area_2d;
use penumbra_scenes::{PlaneFrame, Surface, SurfaceId};
use spade::handles::{FixedFaceHandle, InnerTag};
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation as _,
};

use crate::error::MeshError;
use crate::grading::Density;
use crate::mesh::SurfaceMesh;

/// Grid of mesh coordinates: 2^-36 of a polygon's extent (about 1.5e-11).
pub const SNAP_BITS: i32 = 36;
/// Smallest angle the refinement aims for.
pub const MIN_ANGLE_DEG: f64 = 25.0;
/// Rounds of graded refinement: each halves the triangles still too large, so a density of
/// 2^8 is reached.
const GRADING_ROUNDS: usize = 8;

/// The triangulation type. It keeps spade's default hint generator: with
/// `HierarchyHintGenerator`, `add_constraint_and_split` panics on random crossing segments
/// (spade 2.15.1: 125 of 2,000 random sets of up to 60 segments), and the default one does not.
pub type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

pub(crate) fn snap(x: f64) -> f64 {
    let grid = 2f64.powi(SNAP_BITS);
    (x * grid).round() / grid
}

/// A surface's polygon in mesh coordinates, with the frame and scale that map it back.
#[derive(Clone, Debug)]
pub struct MeshCoordinates {
    pub frame: PlaneFrame,
    pub scale: f64,
    pub boundary: Vec<DVec2>,
}

impl MeshCoordinates {
    pub fn of_surface(id: SurfaceId, surface: &Surface) -> Result<MeshCoordinates, MeshError> {
        let degenerate = || MeshError::Degenerate {
            surface: id,
            name: surface.name.clone(),
        };
        let frame = PlaneFrame::of_polygon(&surface.polygon).ok_or_else(degenerate)?;
        let flat: Vec<DVec2> = surface.polygon.iter().map(|&p| frame.to_2d(p)).collect();
        let (lo, hi) = flat
            .iter()
            .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        let scale = (hi - lo).max_element();
        if !(scale > 0.0 && scale.is_finite()) {
            return Err(degenerate());
        }
        let mut boundary: Vec<DVec2> = flat
            .iter()
            .map(|&p| DVec2::new(snap(p.x / scale), snap(p.y / scale)))
            .collect();
        boundary.dedup();
        while boundary.len() > 1 && boundary.first() == boundary.last() {
            boundary.pop();
        }
        if boundary.len() < 3 || signed_area_2d(&boundary) <= 0.0 {
            return Err(degenerate());
        }
        Ok(MeshCoordinates {
            frame,
            scale,
            boundary,
        })
    }
}

/// The polygon's constrained triangulation and the faces outside it.
fn boundary_cdt(id: SurfaceId, coords: &MeshCoordinates) -> Result<Cdt, MeshError> {
    let mut cdt = Cdt::new();
    let n = coords.boundary.len();
    for k in 0..n {
        // The polygon is simple, so edges do not cross; splitting guards against the snap.
        insert_segment(
            &mut cdt,
            id,
            coords.boundary[k],
            coords.boundary[(k + 1) % n],
        )?;
    }
    Ok(cdt)
}

/// Inserts the segment `a-b` as a constraint, splitting any constraint it crosses (and being
/// split by it).
pub(crate) fn insert_segment(
    cdt: &mut Cdt,
    id: SurfaceId,
    a: DVec2,
    b: DVec2,
) -> Result<(), MeshError> {
    let mut insert = |p: DVec2| {
        cdt.insert(Point2::new(p.x, p.y))
            .map_err(|e| MeshError::Triangulation {
                surface: id,
                message: format!("cannot insert {p}: {e:?}"),
            })
    };
    let (ha, hb) = (insert(a)?, insert(b)?);
    if ha != hb {
        cdt.add_constraint_and_split(ha, hb, |q| q);
    }
    Ok(())
}

/// Faces of the triangulation outside the polygon (flood fill from the convex hull).
fn outside_faces(cdt: &mut Cdt) -> Vec<FixedFaceHandle<InnerTag>> {
    cdt.refine(
        RefinementParameters::<f64>::new()
            .exclude_outer_faces(true)
            .keep_constraint_edges()
            .with_angle_limit(AngleLimit::from_deg(0.0))
            .with_max_additional_vertices(0),
    )
    .excluded_faces
}

/// A surface's constrained triangulation in mesh coordinates, with the faces outside its polygon.
#[derive(Clone)]
pub(crate) struct SurfaceTriangulation {
    pub coords: MeshCoordinates,
    pub cdt: Cdt,
    pub outside: Vec<FixedFaceHandle<InnerTag>>,
    /// Whether every constraint edge lies on the polygon's boundary. spade tells inside from
    /// outside by the parity of constraint edges crossed from the hull, which constraints inside
    /// the polygon would upset; then faces are classified by their centroids instead.
    pub boundary_only: bool,
}

impl SurfaceTriangulation {
    /// The polygon's own constrained Delaunay triangulation, unrefined.
    pub fn of_surface(id: SurfaceId, surface: &Surface) -> Result<SurfaceTriangulation, MeshError> {
        let coords = MeshCoordinates::of_surface(id, surface)?;
        let cdt = boundary_cdt(id, &coords)?;
        Ok(SurfaceTriangulation::new(coords, cdt, true))
    }

    /// A triangulation of the polygon of `coords`; `boundary_only` when its only constraint
    /// edges are the polygon's.
    pub fn new(coords: MeshCoordinates, cdt: Cdt, boundary_only: bool) -> SurfaceTriangulation {
        let mut t = SurfaceTriangulation {
            coords,
            cdt,
            outside: Vec::new(),
            boundary_only,
        };
        t.find_outside();
        t
    }

    /// Recomputes the faces outside the polygon after the triangulation changed.
    pub fn find_outside(&mut self) {
        self.outside = if self.boundary_only {
            outside_faces(&mut self.cdt)
        } else {
            faces_outside_polygon(&self.cdt, &self.coords.boundary)
        };
    }

    /// Triangles inside the polygon.
    pub fn count(&self) -> usize {
        self.cdt.num_inner_faces() - self.outside.len()
    }

    /// A refinement with about `target` triangles (never more, unless the triangulation already
    /// has more) and angles of at least `min_angle_deg` where the budget allows.
    pub fn refined(&self, target: usize, min_angle_deg: f64) -> SurfaceTriangulation {
        self.calibrated(target, |max_area| {
            self.refined_to_area(max_area, min_angle_deg, target)
        })
    }

    /// Like [`Self::refined`], with triangles `density.at(p)` times smaller in area where the
    /// density asks for it: uniform refinement to a base size, then rounds that split the
    /// triangles still too large for their place (at the midpoint of their longest edge, or at
    /// their centroid when that edge is fixed), each followed by quality refinement.
    pub fn refined_graded(
        &self,
        target: usize,
        min_angle_deg: f64,
        density: &Density,
    ) -> SurfaceTriangulation {
        self.calibrated(target, |max_area| {
            let mut cdt = self.cdt.clone();
            let smallest = max_area / density.max_factor();
            self.refine_cdt(&mut cdt, min_angle_deg, Some(max_area), max_area, target);
            for _ in 0..GRADING_ROUNDS {
                let points = split_points(&cdt, |face| {
                    let centroid = face_centroid(face);
                    face.area() > max_area / density.at(centroid)
                        && crate::planar::inside_polygon(centroid, &self.coords.boundary)
                });
                if points.is_empty() || cdt.num_vertices() > 2 * target + 64 {
                    break;
                }
                for p in points {
                    // Only positions spade cannot represent fail; skipping one costs a split.
                    let _ = cdt.insert(Point2::new(p.x, p.y));
                }
                self.refine_cdt(&mut cdt, min_angle_deg, None, smallest, target);
            }
            cdt
        })
    }

    /// Splits the triangles that hold one of `points` (each once), then refines for quality
    /// (angles of at least `min_angle_deg`, nothing refined below a thousandth of the smallest
    /// split triangle). Returns how many vertices were added.
    pub fn split_triangles_at(&mut self, points: &[DVec2], min_angle_deg: f64) -> usize {
        let before = self.cdt.num_vertices();
        let mut faces = std::collections::HashSet::new();
        for p in points {
            if let spade::PositionInTriangulation::OnFace(f) =
                self.cdt.locate(Point2::new(p.x, p.y))
            {
                faces.insert(f);
            }
        }
        if faces.is_empty() {
            return 0;
        }
        let smallest = faces
            .iter()
            .map(|&f| self.cdt.face(f).area())
            .fold(f64::INFINITY, f64::min);
        let splits = split_points(&self.cdt, |face| faces.contains(&face.fix()));
        for p in splits {
            // Only positions spade cannot represent fail; skipping one costs a split.
            let _ = self.cdt.insert(Point2::new(p.x, p.y));
        }
        let mut cdt = std::mem::take(&mut self.cdt);
        let budget = cdt.num_vertices();
        self.refine_cdt(&mut cdt, min_angle_deg, None, smallest, budget);
        self.cdt = cdt;
        self.find_outside();
        self.cdt.num_vertices() - before
    }

    /// The area bound that leaves about `target` triangles in a refinement of the polygon.
    pub(crate) fn area_for(&self, target: usize) -> f64 {
        // Area-bounded refinement leaves triangles of about 0.6 of the bound.
        1.6 * signed_area_2d(&self.coords.boundary) / target.max(1) as f64
    }

    /// One refinement with triangles no larger than `max_area` (and at most about `target`
    /// more vertices than there are).
    pub(crate) fn refined_to_area(&self, max_area: f64, min_angle_deg: f64, target: usize) -> Cdt {
        let mut cdt = self.cdt.clone();
        self.refine_cdt(&mut cdt, min_angle_deg, Some(max_area), max_area, target);
        cdt
    }

    /// Runs spade's refinement: angles of at least `min_angle_deg`, triangles no larger than
    /// `max_area` (when given), none refined below a thousandth of `base_area`.
    fn refine_cdt(
        &self,
        cdt: &mut Cdt,
        min_angle_deg: f64,
        max_area: Option<f64>,
        base_area: f64,
        target: usize,
    ) {
        let mut parameters = RefinementParameters::<f64>::new()
            .exclude_outer_faces(self.boundary_only)
            .with_angle_limit(AngleLimit::from_deg(min_angle_deg))
            .with_min_required_area(1e-3 * base_area)
            .with_max_additional_vertices(target + 64);
        if let Some(max_area) = max_area {
            parameters = parameters.with_max_allowed_area(max_area);
        }
        cdt.refine(parameters);
    }

    /// The best of a few refinements made by `refine(max_area)` with the area bound calibrated so
    /// that the count comes to 90-100 % of `target`.
    fn calibrated(&self, target: usize, refine: impl Fn(f64) -> Cdt) -> SurfaceTriangulation {
        let mut best = self.clone();
        let base_count = self.count();
        if target <= base_count {
            return best;
        }
        let mut best_count = base_count;
        // Calibrate the area bound from the counts of a few trial runs.
        let mut max_area = self.area_for(target);
        for _ in 0..8 {
            let mut refined = SurfaceTriangulation {
                coords: self.coords.clone(),
                cdt: refine(max_area),
                outside: Vec::new(),
                boundary_only: self.boundary_only,
            };
            refined.find_outside();
            let count = refined.count();
            let ratio = count as f64 / target as f64;
            if count <= target && count > best_count {
                best_count = count;
                best = refined;
            }
            if (0.9..=1.0).contains(&ratio) {
                break;
            }
            max_area *= if ratio > 1.0 {
                ratio * 1.04
            } else {
                ratio * 0.98
            };
        }
        best
    }

    pub fn into_mesh(self, id: SurfaceId, surface: &Surface) -> SurfaceMesh {
        extract(id, surface, self.coords, &self.cdt, &self.outside)
    }
}

type Face<'a> = spade::handles::FaceHandle<'a, InnerTag, Point2<f64>, (), spade::CdtEdge<()>, ()>;

fn face_centroid(face: Face<'_>) -> DVec2 {
    let [a, b, c] = face.positions().map(|p| DVec2::new(p.x, p.y));
    (a + b + c) / 3.0
}

/// Where to split each face for which `wants` holds: the midpoint of its longest edge (shared
/// with the neighbour across it, once), or its centroid when that edge is a constraint or on the
/// hull. Longest-edge bisection keeps the triangles' shapes.
fn split_points(cdt: &Cdt, wants: impl Fn(Face<'_>) -> bool) -> Vec<DVec2> {
    let mut split_edges = std::collections::HashSet::new();
    let mut points = Vec::new();
    for face in cdt.inner_faces() {
        if !wants(face) {
            continue;
        }
        let longest = face
            .adjacent_edges()
            .into_iter()
            .max_by(|e, f| e.length_2().total_cmp(&f.length_2()))
            .expect("a face has three edges");
        let undirected = longest.as_undirected();
        if undirected.is_constraint_edge() || undirected.is_part_of_convex_hull() {
            points.push(face_centroid(face));
        } else if split_edges.insert(undirected.fix()) {
            let [p, q] = undirected.positions();
            points.push(DVec2::new(0.5 * (p.x + q.x), 0.5 * (p.y + q.y)));
        }
    }
    points
}

/// Faces whose centroid lies outside the polygon (exact even-odd test). Faces never straddle the
/// boundary, whose edges are constraints.
fn faces_outside_polygon(cdt: &Cdt, polygon: &[DVec2]) -> Vec<FixedFaceHandle<InnerTag>> {
    cdt.inner_faces()
        .filter(|f| {
            let [a, b, c] = f.positions();
            let centroid = DVec2::new((a.x + b.x + c.x) / 3.0, (a.y + b.y + c.y) / 3.0);
            !crate::planar::inside_polygon(centroid, polygon)
        })
        .map(|f| f.fix())
        .collect()
}

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

/// Copies the inside faces of a triangulation into a `SurfaceMesh`.
pub(crate) fn extract(
    id: SurfaceId,
    surface: &Surface,
    coords: MeshCoordinates,
    cdt: &Cdt,
    outside: &[FixedFaceHandle<InnerTag>],
) -> SurfaceMesh {
    let outside: std::collections::HashSet<_> = outside.iter().copied().collect();
    let mut index = vec![u32::MAX; cdt.num_vertices()];
    let mut local = Vec::new();
    let mut triangles = Vec::new();
    for face in cdt.inner_faces() {
        if outside.contains(&face.fix()) {
            continue;
        }
        let tri = face.vertices().map(|v| {
            let slot = &mut index[v.fix().index()];
            if *slot == u32::MAX {
                *slot = local.len() as u32;
                let p = v.position();
                local.push(DVec2::new(p.x, p.y));
            }
            *slot
        });
        triangles.push(tri);
    }
    let points3 = local
        .iter()
        .map(|&q| coords.frame.to_3d(q * coords.scale))
        .collect();
    SurfaceMesh {
        surface: id,
        frame: coords.frame,
        scale: coords.scale,
        local,
        points3,
        triangles,
        boundary: coords.boundary,
        constraints: Vec::new(),
        polygon_area: surface.area(),
    }
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
