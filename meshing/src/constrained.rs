//! Discontinuity meshing, second half: the segments become constraint edges of each surface's
//! constrained Delaunay triangulation, which is then refined for quality without losing them.
//!
//! Segments cross, overlap, share endpoints and come within rounding of each other. They are
//! mapped into mesh coordinates and snapped to its grid, endpoints closer than
//! [`MERGE_DISTANCE`] become one vertex, and each segment is inserted with spade's
//! `add_constraint_and_split`, which splits both constraints where two cross. The result is
//! checked: every segment must be a chain of mesh edges.
//!
//! Along value discontinuities (D0: a blocker standing on the receiver) the triangles on the two
//! sides get separate vertices, so the mesh can carry the jump.

use std::collections::HashMap;

use glam::{DVec2, DVec3};
use penumbra_scenes::{PlaneFrame, Surface, SurfaceId};

use crate::cdt::{Cdt, SurfaceTriangulation, insert_segment, quietly};
use crate::error::MeshError;
use crate::grading::Density;
use crate::mesh::SurfaceMesh;
use crate::mesh_coordinates::{MeshCoordinates, snap};
use crate::progress::Interrupt;
use crate::tolerances::{
    CONSTRAINED_MIN_ANGLE_DEG, MAX_MIN_ANGLE_DEG, MERGE_DISTANCE, ON_SEGMENT_TOLERANCE,
    SPLIT_MIN_ANGLE_DEG,
};
use penumbra_scenes::polygon::clip_segment;
use spade::Triangulation as _;

/// Margin of the frame around a constrained polygon, relative to its extent.
const FRAME_MARGIN: f64 = 0.05;

/// A segment to be a chain of mesh edges, in the surface's plane-frame coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Constraint {
    /// One end.
    pub from: DVec2,
    /// The other end.
    pub to: DVec2,
    /// The light jumps across it: the two sides get separate vertices.
    pub splits: bool,
}

/// A surface's triangulation with constraints inserted, before refinement.
#[derive(Clone)]
pub struct ConstrainedSurface {
    id: SurfaceId,
    triangulation: SurfaceTriangulation,
    /// The constraints as inserted, in mesh coordinates.
    segments: Vec<([DVec2; 2], bool)>,
    /// The least quality mesh, once looked for ([`Self::quality_triangles`]): `Some(None)` when
    /// it takes more triangles than were allowed.
    quality: Option<Option<SurfaceTriangulation>>,
    /// The smallest angle refinement aims for where the constraints do not force a smaller one
    /// (0: none; refinement then only splits by area).
    min_angle_deg: f64,
}

/// Vertices beyond a target's triangle count that the search for a quality mesh may add: Ruppert's
/// refinement also refines the frame around the polygon, and small targets need some room.
const QUALITY_SPARE_VERTICES: usize = 64;

impl std::fmt::Debug for ConstrainedSurface {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ConstrainedSurface")
            .field("id", &self.id)
            .field("segments", &self.segments.len())
            .finish()
    }
}

impl ConstrainedSurface {
    /// Triangulates the surface's polygon with `constraints` inserted.
    pub fn new(
        id: SurfaceId,
        surface: &Surface,
        constraints: &[Constraint],
    ) -> Result<ConstrainedSurface, MeshError> {
        ConstrainedSurface::joining(id, surface, constraints, 0.0)
    }

    /// [`Self::new`], with constraint ends within `join` (a length in the scene's units, when
    /// larger than the mesh's merge distance, 2^-30 of the polygon's extent) of another end, or
    /// of another constraint, put
    /// on it: the precision to which the constraints were found (a line trimmed where a block
    /// hides it ends within a few contact distances of that block's foot).
    pub fn joining(
        id: SurfaceId,
        surface: &Surface,
        constraints: &[Constraint],
        join: f64,
    ) -> Result<ConstrainedSurface, MeshError> {
        // The constraints are in the polygon's own frame; the mesh's starts at the corner the
        // constraints pick among those it could start at, which for a polygon without a
        // rotational symmetry is the same.
        let plane = PlaneFrame::of_polygon(&surface.polygon);
        let marks: Vec<DVec3> = plane
            .iter()
            .flat_map(|f| {
                constraints
                    .iter()
                    .flat_map(|c| [f.to_3d(c.from), f.to_3d(c.to)])
            })
            .collect();
        let coords = MeshCoordinates::of_surface_marked(id, surface, &marks)?;
        let to_mesh = |p: DVec2| {
            let p = match plane {
                Some(f) if f != coords.frame => coords.frame.to_2d(f.to_3d(p)),
                _ => p,
            };
            let q = p / coords.scale;
            DVec2::new(snap(q.x), snap(q.y))
        };
        let merge = MERGE_DISTANCE.max(join / coords.scale);
        let mut welder = Welder::new(merge);
        for &b in &coords.boundary {
            welder.weld(b);
        }
        let mut segments = Vec::new();
        for c in constraints {
            let (a, b) = (to_mesh(c.from), to_mesh(c.to));
            if !(a.is_finite() && b.is_finite()) {
                continue;
            }
            // Snapping may move an end that was on the boundary just outside it.
            for [s, t] in clip_segment(a, b, &coords.boundary) {
                let (p, q) = (welder.weld(a.lerp(b, s)), welder.weld(a.lerp(b, t)));
                if p != q {
                    segments.push(([p, q], c.splits));
                }
            }
        }
        let (segments, boundary_splits) = snap_t_junctions(&coords.boundary, segments, merge);

        let mut cdt = Cdt::new();
        // spade panics on some near-collinear input (two constraints from one point in nearly
        // one direction); a panic here must become an error, not a crash.
        let inserted = quietly(|| {
            let n = coords.boundary.len();
            for k in 0..n {
                let mut chain = vec![coords.boundary[k]];
                chain.extend(&boundary_splits[k]);
                chain.push(coords.boundary[(k + 1) % n]);
                for w in chain.windows(2) {
                    insert_segment(&mut cdt, id, w[0], w[1])?;
                }
            }
            segments
                .iter()
                .try_for_each(|&([a, b], _)| insert_segment(&mut cdt, id, a, b))?;
            if !segments.is_empty() {
                // A frame just outside the polygon: refinement then sees the whole neighbourhood
                // of the boundary, not slivers between nearly straight boundary chains (split
                // at T-junctions) and the convex hull.
                let (lo, hi) = coords
                    .boundary
                    .iter()
                    .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &p| {
                        (lo.min(p), hi.max(p))
                    });
                let margin = FRAME_MARGIN * (hi - lo).max_element();
                for corner in [
                    DVec2::new(lo.x - margin, lo.y - margin),
                    DVec2::new(hi.x + margin, lo.y - margin),
                    DVec2::new(hi.x + margin, hi.y + margin),
                    DVec2::new(lo.x - margin, hi.y + margin),
                ] {
                    cdt.insert(spade::Point2::new(corner.x, corner.y))
                        .map_err(|e| MeshError::Triangulation {
                            surface: id,
                            message: format!("cannot insert the frame: {e:?}"),
                        })?;
                }
            }
            Ok(())
        });
        match inserted {
            Ok(result) => result?,
            Err(_) => {
                return Err(MeshError::Triangulation {
                    surface: id,
                    message: "spade failed while inserting constraints".into(),
                });
            }
        }
        let boundary_only = segments.is_empty();
        Ok(ConstrainedSurface {
            id,
            triangulation: SurfaceTriangulation::new(coords, cdt, boundary_only),
            segments,
            quality: None,
            min_angle_deg: CONSTRAINED_MIN_ANGLE_DEG,
        })
    }

    /// The same surface, refined to `min_angle_deg` (0 to [`MAX_MIN_ANGLE_DEG`]; 0: no quality
    /// refinement) instead of [`CONSTRAINED_MIN_ANGLE_DEG`].
    pub fn with_min_angle(mut self, min_angle_deg: f64) -> ConstrainedSurface {
        self.min_angle_deg = min_angle_deg.clamp(0.0, MAX_MIN_ANGLE_DEG);
        self.quality = None;
        self
    }

    /// Triangles before refinement: the least this surface can have.
    pub fn minimum_triangles(&self) -> usize {
        self.triangulation.count()
    }

    /// Triangles of the least mesh whose angles are all at least
    /// [`FORCING_WEDGE_DEG`](crate::FORCING_WEDGE_DEG) where the input does not force them, if
    /// it can be had with
    /// at most `target` triangles; meshes of this surface with at least as many then keep
    /// those angles ([`Self::into_refinable`]).
    pub fn quality_triangles(&mut self, target: usize) -> Option<usize> {
        if self.min_angle_deg <= 0.0 {
            return None;
        }
        if self.quality.is_none() {
            self.quality = Some(
                self.triangulation
                    .quality_least(self.min_angle_deg, target + QUALITY_SPARE_VERTICES)
                    .filter(|q| q.count() <= target),
            );
        }
        self.quality
            .as_ref()
            .and_then(|q| q.as_ref().map(SurfaceTriangulation::count))
    }

    /// Refines to about `target` triangles and makes the mesh, with separate vertices on the two
    /// sides of every value discontinuity.
    pub fn into_mesh(self, surface: &Surface, target: usize) -> SurfaceMesh {
        self.into_refinable(target, 1.0, &|_| false, None)
            .mesh(surface)
    }

    /// Like [`Self::into_mesh`], with triangles `penumbra_density` times smaller in area where
    /// `varies` says the light varies (see
    /// [`DEFAULT_PENUMBRA_DENSITY`](crate::DEFAULT_PENUMBRA_DENSITY)).
    pub fn into_graded_mesh(
        self,
        surface: &Surface,
        target: usize,
        penumbra_density: f64,
        varies: &(dyn Fn(&[DVec3]) -> bool + Sync),
    ) -> SurfaceMesh {
        self.into_refinable(target, penumbra_density, varies, None)
            .mesh(surface)
    }

    /// The refined triangulation, graded as in [`Self::into_graded_mesh`], kept so that
    /// triangles can be split later.
    ///
    /// Refinement starts from the least quality mesh when that fits `target`
    /// ([`Self::quality_triangles`]), so that the angles the input does not force stay at
    /// [`FORCING_WEDGE_DEG`](crate::FORCING_WEDGE_DEG) or more.
    pub fn into_refinable(
        mut self,
        target: usize,
        penumbra_density: f64,
        varies: &(dyn Fn(&[DVec3]) -> bool + Sync),
        stop: Option<&Interrupt>,
    ) -> RefinableSurface {
        self.quality_triangles(target);
        let base = match self.quality {
            Some(Some(q)) if q.count() <= target => q,
            _ => self.triangulation,
        };
        let angle = self.min_angle_deg;
        let triangulation = if self.segments.is_empty() || penumbra_density <= 1.0 {
            base.refined_until(target, angle, stop)
        } else {
            let density = Density::probe(&base, target, penumbra_density, varies);
            base.refined_graded(target, angle, &density, stop)
        };
        RefinableSurface {
            id: self.id,
            triangulation,
            segments: self.segments,
            min_angle_deg: angle,
        }
    }
}

/// A surface's refined triangulation with its constraints, kept so that triangles can be split
/// later (adaptive refinement) without losing a constraint or the quality of the rest.
#[derive(Clone)]
pub struct RefinableSurface {
    id: SurfaceId,
    triangulation: SurfaceTriangulation,
    segments: Vec<([DVec2; 2], bool)>,
    min_angle_deg: f64,
}

impl std::fmt::Debug for RefinableSurface {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RefinableSurface")
            .field("id", &self.id)
            .field("vertices", &self.triangulation.cdt.num_vertices())
            .field("segments", &self.segments.len())
            .finish()
    }
}

impl RefinableSurface {
    /// A uniform mesh of the surface, about `target` triangles, that can be refined later.
    pub fn uniform(
        id: SurfaceId,
        surface: &Surface,
        target: usize,
    ) -> Result<RefinableSurface, MeshError> {
        RefinableSurface::uniform_until(id, surface, target, None)
    }

    /// [`Self::uniform`], given up between its trial refinements once `stop` is set (the
    /// caller then lets the surface go).
    pub fn uniform_until(
        id: SurfaceId,
        surface: &Surface,
        target: usize,
        stop: Option<&Interrupt>,
    ) -> Result<RefinableSurface, MeshError> {
        Ok(RefinableSurface {
            id,
            triangulation: SurfaceTriangulation::of_surface(id, surface)?.refined_until(
                target,
                crate::tolerances::MIN_ANGLE_DEG,
                stop,
            ),
            segments: Vec::new(),
            min_angle_deg: crate::tolerances::MIN_ANGLE_DEG,
        })
    }

    /// The mesh, with separate vertices on the two sides of every value discontinuity.
    pub fn mesh(&self, surface: &Surface) -> SurfaceMesh {
        let mut mesh = self.triangulation.clone().into_mesh(self.id, surface);
        mesh.constraints = self.segments.iter().map(|s| s.0).collect();
        let jumps: Vec<[DVec2; 2]> = self.segments.iter().filter(|s| s.1).map(|s| s.0).collect();
        if !jumps.is_empty() {
            let lines = mesh.constraints.clone();
            split_along(&mut mesh, &jumps, &lines);
        }
        mesh
    }

    /// Splits the triangles holding the points `at` (mesh coordinates, such as the centroids of
    /// a mesh's triangles), never across a constraint, and restores quality around them, to
    /// [`SPLIT_MIN_ANGLE_DEG`] at most. Returns how many vertices were added.
    pub fn split_at(&mut self, at: &[DVec2]) -> usize {
        self.triangulation
            .split_triangles_at(at, self.min_angle_deg.min(SPLIT_MIN_ANGLE_DEG))
    }

    /// Triangles inside the polygon.
    pub fn triangle_count(&self) -> usize {
        self.triangulation.count()
    }
}

/// Makes near T-junctions exact: a segment end within `tol` of another segment (or of a boundary
/// edge), away from its ends, moves onto it, and that segment (or edge) is split there. Without
/// this, the end and the segment would be two features a rounding error apart, which the
/// refinement then chases with ever smaller triangles. Returns the segments and, for each
/// boundary edge, the points to split it at, in order along it.
#[allow(clippy::type_complexity)]
fn snap_t_junctions(
    boundary: &[DVec2],
    mut segments: Vec<([DVec2; 2], bool)>,
    tol: f64,
) -> (Vec<([DVec2; 2], bool)>, Vec<Vec<DVec2>>) {
    let n = boundary.len();
    let mut splits: Vec<Vec<(f64, DVec2)>> = vec![Vec::new(); n];
    // The projection of p onto segment a-b, if p is within tol of it and away from its ends.
    let onto = |p: DVec2, a: DVec2, b: DVec2| -> Option<(f64, DVec2)> {
        let d = b - a;
        let len2 = d.length_squared();
        let t = (p - a).dot(d) / len2;
        let q = a + d * t;
        let inner = t * len2.sqrt() > tol && (1.0 - t) * len2.sqrt() > tol;
        (inner && p.distance(q) <= tol).then_some((t, q))
    };
    // Only the segments passing near an end can take it: a grid finds them.
    let mut grid = SegmentGrid::new(boundary.iter().copied(), segments.len());
    for (j, s) in segments.iter().enumerate() {
        grid.add(j, s.0, tol);
    }
    let mut i = 0;
    while i < segments.len() {
        for end in 0..2 {
            let p = segments[i].0[end];
            if let Some((k, (t, q))) =
                (0..n).find_map(|k| onto(p, boundary[k], boundary[(k + 1) % n]).map(|x| (k, x)))
            {
                segments[i].0[end] = q;
                splits[k].push((t, q));
                continue;
            }
            // The first segment in order that passes within `tol`, as a scan of all would find.
            let hit = grid
                .near(p)
                .iter()
                .copied()
                .filter(|&j| j != i)
                .filter_map(|j| onto(p, segments[j].0[0], segments[j].0[1]).map(|(_, q)| (j, q)))
                .min_by_key(|&(j, _)| j);
            if let Some((j, q)) = hit {
                segments[i].0[end] = q;
                let ([a, b], splits_d0) = segments[j];
                // The first piece stays within the cells of the whole segment.
                segments[j].0 = [a, q];
                grid.add(segments.len(), [q, b], tol);
                segments.push(([q, b], splits_d0));
            }
        }
        i += 1;
    }
    // Projections made new points; weld them again so that ends a rounding error apart are one.
    let mut welder = Welder::new(tol);
    for &b in boundary {
        welder.weld(b);
    }
    for list in &mut splits {
        for (_, q) in list.iter_mut() {
            *q = welder.weld(*q);
        }
    }
    for s in &mut segments {
        s.0 = s.0.map(|p| welder.weld(p));
    }
    segments.retain(|s| s.0[0] != s.0[1]);
    // One orientation per segment, so that a segment and its reverse sort together and only one
    // is inserted: inserting a constraint twice upsets spade's splitting of later crossings.
    for s in &mut segments {
        let [a, b] = s.0;
        if (b.x, b.y) < (a.x, a.y) {
            s.0 = [b, a];
        }
    }
    segments.sort_by(|x, y| {
        let key = |s: &([DVec2; 2], bool)| [s.0[0].x, s.0[0].y, s.0[1].x, s.0[1].y];
        key(x)
            .partial_cmp(&key(y))
            .unwrap_or(std::cmp::Ordering::Equal)
            .then(y.1.cmp(&x.1))
    });
    // Keep the splitting copy of a duplicate (sorted first).
    segments.dedup_by(|x, y| x.0 == y.0);
    let splits = splits
        .into_iter()
        .map(|mut v| {
            v.sort_by(|a, b| a.0.total_cmp(&b.0));
            v.dedup_by(|a, b| a.1 == b.1);
            v.into_iter().map(|(_, q)| q).collect()
        })
        .collect();
    (segments, splits)
}

/// Segments filed under the cells of a square grid over a bounding box that they pass within a
/// distance of; points outside the box belong to its nearest cell. It finds the few segments
/// near a point among many (the contact lines of thousands of blockers on one floor).
struct SegmentGrid {
    origin: DVec2,
    cell: DVec2,
    side: usize,
    cells: Vec<Vec<usize>>,
}

impl SegmentGrid {
    /// A grid over the box of `points`, about one cell per segment, at most 1024 a side.
    fn new(points: impl Iterator<Item = DVec2>, segments: usize) -> SegmentGrid {
        let (lo, hi) = points.fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p), hi.max(p))
        });
        let side = ((segments as f64).sqrt().ceil() as usize).clamp(1, 1024);
        let (lo, hi) = if lo.is_finite() && hi.is_finite() {
            (lo, hi)
        } else {
            (DVec2::ZERO, DVec2::ONE)
        };
        let extent = (hi - lo).max(DVec2::splat(f64::MIN_POSITIVE * side as f64));
        SegmentGrid {
            origin: lo,
            cell: extent / side as f64,
            side,
            cells: vec![Vec::new(); side * side],
        }
    }

    /// The column or row of coordinate `x` along axis `axis`, clamped to the grid.
    fn index(&self, x: f64, axis: usize) -> usize {
        let t = ((x - self.origin[axis]) / self.cell[axis]).floor();
        if t.is_nan() {
            0
        } else {
            t.clamp(0.0, (self.side - 1) as f64) as usize
        }
    }

    /// Files segment `j` under every cell it passes within `tol` of.
    fn add(&mut self, j: usize, [a, b]: [DVec2; 2], tol: f64) {
        let (y0, y1) = (a.y.min(b.y) - tol, a.y.max(b.y) + tol);
        for row in self.index(y0, 1)..=self.index(y1, 1) {
            // The part of the segment within `tol` of this row's band, in x.
            // The first and last rows also hold everything beyond the box.
            let band_lo = match row {
                0 => f64::NEG_INFINITY,
                _ => self.origin.y + row as f64 * self.cell.y - tol,
            };
            let band_hi = match row + 1 == self.side {
                true => f64::INFINITY,
                false => self.origin.y + (row + 1) as f64 * self.cell.y + tol,
            };
            let (lo_y, hi_y) = (band_lo.max(y0), band_hi.min(y1));
            let x_at = |y: f64| {
                if b.y == a.y {
                    None
                } else {
                    Some(a.x + (b.x - a.x) * ((y - a.y) / (b.y - a.y)).clamp(0.0, 1.0))
                }
            };
            let (x0, x1) = match (x_at(lo_y), x_at(hi_y)) {
                (Some(p), Some(q)) => (p.min(q), p.max(q)),
                _ => (a.x.min(b.x), a.x.max(b.x)),
            };
            let (first, last) = (self.index(x0 - tol, 0), self.index(x1 + tol, 0));
            for column in first..=last {
                self.cells[row * self.side + column].push(j);
            }
        }
    }

    /// The segments that may pass within their distance of `p`, each once.
    fn near(&self, p: DVec2) -> &[usize] {
        &self.cells[self.index(p.y, 1) * self.side + self.index(p.x, 0)]
    }
}

/// Points within a distance of an earlier point are replaced by it (a hash grid of that size).
struct Welder {
    tol: f64,
    grid: HashMap<(i64, i64), Vec<DVec2>>,
}

impl Welder {
    fn new(tol: f64) -> Welder {
        Welder {
            tol,
            grid: HashMap::new(),
        }
    }

    fn weld(&mut self, p: DVec2) -> DVec2 {
        let key = |q: DVec2| {
            (
                (q.x / self.tol).floor() as i64,
                (q.y / self.tol).floor() as i64,
            )
        };
        let (kx, ky) = key(p);
        for dx in -1..=1 {
            for dy in -1..=1 {
                if let Some(found) = self
                    .grid
                    .get(&(kx + dx, ky + dy))
                    .and_then(|v| v.iter().find(|&&q| q.distance(p) <= self.tol).copied())
                {
                    return found;
                }
            }
        }
        self.grid.entry((kx, ky)).or_default().push(p);
        p
    }
}

/// Gives the triangles on each side of the value discontinuities `jumps` their own copies of the
/// vertices on them: around each such vertex, the triangles that can reach each other without
/// crossing a jump keep one vertex.
///
/// Where a jump ends or meets another of the `lines` (a shadow line at a blocker's corner), the
/// light's limit at the vertex depends on the direction of approach, continuously but steeply;
/// there every triangle gets its own copy, whose value is the limit towards that triangle.
fn split_along(mesh: &mut SurfaceMesh, jumps: &[[DVec2; 2]], lines: &[[DVec2; 2]]) {
    let on_line = |p: DVec2, [a, b]: [DVec2; 2]| {
        let d = b - a;
        let len = d.length();
        let t = (p - a).dot(d) / (len * len);
        d.perp_dot(p - a).abs() <= ON_SEGMENT_TOLERANCE * len.max(1.0)
            && (-1e-12..=1.0 + 1e-12).contains(&t)
    };
    // The lines near a point, through grids: a floor may carry thousands.
    let index = |lines: &[[DVec2; 2]]| {
        let mut grid = SegmentGrid::new(mesh.local.iter().copied(), lines.len());
        for (j, &[a, b]) in lines.iter().enumerate() {
            let len = a.distance(b);
            if len > 0.0 {
                // As far off a line as `on_line` accepts, across and along.
                let reach = ON_SEGMENT_TOLERANCE * len.max(1.0) / len + 1e-12 * len;
                grid.add(j, [a, b], 2.0 * reach);
            }
        }
        grid
    };
    let (jump_grid, line_grid) = (index(jumps), index(lines));
    let jumps_at = |p: DVec2| {
        jump_grid
            .near(p)
            .iter()
            .map(|&j| jumps[j])
            .filter(move |&l| on_line(p, l))
    };
    let n = mesh.local.len();
    let touched: Vec<bool> = mesh
        .local
        .iter()
        .map(|&p| jumps_at(p).next().is_some())
        .collect();
    let is_cut = |u: u32, v: u32| {
        let (p, q) = (mesh.local[u as usize], mesh.local[v as usize]);
        jumps_at(p).any(|l| on_line(q, l))
    };
    // A junction: the end of a jump, or a point a jump shares with another line.
    let is_junction = |p: DVec2| {
        let ends_jump = jumps_at(p).any(|[a, b]| a == p || b == p);
        let through = line_grid
            .near(p)
            .iter()
            .filter(|&&j| on_line(p, lines[j]))
            .count();
        ends_jump || through >= 2
    };
    let mut around: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for &v in tri {
            if touched[v as usize] {
                around[v as usize].push(t);
            }
        }
    }
    // (vertex, triangle, component) for every triangle not in the vertex's first component.
    let mut moves: Vec<(usize, usize, usize)> = Vec::new();
    for v in 0..n {
        let tris = &around[v];
        if tris.len() < 2 {
            continue;
        }
        // Union the triangles around v that share an uncut edge through v.
        let mut group: Vec<usize> = (0..tris.len()).collect();
        let junction = is_junction(mesh.local[v]);
        fn root(g: &mut [usize], mut i: usize) -> usize {
            while g[i] != i {
                g[i] = g[g[i]];
                i = g[i];
            }
            i
        }
        for i in 0..tris.len() {
            for j in i + 1..tris.len() {
                let (ti, tj) = (mesh.triangles[tris[i]], mesh.triangles[tris[j]]);
                let shared = ti.iter().find(|&&w| w != v as u32 && tj.contains(&w));
                if let Some(&w) = shared
                    && !junction
                    && !is_cut(v as u32, w)
                {
                    let (a, b) = (root(&mut group, i), root(&mut group, j));
                    group[a.max(b)] = a.min(b);
                }
            }
        }
        let first = root(&mut group, 0);
        for i in 0..tris.len() {
            let r = root(&mut group, i);
            if r != first {
                moves.push((v, tris[i], r));
            }
        }
    }
    let mut new_triangles = mesh.triangles.clone();
    let mut copies: HashMap<(usize, usize), u32> = HashMap::new();
    for (v, t, component) in moves {
        let copy = *copies.entry((v, component)).or_insert_with(|| {
            mesh.local.push(mesh.local[v]);
            mesh.points3.push(mesh.points3[v]);
            (mesh.local.len() - 1) as u32
        });
        for slot in new_triangles[t].iter_mut() {
            if *slot == v as u32 {
                *slot = copy;
            }
        }
    }
    mesh.triangles = new_triangles;
}
