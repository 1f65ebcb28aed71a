//! The exact direct light does not depend on how finely the occluders are tessellated, and its
//! two ways of subtracting shadows (one by one, or all at once by a polygon difference) agree.

use glam::DVec3;
use penumbra_scenes::SplitMix64;
use penumbra_scenes::tessellated::tessellated;
use penumbra_scenes::{Scene, Visibility, builtin};
use penumbra_solver::{DirectLight, ReceivingPoint};

/// Seeded points on the floor (z = 0) within `half` of the origin, facing up.
fn floor_points(count: usize, half: f64, seed: u64) -> Vec<ReceivingPoint> {
    let mut rng = SplitMix64::new(seed);
    (0..count)
        .map(|_| {
            let (x, y) = (rng.next_f64(), rng.next_f64());
            ReceivingPoint::interior(
                DVec3::new(half * (2.0 * x - 1.0), half * (2.0 * y - 1.0), 0.0),
                DVec3::Z,
            )
        })
        .collect()
}

fn floor_irradiance(scene: &Scene, points: &[ReceivingPoint], sequential: usize) -> Vec<f64> {
    let vis = Visibility::build(scene);
    let direct = DirectLight::new(scene, &vis).with_sequential_shadows(sequential);
    let floor = scene.surface_id("floor").expect("a floor");
    points
        .iter()
        .map(|x| direct.irradiance(x, floor).r)
        .collect()
}

/// The L prism as 8 polygons and as 20, 180 and 1,280 triangles casts the same light on the
/// floor, to 10⁻⁹ of the largest value, in its umbra, penumbra and around it.
#[test]
fn tessellated_occluders_cast_the_same_light_as_their_polygons() {
    let points = floor_points(400, 2.0, 7);
    let solid = floor_irradiance(&tessellated(0), &points, usize::MAX);
    let peak = solid.iter().copied().fold(0.0, f64::max);
    let lit = solid.iter().filter(|&&h| h == peak).count();
    let dark = solid.iter().filter(|&&h| h < 0.5 * peak).count();
    assert!(
        dark > 20 && solid.len() - lit > 100,
        "the points must cross the shadow"
    );
    for n in [1, 3, 8] {
        let fine = floor_irradiance(
            &tessellated(n),
            &points,
            penumbra_solver::SEQUENTIAL_SHADOWS,
        );
        let worst = solid
            .iter()
            .zip(&fine)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(
            worst <= 1e-9 * peak,
            "tessellated-{n}: off by {worst:e} (peak {peak})"
        );
    }
}

/// Subtracting shadows one by one and all at once give the same light, on scenes with many
/// occluders per shaft.
#[test]
fn one_by_one_and_all_at_once_agree() {
    for (scene, half) in [
        (tessellated(3), 2.0),
        (builtin::builtin("boxworld-60").expect("built in"), 9.0),
    ] {
        let points = floor_points(300, half, 11);
        let one_by_one = floor_irradiance(&scene, &points, usize::MAX);
        let at_once = floor_irradiance(&scene, &points, 0);
        let peak = one_by_one.iter().copied().fold(0.0, f64::max);
        for (k, (a, b)) in one_by_one.iter().zip(&at_once).enumerate() {
            assert!(
                (a - b).abs() <= 1e-12 * peak,
                "{} at {}: {a} one by one, {b} at once",
                scene.name,
                points[k].point
            );
        }
    }
}

/// Receivers that share a point (the faces of the prism meeting at a vertex) get from the
/// shared evaluation what each gets on its own, with and without other faces touching them,
/// and exactly what each gets in a group of its own at that point (a sharded run has only its
/// own surfaces' vertices).
#[test]
fn receivers_at_one_point_share_work_without_changing_it() {
    use penumbra_solver::Discretization;
    use std::collections::BTreeMap;
    for scene in [tessellated(3), tessellated(6)] {
        let vis = Visibility::build(&scene);
        let direct = DirectLight::new(&scene, &vis);
        // Shared whatever the number of occluders, against each receiver on its own.
        let shared_always = DirectLight::new(&scene, &vis).with_sequential_shadows(0);
        let mesh = penumbra_meshing::mesh_scene_uniform(&scene, 4000).expect("meshes");
        let disc = Discretization::new(&scene, &mesh, 24);
        let mut at_point: BTreeMap<[u64; 3], Vec<usize>> = BTreeMap::new();
        for (v, x) in disc.receivers.iter().enumerate() {
            let p = x.point;
            at_point
                .entry([p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
                .or_default()
                .push(v);
        }
        let shared: Vec<&Vec<usize>> = at_point.values().filter(|g| g.len() > 1).collect();
        assert!(shared.len() > 50, "the prism's vertices are shared");
        let (mut worst, mut peak, mut lit) = (0.0f64, 0.0f64, 0);
        for group in shared {
            let members: Vec<(ReceivingPoint, usize)> = group
                .iter()
                .map(|&v| (disc.receivers[v], disc.receiver_surface[v]))
                .collect();
            let at = members[0].0.point;
            let together = shared_always.irradiance_group(at, &members);
            for (member, h) in members.iter().zip(&together) {
                let single = shared_always.irradiance_group(at, std::slice::from_ref(member));
                assert_eq!(single[0], *h, "a receiver's value depends on its group");
                let (x, r) = member;
                let alone = direct.irradiance(x, *r);
                worst = worst.max((alone.r - h.r).abs());
                peak = peak.max(alone.r);
                lit += usize::from(alone.r > 0.0);
            }
        }
        assert!(lit > 50, "enough lit receivers to compare");
        assert!(
            worst <= 1e-12 * peak,
            "{}: off by {worst:e} of {peak}",
            scene.name
        );
    }
}

/// A bumpy blob (a closed welded solid of 1,280 triangles with folds and overhangs) under a
/// square light: at each of its corners, the faces meeting there get from the shared view at
/// the grid point they round to what each gets on its own, to 10⁻⁹ of the largest value. Faces
/// through the point that a shaft's side only grazes there are still the faces through it; the
/// whole mesh lit at once, one evaluation a point, gives each face the same.
#[test]
fn the_faces_at_a_blob_corner_share_their_view_exactly() {
    use penumbra_scenes::Surface;
    use penumbra_scenes::tessellated::bumpy_blob;
    use penumbra_solver::Discretization;
    let mut scene = tessellated(0);
    scene.surfaces.retain(|s| !s.name.starts_with("prism"));
    let grey = penumbra_scenes::Rgb::splat(0.6);
    for (i, t) in bumpy_blob(DVec3::new(0.1, -0.1, 1.3), 0.45, 3)
        .into_iter()
        .enumerate()
    {
        scene
            .surfaces
            .push(Surface::new(format!("blob/{i}"), t.to_vec(), grey));
    }
    let vis = Visibility::build(&scene);
    let direct = DirectLight::new(&scene, &vis);
    // Shared whatever the number of occluders.
    let shared = DirectLight::new(&scene, &vis).with_sequential_shadows(0);
    let least = penumbra_meshing::polygon_minimum(&scene);
    let mesh = penumbra_meshing::mesh_scene_uniform(&scene, least).expect("meshes");
    let disc = Discretization::new(&scene, &mesh, 24);
    // Grouped as the solver groups them: by the grid point they round to.
    let receivers: Vec<(ReceivingPoint, usize)> = (0..disc.receivers.len())
        .map(|v| (disc.receivers[v], disc.receiver_surface[v]))
        .collect();
    let groups = penumbra_solver::shared_points(
        receivers.iter().map(|(x, _)| x.point),
        direct.scene_diagonal(),
    );
    assert!(groups.len() < receivers.len() / 2, "the corners are shared");
    let (all, evaluated) = penumbra_solver::irradiance_shared(&shared, &receivers);
    assert_eq!(evaluated, groups.len());
    let (mut worst, mut peak, mut lit) = (0.0f64, 0.0f64, 0);
    for (at, group) in groups.iter().filter(|(_, g)| g.len() > 2) {
        let members: Vec<(ReceivingPoint, usize)> = group.iter().map(|&v| receivers[v]).collect();
        for ((&v, (x, r)), h) in group
            .iter()
            .zip(&members)
            .zip(shared.irradiance_group(*at, &members))
        {
            assert_eq!(
                all[v], h,
                "the shared evaluation of the whole mesh gives each its own"
            );
            let alone = direct.irradiance(x, *r);
            worst = worst.max((alone.r - h.r).abs());
            peak = peak.max(alone.r);
            lit += usize::from(alone.r > 0.0);
        }
    }
    assert!(lit > 500, "{lit} lit receivers");
    assert!(worst <= 1e-9 * peak, "off by {worst:e} of {peak}");
}

/// Seeded points inside the floor of `scene` (a quadrilateral: its parallelogram from the first
/// corner, kept off the edges), facing into the room.
fn points_on_floor(scene: &Scene, count: usize, seed: u64) -> Vec<ReceivingPoint> {
    let floor = &scene.surfaces[scene.surface_id("floor").expect("a floor")];
    let p = &floor.polygon;
    let mut rng = SplitMix64::new(seed);
    (0..count)
        .map(|_| {
            let (u, w) = (0.02 + 0.96 * rng.next_f64(), 0.02 + 0.96 * rng.next_f64());
            let at = p[0] + u * (p[1] - p[0]) + w * (p[3] - p[0]);
            ReceivingPoint::interior(at, floor.normal())
        })
        .collect()
}

/// Narrowing a crowded shaft to what its largest occluders leave visible changes no value:
/// every shaft narrowed and none agree to 10⁻⁹ of the largest value, on the Cornell box, the
/// 1,280-triangle prism and a field of boxes, with all shadows subtracted at once.
#[test]
fn narrowed_shafts_change_no_value() {
    for name in ["cornell", "tessellated-8", "boxworld-60"] {
        let scene = builtin::builtin(name).expect("built in");
        let vis = Visibility::build(&scene);
        let floor = scene.surface_id("floor").expect("a floor");
        let light = |window: usize| -> Vec<f64> {
            let direct = DirectLight::new(&scene, &vis)
                .with_sequential_shadows(0)
                .with_window_faces(window);
            points_on_floor(&scene, 300, 13)
                .iter()
                .map(|x| direct.irradiance(x, floor).r)
                .collect()
        };
        let (narrowed, whole) = (light(0), light(usize::MAX));
        let peak = whole.iter().copied().fold(0.0, f64::max);
        let shaded = whole.iter().filter(|&&h| h < 0.99 * peak).count();
        assert!(shaded > 30, "{name}: the points must cross shadows");
        for (a, b) in narrowed.iter().zip(&whole) {
            assert!(
                (a - b).abs() <= 1e-9 * peak,
                "{name}: {a} narrowed, {b} whole (peak {peak})"
            );
        }
    }
}
