//! Merging coplanar adjacent faces into single surfaces, where that is exact.
//!
//! Exported meshes tessellate a flat wall into many triangles; radiosity wants the wall. Faces
//! are merged when they share whole edges (corners welded by identical position), lie in one
//! plane (each within [`PLANARITY_TOLERANCE`] of the other's, relative to their size), face the
//! same way (they run along their shared edge in opposite directions) and belong to the same
//! group (material). A connected set of such faces, a *region*, becomes one polygon when its
//! union is a simple polygon without holes; otherwise it is grown into pieces that are
//! ([`disk`]), and what still fails stays as it was.
//!
//! Why the union is exact: the interior edges of a region cancel in pairs, so its boundary chain
//! is the sum of its faces' boundaries, and for any point the winding numbers add up the same way.
//! The faces are simple and counter-clockwise, each winding a point 0 or 1 times; when the
//! boundary is one simple counter-clockwise loop it winds each point 0 or 1 times too, so no two
//! faces overlap and the loop encloses exactly their union. The area is unchanged, and so is
//! the light. Every merged polygon is checked as validation would check it, and its area
//! against the faces' sum, before it replaces them.
//!
//! Every step is linear in the number of corners: welding and edges through hash maps, regions
//! through union-find, boundaries by tracing.

mod disk;
mod outline;

use std::collections::HashMap;

use glam::DVec3;

use crate::polygon;
use crate::validate::{PLANARITY_TOLERANCE, polygon_problem};

/// Marks a face edge that is not merged with a neighbour.
const NO_TWIN: u32 = u32::MAX;

/// Faces that become one surface, and its polygon. A piece of one face keeps the face's polygon.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Piece {
    /// Indices of the faces, ascending.
    pub faces: Vec<usize>,
    pub polygon: Vec<DVec3>,
}

/// What merging did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct MergeSummary {
    /// Faces that are now part of a larger surface.
    pub merged_faces: usize,
    /// The surfaces they became.
    pub merged_surfaces: usize,
    /// Regions of coplanar faces that could not become one polygon (their union has holes or
    /// touches itself) and were kept in several pieces.
    pub split_regions: usize,
}

/// Merges coplanar adjacent faces of the same group. `polygons[i]` is face `i`, in the group
/// `groups[i]`; `scene_diagonal` scales the tolerances, as in validation. Returns pieces covering
/// every face once, in the order of their first faces.
pub(crate) fn merge_coplanar(
    polygons: &[Vec<DVec3>],
    groups: &[usize],
    scene_diagonal: f64,
) -> (Vec<Piece>, MergeSummary) {
    let mesh = Mesh::build(polygons, groups, scene_diagonal);
    let mut pieces = Vec::with_capacity(polygons.len());
    let mut summary = MergeSummary::default();
    let mut owner = vec![disk::FREE; polygons.len()];
    for region in mesh.regions() {
        if region.len() == 1 {
            pieces.push(mesh.single(region[0]));
            continue;
        }
        let whole = outline::trace(&mesh, &region, |_| true)
            .and_then(|boundary| outline::polygon(&mesh, &region, &boundary, scene_diagonal));
        let merged = match whole {
            Some(polygon) => vec![Piece {
                faces: region,
                polygon,
            }],
            None => {
                summary.split_regions += 1;
                disk::split_region(&mesh, &region, &mut owner, scene_diagonal)
            }
        };
        for piece in merged {
            if piece.faces.len() > 1 {
                summary.merged_faces += piece.faces.len();
                summary.merged_surfaces += 1;
            }
            pieces.push(piece);
        }
    }
    pieces.sort_by_key(|p| p.faces.first().copied());
    (pieces, summary)
}

/// The faces as welded corners, with each edge's mergeable neighbour.
struct Mesh<'a> {
    polygons: &'a [Vec<DVec3>],
    /// Face `f`'s corners are `ids[starts[f]..starts[f + 1]]`; edge `k` of the flat array runs
    /// from corner `k` to the next corner of its face.
    starts: Vec<usize>,
    ids: Vec<u32>,
    positions: Vec<DVec3>,
    /// The face across edge `k` when the two merge, else [`NO_TWIN`].
    twins: Vec<u32>,
    /// Union-find parents: faces with the same root form a region.
    parents: Vec<u32>,
}

/// The faces that use an undirected edge, as (face, edge) pairs; the first two are kept.
#[derive(Clone, Copy)]
struct EdgeUse {
    uses: [(u32, u32); 2],
    count: u32,
}

impl<'a> Mesh<'a> {
    fn build(polygons: &'a [Vec<DVec3>], groups: &[usize], scene_diagonal: f64) -> Mesh<'a> {
        let mut mesh = Mesh {
            polygons,
            starts: Vec::with_capacity(polygons.len() + 1),
            ids: Vec::new(),
            positions: Vec::new(),
            twins: Vec::new(),
            parents: (0..polygons.len() as u32).collect(),
        };
        mesh.weld();
        let planes: Vec<Option<FacePlane>> = polygons
            .iter()
            .map(|p| FacePlane::of(p, scene_diagonal))
            .collect();
        for (first, second) in mesh.shared_edges() {
            let (f, g) = (mesh.face_of(first), mesh.face_of(second));
            let same_group = groups.get(f) == groups.get(g);
            let coplanar = match (&planes[f], &planes[g]) {
                (Some(a), Some(b)) => a.coplanar_with(b, &polygons[f], &polygons[g]),
                _ => false,
            };
            if f != g && same_group && coplanar {
                mesh.twins[first] = g as u32;
                mesh.twins[second] = f as u32;
                mesh.union(f, g);
            }
        }
        mesh
    }

    /// Corner ids by identical position (`-0.0` and `0.0` alike).
    fn weld(&mut self) {
        let mut by_position: HashMap<[u64; 3], u32> = HashMap::new();
        for polygon in self.polygons {
            self.starts.push(self.ids.len());
            for &p in polygon {
                let key = [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits);
                let next = self.positions.len() as u32;
                let id = *by_position.entry(key).or_insert(next);
                if id == next {
                    self.positions.push(p);
                }
                self.ids.push(id);
            }
        }
        self.starts.push(self.ids.len());
        self.twins = vec![NO_TWIN; self.ids.len()];
    }

    /// Pairs of face edges that run along the same two corners in opposite directions, where no
    /// third face uses those corners as an edge.
    fn shared_edges(&self) -> Vec<(usize, usize)> {
        let mut edges: HashMap<(u32, u32), EdgeUse> = HashMap::with_capacity(self.ids.len());
        for face in 0..self.polygons.len() {
            for edge in self.starts[face]..self.starts[face + 1] {
                let (a, b) = self.edge(edge);
                let entry = edges.entry((a.min(b), a.max(b))).or_insert(EdgeUse {
                    uses: [(face as u32, edge as u32); 2],
                    count: 0,
                });
                if entry.count < 2 {
                    entry.uses[entry.count as usize] = (face as u32, edge as u32);
                }
                entry.count += 1;
            }
        }
        // In face order, so the result does not depend on the hash map's order.
        let mut pairs = Vec::new();
        for edge in 0..self.ids.len() {
            let (a, b) = self.edge(edge);
            let Some(uses) = edges.get(&(a.min(b), a.max(b))) else {
                continue;
            };
            let (first, second) = (uses.uses[0].1 as usize, uses.uses[1].1 as usize);
            if uses.count == 2 && first == edge && self.edge(second) == (b, a) {
                pairs.push((first, second));
            }
        }
        pairs
    }

    /// The corners an edge of the flat array runs between.
    fn edge(&self, k: usize) -> (u32, u32) {
        let face = self.face_of(k);
        let (start, end) = (self.starts[face], self.starts[face + 1]);
        let next = if k + 1 == end { start } else { k + 1 };
        (self.ids[k], self.ids[next])
    }

    /// The face an edge of the flat array belongs to.
    fn face_of(&self, k: usize) -> usize {
        self.starts.partition_point(|&s| s <= k) - 1
    }

    /// Face `f`'s edges in the flat array.
    fn edges_of(&self, f: usize) -> std::ops::Range<usize> {
        self.starts[f]..self.starts[f + 1]
    }

    fn root(&mut self, mut f: u32) -> u32 {
        while self.parents[f as usize] != f {
            let grandparent = self.parents[self.parents[f as usize] as usize];
            self.parents[f as usize] = grandparent;
            f = grandparent;
        }
        f
    }

    fn union(&mut self, f: usize, g: usize) {
        let (a, b) = (self.root(f as u32), self.root(g as u32));
        // The smaller index as the root keeps regions in face order.
        self.parents[a.max(b) as usize] = a.min(b);
    }

    /// Every region, its faces ascending, in the order of its first face.
    fn regions(&self) -> Vec<Vec<usize>> {
        let mut slot = vec![usize::MAX; self.polygons.len()];
        let mut regions: Vec<Vec<usize>> = Vec::new();
        for f in 0..self.polygons.len() {
            let mut r = f;
            while self.parents[r] as usize != r {
                r = self.parents[r] as usize;
            }
            if slot[r] == usize::MAX {
                slot[r] = regions.len();
                regions.push(Vec::new());
            }
            regions[slot[r]].push(f);
        }
        regions
    }

    fn single(&self, f: usize) -> Piece {
        Piece {
            faces: vec![f],
            polygon: self.polygons[f].clone(),
        }
    }
}

/// A face's plane and size, for faces that are valid surfaces on their own.
struct FacePlane {
    normal: DVec3,
    centroid: DVec3,
    diameter: f64,
}

impl FacePlane {
    fn of(points: &[DVec3], scene_diagonal: f64) -> Option<FacePlane> {
        if polygon_problem(points, scene_diagonal).is_some() {
            return None;
        }
        Some(FacePlane {
            normal: polygon::newell_normal(points).try_normalize()?,
            centroid: polygon::centroid(points),
            diameter: polygon::diameter(points),
        })
    }

    /// Facing the same way, and each face's corners within the planarity tolerance of the
    /// other's plane, relative to the larger face.
    fn coplanar_with(&self, other: &FacePlane, mine: &[DVec3], theirs: &[DVec3]) -> bool {
        let tolerance = PLANARITY_TOLERANCE * self.diameter.max(other.diameter);
        let near = |plane: &FacePlane, points: &[DVec3]| {
            points
                .iter()
                .all(|&p| (p - plane.centroid).dot(plane.normal).abs() <= tolerance)
        };
        self.normal.dot(other.normal) > 0.0 && near(self, theirs) && near(other, mine)
    }
}
