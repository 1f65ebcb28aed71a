//! Visibility: a BVH over every surface, triangulated, answering segment and ray queries in f64.
//!
//! `obvhs` stores f32 boxes. Coordinates are re-centred on the scene and scaled to a unit
//! diagonal before rounding, every box is padded by [`BOX_PADDING`] (more than the rounding of
//! the rays tested against it) and rounded outward, and every candidate triangle is then tested
//! in f64 with the watertight ray–triangle test of Woop, Benthin & Wald (2013): a ray through an
//! edge shared by two triangles hits at least one of them, so light does not leak through the
//! seams of closed geometry.
//!
//! The f32 walk may offer too many triangles, never too few: a query is clipped to the scene's
//! box, then walked with an f32 ray that starts [`RAY_LEAD`] before it (obvhs does not enter boxes
//! that a ray leaves within [`TRAVERSAL_BOX_START`] of its origin) and has no negative zeros in
//! its direction. [`Visibility::occluded_exhaustive`] and [`Visibility::closest_hit_exhaustive`]
//! decide the same queries over every triangle; [`crate::visibility_check`] compares the two.

use std::time::Duration;

use glam::{DVec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::ray::{Ray, RayHit};
use obvhs::{Boundable, BvhBuildParams};

use crate::frame::PlaneFrame;
use crate::model::{Bounds, Scene, SurfaceId};
use crate::polygon;

/// Points closer than this fraction of the scene diagonal to a surface count as lying on it: a
/// segment that starts or ends within this distance of a surface is not blocked by it there.
pub const CONTACT_TOLERANCE: f64 = 1e-9;
/// How far ray origins at a surface's junctions are moved into the surface, relative to the
/// scene diagonal: a ray that leaves a vertex on the edge where a wall meets a floor must pass
/// above the floor, not through its plane, or its fate is decided by rounding.
pub const JUNCTION_OFFSET: f64 = 1e-7;
/// Outward padding of the f32 boxes, relative to the scene diagonal.
///
/// It covers the distance between the f32 ray the index walks and the exact segment: the ray
/// starts inside the scene's box (within 2^-24 of its exact start), its unit direction is
/// rounded by 2^-24 per component, it is at most about one diagonal long once clipped to the
/// scene, and obvhs's slab test rounds three terms under 2 in size: together under 5e-7. The
/// slab test also replaces direction components under `f32::EPSILON` by `f32::EPSILON`, which
/// moves the ray by under 1.2e-7 over that length. Boxes themselves are rounded outward.
pub(crate) const BOX_PADDING: f64 = 1e-6;
/// The ray parameter at which obvhs starts every box of its ray traversal (`cwbvh::node::EPSILON`,
/// in f32-world units: scene diagonals). Its slab test ignores the ray's own `tmin`, so a box that
/// the ray leaves before this parameter is never entered.
pub(crate) const TRAVERSAL_BOX_START: f64 = 1e-4;
/// How far before the start of a query the f32 ray starts, in scene diagonals: everything the
/// query can meet then lies past [`TRAVERSAL_BOX_START`] along the f32 ray, with room to spare.
pub(crate) const RAY_LEAD: f64 = 2.0 * TRAVERSAL_BOX_START;

/// One triangle of a scene surface, with the surface's own (unrounded) vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneTriangle {
    /// The corners, counter-clockwise seen from the surface's front.
    pub vertices: [DVec3; 3],
    /// The surface the triangle is part of.
    pub surface: SurfaceId,
}

/// The closest surface along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// The surface hit.
    pub surface: SurfaceId,
    /// The triangle hit, an index into [`Visibility::triangles`].
    pub triangle: usize,
    /// Ray parameter: the hit point is `origin + t * direction`.
    pub t: f64,
    /// The hit point.
    pub point: DVec3,
}

#[derive(Clone, Copy)]
struct PaddedBox(Aabb);

/// A segment query of [`Visibility::occluded`]: hits at `from + t * d` with `t` in
/// `(t_min, t_max)` block it.
struct Segment {
    from: DVec3,
    to: DVec3,
    d: DVec3,
    t_min: f64,
    t_max: f64,
    ignore: [SurfaceId; 2],
}

/// A query ray in the f32 world of the index, starting [`RAY_LEAD`] before the part of the
/// caller's ray that lies in the scene's box.
struct IndexRay {
    ray: Ray,
    /// The caller's parameter at which that part starts.
    t_start: f64,
    /// f32-ray parameter per unit of the caller's parameter.
    scale: f64,
}

impl IndexRay {
    /// The f32-ray parameter of the caller's `t`, rounded up: the traversal enters every box
    /// that holds the point at `t` before it.
    fn parameter_rounded_up(&self, t: f64) -> f32 {
        round_up(RAY_LEAD + (t - self.t_start) * self.scale)
    }
}

impl Boundable for PaddedBox {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

/// The visibility index of a scene.
pub struct Visibility {
    triangles: Vec<SceneTriangle>,
    /// Unit normal of each triangle's plane.
    normals: Vec<DVec3>,
    /// Ray traversal (8-wide, fastest for rays); `None` for a scene without triangles.
    rays: Option<CwBvh>,
    /// Box queries (obvhs has them on the binary BVH only).
    boxes: Option<Bvh2>,
    /// For each triangle, the box of the leaf of `boxes` that holds it, when every node's box
    /// holds its children's (then a leaf is visited exactly when its own box overlaps a query).
    leaf_boxes: Option<Vec<IndexBox>>,
    /// The box of every triangle, padded by [`BOX_PADDING`]: rays are clipped to it.
    extent: Bounds,
    center: DVec3,
    /// Scene units per f32-world unit (the scene diagonal).
    unit: f64,
    padding: f64,
    contact: f64,
}

impl std::fmt::Debug for Visibility {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Visibility")
            .field("triangles", &self.triangles.len())
            .field("center", &self.center)
            .finish()
    }
}

/// Triangulates every surface of a scene, keeping each surface's own vertices.
pub(crate) fn triangulate_scene(scene: &Scene) -> Vec<SceneTriangle> {
    let mut out = Vec::new();
    for (surface, s) in scene.surfaces.iter().enumerate() {
        let Some(frame) = PlaneFrame::of_polygon(&s.polygon) else {
            continue;
        };
        let flat: Vec<_> = s.polygon.iter().map(|&p| frame.to_2d(p)).collect();
        for [a, b, c] in polygon::triangulate_ccw(&flat) {
            out.push(SceneTriangle {
                vertices: [s.polygon[a], s.polygon[b], s.polygon[c]],
                surface,
            });
        }
    }
    out
}

impl Visibility {
    /// The index of every surface of `scene`, each triangulated.
    pub fn build(scene: &Scene) -> Visibility {
        Visibility::from_triangles(triangulate_scene(scene), scene.bounds())
    }

    /// The index of any triangles; `bounds` (grown to hold them) sets the scale that the
    /// tolerances are relative to, normally the scene's box.
    pub fn from_triangles(triangles: Vec<SceneTriangle>, bounds: Bounds) -> Visibility {
        let extent = triangles.iter().fold(Bounds::EMPTY, |b, t| {
            b.union(Bounds::from_points(&t.vertices))
        });
        let bounds = bounds.union(extent);
        let center = if bounds.is_empty() {
            DVec3::ZERO
        } else {
            bounds.center()
        };
        let diagonal = bounds.diagonal();
        // The f32 world is the scene re-centred and scaled to a diagonal of 1, so that the
        // absolute epsilons inside the BVH (obvhs clamps ray direction components under f32's
        // epsilon) mean the same at every scale.
        let unit = if diagonal > 0.0 && diagonal.is_finite() {
            diagonal
        } else {
            1.0
        };
        let padding = BOX_PADDING;
        let boxes: Vec<PaddedBox> = triangles
            .iter()
            .map(|t| {
                let b = Bounds::from_points(&t.vertices);
                PaddedBox(to_f32_box(b, center, unit, padding))
            })
            .collect();
        let (rays, box_bvh) = if boxes.is_empty() {
            (None, None)
        } else {
            let mut time = Duration::default();
            (
                Some(build_cwbvh(
                    &boxes,
                    BvhBuildParams::medium_build(),
                    &mut time,
                )),
                Some(build_bvh2(
                    &boxes,
                    BvhBuildParams::medium_build(),
                    &mut time,
                )),
            )
        };
        let leaf_boxes = box_bvh
            .as_ref()
            .and_then(|bvh| leaf_box_of_each(bvh, triangles.len()));
        let normals = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.vertices;
                (b - a).cross(c - a).normalize_or_zero()
            })
            .collect();
        Visibility {
            triangles,
            normals,
            rays,
            boxes: box_bvh,
            leaf_boxes,
            extent: Bounds {
                min: extent.min - DVec3::splat(padding * unit),
                max: extent.max + DVec3::splat(padding * unit),
            },
            center,
            unit,
            padding,
            contact: CONTACT_TOLERANCE * diagonal,
        }
    }

    /// The indexed triangles; [`Hit::triangle`] and the box queries refer to them by index.
    pub fn triangles(&self) -> &[SceneTriangle] {
        &self.triangles
    }

    /// The unit normal of triangle `index`'s plane, toward its surface's front.
    pub fn triangle_normal(&self, index: usize) -> DVec3 {
        self.normals[index]
    }

    /// Distance below which a point counts as lying on a surface.
    pub fn contact_distance(&self) -> f64 {
        self.contact
    }

    /// Distance within which a point where surfaces meet counts as lying on the other's plane:
    /// polygons are planar only to [`PLANARITY_TOLERANCE`](crate::PLANARITY_TOLERANCE) of their
    /// size, and files rounded to six decimals put walls that meet that far apart (CornellBox-
    /// Sphere's back wall ends 5·10⁻⁷ behind the plane of the side wall it meets).
    pub fn meeting_distance(&self) -> f64 {
        self.contact * (crate::PLANARITY_TOLERANCE / CONTACT_TOLERANCE)
    }

    /// Distance by which ray origins at junctions move into their surface ([`JUNCTION_OFFSET`]).
    pub fn junction_offset(&self) -> f64 {
        self.contact * (JUNCTION_OFFSET / CONTACT_TOLERANCE)
    }

    /// The part of the ray `origin + t * direction`, `t` in `[t_min, t_max]`, that lies in the
    /// (padded) box of the scene's triangles, as an f32 ray with a unit direction that starts
    /// [`RAY_LEAD`] before it; `None` when that part is empty.
    fn f32_ray(&self, origin: DVec3, direction: DVec3, t_min: f64, t_max: f64) -> Option<IndexRay> {
        let (mut start, mut end) = (t_min, t_max);
        for axis in 0..3 {
            let (o, d) = (origin[axis], direction[axis]);
            let (lo, hi) = (self.extent.min[axis], self.extent.max[axis]);
            if d == 0.0 {
                if o < lo || o > hi {
                    return None;
                }
                continue;
            }
            let (a, b) = ((lo - o) / d, (hi - o) / d);
            start = start.max(a.min(b));
            end = end.min(a.max(b));
        }
        if !(start <= end) {
            return None;
        }
        let length = direction.length();
        let unit_direction = direction / length;
        let scale = length / self.unit;
        let ray_origin =
            (origin + direction * start - self.center) / self.unit - unit_direction * RAY_LEAD;
        // obvhs picks a slab's near side by `direction < 0` but inverts a zero by its sign bit,
        // so a component of -0.0 (or one that rounds to it) would turn the slab inside out and
        // the ray would miss every box: zeros are made positive.
        let ray = Ray::new(
            to_vec3a(ray_origin),
            to_vec3a(unit_direction) + Vec3A::ZERO,
            0.0,
            round_up(RAY_LEAD + (end - start) * scale),
        );
        Some(IndexRay {
            ray,
            t_start: start,
            scale,
        })
    }

    /// Whether something other than the `ignore`d surfaces blocks the open segment `from -> to`.
    ///
    /// The endpoints are usually on surfaces (a receiving vertex and a point of a shooter); planar
    /// surfaces cannot block segments from their own points, so pass them in `ignore`. Hits within
    /// the contact distance of either endpoint do not count, and neither do surfaces whose plane
    /// holds both endpoints (a segment along a surface grazes it, it does not cross it).
    pub fn occluded(&self, from: DVec3, to: DVec3, ignore: [SurfaceId; 2]) -> bool {
        let Some(bvh) = &self.rays else {
            return false;
        };
        let Some(segment) = self.segment(from, to, ignore) else {
            return false;
        };
        let Some(ray) = self.f32_ray(from, segment.d, segment.t_min, segment.t_max) else {
            return false;
        };
        !bvh.ray_traverse_miss(ray.ray, |_, id| {
            if self.blocks(bvh.primitive_indices[id] as usize, &segment) {
                0.0
            } else {
                f32::INFINITY
            }
        })
    }

    /// [`Self::occluded`] decided without the index, by testing every triangle: the reference
    /// the index is checked against (slow: for tests and measurements).
    pub fn occluded_exhaustive(&self, from: DVec3, to: DVec3, ignore: [SurfaceId; 2]) -> bool {
        let Some(segment) = self.segment(from, to, ignore) else {
            return false;
        };
        (0..self.triangles.len()).any(|index| self.blocks(index, &segment))
    }

    /// The segment `from -> to` as [`Self::occluded`] tests it; `None` when nothing can block it.
    fn segment(&self, from: DVec3, to: DVec3, ignore: [SurfaceId; 2]) -> Option<Segment> {
        let d = to - from;
        let length = d.length();
        if !(length > 2.0 * self.contact) || !d.is_finite() || !from.is_finite() {
            return None;
        }
        let margin = self.contact / length;
        Some(Segment {
            from,
            to,
            d,
            t_min: margin,
            t_max: 1.0 - margin,
            ignore,
        })
    }

    /// Whether triangle `index` blocks `segment`: the exact f64 decision of [`Self::occluded`].
    fn blocks(&self, index: usize, segment: &Segment) -> bool {
        let tri = &self.triangles[index];
        if segment.ignore.contains(&tri.surface) {
            return false;
        }
        let n = self.normals[index];
        let anchor = tri.vertices[0];
        if n.dot(segment.from - anchor).abs() <= self.contact
            && n.dot(segment.to - anchor).abs() <= self.contact
        {
            return false;
        }
        matches!(
            intersect_watertight(segment.from, segment.d, &tri.vertices),
            Some(t) if t > segment.t_min && t < segment.t_max
        )
    }

    /// The closest hit along `origin + t * direction` for `t` in `(t_min, t_max)`, skipping `ignore`.
    pub fn closest_hit(
        &self,
        origin: DVec3,
        direction: DVec3,
        t_min: f64,
        t_max: f64,
        ignore: Option<SurfaceId>,
    ) -> Option<Hit> {
        let bvh = self.rays.as_ref()?;
        if !ray_is_usable(origin, direction) {
            return None;
        }
        let ray = self.f32_ray(origin, direction, t_min, t_max)?;
        let mut best: Option<(f64, usize)> = None;
        let mut hit = RayHit::none();
        bvh.ray_traverse(ray.ray, &mut hit, |_, id| {
            let index = bvh.primitive_indices[id] as usize;
            match self.hit_parameter(index, origin, direction, t_min, t_max, ignore) {
                Some(t) => {
                    if best.is_none_or(|(bt, _)| t < bt) {
                        best = Some((t, index));
                    }
                    // Boxes that hold a closer hit are entered before this parameter.
                    ray.parameter_rounded_up(t)
                }
                None => f32::INFINITY,
            }
        });
        best.map(|(t, triangle)| self.hit(origin, direction, t, triangle))
    }

    /// [`Self::closest_hit`] found without the index, by testing every triangle (the first of
    /// equally close ones): the reference the index is checked against.
    pub fn closest_hit_exhaustive(
        &self,
        origin: DVec3,
        direction: DVec3,
        t_min: f64,
        t_max: f64,
        ignore: Option<SurfaceId>,
    ) -> Option<Hit> {
        if !ray_is_usable(origin, direction) {
            return None;
        }
        let mut best: Option<(f64, usize)> = None;
        for index in 0..self.triangles.len() {
            if let Some(t) = self.hit_parameter(index, origin, direction, t_min, t_max, ignore)
                && best.is_none_or(|(bt, _)| t < bt)
            {
                best = Some((t, index));
            }
        }
        best.map(|(t, triangle)| self.hit(origin, direction, t, triangle))
    }

    /// Where the ray meets triangle `index` within `(t_min, t_max)`, unless its surface is ignored.
    fn hit_parameter(
        &self,
        index: usize,
        origin: DVec3,
        direction: DVec3,
        t_min: f64,
        t_max: f64,
        ignore: Option<SurfaceId>,
    ) -> Option<f64> {
        let tri = &self.triangles[index];
        if Some(tri.surface) == ignore {
            return None;
        }
        intersect_watertight(origin, direction, &tri.vertices).filter(|&t| t > t_min && t < t_max)
    }

    fn hit(&self, origin: DVec3, direction: DVec3, t: f64, triangle: usize) -> Hit {
        Hit {
            surface: self.triangles[triangle].surface,
            triangle,
            t,
            point: origin + direction * t,
        }
    }

    /// Calls `visit` with the index of every triangle whose box overlaps `bounds` (and maybe a few
    /// more: boxes are padded).
    pub fn triangles_overlapping(&self, bounds: Bounds, mut visit: impl FnMut(usize)) {
        let Some(bvh) = &self.boxes else {
            return;
        };
        let query = to_f32_box(bounds, self.center, self.unit, self.padding);
        bvh.aabb_traverse(query, |bvh, node_index| {
            let node = &bvh.nodes[node_index as usize];
            let first = node.first_index as usize;
            for &p in &bvh.primitive_indices[first..first + node.prim_count as usize] {
                visit(p as usize);
            }
            true
        });
    }
}

/// A box in the precision of the visibility index (f32, padded outward), as box queries test
/// them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IndexBox(Aabb);

impl IndexBox {
    /// Whether the boxes overlap, as the index's traversal decides it (touching counts).
    #[inline]
    pub fn overlaps(&self, other: &IndexBox) -> bool {
        self.0.intersect_aabb(&other.0)
    }
}

/// For each of `count` triangles, the box of the leaf holding it, if every inner node's box holds
/// its children's boxes and each triangle lies in one leaf.
fn leaf_box_of_each(bvh: &Bvh2, count: usize) -> Option<Vec<IndexBox>> {
    let holds = |outer: &Aabb, inner: &Aabb| {
        outer.min.cmple(inner.min).all() && inner.max.cmple(outer.max).all()
    };
    let mut boxes: Vec<Option<IndexBox>> = vec![None; count];
    for node in &bvh.nodes {
        if node.is_leaf() {
            let first = node.first_index as usize;
            for &p in &bvh.primitive_indices[first..first + node.prim_count as usize] {
                let slot = boxes.get_mut(p as usize)?;
                if slot.is_some() {
                    return None;
                }
                *slot = Some(IndexBox(*node.aabb()));
            }
        } else {
            let first = node.first_index as usize;
            for child in &bvh.nodes[first..first + 2] {
                if !holds(node.aabb(), child.aabb()) {
                    return None;
                }
            }
        }
    }
    boxes.into_iter().collect()
}

impl Visibility {
    /// The box that [`Self::triangles_overlapping`] tests the index with for `bounds`.
    pub fn query_box(&self, bounds: Bounds) -> IndexBox {
        IndexBox(to_f32_box(bounds, self.center, self.unit, self.padding))
    }

    /// For each triangle, the box of the index's leaf that holds it: a query for `bounds` visits
    /// exactly the triangles whose leaf box overlaps [`Self::query_box`]. `None` when the
    /// index's boxes are not nested (the leaf alone would not decide) or it has no triangles.
    pub fn leaf_boxes(&self) -> Option<&[IndexBox]> {
        self.leaf_boxes.as_deref()
    }
}

/// Slices a shaft is cut into along its length for box queries.
const SHAFT_SLICES: usize = 8;

impl Visibility {
    /// Calls `visit` with every triangle whose box overlaps the shaft between two boxes, the
    /// convex hull of `from` and `to` (a triangle may come more than once). Every point of the
    /// hull is `(1 - t) a + t b` for some `a` in `from` and `b` in `to`, so the boxes between
    /// the sections at the ends of a few (eight) ranges of `t` cover it; one box around a
    /// long shaft would hold most of a large scene.
    pub fn triangles_overlapping_between(
        &self,
        from: Bounds,
        to: Bounds,
        mut visit: impl FnMut(usize),
    ) {
        let section = |t: f64| Bounds {
            min: from.min.lerp(to.min, t),
            max: from.max.lerp(to.max, t),
        };
        for i in 0..SHAFT_SLICES {
            let (t0, t1) = (
                i as f64 / SHAFT_SLICES as f64,
                (i + 1) as f64 / SHAFT_SLICES as f64,
            );
            self.triangles_overlapping(section(t0).union(section(t1)), &mut visit);
        }
    }

    /// Whether some triangle whose box overlaps `bounds` satisfies `pred`; stops at the first.
    pub fn any_triangle_overlapping(
        &self,
        bounds: Bounds,
        mut pred: impl FnMut(&SceneTriangle) -> bool,
    ) -> bool {
        let Some(bvh) = &self.boxes else {
            return false;
        };
        let query = to_f32_box(bounds, self.center, self.unit, self.padding);
        let mut found = false;
        bvh.aabb_traverse(query, |bvh, node_index| {
            let node = &bvh.nodes[node_index as usize];
            let first = node.first_index as usize;
            found = bvh.primitive_indices[first..first + node.prim_count as usize]
                .iter()
                .any(|&p| pred(&self.triangles[p as usize]));
            !found
        });
        found
    }
}

fn to_vec3a(v: DVec3) -> Vec3A {
    Vec3A::new(v.x as f32, v.y as f32, v.z as f32)
}

fn to_f32_box(b: Bounds, center: DVec3, unit: f64, padding: f64) -> Aabb {
    let lo = (b.min - center) / unit - DVec3::splat(padding);
    let hi = (b.max - center) / unit + DVec3::splat(padding);
    Aabb::new(
        Vec3A::new(round_down(lo.x), round_down(lo.y), round_down(lo.z)),
        Vec3A::new(round_up(hi.x), round_up(hi.y), round_up(hi.z)),
    )
}

/// The least f32 not below `x`.
fn round_up(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) < x { f.next_up() } else { f }
}

/// The greatest f32 not above `x`.
fn round_down(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) > x { f.next_down() } else { f }
}

/// Watertight ray–triangle intersection (Woop, Benthin & Wald 2013) in f64; no back-face culling.
/// Returns the ray parameter of the hit. Points on an edge or a vertex count as hits.
pub(crate) fn intersect_watertight(origin: DVec3, direction: DVec3, v: &[DVec3; 3]) -> Option<f64> {
    let d = direction.to_array();
    let abs = direction.abs();
    let kz = if abs.x >= abs.y && abs.x >= abs.z {
        0
    } else if abs.y >= abs.z {
        1
    } else {
        2
    };
    let mut kx = (kz + 1) % 3;
    let mut ky = (kx + 1) % 3;
    if d[kz] < 0.0 {
        std::mem::swap(&mut kx, &mut ky);
    }
    let sx = d[kx] / d[kz];
    let sy = d[ky] / d[kz];
    let sz = 1.0 / d[kz];
    let a = (v[0] - origin).to_array();
    let b = (v[1] - origin).to_array();
    let c = (v[2] - origin).to_array();
    let ax = a[kx] - sx * a[kz];
    let ay = a[ky] - sy * a[kz];
    let bx = b[kx] - sx * b[kz];
    let by = b[ky] - sy * b[kz];
    let cx = c[kx] - sx * c[kz];
    let cy = c[ky] - sy * c[kz];
    let u = cx * by - cy * bx;
    let w_v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    if (u < 0.0 || w_v < 0.0 || w < 0.0) && (u > 0.0 || w_v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + w_v + w;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let t_scaled = u * sz * a[kz] + w_v * sz * b[kz] + w * sz * c[kz];
    Some(t_scaled / det)
}

/// Whether a ray has a finite start and a finite, non-zero direction.
fn ray_is_usable(origin: DVec3, direction: DVec3) -> bool {
    origin.is_finite() && direction.is_finite() && direction != DVec3::ZERO
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin;
    use crate::rng::SplitMix64;
    use glam::DAffine3;

    #[test]
    fn closed_box_does_not_leak_through_shared_edges_and_corners() {
        // Rays from inside the furnace cube aimed exactly at its edges and corners, and at the
        // shared diagonals of its triangulated faces, must all hit the cube.
        let scene = builtin::furnace(1.0, 0.5);
        let vis = Visibility::build(&scene);
        let mut rng = SplitMix64::new(7);
        let mut misses = 0;
        for _ in 0..20_000 {
            let o = DVec3::new(
                0.05 + 0.9 * rng.next_f64(),
                0.05 + 0.9 * rng.next_f64(),
                0.05 + 0.9 * rng.next_f64(),
            );
            // A target on an edge of the cube (two coordinates in {0, 1}) or a face diagonal.
            let s = rng.next_f64();
            let (a, b) = (
                if rng.next_f64() < 0.5 { 0.0 } else { 1.0 },
                if rng.next_f64() < 0.5 { 0.0 } else { 1.0 },
            );
            let target = match (rng.next_f64() * 5.0) as usize {
                0 => DVec3::new(s, a, b),
                1 => DVec3::new(a, s, b),
                2 => DVec3::new(a, b, s),
                3 => DVec3::new(s, s, a),
                _ => DVec3::new(s, 1.0 - s, a),
            };
            if vis
                .closest_hit(o, target - o, 0.0, f64::INFINITY, None)
                .is_none()
            {
                misses += 1;
            }
        }
        assert_eq!(misses, 0);
    }

    #[test]
    fn segments_between_adjacent_faces_are_not_blocked_by_them() {
        // From a point on the floor at its edge with a wall, to points on that wall and on the
        // ceiling: the floor and the wall touch the segment only at its ends.
        let scene = builtin::furnace(1.0, 0.5);
        let vis = Visibility::build(&scene);
        let floor = scene.surface_id("floor").expect("furnace has a floor");
        let south = scene.surface_id("south").expect("furnace has a south wall");
        let ceiling = scene.surface_id("ceiling").expect("furnace has a ceiling");
        let on_edge = DVec3::new(0.3, 0.0, 0.0);
        assert!(!vis.occluded(on_edge, DVec3::new(0.7, 0.0, 0.6), [floor, south]));
        assert!(!vis.occluded(on_edge, DVec3::new(0.6, 0.2, 1.0), [floor, ceiling]));
        assert!(!vis.occluded(
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 1.0),
            [floor, ceiling]
        ));
    }

    #[test]
    fn segments_out_of_a_closed_box_are_always_blocked() {
        let scene = builtin::furnace(1.0, 0.5);
        let vis = Visibility::build(&scene);
        let mut rng = SplitMix64::new(11);
        for _ in 0..20_000 {
            let o = DVec3::new(
                0.1 + 0.8 * rng.next_f64(),
                0.1 + 0.8 * rng.next_f64(),
                0.1 + 0.8 * rng.next_f64(),
            );
            // Through an edge or corner of the cube to a far point outside.
            let through = DVec3::new(
                rng.next_f64().round(),
                rng.next_f64().round(),
                rng.next_f64(),
            );
            let far = o + (through - o) * 3.0;
            assert!(
                vis.occluded(o, far, [usize::MAX, usize::MAX]),
                "leak from {o} through {through}"
            );
        }
    }

    #[test]
    fn closest_hit_matches_brute_force_on_cornell() {
        let scene = builtin::cornell();
        let vis = Visibility::build(&scene);
        let mut rng = SplitMix64::new(3);
        for _ in 0..2000 {
            let o = DVec3::new(
                20.0 + 500.0 * rng.next_f64(),
                20.0 + 500.0 * rng.next_f64(),
                20.0 + 500.0 * rng.next_f64(),
            );
            let d = DVec3::new(
                rng.next_f64() - 0.5,
                rng.next_f64() - 0.5,
                rng.next_f64() - 0.5,
            );
            let hit = vis.closest_hit(o, d, 0.0, f64::INFINITY, None);
            let brute = vis
                .triangles()
                .iter()
                .filter_map(|t| intersect_watertight(o, d, &t.vertices))
                .filter(|&t| t > 0.0)
                .fold(f64::INFINITY, f64::min);
            match hit {
                Some(h) => assert!((h.t - brute).abs() <= 1e-12 * brute, "{} vs {brute}", h.t),
                None => assert!(brute.is_infinite()),
            }
        }
    }

    /// Sibenik's leak: a segment that starts 1.3e-3 above a corner of a small triangle's box
    /// and crosses the triangle 3.3e-3 further on, less than 1e-4 scene diagonals from its start,
    /// where obvhs's traversal used to begin (it skips boxes that a ray leaves before that).
    /// Re-run moved far from the origin and scaled.
    #[test]
    fn segment_crossing_a_triangle_next_to_its_start_is_blocked() {
        for (offset, scale) in [
            (DVec3::ZERO, 1.0),
            (DVec3::new(3e6, -1e6, 2e5), 1.0),
            (DVec3::new(-7e3, 2e4, 5e3), 1e-3),
            (DVec3::new(1e9, 1e9, -1e9), 1e3),
        ] {
            let at = |x: f64, y: f64, z: f64| offset + DVec3::new(x, y, z) * scale;
            let blocker = [
                at(11.5884, -12.385, 0.929501),
                at(11.6694, -12.385, 0.929501),
                at(11.6716, -12.3975, 0.927251),
            ];
            let mut triangles = vec![SceneTriangle {
                vertices: blocker,
                surface: 1,
            }];
            // Copies of the blocker behind the segment's start, so that the blocker's node of
            // the index is small, and so are the steps its children's boxes are quantized in.
            for i in 1..4 {
                for j in 1..4 {
                    let shift = at(0.1 * i as f64, -0.1 * j as f64, 0.05) - at(0.0, 0.0, 0.0);
                    triangles.push(SceneTriangle {
                        vertices: blocker.map(|v| v + shift),
                        surface: 2,
                    });
                }
            }
            // A floor 80 units across cut in 8 x 8 squares.
            let corner =
                |i: usize, j: usize| at(i as f64 * 10.0 - 40.0, j as f64 * 10.0 - 40.0, -2.0);
            for i in 0..8 {
                for j in 0..8 {
                    let [a, b, c, d] = [
                        corner(i, j),
                        corner(i + 1, j),
                        corner(i + 1, j + 1),
                        corner(i, j + 1),
                    ];
                    for vertices in [[a, b, c], [a, c, d]] {
                        triangles.push(SceneTriangle {
                            vertices,
                            surface: 0,
                        });
                    }
                }
            }
            let bounds = Bounds::from_points(triangles.iter().flat_map(|t| &t.vertices));
            let vis = Visibility::from_triangles(triangles, bounds);
            let from = at(11.6716, -12.3975, 0.928586921875);
            let to = at(4.6347, -5.0, -2.0);
            let t = intersect_watertight(from, to - from, &blocker).expect("the segment crosses");
            assert!(t > 3e-4 && t < 3.2e-4, "{t}");
            assert!(vis.occluded_exhaustive(from, to, [0, usize::MAX]));
            assert!(
                vis.occluded(from, to, [0, usize::MAX]),
                "{offset} x {scale}"
            );
            let hit = vis.closest_hit(from, to - from, 0.0, f64::INFINITY, None);
            assert_eq!(hit.map(|h| h.surface), Some(1), "{offset} x {scale}");
            assert_eq!(hit.map(|h| h.t), Some(t));
        }
    }

    #[test]
    fn rays_with_negative_zero_direction_components_are_traced() {
        // -0.0 and components too small for f32 that round to it, in rays straight down.
        let scene = builtin::cornell();
        let vis = Visibility::build(&scene);
        for tiny in [-0.0, -1e-50, 0.0, 1e-50] {
            let origin = DVec3::new(300.0, 300.0, 270.0);
            let direction = DVec3::new(tiny, -1.0, tiny);
            let hit = vis.closest_hit(origin, direction, 0.0, f64::INFINITY, None);
            let exhaustive =
                vis.closest_hit_exhaustive(origin, direction, 0.0, f64::INFINITY, None);
            assert!(exhaustive.is_some());
            assert_eq!(hit.map(|h| h.t), exhaustive.map(|h| h.t), "{tiny:e}");
            let below = origin + direction * 1e4;
            assert!(vis.occluded(origin, below, [usize::MAX; 2]), "{tiny:e}");
        }
    }

    /// Every kind of sampled segment, on `scene`: the index agrees with exhaustive search.
    /// Returns how many sampled segments were blocked.
    fn assert_index_matches_exhaustive_search(scene: &Scene, seed: u64, count: usize) -> usize {
        use crate::visibility_check::{
            ProbeKind, closest_hit_mismatch, occlusion_mismatch, sample_segment,
        };
        let vis = Visibility::build(scene);
        let diagonal = scene.bounds().diagonal();
        let mut rng = SplitMix64::new(seed);
        let mut total_blocked = 0;
        for kind in ProbeKind::ALL {
            let (mut leaks, mut hits, mut blocked) = (Vec::new(), 0, 0);
            for _ in 0..count {
                let segment = sample_segment(&vis, kind, diagonal, &mut rng).expect("triangles");
                blocked +=
                    usize::from(vis.occluded_exhaustive(segment.from, segment.to, segment.ignore));
                if occlusion_mismatch(&vis, &segment).is_some() {
                    leaks.push(segment);
                }
                hits += usize::from(closest_hit_mismatch(&vis, &segment));
            }
            assert!(
                leaks.is_empty(),
                "{}: {} of {count} {kind:?} segments disagree, first {:?}",
                scene.name,
                leaks.len(),
                leaks[0]
            );
            assert_eq!(hits, 0, "{}: {kind:?} closest hits disagree", scene.name);
            total_blocked += blocked;
        }
        total_blocked
    }

    #[test]
    fn index_matches_exhaustive_search_on_built_in_scenes() {
        for (seed, name) in [
            "cornell",
            "furnace",
            "bars",
            "textbook",
            "boxworld",
            "tessellated",
        ]
        .into_iter()
        .enumerate()
        {
            let scene = builtin::builtin(name).expect("a built-in scene");
            let blocked = assert_index_matches_exhaustive_search(&scene, seed as u64, 1500);
            // Not vacuous (even in the furnace, segments from beside its corners can be blocked).
            assert!(blocked > 0, "{name}: nothing blocked");
        }
    }

    #[test]
    fn index_matches_exhaustive_search_far_from_the_origin() {
        // A hundred boxes a few units across, 1e7 units from the origin, and the same scene
        // shrunk to a millimetre across and moved 1e4 away.
        let scene = builtin::boxworld(100, 5);
        let far = DAffine3::from_translation(DVec3::new(1e7, -3e7, 2e6));
        assert!(assert_index_matches_exhaustive_search(&scene.transformed(&far), 21, 1500) > 0);
        let size = scene.bounds().diagonal();
        let tiny = DAffine3::from_scale_rotation_translation(
            DVec3::splat(1e-3 / size),
            glam::DQuat::from_rotation_y(0.7),
            DVec3::new(-1e4, 5e3, 1e4),
        );
        assert!(assert_index_matches_exhaustive_search(&scene.transformed(&tiny), 22, 1500) > 0);
    }

    #[test]
    fn leaf_boxes_tell_which_triangles_a_box_query_visits() {
        let scene = builtin::builtin("boxworld-100").expect("a built-in scene");
        let vis = Visibility::build(&scene);
        let leaves = vis.leaf_boxes().expect("obvhs nests its boxes");
        assert_eq!(leaves.len(), vis.triangles().len());
        let bounds = scene.bounds();
        let mut rng = SplitMix64::new(13);
        let mut visited = vec![false; leaves.len()];
        for _ in 0..500 {
            let mut corner = || {
                let s = DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64());
                bounds.min + (bounds.max - bounds.min) * s
            };
            let (a, b) = (corner(), corner());
            let query = Bounds {
                min: a.min(b),
                max: a.max(b),
            };
            visited.fill(false);
            vis.triangles_overlapping(query, |t| visited[t] = true);
            let q = vis.query_box(query);
            for (t, leaf) in leaves.iter().enumerate() {
                assert_eq!(visited[t], leaf.overlaps(&q), "triangle {t}");
            }
        }
    }

    #[test]
    fn box_queries_find_every_overlapping_triangle() {
        let scene = builtin::cornell();
        let vis = Visibility::build(&scene);
        let query = Bounds {
            min: DVec3::new(100.0, 100.0, 100.0),
            max: DVec3::new(300.0, 200.0, 300.0),
        };
        let mut found = Vec::new();
        vis.triangles_overlapping(query, |i| found.push(i));
        for (i, t) in vis.triangles().iter().enumerate() {
            if Bounds::from_points(&t.vertices).overlaps(&query) {
                assert!(
                    found.contains(&i),
                    "triangle {i} of surface {} missed",
                    t.surface
                );
            }
        }
    }
}
