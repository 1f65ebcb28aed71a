//! Built-in scenes: the measured Cornell box, the textbook penumbra scene, and a furnace.

use glam::DVec3;

use crate::color::Rgb;
use crate::model::{Camera, Scene, Surface};
use crate::polygon;

/// Names and one-line descriptions of the built-in scenes.
pub const NAMES: [(&str, &str); 11] = [
    (
        "cornell",
        "the measured Cornell box (mm): red and green walls, two white blocks, ceiling light",
    ),
    (
        "textbook",
        "unit square light at height 3, unit square blocker at height 1, a floor: closed-form penumbra",
    ),
    (
        "furnace",
        "closed unit cube, every face emitting (E = 1) and reflecting (rho = 0.5): B = E / (1 - rho)",
    ),
    (
        "furnace-l",
        "closed L-shaped room, 2 x 2 x 1 less a quarter, every face emitting (E = 1) and reflecting (rho = 0.5): B = E / (1 - rho), with occlusion",
    ),
    (
        "furnace-long",
        "closed 8 x 1 x 1 box, every face emitting (E = 1) and reflecting (rho = 0.5): B = E / (1 - rho)",
    ),
    (
        "boxworld",
        "100 boxes of random size and turn standing on a floor under a square light (seed 1); boxworld-N for N boxes",
    ),
    (
        "tessellated",
        "an L-shaped prism hanging under a square light, as 20 triangles; tessellated-N splits each into N x N (tessellated-0: its 8 polygons)",
    ),
    (
        "bars",
        "two thin bars crossing at two heights under a square light, turned against its edges: EEE events",
    ),
    (
        "cie-5.3",
        "CIE 171:2006 test case 5.3: a 1 m square source in the ceiling of a black 4 x 4 x 3 m room",
    ),
    (
        "cie-5.6",
        "CIE 171:2006 test case 5.6: a uniformly lit diffuse floor lighting black walls and ceiling",
    ),
    (
        "cie-5.8",
        "CIE 171:2006 test case 5.8: a 4 m cube reflecting 0.5, a 10,000 lm source at its centre",
    ),
];

/// The built-in scene called `name`.
pub fn builtin(name: &str) -> Option<Scene> {
    match name {
        "cornell" => Some(cornell()),
        "textbook" => Some(textbook()),
        "furnace" => Some(furnace(1.0, 0.5)),
        "furnace-l" => Some(l_room_furnace(1.0, 0.5)),
        "furnace-long" => Some(long_furnace(1.0, 0.5)),
        "boxworld" => Some(boxworld(100, 1)),
        "bars" => Some(crossed_bars()),
        "cie-5.3" => Some(crate::cie::area_source()),
        "cie-5.6" => Some(crate::cie::floor_reflection()),
        "cie-5.8" => Some(crate::cie::reflecting_cube(0.5)),
        "tessellated" => Some(crate::tessellated::tessellated(1)),
        _ => boxworld_count(name)
            .map(|count| boxworld(count, 1))
            .or_else(|| tessellation_count(name).map(crate::tessellated::tessellated)),
    }
}

/// Most boxes a `boxworld-N` name may ask for (five million polygons).
pub const MAX_BOXWORLD: usize = 1_000_000;

/// `N` from `tessellated-N`, for 0 ≤ N ≤ [`crate::tessellated::MAX_SUBDIVISIONS`].
fn tessellation_count(name: &str) -> Option<usize> {
    count_after(name, "tessellated-").filter(|&n| n <= crate::tessellated::MAX_SUBDIVISIONS)
}

/// The plain decimal number that follows `prefix` in a built-in name.
fn count_after(name: &str, prefix: &str) -> Option<usize> {
    let digits = name.strip_prefix(prefix)?;
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    digits.parse().ok()
}

/// `N` from `boxworld-N`, for 1 ≤ N ≤ [`MAX_BOXWORLD`].
fn boxworld_count(name: &str) -> Option<usize> {
    count_after(name, "boxworld-").filter(|n| (1..=MAX_BOXWORLD).contains(n))
}

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

/// A camera at `eye` looking at `target`, z up, with a vertical field of view of `fov_deg`.
fn upright(eye: DVec3, target: DVec3, fov_deg: f64) -> Option<Camera> {
    Some(Camera {
        eye,
        target,
        up: DVec3::Z,
        fov_deg,
    })
}

/// Reverses `polygon` if needed so that its front faces `toward` (or away, if `outward`).
fn facing(mut polygon: Vec<DVec3>, point: DVec3, outward: bool) -> Vec<DVec3> {
    let n = polygon::newell_normal(&polygon);
    let to_point = point - polygon::centroid(&polygon);
    if (n.dot(to_point) < 0.0) != outward {
        polygon.reverse();
    }
    polygon
}

/// The Cornell box as measured (<https://www.graphics.cornell.edu/online/box/data.html>), in mm.
///
/// The red wall's measured corners are 3 mm off a plane, so it is split into two triangles. The
/// light is lowered 0.1 mm below the ceiling so that the two do not share a plane. The blocks are
/// their five visible faces.
pub fn cornell() -> Scene {
    let white = Rgb::splat(0.73);
    let mut surfaces = cornell_room(white);
    let short_top = [
        v(130.0, 165.0, 65.0),
        v(82.0, 165.0, 225.0),
        v(240.0, 165.0, 272.0),
        v(290.0, 165.0, 114.0),
    ];
    let tall_top = [
        v(423.0, 330.0, 247.0),
        v(265.0, 330.0, 296.0),
        v(314.0, 330.0, 456.0),
        v(472.0, 330.0, 406.0),
    ];
    for (block, top) in [("short_block", short_top), ("tall_block", tall_top)] {
        surfaces.extend(cornell_block(block, top, white));
    }
    Scene {
        up: None,
        unit: None,
        name: "cornell".into(),
        camera: Some(Camera {
            eye: v(278.0, 273.0, -800.0),
            target: v(278.0, 273.0, 0.0),
            up: v(0.0, 1.0, 0.0),
            // 35 mm focal length on a 25 mm film.
            fov_deg: 2.0 * (12.5f64 / 35.0).atan().to_degrees(),
        }),
        surfaces,
    }
}

/// The Cornell box's room: floor, ceiling, the three walls and the light, all facing inside.
fn cornell_room(white: Rgb) -> Vec<Surface> {
    let red = Rgb::new(0.63, 0.065, 0.05);
    let green = Rgb::new(0.14, 0.45, 0.091);
    let inside = v(278.0, 274.4, 279.6);
    let wall =
        |name: &str, p: Vec<DVec3>, rho: Rgb| Surface::new(name, facing(p, inside, false), rho);
    vec![
        wall(
            "floor",
            vec![
                v(552.8, 0.0, 0.0),
                v(0.0, 0.0, 0.0),
                v(0.0, 0.0, 559.2),
                v(549.6, 0.0, 559.2),
            ],
            white,
        ),
        wall(
            "ceiling",
            vec![
                v(556.0, 548.8, 0.0),
                v(556.0, 548.8, 559.2),
                v(0.0, 548.8, 559.2),
                v(0.0, 548.8, 0.0),
            ],
            white,
        ),
        wall(
            "back_wall",
            vec![
                v(549.6, 0.0, 559.2),
                v(0.0, 0.0, 559.2),
                v(0.0, 548.8, 559.2),
                v(556.0, 548.8, 559.2),
            ],
            white,
        ),
        wall(
            "green_wall",
            vec![
                v(0.0, 0.0, 559.2),
                v(0.0, 0.0, 0.0),
                v(0.0, 548.8, 0.0),
                v(0.0, 548.8, 559.2),
            ],
            green,
        ),
        // The measured red wall is not planar: split along the diagonal 0-2.
        wall(
            "red_wall_low",
            vec![
                v(552.8, 0.0, 0.0),
                v(549.6, 0.0, 559.2),
                v(556.0, 548.8, 559.2),
            ],
            red,
        ),
        wall(
            "red_wall_high",
            vec![
                v(552.8, 0.0, 0.0),
                v(556.0, 548.8, 559.2),
                v(556.0, 548.8, 0.0),
            ],
            red,
        ),
        wall(
            "light",
            vec![
                v(343.0, 548.7, 227.0),
                v(343.0, 548.7, 332.0),
                v(213.0, 548.7, 332.0),
                v(213.0, 548.7, 227.0),
            ],
            Rgb::splat(0.78),
        )
        .with_emission(Rgb::new(57.8, 49.0, 25.1)),
    ]
}

/// A Cornell box block standing on the floor under its measured `top`: the top and four sides,
/// facing out from a point inside the block.
fn cornell_block(block: &str, top: [DVec3; 4], white: Rgb) -> Vec<Surface> {
    let center = polygon::centroid(&top) * DVec3::new(1.0, 0.5, 1.0);
    let mut surfaces = vec![Surface::new(
        format!("{block}_top"),
        facing(top.to_vec(), center, true),
        white,
    )];
    for i in 0..4 {
        let (a, b) = (top[i], top[(i + 1) % 4]);
        let side = vec![v(a.x, 0.0, a.z), v(b.x, 0.0, b.z), b, a];
        surfaces.push(Surface::new(
            format!("{block}_side{i}"),
            facing(side, center, true),
            white,
        ));
    }
    surfaces
}

/// `docs/closed-forms.md`, "The textbook scene": a unit square light (exitance 1) at height 3
/// facing down, a unit square blocker at height 1, and a 6 x 6 floor. On the floor the umbra is
/// |x|, |y| <= 0.5 and the penumbra reaches |x|, |y| = 1.
pub fn textbook() -> Scene {
    let square = |h: f64, s: f64| vec![v(-s, -s, h), v(s, -s, h), v(s, s, h), v(-s, s, h)];
    let mut light = square(3.0, 0.5);
    light.reverse(); // facing down
    Scene {
        up: None,
        unit: None,
        name: "textbook".into(),
        camera: upright(v(0.0, -6.5, 4.5), v(0.0, 0.0, 0.4), 45.0),
        surfaces: vec![
            Surface::new("light", light, Rgb::ZERO).with_emission(Rgb::splat(1.0)),
            Surface::new("blocker", square(1.0, 0.5), Rgb::splat(0.5)),
            Surface::new("floor", square(0.0, 3.0), Rgb::splat(0.7)),
        ],
    }
}

/// A unit square light at height 4 over two thin bars (4 x 0.2) at heights 2 and 1, crossing at
/// right angles and turned 20 degrees against the light's edges, over a floor. Where the bars'
/// shadows cross, the corner of their crossing slides over the light's edges: EEE events, whose
/// critical surfaces are ruled quadrics meeting the floor in conic arcs.
pub fn crossed_bars() -> Scene {
    let square = |h: f64, s: f64| vec![v(-s, -s, h), v(s, -s, h), v(s, s, h), v(-s, s, h)];
    let bar = |h: f64, turn_deg: f64| {
        let (sin, cos) = turn_deg.to_radians().sin_cos();
        [
            v(-2.0, -0.1, h),
            v(2.0, -0.1, h),
            v(2.0, 0.1, h),
            v(-2.0, 0.1, h),
        ]
        .iter()
        .map(|p| v(cos * p.x - sin * p.y, sin * p.x + cos * p.y, h))
        .collect::<Vec<_>>()
    };
    let mut light = square(4.0, 0.5);
    light.reverse(); // facing down
    Scene {
        up: None,
        unit: None,
        name: "bars".into(),
        camera: upright(v(0.0, -7.5, 5.5), v(0.0, 0.0, 0.6), 45.0),
        surfaces: vec![
            Surface::new("light", light, Rgb::ZERO).with_emission(Rgb::splat(1.0)),
            Surface::new("upper", bar(2.0, 20.0), Rgb::splat(0.5)),
            Surface::new("lower", bar(1.0, 110.0), Rgb::splat(0.5)),
            Surface::new("floor", square(0.0, 4.0), Rgb::splat(0.7)),
        ],
    }
}

/// A closed unit cube whose six inward faces all emit `emission` and reflect `reflectance`: the
/// exact radiosity is `emission / (1 - reflectance)` everywhere.
pub fn furnace(emission: f64, reflectance: f64) -> Scene {
    Scene {
        name: "furnace".into(),
        camera: upright(v(0.5, 0.02, 0.5), v(0.5, 1.0, 0.5), 100.0),
        ..closed_box(DVec3::ONE, emission, reflectance)
    }
}

/// A closed 8 x 1 x 1 box whose six inward faces all emit `emission` and reflect `reflectance`:
/// the exact radiosity is `emission / (1 - reflectance)` everywhere, though most of each long
/// face sees the box's far end at grazing angles.
pub fn long_furnace(emission: f64, reflectance: f64) -> Scene {
    Scene {
        name: "furnace-long".into(),
        camera: upright(v(0.05, 0.5, 0.5), v(8.0, 0.5, 0.5), 70.0),
        ..closed_box(v(8.0, 1.0, 1.0), emission, reflectance)
    }
}

/// A closed L-shaped room (the 2 x 2 x 1 box less its quarter x, y > 1) whose eight inward
/// faces all emit `emission` and reflect `reflectance`: the exact radiosity is `emission / (1 -
/// reflectance)` everywhere, though the room's inner corner hides part of it from most points.
/// The floor and ceiling are L-shaped hexagons; the walls meet them and each other edge to edge.
pub fn l_room_furnace(emission: f64, reflectance: f64) -> Scene {
    let outline = [
        v(0.0, 0.0, 0.0),
        v(2.0, 0.0, 0.0),
        v(2.0, 1.0, 0.0),
        v(1.0, 1.0, 0.0),
        v(1.0, 2.0, 0.0),
        v(0.0, 2.0, 0.0),
    ];
    let up = v(0.0, 0.0, 1.0);
    let inside = v(0.5, 0.5, 0.5);
    let mut faces = vec![
        ("floor".to_owned(), facing(outline.to_vec(), inside, false)),
        (
            "ceiling".to_owned(),
            facing(outline.iter().map(|&p| p + up).collect(), inside, false),
        ),
    ];
    for (i, &a) in outline.iter().enumerate() {
        let b = outline[(i + 1) % outline.len()];
        // The room lies to the left of each edge of the counter-clockwise outline.
        let left = up.cross(b - a).normalize();
        let wall = vec![a, b, b + up, a + up];
        let point = (a + b) / 2.0 + up * 0.5 + left * 0.1;
        faces.push((format!("wall{i}"), facing(wall, point, false)));
    }
    Scene {
        up: None,
        unit: None,
        name: "furnace-l".into(),
        camera: upright(v(1.9, 0.1, 0.5), v(0.3, 1.7, 0.5), 90.0),
        surfaces: faces
            .into_iter()
            .map(|(name, polygon)| {
                Surface::new(name, polygon, Rgb::splat(reflectance))
                    .with_emission(Rgb::splat(emission))
            })
            .collect(),
    }
}

/// A closed box `[0, size.x] x [0, size.y] x [0, size.z]` whose six faces face inward, each
/// emitting `emission` and reflecting `reflectance`.
pub fn closed_box(size: DVec3, emission: f64, reflectance: f64) -> Scene {
    let inside = 0.5 * size;
    let corner = |x: f64, y: f64, z: f64| v(x, y, z) * size;
    let faces = [
        (
            "floor",
            [
                corner(0., 0., 0.),
                corner(1., 0., 0.),
                corner(1., 1., 0.),
                corner(0., 1., 0.),
            ],
        ),
        (
            "ceiling",
            [
                corner(0., 0., 1.),
                corner(1., 0., 1.),
                corner(1., 1., 1.),
                corner(0., 1., 1.),
            ],
        ),
        (
            "south",
            [
                corner(0., 0., 0.),
                corner(1., 0., 0.),
                corner(1., 0., 1.),
                corner(0., 0., 1.),
            ],
        ),
        (
            "north",
            [
                corner(0., 1., 0.),
                corner(1., 1., 0.),
                corner(1., 1., 1.),
                corner(0., 1., 1.),
            ],
        ),
        (
            "west",
            [
                corner(0., 0., 0.),
                corner(0., 1., 0.),
                corner(0., 1., 1.),
                corner(0., 0., 1.),
            ],
        ),
        (
            "east",
            [
                corner(1., 0., 0.),
                corner(1., 1., 0.),
                corner(1., 1., 1.),
                corner(1., 0., 1.),
            ],
        ),
    ];
    Scene {
        up: None,
        unit: None,
        name: "box".into(),
        camera: None,
        surfaces: faces
            .into_iter()
            .map(|(name, p)| {
                Surface::new(
                    name,
                    facing(p.to_vec(), inside, false),
                    Rgb::splat(reflectance),
                )
                .with_emission(Rgb::splat(emission))
            })
            .collect(),
    }
}

/// `count` boxes standing on a floor, one per cell of a square grid (2 m cells), each of random
/// size, height and turn about the vertical, under a square light; blockers for benchmarks and
/// soak tests. The same `count` and `seed` give the same scene.
pub fn boxworld(count: usize, seed: u64) -> Scene {
    let cells = (count as f64).sqrt().ceil().max(1.0) as usize;
    let side = 2.0 * cells as f64;
    let height = 0.6 * side.max(4.0);
    let mut rng = crate::rng::SplitMix64::new(seed);
    let white = Rgb::splat(0.6);
    let light_half = 0.1 * side.max(4.0);
    let center = 0.5 * side;
    let mut light = vec![
        v(center - light_half, center - light_half, height),
        v(center + light_half, center - light_half, height),
        v(center + light_half, center + light_half, height),
        v(center - light_half, center + light_half, height),
    ];
    light.reverse(); // facing down
    let mut surfaces = vec![
        Surface::new("light", light, Rgb::ZERO).with_emission(Rgb::splat(100.0)),
        Surface::new(
            "floor",
            vec![
                v(0.0, 0.0, 0.0),
                v(side, 0.0, 0.0),
                v(side, side, 0.0),
                v(0.0, side, 0.0),
            ],
            white,
        ),
    ];
    for k in 0..count {
        let (i, j) = ((k % cells) as f64, (k / cells) as f64);
        let (w, d, h) = (
            0.3 + 0.5 * rng.next_f64(),
            0.3 + 0.5 * rng.next_f64(),
            0.3 + 1.2 * rng.next_f64(),
        );
        let turn = rng.next_f64() * std::f64::consts::PI;
        let c = v(
            2.0 * i + 1.0 + 0.2 * (rng.next_f64() - 0.5),
            2.0 * j + 1.0 + 0.2 * (rng.next_f64() - 0.5),
            0.0,
        );
        let (cos, sin) = (turn.cos(), turn.sin());
        let corner =
            |a: f64, b: f64, z: f64| c + v(a * w * cos - b * d * sin, a * w * sin + b * d * cos, z);
        let top: Vec<DVec3> = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]
            .iter()
            .map(|&(a, b)| corner(a, b, h))
            .collect();
        let axis = c + v(0.0, 0.0, 0.5 * h);
        surfaces.push(Surface::new(
            format!("box{k}_top"),
            facing(top.clone(), axis, true),
            white,
        ));
        for e in 0..4 {
            let (a, b) = (top[e], top[(e + 1) % 4]);
            let side_face = vec![v(a.x, a.y, 0.0), v(b.x, b.y, 0.0), b, a];
            surfaces.push(Surface::new(
                format!("box{k}_side{e}"),
                facing(side_face, axis, true),
                white,
            ));
        }
    }
    Scene {
        up: None,
        unit: None,
        name: format!("boxworld-{count}"),
        camera: upright(
            v(center, -0.6 * side, 0.9 * height),
            v(center, 0.45 * side, 0.0),
            50.0,
        ),
        surfaces,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::validate::validate;

    #[test]
    fn builtins_are_valid() {
        for (name, _) in NAMES {
            let scene = builtin(name).expect("every listed name is built in");
            assert_eq!(validate(&scene), vec![], "{name}");
        }
    }

    #[test]
    fn boxworld_names_carry_their_count() {
        let scene = builtin("boxworld-7").expect("a count is a built-in name");
        assert_eq!(scene.surfaces.len(), 2 + 5 * 7);
        assert_eq!(scene.name, "boxworld-7");
        assert_eq!(builtin("boxworld-100"), Some(boxworld(100, 1)));
        for bad in [
            "boxworld-",
            "boxworld-0",
            "boxworld--3",
            "boxworld-+3",
            "boxworld-1000001",
        ] {
            assert_eq!(builtin(bad), None, "{bad}");
        }
    }

    #[test]
    fn cornell_faces_point_into_the_room_and_out_of_the_blocks() {
        let scene = cornell();
        let room_center = v(278.0, 274.4, 279.6);
        for s in &scene.surfaces {
            let c = polygon::centroid(&s.polygon);
            let n = s.normal();
            if s.name.contains("block") {
                // Block faces see the room centre's side less than the walls do; check against the block axis.
                let axis = if s.name.starts_with("short") {
                    v(186.0, c.y, 169.0)
                } else {
                    v(368.5, c.y, 351.25)
                };
                let outward = if s.name.ends_with("top") {
                    v(0.0, 1.0, 0.0)
                } else {
                    (c - axis).normalize()
                };
                assert!(n.dot(outward) > 0.5, "{} faces inward", s.name);
            } else {
                assert!(
                    n.dot(room_center - c) > 0.0,
                    "{} faces out of the room",
                    s.name
                );
            }
        }
        let light = &scene.surfaces[scene.surface_id("light").expect("cornell has a light")];
        assert!(light.normal().y < -0.999);
    }

    #[test]
    fn furnace_faces_point_inward() {
        let scene = furnace(1.0, 0.5);
        for s in &scene.surfaces {
            let c = polygon::centroid(&s.polygon);
            assert!(s.normal().dot(DVec3::splat(0.5) - c) > 0.0, "{}", s.name);
            assert!((s.area() - 1.0).abs() < 1e-15);
        }
    }
}
