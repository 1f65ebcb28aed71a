//! The exact direct light does not depend on how finely the occluders are tessellated, and its
//! two ways of subtracting shadows (one by one, or all at once by a polygon difference) agree.

use glam::DVec3;
use penumbra_scenes::rng::SplitMix64;
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
            penumbra_solver::direct::SEQUENTIAL_SHADOWS,
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
