//! The energy balance of the leaves' system.
//!
//! Each leaf's row is scaled to its total ([`super::totals`]), so a field of one radiosity
//! everywhere is carried exactly; but a column is not: the light a source leaf sends is spread
//! over receivers by their ancestors' averaged form factors, and where a bright source's light
//! falls mostly on receivers that read it low (the faces beside a lit floor, next to their
//! junction), part of it is never received. In the CIE 171 5.8 cube that is 0.04 % of the
//! reflected light per bounce, which twenty bounces at ρ = 0.95 make 0.8 %.
//!
//! Reciprocity says what the solution must carry: what the leaves send toward fronts of
//! surfaces that reflect, Σ A b T (T the part of each leaf's total those cover), is what they
//! receive, Σ A H. The converged field B is corrected by what is
//! missing, received as ambient light: every leaf gets γ T more irradiance, which it reflects
//! and the links carry on. That response R is a solve of the same system, with the ambient
//! light reflected in place of the direct light; γ per channel then makes B + γ R balance
//! exactly. Both solves are the system's contraction; the correction adds nothing that could
//! make the sweeps diverge.

use penumbra_scenes::Rgb;

use super::iterate::{Field, System};
use crate::elements::Discretization;

impl System<'_> {
    /// What the leaves of `field` send toward fronts of surfaces that reflect (radiosity × area
    /// × the reflecting part of the total) and what those receive along the links (irradiance ×
    /// area), per channel. Black surfaces are left out: they send nothing, and what they
    /// receive is absorbed, not carried on.
    pub(super) fn transport(&self, field: &Field) -> (Rgb, Rgb) {
        let (mut sent, mut received) = (Rgb::ZERO, Rgb::ZERO);
        for i in self.reflecting_leaves() {
            let area = self.hierarchy.nodes[i].area;
            sent += field.b[i] * (area * self.reflecting[i]);
            received += field.irradiance[i] * area;
        }
        (sent, received)
    }

    /// The leaves of surfaces that reflect.
    fn reflecting_leaves(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.hierarchy.nodes.len()).filter(|&i| {
            let n = &self.hierarchy.nodes[i];
            n.is_leaf() && !n.is_cluster() && n.reflects()
        })
    }

    /// What each leaf reflects of an ambient irradiance of one times the reflecting part of its
    /// total (by node).
    pub(super) fn ambient_source(&self) -> Vec<Rgb> {
        self.hierarchy
            .nodes
            .iter()
            .zip(&self.reflecting)
            .map(|(n, &t)| n.reflectance * t)
            .collect()
    }
}

/// γ per channel such that `solved` + γ `response` balances, where `response` is the solution
/// for an ambient irradiance of one times each leaf's total (not in its irradiance): what the
/// solution loses, over what the ambient light brings in less what its own response loses.
/// Zero where the links lose nothing (light they make up is left: taking it away could leave a
/// dark leaf below zero).
pub(super) fn ambient_gain(system: &System, solved: &Field, response: &Field) -> Rgb {
    let (sent, received) = system.transport(solved);
    let (sent_r, received_r) = system.transport(response);
    let brought: f64 = system
        .reflecting_leaves()
        .map(|i| system.hierarchy.nodes[i].area * system.reflecting[i])
        .sum();
    let missing = sent - received;
    let net = Rgb::splat(brought) + received_r - sent_r;
    let gain = |m: f64, n: f64| {
        if n > 0.0 && m > 0.0 && m.is_finite() {
            m / n
        } else {
            0.0
        }
    };
    Rgb::new(
        gain(missing.r, net.r),
        gain(missing.g, net.g),
        gain(missing.b, net.b),
    )
}

/// The ambient irradiance per unit of total that the final gather's points on surfaces that
/// reflect need besides what they gathered (`reflected` and `totals` at every vertex of
/// `disc`), so that the display receives in all what the balanced leaves receive: the gather
/// carries light from the leaves with each point's own form factors, and loses a little of it
/// too, once (light it makes up is left, as in [`ambient_gain`]). With the share of the leaves'
/// light it lost (channel means).
pub(super) fn display_gain(
    system: &System,
    field: &Field,
    disc: &Discretization,
    reflected: &[Rgb],
    totals: &[f64],
) -> (Rgb, f64) {
    let (_, target) = system.transport(field);
    let reflects = |v: usize| disc.reflectance[v].max_channel() > 0.0;
    let received = disc.integrate(reflected, |e| {
        Rgb::splat(if reflects(e.vertices[0]) { 1.0 } else { 0.0 })
    });
    let ones: Vec<Rgb> = (0..disc.receiver_count())
        .map(|v| Rgb::splat(if reflects(v) { 1.0 } else { 0.0 }))
        .collect();
    let brought = disc.integrate_product(&ones, totals).mean();
    if !(brought > 0.0 && target.mean() > 0.0) {
        return (Rgb::ZERO, 0.0);
    }
    let lost = 1.0 - received.mean() / target.mean();
    ((target - received).max(Rgb::ZERO) / brought, lost)
}
