//! A surface's mesh does not depend on the corner its vertex list starts at: every cyclic
//! rotation of the list gives the same mesh up to labels (the same triangles, in any order, with
//! their vertices numbered in any order), and every surface gets triangles in proportion to its
//! area, whichever corner it starts at.
//!
//! A polygon with a rotational symmetry (a rectangle, a square) looks the same from several
//! corners, and its meshes from two rotations of its list may be the same mesh turned by that
//! symmetry: no rule can pick one of those corners both independently of the list and so that a
//! turned scene keeps its meshes to the bit, which the solver's invariance tests hold it to.
//! Where discontinuity segments tell the corners apart, they pick one.
//!
//! Once a triangle stayed a single element at any budget when its list started at one corner
//! and got its share from another: each surface's frame started at its list's first vertex, and
//! in the frame of one corner the circumcenter of the triangle's right angle (the midpoint of its
//! hypotenuse) rounded to just outside it, where spade's refinement skips a face. Triangulated
//! (split-quad) input is full of such triangles. A sliver (an obtuse needle) stayed whole at
//! small budgets too, from any corner.

use glam::{DAffine3, DQuat, DVec3};
use penumbra_meshing::DEFAULT_PENUMBRA_DENSITY;
use penumbra_meshing::discontinuity::{DiscontinuityOptions, find_discontinuities};
use penumbra_meshing::{SceneMesh, SurfaceMesh, mesh_scene_discontinuity, mesh_scene_uniform};
use penumbra_scenes::SplitMix64;
use penumbra_scenes::{Rgb, Scene, Surface, Visibility, builtin};

/// Meshes of two rotations may differ by this much, relative to the surface's diameter (lengths)
/// or its square (areas): rounding, not a different triangle.
const SAME_MESH_TOLERANCE: f64 = 1e-9;

/// A surface's meshes get at least this share of their part of the budget (budget times the
/// surface's area over the scene's), and never more than all of it.
const LEAST_SHARE: f64 = 0.5;

/// Surfaces whose part of the budget is smaller than this are not held to [`LEAST_SHARE`]: the
/// polygon's own triangulation may already be most of it.
const SMALLEST_CHECKED_SHARE: f64 = 20.0;

fn rotated(polygon: &[DVec3], k: usize) -> Vec<DVec3> {
    let n = polygon.len();
    (0..n).map(|i| polygon[(i + k) % n]).collect()
}

fn scene_of(surfaces: Vec<Surface>) -> Scene {
    Scene {
        up: None,
        unit: None,
        name: "rotations".into(),
        camera: None,
        surfaces,
    }
}

fn diameter(points: &[DVec3]) -> f64 {
    penumbra_scenes::polygon::diameter(points)
}

/// A mesh up to labels: its triangles' areas, its triangles' centroids and its vertices.
struct Shape {
    areas: Vec<f64>,
    centroids: Vec<DVec3>,
    vertices: Vec<DVec3>,
}

impl Shape {
    fn of(mesh: &SurfaceMesh) -> Shape {
        let corners = |t: &[u32; 3]| t.map(|i| mesh.points3[i as usize]);
        let mut areas: Vec<f64> = mesh
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = corners(t);
                0.5 * (b - a).cross(c - a).length()
            })
            .collect();
        areas.sort_by(f64::total_cmp);
        Shape {
            areas,
            centroids: mesh
                .triangles
                .iter()
                .map(|t| corners(t).iter().sum::<DVec3>() / 3.0)
                .collect(),
            vertices: mesh.points3.clone(),
        }
    }

    fn turned(self, turn: &DAffine3) -> Shape {
        let map = |points: Vec<DVec3>| points.iter().map(|&p| turn.transform_point3(p)).collect();
        Shape {
            areas: self.areas,
            centroids: map(self.centroids),
            vertices: map(self.vertices),
        }
    }

    /// Why `self` and `other` are not the same mesh of a surface of diameter `size`, if they
    /// are not.
    fn difference(&self, other: &Shape, size: f64) -> Option<String> {
        if self.areas.len() != other.areas.len() {
            return Some(format!(
                "{} triangles against {}",
                self.areas.len(),
                other.areas.len()
            ));
        }
        let (tol, area_tol) = (
            SAME_MESH_TOLERANCE * size,
            SAME_MESH_TOLERANCE * size * size,
        );
        if let Some((a, b)) = self
            .areas
            .iter()
            .zip(&other.areas)
            .find(|(a, b)| (*a - *b).abs() > area_tol)
        {
            return Some(format!("triangle areas {a} and {b}"));
        }
        unmatched(&self.centroids, &other.centroids, tol)
            .map(|p| format!("no triangle centroid near {p}"))
            .or_else(|| {
                unmatched(&self.vertices, &other.vertices, tol)
                    .map(|p| format!("no vertex near {p}"))
            })
    }
}

/// A point of `a` with no partner in `b` within `tol`, each point of `b` partnering one of `a`;
/// `a` and `b` have the same length.
fn unmatched(a: &[DVec3], b: &[DVec3], tol: f64) -> Option<DVec3> {
    if a.len() != b.len() {
        return a.first().copied().or(Some(DVec3::NAN));
    }
    let mut b: Vec<(DVec3, bool)> = b.iter().map(|&p| (p, false)).collect();
    b.sort_by(|p, q| p.0.x.total_cmp(&q.0.x));
    for &p in a {
        let start = b.partition_point(|q| q.0.x < p.x - tol);
        let partner = b[start..]
            .iter_mut()
            .take_while(|q| q.0.x <= p.x + tol)
            .find(|q| !q.1 && q.0.distance(p) <= tol);
        match partner {
            Some(q) => q.1 = true,
            None => return Some(p),
        }
    }
    None
}

/// The turns about its centroid that map a polygon onto itself, corner to corner (the identity
/// among them), to `SAME_MESH_TOLERANCE` of its size.
fn symmetries(polygon: &[DVec3]) -> Vec<DAffine3> {
    let n = polygon.len();
    let size = diameter(polygon);
    let centroid = polygon.iter().sum::<DVec3>() / n as f64;
    let normal = penumbra_scenes::polygon::newell_normal(polygon).normalize();
    (0..n)
        .map(|shift| {
            let (a, b) = (polygon[0] - centroid, polygon[shift] - centroid);
            let angle = normal.dot(a.cross(b)).atan2(a.dot(b));
            DAffine3::from_translation(centroid)
                * DAffine3::from_quat(DQuat::from_axis_angle(normal, angle))
                * DAffine3::from_translation(-centroid)
        })
        .enumerate()
        .filter(|(shift, turn)| {
            (0..n).all(|i| {
                turn.transform_point3(polygon[i])
                    .distance(polygon[(i + shift) % n])
                    <= SAME_MESH_TOLERANCE * size
            })
        })
        .map(|(_, turn)| turn)
        .collect()
}

/// Asserts that every surface of `mesh` has the same shape as in `reference`, up to the
/// surface's own symmetry.
fn assert_same_meshes(scene: &Scene, reference: &SceneMesh, mesh: &SceneMesh, what: &str) {
    for (s, surface) in scene.surfaces.iter().enumerate() {
        let size = diameter(&surface.polygon);
        let b = Shape::of(&mesh.surfaces[s]);
        let turns = symmetries(&surface.polygon);
        let differences: Vec<String> = turns
            .iter()
            .filter_map(|turn| {
                Shape::of(&reference.surfaces[s])
                    .turned(turn)
                    .difference(&b, size)
            })
            .collect();
        // The first turn is the identity, and its difference the one worth reading.
        assert!(
            differences.len() < turns.len(),
            "{what}, surface {s} ({}): {}",
            surface.name,
            differences[0]
        );
    }
}

/// A random rigid placement of a polygon given in the plane z = 0.
fn placed(rng: &mut SplitMix64, flat: &[DVec3], size: f64) -> Vec<DVec3> {
    let mut angle = || (rng.next_f64() * 2.0 - 1.0) * std::f64::consts::PI;
    let turn = DQuat::from_euler(glam::EulerRot::ZXY, angle(), angle(), angle());
    let shift = DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * 10.0 * size;
    flat.iter().map(|&p| turn * (p * size) + shift).collect()
}

/// Triangles of every kind split-quad and hand-made input holds: generic, right (half of a
/// rectangle), slivers (an obtuse needle a thousandth as high as long), obtuse, and thin and
/// obtuse, at sizes from 1e-4 to 1e4.
fn random_triangle(rng: &mut SplitMix64, case: u64) -> Vec<DVec3> {
    let mut r = || rng.next_f64();
    let (w, h) = (0.2 + r(), 0.2 + r());
    let flat = match case % 5 {
        0 => vec![
            DVec3::ZERO,
            DVec3::new(w, 0.0, 0.0),
            DVec3::new(r() * w, h, 0.0),
        ],
        1 => vec![DVec3::ZERO, DVec3::new(w, 0.0, 0.0), DVec3::new(w, h, 0.0)],
        2 => vec![
            DVec3::ZERO,
            DVec3::new(w, 0.0, 0.0),
            DVec3::new(r() * w, 1e-3 * h, 0.0),
        ],
        3 => vec![
            DVec3::ZERO,
            DVec3::new(w, 0.0, 0.0),
            DVec3::new(-(0.5 + r()) * w, 0.3 * h, 0.0),
        ],
        _ => vec![
            DVec3::ZERO,
            DVec3::new(w, 0.0, 0.0),
            DVec3::new(w * (1.0 + 2.0 * r()), 0.05 * h, 0.0),
        ],
    };
    let size = 10f64.powf(8.0 * r() - 4.0);
    placed(rng, &flat, size)
}

/// Quads (rectangles, squares, random convex ones) and non-convex polygons.
fn random_polygon(rng: &mut SplitMix64, case: u64) -> Vec<DVec3> {
    let v = |x: f64, y: f64| DVec3::new(x, y, 0.0);
    let flat = match case % 5 {
        0 => vec![v(0.0, 0.0), v(1.0, 0.0), v(1.0, 1.0), v(0.0, 1.0)],
        1 => {
            let (w, h) = (0.1 + rng.next_f64(), 0.1 + rng.next_f64());
            vec![v(0.0, 0.0), v(w, 0.0), v(w, h), v(0.0, h)]
        }
        2 => {
            // Four points on an ellipse, counter-clockwise: convex.
            let mut angles: Vec<f64> = (0..4)
                .map(|k| (k as f64 + 0.8 * rng.next_f64()) * std::f64::consts::FRAC_PI_2)
                .collect();
            angles.sort_by(f64::total_cmp);
            let ratio = 0.2 + rng.next_f64();
            angles.iter().map(|a| v(a.cos(), ratio * a.sin())).collect()
        }
        3 => vec![
            v(-1.0, -1.0),
            v(1.0, -1.0),
            v(1.0, 0.0),
            v(0.0, 0.0),
            v(0.0, 1.0),
            v(-1.0, 1.0),
        ],
        _ => vec![
            // An arrow: a reflex corner at the notch and a sharp tip.
            v(0.0, 0.0),
            v(2.0, 0.3),
            v(0.0, 0.6),
            v(0.5, 0.3),
        ],
    };
    let size = 10f64.powf(6.0 * rng.next_f64() - 3.0);
    placed(rng, &flat, size)
}

fn assert_rotations_mesh_alike(polygon: &[DVec3], budget: usize, what: &str) {
    let mesh_of = |p: Vec<DVec3>| {
        let scene = scene_of(vec![Surface::new("s", p, Rgb::splat(0.5))]);
        let mesh = mesh_scene_uniform(&scene, budget).unwrap_or_else(|e| panic!("{what}: {e}"));
        mesh.sanity_check()
            .unwrap_or_else(|e| panic!("{what}: {e}"));
        (scene, mesh)
    };
    let (scene, reference) = mesh_of(polygon.to_vec());
    let count = reference.triangle_count();
    assert!(
        count as f64 >= LEAST_SHARE * budget as f64 && count <= budget,
        "{what}: {count} triangles for a budget of {budget}: {polygon:?}"
    );
    for k in 1..polygon.len() {
        let (_, mesh) = mesh_of(rotated(polygon, k));
        assert_same_meshes(&scene, &reference, &mesh, &format!("{what}, rotation {k}"));
    }
}

#[test]
fn rotated_triangles_mesh_alike() {
    for case in 0..60u64 {
        let mut rng = SplitMix64::new(0x7121 + case);
        let triangle = random_triangle(&mut rng, case);
        let budget = 60 + (rng.next_f64() * 500.0) as usize;
        assert_rotations_mesh_alike(&triangle, budget, &format!("triangle case {case}"));
    }
}

/// The ceiling that kept one triangle when its list started at its right angle.
#[test]
fn right_triangle_starting_at_its_right_angle() {
    let triangle = [
        DVec3::new(-1.02, -0.99, 1.99),
        DVec3::new(-1.02, 1.04, 1.99),
        DVec3::new(1.0, 1.04, 1.99),
    ];
    for budget in [10, 100, 1000, 3000] {
        assert_rotations_mesh_alike(&triangle, budget, &format!("budget {budget}"));
    }
}

#[test]
fn rotated_quads_and_non_convex_polygons_mesh_alike() {
    for case in 0..30u64 {
        let mut rng = SplitMix64::new(0x9aad + case);
        let polygon = random_polygon(&mut rng, case);
        let budget = 100 + (rng.next_f64() * 500.0) as usize;
        assert_rotations_mesh_alike(&polygon, budget, &format!("polygon case {case}"));
    }
}

/// A light over a tilted triangular blocker, a floor split into two right triangles, and a
/// rectangular wall (symmetric) with a triangular shelf casting a shadow on it (not symmetric).
fn shadow_scene() -> Scene {
    let v = DVec3::new;
    let mut light = vec![
        v(-0.4, -0.3, 2.0),
        v(0.4, -0.3, 2.0),
        v(0.4, 0.3, 2.0),
        v(-0.4, 0.3, 2.0),
    ];
    light.reverse();
    scene_of(vec![
        Surface::new("light", light, Rgb::ZERO).with_emission(Rgb::splat(5.0)),
        Surface::new(
            "blocker",
            vec![v(-0.3, -0.2, 1.0), v(0.35, -0.1, 1.1), v(0.0, 0.4, 0.9)],
            Rgb::splat(0.5),
        ),
        Surface::new(
            "floor-a",
            vec![v(-2.0, -2.0, 0.0), v(2.0, -2.0, 0.0), v(2.0, 2.0, 0.0)],
            Rgb::splat(0.7),
        ),
        Surface::new(
            "floor-b",
            vec![v(-2.0, -2.0, 0.0), v(2.0, 2.0, 0.0), v(-2.0, 2.0, 0.0)],
            Rgb::splat(0.7),
        ),
        Surface::new(
            "wall",
            vec![
                v(-2.0, 2.0, 0.0),
                v(2.0, 2.0, 0.0),
                v(2.0, 2.0, 2.5),
                v(-2.0, 2.0, 2.5),
            ],
            Rgb::splat(0.6),
        ),
        Surface::new(
            "shelf",
            vec![v(0.2, 1.3, 1.0), v(1.1, 1.5, 1.05), v(0.9, 1.95, 1.1)],
            Rgb::splat(0.5),
        ),
    ])
}

fn discontinuity_mesh(scene: &Scene, budget: usize) -> SceneMesh {
    let visibility = Visibility::build(scene);
    let found = find_discontinuities(scene, &visibility, &DiscontinuityOptions::default());
    let mesh =
        mesh_scene_discontinuity(scene, &visibility, found, budget, DEFAULT_PENUMBRA_DENSITY)
            .expect("the scene meshes");
    mesh.sanity_check().expect("sane meshes");
    mesh
}

#[test]
fn rotated_surfaces_get_the_same_discontinuity_meshes() {
    for (scene, budget) in [(shadow_scene(), 4000), (builtin::textbook(), 3000)] {
        let reference = discontinuity_mesh(&scene, budget);
        assert!(reference.segment_count() > 0, "{}: no shadows", scene.name);
        for s in 0..scene.surfaces.len() {
            for k in 1..scene.surfaces[s].polygon.len() {
                let mut turned = scene.clone();
                turned.surfaces[s].polygon = rotated(&scene.surfaces[s].polygon, k);
                let mesh = discontinuity_mesh(&turned, budget);
                let what = format!("{}: surface {s} rotated by {k}", scene.name);
                assert_eq!(mesh.segment_count(), reference.segment_count(), "{what}");
                assert_same_meshes(&scene, &reference, &mesh, &what);
            }
        }
    }
}

/// A floor of rectangles of random sizes, each split along a random diagonal into two right
/// triangles whose lists start at random corners, with a few whole rectangles among them.
fn split_quad_floor(rng: &mut SplitMix64) -> Scene {
    let mut surfaces = Vec::new();
    let widths: Vec<f64> = (0..8).map(|_| 0.3 + 2.0 * rng.next_f64()).collect();
    let (mut y, mut x);
    y = 0.0;
    for row in 0..8 {
        let depth = 0.3 + 2.0 * rng.next_f64();
        x = 0.0;
        for (column, &w) in widths.iter().enumerate() {
            let c = [
                DVec3::new(x, y, 0.0),
                DVec3::new(x + w, y, 0.0),
                DVec3::new(x + w, y + depth, 0.0),
                DVec3::new(x, y + depth, 0.0),
            ];
            let name = format!("r{row}c{column}");
            let mut add = |polygon: Vec<DVec3>, rng: &mut SplitMix64, part: &str| {
                let k = (rng.next_f64() * polygon.len() as f64) as usize;
                surfaces.push(Surface::new(
                    format!("{name}{part}"),
                    rotated(&polygon, k),
                    Rgb::splat(0.5),
                ));
            };
            match (row + column) % 5 {
                0 => add(c.to_vec(), rng, ""),
                1 | 3 => {
                    add(vec![c[0], c[1], c[2]], rng, "a");
                    add(vec![c[0], c[2], c[3]], rng, "b");
                }
                _ => {
                    add(vec![c[0], c[1], c[3]], rng, "a");
                    add(vec![c[1], c[2], c[3]], rng, "b");
                }
            }
            x += w;
        }
        y += depth;
    }
    scene_of(surfaces)
}

#[test]
fn triangles_follow_area_whatever_the_first_corner() {
    for seed in 0..3u64 {
        let mut rng = SplitMix64::new(0x5eed + seed);
        let scene = split_quad_floor(&mut rng);
        let total = scene.total_area();
        for budget in [2_000, 20_000] {
            let mesh = mesh_scene_uniform(&scene, budget).expect("the floor meshes");
            mesh.sanity_check().expect("sane meshes");
            for (surface, m) in scene.surfaces.iter().zip(&mesh.surfaces) {
                let share = budget as f64 * surface.area() / total;
                let count = m.triangle_count() as f64;
                assert!(
                    count <= share.max(surface.polygon.len() as f64 - 2.0),
                    "seed {seed}, budget {budget}, {}: {count} triangles for a share of {share:.1}",
                    surface.name
                );
                if share >= SMALLEST_CHECKED_SHARE {
                    assert!(
                        count >= LEAST_SHARE * share,
                        "seed {seed}, budget {budget}, {}: {count} triangles for a share of \
                         {share:.1}",
                        surface.name
                    );
                }
            }
        }
    }
}
