//! Visibility: a BVH over every surface, triangulated, answering segment and ray queries in f64.
//!
//! `obvhs` stores f32 boxes. Coordinates are re-centred on the scene before rounding, every box is
//! padded outward by more than the rounding of box and ray, and every candidate triangle is then
//! tested in f64 with the watertight ray–triangle test of Woop, Benthin & Wald (2013): a ray
//! through an edge shared by two triangles hits at least one of them, so light does not leak
//! through the seams of closed geometry.

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
/// Outward padding of the f32 boxes, relative to the scene diagonal (f32 rounding is ~6e-8).
const BOX_PADDING: f64 = 1e-6;

/// One triangle of a scene surface, with the surface's own (unrounded) vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneTriangle {
    pub vertices: [DVec3; 3],
    pub surface: SurfaceId,
}

/// The closest surface along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub surface: SurfaceId,
    pub triangle: usize,
    /// Ray parameter: the hit point is `origin + t * direction`.
    pub t: f64,
    pub point: DVec3,
}

#[derive(Clone, Copy)]
struct PaddedBox(Aabb);

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
pub fn triangulate_scene(scene: &Scene) -> Vec<SceneTriangle> {
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
    pub fn build(scene: &Scene) -> Visibility {
        Visibility::from_triangles(triangulate_scene(scene), scene.bounds())
    }

    pub fn from_triangles(triangles: Vec<SceneTriangle>, bounds: Bounds) -> Visibility {
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
            center,
            unit,
            padding,
            contact: CONTACT_TOLERANCE * diagonal,
        }
    }

    pub fn triangles(&self) -> &[SceneTriangle] {
        &self.triangles
    }

    /// Distance below which a point counts as lying on a surface.
    pub fn contact_distance(&self) -> f64 {
        self.contact
    }

    /// Distance by which ray origins at junctions move into their surface ([`JUNCTION_OFFSET`]).
    pub fn junction_offset(&self) -> f64 {
        self.contact * (JUNCTION_OFFSET / CONTACT_TOLERANCE)
    }

    /// The ray in the f32 world, with a unit direction, and the factor that turns the caller's
    /// ray parameter into the f32 ray's.
    fn f32_ray(&self, origin: DVec3, direction: DVec3, t_max: f64) -> (Ray, f64) {
        let length = direction.length();
        let scale = length / self.unit;
        // The f32 ray only prunes boxes; generous parameter slack keeps that conservative.
        let ray = Ray::new(
            to_vec3a((origin - self.center) / self.unit),
            to_vec3a(direction / length),
            -1e-5,
            if t_max.is_finite() {
                (t_max * scale * (1.0 + 1e-5)) as f32 + 1e-5
            } else {
                f32::INFINITY
            },
        );
        (ray, scale)
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
        let d = to - from;
        let length = d.length();
        if !(length > 2.0 * self.contact) || !d.is_finite() || !from.is_finite() {
            return false;
        }
        let margin = self.contact / length;
        let (t_min, t_max) = (margin, 1.0 - margin);
        let (ray, _) = self.f32_ray(from, d, 1.0);
        !bvh.ray_traverse_miss(ray, |_, id| {
            let index = bvh.primitive_indices[id] as usize;
            let tri = &self.triangles[index];
            if tri.surface == ignore[0] || tri.surface == ignore[1] {
                return f32::INFINITY;
            }
            let n = self.normals[index];
            let anchor = tri.vertices[0];
            if n.dot(from - anchor).abs() <= self.contact
                && n.dot(to - anchor).abs() <= self.contact
            {
                return f32::INFINITY;
            }
            match intersect_watertight(from, d, &tri.vertices) {
                Some(t) if t > t_min && t < t_max => 0.0,
                _ => f32::INFINITY,
            }
        })
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
        if !origin.is_finite() || !direction.is_finite() || direction == DVec3::ZERO {
            return None;
        }
        let (ray, scale) = self.f32_ray(origin, direction, t_max);
        let mut best: Option<(f64, usize)> = None;
        let mut hit = RayHit::none();
        bvh.ray_traverse(ray, &mut hit, |_, id| {
            let index = bvh.primitive_indices[id] as usize;
            let tri = &self.triangles[index];
            if Some(tri.surface) == ignore {
                return f32::INFINITY;
            }
            match intersect_watertight(origin, direction, &tri.vertices) {
                Some(t) if t > t_min && t < t_max => {
                    if best.is_none_or(|(bt, _)| t < bt) {
                        best = Some((t, index));
                    }
                    // Round up so that the f32 traversal never prunes a closer f64 hit.
                    ((t * scale * (1.0 + 1e-6)) as f32).max(f32::MIN_POSITIVE) + 1e-6
                }
                _ => f32::INFINITY,
            }
        });
        best.map(|(t, triangle)| Hit {
            surface: self.triangles[triangle].surface,
            triangle,
            t,
            point: origin + direction * t,
        })
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
    /// the sections at the ends of [`SHAFT_SLICES`] ranges of `t` cover it; one box around a
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
    // Padding covers the f32 rounding of both the box and the rays tested against it.
    let lo = (b.min - center) / unit;
    let hi = (b.max - center) / unit;
    let slack = padding + 2f64.powi(-22) * lo.abs().max(hi.abs()).max_element();
    Aabb::new(
        to_vec3a(lo - DVec3::splat(slack)),
        to_vec3a(hi + DVec3::splat(slack)),
    )
}

/// Watertight ray–triangle intersection (Woop, Benthin & Wald 2013) in f64; no back-face culling.
/// Returns the ray parameter of the hit. Points on an edge or a vertex count as hits.
pub fn intersect_watertight(origin: DVec3, direction: DVec3, v: &[DVec3; 3]) -> Option<f64> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin;
    use crate::rng::SplitMix64;

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
