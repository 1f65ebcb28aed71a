//! Links and the oracle that refines them (Hanrahan, Salzman & Aupperle 1991, with clusters as
//! in Smits, Arvo & Greenberg 1994).
//!
//! A link carries light from a source node to a receiver node. Linking starts from the root
//! cluster's link to itself; a link is kept when the light it would carry wrongly is below the
//! tolerance, and otherwise replaced by the links of the larger node's children. What a link
//! carries wrongly (BF refinement) is the receiver's reflectance times its area times:
//! - between elements, the source's radiosity times the spread of the form factor over the
//!   receiver (at its quadrature points and corners), and the form factor times half the range
//!   of the source's leaves' radiosities; nodes whose spheres overlap allow only a bound, all
//!   the light the link could carry;
//! - from or to a cluster, all the light the link carries (a cluster's light is only
//!   approximately directional, see [`super::transfer`]).
//!
//! The oracle's form factors are quick (centroids, corners); a kept link's is computed with a
//! finer rule over the receiver ([`super::tree::Hierarchy::fine_quadrature`]).
//!
//! Visibility comes from shaft culling ([`super::shaft`]); only partial links cast rays, a
//! stratified, seeded set between the two nodes.

use glam::DVec3;
use penumbra_scenes::SplitMix64;
use penumbra_scenes::{Rgb, Visibility};
use rayon::prelude::*;

use super::directions::{self, Table};
use super::shaft::{Shafts, Sight};
use super::transfer::{
    FAR_DISTANCE, element_intensity, far_factor, leaf_factor, point_factor, triangle_mean,
};
use super::tree::{Hierarchy, NONE, Node};
use crate::SolverOptions;
use crate::lambert::ReceivingPoint;

/// How light goes along a link.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Transfer {
    /// Element to element: the receiver's mean irradiance is `factor` times the source's
    /// radiosity; `spread` is the form factor's range over the receiver (unoccluded), `visible`
    /// the fraction of it left by occlusion (already in `factor`).
    Factor {
        factor: f64,
        spread: f64,
        visible: f64,
    },
    /// From or to a cluster: the source's intensity along unit `direction` (source to receiver),
    /// over the squared `distance`, times the fraction `visible` of open segments.
    Far {
        direction: DVec3,
        distance2: f64,
        visible: f64,
    },
}

#[derive(Clone, Copy, Debug)]
pub(crate) struct Link {
    pub receiver: u32,
    pub source: u32,
    pub transfer: Transfer,
    /// Whether shaft culling left some blocker: the final gather casts rays for such links.
    pub partial: bool,
}

/// The solution the oracle judges links by: every element's mean reflected radiosity, every
/// cluster's power, and the large clusters' intensities over directions.
pub(crate) struct Radiosities<'s> {
    pub b: &'s [Rgb],
    /// Each cluster's power (W), by slot.
    pub power: &'s [Rgb],
    /// The least and greatest radiosity of each element's leaves.
    pub low: &'s [Rgb],
    pub high: &'s [Rgb],
    /// The mean radiosity each element gathers (zero before any is gathered).
    pub incoming: &'s [Rgb],
    /// Each node's slot in `power` (clusters only).
    pub slot: &'s [u32],
    /// Intensities of large clusters, and each node's slot among them.
    pub tables: &'s [Table],
    pub table_slot: &'s [u32],
    pub hierarchy: &'s Hierarchy,
}

impl Radiosities<'_> {
    /// Half the range of element `id`'s leaves' radiosities: how far its mean may be from its
    /// parts (a light in the middle of a wall leaves halves of equal means).
    pub(super) fn spread(&self, id: u32) -> Rgb {
        (self.high[id as usize] - self.low[id as usize]) * 0.5
    }

    /// How far element `s`'s light may be from what element `r` gathers on average, per unit
    /// form factor: a leaf's gathered light is scaled to its total, so a form factor off by δ
    /// brings δ times the source's difference from that mean wrongly, not δ times the source;
    /// and the source's mean stands for parts up to its spread away.
    pub(super) fn excess(&self, r: u32, s: u32) -> Rgb {
        let difference = (self.b[s as usize] - self.incoming[r as usize]).map(f64::abs);
        difference + self.spread(s)
    }

    /// The power the source sends (W).
    pub(super) fn power(&self, node: &Node, id: u32) -> Rgb {
        if node.is_cluster() {
            self.power[self.slot[id as usize] as usize]
        } else {
            self.b[id as usize] * node.area
        }
    }

    /// The source's intensity toward unit `d` (W/sr): an element's exactly; a cluster of at
    /// most [`EXACT_CLUSTER_SURFACES`] surfaces as the sum of its surfaces', a larger one from
    /// its table of intensities ([`directions`]).
    pub(super) fn intensity(&self, node: &Node, id: u32, d: DVec3) -> Rgb {
        match node.children {
            _ if self.table_slot[id as usize] != NONE => {
                directions::intensity(&self.tables[self.table_slot[id as usize] as usize], d)
            }
            Some(children) if node.is_cluster() => children
                .iter()
                .map(|&c| self.intensity(self.hierarchy.node(c), c, d))
                .sum(),
            _ => self.b[id as usize] * element_intensity(node, d),
        }
    }
}

/// Clusters of at most this many surfaces send their light as the sum of their surfaces' (a
/// walk of twice as many nodes); larger ones keep a table of their intensities over directions.
/// On CornellBox-Sphere's floor (full solution, 30,000-path reference) the sum over clusters of
/// up to 64 surfaces, with light per axis direction above that, gave 1.4 % RMS; up to 256, 0.73 %
/// (and the gather on CornellBox-Lucy took 80 % longer).
pub(crate) const EXACT_CLUSTER_SURFACES: u32 = 64;

/// What refinement counted.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct RefineCounts {
    /// Pairs of nodes found hidden from each other by one polygon, and not linked.
    pub hidden: u64,
    pub rays: u64,
}

impl RefineCounts {
    pub(super) fn add(&mut self, other: RefineCounts) {
        self.hidden += other.hidden;
        self.rays += other.rays;
    }
}

/// A leaf's form factor to a source is integrated finely when it varies over the leaf by more
/// than this fraction of its mean, in at most [`LEAF_DEPTH`] rounds of splitting in four.
const LEAF_SPREAD: f64 = 0.05;
const LEAF_DEPTH: u32 = 2;

/// How far toward a receiver's corners its form factors are judged, from its centroid.
const CORNER_SHRINK: f64 = 0.98;

/// Below this sum of the two nodes' depths, a link's children are refined in parallel.
const PARALLEL_DEPTH: u16 = 10;

/// Everything refinement needs, borrowed.
pub(crate) struct Refiner<'a> {
    pub hierarchy: &'a Hierarchy,
    pub shafts: &'a Shafts<'a>,
    /// Light a link may carry wrongly (W, channel mean).
    pub tolerance: f64,
    pub rays: usize,
    pub seed: u64,
    /// Distance under which a point counts as lying on a plane.
    pub tol: f64,
    /// The run's options, whose deadline and interrupt end refinement early (the links then
    /// stop where they are; the sweeps that follow stop at once too).
    pub stop: Option<&'a SolverOptions>,
}

impl Refiner<'_> {
    /// Whether the run must stop now.
    fn must_stop(&self) -> bool {
        self.stop.is_some_and(|o| o.stop_now().is_some())
    }

    fn visibility(&self) -> &Visibility {
        self.shafts.visibility
    }

    /// The links that replace the link from `s` to `r` (itself, if it holds), appended to `out`.
    /// `candidates` are the blockers of a shaft that holds this pair's.
    pub(super) fn refine(
        &self,
        r: u32,
        s: u32,
        candidates: Option<&[u32]>,
        state: &Radiosities,
        out: &mut Vec<Link>,
        counts: &mut RefineCounts,
    ) {
        if self.must_stop() {
            return;
        }
        let h = self.hierarchy;
        let (rn, sn) = (h.node(r), h.node(s));
        if r == s {
            // A cluster's light among its own parts; an element cannot see itself.
            if let Some([a, b]) = rn.children.filter(|_| rn.is_cluster()) {
                let pairs = [(a, a), (a, b), (b, a), (b, b)];
                self.refine_all(&pairs, candidates, 2 * rn.depth, state, out, counts);
            }
            return;
        }
        if rn.surface.is_some() && rn.surface == sn.surface {
            return;
        }
        if behind(sn, rn, self.tol) || behind(rn, sn, self.tol) {
            return;
        }
        let (transfer, error) = self.estimate(r, s, state);
        // Between clusters that are split anyway the shaft is not worth its cost (a box's hull
        // has many faces and a cluster's shaft holds many triangles): their children look for
        // their own blockers.
        let sight = if error > self.tolerance && rn.is_cluster() && sn.is_cluster() {
            Sight::Blocked
        } else {
            self.shafts.classify(rn, sn, candidates)
        };
        if sight == Sight::Hidden {
            counts.hidden += 1;
            return;
        }
        let split = if error <= self.tolerance {
            None
        } else {
            match (rn.children, sn.children) {
                (None, None) => None,
                (Some(c), None) => Some((c, true)),
                (None, Some(c)) => Some((c, false)),
                (Some(rc), Some(sc)) => Some(if rn.radius >= sn.radius {
                    (rc, true)
                } else {
                    (sc, false)
                }),
            }
        };
        // What the children's shafts (inside this one) need to test.
        let blockers: Option<&[u32]> = match &sight {
            Sight::Partial(list) => Some(list),
            Sight::Blocked => None,
            Sight::Full | Sight::Hidden => Some(&[]),
        };
        match split {
            Some((children, receiver_side)) => {
                let pairs = children.map(|c| if receiver_side { (c, s) } else { (r, c) });
                let depth = rn.depth + sn.depth;
                self.refine_all(&pairs, blockers, depth, state, out, counts);
            }
            None => {
                let partial = sight != Sight::Full;
                let transfer = match transfer {
                    Transfer::Factor { spread, .. } => self.factor(r, s, spread),
                    far => far,
                };
                let transfer = if partial {
                    self.occlude(r, s, transfer, counts)
                } else {
                    transfer
                };
                out.push(Link {
                    receiver: r,
                    source: s,
                    transfer,
                    partial,
                });
            }
        }
    }

    /// [`Self::refine`] for each pair, in parallel for shallow pairs, collected in order.
    fn refine_all(
        &self,
        pairs: &[(u32, u32)],
        candidates: Option<&[u32]>,
        depth: u16,
        state: &Radiosities,
        out: &mut Vec<Link>,
        counts: &mut RefineCounts,
    ) {
        if depth >= PARALLEL_DEPTH {
            for &(x, y) in pairs {
                self.refine(x, y, candidates, state, out, counts);
            }
            return;
        }
        let parts: Vec<(Vec<Link>, RefineCounts)> = pairs
            .par_iter()
            .map(|&(x, y)| {
                let (mut links, mut c) = (Vec::new(), RefineCounts::default());
                self.refine(x, y, candidates, state, &mut links, &mut c);
                (links, c)
            })
            .collect();
        for (links, c) in parts {
            out.extend(links);
            counts.add(c);
        }
    }

    /// The link's unoccluded transfer, and the light it would carry wrongly (W). Nodes nearer
    /// than their radii allow no estimate but a bound: the receiver reflects at most all the
    /// light the source sends, and at most its own area times the source's radiosity.
    fn estimate(&self, r: u32, s: u32, state: &Radiosities) -> (Transfer, f64) {
        let h = self.hierarchy;
        let (rn, sn) = (h.node(r), h.node(s));
        if rn.is_cluster() || sn.is_cluster() {
            let offset = rn.centroid - sn.centroid;
            let distance2 = offset.length_squared().max(f64::MIN_POSITIVE);
            let direction = offset / distance2.sqrt();
            let transfer = Transfer::Far {
                direction,
                distance2,
                visible: 1.0,
            };
            if touching(rn, sn) {
                return (transfer, self.bound(r, s, state));
            }
            let facing = if rn.is_cluster() {
                1.0
            } else {
                rn.normal.dot(-direction).max(0.0)
            };
            let irradiance = state.intensity(sn, s, direction) * (facing / distance2);
            return (transfer, carried(rn, irradiance, rn.area));
        }
        // A quick estimate decides, and a kept link gets its factor the careful way (the quick
        // spread is kept for judging it again).
        let (factor, spread) = self.quick_factor(r, s);
        let transfer = Transfer::Factor {
            factor,
            spread,
            visible: 1.0,
        };
        (transfer, self.factor_error(r, s, factor, spread, state))
    }

    /// The form factor from element `r` to element `s` at `r`'s quadrature points and corners,
    /// `s` seen from afar (or exactly, if a leaf): their weighted mean and their spread.
    fn quick_factor(&self, r: u32, s: u32) -> (f64, f64) {
        let h = self.hierarchy;
        let (rn, sn) = (h.node(r), h.node(s));
        let far = (FAR_DISTANCE * sn.radius).powi(2);
        let at = |p: DVec3| match sn.children {
            None if p.distance_squared(sn.centroid) < far => leaf_factor(
                &ReceivingPoint::interior(p, rn.normal),
                &h.triangles[sn.first as usize].points,
                sn.normal,
                self.tol,
            ),
            _ => far_factor(p, rn.normal, sn),
        };
        let points = h.quadrature(r);
        let factors: smallvec::SmallVec<[f64; 4]> = points.iter().map(|&(p, _)| at(p)).collect();
        let factor: f64 = factors.iter().zip(&points).map(|(f, (_, w))| f * w).sum();
        (factor, spread(&factors, rn, at))
    }

    /// What a link can carry wrongly at most: between clusters all the light the source sends;
    /// between elements a form factor is at most one and at most the source's area over the
    /// receiver's, so the receiver reflects at most the smaller area times the source's
    /// [`Radiosities::excess`] wrongly.
    fn bound(&self, r: u32, s: u32, state: &Radiosities) -> f64 {
        let (rn, sn) = (self.hierarchy.node(r), self.hierarchy.node(s));
        let power = state.power(sn, s);
        let limit = if sn.is_cluster() || rn.is_cluster() {
            power
        } else {
            state.excess(r, s) * rn.area.min(sn.area)
        };
        carried(rn, limit, 1.0)
    }

    /// The link from element `s` to element `r` with its mean form factor computed carefully
    /// (`spread`, its quick spread over `r`, is kept with it).
    fn factor(&self, r: u32, s: u32, spread: f64) -> Transfer {
        let h = self.hierarchy;
        let (rn, sn) = (h.node(r), h.node(s));
        let at = |p: DVec3| point_factor(h, &ReceivingPoint::interior(p, rn.normal), s, self.tol);
        let mut factor: f64 = h.fine_quadrature(r).iter().map(|&(p, w)| at(p) * w).sum();
        // A leaf cannot be split: where the form factor varies much over it (next to a
        // junction, where it rises toward one half), its mean is integrated more finely, from
        // leaves (inner sources varying that much are split by the oracle unless they send
        // little).
        if rn.is_leaf() && sn.is_leaf() && spread > LEAF_SPREAD * factor {
            let t = &h.triangles[rn.first as usize].points;
            factor = triangle_mean(t, &at, LEAF_DEPTH);
        }
        Transfer::Factor {
            factor,
            spread,
            visible: 1.0,
        }
    }

    /// The light an element-to-element link with form factor `factor` (spread `spread` over
    /// the receiver) carries wrongly; for nodes whose spheres overlap, one of which can still be
    /// split, only the bound tells.
    fn factor_error(&self, r: u32, s: u32, factor: f64, spread: f64, state: &Radiosities) -> f64 {
        let (rn, sn) = (self.hierarchy.node(r), self.hierarchy.node(s));
        if touching(rn, sn) && (rn.children.is_some() || sn.children.is_some()) {
            return self.bound(r, s, state);
        }
        // The source's mean stands for parts up to its spread away from it.
        let difference = (state.b[s as usize] - state.incoming[r as usize]).map(f64::abs);
        let wrong = difference * spread + state.spread(s) * factor;
        carried(rn, wrong, rn.area)
    }

    /// The error a kept link still carries, with the radiosities as they are now: links over
    /// `tolerance` are refined again.
    pub(super) fn error_of(&self, link: &Link, state: &Radiosities) -> f64 {
        let (r, s) = (link.receiver, link.source);
        match link.transfer {
            Transfer::Factor { factor, spread, .. } => {
                self.factor_error(r, s, factor, spread, state)
            }
            Transfer::Far { .. } => self.estimate(r, s, state).1,
        }
    }

    /// The transfer times the fraction of stratified segments between the two nodes that
    /// nothing blocks (weighted by the form-factor kernel between elements).
    fn occlude(&self, r: u32, s: u32, transfer: Transfer, counts: &mut RefineCounts) -> Transfer {
        let h = self.hierarchy;
        let mut rng = SplitMix64::keyed(self.seed, &[r as u64, s as u64]);
        let vis = self.visibility();
        let offset = vis.junction_offset();
        let (mut seen, mut weight) = (0.0, 0.0);
        for k in 0..self.rays {
            let (x, xt) = h.sample(r, k, self.rays, &mut rng);
            let (y, yt) = h.sample(s, (k * 7 + 3) % self.rays, self.rays, &mut rng);
            let (xs, ys) = (xt.surface, yt.surface);
            let d = y - x;
            let w = (xt.normal.dot(d) * -yt.normal.dot(d)).max(0.0) / d.length_squared().powi(2);
            if !(w > 0.0) {
                continue;
            }
            weight += w;
            counts.rays += 1;
            // Each end moves off its surface a little, so that no segment runs along a surface
            // it starts on.
            let from = x + d.normalize_or_zero() * offset;
            let to = y - d.normalize_or_zero() * offset;
            if !vis.occluded(from, to, [xs, ys]) {
                seen += w;
            }
        }
        let visible = if weight > 0.0 { seen / weight } else { 1.0 };
        match transfer {
            Transfer::Factor { factor, spread, .. } => Transfer::Factor {
                factor: factor * visible,
                spread,
                visible,
            },
            Transfer::Far {
                direction,
                distance2,
                ..
            } => Transfer::Far {
                direction,
                distance2,
                visible,
            },
        }
    }
}

/// The range of `factors` and of `at` at the receiver's corners. The spread is judged at its
/// extremes too (its hull's corners, drawn in a little off any plane they touch): next to a
/// junction the form factor changes most at the edge, where no inner point sees it.
fn spread(factors: &[f64], rn: &Node, at: impl Fn(DVec3) -> f64) -> f64 {
    let corners = rn
        .hull
        .iter()
        .map(|&c| at(rn.centroid + (c - rn.centroid) * CORNER_SHRINK));
    let (lo, hi) = factors
        .iter()
        .copied()
        .chain(corners)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), f| {
            (lo.min(f), hi.max(f))
        });
    (hi - lo).max(0.0)
}

/// The light (W, one number) that an error of `irradiance` times `area` on `receiver` amounts
/// to. Weighed by the receiver's mean reflectance against the error's mean, not channel by
/// channel: a link between a red wall and a blue one carries no light that either reflects, yet
/// its form factor sets both walls' totals, so the light they send out of the scene and the
/// energy balance; judged by colour, such links stayed as coarse as the two whole walls and read
/// their form factor a third too high. A surface that reflects nothing weighs all of it, since
/// what it receives is the light it absorbs, which the energy account and its total rest on (an
/// emitter's total says how much of its light leaves the scene).
fn carried(receiver: &Node, irradiance: Rgb, area: f64) -> f64 {
    let weight = if receiver.reflects() {
        receiver.reflectance.mean()
    } else {
        1.0
    };
    weight * irradiance.mean() * area
}

/// Whether two nodes' bounding spheres overlap: then no estimate holds, only a bound.
fn touching(a: &Node, b: &Node) -> bool {
    a.centroid.distance(b.centroid) <= a.radius + b.radius
}

/// Whether element `a` lies wholly behind (or in) the plane of element `b` (so `b` cannot send
/// it light, nor receive light from it); never for clusters.
fn behind(a: &Node, b: &Node, tol: f64) -> bool {
    if b.is_cluster() {
        return false;
    }
    a.hull.iter().all(|&p| b.normal.dot(p - b.centroid) <= tol)
}
