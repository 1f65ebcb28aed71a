//! The final gather (Lischinski, Tampieri & Greenberg 1993): the display mesh's vertices are not
//! given their element's constant radiosity, but gather the reflected light themselves, along the
//! links of the leaf that holds them and of its ancestors, with point-to-element form factors.
//! Between them those links see every source once, so a vertex's value is the hierarchy's
//! solution seen from that point: smooth where the light is smooth, with no blocks at element
//! boundaries. Links that shaft culling left partial get their own rays from the vertex.

use std::f64::consts::PI;

use penumbra_scenes::rng::SplitMix64;
use penumbra_scenes::{Rgb, SurfaceId};

use super::iterate::{Field, System};
use super::links::Link;
use super::transfer::point_factor;
use crate::lambert::ReceivingPoint;

/// Gathers at points along the links of a solved system.
pub(crate) struct FinalGather<'a> {
    pub system: &'a System<'a>,
    pub field: &'a Field,
    pub visibility: &'a penumbra_scenes::Visibility,
    pub rays: usize,
    pub seed: u64,
}

impl FinalGather<'_> {
    /// The reflected irradiance at `x`, which lies in `leaf`, and the rays cast for it. `key`
    /// picks the point's random streams.
    pub fn irradiance(
        &self,
        x: &ReceivingPoint,
        surface: SurfaceId,
        leaf: u32,
        key: u64,
    ) -> (Rgb, u64) {
        let h = self.system.hierarchy;
        let mut total = Rgb::ZERO;
        let mut rays = 0;
        for node in h.ancestry(leaf) {
            for link in self.system.links_of(node) {
                let (value, cast) = self.along(x, surface, link, key);
                total += value;
                rays += cast;
            }
        }
        (total, rays)
    }

    /// What `x` receives from `link`'s source.
    fn along(&self, x: &ReceivingPoint, surface: SurfaceId, link: &Link, key: u64) -> (Rgb, u64) {
        let h = self.system.hierarchy;
        let s = link.source;
        let sn = h.node(s);
        let tol = self.visibility.contact_distance();
        let unoccluded = if sn.is_cluster() {
            let offset = x.point - sn.centroid;
            let distance2 = offset.length_squared();
            let direction = offset / distance2.sqrt();
            let facing = x.normal.dot(-direction).max(0.0);
            self.system
                .radiosities(self.field)
                .intensity(sn, s, direction)
                * (facing / distance2)
        } else {
            self.field.b[s as usize] * point_factor(h, x, s, tol)
        };
        if !link.partial || unoccluded.max_channel() <= 0.0 {
            return (unoccluded, 0);
        }
        let (visible, rays) = self.visible_fraction(x, surface, s, key);
        (unoccluded * visible, rays)
    }

    /// The fraction of node `s` that `x` sees, weighted by the form-factor kernel, from
    /// stratified rays.
    fn visible_fraction(
        &self,
        x: &ReceivingPoint,
        surface: SurfaceId,
        s: u32,
        key: u64,
    ) -> (f64, u64) {
        let h = self.system.hierarchy;
        let mut rng = SplitMix64::keyed(self.seed, &[key, s as u64]);
        let origin = x.point + x.inward * self.visibility.junction_offset();
        let (mut seen, mut weight, mut rays) = (0.0, 0.0, 0);
        for k in 0..self.rays {
            let (y, t) = h.sample(s, k, self.rays, &mut rng);
            let d = y - origin;
            let w =
                (x.normal.dot(d) * -t.normal.dot(d)).max(0.0) / (PI * d.length_squared().powi(2));
            if !(w > 0.0) {
                continue;
            }
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
