//! Critical surfaces of EV and VE visual events, and where they meet a receiver's plane.
//!
//! An EV wedge is swept by the rays from every point of an emitter edge through a blocker vertex;
//! a VE wedge by the rays from an emitter vertex through every point of a blocker edge. Both are
//! planar and start at the blocker: only beyond it do they separate more light from less.

use glam::DVec3;
use penumbra_scenes::SurfaceId;

/// Whether the emitter or the blocker contributes the edge of a visual event.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Event {
    /// Emitter edge, blocker vertex.
    Ev,
    /// Emitter vertex, blocker edge.
    Ve,
    /// Emitter edge and two blocker edges (a ruled quadric).
    Eee,
    /// A blocker touching the receiver.
    Contact,
    /// A blocker vertex and an edge of another blocker, in a plane that cuts the emitter.
    BlockerEv,
    /// The emitter's own plane, cutting the receiver.
    Horizon,
}

impl Event {
    /// Every event, in the order the exports number them.
    pub const ALL: [Event; 6] = [
        Event::Ev,
        Event::Ve,
        Event::Eee,
        Event::Contact,
        Event::BlockerEv,
        Event::Horizon,
    ];

    /// The event's name in outputs: `EV`, `VE`, `EEE`, `contact`, `blocker-EV` or `horizon`.
    pub fn name(self) -> &'static str {
        match self {
            Event::Ev => "EV",
            Event::Ve => "VE",
            Event::Eee => "EEE",
            Event::Contact => "contact",
            Event::BlockerEv => "blocker-EV",
            Event::Horizon => "horizon",
        }
    }
}

/// A planar critical surface: rays from `source` (an emitter edge, or a vertex repeated) through
/// `through` (a blocker vertex repeated, or a blocker edge).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Wedge {
    pub emitter: SurfaceId,
    pub event: Event,
    pub source: [DVec3; 2],
    pub through: [DVec3; 2],
    /// 1 when the wedge also holds an edge of the other feature's polygon (edge–edge, as with
    /// parallel emitter and blocker edges), else 2.
    pub order: u8,
}

impl Wedge {
    /// The wedge cut off at `reach` from its blocker feature: a convex fan polygon in its plane.
    pub(super) fn polygon(&self, reach: f64) -> Vec<DVec3> {
        // Directions of the rays at a few parameters along the moving feature: a fan covers the
        // wedge up to `reach * cos(pi / 8)` however wide it opens.
        const FAN: usize = 4;
        let ray = |l: f64| {
            let q = self.source[0].lerp(self.source[1], l);
            let p = self.through[0].lerp(self.through[1], l);
            (p, (p - q).normalize_or_zero())
        };
        match self.event {
            Event::Ev | Event::BlockerEv => {
                let v = self.through[0];
                let mut poly = vec![v];
                poly.extend((0..=FAN).map(|k| {
                    let (p, d) = ray(k as f64 / FAN as f64);
                    p + d * reach
                }));
                poly
            }
            _ => {
                let mut poly = vec![self.through[1], self.through[0]];
                poly.extend((0..=FAN).map(|k| {
                    let (p, d) = ray(k as f64 / FAN as f64);
                    p + d * reach
                }));
                poly
            }
        }
    }

    /// The segment where the wedge meets the plane through `origin` with unit normal `n`, if it
    /// crosses it. `reach` bounds the wedge (a few scene diagonals).
    pub(super) fn meet_plane(&self, origin: DVec3, n: DVec3, reach: f64) -> Option<[DVec3; 2]> {
        let poly = self.polygon(reach);
        let h: Vec<f64> = poly.iter().map(|&p| n.dot(p - origin)).collect();
        let mut points = Vec::with_capacity(2);
        let m = poly.len();
        for i in 0..m {
            let j = (i + 1) % m;
            if (h[i] > 0.0) != (h[j] > 0.0) {
                let t = h[i] / (h[i] - h[j]);
                points.push(poly[i].lerp(poly[j], t));
            }
        }
        (points.len() == 2).then(|| [points[0], points[1]])
    }

    /// For a point `x` on the wedge beyond its blocker feature, the ray that generates it: the
    /// point where it grazes the blocker, and the point of the emitter it comes from.
    pub(super) fn generator(&self, x: DVec3) -> (DVec3, DVec3) {
        match self.event {
            Event::Ev | Event::BlockerEv => {
                let v = self.through[0];
                (v, line_meet(x, v, self.source[0], self.source[1]))
            }
            _ => {
                let a = self.source[0];
                (line_meet(a, x, self.through[0], self.through[1]), a)
            }
        }
    }
}

/// The point of line `c + s (d - c)` closest to the line through `a` and `b` (for coplanar
/// lines, their intersection), clamped to the segment `c-d`.
pub(super) fn line_meet(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> DVec3 {
    let (u, v, w) = (b - a, d - c, c - a);
    let (uu, uv, vv, uw, vw) = (u.dot(u), u.dot(v), v.dot(v), u.dot(w), v.dot(w));
    let den = uu * vv - uv * uv;
    let s = if den.abs() <= f64::EPSILON * uu * vv {
        0.0
    } else {
        (uv * uw - uu * vw) / den
    };
    c + v * s.clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ev_wedge_meets_the_floor_where_the_shadow_edge_is() {
        // Light edge y = -0.5 at height 3, blocker corner (0.5, 0.5, 1): the textbook's outer
        // penumbra boundary y = 1 on the floor, for x in [0.5, 1].
        let w = Wedge {
            emitter: 0,
            event: Event::Ev,
            source: [DVec3::new(-0.5, -0.5, 3.0), DVec3::new(0.5, -0.5, 3.0)],
            through: [DVec3::new(0.5, 0.5, 1.0); 2],
            order: 1,
        };
        let [p, q] = w
            .meet_plane(DVec3::ZERO, DVec3::Z, 100.0)
            .expect("meets the floor");
        for x in [p, q] {
            assert!((x.y - 1.0).abs() < 1e-12 && x.z.abs() < 1e-12, "{x}");
        }
        let (lo, hi) = (p.x.min(q.x), p.x.max(q.x));
        assert!(
            (lo - 0.5).abs() < 1e-12 && (hi - 1.0).abs() < 1e-12,
            "{lo} {hi}"
        );
        let (g, s) = w.generator(DVec3::new(0.75, 1.0, 0.0));
        assert!((g - DVec3::new(0.5, 0.5, 1.0)).length() < 1e-12);
        assert!((s - DVec3::new(0.0, -0.5, 3.0)).length() < 1e-12, "{s}");
    }

    #[test]
    fn ve_wedge_starts_beyond_the_blocker_edge() {
        let w = Wedge {
            emitter: 0,
            event: Event::Ve,
            source: [DVec3::new(0.5, -0.5, 3.0); 2],
            through: [DVec3::new(-0.5, 0.5, 1.0), DVec3::new(0.5, 0.5, 1.0)],
            order: 2,
        };
        let [p, q] = w
            .meet_plane(DVec3::ZERO, DVec3::Z, 100.0)
            .expect("meets the floor");
        // Rays from (0.5, -0.5, 3) through (x_b, 0.5, 1) hit the floor at (1.5 x_b - 0.25, 1).
        let (lo, hi) = (p.x.min(q.x), p.x.max(q.x));
        assert!(
            (lo + 1.0).abs() < 1e-12 && (hi - 0.5).abs() < 1e-12,
            "{lo} {hi}"
        );
        assert!((p.y - 1.0).abs() < 1e-12);
        // The same wedge does not reach a plane above the blocker.
        assert!(
            w.meet_plane(DVec3::new(0.0, 0.0, 2.0), DVec3::Z, 100.0)
                .is_none()
        );
    }
}
