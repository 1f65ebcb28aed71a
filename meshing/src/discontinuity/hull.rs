//! Convex hulls of a few points as planes: the shaft between an emitter and a receiver, and the
//! region an EEE event's second edge must reach into.

use glam::{DVec2, DVec3};
use penumbra_scenes::PlaneFrame;

/// The outward planes (normal, point) of the convex hull of `points`: every plane through three
/// of them with all the others on one side (within `tol`). Quartic in the count, for the handful
/// of corners of two polygons.
pub(super) fn hull_planes(points: &[DVec3], tol: f64) -> Vec<(DVec3, DVec3)> {
    let n = points.len();
    let mut planes = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                planes.extend(supporting_plane(
                    points, points[i], points[j], points[k], tol,
                ));
            }
        }
    }
    planes
}

/// The outward planes of the convex hull of two planar polygons' corners, as [`hull_planes`]
/// finds them for the corners together (each plane once or a few times rather than once per
/// triple of corners), in time linear in the corners of each times those of the other rather
/// than quartic in all: a light with hundreds of corners made [`hull_planes`] store one copy of
/// its plane per triple of them. A supporting plane through two corners of one polygon, other
/// than that polygon's own, meets its plane in a supporting line, so it holds an edge of that
/// polygon's convex hull; the planes are each polygon's own (where supporting) and those through
/// a hull edge of one and a corner of the other.
pub(super) fn polygon_pair_hull_planes(
    polygons: [(&[DVec3], &PlaneFrame); 2],
    tol: f64,
) -> Vec<(DVec3, DVec3)> {
    let corners: Vec<DVec3> = polygons
        .iter()
        .flat_map(|(p, _)| p.iter().copied())
        .collect();
    let mut planes = Vec::new();
    let mut supporting = |p: DVec3, q: DVec3, r: DVec3| {
        if let Some(plane) = supporting_plane(&corners, p, q, r, tol) {
            planes.push(plane);
        }
    };
    for (k, &(polygon, frame)) in polygons.iter().enumerate() {
        let other = polygons[1 - k].0;
        let hull = convex_hull(polygon, frame);
        if let [a, b, c, ..] = hull[..] {
            supporting(polygon[a], polygon[b], polygon[c]);
        }
        for (i, &a) in hull.iter().enumerate() {
            let b = hull[(i + 1) % hull.len()];
            for &r in other {
                supporting(polygon[a], polygon[b], r);
            }
        }
    }
    planes
}

/// The outward plane through `p`, `q` and `r` if every corner lies on its inner side (within
/// `tol`).
fn supporting_plane(
    corners: &[DVec3],
    p: DVec3,
    q: DVec3,
    r: DVec3,
    tol: f64,
) -> Option<(DVec3, DVec3)> {
    let normal = (q - p).cross(r - p).try_normalize()?;
    let (lo, hi) = corners.iter().fold((0.0f64, 0.0f64), |(lo, hi), &x| {
        let h = normal.dot(x - p);
        (lo.min(h), hi.max(h))
    });
    if hi <= tol {
        Some((normal, p))
    } else if lo >= -tol {
        Some((-normal, p))
    } else {
        None
    }
}

/// The corners of `polygon` on its convex hull in its plane, counter-clockwise (Andrew's
/// monotone chain; corners on a hull edge's line between its ends are left out). Rounding may
/// keep a corner that is not quite on the hull or drop one that is: the planes built on the
/// hull's edges are checked against every corner, and a missing one only makes the shaft
/// wider.
fn convex_hull(polygon: &[DVec3], frame: &PlaneFrame) -> Vec<usize> {
    let points: Vec<DVec2> = polygon.iter().map(|&p| frame.to_2d(p)).collect();
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&i, &j| {
        points[i]
            .x
            .total_cmp(&points[j].x)
            .then(points[i].y.total_cmp(&points[j].y))
    });
    let turns_left = |a: usize, b: usize, c: usize| {
        (points[b] - points[a]).perp_dot(points[c] - points[a]) > 0.0
    };
    let chain = |indices: &mut dyn Iterator<Item = usize>| {
        let mut half: Vec<usize> = Vec::new();
        for i in indices {
            while half.len() >= 2 && !turns_left(half[half.len() - 2], half[half.len() - 1], i) {
                half.pop();
            }
            half.push(i);
        }
        half.pop();
        half
    };
    let mut hull = chain(&mut order.iter().copied());
    hull.extend(chain(&mut order.iter().rev().copied()));
    hull
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
    #[cfg(test)]
    pub(super) fn new(points: &[DVec3], tol: f64, extent: f64) -> HullPlanes {
        HullPlanes::grouped(hull_planes(points, tol), tol, extent)
    }

    /// The planes of [`polygon_pair_hull_planes`], grouped as [`Self::new`] groups them.
    pub(super) fn of_polygons(
        polygons: [(&[DVec3], &PlaneFrame); 2],
        tol: f64,
        extent: f64,
    ) -> HullPlanes {
        HullPlanes::grouped(polygon_pair_hull_planes(polygons, tol), tol, extent)
    }

    fn grouped(planes: Vec<(DVec3, DVec3)>, tol: f64, extent: f64) -> HullPlanes {
        // Rounding of one height `n . (x - o)` with |n| = 1 and |x - o| <= extent is below 5 units
        // in the last place of `extent`; four times that for both evaluations and the sums here.
        let rounding = 20.0 * f64::EPSILON * extent;
        // The exact difference of heights above (n, o) and (n0, o0) at x is
        // (n - n0) . (x - o) + n0 . (o0 - o), at most |n - n0| extent + |n0 . (o0 - o)|.
        let spread_of = |(n0, o0): (DVec3, DVec3), (n, o): (DVec3, DVec3)| {
            ((n - n0).length() * extent + n0.dot(o0 - o).abs()) * (1.0 + 1e-9) + rounding
        };
        let mut groups: Vec<PlaneGroup> = Vec::new();
        for plane in planes {
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

    /// A regular `k`-gon of radius `r` at height `z`, turned by `turn`, facing down; with `notch`,
    /// every other corner pulled in (not convex).
    fn ring(k: usize, r: f64, z: f64, turn: f64, notch: bool) -> Vec<DVec3> {
        (0..k)
            .map(|i| {
                let a = turn - i as f64 * std::f64::consts::TAU / k as f64;
                let r = if notch && i % 2 == 1 { 0.6 * r } else { r };
                DVec3::new(r * a.cos(), r * a.sin(), z)
            })
            .collect()
    }

    /// The planes of two polygons' hull are those of their corners' hull: each plane of one set
    /// is a plane of the other (to rounding), and points beyond a face of one are beyond a face
    /// of the other, for convex polygons and polygons with notches.
    #[test]
    fn polygon_pairs_have_the_hull_of_their_corners() {
        let mut rng = penumbra_scenes::SplitMix64::new(11);
        let tol = 1e-9;
        for (k, notch) in [(3, false), (4, false), (7, true), (12, false), (10, true)] {
            let light = ring(k, 1.0, 3.0, 0.3, notch);
            let mut floor = ring(6, 3.0, 0.0, 0.1, false);
            floor.reverse(); // facing up
            let frames = [&light, &floor].map(|p| PlaneFrame::of_polygon(p).expect("a plane"));
            let old = hull_planes(&[light.clone(), floor.clone()].concat(), tol);
            let new = polygon_pair_hull_planes([(&light, &frames[0]), (&floor, &frames[1])], tol);
            let same = |(n, o): (DVec3, DVec3), (m, p): (DVec3, DVec3)| {
                (n - m).length() < 1e-9 && n.dot(p - o).abs() < 1e-9
            };
            for &plane in &old {
                assert!(
                    new.iter().any(|&q| same(plane, q)),
                    "{k}-gon: {plane:?} missing"
                );
            }
            for &plane in &new {
                assert!(
                    old.iter().any(|&q| same(plane, q)),
                    "{k}-gon: {plane:?} extra"
                );
            }
            for _ in 0..2_000 {
                let mut point = || {
                    DVec3::new(
                        rng.next_f64() * 8.0 - 4.0,
                        rng.next_f64() * 8.0 - 4.0,
                        rng.next_f64() * 5.0 - 1.0,
                    )
                };
                let triangle = [point(), point(), point()];
                assert_eq!(
                    beyond_a_face(&new, &triangle, tol),
                    beyond_a_face(&old, &triangle, tol)
                );
            }
        }
    }

    /// A light of many corners gives a hull of about as many planes, not one per triple.
    #[test]
    fn many_corners_give_few_planes() {
        let light = ring(500, 0.5, 2.0, 0.0, false);
        let mut floor = ring(4, 2.0, 0.0, 0.7, false);
        floor.reverse();
        let frames = [&light, &floor].map(|p| PlaneFrame::of_polygon(p).expect("a plane"));
        let planes = polygon_pair_hull_planes([(&light, &frames[0]), (&floor, &frames[1])], 1e-9);
        // Two own planes, 500 + 4 side faces, each found from one or two of its edges.
        assert!(
            (504..=2 * 504 + 2).contains(&planes.len()),
            "{}",
            planes.len()
        );
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
