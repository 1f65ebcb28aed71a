//! How light goes between nodes: form factors from points to elements, and the directional light
//! of clusters.
//!
//! A cluster sends as the sum of its surfaces, or from its table of intensities over directions
//! when it holds many (see [`super::directions`]). It receives as a whole, after Sillion's
//! (1995) clusters: it keeps the irradiance each axis-facing plane (+x, −x, +y, −y, +z, −z)
//! would get, G_k, and a surface inside it with normal `n` reads Σ_k s_k(n) G_k, with s_k the
//! shares |n_k| / Σ|n_j| ([`axis_shares`]). That is exact for
//! surfaces facing along the axes (boxes, rooms) and for light from all around, and an
//! approximation otherwise, bounded by the link oracle, which refines every cluster link that
//! carries much light.

use std::f64::consts::PI;

use glam::DVec3;
use penumbra_scenes::Rgb;

use super::tree::{Hierarchy, Node};
use crate::lambert::{ReceivingPoint, form_factor_in_sum};

/// Light per axis direction: +x, −x, +y, −y, +z, −z.
pub(crate) type Axes = [Rgb; 6];

/// How far from a node, in its radii, a point integrates the kernel over it by the four-point
/// rule of [`far_factor`]; nearer, it is seen through its children. The rule matches the node's
/// moments of area up to the second, so it is off by about (radius / distance)⁴ of itself there,
/// under half a percent.
pub(crate) const FAR_DISTANCE: f64 = 4.0;

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

/// The shares by which a surface facing `normal` reads the axis planes' irradiances: |n_k| over
/// their sum.
pub(crate) fn axis_shares(normal: DVec3) -> [f64; 6] {
    let w = axis_weights(normal);
    let sum: f64 = w.iter().sum();
    w.map(|x| x / sum.max(f64::MIN_POSITIVE))
}

/// Irradiance on a surface facing `normal` inside a cluster that receives `g`: the axis planes'
/// irradiances weighed by shares that sum to one, so that a uniform surround is read as it is.
/// Weighed by |n_k| alone, a surface at 45° to two axes read it √2 times over, and a curved
/// blocker's facets gathered half as much again as their view holds.
pub(crate) fn irradiance_from_axes(g: &Axes, normal: DVec3) -> Rgb {
    axis_shares(normal)
        .iter()
        .zip(g)
        .map(|(&w, &h)| h * w)
        .sum()
}

/// Intensity (W/sr per unit radiosity) toward unit `d` of an element.
pub(crate) fn element_intensity(node: &Node, d: DVec3) -> f64 {
    node.area * node.normal.dot(d).max(0.0) / PI
}

/// The form factor from a point at `x` facing `normal` to element `node`, by the kernel
/// cos θ cos θ' / (π r²) at the four points centroid ± half-axis, a quarter of the area each
/// (exact for kernels quadratic over the element; good for elements far from `x`).
pub(crate) fn far_factor(x: DVec3, normal: DVec3, node: &Node) -> f64 {
    let [a, b] = node.axes;
    [a, -a, b, -b]
        .iter()
        .map(|&offset| {
            let d = node.centroid + offset - x;
            let r2 = d.length_squared();
            normal.dot(d).max(0.0) * (-node.normal.dot(d)).max(0.0) / (r2 * r2)
        })
        .sum::<f64>()
        * node.area
        / (4.0 * PI)
}

/// The unoccluded form factor from `x` to element `s`: [`far_factor`] for nodes at least
/// [`FAR_DISTANCE`] radii away, exact (Lambert's formula) over nearer leaves, and the sum over
/// the children of nearer inner nodes. (Lambert's formula is exact everywhere, but far away, at
/// grazing angles, its terms cancel and it must integrate instead: slower, and no better than
/// the four-point rule there.)
pub(crate) fn point_factor(h: &Hierarchy, x: &ReceivingPoint, s: u32, tol: f64) -> f64 {
    let node = h.node(s);
    if !x.in_front_of(node.centroid, node.normal, tol) {
        return 0.0;
    }
    let far = x.point.distance_squared(node.centroid)
        >= (FAR_DISTANCE * node.radius) * (FAR_DISTANCE * node.radius);
    match node.children {
        _ if far => far_factor(x.point, x.normal, node),
        None => leaf_factor(
            x,
            &h.triangles[node.first as usize].points,
            node.normal,
            tol,
        ),
        Some([a, b]) => point_factor(h, x, a, tol) + point_factor(h, x, b, tol),
    }
}

/// The mean of `f` over a triangle: the three-point rule (exact for quadratics), on the four
/// halves-by-side of the triangle in turn, down `depth` levels, wherever the three values differ
/// by more than a twentieth of their mean.
pub(crate) fn triangle_mean(t: &[DVec3; 3], f: &impl Fn(DVec3) -> f64, depth: u32) -> f64 {
    let at = |a: f64, b: f64, c: f64| t[0] * a + t[1] * b + t[2] * c;
    let (a, b) = (2.0 / 3.0, 1.0 / 6.0);
    let values = [f(at(a, b, b)), f(at(b, a, b)), f(at(b, b, a))];
    let mean = values.iter().sum::<f64>() / 3.0;
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    if depth == 0 || hi - lo <= 0.05 * mean.abs() {
        return mean;
    }
    let [p, q, r] = *t;
    let (pq, qr, rp) = ((p + q) / 2.0, (q + r) / 2.0, (r + p) / 2.0);
    [[p, pq, rp], [pq, q, qr], [rp, qr, r], [qr, rp, pq]]
        .iter()
        .map(|part| triangle_mean(part, f, depth - 1))
        .sum::<f64>()
        / 4.0
}

/// The form factor from `x` to triangle `t` (unit normal `normal`) by Lambert's formula; zero
/// at once for a point in the triangle's plane but off it (the one-sided limit is zero there,
/// and the formula's terms would cancel to nothing only after integrating).
pub(crate) fn leaf_factor(x: &ReceivingPoint, t: &[DVec3; 3], normal: DVec3, tol: f64) -> f64 {
    if normal.dot(x.point - t[0]).abs() <= tol {
        let w = barycentric_nearest(x.point, t);
        let nearest = t[0] * w[0] + t[1] * w[1] + t[2] * w[2];
        if nearest.distance(x.point) > tol {
            return 0.0;
        }
    }
    form_factor_in_sum(x, t, tol)
}

/// Barycentric coordinates of the point of triangle `t` nearest to `p`.
pub(crate) fn barycentric_nearest(p: DVec3, t: &[DVec3; 3]) -> [f64; 3] {
    let (a, b, c) = (t[0], t[1], t[2]);
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    [1.0 - v - w, v, w]
}
