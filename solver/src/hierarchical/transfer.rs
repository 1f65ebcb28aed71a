//! How light goes between nodes: form factors from points to elements, and the directional light
//! of clusters.
//!
//! A cluster's light is kept per axis direction (+x, −x, +y, −y, +z, −z), after Sillion's (1995)
//! clusters that send and receive as a whole. Going out, a surface's power is shared among the
//! directions its normal leans to, in proportion to |n_k| (the shares sum to one, so no power is
//! made or lost), and the cluster's intensity toward `d` is Σ_k max(0, d · a_k) Q_k / π. Coming
//! in, a cluster keeps the irradiance each axis-facing plane would get, and a surface inside it
//! with normal `n` reads Σ_k max(0, n · a_k) G_k. Both are exact for surfaces facing along the
//! axes (boxes, rooms) and an approximation otherwise, bounded by the link oracle, which refines
//! every cluster link that carries much light.

use std::f64::consts::PI;

use glam::DVec3;
use penumbra_scenes::Rgb;

use super::tree::{Hierarchy, Node};
use crate::lambert::{ReceivingPoint, form_factor};

/// Light per axis direction: +x, −x, +y, −y, +z, −z.
pub(crate) type Axes = [Rgb; 6];

/// How far from a node, in its radii, a point sees it as a disc at its centroid; nearer, it is
/// seen through its children. The disc's form factor is off by about (radius / distance)² of
/// itself there, under 7 %, on a link that carries little light or the oracle would have split it.
pub(crate) const DISC_DISTANCE: f64 = 4.0;

/// max(0, d · a_k) for the six axis directions.
pub(crate) fn axis_weights(d: DVec3) -> [f64; 6] {
    [
        d.x.max(0.0),
        (-d.x).max(0.0),
        d.y.max(0.0),
        (-d.y).max(0.0),
        d.z.max(0.0),
        (-d.z).max(0.0),
    ]
}

/// The shares of a surface's power sent along each axis direction: |n_k| over their sum.
pub(crate) fn power_shares(normal: DVec3) -> [f64; 6] {
    let w = axis_weights(normal);
    let sum: f64 = w.iter().sum();
    w.map(|x| x / sum.max(f64::MIN_POSITIVE))
}

/// Irradiance on a surface facing `normal` inside a cluster that receives `g`.
pub(crate) fn irradiance_from_axes(g: &Axes, normal: DVec3) -> Rgb {
    axis_weights(normal)
        .iter()
        .zip(g)
        .map(|(&w, &h)| h * w)
        .sum()
}

/// Intensity (W/sr) toward unit `d` of a cluster whose power per axis direction is `q`.
pub(crate) fn cluster_intensity(q: &Axes, d: DVec3) -> Rgb {
    axis_weights(d)
        .iter()
        .zip(q)
        .map(|(&w, &p)| p * w)
        .sum::<Rgb>()
        / PI
}

/// Intensity (W/sr per unit radiosity) toward unit `d` of an element.
pub(crate) fn element_intensity(node: &Node, d: DVec3) -> f64 {
    node.area * node.normal.dot(d).max(0.0) / PI
}

/// The form factor from a point at `x` facing `normal` to a disc of `area` at `center` facing
/// `disc_normal`: A cos θ cos θ' / (π r² + A), exact on the axis of a disc facing the point.
pub(crate) fn disc_factor(
    x: DVec3,
    normal: DVec3,
    center: DVec3,
    disc_normal: DVec3,
    area: f64,
) -> f64 {
    let d = center - x;
    let r2 = d.length_squared();
    let cos_product = normal.dot(d).max(0.0) * (-disc_normal.dot(d)).max(0.0) / r2;
    area * cos_product / (PI * r2 + area)
}

/// The unoccluded form factor from `x` to element `s`: exact (Lambert's formula) over leaves,
/// a disc for nodes at least [`DISC_DISTANCE`] radii away, and the sum over the children of
/// nearer ones.
pub(crate) fn point_factor(h: &Hierarchy, x: &ReceivingPoint, s: u32, tol: f64) -> f64 {
    let node = h.node(s);
    if !x.in_front_of(node.centroid, node.normal, tol) {
        return 0.0;
    }
    let far = x.point.distance_squared(node.centroid)
        >= (DISC_DISTANCE * node.radius) * (DISC_DISTANCE * node.radius);
    match node.children {
        None => form_factor(x, &h.triangles[node.first as usize].points, tol),
        Some(_) if far => disc_factor(x.point, x.normal, node.centroid, node.normal, node.area),
        Some([a, b]) => point_factor(h, x, a, tol) + point_factor(h, x, b, tol),
    }
}
