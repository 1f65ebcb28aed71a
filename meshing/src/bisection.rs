//! Longest-edge bisection of a finished surface mesh (Rivara 1984, 1997): a triangle is split at
//! the midpoint of its longest edge, after the neighbour across that edge has been split until
//! the edge is its longest too (the longest-edge propagation path), so the mesh stays
//! conforming. No angle falls below half the smallest angle the mesh starts with, a segment
//! that was a chain of edges stays one, and every new vertex is the midpoint of an edge that
//! existed before: a value measured there ahead of time is that vertex's value.
//!
//! Along a value discontinuity the two sides have separate vertices at the same points. Triangles
//! are neighbours when their edges join the same *sites* (points), and an edge whose two ends both
//! differ between the sides is split with a midpoint of each side's own.

use std::collections::HashMap;

use crate::mesh::SurfaceMesh;

/// No triangle whose longest edge is shorter than this (in mesh units, where the surface's extent
/// is 1) is split: below it, the midpoints' rounding is a sizeable part of the edge.
pub const SHORTEST_SPLIT_EDGE: f64 = 1e-9;

/// What one [`BisectionMesh::split`] changed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Split {
    /// Triangles that are new or were cut down (each half of every triangle split), possibly
    /// with repeats.
    pub triangles: Vec<u32>,
    /// The vertices added, each with the two vertices of the edge it is the midpoint of and the
    /// corner across that edge, all on the side of the triangle it was made in.
    pub vertices: Vec<(u32, [u32; 3])>,
}

/// The end of a longest-edge propagation path ([`BisectionMesh::terminal`]): the triangles
/// that share the edge to bisect, each with the corner that starts it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Terminal {
    sides: [(u32, usize); 2],
}

impl Terminal {
    /// Each triangle with its corner starting the edge: one, or two.
    pub fn sides(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        (self.sides.iter())
            .filter(|(t, _)| *t != NONE)
            .map(|&(t, k)| (t as usize, k))
    }

    /// Whether bisecting it splits triangle `t`.
    pub fn splits(&self, t: usize) -> bool {
        self.sides().any(|(s, _)| s == t)
    }
}

/// A surface mesh that can be refined by conforming longest-edge bisection.
#[derive(Clone, Debug)]
pub struct BisectionMesh {
    mesh: SurfaceMesh,
    /// Each vertex's site: one per point, shared by the copies on the two sides of a jump.
    site: Vec<u32>,
    sites: u32,
    /// The triangles on each edge, by its sites (smaller first); `NONE` for no triangle.
    edges: HashMap<(u32, u32), [u32; 2]>,
}

const NONE: u32 = u32::MAX;

impl BisectionMesh {
    /// Takes a conforming mesh (a spade triangulation's, with jumps split).
    pub fn new(mesh: SurfaceMesh) -> BisectionMesh {
        let mut at: HashMap<(u64, u64), u32> = HashMap::new();
        let site: Vec<u32> = mesh
            .local
            .iter()
            .map(|p| {
                let n = at.len() as u32;
                *at.entry((p.x.to_bits(), p.y.to_bits())).or_insert(n)
            })
            .collect();
        let sites = at.len() as u32;
        let mut b = BisectionMesh {
            mesh,
            site,
            sites,
            edges: HashMap::new(),
        };
        for t in 0..b.mesh.triangles.len() {
            b.attach(t as u32);
        }
        b
    }

    /// The mesh as it is now.
    pub fn mesh(&self) -> &SurfaceMesh {
        &self.mesh
    }

    /// The mesh, refined.
    pub fn into_mesh(self) -> SurfaceMesh {
        self.mesh
    }

    /// Vertex `k`'s edge of triangle `t`: from its corner `k` to the next.
    pub fn edge(&self, t: usize, k: usize) -> [u32; 2] {
        let tri = self.mesh.triangles[t];
        [tri[k], tri[(k + 1) % 3]]
    }

    /// Whether triangle `t` is too small to split ([`SHORTEST_SPLIT_EDGE`]).
    pub fn too_small(&self, t: usize) -> bool {
        let k = self.longest(t);
        self.length2(self.edge(t, k)) < SHORTEST_SPLIT_EDGE * SHORTEST_SPLIT_EDGE
    }

    /// Splits triangle `t` at its longest edge, splitting first what conformity needs; appends
    /// what changed to `out`.
    pub fn split(&mut self, t: usize, out: &mut Split) {
        loop {
            let end = self.terminal(t);
            self.bisect_terminal(end, out);
            if end.splits(t) {
                return;
            }
        }
    }

    /// Where `t`'s longest-edge propagation path ends: the first triangle on it whose longest
    /// edge is its neighbour's longest too (or has no neighbour). Bisecting that pair, again
    /// and again, splits `t`.
    pub fn terminal(&self, t: usize) -> Terminal {
        let mut t = t as u32;
        loop {
            let k = self.longest(t as usize);
            let e = self.edge(t as usize, k);
            let Some(n) = self.across(t, e) else {
                return Terminal {
                    sides: [(t, k), (NONE, 0)],
                };
            };
            let kn = self.longest(n as usize);
            if self.key(self.edge(n as usize, kn)) == self.key(e) {
                return Terminal {
                    sides: [(t, k), (n, kn)],
                };
            }
            t = n;
        }
    }

    /// Bisects the pair [`Self::terminal`] found (nothing else changed since); appends what
    /// changed to `out`.
    pub fn bisect_terminal(&mut self, end: Terminal, out: &mut Split) {
        let [(t, k), (n, kn)] = end.sides;
        self.bisect(t, k, (n != NONE).then_some((n, kn)), out);
    }

    fn key(&self, [a, b]: [u32; 2]) -> (u32, u32) {
        let (p, q) = (self.site[a as usize], self.site[b as usize]);
        (p.min(q), p.max(q))
    }

    fn length2(&self, [a, b]: [u32; 2]) -> f64 {
        (self.mesh.local[a as usize] - self.mesh.local[b as usize]).length_squared()
    }

    /// The corner starting triangle `t`'s longest edge; ties go to the edge with the smaller
    /// sites, so that every edge has one rank and propagation paths end.
    fn longest(&self, t: usize) -> usize {
        (0..3)
            .max_by(|&i, &j| {
                let (ei, ej) = (self.edge(t, i), self.edge(t, j));
                self.length2(ei)
                    .total_cmp(&self.length2(ej))
                    .then(self.key(ej).cmp(&self.key(ei)))
            })
            .unwrap_or(0)
    }

    /// The triangle across edge `e` of triangle `t`, if any.
    fn across(&self, t: u32, e: [u32; 2]) -> Option<u32> {
        let pair = self.edges.get(&self.key(e))?;
        let other = if pair[0] == t { pair[1] } else { pair[0] };
        (other != NONE).then_some(other)
    }

    fn attach(&mut self, t: u32) {
        for k in 0..3 {
            let key = self.key(self.edge(t as usize, k));
            let pair = self.edges.entry(key).or_insert([NONE, NONE]);
            if pair[0] == NONE {
                pair[0] = t;
            } else {
                pair[1] = t;
            }
        }
    }

    fn detach(&mut self, t: u32) {
        for k in 0..3 {
            let key = self.key(self.edge(t as usize, k));
            if let Some(pair) = self.edges.get_mut(&key) {
                if pair[0] == t {
                    pair[0] = pair[1];
                }
                pair[1] = NONE;
                if pair[0] == NONE {
                    self.edges.remove(&key);
                }
            }
        }
    }

    /// Splits triangle `t` at its edge `k`, and its neighbour `n` at its edge `kn` (the same
    /// edge) if it has one.
    fn bisect(&mut self, t: u32, k: usize, n: Option<(u32, usize)>, out: &mut Split) {
        let [a, b] = self.edge(t as usize, k);
        let site = self.sites;
        self.sites += 1;
        let m = self.midpoint(a, b, site);
        out.vertices.push((m, [a, b, self.opposite(t, k)]));
        self.halve(t, k, m, out);
        if let Some((n, kn)) = n {
            let [c, d] = self.edge(n as usize, kn);
            // The other side has the same vertices unless the edge lies on a jump.
            let mn = if c == b || d == a {
                m
            } else {
                let mn = self.midpoint(c, d, site);
                out.vertices.push((mn, [c, d, self.opposite(n, kn)]));
                mn
            };
            self.halve(n, kn, mn, out);
        }
    }

    /// The corner of triangle `t` across its edge `k`.
    pub fn opposite(&self, t: u32, k: usize) -> u32 {
        self.mesh.triangles[t as usize][(k + 2) % 3]
    }

    fn midpoint(&mut self, a: u32, b: u32, site: u32) -> u32 {
        let mesh = &mut self.mesh;
        let (a, b) = (a as usize, b as usize);
        mesh.local.push((mesh.local[a] + mesh.local[b]) * 0.5);
        mesh.points3.push((mesh.points3[a] + mesh.points3[b]) * 0.5);
        self.site.push(site);
        (mesh.local.len() - 1) as u32
    }

    /// Replaces triangle `t` by its two halves at vertex `m` on its edge `k`.
    fn halve(&mut self, t: u32, k: usize, m: u32, out: &mut Split) {
        self.detach(t);
        let tri = self.mesh.triangles[t as usize];
        let (a, b, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
        self.mesh.triangles[t as usize] = [a, m, c];
        let other = self.mesh.triangles.len() as u32;
        self.mesh.triangles.push([m, b, c]);
        self.attach(t);
        self.attach(other);
        out.triangles.extend([t, other]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::discontinuity::{DiscontinuityOptions, find_discontinuities};
    use crate::mesh_scene_discontinuity;
    use penumbra_scenes::{Visibility, builtin};

    fn smallest_angle(mesh: &SurfaceMesh) -> f64 {
        mesh.triangles
            .iter()
            .map(|tri| {
                let p = tri.map(|i| mesh.local[i as usize]);
                (0..3)
                    .map(|k| {
                        let (u, v) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
                        u.angle_to(v).abs()
                    })
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Every edge has one triangle on each side but the polygon's boundary, whose edges add up
    /// to its perimeter: a hanging vertex would leave edges of one triangle inside.
    fn assert_conforming(b: &BisectionMesh) {
        let m = b.mesh();
        let mut open = 0.0;
        for (&(p, q), pair) in &b.edges {
            assert!(pair[0] != NONE, "edge {p}-{q} without triangles");
            if pair[1] == NONE {
                let t = pair[0] as usize;
                let k = (0..3)
                    .find(|&k| b.key(b.edge(t, k)) == (p, q))
                    .expect("on it");
                let [u, v] = b.edge(t, k);
                open += m.local[u as usize].distance(m.local[v as usize]);
            }
        }
        let n = m.boundary.len();
        let perimeter: f64 = (0..n)
            .map(|k| m.boundary[k].distance(m.boundary[(k + 1) % n]))
            .sum();
        assert!(
            (open - perimeter).abs() <= 1e-9 * perimeter,
            "{open} vs {perimeter}"
        );
    }

    /// Splitting any triangles keeps the mesh conforming and covering the polygon (the sanity
    /// check), adds at least one triangle each, and keeps every angle above half the smallest
    /// one it started with; on the Cornell box, whose blocks stand on the floor, the two sides
    /// of their contact lines keep vertices of their own.
    #[test]
    fn splits_stay_conforming_and_keep_angles() {
        let scene = builtin::cornell();
        let visibility = Visibility::build(&scene);
        let found = find_discontinuities(&scene, &visibility, &DiscontinuityOptions::default());
        let mesh = mesh_scene_discontinuity(&scene, &visibility, found, 3000, 1.0).expect("meshes");
        let floor = scene.surface_id("floor").expect("a floor");
        for m in mesh.surfaces {
            let start = smallest_angle(&m);
            let mut b = BisectionMesh::new(m);
            for round in 0..6 {
                let count = b.mesh().triangle_count();
                let mut out = Split::default();
                // Every third triangle, then the newest ones: paths cross each other.
                for t in (round % 3..count).step_by(3) {
                    b.split(t, &mut out);
                }
                assert!(b.mesh().triangle_count() >= count + count / 3);
                b.mesh().sanity_check().expect("conforming");
                let edges = b.mesh().edge_list();
                // Conforming: each interior edge has two triangles, so no vertex lies inside
                // another triangle's edge; every new vertex is the midpoint of its parent edge.
                for &(v, [p, q, _]) in &out.vertices {
                    let mid = (b.mesh().local[p as usize] + b.mesh().local[q as usize]) * 0.5;
                    assert_eq!(b.mesh().local[v as usize], mid);
                }
                let _ = edges;
                assert_conforming(&b);
            }
            assert!(smallest_angle(b.mesh()) >= 0.5 * start - 1e-12);
            let copies = b.mesh().vertex_count() - b.sites as usize;
            if b.mesh().surface == floor {
                assert!(copies > 0, "the floor's contact lines split its vertices");
            }
        }
    }
}
