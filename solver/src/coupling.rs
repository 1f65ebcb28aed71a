//! Vertex-to-patch form factors: the analytic unoccluded value (Lambert's formula over the patch
//! outline) times a visibility fraction estimated with stratified rays (Wallace, Elmquist &
//! Haines 1989).

use std::f64::consts::PI;

use penumbra_scenes::Visibility;

use crate::elements::{Discretization, Element, Patch};
use crate::lambert::{ReceivingPoint, edge_term, form_factor};
use penumbra_scenes::rng::SplitMix64;

/// Form factors from receivers (mesh vertices) to shooting patches.
#[derive(Debug)]
pub struct PatchCoupling<'a> {
    pub disc: &'a Discretization,
    pub visibility: &'a Visibility,
    /// Rays per vertex–patch pair for the visibility fraction.
    pub rays: usize,
    pub seed: u64,
}

impl PatchCoupling<'_> {
    fn tol(&self) -> f64 {
        self.visibility.contact_distance()
    }

    /// The unoccluded form factor from receiver `v` to patch `p` (zero if either faces away).
    pub fn unoccluded(&self, v: usize, p: usize) -> f64 {
        let patch = &self.disc.patches[p];
        let x = &self.disc.receivers[v];
        if self.disc.receiver_surface[v] == patch.surface
            || !x.in_front_of(patch.origin, patch.normal, self.tol())
        {
            return 0.0;
        }
        patch_form_factor(x, patch, &self.disc.elements, self.tol())
    }

    /// Fraction of patch `p` visible from receiver `v`, weighted by the form-factor kernel, and
    /// the number of rays cast for it.
    pub fn visible_fraction(&self, v: usize, p: usize) -> (f64, u32) {
        let patch = &self.disc.patches[p];
        let x = &self.disc.receivers[v];
        let own = [self.disc.receiver_surface[v], patch.surface];
        // Nothing else in the box around both: nothing can block.
        let shaft = patch.bounds.including(x.point);
        if !self
            .visibility
            .any_triangle_overlapping(shaft, |t| t.surface != own[0] && t.surface != own[1])
        {
            return (1.0, 0);
        }
        // Rays leave from just inside the receiving surface, so that a vertex on a junction sees
        // past (not along) the surfaces it touches: the one-sided limit again.
        let origin = x.point + x.inward * self.visibility.junction_offset();
        let mut rng = SplitMix64::keyed(self.seed, &[v as u64, p as u64]);
        let total = patch.area;
        let (mut seen, mut weight, mut count) = (0.0, 0.0, 0u32);
        // Samples that face away (behind x's tangent plane, or behind the patch) carry no weight
        // and cast no ray; a patch straddling x's plane may need a few more draws.
        let mut draws = 0;
        while count < self.rays as u32 && draws < 4 * self.rays {
            // Stratified over the patch's area, then uniform inside the chosen element.
            let u = ((draws % self.rays) as f64 + rng.next_f64()) / self.rays as f64 * total;
            draws += 1;
            let idx = patch
                .cumulative_area
                .partition_point(|&c| c < u)
                .min(patch.elements.len() - 1);
            let e = &self.disc.elements[patch.elements[idx]];
            let (r1, r2) = (rng.next_f64().sqrt(), rng.next_f64());
            let y = e.points[0] * (1.0 - r1)
                + e.points[1] * (r1 * (1.0 - r2))
                + e.points[2] * (r1 * r2);
            let d = y - origin;
            let w = x.normal.dot(d) * -patch.normal.dot(d) / d.length_squared().powi(2);
            if !(w > 0.0) {
                continue;
            }
            count += 1;
            weight += w;
            if !self.visibility.occluded(origin, y, own) {
                seen += w;
            }
        }
        // No sample in front: the part of the patch x sees is too small to hit; take it as open.
        let fraction = if weight > 0.0 { seen / weight } else { 1.0 };
        (fraction, count)
    }

    /// Form factor times visibility, and the rays it took.
    pub fn coupling(&self, v: usize, p: usize) -> (f64, u32) {
        let f = self.unoccluded(v, p);
        if f <= 0.0 {
            return (0.0, 0);
        }
        let (vis, rays) = self.visible_fraction(v, p);
        (f * vis, rays)
    }
}

/// Lambert's formula over a patch: over its outline when the patch lies wholly in front of x,
/// else over its elements one by one, each clipped to x's tangent half-space.
pub fn patch_form_factor(x: &ReceivingPoint, patch: &Patch, elements: &[Element], tol: f64) -> f64 {
    let (mut any_front, mut any_behind) = (false, false);
    for &c in &patch.corners {
        let h = x.height(c, tol);
        any_front |= h > 0.0;
        any_behind |= h < 0.0;
    }
    if !any_front {
        return 0.0;
    }
    if !any_behind {
        let sum: f64 = patch
            .outline
            .iter()
            .map(|&[a, b]| edge_term(x, a, b, tol))
            .sum();
        return sum.abs() / (2.0 * PI);
    }
    patch
        .elements
        .iter()
        .map(|&e| form_factor(x, &elements[e].points, tol))
        .sum()
}
