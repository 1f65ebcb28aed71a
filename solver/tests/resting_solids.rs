//! A closed solid standing on a floor, as in every modelling program's first scene: the floor
//! under it is dark, and the face it stands on changes nothing anywhere else.

use glam::DVec3;
use penumbra_scenes::{Rgb, Scene, Surface, Visibility};
use penumbra_solver::{DirectLight, ReceivingPoint};

/// A 10 × 10 floor at z = 0 facing up, a 2 × 2 lamp at z = 4 facing down, and a cube of side 2
/// centred over the origin standing on the floor, its faces turned out; without its bottom face
/// when `bottom` is false.
fn cube_on_a_floor(bottom: bool) -> Scene {
    let v = DVec3::new;
    let quad = |c: DVec3, u: DVec3, w: DVec3| vec![c, c + u, c + u + w, c + w];
    let grey = Rgb::splat(0.5);
    let mut surfaces = vec![
        Surface::new(
            "floor",
            quad(v(-5., -5., 0.), v(10., 0., 0.), v(0., 10., 0.)),
            grey,
        ),
        Surface::new(
            "lamp",
            quad(v(-1., -1., 4.), v(0., 2., 0.), v(2., 0., 0.)),
            Rgb::ZERO,
        )
        .with_emission(Rgb::splat(10.0)),
    ];
    let (x, y, z) = (v(2., 0., 0.), v(0., 2., 0.), v(0., 0., 2.));
    let corner = v(-1., -1., 0.);
    let faces = [
        ("top", quad(corner + z, x, y)),
        ("bottom", quad(corner, y, x)),
        ("south", quad(corner, x, z)),
        ("north", quad(corner + y, z, x)),
        ("west", quad(corner, z, y)),
        ("east", quad(corner + x, y, z)),
    ];
    for (name, polygon) in faces {
        if bottom || name != "bottom" {
            surfaces.push(Surface::new(name, polygon, grey));
        }
    }
    Scene {
        name: "cube on a floor".into(),
        camera: None,
        up: None,
        unit: None,
        surfaces,
    }
}

fn floor_light(scene: &Scene, points: &[DVec3]) -> Vec<f64> {
    let visibility = Visibility::build(scene);
    let direct = DirectLight::new(scene, &visibility);
    points
        .iter()
        .map(|&p| {
            direct
                .irradiance(&ReceivingPoint::interior(p, DVec3::Z), 0)
                .r
        })
        .collect()
}

#[test]
fn the_floor_under_a_standing_cube_is_dark() {
    let closed = cube_on_a_floor(true);
    // Every face turned out, each edge shared: a closed solid, resting on the floor.
    for s in &closed.surfaces[2..] {
        let centre = s.polygon.iter().sum::<DVec3>() / s.polygon.len() as f64;
        assert!(
            s.normal().dot(centre - DVec3::new(0.0, 0.0, 1.0)) > 0.0,
            "{}",
            s.name
        );
    }
    let under: Vec<DVec3> = [(0.0, 0.0), (0.5, -0.3), (-0.9, 0.9), (0.99, 0.0)]
        .map(|(x, y)| DVec3::new(x, y, 0.0))
        .to_vec();
    for (p, h) in under.iter().zip(floor_light(&closed, &under)) {
        assert_eq!(h, 0.0, "light under the cube at {p}");
    }
    // Beside it, the bottom face (in the floor's plane) changes nothing: the open cube, which
    // no face turned away can hide, gives the same light to rounding.
    let beside: Vec<DVec3> = [
        (1.2, 0.0),
        (3.0, 2.0),
        (-1.5, -1.5),
        (0.0, 4.5),
        (1.0001, 0.3),
    ]
    .map(|(x, y)| DVec3::new(x, y, 0.0))
    .to_vec();
    let with = floor_light(&closed, &beside);
    let without = floor_light(&cube_on_a_floor(false), &beside);
    let scale = 10.0;
    for ((p, a), b) in beside.iter().zip(&with).zip(&without) {
        assert!((a - b).abs() <= 1e-9 * scale, "at {p}: {a} against {b}");
    }
    assert!(with.iter().all(|&h| h > 0.0), "{with:?}");
}
