//! Flat patches: welded neighbouring faces that lie in one plane, as a tessellated wall or the
//! flat side of a tessellated solid does. A patch casts the shadow its outline casts, so events
//! are judged per patch, and a vertex inside a straight stretch of a patch's outline is no
//! corner of it.

use glam::DVec3;
use penumbra_scenes::SurfaceId;
use penumbra_scenes::UnionFind;

use super::topology::Topology;

/// Normals of coplanar faces agree to this cosine (faces split from one polygon differ by
/// rounding only).
const COPLANAR_COSINE: f64 = 1.0 - 1e-12;

/// Patches of at most this many faces are judged by all their vertices; larger ones by the
/// vertices where their outline turns.
const FEW_FACES: usize = 8;

/// Each surface's flat patch, and the points each patch's outline turns at.
#[derive(Clone, Debug)]
pub(super) struct Patches {
    pub of_surface: Vec<usize>,
    pub corners: Vec<Vec<DVec3>>,
}

impl Patches {
    pub(super) fn new(topology: &Topology) -> Patches {
        let count = topology.loops.len();
        let mut sets = UnionFind::new(count);
        for faces in topology.edges.values() {
            if let [(s, forward_s), (t, forward_t)] = faces.as_slice()
                && forward_s != forward_t
                && coplanar(topology, *s, *t)
            {
                sets.join(*s, *t);
            }
        }
        let mut index = vec![usize::MAX; count];
        let mut faces: Vec<Vec<SurfaceId>> = Vec::new();
        let mut of_surface = vec![0; count];
        for s in 0..count {
            let root = sets.find(s);
            if index[root] == usize::MAX {
                index[root] = faces.len();
                faces.push(Vec::new());
            }
            of_surface[s] = index[root];
            faces[index[root]].push(s);
        }
        let corners = faces
            .iter()
            .map(|members| {
                let mut ids: Vec<usize> = members
                    .iter()
                    .flat_map(|&f| topology.loops[f].iter().copied())
                    .collect();
                ids.sort_unstable();
                ids.dedup();
                if members.len() > FEW_FACES {
                    ids.retain(|&v| !topology.is_straight(v));
                }
                ids.into_iter().map(|v| topology.points[v]).collect()
            })
            .collect();
        Patches {
            of_surface,
            corners,
        }
    }
}

/// Whether faces `s` and `t` lie in one plane (within the weld distance).
fn coplanar(topology: &Topology, s: SurfaceId, t: SurfaceId) -> bool {
    let (ns, nt) = (topology.normals[s], topology.normals[t]);
    if ns.dot(nt) < COPLANAR_COSINE {
        return false;
    }
    let origin = topology.points[topology.loops[s][0]];
    topology.loops[t]
        .iter()
        .all(|&v| ns.dot(topology.points[v] - origin).abs() <= topology.weld)
}

impl Topology {
    /// Whether vertex `v` lies inside a straight stretch of edges with every face around it
    /// holding that line (a vertex splitting one edge of a tessellated solid, or inside a flat
    /// patch): the outline has no corner there, so it starts no EV event.
    pub(super) fn is_straight(&self, v: usize) -> bool {
        let here = self.points[v];
        let mut directions: Vec<DVec3> = Vec::new();
        for c in &self.corners[v] {
            for w in [c.prev, c.next] {
                if w != v
                    && let Some(d) = (self.points[w] - here).try_normalize()
                    && !directions.iter().any(|e| e.dot(d) > COPLANAR_COSINE)
                {
                    directions.push(d);
                }
            }
        }
        // A line through v: two opposite directions that every face's plane holds.
        directions.iter().enumerate().any(|(i, &d)| {
            directions[i + 1..].iter().any(|&e| {
                d.dot(e) < -COPLANAR_COSINE
                    && self.corners[v]
                        .iter()
                        .all(|c| self.normals[c.surface].dot(d).abs() <= 1.0 - COPLANAR_COSINE)
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use penumbra_scenes::tessellated::tessellated;

    #[test]
    fn a_tessellated_prism_has_the_patches_of_its_polygons() {
        for n in [1, 3] {
            let scene = tessellated(n);
            let topology = Topology::new(&scene, 1e-9 * scene.diagonal());
            let patches = Patches::new(&topology);
            // Light, floor and the prism's eight sides.
            assert_eq!(patches.corners.len(), 10, "tessellated-{n}");
        }
    }

    #[test]
    fn vertices_along_a_split_edge_are_straight_and_corners_are_not() {
        let scene = tessellated(3);
        let topology = Topology::new(&scene, 1e-9 * scene.diagonal());
        let corners = penumbra_scenes::tessellated::l_prism(
            &glam::DAffine3::IDENTITY, // only the count of true corners matters
        )
        .iter()
        .flatten()
        .count();
        let prism: Vec<usize> = (0..topology.points.len())
            .filter(|&v| {
                topology.corners[v]
                    .iter()
                    .all(|c| scene.surfaces[c.surface].name.starts_with("prism"))
            })
            .collect();
        let not_straight = prism.iter().filter(|&&v| !topology.is_straight(v)).count();
        // The L prism has 12 corners (each listed in three faces).
        assert_eq!(corners, 36);
        assert_eq!(not_straight, 12);
    }
}
