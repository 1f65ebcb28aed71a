//! Plane frames: each surface's own 2D coordinate system.
//!
//! A frame is built from the polygon alone (origin at the start of a longest edge, `u` along
//! that edge, `v = n × u`; see [`polygon::canonical_start`]), so a surface's 2D coordinates do
//! not depend on where the scene sits in space, nor on which corner its vertex list starts at:
//! moving or rotating the scene leaves them unchanged up to rounding, and so does rotating the
//! list (to the bit, unless the polygon has a rotational symmetry).

use glam::{DVec2, DVec3};

use crate::polygon;

/// An orthonormal frame of a plane: `to_3d(to_2d(p)) == p` for points on the plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneFrame {
    /// The point with 2D coordinates (0, 0).
    pub origin: DVec3,
    /// The unit direction of the first 2D axis.
    pub u: DVec3,
    /// The unit direction of the second 2D axis, `normal × u`.
    pub v: DVec3,
    /// The unit normal of the plane: its front side.
    pub normal: DVec3,
}

impl PlaneFrame {
    /// The frame of a polygon; `None` when the polygon has no area or no usable edge.
    pub fn of_polygon(points: &[DVec3]) -> Option<PlaneFrame> {
        PlaneFrame::of_polygon_at(points, polygon::canonical_start(points))
    }

    /// The frame of a polygon with its origin at vertex `start` and `u` along the edge from it
    /// (the next one if that edge is negligible); `None` when the polygon has no area or no
    /// usable edge, or has no vertex `start`.
    pub fn of_polygon_at(points: &[DVec3], start: usize) -> Option<PlaneFrame> {
        let normal = polygon::newell_normal(points).try_normalize()?;
        let origin = *points.get(start)?;
        // The first edge from there that is not negligible against the polygon's size sets `u`.
        let size = polygon::diameter(points);
        let u = points[start + 1..]
            .iter()
            .chain(&points[..start])
            .map(|&p| p - origin)
            .map(|d| d - normal * normal.dot(d))
            .find(|d| d.length() > 1e-9 * size)?
            .try_normalize()?;
        let v = normal.cross(u);
        Some(PlaneFrame {
            origin,
            u,
            v,
            normal,
        })
    }

    /// The 2D coordinates of `p`'s projection onto the plane.
    pub fn to_2d(&self, p: DVec3) -> DVec2 {
        let d = p - self.origin;
        DVec2::new(d.dot(self.u), d.dot(self.v))
    }

    /// The point of the plane with 2D coordinates `q`.
    pub fn to_3d(&self, q: DVec2) -> DVec3 {
        self.origin + self.u * q.x + self.v * q.y
    }

    /// Signed distance of `p` from the plane, positive on the front.
    pub fn height(&self, p: DVec3) -> f64 {
        (p - self.origin).dot(self.normal)
    }

    /// The 3D direction of the 2D vector `d` (no origin added).
    pub fn vector_to_3d(&self, d: DVec2) -> DVec3 {
        self.u * d.x + self.v * d.y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_orientation() {
        let poly = [
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(4.0, 2.0, 3.0),
            DVec3::new(4.0, 5.0, 7.0),
            DVec3::new(1.0, 5.0, 7.0),
        ];
        let f = PlaneFrame::of_polygon(&poly).expect("a valid quad has a frame");
        for &p in &poly {
            assert!((f.to_3d(f.to_2d(p)) - p).length() < 1e-14);
            assert!(f.height(p).abs() < 1e-14);
        }
        // Counter-clockwise in 3D about the normal stays counter-clockwise in 2D.
        let q: Vec<DVec2> = poly.iter().map(|&p| f.to_2d(p)).collect();
        assert!(polygon::signed_area_2d(&q) > 0.0);
        assert!((polygon::signed_area_2d(&q) - 15.0).abs() < 1e-12);
    }

    #[test]
    fn rotating_the_vertex_list_keeps_the_frame() {
        let triangle = [
            DVec3::new(-1.02, -0.99, 1.99),
            DVec3::new(-1.02, 1.04, 1.99),
            DVec3::new(1.0, 1.04, 1.99),
        ];
        let reference = PlaneFrame::of_polygon(&triangle).expect("a triangle has a frame");
        // The longest edge, the hypotenuse, runs from the third vertex to the first.
        assert_eq!(reference.origin, triangle[2]);
        for k in 1..3 {
            let turned: Vec<DVec3> = (0..3).map(|i| triangle[(i + k) % 3]).collect();
            assert_eq!(PlaneFrame::of_polygon(&turned), Some(reference));
        }
    }
}
