//! Surfaces planar only to the validation's tolerance. An OBJ exporter that writes six decimals
//! leaves a room's walls with one corner a millionth off the plane of the others: within
//! [`penumbra_scenes::PLANARITY_TOLERANCE`], so each wall loads as one polygon, but over a
//! hundred contact distances, the distance that decides which points lie on a plane. A wall's
//! mesh lies in the plane through one of its corners, so its vertices, and its neighbours'
//! along their junctions with it, are that far off the planes through its other corners.

use std::collections::BTreeMap;

use glam::{DVec2, DVec3};
use penumbra_meshing::mesh_scene_uniform;
use penumbra_scenes::{PlaneFrame, Rgb, Scene, Surface, Visibility, validate};
use penumbra_solver::{
    DirectLight, Discretization, NoProgress, ReceivingPoint, SHARED_POINT, SolverOptions,
    form_factor, solve_progressive,
};

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

/// The enclosure of `CornellBox-Normal.obj` (a Blender export, y up) as it reads: no ceiling,
/// the back and right walls off their planes by 1e-6 at a shared corner, and a 0.5 × 0.5 light
/// facing down at y = 0.99. Nothing stands in the room. The walls' lists start `turn` corners
/// on from the file's (the mesh of a polygon does not depend on where its list starts, and
/// whichever corner that is, the light must be the same).
fn exported_room(turn: usize) -> Scene {
    let light = vec![
        v(-0.25, 0.99, -0.25),
        v(0.25, 0.99, -0.25),
        v(0.25, 0.99, 0.25),
        v(-0.25, 0.99, 0.25),
    ];
    let wall = |name: &str, mut polygon: Vec<DVec3>| {
        polygon.rotate_left(turn);
        Surface::new(name, polygon, Rgb::splat(0.5))
    };
    Scene {
        up: None,
        unit: None,
        name: "exported room".into(),
        camera: None,
        surfaces: vec![
            wall(
                "back",
                vec![
                    v(1.0, 1.0, -0.999999),
                    v(-1.0, 1.0, -1.0),
                    v(-1.0, -1.0, -1.0),
                    v(1.0, -1.0, -1.0),
                ],
            ),
            wall(
                "floor",
                vec![
                    v(1.0, -1.0, -1.0),
                    v(-1.0, -1.0, -1.0),
                    v(-1.0, -1.0, 1.0),
                    v(1.0, -1.0, 1.0),
                ],
            ),
            wall(
                "left",
                vec![
                    v(-1.0, -1.0, 1.0),
                    v(-1.0, -1.0, -1.0),
                    v(-1.0, 1.0, -1.0),
                    v(-1.0, 1.0, 1.0),
                ],
            ),
            wall(
                "right",
                vec![
                    v(1.0, -1.0, -1.0),
                    v(1.0, -1.0, 1.0),
                    v(0.999999, 1.0, 1.000001),
                    v(1.0, 1.0, -0.999999),
                ],
            ),
            Surface::new("light", light, Rgb::ZERO).with_emission(Rgb::splat(10.0)),
        ],
    }
}

/// What the light gives x with nothing in the way: its exitance times Lambert's form factor to
/// the whole light, or nothing behind the light's plane.
fn unoccluded(scene: &Scene, x: &ReceivingPoint, tol: f64) -> f64 {
    let light = &scene.surfaces[scene.surface_id("light").expect("a light")];
    if x.in_front_of(light.polygon[0], light.normal(), tol) {
        light.emission.mean() * form_factor(x, &light.polygon, tol)
    } else {
        0.0
    }
}

/// A wall's mesh lies in the plane through one of its corners (which one depends on the marks
/// it carries, not on its list), a millionth away from the planes through the others. Points
/// of a wall on the plane through any of its corners, evaluated as the solver evaluates its
/// vertices (at the grid point they round to, in a group of their own), one shadow at a time or
/// all at once, get the whole light. The wall took itself for an occluder just in front of the
/// points behind the plane it was cut along, and where its shadow covered the light they got
/// none: dark stars, one vertex each, scattered over a discontinuity-meshed wall.
#[test]
fn a_nearly_planar_wall_casts_no_shadow_on_its_own_points() {
    let scene = exported_room(0);
    assert!(validate(&scene).is_empty(), "{:?}", validate(&scene));
    let vis = Visibility::build(&scene);
    let tol = vis.contact_distance();
    let evaluators = [
        ("one by one", DirectLight::new(&scene, &vis)),
        (
            "at once",
            DirectLight::new(&scene, &vis).with_sequential_shadows(0),
        ),
    ];
    let quantum = SHARED_POINT * scene.diagonal();
    let (mut worst, mut peak, mut dark) = (0.0f64, 0.0f64, Vec::new());
    for wall in ["back", "right"] {
        let s = scene.surface_id(wall).expect("the wall");
        let polygon = &scene.surfaces[s].polygon;
        for corner in 0..polygon.len() {
            let frame = PlaneFrame::of_polygon_at(polygon, corner).expect("a frame");
            let flat: Vec<DVec2> = polygon.iter().map(|&p| frame.to_2d(p)).collect();
            // A grid over the square wall, bilinear in its corners.
            for i in 1..16 {
                for j in 1..16 {
                    let (a, b) = (f64::from(i) / 16.0, f64::from(j) / 16.0);
                    let q = flat[0] * ((1.0 - a) * (1.0 - b))
                        + flat[1] * (a * (1.0 - b))
                        + flat[2] * (a * b)
                        + flat[3] * ((1.0 - a) * b);
                    let p = frame.to_3d(q);
                    let x = ReceivingPoint::interior(p, frame.normal);
                    let at = (p / quantum).round() * quantum;
                    let expected = unoccluded(&scene, &x, tol);
                    peak = peak.max(expected);
                    for (how, direct) in &evaluators {
                        let h = direct.irradiance_group(at, &[(x, s)])[0].mean();
                        let off = (h - expected).abs();
                        worst = worst.max(off);
                        if off > 1e-3 * expected {
                            dark.push((*how, wall, corner, p, h, expected));
                        }
                    }
                }
            }
        }
    }
    eprintln!("worst difference {worst:.2e} of {peak:.2e} W/m²");
    assert!(dark.is_empty(), "{} points off: {dark:?}", dark.len());
    assert!(worst <= 1e-12 * peak, "{worst:e} of {peak:e}");
}

/// In a room with nothing in it, the light reaches every point of the walls below it whole: the
/// exact direct light at every vertex, one-sided limits at the junctions included, is the
/// light's exitance times Lambert's form factor to the whole light. So it is in the direct
/// light a solve computes, and in the view a group of receivers at one point shares, whatever
/// the number of occluders. A wall that took itself for an occluder just in front of its own
/// vertices (or of its neighbour's, along their junction) left some of them black, each a dark
/// star on the rendered wall.
#[test]
fn nearly_planar_walls_cast_no_shadow_on_their_own_vertices_or_their_neighbours() {
    for turn in 0..4 {
        check_unoccluded(&exported_room(turn));
    }
}

fn check_unoccluded(scene: &Scene) {
    assert!(validate(scene).is_empty(), "{:?}", validate(scene));
    let vis = Visibility::build(scene);
    let mesh = mesh_scene_uniform(scene, 6000).expect("the room meshes");
    let options = SolverOptions {
        direct_only: true,
        ..SolverOptions::default()
    };
    let solution =
        solve_progressive(scene, &mesh, &vis, &options, &NoProgress).expect("direct light");
    let solved: Vec<Rgb> = solution.irradiance.concat();
    let disc = Discretization::new(scene, &mesh, options.elements_per_patch);

    // The view shared at the grid points the solver groups receivers by, whatever the number of
    // occluders.
    let at_once = DirectLight::new(scene, &vis).with_sequential_shadows(0);
    let quantum = SHARED_POINT * at_once.scene_diagonal();
    let mut groups: BTreeMap<[i64; 3], Vec<usize>> = BTreeMap::new();
    for (v, x) in disc.receivers.iter().enumerate() {
        let q = (x.point / quantum).round();
        groups
            .entry([q.x as i64, q.y as i64, q.z as i64])
            .or_default()
            .push(v);
    }
    let mut shared = vec![Rgb::ZERO; disc.receiver_count()];
    for (key, group) in &groups {
        let at = DVec3::new(key[0] as f64, key[1] as f64, key[2] as f64) * quantum;
        let members: Vec<_> = group
            .iter()
            .map(|&v| (disc.receivers[v], disc.receiver_surface[v]))
            .collect();
        for (&v, h) in group.iter().zip(at_once.irradiance_group(at, &members)) {
            shared[v] = h;
        }
    }

    let tol = vis.contact_distance();
    let (mut worst, mut peak, mut dark, mut checked) = (0.0f64, 0.0f64, Vec::new(), 0);
    for (v, x) in disc.receivers.iter().enumerate() {
        let s = disc.receiver_surface[v];
        if scene.surfaces[s].is_emitter() {
            continue;
        }
        let expected = unoccluded(scene, x, tol);
        peak = peak.max(expected);
        for (how, h) in [("solved", solved[v]), ("shared", shared[v])] {
            let off = (h.mean() - expected).abs();
            worst = worst.max(off);
            if off > 1e-3 * expected {
                dark.push((how, &scene.surfaces[s].name, x.point, h.mean(), expected));
            }
        }
        checked += 1;
    }
    eprintln!("{checked} vertices, worst difference {worst:.2e} of {peak:.2e} W/m²");
    assert!(dark.is_empty(), "{} values off: {dark:?}", dark.len());
    assert!(worst <= 1e-12 * peak, "{worst:e} of {peak:e}");
}
