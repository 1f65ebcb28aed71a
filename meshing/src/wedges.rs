//! The wedges that input edges (the polygon's edges and the constraints, each a chain of mesh
//! edges) make around each vertex of a mesh, and the angles they force. A triangle corner inside
//! a wedge narrower than the angle refinement aims for cannot reach it; nor can the triangles
//! that lie between two input edges meeting at such an angle (every vertex on one of the two),
//! which quality refinement lays out in shells around the apex: the input forces those angles.

use std::collections::HashMap;
use std::f64::consts::TAU;

use glam::DVec2;

use crate::mesh::SurfaceMesh;
use crate::tolerances::ON_SEGMENT_TOLERANCE;

/// Two input edges that meet at less than this leave triangles between them (every vertex on
/// one of the two) that Delaunay refinement cannot improve without splitting the edges without
/// end: it lays them out in shells around the meeting point and leaves them (Ruppert 1995;
/// Shewchuk 2000, "Mesh generation for domains with small angles": the angle guarantee holds
/// only away from input angles under 60 degrees).
pub(crate) const SHELL_ANGLE_DEG: f64 = 60.0;

/// Per vertex, the directions of the input edges that leave it and the input edges it is on.
#[derive(Clone, Debug)]
pub(crate) struct InputWedges {
    /// Each vertex's place: copies of a vertex split along a value discontinuity share one.
    place_of: Vec<u32>,
    /// Per place, the angles of the input edges leaving it, sorted, in `[-pi, pi]`.
    directions: Vec<Vec<f64>>,
    /// Per place, the input edges through it (their index in `inputs`).
    on: Vec<Vec<u32>>,
    /// The input edges: the polygon's, then the constraints.
    inputs: Vec<[DVec2; 2]>,
}

impl InputWedges {
    pub(crate) fn of(m: &SurfaceMesh) -> InputWedges {
        let mut places: HashMap<(u64, u64), u32> = HashMap::new();
        let place_of: Vec<u32> = m
            .local
            .iter()
            .map(|p| {
                let next = places.len() as u32;
                *places.entry((p.x.to_bits(), p.y.to_bits())).or_insert(next)
            })
            .collect();
        let mut at: Vec<DVec2> = vec![DVec2::ZERO; places.len()];
        for (v, &p) in place_of.iter().enumerate() {
            at[p as usize] = m.local[v];
        }
        let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); places.len()];
        for t in &m.triangles {
            for k in 0..3 {
                let (a, b) = (place_of[t[k] as usize], place_of[t[(k + 1) % 3] as usize]);
                neighbours[a as usize].push(b);
                neighbours[b as usize].push(a);
            }
        }
        for list in &mut neighbours {
            list.sort_unstable();
            list.dedup();
        }
        let mut directions: Vec<Vec<f64>> = vec![Vec::new(); places.len()];
        let n = m.boundary.len();
        let inputs: Vec<[DVec2; 2]> = (0..n)
            .map(|k| [m.boundary[k], m.boundary[(k + 1) % n]])
            .chain(m.constraints.iter().copied())
            .collect();
        let mut on: Vec<Vec<u32>> = vec![Vec::new(); places.len()];
        for (i, &[p, q]) in inputs.iter().enumerate() {
            let Some(&start) = places.get(&(p.x.to_bits(), p.y.to_bits())) else {
                continue;
            };
            let chain = follow(start, p, q, &at, &neighbours);
            for &c in &chain {
                on[c as usize].push(i as u32);
            }
            for w in chain.windows(2) {
                let (a, b) = (w[0] as usize, w[1] as usize);
                let d = at[b] - at[a];
                directions[a].push(d.y.atan2(d.x));
                directions[b].push((-d.y).atan2(-d.x));
            }
        }
        for list in &mut directions {
            list.sort_by(f64::total_cmp);
            list.dedup();
        }
        InputWedges {
            place_of,
            directions,
            on,
            inputs,
        }
    }

    /// Whether the input forces the corner of triangle `tri` at its `k`-th vertex below
    /// `limit` (radians): the corner lies in a narrower wedge of input edges, or the triangle
    /// lies between two input edges that meet at less than [`SHELL_ANGLE_DEG`].
    pub(crate) fn forces(&self, local: &[DVec2], tri: [u32; 3], k: usize, limit: f64) -> bool {
        let [v, a, b] = [tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]].map(|i| i as usize);
        let (da, db) = (
            (local[a] - local[v]).normalize(),
            (local[b] - local[v]).normalize(),
        );
        self.around(v, da, db) < limit
            || self.between_narrow_inputs(tri, SHELL_ANGLE_DEG.to_radians())
    }

    /// Whether every vertex of `tri` is on one of two input edges that meet at an angle under
    /// `limit`.
    fn between_narrow_inputs(&self, tri: [u32; 3], limit: f64) -> bool {
        let sets = tri.map(|v| &self.on[self.place_of[v as usize] as usize]);
        if sets.iter().any(|s| s.is_empty()) {
            return false;
        }
        let covers = |s: u32, t: u32| sets.iter().all(|set| set.contains(&s) || set.contains(&t));
        sets[0].iter().any(|&s| {
            sets.iter().flat_map(|set| set.iter()).any(|&t| {
                t != s
                    && covers(s, t)
                    && meeting_angle(self.inputs[s as usize], self.inputs[t as usize]) < limit
            })
        })
    }

    /// The angle (radians) of the wedge between input edges at vertex `v` that holds the corner
    /// turning counter-clockwise from direction `from` to direction `to`; a full turn where fewer
    /// than two input edges leave `v`.
    pub(crate) fn around(&self, v: usize, from: DVec2, to: DVec2) -> f64 {
        let dirs = &self.directions[self.place_of[v] as usize];
        if dirs.len() < 2 {
            return TAU;
        }
        let mid = from + to;
        let mid = if mid.length_squared() > 0.0 {
            mid
        } else {
            from.perp()
        };
        let phi = mid.y.atan2(mid.x);
        // The first input direction counter-clockwise after the corner's bisector, and the one
        // before it.
        let after = dirs.iter().position(|&a| a > phi).unwrap_or(0);
        let before = (after + dirs.len() - 1) % dirs.len();
        (dirs[after] - dirs[before]).rem_euclid(TAU)
    }
}

/// The narrowest angle (radians) between two segments where they meet; a half turn when they do
/// not meet. Where one ends, only its direction away from the meeting point counts.
fn meeting_angle([p, q]: [DVec2; 2], [r, s]: [DVec2; 2]) -> f64 {
    let (d, e) = (q - p, s - r);
    let den = d.perp_dot(e);
    let slack = ON_SEGMENT_TOLERANCE;
    if den.abs() <= f64::EPSILON * d.length() * e.length() {
        return std::f64::consts::PI;
    }
    let t = (r - p).perp_dot(e) / den;
    let u = (r - p).perp_dot(d) / den;
    if !(-slack..=1.0 + slack).contains(&t) || !(-slack..=1.0 + slack).contains(&u) {
        return std::f64::consts::PI;
    }
    // The directions leaving the meeting point along each segment.
    let leaving = |t: f64, d: DVec2| -> Vec<DVec2> {
        let d = d.normalize();
        let mut out = Vec::with_capacity(2);
        if t < 1.0 - slack {
            out.push(d);
        }
        if t > slack {
            out.push(-d);
        }
        out
    };
    let mut narrowest = std::f64::consts::PI;
    for x in leaving(t, d) {
        for y in leaving(u, e) {
            narrowest = narrowest.min(x.dot(y).clamp(-1.0, 1.0).acos());
        }
    }
    narrowest
}

/// The places along the input edge `p -> q`, from `start` (at `p`), as a chain of mesh edges.
fn follow(start: u32, p: DVec2, q: DVec2, at: &[DVec2], neighbours: &[Vec<u32>]) -> Vec<u32> {
    let d = q - p;
    let len2 = d.length_squared();
    if len2 == 0.0 {
        return Vec::new();
    }
    let len = len2.sqrt();
    let along = |x: DVec2| (x - p).dot(d) / len2;
    let on = |x: DVec2| d.perp_dot(x - p).abs() / len <= ON_SEGMENT_TOLERANCE;
    let slack = ON_SEGMENT_TOLERANCE / len;
    let mut chain = vec![start];
    let mut current = start;
    while along(at[current as usize]) < 1.0 - slack {
        let here = along(at[current as usize]);
        let next = neighbours[current as usize]
            .iter()
            .copied()
            .filter(|&w| {
                let x = at[w as usize];
                on(x) && along(x) > here + slack && along(x) <= 1.0 + slack
            })
            .min_by(|&a, &b| along(at[a as usize]).total_cmp(&along(at[b as usize])));
        let Some(next) = next else { break };
        chain.push(next);
        current = next;
    }
    chain
}
