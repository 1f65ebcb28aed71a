//! Shaft culling (Haines & Wallace 1994): what can block the light between two nodes. The shaft
//! is the convex hull of the two nodes' hulls; a scene triangle outside one of its faces cannot
//! block any segment between them. A link whose shaft holds no triangle is fully visible and
//! casts no ray; one whose every segment crosses a single convex polygon is hidden and is not
//! made; the rest are partial, and their blockers are the only candidates their children's
//! shafts (which lie inside) need to test.

use glam::DVec3;
use penumbra_scenes::{Scene, SurfaceId, Visibility};
use smallvec::SmallVec;

use super::tree::Node;

/// What lies between two nodes.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Sight {
    /// Nothing: every segment between them is open.
    Full,
    /// Some segments may be blocked, by these scene triangles only.
    Partial(Vec<u32>),
    /// Some segments may be blocked, by some of too many triangles to list.
    Blocked,
    /// Every segment crosses one polygon.
    Hidden,
}

/// How many distinct blocking polygons are tried as the one that hides a shaft whole.
const HIDING_CANDIDATES: usize = 8;

/// Candidates beyond which a shaft's blockers are not listed (it is only found that one blocks):
/// filtering long lists again at every level would cost more than asking the index again.
const LISTED_CANDIDATES: usize = 64;

/// The scene's blockers, and which of its polygons are convex (only those can prove a shaft
/// hidden by a containment test of its crossing points).
pub(crate) struct Shafts<'a> {
    pub visibility: &'a Visibility,
    scene: &'a Scene,
    convex: Vec<bool>,
    /// Distance under which a point counts as lying on a plane.
    tol: f64,
}

impl<'a> Shafts<'a> {
    pub(super) fn new(scene: &'a Scene, visibility: &'a Visibility) -> Shafts<'a> {
        Shafts {
            visibility,
            scene,
            convex: scene
                .surfaces
                .iter()
                .map(|s| is_convex(&s.polygon, s.normal()))
                .collect(),
            tol: visibility.contact_distance(),
        }
    }

    /// What lies between `a` and `b`; `candidates` are the blockers of a shaft that holds this
    /// one (all of the scene's when `None`).
    pub(super) fn classify(&self, a: &Node, b: &Node, candidates: Option<&[u32]>) -> Sight {
        let shaft = Shaft::new(&a.hull, &b.hull, self.tol);
        let own = |s: SurfaceId| a.surface == Some(s) || b.surface == Some(s);
        let triangles = self.visibility.triangles();
        let blocks = |t: u32| {
            let tri = &triangles[t as usize];
            !own(tri.surface) && !shaft.excludes(&tri.vertices, self.tol)
        };
        let queried;
        let list: &[u32] = match candidates {
            Some(list) => list,
            None => {
                let mut found = Vec::new();
                self.visibility
                    .triangles_overlapping_between(a.bounds, b.bounds, |t| found.push(t as u32));
                found.sort_unstable();
                found.dedup();
                queried = found;
                &queried
            }
        };
        if list.len() > LISTED_CANDIDATES {
            return match list.iter().find(|&&t| blocks(t)) {
                Some(_) => Sight::Blocked,
                None => Sight::Full,
            };
        }
        let blockers: Vec<u32> = list.iter().copied().filter(|&t| blocks(t)).collect();
        if blockers.is_empty() {
            return Sight::Full;
        }
        let mut tried: SmallVec<[SurfaceId; HIDING_CANDIDATES]> = SmallVec::new();
        for &t in &blockers {
            let s = triangles[t as usize].surface;
            if tried.contains(&s) {
                continue;
            }
            if tried.len() == HIDING_CANDIDATES {
                break;
            }
            tried.push(s);
            if self.convex[s] && self.hides(s, &a.hull, &b.hull) {
                return Sight::Hidden;
            }
        }
        Sight::Partial(blockers)
    }

    /// Whether every segment from a point of `a`'s hull to one of `b`'s crosses the convex
    /// polygon of surface `s` strictly inside it: the crossings of the segments between hull
    /// points span every crossing (the shaft's section by the polygon's plane is their hull).
    fn hides(&self, s: SurfaceId, a: &[DVec3], b: &[DVec3]) -> bool {
        let surface = &self.scene.surfaces[s];
        let (n, p0) = (surface.normal(), surface.polygon[0]);
        let height = |p: DVec3| n.dot(p - p0);
        let above = |h: f64| h > self.tol;
        let below = |h: f64| h < -self.tol;
        let (ha, hb): (Vec<f64>, Vec<f64>) = (
            a.iter().map(|&p| height(p)).collect(),
            b.iter().map(|&p| height(p)).collect(),
        );
        let split = (ha.iter().all(|&h| above(h)) && hb.iter().all(|&h| below(h)))
            || (ha.iter().all(|&h| below(h)) && hb.iter().all(|&h| above(h)));
        if !split {
            return false;
        }
        let polygon = &surface.polygon;
        let inside = |x: DVec3| {
            polygon.iter().enumerate().all(|(i, &p)| {
                let q = polygon[(i + 1) % polygon.len()];
                let edge = q - p;
                edge.cross(x - p).dot(n) > self.tol * edge.length()
            })
        };
        a.iter().zip(&ha).all(|(&pa, &h1)| {
            b.iter()
                .zip(&hb)
                .all(|(&pb, &h2)| inside(pa + (pb - pa) * (h1 / (h1 - h2))))
        })
    }
}

/// Whether a planar polygon turns the same way at every corner about `normal`.
fn is_convex(polygon: &[DVec3], normal: DVec3) -> bool {
    let n = polygon.len();
    (0..n).all(|i| {
        let (a, b, c) = (polygon[i], polygon[(i + 1) % n], polygon[(i + 2) % n]);
        (b - a).cross(c - b).dot(normal) >= 0.0
    })
}

/// The plane `n · x = d` (unit `n`) oriented so that every point is on its inner side (within
/// `tol`), or `None` if points lie on both sides; stops at the first point that tells.
fn supporting(
    n: DVec3,
    d: f64,
    points: impl Iterator<Item = DVec3>,
    tol: f64,
) -> Option<(DVec3, f64)> {
    let (mut above, mut below) = (false, false);
    for p in points {
        let h = n.dot(p) - d;
        above |= h > tol;
        below |= h < -tol;
        if above && below {
            return None;
        }
    }
    Some(if above { (-n, -d) } else { (n, d) })
}

/// The faces of the convex hull of two point sets, as planes `n · x = d` with outward unit `n`.
struct Shaft {
    planes: SmallVec<[(DVec3, f64); 32]>,
}

impl Shaft {
    /// The hull's faces are among the planes through an edge of one hull and a point of the
    /// other, and the faces of each hull: of those, the planes with every point on one side.
    fn new(a: &[DVec3], b: &[DVec3], tol: f64) -> Shaft {
        if a.len() == 8 && b.len() == 8 {
            return Shaft::between_boxes(a, b, tol);
        }
        let mut planes = SmallVec::new();
        let points = || a.iter().chain(b).copied();
        let mut consider = |normal: DVec3, at: DVec3| {
            let length = normal.length();
            if length > 0.0 {
                let n = normal / length;
                planes.extend(supporting(n, n.dot(at), points(), tol));
            }
        };
        for (hull, other) in [(a, b), (b, a)] {
            for [p, q] in edges(hull) {
                for &w in other {
                    consider((q - p).cross(w - p), p);
                }
            }
            for (normal, at) in faces(hull) {
                consider(normal, at);
            }
        }
        Shaft { planes }
    }

    /// The shaft between two boxes (corners as from [`box_corners`](super::tree)): its faces
    /// are faces of the boxes' union, or planes through an edge of one box and the parallel edge
    /// of the other, since every edge runs along an axis.
    fn between_boxes(a: &[DVec3], b: &[DVec3], tol: f64) -> Shaft {
        let mut planes: SmallVec<[(DVec3, f64); 32]> = SmallVec::new();
        let (lo, hi) = (a[0].min(b[0]), a[7].max(b[7]));
        for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
            planes.push((-axis, -axis.dot(lo)));
            planes.push((axis, axis.dot(hi)));
        }
        let points = || a.iter().chain(b).copied();
        for bit in [1, 2, 4] {
            let axis = a[bit] - a[0];
            // The edges along this axis start at the corners without its bit.
            for i in (0..8).filter(|i| i & bit == 0) {
                for j in (0..8).filter(|j| j & bit == 0) {
                    let normal = axis.cross(b[j] - a[i]);
                    let length = normal.length();
                    if !(length > 0.0) {
                        continue;
                    }
                    let n = normal / length;
                    planes.extend(supporting(n, n.dot(a[i]), points(), tol));
                }
            }
        }
        Shaft { planes }
    }

    /// Whether some face has the whole triangle outside (or on it, within `tol`).
    fn excludes(&self, triangle: &[DVec3; 3], tol: f64) -> bool {
        self.planes
            .iter()
            .any(|&(n, d)| triangle.iter().all(|&p| n.dot(p) - d >= -tol))
    }
}

/// The edges of a hull: a polygon's sides (three or four points in order), or a box's twelve
/// (eight corners indexed by bits x, y, z).
fn edges(hull: &[DVec3]) -> SmallVec<[[DVec3; 2]; 12]> {
    if hull.len() == 8 {
        let mut out = SmallVec::new();
        for i in 0..8 {
            for bit in [1, 2, 4] {
                if i & bit == 0 {
                    out.push([hull[i], hull[i | bit]]);
                }
            }
        }
        return out;
    }
    (0..hull.len())
        .map(|i| [hull[i], hull[(i + 1) % hull.len()]])
        .collect()
}

/// The face planes of a hull (a normal, not necessarily outward, and a point): a polygon's own
/// plane, or a box's six.
fn faces(hull: &[DVec3]) -> SmallVec<[(DVec3, DVec3); 6]> {
    if hull.len() == 8 {
        let (lo, hi) = (hull[0], hull[7]);
        return [DVec3::X, DVec3::Y, DVec3::Z]
            .into_iter()
            .flat_map(|axis| [(axis, lo), (axis, hi)])
            .collect();
    }
    let n = (hull[1] - hull[0]).cross(hull[2] - hull[0]);
    SmallVec::from_slice(&[(n, hull[0])])
}
