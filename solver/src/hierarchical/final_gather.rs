//! The final gather (Lischinski, Tampieri & Greenberg 1993): the display mesh's vertices are not
//! given their element's constant radiosity, but gather the reflected light themselves, along the
//! links of the leaf that holds them and of its ancestors, with point-to-element form factors.
//! Between them those links see every source once, so a vertex's value is the hierarchy's
//! solution seen from that point: smooth where the light is smooth, with no blocks at element
//! boundaries. Links that shaft culling left partial get their own rays from the vertex.
//!
//! A linked cluster is a point at its centre only for vertices [`FAR_DISTANCE`] of its radii
//! away; nearer ones see it through its children. As a point, the lit top of CornellBox-Sphere's
//! sphere, half a metre from the back wall, lit the wall's upper half 8 % too little.
//!
//! Leaves near the vertex are the exception. Next to a concave junction half of what a point
//! sees is the strip of the other surface right beside it, darker than that surface's elements
//! on average (it sees the first surface's dark strip in turn), so a leaf's mean radiosity
//! overstates it. Near leaves are therefore gathered again with their radiosity linear over them,
//! from their vertices' values of the gather before.
//!
//! A point where surfaces meet takes the one-sided limit of each form factor from inside its own
//! surface when a source's plane passes within the meeting distance of it
//! (`Visibility::meeting_distance`), on either side: walls read from files meet only to the
//! files' rounding, and a vertex a hair behind the wall it meets would otherwise see nothing of
//! it.
//!
//! Each point also sums the form factors it gathers along (`unit`, the irradiance a radiosity of
//! one everywhere would give), so that its light can be scaled to its total as the leaves' are
//! ([`super::totals`]): to one inside a closed solid, and never above one.

use std::f64::consts::PI;

use glam::DVec3;
use penumbra_scenes::SplitMix64;
use penumbra_scenes::{Rgb, SurfaceId};
use smallvec::SmallVec;

use super::iterate::{Field, System};
use super::links::{Link, Transfer};
use super::transfer::{FAR_DISTANCE, barycentric_nearest, leaf_factor, point_factor};
use crate::elements::Element;
use crate::lambert::ReceivingPoint;

/// Gathers at points along the links of a solved system.
pub(crate) struct FinalGather<'a> {
    pub system: &'a System<'a>,
    pub field: &'a Field,
    pub visibility: &'a penumbra_scenes::Visibility,
    pub elements: &'a [Element],
    pub rays: usize,
    pub seed: u64,
}

/// What a point gathers: from near leaves, and from everything else, the sum of the form factors
/// it gathered along, and the rays cast.
#[derive(Clone, Debug, Default)]
pub(crate) struct Gathered {
    pub near: Rgb,
    pub far: Rgb,
    pub unit: f64,
    pub rays: u64,
    /// The fraction of each partial near leaf seen, in the order of the links, for the gathers
    /// that follow.
    pub near_visible: SmallVec<[f32; 8]>,
}

/// A partial link that brings less than this share of the light the vertex's leaf receives in
/// the hierarchy gets [`MINOR_RAYS`] rays, not the full count: its visibility's noise is a small
/// part of a small part.
const MINOR_SHARE: f64 = 0.02;
const MINOR_RAYS: usize = 4;

/// Levels below a linked element whose radiosities a vertex gathers.
const SOURCE_LEVELS: u32 = 3;

/// Levels below a linked cluster that a vertex near it sees it through: enough for a vertex a
/// quarter of the cluster's radius away (each level takes a node's radius down by about √2).
const CLUSTER_LEVELS: u32 = 8;

/// Rounds of subdividing a near leaf to integrate its linear radiosity against the kernel.
const LINEAR_DEPTH: u32 = 4;

impl FinalGather<'_> {
    /// The reflected irradiance at `x`, which lies in `leaf`. With `linear` (the reflected
    /// radiosity at every vertex, and what the first gather at `x` found of it), near leaves
    /// are linear over their triangles and only they are gathered (`far` is left zero). `key`
    /// picks the point's random streams.
    pub(super) fn irradiance(
        &self,
        x: &ReceivingPoint,
        surface: SurfaceId,
        leaf: u32,
        key: u64,
        linear: Option<(&[Rgb], &Gathered)>,
    ) -> Gathered {
        let h = self.system.hierarchy;
        let mut out = Gathered::default();
        let mut seen = linear.map(|(_, first)| first.near_visible.iter());
        // Links that bring little of the light get fewer rays.
        let minor = MINOR_SHARE * self.field.irradiance[leaf as usize].mean();
        for node in h.ancestry(leaf) {
            for link in self.system.links_of(node) {
                let sn = h.node(link.source);
                let near = sn.is_leaf()
                    && !sn.is_cluster()
                    && x.point.distance_squared(sn.centroid)
                        < (FAR_DISTANCE * sn.radius) * (FAR_DISTANCE * sn.radius);
                if linear.is_some() && !near {
                    continue;
                }
                let (unoccluded, unit) = match linear {
                    Some((vertex_b, _)) => self.linear_leaf(x, link.source, vertex_b),
                    None => self.unoccluded(x, link),
                };
                let known = match (&mut seen, link.partial && near) {
                    (Some(list), true) => list.next().map(|&f| f as f64),
                    _ => None,
                };
                // A cluster's link carries little light (the oracle refines any that carries
                // much), so its own visible fraction serves every point of its receiver.
                let cluster_visible = match link.transfer {
                    Transfer::Far { visible, .. } => Some(visible),
                    Transfer::Factor { .. } => None,
                };
                let visible = match known.or(cluster_visible) {
                    Some(visible) => visible,
                    None if link.partial && (near || unit > 0.0) => {
                        let rays = if unoccluded.mean() < minor {
                            MINOR_RAYS.min(self.rays)
                        } else {
                            self.rays
                        };
                        let (visible, rays) =
                            self.visible_fraction(x, surface, link.source, key, rays);
                        out.rays += rays;
                        if near {
                            out.near_visible.push(visible as f32);
                        }
                        visible
                    }
                    None => 1.0,
                };
                let value = unoccluded * visible;
                out.unit += unit * visible;
                if near {
                    out.near += value;
                } else {
                    out.far += value;
                }
            }
        }
        out
    }

    /// What `x` receives from `link`'s source, unoccluded, at the source's mean radiosity, and
    /// what it would receive at a radiosity of one.
    fn unoccluded(&self, x: &ReceivingPoint, link: &Link) -> (Rgb, f64) {
        self.source(x, link.source, CLUSTER_LEVELS)
    }

    /// What `x` receives from node `s`, unoccluded, and the form factor: a cluster far from `x`
    /// as a point at its centroid with its intensity toward `x`, a nearer one through its
    /// children (`levels` down at most), an element by [`Self::element_source`].
    fn source(&self, x: &ReceivingPoint, s: u32, levels: u32) -> (Rgb, f64) {
        let h = self.system.hierarchy;
        let sn = h.node(s);
        if !sn.is_cluster() {
            return self.element_source(x, s, SOURCE_LEVELS);
        }
        let offset = x.point - sn.centroid;
        let distance2 = offset.length_squared();
        match sn.children {
            Some([a, b]) if levels > 0 && distance2 < (FAR_DISTANCE * sn.radius).powi(2) => {
                let (la, fa) = self.source(x, a, levels - 1);
                let (lb, fb) = self.source(x, b, levels - 1);
                (la + lb, fa + fb)
            }
            _ => {
                let direction = offset / distance2.sqrt();
                let facing = x.normal.dot(-direction).max(0.0) / distance2;
                let intensity = |field| self.system.radiosities(field).intensity(sn, s, direction);
                (
                    intensity(self.field) * facing,
                    intensity(&self.system.unit).mean() * facing,
                )
            }
        }
    }

    /// What `x` receives from element `s`, unoccluded, with the radiosities of its descendants
    /// `levels` down (a source's mean would miss how its brighter parts lie toward `x`: the
    /// floor's bright middle under the ceiling's middle), and the form factor.
    fn element_source(&self, x: &ReceivingPoint, s: u32, levels: u32) -> (Rgb, f64) {
        let h = self.system.hierarchy;
        match h.node(s).children {
            Some([a, b]) if levels > 0 => {
                let (la, fa) = self.element_source(x, a, levels - 1);
                let (lb, fb) = self.element_source(x, b, levels - 1);
                (la + lb, fa + fb)
            }
            _ => {
                let factor = point_factor(h, x, s, self.visibility.meeting_distance());
                (self.field.b[s as usize] * factor, factor)
            }
        }
    }

    /// What `x` receives from leaf `s` with its radiosity linear over it, from the values at its
    /// vertices: the value at the point of `s` nearest to `x` times the exact form factor (which
    /// takes the one-sided limit at a junction), plus the rest, which vanishes at that point,
    /// integrated over `s`; and the form factor.
    fn linear_leaf(&self, x: &ReceivingPoint, s: u32, vertex_b: &[Rgb]) -> (Rgb, f64) {
        let h = self.system.hierarchy;
        let triangle = &h.triangles[h.node(s).first as usize];
        let t = triangle.points;
        let tol = self.visibility.meeting_distance();
        if !x.in_front_of(t[0], triangle.normal, tol) {
            return (Rgb::ZERO, 0.0);
        }
        let b = self.elements[triangle.element as usize]
            .vertices
            .map(|v| vertex_b[v]);
        let nearest = barycentric_nearest(x.point, &t);
        let at = |w: [f64; 3]| b[0] * w[0] + b[1] * w[1] + b[2] * w[2];
        let b0 = at(nearest);
        let factor = leaf_factor(x, &t, triangle.normal, tol);
        let rest = linear_rest(x, triangle.normal, t, b, b0, LINEAR_DEPTH);
        (b0 * factor + rest, factor)
    }

    /// The fraction of node `s` that `x` sees, weighted by the form-factor kernel, from
    /// `strata` stratified rays.
    fn visible_fraction(
        &self,
        x: &ReceivingPoint,
        surface: SurfaceId,
        s: u32,
        key: u64,
        strata: usize,
    ) -> (f64, u64) {
        let h = self.system.hierarchy;
        let mut rng = SplitMix64::keyed(self.seed, &[key, s as u64]);
        let origin = x.point + x.inward * self.visibility.junction_offset();
        let (mut seen, mut weight, mut rays) = (0.0, 0.0, 0);
        for k in 0..strata {
            let (y, t) = h.sample(s, k, strata, &mut rng);
            let d = y - origin;
            let (cx, cy) = (x.normal.dot(d), -t.normal.dot(d));
            if !(cx > 0.0 && cy > 0.0) {
                continue;
            }
            let w = cx * cy / (PI * d.length_squared().powi(2));
            weight += w;
            rays += 1;
            if !self.visibility.occluded(origin, y, [surface, t.surface]) {
                seen += w;
            }
        }
        let fraction = if weight > 0.0 { seen / weight } else { 1.0 };
        (fraction, rays)
    }
}

/// ∫ over triangle `t` (unit normal `normal`, radiosity linear from `b` at its corners) of
/// (B(y) − `b0`) cos θ cos θ' / (π r²) seen from `x`: the three-point rule on pieces split in
/// four until they are smaller than half their distance from `x`, `depth` times at most.
fn linear_rest(
    x: &ReceivingPoint,
    normal: DVec3,
    t: [DVec3; 3],
    b: [Rgb; 3],
    b0: Rgb,
    depth: u32,
) -> Rgb {
    let centroid = (t[0] + t[1] + t[2]) / 3.0;
    let size = t[0]
        .distance(t[1])
        .max(t[1].distance(t[2]))
        .max(t[2].distance(t[0]));
    if depth > 0 && size > 0.5 * centroid.distance(x.point) {
        let mid = |i: usize, j: usize| ((t[i] + t[j]) / 2.0, (b[i] + b[j]) * 0.5);
        let ((p01, b01), (p12, b12), (p20, b20)) = (mid(0, 1), mid(1, 2), mid(2, 0));
        return [
            ([t[0], p01, p20], [b[0], b01, b20]),
            ([p01, t[1], p12], [b01, b[1], b12]),
            ([p20, p12, t[2]], [b20, b12, b[2]]),
            ([p12, p20, p01], [b12, b20, b01]),
        ]
        .into_iter()
        .map(|(pt, pb)| linear_rest(x, normal, pt, pb, b0, depth - 1))
        .sum();
    }
    let area = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
    let (a, c) = (2.0 / 3.0, 1.0 / 6.0);
    [[a, c, c], [c, a, c], [c, c, a]]
        .iter()
        .map(|w| {
            let y = t[0] * w[0] + t[1] * w[1] + t[2] * w[2];
            let d = y - x.point;
            let r2 = d.length_squared();
            let k = x.normal.dot(d).max(0.0) * (-normal.dot(d)).max(0.0) / (PI * r2 * r2);
            let value = b[0] * w[0] + b[1] * w[1] + b[2] * w[2];
            (value - b0) * (k * area / 3.0)
        })
        .sum()
}
