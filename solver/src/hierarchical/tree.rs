//! The hierarchy the hierarchical solver links: on every surface that reflects light, a binary
//! tree over its mesh triangles (split in two halves of about equal area across the longer axis
//! of their centroids, so the leaves are the discontinuity mesh's own triangles and every
//! discontinuity is an element boundary, as in Lischinski, Tampieri & Greenberg 1993), and above
//! the surfaces a binary tree of clusters (split at the median of the surfaces' centroids), so
//! that linking starts from one cluster and is never quadratic in the number of polygons.
//!
//! Triangles are stored in the order of a depth-first walk, so every node, element or cluster,
//! holds a contiguous range of them: points are sampled on any node by area in one search.

use glam::DVec3;
use penumbra_scenes::SplitMix64;
use penumbra_scenes::{Bounds, Rgb, SurfaceId};
use smallvec::SmallVec;

use crate::elements::Discretization;

/// No node (the parent of a root).
pub(crate) const NONE: u32 = u32::MAX;

/// An element (a part of one surface) or a cluster (a group of surfaces).
#[derive(Clone, Debug)]
pub(crate) struct Node {
    pub children: Option<[u32; 2]>,
    pub parent: u32,
    /// The surface of an element; `None` for a cluster.
    pub surface: Option<SurfaceId>,
    /// Its triangles: `first..end` of [`Hierarchy::triangles`].
    pub first: u32,
    pub end: u32,
    pub area: f64,
    /// The area-weighted centroid.
    pub centroid: DVec3,
    /// The surface's unit normal (zero for a cluster).
    pub normal: DVec3,
    /// The largest distance from the centroid to a point of the node.
    pub radius: f64,
    pub bounds: Bounds,
    /// Points whose convex hull holds the node: a leaf's triangle, an element's bounding
    /// rectangle in its plane, or a cluster's box.
    pub hull: SmallVec<[DVec3; 8]>,
    /// An element's principal half-axes in its plane, scaled so that the four points centroid
    /// ± axis, each with a quarter of the area, have the element's second moments of area (zero
    /// for clusters).
    pub axes: [DVec3; 2],
    /// An element's reflectance; for a cluster, the largest of its surfaces' per channel.
    pub reflectance: Rgb,
    /// The surfaces it holds: one for an element.
    pub surfaces: u32,
    pub depth: u16,
}

impl Node {
    pub(super) fn is_cluster(&self) -> bool {
        self.surface.is_none()
    }

    pub(super) fn is_leaf(&self) -> bool {
        self.children.is_none()
    }

    /// Whether the node reflects any light (a cluster: some surface in it does).
    pub(super) fn reflects(&self) -> bool {
        self.reflectance.max_channel() > 0.0
    }
}

/// One mesh triangle in the hierarchy's order.
#[derive(Clone, Debug)]
pub(crate) struct Triangle {
    pub surface: SurfaceId,
    /// Its index among the discretization's elements.
    pub element: u32,
    pub points: [DVec3; 3],
    pub area: f64,
    pub normal: DVec3,
}

/// Every node, the triangles in walk order, and where each element's leaf is.
#[derive(Debug)]
pub(crate) struct Hierarchy {
    pub nodes: Vec<Node>,
    pub root: Option<u32>,
    pub triangles: Vec<Triangle>,
    /// Area of the triangles before each one and including it, for sampling by area.
    pub cumulative_area: Vec<f64>,
    /// The leaf of each element of the discretization (`NONE` for elements without area).
    pub leaf_of_element: Vec<u32>,
}

impl Hierarchy {
    /// The hierarchy over the elements of `disc`. Surfaces that reflect nothing are in it too:
    /// they send no reflected light, but what they receive counts in each receiver's total and
    /// in the energy account (light that meets a black wall is absorbed, not lost).
    pub(super) fn build(
        disc: &Discretization,
        reflectance: impl Fn(SurfaceId) -> Rgb,
    ) -> Hierarchy {
        let mut by_surface: Vec<Vec<u32>> = vec![Vec::new(); disc.offsets.len()];
        for (i, e) in disc.elements.iter().enumerate() {
            if e.area > 0.0 {
                by_surface[e.surface].push(i as u32);
            }
        }
        let mut builder = Builder {
            disc,
            reflectance: &reflectance,
            by_surface,
            moments: Vec::new(),
            hierarchy: Hierarchy {
                nodes: Vec::new(),
                root: None,
                triangles: Vec::new(),
                cumulative_area: Vec::new(),
                leaf_of_element: vec![NONE; disc.elements.len()],
            },
        };
        let mut surfaces: Vec<SurfaceId> = (0..disc.offsets.len())
            .filter(|&s| !builder.by_surface[s].is_empty())
            .collect();
        if !surfaces.is_empty() {
            let root = builder.cluster(&mut surfaces, NONE, 0);
            builder.hierarchy.root = Some(root);
        }
        let mut h = builder.hierarchy;
        let mut total = 0.0;
        h.cumulative_area = h
            .triangles
            .iter()
            .map(|t| {
                total += t.area;
                total
            })
            .collect();
        h
    }

    pub(super) fn node(&self, id: u32) -> &Node {
        &self.nodes[id as usize]
    }

    /// A point of node `id` in stratum `k` of `strata` (equal shares of its area), uniform in
    /// the triangle the stratum's draw falls in, and that triangle.
    pub(super) fn sample(
        &self,
        id: u32,
        k: usize,
        strata: usize,
        rng: &mut SplitMix64,
    ) -> (DVec3, &Triangle) {
        let n = self.node(id);
        let (first, end) = (n.first as usize, n.end as usize);
        let before = if first == 0 {
            0.0
        } else {
            self.cumulative_area[first - 1]
        };
        let u = before + (k as f64 + rng.next_f64()) / strata as f64 * n.area;
        let idx =
            (first + self.cumulative_area[first..end].partition_point(|&c| c < u)).min(end - 1);
        let t = &self.triangles[idx];
        let (r1, r2) = (rng.next_f64().sqrt(), rng.next_f64());
        let p =
            t.points[0] * (1.0 - r1) + t.points[1] * (r1 * (1.0 - r2)) + t.points[2] * (r1 * r2);
        (p, t)
    }

    /// Points of element `id` and their weights (summing to one) for averaging over it: a leaf's
    /// three-point rule (exact for quadratics), else the centroids of its grandchildren (or
    /// children, where those are leaves), by area.
    pub(super) fn quadrature(&self, id: u32) -> SmallVec<[(DVec3, f64); 4]> {
        let n = self.node(id);
        let Some(children) = n.children else {
            let t = &self.triangles[n.first as usize].points;
            let at = |a: f64, b: f64, c: f64| t[0] * a + t[1] * b + t[2] * c;
            let (a, b) = (2.0 / 3.0, 1.0 / 6.0);
            return SmallVec::from_slice(&[
                (at(a, b, b), 1.0 / 3.0),
                (at(b, a, b), 1.0 / 3.0),
                (at(b, b, a), 1.0 / 3.0),
            ]);
        };
        let mut out = SmallVec::new();
        for c in children {
            let child = self.node(c);
            match child.children {
                Some(grand) => {
                    for g in grand {
                        let g = self.node(g);
                        out.push((g.centroid, g.area / n.area));
                    }
                }
                None => out.push((child.centroid, child.area / n.area)),
            }
        }
        out
    }

    /// A finer rule than [`Self::quadrature`] for the mean over element `id`: each grandchild
    /// (or leaf child) by its own second-moment rule (centroid ± half-axes) or, for a leaf, its
    /// three-point rule. Centroids alone read a form factor that peaks inside the element too
    /// high (its mean is below its middle's value), and that bias adds up at many bounces.
    pub(super) fn fine_quadrature(&self, id: u32) -> SmallVec<[(DVec3, f64); 16]> {
        let n = self.node(id);
        let mut out = SmallVec::new();
        let mut add = |part: u32| {
            let p = self.node(part);
            let share = p.area / n.area;
            match p.children {
                None => out.extend(
                    self.quadrature(part)
                        .into_iter()
                        .map(|(x, w)| (x, w * share)),
                ),
                Some(_) => {
                    let [a, b] = p.axes;
                    for offset in [a, -a, b, -b] {
                        out.push((p.centroid + offset, share / 4.0));
                    }
                }
            }
        };
        match n.children {
            None => return self.quadrature(id).into_iter().collect(),
            Some(children) => {
                for c in children {
                    match self.node(c).children {
                        Some(grand) => grand.into_iter().for_each(&mut add),
                        None => add(c),
                    }
                }
            }
        }
        out
    }

    /// The nodes from `id` up to the root.
    pub(super) fn ancestry(&self, id: u32) -> impl Iterator<Item = u32> + '_ {
        std::iter::successors(Some(id), |&n| {
            let p = self.node(n).parent;
            (p != NONE).then_some(p)
        })
    }
}

struct Builder<'a, F> {
    disc: &'a Discretization,
    reflectance: &'a F,
    by_surface: Vec<Vec<u32>>,
    hierarchy: Hierarchy,
    /// Per node, an element's second moment of area about its centroid, in its plane's axes.
    moments: Vec<Moment>,
}

impl<F: Fn(SurfaceId) -> Rgb> Builder<'_, F> {
    fn push(&mut self, node: Node) -> u32 {
        self.moments.push(Moment::default());
        self.hierarchy.nodes.push(node);
        (self.hierarchy.nodes.len() - 1) as u32
    }

    /// A cluster over `surfaces` (or the surface's own tree, for one).
    fn cluster(&mut self, surfaces: &mut [SurfaceId], parent: u32, depth: u16) -> u32 {
        if let [s] = surfaces {
            let elements = std::mem::take(&mut self.by_surface[*s]);
            return self.surface(&elements, *s, parent, depth);
        }
        let centroid = |s: SurfaceId| -> DVec3 {
            let (sum, area) = self.by_surface[s]
                .iter()
                .fold((DVec3::ZERO, 0.0), |(p, a), &e| {
                    let e = &self.disc.elements[e as usize];
                    (
                        p + (e.points[0] + e.points[1] + e.points[2]) / 3.0 * e.area,
                        a + e.area,
                    )
                });
            sum / area
        };
        let mut keyed: Vec<(DVec3, SurfaceId)> =
            surfaces.iter().map(|&s| (centroid(s), s)).collect();
        let axis = longest_axis(keyed.iter().map(|k| k.0));
        keyed.sort_by(|a, b| a.0[axis].total_cmp(&b.0[axis]).then(a.1.cmp(&b.1)));
        for (slot, k) in surfaces.iter_mut().zip(&keyed) {
            *slot = k.1;
        }
        let id = self.push(placeholder(parent, depth));
        let first = self.hierarchy.triangles.len() as u32;
        let mid = surfaces.len() / 2;
        let (left, right) = surfaces.split_at_mut(mid);
        let a = self.cluster(left, id, depth + 1);
        let b = self.cluster(right, id, depth + 1);
        let end = self.hierarchy.triangles.len() as u32;
        let (na, nb) = (self.hierarchy.node(a), self.hierarchy.node(b));
        let area = na.area + nb.area;
        let centroid = (na.centroid * na.area + nb.centroid * nb.area) / area;
        let bounds = na.bounds.union(nb.bounds);
        let reflectance = Rgb::new(
            na.reflectance.r.max(nb.reflectance.r),
            na.reflectance.g.max(nb.reflectance.g),
            na.reflectance.b.max(nb.reflectance.b),
        );
        let hull = box_corners(bounds);
        self.hierarchy.nodes[id as usize] = Node {
            children: Some([a, b]),
            surface: None,
            first,
            end,
            area,
            centroid,
            normal: DVec3::ZERO,
            radius: farthest(&hull, centroid),
            bounds,
            hull,
            reflectance,
            surfaces: na.surfaces + nb.surfaces,
            ..placeholder(parent, depth)
        };
        id
    }

    /// The tree over `elements` of surface `s`.
    fn element(&mut self, elements: &mut [u32], s: SurfaceId, parent: u32, depth: u16) -> u32 {
        let disc = self.disc;
        let rho = (self.reflectance)(s);
        let normal = disc.receivers[disc.elements[elements[0] as usize].vertices[0]].normal;
        if let [e] = elements {
            let el = &disc.elements[*e as usize];
            let t = self.hierarchy.triangles.len() as u32;
            self.hierarchy.triangles.push(Triangle {
                surface: s,
                element: *e,
                points: el.points,
                area: el.area,
                normal,
            });
            let centroid = (el.points[0] + el.points[1] + el.points[2]) / 3.0;
            let moment = Moment::of_triangle(&el.points, centroid, normal, el.area);
            let id = self.push(Node {
                children: None,
                parent,
                surface: Some(s),
                first: t,
                end: t + 1,
                area: el.area,
                centroid,
                normal,
                radius: farthest(&el.points, centroid),
                bounds: Bounds::from_points(&el.points),
                hull: SmallVec::from_slice(&el.points),
                axes: moment.axes(normal, el.area),
                reflectance: rho,
                surfaces: 1,
                depth,
            });
            self.moments[id as usize] = moment;
            self.hierarchy.leaf_of_element[*e as usize] = id;
            return id;
        }
        let centroid_of = |e: u32| {
            let p = disc.elements[e as usize].points;
            (p[0] + p[1] + p[2]) / 3.0
        };
        let axis = longest_axis(elements.iter().map(|&e| centroid_of(e)));
        elements.sort_by(|&a, &b| {
            centroid_of(a)[axis]
                .total_cmp(&centroid_of(b)[axis])
                .then(a.cmp(&b))
        });
        // Halves of about equal area, each with at least a quarter of the triangles, so the
        // tree's depth stays logarithmic however the triangles' sizes vary.
        let total: f64 = elements
            .iter()
            .map(|&e| disc.elements[e as usize].area)
            .sum();
        let n = elements.len();
        let mut sum = 0.0;
        let mut mid = n / 2;
        for (i, &e) in elements.iter().enumerate() {
            sum += disc.elements[e as usize].area;
            if sum >= total / 2.0 {
                mid = i + 1;
                break;
            }
        }
        let mid = mid.clamp(n.div_ceil(4).max(1), (n - n / 4).min(n - 1));
        let id = self.push(placeholder(parent, depth));
        let first = self.hierarchy.triangles.len() as u32;
        let (left, right) = elements.split_at_mut(mid);
        let a = self.element(left, s, id, depth + 1);
        let b = self.element(right, s, id, depth + 1);
        self.join(id, [a, b], first, s, normal)
    }

    /// The tree of surface `s`: its connected pieces first (the two sides of a contact line
    /// share no vertex, so the floor under a block is never averaged with the floor beside it:
    /// the strongest discontinuities are split first), then each piece's own tree.
    fn surface(&mut self, elements: &[u32], s: SurfaceId, parent: u32, depth: u16) -> u32 {
        let mut pieces = connected_pieces(self.disc, elements);
        self.pieces(&mut pieces, s, parent, depth)
    }

    fn pieces(&mut self, pieces: &mut [Vec<u32>], s: SurfaceId, parent: u32, depth: u16) -> u32 {
        if let [piece] = pieces {
            return self.element(piece, s, parent, depth);
        }
        let disc = self.disc;
        let centroid = |piece: &Vec<u32>| -> DVec3 {
            let (sum, area) = piece.iter().fold((DVec3::ZERO, 0.0), |(p, a), &e| {
                let e = &disc.elements[e as usize];
                (
                    p + (e.points[0] + e.points[1] + e.points[2]) / 3.0 * e.area,
                    a + e.area,
                )
            });
            sum / area.max(f64::MIN_POSITIVE)
        };
        let axis = longest_axis(pieces.iter().map(centroid));
        pieces.sort_by(|a, b| {
            centroid(a)[axis]
                .total_cmp(&centroid(b)[axis])
                .then(a[0].cmp(&b[0]))
        });
        let normal = disc.receivers[disc.elements[pieces[0][0] as usize].vertices[0]].normal;
        let id = self.push(placeholder(parent, depth));
        let first = self.hierarchy.triangles.len() as u32;
        let mid = pieces.len() / 2;
        let (left, right) = pieces.split_at_mut(mid);
        let a = self.pieces(left, s, id, depth + 1);
        let b = self.pieces(right, s, id, depth + 1);
        self.join(id, [a, b], first, s, normal)
    }

    /// Fills in element node `id` over its two children, whose triangles start at `first`.
    fn join(&mut self, id: u32, [a, b]: [u32; 2], first: u32, s: SurfaceId, normal: DVec3) -> u32 {
        let end = self.hierarchy.triangles.len() as u32;
        let (na, nb) = (self.hierarchy.node(a), self.hierarchy.node(b));
        let area = na.area + nb.area;
        let centroid = (na.centroid * na.area + nb.centroid * nb.area) / area;
        let bounds = na.bounds.union(nb.bounds);
        let hull = plane_rectangle(
            &self.hierarchy.triangles[first as usize..end as usize],
            normal,
            centroid,
        );
        let moment = self.moments[a as usize].shifted(na.centroid - centroid, normal, na.area)
            + self.moments[b as usize].shifted(nb.centroid - centroid, normal, nb.area);
        self.moments[id as usize] = moment;
        let node = &mut self.hierarchy.nodes[id as usize];
        let (parent, depth) = (node.parent, node.depth);
        *node = Node {
            children: Some([a, b]),
            surface: Some(s),
            first,
            end,
            area,
            centroid,
            normal,
            radius: farthest(&hull, centroid),
            bounds,
            hull,
            axes: moment.axes(normal, area),
            reflectance: (self.reflectance)(s),
            ..placeholder(parent, depth)
        };
        id
    }
}

/// `elements` split into groups connected through shared vertices, each group in ascending
/// order, groups ordered by their first element.
fn connected_pieces(disc: &Discretization, elements: &[u32]) -> Vec<Vec<u32>> {
    let mut sets = penumbra_scenes::UnionFind::new(elements.len());
    let mut owner: std::collections::HashMap<usize, usize> = std::collections::HashMap::new();
    for (k, &e) in elements.iter().enumerate() {
        for &v in &disc.elements[e as usize].vertices {
            match owner.get(&v) {
                Some(&j) => sets.join(k, j),
                None => {
                    owner.insert(v, k);
                }
            }
        }
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<u32>> = std::collections::BTreeMap::new();
    for (k, &e) in elements.iter().enumerate() {
        groups.entry(sets.find(k)).or_default().push(e);
    }
    groups.into_values().collect()
}

fn placeholder(parent: u32, depth: u16) -> Node {
    Node {
        children: None,
        parent,
        surface: None,
        first: 0,
        end: 0,
        area: 0.0,
        centroid: DVec3::ZERO,
        normal: DVec3::ZERO,
        radius: 0.0,
        bounds: Bounds {
            min: DVec3::ZERO,
            max: DVec3::ZERO,
        },
        hull: SmallVec::new(),
        axes: [DVec3::ZERO; 2],
        reflectance: Rgb::ZERO,
        surfaces: 1,
        depth,
    }
}

/// The largest distance from `center` to one of `points`.
fn farthest(points: &[DVec3], center: DVec3) -> f64 {
    points
        .iter()
        .map(|p| p.distance(center))
        .fold(0.0, f64::max)
}

/// The axis along which `points` spread most.
fn longest_axis(points: impl Iterator<Item = DVec3>) -> usize {
    let (lo, hi) = points.fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
        (lo.min(p), hi.max(p))
    });
    let extent = hi - lo;
    if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    }
}

/// The eight corners of a box.
fn box_corners(b: Bounds) -> SmallVec<[DVec3; 8]> {
    (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { b.min.x } else { b.max.x },
                if i & 2 == 0 { b.min.y } else { b.max.y },
                if i & 4 == 0 { b.min.z } else { b.max.z },
            )
        })
        .collect()
}

/// The corners, in order around it, of the smallest rectangle holding `triangles` with sides
/// along a fixed pair of axes of the plane through `origin` with unit `normal`.
fn plane_rectangle(triangles: &[Triangle], normal: DVec3, origin: DVec3) -> SmallVec<[DVec3; 8]> {
    let (u, v) = normal.any_orthonormal_pair();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in triangles.iter().flat_map(|t| t.points) {
        let d = p - origin;
        let c = [d.dot(u), d.dot(v)];
        for k in 0..2 {
            lo[k] = lo[k].min(c[k]);
            hi[k] = hi[k].max(c[k]);
        }
    }
    [
        (lo[0], lo[1]),
        (hi[0], lo[1]),
        (hi[0], hi[1]),
        (lo[0], hi[1]),
    ]
    .into_iter()
    .map(|(a, b)| origin + u * a + v * b)
    .collect()
}

/// A second moment of area [xx, xy, yy] in the axes `normal.any_orthonormal_pair()` of a plane.
#[derive(Clone, Copy, Debug, Default)]
struct Moment([f64; 3]);

impl std::ops::Add for Moment {
    type Output = Moment;
    fn add(self, o: Moment) -> Moment {
        Moment([self.0[0] + o.0[0], self.0[1] + o.0[1], self.0[2] + o.0[2]])
    }
}

impl Moment {
    /// ∫ x xᵀ over a triangle about its centroid: A/12 Σ v vᵀ over its corners, relative to it.
    fn of_triangle(points: &[DVec3; 3], centroid: DVec3, normal: DVec3, area: f64) -> Moment {
        let (u, v) = normal.any_orthonormal_pair();
        let mut m = [0.0; 3];
        for p in points {
            let (x, y) = ((*p - centroid).dot(u), (*p - centroid).dot(v));
            m[0] += x * x;
            m[1] += x * y;
            m[2] += y * y;
        }
        Moment(m.map(|c| c * area / 12.0))
    }

    /// The moment about a point `offset` away from the centroid (parallel axes).
    fn shifted(self, offset: DVec3, normal: DVec3, area: f64) -> Moment {
        let (u, v) = normal.any_orthonormal_pair();
        let (x, y) = (offset.dot(u), offset.dot(v));
        self + Moment([area * x * x, area * x * y, area * y * y])
    }

    /// The half-axes a₁, a₂ with (a₁a₁ᵀ + a₂a₂ᵀ) / 2 equal to the covariance (moment / area).
    fn axes(self, normal: DVec3, area: f64) -> [DVec3; 2] {
        let (u, v) = normal.any_orthonormal_pair();
        let [p, q, r] = self.0.map(|c| c / area.max(f64::MIN_POSITIVE));
        let mean = (p + r) / 2.0;
        let radius = (((p - r) / 2.0).powi(2) + q * q).sqrt();
        let (l1, l2) = (mean + radius, (mean - radius).max(0.0));
        // The first eigenvector: of the two forms, the longer (better conditioned) one.
        let (a, b) = ((q, l1 - p), (l1 - r, q));
        let e = if a.0.hypot(a.1) >= b.0.hypot(b.1) {
            a
        } else {
            b
        };
        let norm = e.0.hypot(e.1);
        let (c, s) = if norm > 0.0 {
            (e.0 / norm, e.1 / norm)
        } else {
            (1.0, 0.0)
        };
        let e1 = u * c + v * s;
        let e2 = v * c - u * s;
        [e1 * (2.0 * l1).sqrt(), e2 * (2.0 * l2).sqrt()]
    }
}
