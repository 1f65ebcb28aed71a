//! `SurfaceMesh`: the triangles of one surface, in its own 2D coordinates and in 3D.

use glam::{DVec2, DVec3};
use penumbra_scenes::polygon::{orient, signed_area_2d};
use penumbra_scenes::{PlaneFrame, Surface, SurfaceId};

use crate::error::MeshError;
use crate::tolerances::{AREA_CHECK_TOLERANCE, ON_SEGMENT_TOLERANCE};

/// The mesh of one surface. Values live at vertices and are interpolated linearly over triangles.
///
/// Positions are kept in *mesh coordinates* (`local`): the surface's plane-frame coordinates
/// divided by `scale` and snapped to a grid, the exact coordinates the triangulation was built in.
/// `frame.to_3d(local[i] * scale) == points3[i]` up to rounding.
#[derive(Clone, Debug)]
pub struct SurfaceMesh {
    /// The surface meshed.
    pub surface: SurfaceId,
    /// The plane frame the mesh coordinates are measured in (it may start at another corner
    /// than [`PlaneFrame::of_polygon`]'s).
    pub frame: PlaneFrame,
    /// Surface units per mesh unit.
    pub scale: f64,
    /// Each vertex in mesh coordinates.
    pub local: Vec<DVec2>,
    /// Each vertex in 3D, on the surface.
    pub points3: Vec<DVec3>,
    /// Counter-clockwise (seen from the surface's front) vertex index triples.
    pub triangles: Vec<[u32; 3]>,
    /// The meshed polygon in mesh coordinates (the surface polygon snapped to the grid).
    pub boundary: Vec<DVec2>,
    /// Segments that must be chains of mesh edges (discontinuities), in mesh coordinates.
    pub constraints: Vec<[DVec2; 2]>,
    /// Area of the surface's own polygon in 3D.
    pub polygon_area: f64,
}

impl SurfaceMesh {
    /// A mesh of no triangles: a surface left to another shard of a run.
    pub fn empty(id: SurfaceId, surface: &Surface) -> Result<SurfaceMesh, MeshError> {
        let frame =
            PlaneFrame::of_polygon(&surface.polygon).ok_or_else(|| MeshError::Degenerate {
                surface: id,
                name: surface.name.clone(),
            })?;
        Ok(SurfaceMesh {
            surface: id,
            frame,
            scale: 1.0,
            local: Vec::new(),
            points3: Vec::new(),
            triangles: Vec::new(),
            boundary: Vec::new(),
            constraints: Vec::new(),
            polygon_area: surface.area(),
        })
    }

    /// Vertices of the mesh.
    pub fn vertex_count(&self) -> usize {
        self.local.len()
    }

    /// Triangles of the mesh.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Plane-frame (surface) coordinates of vertex `i`.
    pub fn point2(&self, i: usize) -> DVec2 {
        self.local[i] * self.scale
    }

    /// The 3D corners of triangle `t`.
    pub fn triangle_points3(&self, t: usize) -> [DVec3; 3] {
        self.triangles[t].map(|i| self.points3[i as usize])
    }

    /// Area of triangle `t` in surface units squared.
    pub fn triangle_area(&self, t: usize) -> f64 {
        let [a, b, c] = self.triangles[t].map(|i| self.local[i as usize]);
        0.5 * (b - a).perp_dot(c - a) * self.scale * self.scale
    }

    /// The triangles' total area in surface units squared.
    pub fn area(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| self.triangle_area(t))
            .sum()
    }

    /// Area of the meshed polygon (the snapped surface polygon).
    pub fn boundary_area(&self) -> f64 {
        signed_area_2d(&self.boundary) * self.scale * self.scale
    }

    /// Checks the invariants every mesh must hold:
    /// every triangle is strictly counter-clockwise (exact predicate), the triangles' areas sum to
    /// the meshed polygon's area, and every boundary edge of the polygon and every constraint is
    /// covered by mesh edges.
    pub fn sanity_check(&self) -> Result<(), MeshError> {
        let fail = |what: String| {
            Err(MeshError::SanityCheck {
                surface: self.surface,
                what,
            })
        };
        if self.local.len() != self.points3.len() {
            return fail("2D and 3D vertex counts differ".into());
        }
        for (t, tri) in self.triangles.iter().enumerate() {
            if tri.iter().any(|&i| i as usize >= self.local.len()) {
                return fail(format!("triangle {t} has a vertex index out of range"));
            }
            let [a, b, c] = tri.map(|i| self.local[i as usize]);
            if !(orient(a, b, c) > 0.0) {
                return fail(format!("triangle {t} is not counter-clockwise"));
            }
        }
        let total = self.area();
        let expected = self.boundary_area();
        if !((total - expected).abs() <= AREA_CHECK_TOLERANCE * expected) {
            return fail(format!(
                "triangle areas sum to {total:e}, the polygon's area is {expected:e}"
            ));
        }
        // Each polygon edge must be a union of mesh edges: collect mesh edges lying on it, and
        // check they chain from one end to the other.
        let edges = self.edge_list();
        let n = self.boundary.len();
        for k in 0..n {
            let (p, q) = (self.boundary[k], self.boundary[(k + 1) % n]);
            if !self.edge_is_covered(p, q, &edges) {
                return fail(format!("boundary edge {k} is not made of mesh edges"));
            }
        }
        for (k, &[p, q]) in self.constraints.iter().enumerate() {
            if !self.edge_is_covered(p, q, &edges) {
                return fail(format!(
                    "constraint {k} ({p} - {q}) is not made of mesh edges"
                ));
            }
        }
        Ok(())
    }

    /// Undirected edges, each once, as sorted index pairs.
    pub fn edge_list(&self) -> Vec<[u32; 2]> {
        let mut edges: Vec<[u32; 2]> = self
            .triangles
            .iter()
            .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
            .map(|[a, b]| [a.min(b), a.max(b)])
            .collect();
        edges.sort_unstable();
        edges.dedup();
        edges
    }

    /// Whether the segment `p -> q` is a chain of mesh edges from end to end. Split points may sit
    /// off the segment by the rounding of their construction (1e-12 mesh units).
    pub fn edge_is_covered(&self, p: DVec2, q: DVec2, edges: &[[u32; 2]]) -> bool {
        let d = q - p;
        let len2 = d.length_squared();
        let off = |x: DVec2| d.perp_dot(x - p).abs() / len2.sqrt();
        // Parameters along p -> q of the mesh edges that lie on the segment.
        let mut pieces: Vec<(f64, f64)> = edges
            .iter()
            .filter_map(|&[a, b]| {
                let (pa, pb) = (self.local[a as usize], self.local[b as usize]);
                if off(pa) > ON_SEGMENT_TOLERANCE || off(pb) > ON_SEGMENT_TOLERANCE {
                    return None;
                }
                let (ta, tb) = ((pa - p).dot(d) / len2, (pb - p).dot(d) / len2);
                let (lo, hi) = (ta.min(tb), ta.max(tb));
                (hi > 0.0 && lo < 1.0).then_some((lo, hi))
            })
            .collect();
        pieces.sort_by(|a, b| a.0.total_cmp(&b.0));
        // Chain the pieces; gaps of the rounding size are the split points' own error.
        let slack = ON_SEGMENT_TOLERANCE / len2.sqrt();
        let mut reached = 0.0;
        for (lo, hi) in pieces {
            if lo > reached + slack {
                return false;
            }
            reached = f64::max(reached, hi);
        }
        reached >= 1.0 - slack
    }

    /// Per vertex, a unit direction into the surface: the mean direction to the centroids of the
    /// triangles around it. Evaluations at boundary vertices take the one-sided limit from there.
    pub fn interior_directions(&self) -> Vec<DVec3> {
        let mut dirs = vec![DVec3::ZERO; self.local.len()];
        for t in 0..self.triangles.len() {
            let p = self.triangle_points3(t);
            let c = (p[0] + p[1] + p[2]) / 3.0;
            for (k, &i) in self.triangles[t].iter().enumerate() {
                dirs[i as usize] += (c - p[k]).normalize_or_zero();
            }
        }
        dirs.into_iter().map(DVec3::normalize_or_zero).collect()
    }
}
