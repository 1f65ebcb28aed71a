//! Point-to-polygon form factors by Lambert's contour formula.
//!
//! For a point x with unit normal n and a polygon with vertices v_i (R_i = v_i - x):
//!
//! F = 1/(2π) |Σ_i Θ_i (n · Γ_i)|, Θ_i = angle(R_i, R_{i+1}), Γ_i = unit(R_i × R_{i+1}).
//!
//! It is exact for an unoccluded polygon lying in front of x, so the polygon is first clipped to
//! x's tangent half-space. Receiving points on a surface's boundary (where a wall meets a floor)
//! lie on other polygons' planes or edges, where the formula is singular; there it returns the
//! one-sided limit from inside the receiving surface, taken along its `inward` direction.

use std::f64::consts::PI;

use glam::DVec3;

use crate::clip::clip_polygon_3d;

/// A point receiving light: where it is, which way it faces, and which way its surface lies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReceivingPoint {
    /// Where it is.
    pub point: DVec3,
    /// Unit normal of the receiving surface.
    pub normal: DVec3,
    /// Unit direction into the receiving surface (tangent to it). Only used for the one-sided
    /// limit at points on other polygons' planes, edges or vertices.
    pub inward: DVec3,
}

impl ReceivingPoint {
    /// A point in the interior of its surface, where no limit is needed.
    pub fn interior(point: DVec3, normal: DVec3) -> ReceivingPoint {
        ReceivingPoint {
            point,
            normal,
            inward: normal.any_orthonormal_vector(),
        }
    }

    /// Signed height of a point above the receiving tangent plane, snapped to zero within `tol`.
    pub fn height(&self, p: DVec3, tol: f64) -> f64 {
        let h = self.normal.dot(p - self.point);
        if h.abs() <= tol { 0.0 } else { h }
    }

    /// Whether the (one-sided limit of the) point is strictly in front of a plane with unit normal
    /// `plane_normal` through `plane_point`.
    pub fn in_front_of(&self, plane_point: DVec3, plane_normal: DVec3, tol: f64) -> bool {
        let h = plane_normal.dot(self.point - plane_point);
        if h.abs() <= tol {
            plane_normal.dot(self.inward) > 0.0
        } else {
            h > 0.0
        }
    }
}

/// Θ (n · Γ) for the directed edge `a -> b` seen from `x`: the edge's contribution to the contour
/// sum. `tol` is the distance under which x counts as lying on a vertex or on the edge's line.
pub(crate) fn edge_term(x: &ReceivingPoint, a: DVec3, b: DVec3, tol: f64) -> f64 {
    let ra = a - x.point;
    let rb = b - x.point;
    let (la, lb) = (ra.length(), rb.length());
    // A vertex at the point: the limit from inside the receiver sees it along -inward.
    let da = if la <= tol { -x.inward } else { ra / la };
    let db = if lb <= tol { -x.inward } else { rb / lb };
    let e = b - a;
    let le = e.length();
    if le == 0.0 {
        return 0.0;
    }
    // Distance of x from the edge's line, measured from the nearer end (fewer cancelled digits).
    let line_distance = if la <= lb {
        ra.cross(e).length() / le
    } else {
        rb.cross(e).length() / le
    };
    if line_distance <= tol {
        // x on the edge's line: between the ends the limit plane through the edge and x is
        // spanned by the edge and the inward direction; beyond the ends the edge subtends nothing.
        let between = ra.dot(e) <= 0.0 && rb.dot(e) >= 0.0;
        if !between && la > tol && lb > tol {
            return 0.0;
        }
        let gamma = e.cross(x.inward).normalize_or_zero();
        let theta = if la <= tol || lb <= tol {
            da.angle_between(db)
        } else {
            PI
        };
        return theta * x.normal.dot(gamma);
    }
    let c = da.cross(db);
    let s = c.length();
    if s == 0.0 {
        return 0.0;
    }
    let theta = s.atan2(da.dot(db));
    theta * x.normal.dot(c / s)
}

/// Sum of the edge terms of a closed polygon (no clipping; the caller guarantees the polygon is
/// in front of x). Its magnitude over 2π is the form factor.
///
/// The edge terms are of the size of the angles the edges subtend, while their sum, for a
/// polygon far away and seen at a grazing angle, is of the size of that angle squared times the
/// two cosines: the sum cancels almost all of its digits (on a light 10⁻⁵ above the receiver's
/// plane, 6 units away, half of them). When the terms are more than [`CANCELLATION_LIMIT`] times
/// their sum, the form factor is integrated directly instead ([`quadrature_sum`]), where the
/// cosines are computed from the coordinates and keep all their digits.
pub(crate) fn contour_sum(x: &ReceivingPoint, polygon: &[DVec3], tol: f64) -> f64 {
    let (sum, magnitude) = edge_terms(x, polygon, tol);
    if magnitude > CANCELLATION_LIMIT * sum.abs() && far_from(x.point, polygon) {
        return quadrature_sum(x, polygon);
    }
    sum
}

/// The sum of the edge terms, however many digits it cancels.
fn edge_sum(x: &ReceivingPoint, polygon: &[DVec3], tol: f64) -> f64 {
    edge_terms(x, polygon, tol).0
}

/// The sum of the edge terms and the sum of their magnitudes.
fn edge_terms(x: &ReceivingPoint, polygon: &[DVec3], tol: f64) -> (f64, f64) {
    let n = polygon.len();
    let (mut sum, mut magnitude) = (0.0, 0.0);
    for i in 0..n {
        let t = edge_term(x, polygon[i], polygon[(i + 1) % n], tol);
        sum += t;
        magnitude += t.abs();
    }
    (sum, magnitude)
}

/// Whether the polygon is further from `x` than twice its diameter: far enough for a few levels
/// of subdivision to make quadrature exact to 10⁻¹⁰ (near polygons do not cancel this way).
fn far_from(x: DVec3, polygon: &[DVec3]) -> bool {
    let diameter = polygon
        .iter()
        .flat_map(|a| polygon.iter().map(move |b| a.distance(*b)))
        .fold(0.0, f64::max);
    polygon.iter().all(|p| p.distance(x) > 2.0 * diameter)
}

/// Edge terms this many times larger than their sum leave fewer than 10 good digits.
pub(crate) const CANCELLATION_LIMIT: f64 = 1e6;

/// 2π times the form factor from x to a planar polygon lying wholly in front of it, integrated
/// directly: the polygon is fanned into triangles, each split until it is smaller than a fiftieth
/// of its distance from x, and each piece is integrated with the 7-point degree-5 rule
/// (relative error about (size / distance)^6, 10⁻¹⁰ at a fiftieth).
pub(crate) fn quadrature_sum(x: &ReceivingPoint, polygon: &[DVec3]) -> f64 {
    let normal = penumbra_scenes::polygon::newell_normal(polygon).normalize_or_zero();
    let kernel = |y: DVec3| {
        let d = y - x.point;
        let r2 = d.length_squared();
        let (cx, cy) = (x.normal.dot(d), normal.dot(d).abs());
        if !(r2 > 0.0) || cx <= 0.0 {
            return 0.0;
        }
        cx * cy / (r2 * r2)
    };
    let mut total = 0.0;
    for i in 1..polygon.len().saturating_sub(1) {
        let t = [polygon[0], polygon[i], polygon[i + 1]];
        // Signed by the fan triangle's orientation, so that fans of non-convex polygons add up.
        let signed = normal.dot((t[1] - t[0]).cross(t[2] - t[0])).signum();
        total += signed * triangle_integral(&kernel, x.point, t, 0);
    }
    // ∫ cos cos / (π r²) dA = F, and the contour sum is 2π F.
    2.0 * total
}

fn triangle_integral(kernel: &impl Fn(DVec3) -> f64, x: DVec3, t: [DVec3; 3], depth: u32) -> f64 {
    let size = t[0]
        .distance(t[1])
        .max(t[1].distance(t[2]))
        .max(t[2].distance(t[0]));
    let distance = t
        .iter()
        .map(|p| p.distance(x))
        .fold(f64::INFINITY, f64::min);
    if size > distance / 50.0 && depth < 6 {
        let m = [
            (t[0] + t[1]) / 2.0,
            (t[1] + t[2]) / 2.0,
            (t[2] + t[0]) / 2.0,
        ];
        return [
            [t[0], m[0], m[2]],
            [m[0], t[1], m[1]],
            [m[2], m[1], t[2]],
            [m[0], m[1], m[2]],
        ]
        .into_iter()
        .map(|s| triangle_integral(kernel, x, s, depth + 1))
        .sum();
    }
    const A1: f64 = 0.059_715_871_789_770;
    const B1: f64 = 0.470_142_064_105_115;
    const W1: f64 = 0.132_394_152_788_506;
    const A2: f64 = 0.797_426_985_353_087;
    const B2: f64 = 0.101_286_507_323_456;
    const W2: f64 = 0.125_939_180_544_827;
    let at = |w: [f64; 3]| kernel(t[0] * w[0] + t[1] * w[1] + t[2] * w[2]);
    let sum = 0.225 * at([1.0 / 3.0; 3])
        + W1 * (at([A1, B1, B1]) + at([B1, A1, B1]) + at([B1, B1, A1]))
        + W2 * (at([A2, B2, B2]) + at([B2, A2, B2]) + at([B2, B2, A2]));
    let area = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
    sum * area
}

/// The form factor from the point to a planar polygon, unoccluded: the polygon is clipped to the
/// point's tangent half-space, then Lambert's formula applies. Exact to rounding relative to the
/// form factor itself, however grazing the view ([`contour_sum`]).
pub fn form_factor(x: &ReceivingPoint, polygon: &[DVec3], tol: f64) -> f64 {
    clipped_factor(x, polygon, tol, contour_sum)
}

/// As [`form_factor`], exact to rounding relative to the angle the polygon subtends rather than
/// to the form factor: what a sum over many sources needs, where a grazing polygon's form factor
/// is far below the rounding of the others. It skips the quadrature that keeps such a form
/// factor's own digits, which costs thousands of kernel evaluations.
pub(crate) fn form_factor_in_sum(x: &ReceivingPoint, polygon: &[DVec3], tol: f64) -> f64 {
    clipped_factor(x, polygon, tol, edge_sum)
}

fn clipped_factor(
    x: &ReceivingPoint,
    polygon: &[DVec3],
    tol: f64,
    sum: fn(&ReceivingPoint, &[DVec3], f64) -> f64,
) -> f64 {
    let heights: Vec<f64> = polygon.iter().map(|&p| x.height(p, tol)).collect();
    // Behind, or in the tangent plane itself (seen edge-on): nothing.
    if heights.iter().all(|&h| h <= 0.0) {
        return 0.0;
    }
    if heights.iter().all(|&h| h >= 0.0) {
        return sum(x, polygon, tol).abs() / (2.0 * PI);
    }
    let clipped = clip_polygon_3d(polygon, |p| x.height(p, tol));
    if clipped.len() < 3 {
        return 0.0;
    }
    sum(x, &clipped, tol).abs() / (2.0 * PI)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    fn up_at(p: DVec3) -> ReceivingPoint {
        ReceivingPoint::interior(p, DVec3::Z)
    }

    fn close(a: f64, b: f64, rel: f64) {
        assert!(
            (a - b).abs() <= rel * b.abs(),
            "{a} vs {b} (relative {:e})",
            (a - b).abs() / b.abs()
        );
    }

    /// `docs/closed-forms.md`, "Rectangles by superposition": differential area to a parallel
    /// rectangle, corner on the normal.
    #[test]
    fn parallel_rectangle_corner_on_normal() {
        for (a, b, c, f) in [
            (1.0, 1.0, 1.0, 0.138531605994893),
            (2.0, 3.0, 1.0, 0.217575206107758),
            (0.5, 0.25, 2.0, 0.00945845765854797),
            (10.0, 10.0, 1.0, 0.24797140829531),
        ] {
            let rect = [v(0., 0., c), v(a, 0., c), v(a, b, c), v(0., b, c)];
            close(form_factor(&up_at(DVec3::ZERO), &rect, 1e-12), f, 1e-9);
        }
    }

    /// A unit square 10⁻⁵ above the point's tangent plane, 6 units away, parallel to it: its edge
    /// terms are about a sixth and cancel to 10⁻¹⁴. The form factor keeps its own digits (the
    /// point-to-point kernel h² A / (π r⁴), to the square's size over its distance squared);
    /// the one for sums keeps the digits of the angle (10⁻¹⁶ absolute), and is the same value
    /// where nothing cancels.
    #[test]
    fn a_grazing_polygon_keeps_its_digits_only_where_they_matter() {
        let h = 1e-5;
        let square = [
            v(5.5, -0.5, h),
            v(6.5, -0.5, h),
            v(6.5, 0.5, h),
            v(5.5, 0.5, h),
        ];
        let x = up_at(DVec3::ZERO);
        let kernel = h * h / (PI * 6f64.powi(4));
        let exact = form_factor(&x, &square, 1e-12);
        close(exact, kernel, 0.05);
        let in_sum = form_factor_in_sum(&x, &square, 1e-12);
        assert!((in_sum - exact).abs() < 1e-16, "{in_sum:e} vs {exact:e}");
        let facing = [v(0., 0., 1.), v(1., 0., 1.), v(1., 1., 1.), v(0., 1., 1.)];
        assert_eq!(
            form_factor_in_sum(&x, &facing, 1e-12),
            form_factor(&x, &facing, 1e-12)
        );
    }

    /// `docs/closed-forms.md`, "Rectangles by superposition": differential area to a perpendicular
    /// rectangle whose bottom edge lies in the point's tangent plane.
    #[test]
    fn perpendicular_rectangle() {
        for (a, b, c, f) in [
            (1.0, 1.0, 1.0, 0.0557341970025535),
            (2.0, 1.0, 0.5, 0.158774804514299),
            (1.0, 3.0, 2.0, 0.0239896394221535),
            (0.1, 1.0, 1.0, 0.00101429585234492),
        ] {
            let rect = [v(c, 0., 0.), v(c, b, 0.), v(c, b, a), v(c, 0., a)];
            close(form_factor(&up_at(DVec3::ZERO), &rect, 1e-12), f, 1e-9);
        }
    }

    /// `docs/closed-forms.md`, "A point and a polygon", cases A-D, including the square that
    /// straddles the tangent plane.
    #[test]
    fn arbitrary_polygons_and_clipping() {
        let o = up_at(DVec3::ZERO);
        close(
            form_factor(&o, &[v(0., 0., 1.), v(1., 0., 1.), v(0., 1., 1.)], 1e-12),
            0.0962250448649376,
            1e-9,
        );
        let (c30, s30) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let center = v(0.3, -0.2, 1.5);
        let (du, dv) = (v(0.5, 0., 0.), v(0., 0.5 * c30, 0.5 * s30));
        let tilted = [
            center - du - dv,
            center + du - dv,
            center + du + dv,
            center - du + dv,
        ];
        close(form_factor(&o, &tilted, 1e-12), 0.107488688911369, 1e-9);
        let l = [
            (-1., -1.),
            (1., -1.),
            (1., 0.),
            (0., 0.),
            (0., 1.),
            (-1., 1.),
        ]
        .map(|(x, y)| v(x, y, 1.0));
        let tilt = ReceivingPoint::interior(
            DVec3::ZERO,
            v(20f64.to_radians().sin(), 0., 20f64.to_radians().cos()),
        );
        close(form_factor(&tilt, &l, 1e-12), 0.371469165650111, 1e-9);
        let straddling = [
            v(1., -1., -1.),
            v(1., 1., -1.),
            v(1., 1., 1.),
            v(1., -1., 1.),
        ];
        close(form_factor(&o, &straddling, 1e-12), 0.111468394005107, 1e-9);
    }

    #[test]
    fn orientation_and_vertex_order_do_not_matter() {
        let o = up_at(DVec3::ZERO);
        let mut rect = vec![v(0., 0., 1.), v(1., 0., 1.), v(1., 1., 1.), v(0., 1., 1.)];
        let f = form_factor(&o, &rect, 1e-12);
        rect.reverse();
        close(form_factor(&o, &rect, 1e-12), f, 1e-14);
        rect.rotate_left(1);
        close(form_factor(&o, &rect, 1e-12), f, 1e-14);
    }

    /// At a point on the shared edge of a floor and a wall, the limit from inside the floor is the
    /// limit of the values approaching the edge.
    #[test]
    fn one_sided_limit_at_an_edge_and_a_corner() {
        let wall = [v(0., 0., 0.), v(0., 1., 0.), v(0., 1., 1.), v(0., 0., 1.)];
        for (point, inward) in [
            (v(0., 0.5, 0.), v(1., 0., 0.)), // on the wall's bottom edge
            (v(0., 0., 0.), v(1., 1., 0.).normalize()), // at the wall's corner
        ] {
            let at = ReceivingPoint {
                point,
                normal: DVec3::Z,
                inward,
            };
            let approach = inward;
            let limit = form_factor(&at, &wall, 1e-12);
            let near = form_factor(&up_at(point + approach * 1e-7), &wall, 1e-15);
            assert!(limit > 0.05, "{limit}");
            assert!(
                (limit - near).abs() < 1e-5,
                "limit {limit} vs nearby {near}"
            );
        }
    }

    /// Rows of a closed cube sum to one at every point, including edges and corners.
    #[test]
    fn closed_cube_row_sums_are_one() {
        let scene = penumbra_scenes::builtin::furnace(1.0, 0.5);
        let floor = &scene.surfaces[scene.surface_id("floor").expect("floor")];
        for (point, inward) in [
            (v(0.3, 0.7, 0.0), v(1., 0., 0.)),
            (v(0.3, 0.0, 0.0), v(0., 1., 0.)),
            (v(0.0, 0.0, 0.0), v(1., 1., 0.).normalize()),
            (v(1.0, 0.25, 0.0), v(-1., 0., 0.)),
        ] {
            let x = ReceivingPoint {
                point,
                normal: floor.normal(),
                inward,
            };
            let sum: f64 = scene
                .surfaces
                .iter()
                .map(|s| form_factor(&x, &s.polygon, 1e-12))
                .sum();
            assert!((sum - 1.0).abs() < 1e-12, "row sum {sum} at {point}");
        }
    }
}
