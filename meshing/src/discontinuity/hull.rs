//! Convex hulls of a few points as planes: the shaft between an emitter and a receiver, and the
//! region an EEE event's second edge must reach into.

use glam::DVec3;

/// The outward planes (normal, point) of the convex hull of `points`: every plane through three
/// of them with all the others on one side (within `tol`). Quartic in the count, for the handful
/// of corners of two polygons.
pub(super) fn hull_planes(points: &[DVec3], tol: f64) -> Vec<(DVec3, DVec3)> {
    let n = points.len();
    let mut planes = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let Some(normal) = (points[j] - points[i])
                    .cross(points[k] - points[i])
                    .try_normalize()
                else {
                    continue;
                };
                let (lo, hi) = points.iter().fold((0.0f64, 0.0f64), |(lo, hi), &p| {
                    let h = normal.dot(p - points[i]);
                    (lo.min(h), hi.max(h))
                });
                if hi <= tol {
                    planes.push((normal, points[i]));
                } else if lo >= -tol {
                    planes.push((-normal, points[i]));
                }
            }
        }
    }
    planes
}

/// Whether all of `points` lie more than `tol` beyond one of the `planes`: then nothing spanned by
/// them meets the hull.
pub(super) fn beyond_a_face(planes: &[(DVec3, DVec3)], points: &[DVec3], tol: f64) -> bool {
    planes
        .iter()
        .any(|&(n, o)| points.iter().all(|&x| n.dot(x - o) > tol))
}

/// Planes of one [`HullPlanes`] group whose heights agree within this fraction of the tolerance
/// everywhere within the extent share a representative.
const GROUP_SPREAD: f64 = 1e-3;

/// The planes of [`hull_planes`], grouped so that [`HullPlanes::beyond_a_face`] answers exactly as
/// [`beyond_a_face`] over all of them while evaluating mostly one plane per group.
///
/// Many triples of corners span one face of a hull (every three corners of a polygon span its
/// plane), and their planes differ by rounding only. Within a group, the height of a point above
/// any member differs from its height above the representative by at most the group's `spread`
/// (the exact difference bounded from the members' offsets, plus the rounding of both
/// evaluations). A point clearly beyond the representative (by more than `tol + spread`) is
/// beyond every member, and one clearly not beyond it (by less than `tol - spread`) is beyond
/// none; only in between are the members asked one by one.
#[derive(Clone, Debug)]
pub(super) struct HullPlanes {
    groups: Vec<PlaneGroup>,
}

#[derive(Clone, Debug)]
struct PlaneGroup {
    normal: DVec3,
    origin: DVec3,
    spread: f64,
    members: Vec<(DVec3, DVec3)>,
}

impl HullPlanes {
    /// The hull planes of `points` ([`hull_planes`]), grouped for points tested later that lie
    /// within `extent` of every one of `points`.
    pub(super) fn new(points: &[DVec3], tol: f64, extent: f64) -> HullPlanes {
        // Rounding of one height `n . (x - o)` with |n| = 1 and |x - o| <= extent is below 5 units
        // in the last place of `extent`; four times that for both evaluations and the sums here.
        let rounding = 20.0 * f64::EPSILON * extent;
        // The exact difference of heights above (n, o) and (n0, o0) at x is
        // (n - n0) . (x - o) + n0 . (o0 - o), at most |n - n0| extent + |n0 . (o0 - o)|.
        let spread_of = |(n0, o0): (DVec3, DVec3), (n, o): (DVec3, DVec3)| {
            ((n - n0).length() * extent + n0.dot(o0 - o).abs()) * (1.0 + 1e-9) + rounding
        };
        let mut groups: Vec<PlaneGroup> = Vec::new();
        for plane in hull_planes(points, tol) {
            let fits = groups.iter_mut().find_map(|g| {
                let spread = spread_of((g.normal, g.origin), plane);
                (spread <= GROUP_SPREAD * tol).then_some((g, spread))
            });
            match fits {
                Some((g, spread)) => {
                    g.spread = g.spread.max(spread);
                    g.members.push(plane);
                }
                None => groups.push(PlaneGroup {
                    normal: plane.0,
                    origin: plane.1,
                    spread: rounding,
                    members: vec![plane],
                }),
            }
        }
        HullPlanes { groups }
    }

    /// [`beyond_a_face`] over every plane.
    pub(super) fn beyond_a_face(&self, points: &[DVec3], tol: f64) -> bool {
        self.groups.iter().any(|g| {
            let (mut clearly_beyond, mut clearly_not) = (true, false);
            for &x in points {
                let h = g.normal.dot(x - g.origin);
                if h <= tol - g.spread {
                    clearly_not = true;
                    break;
                }
                clearly_beyond &= h > tol + g.spread;
            }
            if clearly_not {
                false
            } else if clearly_beyond {
                true
            } else {
                beyond_a_face(&g.members, points, tol)
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cube_has_its_faces_and_separates_what_is_outside() {
        let corners: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64))
            .collect();
        let planes = hull_planes(&corners, 1e-12);
        // Every face is found (twice per face from its two triangles, and more from coplanar
        // triples), and every plane is one of the six faces.
        for (n, o) in &planes {
            assert!(corners.iter().all(|&p| n.dot(p - *o) <= 1e-12));
            assert!((n.abs().max_element() - 1.0).abs() < 1e-12, "{n}");
        }
        let inside = [DVec3::splat(0.5)];
        let crossing = [DVec3::new(-1.0, 0.5, 0.5), DVec3::new(2.0, 0.5, 0.5)];
        let outside = [DVec3::new(2.0, 0.5, 0.5), DVec3::new(3.0, 2.0, 0.1)];
        assert!(!beyond_a_face(&planes, &inside, 1e-12));
        assert!(!beyond_a_face(&planes, &crossing, 1e-12));
        assert!(beyond_a_face(&planes, &outside, 1e-12));
    }

    /// Grouped planes answer as all planes do, at points near the planes' tolerance band too.
    #[test]
    fn grouped_planes_answer_as_all_planes() {
        let mut rng = penumbra_scenes::SplitMix64::new(5);
        let mut point =
            |scale: f64| DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * scale;
        // A square and a hexagon in parallel planes, their corners many times coplanar.
        let mut corners: Vec<DVec3> = (0..4)
            .map(|k| {
                let a = k as f64 * std::f64::consts::FRAC_PI_2;
                DVec3::new(a.cos(), a.sin(), 3.0)
            })
            .collect();
        corners.extend((0..6).map(|k| {
            let a = k as f64 * std::f64::consts::FRAC_PI_3 + 0.1;
            DVec3::new(3.0 * a.cos(), 3.0 * a.sin(), 0.0)
        }));
        let tol = 1e-9;
        let planes = hull_planes(&corners, tol);
        let grouped = HullPlanes::new(&corners, tol, 20.0);
        let members: usize = grouped.groups.iter().map(|g| g.members.len()).sum();
        assert_eq!(members, planes.len());
        assert!(
            grouped.groups.len() < planes.len() / 2,
            "{}",
            grouped.groups.len()
        );
        for _ in 0..20_000 {
            let centre = point(8.0) - DVec3::splat(4.0);
            // Triangles near one of the planes, some within the tolerance of it.
            let (n, o) = planes[(point(1.0).x * planes.len() as f64) as usize % planes.len()];
            // A quarter at the tolerance itself, where members may disagree by rounding.
            let r = point(1.0).x;
            let lift = if r < 0.25 { tol } else { (r - 0.5) * 4e-9 };
            let c = centre - n * (n.dot(centre - o) - lift);
            let mut along = || {
                let v = point(1e-3);
                v - n * n.dot(v)
            };
            let triangle = [c, c + along(), c + along()];
            assert_eq!(
                grouped.beyond_a_face(&triangle, tol),
                beyond_a_face(&planes, &triangle, tol)
            );
        }
    }
}
