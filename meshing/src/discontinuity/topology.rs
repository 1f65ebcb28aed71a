//! Which polygons meet where: vertices welded across surfaces, the faces around each vertex and
//! edge, and the silhouette tests of visual events built on them.
//!
//! A blocker made of several faces (a box) casts shadow edges only from its silhouette as seen
//! from the emitter feature: a vertex or an edge whose surrounding faces all lie on one side of
//! the critical plane.

use std::collections::{BTreeMap, HashMap};

use glam::DVec3;
use penumbra_scenes::{Scene, SurfaceId};

/// One corner of one face: the face, and the welded ids of the corner and its two neighbours.
#[derive(Clone, Copy, Debug)]
pub(super) struct Corner {
    pub surface: SurfaceId,
    pub prev: usize,
    pub next: usize,
}

/// The welded vertices and edges of a scene.
#[derive(Clone, Debug)]
pub(super) struct Topology {
    /// Welded vertex positions.
    pub points: Vec<DVec3>,
    /// Each surface's polygon as welded vertex ids.
    pub loops: Vec<Vec<usize>>,
    /// The face corners at each welded vertex.
    pub corners: Vec<Vec<Corner>>,
    /// Each undirected edge `(lo, hi)` and the faces that have it, with the face's direction
    /// (true when the face runs `lo -> hi`).
    pub edges: BTreeMap<(usize, usize), Vec<(SurfaceId, bool)>>,
    pub normals: Vec<DVec3>,
    /// Distance under which two vertices are one.
    pub weld: f64,
}

impl Topology {
    pub(super) fn new(scene: &Scene, weld: f64) -> Topology {
        let mut points: Vec<DVec3> = Vec::new();
        let mut grid: HashMap<(i64, i64, i64), Vec<usize>> = HashMap::new();
        let cell = (4.0 * weld).max(f64::MIN_POSITIVE);
        let key = |p: DVec3| {
            let q = (p / cell).floor();
            (q.x as i64, q.y as i64, q.z as i64)
        };
        let mut weld_point = |p: DVec3| -> usize {
            let (kx, ky, kz) = key(p);
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        if let Some(&id) = grid
                            .get(&(kx + dx, ky + dy, kz + dz))
                            .and_then(|ids| ids.iter().find(|&&id| points[id].distance(p) <= weld))
                        {
                            return id;
                        }
                    }
                }
            }
            let id = points.len();
            points.push(p);
            grid.entry((kx, ky, kz)).or_default().push(id);
            id
        };
        let loops: Vec<Vec<usize>> = scene
            .surfaces
            .iter()
            .map(|s| s.polygon.iter().map(|&p| weld_point(p)).collect())
            .collect();
        let mut corners = vec![Vec::new(); points.len()];
        let mut edges: BTreeMap<(usize, usize), Vec<(SurfaceId, bool)>> = BTreeMap::new();
        for (surface, l) in loops.iter().enumerate() {
            let n = l.len();
            for i in 0..n {
                let (prev, here, next) = (l[(i + n - 1) % n], l[i], l[(i + 1) % n]);
                corners[here].push(Corner {
                    surface,
                    prev,
                    next,
                });
                if here != next {
                    edges
                        .entry((here.min(next), here.max(next)))
                        .or_default()
                        .push((surface, here < next));
                }
            }
        }
        Topology {
            points,
            loops,
            corners,
            edges,
            normals: scene.surfaces.iter().map(|s| s.normal()).collect(),
            weld,
        }
    }

    /// Side of `p` relative to the plane through `origin` with normal `n`: -1, 0 (within the
    /// weld distance) or 1.
    fn side(&self, n: DVec3, origin: DVec3, p: DVec3) -> i8 {
        let h = n.dot(p - origin);
        if h.abs() <= self.weld {
            0
        } else if h > 0.0 {
            1
        } else {
            -1
        }
    }

    /// Whether every face around vertex `v` for which `include` holds lies on one side of the
    /// plane through `v` with unit normal `n`.
    pub(super) fn vertex_is_tangent(
        &self,
        v: usize,
        n: DVec3,
        include: impl Fn(SurfaceId) -> bool,
    ) -> bool {
        let origin = self.points[v];
        let mut seen = 0i8;
        for c in &self.corners[v] {
            if !include(c.surface) {
                continue;
            }
            let (a, b) = (self.points[c.prev], self.points[c.next]);
            // A reflex corner wraps around the vertex: it straddles every plane through it.
            let convex = (origin - a).cross(b - origin).dot(self.normals[c.surface]) >= 0.0;
            let sides = [self.side(n, origin, a), self.side(n, origin, b)];
            if !convex && sides.iter().all(|&s| s != 0) {
                return false;
            }
            if !sides.into_iter().all(|s| keeps_side(&mut seen, s)) {
                return false;
            }
        }
        true
    }

    /// Whether vertex `v` lies on the rim of an open sheet of the faces for which `include`
    /// holds: an edge at `v` with one such face (every corner of a single polygon). Such a
    /// vertex is on the outline from everywhere.
    pub(super) fn on_rim(&self, v: usize, include: impl Fn(SurfaceId) -> bool) -> bool {
        let faces_on = |a: usize, b: usize| {
            self.edges
                .get(&(a.min(b), a.max(b)))
                .map_or(0, |f| f.iter().filter(|&&(s, _)| include(s)).count())
        };
        self.corners[v]
            .iter()
            .filter(|c| include(c.surface))
            .any(|c| faces_on(v, c.prev) == 1 || faces_on(v, c.next) == 1)
    }

    /// Where along the segment `viewpoints` vertex `v` is on the outline of the faces around it
    /// (those for which `include` holds), as runs of parameters in `[0, 1]`: everywhere when it
    /// lies on the rim of an open sheet (an edge at `v` with one such face: every corner of a
    /// single polygon), else where some of its faces turn towards the viewpoint and some away (a
    /// silhouette vertex of a solid). Each face's side changes at most once along the segment,
    /// where it crosses the face's plane; between those crossings the answer is the same.
    pub(super) fn outline_runs(
        &self,
        v: usize,
        viewpoints: [DVec3; 2],
        include: impl Fn(SurfaceId) -> bool,
    ) -> Vec<[f64; 2]> {
        if self.on_rim(v, &include) {
            return vec![[0.0, 1.0]];
        }
        let faces = || self.corners[v].iter().filter(|c| include(c.surface));
        let origin = self.points[v];
        let mut cuts = vec![0.0, 1.0];
        for c in faces() {
            let n = self.normals[c.surface];
            let (h0, h1) = (n.dot(viewpoints[0] - origin), n.dot(viewpoints[1] - origin));
            if (h0 > 0.0) != (h1 > 0.0) {
                cuts.push(h0 / (h0 - h1));
            }
        }
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        // Whether the faces turn both ways as seen from `q`.
        let straddles = |q: DVec3| {
            let mut seen = 0i8;
            !faces().all(|c| keeps_side(&mut seen, self.side(self.normals[c.surface], origin, q)))
        };
        let mut runs: Vec<[f64; 2]> = Vec::new();
        for w in cuts.windows(2) {
            let mid = viewpoints[0].lerp(viewpoints[1], 0.5 * (w[0] + w[1]));
            if w[1] <= w[0] || !straddles(mid) {
                continue;
            }
            match runs.last_mut() {
                Some(r) if r[1] == w[0] => r[1] = w[1],
                _ => runs.push([w[0], w[1]]),
            }
        }
        runs
    }

    /// Whether every face along the edge `(a, b)` for which `include` holds lies on one side of
    /// the plane through the edge with unit normal `n`.
    pub(super) fn edge_is_tangent(
        &self,
        a: usize,
        b: usize,
        n: DVec3,
        include: impl Fn(SurfaceId) -> bool,
    ) -> bool {
        let mut seen = 0i8;
        self.edge_face_vectors(a, b, include)
            .all(|inward| keeps_side(&mut seen, self.side(n, DVec3::ZERO, inward)))
    }

    /// The faces along the edge `(a, b)` for which `include` holds, each as the vector from the
    /// edge into the face, at right angles to the edge and as long as it: what
    /// [`Self::faces_are_tangent`] compares with a plane through the edge.
    pub(super) fn edge_faces(
        &self,
        a: usize,
        b: usize,
        include: impl Fn(SurfaceId) -> bool,
    ) -> Vec<DVec3> {
        self.edge_face_vectors(a, b, include).collect()
    }

    /// [`Self::edge_faces`], one at a time.
    fn edge_face_vectors(
        &self,
        a: usize,
        b: usize,
        include: impl Fn(SurfaceId) -> bool,
    ) -> impl Iterator<Item = DVec3> {
        let faces = self
            .edges
            .get(&(a.min(b), a.max(b)))
            .map_or(&[][..], Vec::as_slice);
        let (pa, pb) = (self.points[a.min(b)], self.points[a.max(b)]);
        faces
            .iter()
            .filter(move |&&(surface, _)| include(surface))
            .map(move |&(surface, forward)| {
                // Into the face from its edge: left of the edge as the face runs it.
                let along = if forward { pb - pa } else { pa - pb };
                let inward = self.normals[surface].cross(along);
                inward.normalize_or_zero() * (pa - pb).length()
            })
    }

    /// Whether the faces of an edge ([`Self::edge_faces`]) lie on one side of the plane through
    /// the edge with unit normal `n`.
    pub(super) fn faces_are_tangent(&self, faces: &[DVec3], n: DVec3) -> bool {
        let mut seen = 0i8;
        faces
            .iter()
            .all(|&inward| keeps_side(&mut seen, self.side(n, DVec3::ZERO, inward)))
    }

    /// Whether the plane through vertex `v` with unit normal `n` contains one of the edges of the
    /// faces at `v`: the visual event is then degenerate (edge–edge) and of order 1.
    pub(super) fn plane_holds_an_edge_at(
        &self,
        v: usize,
        n: DVec3,
        include: impl Fn(SurfaceId) -> bool,
    ) -> bool {
        let origin = self.points[v];
        self.corners[v]
            .iter()
            .filter(|c| include(c.surface))
            .any(|c| {
                self.side(n, origin, self.points[c.prev]) == 0
                    || self.side(n, origin, self.points[c.next]) == 0
            })
    }
}

/// Folds one more side (-1, 0, 1) into the side seen so far; false once two sides differ.
fn keeps_side(seen: &mut i8, side: i8) -> bool {
    if side == 0 {
        return true;
    }
    if *seen != 0 && side != *seen {
        return false;
    }
    *seen = side;
    true
}
