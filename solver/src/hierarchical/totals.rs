//! What each receiver's form factors must sum to: its *total*, the share of its view that
//! surfaces cover.
//!
//! Links push a node's irradiance down to its leaves as a constant, so a leaf inherits form
//! factors averaged over its ancestors, and the factors it gathers along its own links and its
//! ancestors' sum to its total only on average over the surface: on the closed furnace, leaves of
//! a 24,000-triangle mesh summed to between 0.87 and 1.25. In a closed scene such a sum is
//! amplified by ρ / (1 − ρ), and above one the sweeps diverge. So every leaf's gathered light is
//! scaled to its total ([`super::iterate::System::settle_totals`]):
//!
//! - inside a closed solid (a room whose faces meet edge to edge), the total is exactly one,
//!   whatever the occlusion inside ([`crate::solids::Enclosures`]);
//! - elsewhere, it is what the leaf's own links give at the leaf itself: each link's form factor
//!   from the leaf's centroid to the link's source (Lambert's formula near, the four-point rule
//!   far), times the link's visible fraction, and at most one. That keeps the links' visibility
//!   and replaces the average over an ancestor by the leaf's own value.

use glam::DVec3;
use penumbra_scenes::Rgb;
use rayon::prelude::*;

use super::iterate::{System, bounded};
use super::links::Transfer;
use super::transfer::point_factor;
use super::tree::NONE;
use crate::elements::Discretization;
use crate::lambert::ReceivingPoint;
use crate::solids::Enclosures;

/// Per node: whether a leaf lies inside a closed solid (all its vertices do).
pub(super) fn enclosed_leaves(
    disc: &Discretization,
    leaf_of_element: &[u32],
    nodes: usize,
    enclosures: &Enclosures,
) -> (Vec<bool>, Vec<bool>) {
    let vertices: Vec<bool> = (0..disc.receiver_count())
        .into_par_iter()
        .map(|v| enclosures.encloses(&disc.receivers[v], disc.receiver_surface[v]))
        .collect();
    let mut leaves = vec![false; nodes];
    for (e, &leaf) in leaf_of_element.iter().enumerate() {
        if leaf != NONE {
            leaves[leaf as usize] = disc.elements[e].vertices.iter().all(|&v| vertices[v]);
        }
    }
    (leaves, vertices)
}

impl System<'_> {
    /// Every leaf's total (by node; one elsewhere) and the part of it that surfaces which
    /// reflect cover: the total is one inside a closed solid, else the sum of the leaf's links'
    /// form factors at its centroid, at most one; its reflecting part is the share of that sum
    /// along links to surfaces that reflect. Only `stale` leaves are found again once totals
    /// are set; the others keep theirs.
    pub(super) fn leaf_totals(&self, stale: &[bool]) -> (Vec<f64>, Vec<f64>) {
        let h = self.hierarchy;
        (0..h.nodes.len() as u32)
            .into_par_iter()
            .map(|i| {
                let n = h.node(i);
                if !n.is_leaf() || n.is_cluster() {
                    return (1.0, 1.0);
                }
                let i = i as usize;
                if !stale[i] && !self.totals.is_empty() {
                    return (self.totals[i], self.reflecting[i]);
                }
                let (all, reflecting) = self.own_sums(i as u32);
                let total = bounded(all, self.enclosed[i]);
                let share = if all > 0.0 { reflecting / all } else { 1.0 };
                (total, total * share)
            })
            .unzip()
    }

    /// The form factors from `leaf`'s centroid along its links and its ancestors', to every
    /// surface and to those that reflect.
    fn own_sums(&self, leaf: u32) -> (f64, f64) {
        let tol = self.tol;
        let h = self.hierarchy;
        let ln = h.node(leaf);
        let x = ReceivingPoint::interior(ln.centroid, ln.normal);
        let (unit, lit) = (
            self.radiosities(&self.unit),
            self.radiosities(&self.unit_reflecting),
        );
        let mut sums = (0.0, 0.0);
        for r in h.ancestry(leaf) {
            for l in self.links_of(r) {
                let sn = h.node(l.source);
                let (all, reflecting) = match l.transfer {
                    Transfer::Factor {
                        factor, visible, ..
                    } => {
                        let f = if r == leaf {
                            factor
                        } else {
                            point_factor(h, &x, l.source, tol) * visible
                        };
                        (f, if sn.reflects() { f } else { 0.0 })
                    }
                    Transfer::Far { visible, .. } => {
                        let offset = ln.centroid - sn.centroid;
                        let distance2 = offset.length_squared().max(f64::MIN_POSITIVE);
                        let direction: DVec3 = offset / distance2.sqrt();
                        let weight = ln.normal.dot(-direction).max(0.0) * visible / distance2;
                        let intensity = |field: &super::links::Radiosities| -> Rgb {
                            field.intensity(sn, l.source, direction)
                        };
                        (
                            intensity(&unit).mean() * weight,
                            intensity(&lit).mean() * weight,
                        )
                    }
                };
                sums.0 += all;
                sums.1 += reflecting;
            }
        }
        sums
    }
}
