//! Closed solids among a scene's surfaces: groups of faces that share every edge with exactly
//! one other face of the group, oriented consistently. Light that reaches a closed solid enters
//! it through a face turned towards the light's source, so faces turned away can never be the
//! first thing a ray meets and are skipped as occluders.
//!
//! A closed solid also encloses: no ray from a point inside it leaves the scene, so every form
//! factor from there sums to exactly one ([`Enclosures`]).

use std::collections::{HashMap, HashSet};

use glam::DVec3;
use penumbra_scenes::{Bounds, Scene, SurfaceId, UnionFind, Visibility};
use rayon::prelude::*;

use crate::elements::Discretization;
use crate::lambert::ReceivingPoint;

/// A corner identified by its exact coordinates (faces of a welded mesh share them).
fn key(p: DVec3) -> [u64; 3] {
    [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]
}

/// For each surface, `Some(sign)` when it is a face of a closed, consistently oriented solid
/// that rests on no other surface ([`resting_solids`]): its outward normal is `sign` times its
/// own normal. `None` for every other surface.
pub(crate) fn closed_solid_orientation(scene: &Scene, visibility: &Visibility) -> Vec<Option<f64>> {
    let solids = closed_solids(scene);
    let resting = resting_solids(scene, visibility, &solids);
    solids
        .into_iter()
        .map(|solid| {
            solid
                .filter(|(group, _)| !resting.contains(group))
                .map(|(_, sign)| sign)
        })
        .collect()
}

/// The closed solids (by group) one of whose faces lies on another surface that faces it, as a
/// cube stands on a floor: all the faces' corners within the meeting distance of its plane,
/// their boxes overlapping. A point of that surface under the face lies in the face's plane, so
/// the face casts nothing from there, and the solid's faces turned away from the point are all
/// that stand between it and the light: they must not be skipped as turned away.
fn resting_solids(
    scene: &Scene,
    visibility: &Visibility,
    solids: &[Option<(usize, f64)>],
) -> HashSet<usize> {
    let near = visibility.meeting_distance();
    let triangles = visibility.triangles();
    let mut resting = HashSet::new();
    for (f, face) in scene.surfaces.iter().enumerate() {
        let Some((group, sign)) = solids[f] else {
            continue;
        };
        if resting.contains(&group) {
            continue;
        }
        let outward = face.normal() * sign;
        let origin = face.polygon[0];
        let b = face.bounds();
        let around = Bounds {
            min: b.min - DVec3::splat(near),
            max: b.max + DVec3::splat(near),
        };
        let mut touching = false;
        visibility.triangles_overlapping(around, |t| {
            let other = &triangles[t];
            touching = touching
                || (solids[other.surface].is_none_or(|(g, _)| g != group)
                    && visibility.triangle_normal(t).dot(outward) < 0.0
                    && other
                        .vertices
                        .iter()
                        .all(|&p| outward.dot(p - origin).abs() <= near));
        });
        if touching {
            resting.insert(group);
        }
    }
    resting
}

/// Each surface's outward sign as a face of a closed solid ([`closed_solids`]), resting or not.
fn closed_solid_signs(scene: &Scene) -> Vec<Option<f64>> {
    closed_solids(scene)
        .into_iter()
        .map(|solid| solid.map(|(_, sign)| sign))
        .collect()
}

/// For each surface, `Some((solid, sign))` when it is a face of a closed, consistently oriented
/// solid (numbered by any of its faces): its outward normal is `sign` times its own normal.
fn closed_solids(scene: &Scene) -> Vec<Option<(usize, f64)>> {
    let surfaces = &scene.surfaces;
    // Directed edges by their corners, and the faces that hold them.
    let mut edges: HashMap<([u64; 3], [u64; 3]), Vec<usize>> = HashMap::new();
    for (s, surface) in surfaces.iter().enumerate() {
        let p = &surface.polygon;
        for i in 0..p.len() {
            edges
                .entry((key(p[i]), key(p[(i + 1) % p.len()])))
                .or_default()
                .push(s);
        }
    }
    let mut groups = UnionFind::new(surfaces.len());
    let mut open = vec![false; surfaces.len()];
    for (&(a, b), faces) in &edges {
        match (faces.as_slice(), edges.get(&(b, a)).map(Vec::as_slice)) {
            ([s], Some([t])) => groups.join(*s, *t),
            _ => faces.iter().for_each(|&s| open[s] = true),
        }
    }
    // A group is closed when none of its faces has an unmatched edge; its signed volume says
    // which way its faces turn.
    let mut closed: HashMap<usize, (bool, f64, DVec3)> = HashMap::new();
    for s in 0..surfaces.len() {
        let root = groups.find(s);
        let entry = closed
            .entry(root)
            .or_insert((true, 0.0, surfaces[s].polygon[0]));
        entry.0 &= !open[s];
        let (origin, p) = (entry.2, &surfaces[s].polygon);
        for i in 1..p.len().saturating_sub(1) {
            entry.1 += (p[0] - origin).dot((p[i] - origin).cross(p[i + 1] - origin));
        }
    }
    (0..surfaces.len())
        .map(|s| {
            let root = groups.find(s);
            let (is_closed, volume, _) = closed[&root];
            (is_closed && volume != 0.0).then(|| (root, volume.signum()))
        })
        .collect()
}

/// Probe rays a point tries before it is taken to be open: each leans off the normal toward one
/// of these directions of its tangent plane, by [`PROBE_LEAN`].
const PROBE_TURNS: [f64; 4] = [0.0, 1.7, 3.3, 4.9];
const PROBE_LEAN: f64 = 0.37;

/// A probe whose direction is within this cosine of a face's plane grazes it: it proves nothing,
/// and the next probe is tried.
const GRAZING: f64 = 1e-6;

/// Which points lie inside a *room*: a closed solid whose faces turn inward. From inside a room
/// every ray meets a face's front, of the room or of a solid in it, provided every surface of the
/// scene is a face of a closed solid (a lone polygon would show its black back to some points),
/// so the form factors from such a point sum to exactly one.
pub(crate) struct Enclosures<'a> {
    visibility: &'a Visibility,
    /// Whether each surface is a face of a room.
    room: Vec<bool>,
    /// Whether every surface is a face of a closed solid; else nothing is taken to be enclosed.
    solid: bool,
}

impl<'a> Enclosures<'a> {
    pub(crate) fn new(scene: &Scene, visibility: &'a Visibility) -> Enclosures<'a> {
        let orientation = closed_solid_signs(scene);
        Enclosures {
            visibility,
            room: orientation.iter().map(|o| *o == Some(-1.0)).collect(),
            solid: orientation.iter().all(Option::is_some),
        }
    }

    /// Whether the front of surface `surface` at `x` lies inside a room, proved by a probe ray
    /// that meets a room's face first, on its front. A probe that meets a solid's outside, or
    /// grazes a face, proves nothing, and the next is tried; one that leaves the scene proves
    /// the point open. A point no probe decides is taken to be open: its total is then estimated
    /// instead of known, which is less exact, never wrong.
    pub(crate) fn encloses(&self, x: &ReceivingPoint, surface: SurfaceId) -> bool {
        if !self.solid {
            return false;
        }
        let contact = self.visibility.contact_distance();
        let origin = x.point + x.inward * self.visibility.junction_offset();
        let (u, v) = x.normal.any_orthonormal_pair();
        for turn in PROBE_TURNS {
            let lean = (u * turn.cos() + v * turn.sin()) * PROBE_LEAN;
            let d = (x.normal + lean).normalize();
            let Some(hit) =
                self.visibility
                    .closest_hit(origin, d, contact, f64::INFINITY, Some(surface))
            else {
                return false;
            };
            let facing = -self.visibility.triangle_normal(hit.triangle).dot(d);
            if self.room[hit.surface] && facing > GRAZING {
                return true;
            }
        }
        false
    }
}

/// Whether every vertex of `disc` lies inside a room: then no light can leave the scene.
pub(crate) fn closed_scene(scene: &Scene, visibility: &Visibility, disc: &Discretization) -> bool {
    let enclosures = Enclosures::new(scene, visibility);
    (0..disc.receiver_count())
        .into_par_iter()
        .all(|v| enclosures.encloses(&disc.receivers[v], disc.receiver_surface[v]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use penumbra_scenes::{Rgb, Surface};

    fn cube(flip: bool) -> Vec<Surface> {
        let c = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let faces = [
            [c(0., 0., 0.), c(0., 1., 0.), c(1., 1., 0.), c(1., 0., 0.)],
            [c(0., 0., 1.), c(1., 0., 1.), c(1., 1., 1.), c(0., 1., 1.)],
            [c(0., 0., 0.), c(1., 0., 0.), c(1., 0., 1.), c(0., 0., 1.)],
            [c(0., 1., 0.), c(0., 1., 1.), c(1., 1., 1.), c(1., 1., 0.)],
            [c(0., 0., 0.), c(0., 0., 1.), c(0., 1., 1.), c(0., 1., 0.)],
            [c(1., 0., 0.), c(1., 1., 0.), c(1., 1., 1.), c(1., 0., 1.)],
        ];
        faces
            .into_iter()
            .enumerate()
            .map(|(i, mut f)| {
                if flip {
                    f.reverse();
                }
                Surface::new(format!("f{i}"), f.to_vec(), Rgb::splat(0.5))
            })
            .collect()
    }

    #[test]
    fn a_closed_cube_is_found_with_its_orientation() {
        for (flip, sign) in [(false, 1.0), (true, -1.0)] {
            let mut scene = penumbra_scenes::builtin::textbook();
            let before = scene.surfaces.len();
            scene.surfaces.extend(cube(flip));
            let found = closed_solid_signs(&scene);
            assert!(found[..before].iter().all(Option::is_none));
            assert!(
                found[before..].iter().all(|&o| o == Some(sign)),
                "{found:?}"
            );
            // Outward normals point away from the centre.
            for (s, o) in scene.surfaces[before..].iter().zip(&found[before..]) {
                let outward = s.normal() * o.unwrap_or(0.0);
                let centre = DVec3::splat(0.5);
                assert!(outward.dot(s.polygon[0] - centre) > 0.0);
            }
        }
    }

    #[test]
    fn an_open_box_or_an_inconsistent_one_is_not_closed() {
        let mut open = penumbra_scenes::builtin::textbook();
        let mut faces = cube(false);
        faces.pop();
        open.surfaces.extend(faces);
        assert!(closed_solid_signs(&open).iter().all(Option::is_none));

        let mut inconsistent = penumbra_scenes::builtin::textbook();
        let mut faces = cube(false);
        faces[2].polygon.reverse();
        inconsistent.surfaces.extend(faces);
        assert!(
            closed_solid_signs(&inconsistent)
                .iter()
                .all(Option::is_none)
        );
    }

    /// A point on a receiver, facing `normal`, inside its surface.
    fn at(point: DVec3, normal: DVec3) -> ReceivingPoint {
        ReceivingPoint::interior(point, normal)
    }

    #[test]
    fn a_room_encloses_what_is_in_it_and_an_open_or_mixed_one_does_not() {
        let room = |open: bool, lone: bool| {
            let mut scene = penumbra_scenes::builtin::closed_box(DVec3::splat(4.0), 0.0, 0.5);
            if open {
                scene.surfaces.pop();
            }
            // A closed block in the room, faces out.
            for (i, mut f) in cube(false).into_iter().enumerate() {
                f.polygon = f.polygon.iter().map(|&p| p + DVec3::splat(1.0)).collect();
                f.name = format!("block{i}");
                scene.surfaces.push(f);
            }
            if lone {
                let c = |x: f64, y: f64| DVec3::new(x, y, 3.0);
                scene.surfaces.push(Surface::new(
                    "lamp",
                    vec![c(3.0, 3.0), c(3.5, 3.0), c(3.5, 3.5), c(3.0, 3.5)],
                    Rgb::ZERO,
                ));
            }
            scene
        };
        let floor_point = at(DVec3::new(3.0, 0.5, 0.0), DVec3::Z);
        let block_top = at(DVec3::new(1.5, 1.5, 2.0), DVec3::Z);
        let ids = |scene: &Scene| {
            let id = |name: &str| scene.surface_id(name).expect("surface");
            (id("floor"), id("block1"))
        };
        let closed = room(false, false);
        let (floor, top) = ids(&closed);
        let vis = Visibility::build(&closed);
        let enclosures = Enclosures::new(&closed, &vis);
        assert!(enclosures.encloses(&floor_point, floor));
        assert!(enclosures.encloses(&block_top, top));
        // Inside the block, looking at its backs: not in a room of its own.
        let inside_block = at(DVec3::new(1.5, 1.5, 1.0), DVec3::Z);
        assert!(!enclosures.encloses(&inside_block, floor));
        // A face taken away opens the room; a lone polygon in it may show its black back.
        for scene in [room(true, false), room(false, true)] {
            let (floor, top) = ids(&scene);
            let vis = Visibility::build(&scene);
            let enclosures = Enclosures::new(&scene, &vis);
            assert!(!enclosures.encloses(&floor_point, floor));
            assert!(!enclosures.encloses(&block_top, top));
        }
    }
}
