//! Clipping triangles against the near plane, in camera space.
//!
//! The camera may stand inside the scene (the furnace's camera sits inside a closed cube), so
//! triangles that pass behind the eye are cut at a plane just in front of it, never dropped whole.
//! The cut point on an edge is always computed from its inside end towards its outside end, so
//! two triangles sharing the edge get the very same point and stay watertight.

use glam::DVec3;
use penumbra_scenes::Rgb;

/// A triangle corner in camera space (depth along `z`) with the value interpolated over it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ClipVertex {
    pub(crate) position: DVec3,
    pub(crate) value: Rgb,
}

/// A triangle to clip or draw: corners, and per edge `i` (corner `i` to corner `i + 1`) whether
/// it lies on the outline of what is drawn (the surface's boundary or the near plane) rather
/// than between two triangles of the same surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ClipTriangle {
    pub(crate) corners: [ClipVertex; 3],
    pub(crate) outline: [bool; 3],
}

/// The part of `triangle` at depth `z >= near`, as zero, one or two triangles. Edges made by the
/// cut are outline edges; the diagonal that splits a cut quadrilateral is not.
pub(crate) fn clip_near(triangle: &ClipTriangle, near: f64) -> Vec<ClipTriangle> {
    let inside = |v: &ClipVertex| v.position.z >= near;
    if triangle.corners.iter().all(inside) {
        return vec![*triangle];
    }
    // Sutherland-Hodgman against one plane; each output corner carries the flag of the edge that
    // leaves it.
    let mut polygon: Vec<(ClipVertex, bool)> = Vec::with_capacity(4);
    for i in 0..3 {
        let (a, b) = (triangle.corners[i], triangle.corners[(i + 1) % 3]);
        let flag = triangle.outline[i];
        match (inside(&a), inside(&b)) {
            (true, true) => polygon.push((a, flag)),
            (true, false) => {
                polygon.push((a, flag));
                polygon.push((cut(a, b, near), true));
            }
            (false, true) => polygon.push((cut(b, a, near), flag)),
            (false, false) => {}
        }
    }
    let triangle_of = |k: [usize; 3], outline: [bool; 3]| ClipTriangle {
        corners: k.map(|i| polygon[i].0),
        outline,
    };
    match polygon.len() {
        3 => vec![triangle_of(
            [0, 1, 2],
            [polygon[0].1, polygon[1].1, polygon[2].1],
        )],
        4 => vec![
            triangle_of([0, 1, 2], [polygon[0].1, polygon[1].1, false]),
            triangle_of([0, 2, 3], [false, polygon[2].1, polygon[3].1]),
        ],
        _ => Vec::new(),
    }
}

/// The point at depth `near` on the edge from `inside` to `outside`.
fn cut(inside: ClipVertex, outside: ClipVertex, near: f64) -> ClipVertex {
    let t = (near - inside.position.z) / (outside.position.z - inside.position.z);
    let mut position = inside.position + (outside.position - inside.position) * t;
    position.z = near;
    ClipVertex {
        position,
        value: inside.value + (outside.value - inside.value) * t,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vertex(x: f64, y: f64, z: f64) -> ClipVertex {
        ClipVertex {
            position: DVec3::new(x, y, z),
            value: Rgb::splat(z),
        }
    }

    fn area(t: &ClipTriangle) -> f64 {
        let [a, b, c] = t.corners.map(|v| v.position);
        0.5 * (b - a).cross(c - a).length()
    }

    #[test]
    fn cuts_keep_the_part_in_front() {
        let t = ClipTriangle {
            corners: [
                vertex(0.0, 0.0, -1.0),
                vertex(1.0, 0.0, 1.0),
                vertex(0.0, 1.0, 1.0),
            ],
            outline: [false, true, false],
        };
        let parts = clip_near(&t, 0.0);
        assert_eq!(parts.len(), 2);
        // The part at z >= 0 of this triangle has 3/4 of its area.
        let total: f64 = parts.iter().map(area).sum();
        assert!((total - 0.75 * area(&t)).abs() < 1e-12);
        for p in &parts {
            for v in &p.corners {
                assert!(v.position.z >= 0.0);
                // Values stay linear in 3D: here value = depth.
                assert!((v.value.r - v.position.z).abs() < 1e-15);
            }
        }
        // Fully behind: nothing; fully in front: unchanged.
        let behind = ClipTriangle {
            corners: t.corners.map(|v| vertex(v.position.x, v.position.y, -2.0)),
            outline: [true; 3],
        };
        assert!(clip_near(&behind, 0.0).is_empty());
        assert_eq!(clip_near(&t, -5.0), vec![t]);
    }

    #[test]
    fn shared_edges_are_cut_at_the_same_point() {
        let (a, b) = (vertex(0.3, 0.1, -0.7), vertex(-0.2, 0.9, 2.3));
        let left = ClipTriangle {
            corners: [a, b, vertex(-1.0, 0.0, 1.0)],
            outline: [false; 3],
        };
        let right = ClipTriangle {
            corners: [b, a, vertex(1.0, 0.5, 1.5)],
            outline: [false; 3],
        };
        let points = |t: &ClipTriangle| -> Vec<DVec3> {
            clip_near(t, 0.01)
                .iter()
                .flat_map(|p| p.corners.map(|v| v.position))
                .filter(|p| p.z == 0.01)
                .collect()
        };
        let expected = cut(a, b, 0.01).position;
        assert!(points(&left).contains(&expected));
        assert!(points(&right).contains(&expected));
    }
}
