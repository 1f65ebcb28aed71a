//! Scenes at the numerical extremes, each with the behaviour it must show (the tests in
//! `tests/extremes.rs` hold the solver to it).

use glam::DVec3;

use crate::color::Rgb;
use crate::model::{Scene, Surface};

fn square(center: DVec3, half: f64) -> Vec<DVec3> {
    let c = center;
    vec![
        DVec3::new(c.x - half, c.y - half, c.z),
        DVec3::new(c.x + half, c.y - half, c.z),
        DVec3::new(c.x + half, c.y + half, c.z),
        DVec3::new(c.x - half, c.y + half, c.z),
    ]
}

/// The faces of the box `lo..hi` (top, sides, and the bottom if `bottom`), each facing into the
/// box if `inward`, else out of it.
fn box_faces(lo: DVec3, hi: DVec3, bottom: bool, inward: bool) -> Vec<Vec<DVec3>> {
    let c = (lo + hi) / 2.0;
    let at = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    let mut faces = vec![
        vec![
            at(lo.x, lo.y, hi.z),
            at(hi.x, lo.y, hi.z),
            hi,
            at(lo.x, hi.y, hi.z),
        ],
        vec![
            lo,
            at(hi.x, lo.y, lo.z),
            at(hi.x, lo.y, hi.z),
            at(lo.x, lo.y, hi.z),
        ],
        vec![
            at(lo.x, hi.y, lo.z),
            at(hi.x, hi.y, lo.z),
            hi,
            at(lo.x, hi.y, hi.z),
        ],
        vec![
            lo,
            at(lo.x, hi.y, lo.z),
            at(lo.x, hi.y, hi.z),
            at(lo.x, lo.y, hi.z),
        ],
        vec![
            at(hi.x, lo.y, lo.z),
            at(hi.x, hi.y, lo.z),
            hi,
            at(hi.x, lo.y, hi.z),
        ],
    ];
    if bottom {
        faces.push(vec![
            lo,
            at(hi.x, lo.y, lo.z),
            at(hi.x, hi.y, lo.z),
            at(lo.x, hi.y, lo.z),
        ]);
    }
    for polygon in &mut faces {
        let n = (polygon[1] - polygon[0]).cross(polygon[2] - polygon[0]);
        if (n.dot(c - polygon[0]) > 0.0) != inward {
            polygon.reverse();
        }
    }
    faces
}

fn scene(name: &str, surfaces: Vec<Surface>) -> Scene {
    Scene {
        up: None,
        unit: None,
        name: name.into(),
        camera: None,
        surfaces,
    }
}

/// Facing down (−z).
fn light(center: DVec3, half: f64) -> Surface {
    let mut polygon = square(center, half);
    polygon.reverse();
    Surface::new("light", polygon, Rgb::ZERO).with_emission(Rgb::splat(1.0))
}

/// The textbook scene with a light of side `side` (centred at height 3) over a unit blocker at
/// height 1 and a floor of side 6. As the light shrinks, the direct light on the floor becomes
/// that of a point light of the same power, and the blocker's shadow a hard square of half-side
/// 0.75 (the blocker's half-side 0.5 scaled by 3 / 2).
pub fn tiny_light(side: f64) -> Scene {
    scene(
        "tiny_light",
        vec![
            light(DVec3::new(0.0, 0.0, 3.0), side / 2.0),
            Surface::new(
                "blocker",
                square(DVec3::new(0.0, 0.0, 1.0), 0.5),
                Rgb::splat(0.5),
            ),
            Surface::new("floor", square(DVec3::ZERO, 3.0), Rgb::splat(0.7)),
        ],
    )
}

/// Every blocker edge parallel to a light edge: a unit light at height 3 over a square blocker of
/// side `side` at height 1 and a floor (`docs/closed-forms.md`, "The textbook scene"). Each light
/// edge and the parallel blocker edge span one plane, so the EV wedges of both ends of an edge
/// coincide with its EE wedge (degenerate wedges); they must merge into one line each, on which the
/// light is D1 (its slope jumps). With `side` 1.2 the umbra ends at |x| = 0.65 and the penumbra at
/// 1.15.
pub fn parallel_edges(side: f64) -> Scene {
    scene(
        "parallel_edges",
        vec![
            light(DVec3::new(0.0, 0.0, 3.0), 0.5),
            Surface::new(
                "blocker",
                square(DVec3::new(0.0, 0.0, 1.0), side / 2.0),
                Rgb::splat(0.5),
            ),
            Surface::new("floor", square(DVec3::ZERO, 3.0), Rgb::splat(0.7)),
        ],
    )
}

/// A light at height 1 facing up, away from a blocker and a floor below it: nothing but the
/// light itself may have any radiosity.
pub fn light_facing_away() -> Scene {
    let mut up = light(DVec3::new(0.0, 0.0, 1.0), 0.5);
    up.polygon.reverse();
    scene(
        "light_facing_away",
        vec![
            up,
            Surface::new(
                "blocker",
                square(DVec3::new(0.0, 0.0, 0.5), 0.3),
                Rgb::splat(0.5),
            ),
            Surface::new("floor", square(DVec3::ZERO, 3.0), Rgb::splat(0.7)),
        ],
    )
}

/// A light facing down, with a receiver above it (behind the light, facing down too) and a floor
/// below: the receiver gets no direct light, the floor does.
pub fn receiver_behind_light() -> Scene {
    let mut ceiling = square(DVec3::new(0.0, 0.0, 2.0), 2.0);
    ceiling.reverse();
    scene(
        "receiver_behind_light",
        vec![
            light(DVec3::new(0.0, 0.0, 1.0), 0.5),
            Surface::new("ceiling", ceiling, Rgb::splat(0.5)),
            Surface::new("floor", square(DVec3::ZERO, 2.0), Rgb::splat(0.5)),
        ],
    )
}

/// A light sealed in a box (walls facing in) over a floor: the floor outside sees nothing.
pub fn hidden_emitter() -> Scene {
    let mut surfaces = vec![light(DVec3::new(0.0, 0.0, 1.9), 0.3)];
    let sealed = box_faces(
        DVec3::new(-1.0, -1.0, 0.5),
        DVec3::new(1.0, 1.0, 2.0),
        true,
        true,
    );
    for (k, polygon) in sealed.into_iter().enumerate() {
        surfaces.push(Surface::new(format!("box{k}"), polygon, Rgb::splat(0.5)));
    }
    surfaces.push(Surface::new(
        "floor",
        square(DVec3::ZERO, 4.0),
        Rgb::splat(0.5),
    ));
    scene("hidden_emitter", surfaces)
}

/// A light facing down at height `height` over a floor strip that starts 2 units to the side:
/// with a tiny height every floor point sees the light at a grazing angle, and the irradiance is
/// tiny, positive and that of the point-light formula.
pub fn grazing_light(height: f64) -> Scene {
    let floor = vec![
        DVec3::new(2.0, -1.0, 0.0),
        DVec3::new(6.0, -1.0, 0.0),
        DVec3::new(6.0, 1.0, 0.0),
        DVec3::new(2.0, 1.0, 0.0),
    ];
    scene(
        "grazing_light",
        vec![
            light(DVec3::new(0.0, 0.0, height), 0.005),
            Surface::new("floor", floor, Rgb::splat(0.5)),
        ],
    )
}

/// A square light over a floor with a blocker lying in the floor's own plane (coplanar,
/// overlapping it): a coplanar blocker hides nothing, so the floor's light is what it is without it.
pub fn coplanar_blocker(with_blocker: bool) -> Scene {
    let mut surfaces = vec![
        light(DVec3::new(0.0, 0.0, 2.0), 0.5),
        Surface::new("floor", square(DVec3::ZERO, 3.0), Rgb::splat(0.5)),
    ];
    if with_blocker {
        surfaces.push(Surface::new(
            "blocker",
            square(DVec3::new(0.5, 0.0, 0.0), 0.5),
            Rgb::splat(0.5),
        ));
    }
    scene("coplanar_blocker", surfaces)
}

/// A unit cube standing on a floor under a light: the light jumps across the cube's footprint
/// (D0 contact lines), from nothing under the cube to the open floor's value beside it.
pub fn touching_blocker() -> Scene {
    let mut surfaces = vec![light(DVec3::new(0.3, 0.2, 3.0), 0.5)];
    let cube = box_faces(
        DVec3::new(-0.5, -0.5, 0.0),
        DVec3::new(0.5, 0.5, 1.0),
        false,
        false,
    );
    for (k, polygon) in cube.into_iter().enumerate() {
        surfaces.push(Surface::new(format!("cube{k}"), polygon, Rgb::splat(0.5)));
    }
    surfaces.push(Surface::new(
        "floor",
        square(DVec3::ZERO, 3.0),
        Rgb::splat(0.5),
    ));
    scene("touching_blocker", surfaces)
}

/// A floor of three tiles under a light, meeting in a T: a large tile on the left (x < 0) and two
/// small ones on the right, whose shared edge ends on the middle of the large tile's right
/// edge. Each tile is meshed on its own, so the seams do not share vertices; the light must
/// still be continuous across them.
pub fn t_junction() -> Scene {
    let tile = |x0: f64, x1: f64, y0: f64, y1: f64, name: &str| {
        Surface::new(
            name,
            vec![
                DVec3::new(x0, y0, 0.0),
                DVec3::new(x1, y0, 0.0),
                DVec3::new(x1, y1, 0.0),
                DVec3::new(x0, y1, 0.0),
            ],
            Rgb::splat(0.5),
        )
    };
    scene(
        "t_junction",
        vec![
            light(DVec3::new(0.0, 0.0, 2.0), 0.5),
            tile(-2.0, 0.0, -2.0, 2.0, "left"),
            tile(0.0, 2.0, -2.0, 0.0, "lower_right"),
            tile(0.0, 2.0, 0.0, 2.0, "upper_right"),
        ],
    )
}

/// Two blockers side by side at the same height, their facing edges `gap` apart (1e-9 of the
/// scene for the extreme): their shadows' edges are two wedge lines that close together on the
/// floor. Meshing must stay sane and within budget instead of chasing the sliver between them.
pub fn close_wedges(gap: f64) -> Scene {
    let rect = |x0: f64, x1: f64, name: &str| {
        Surface::new(
            name,
            vec![
                DVec3::new(x0, -0.5, 1.0),
                DVec3::new(x1, -0.5, 1.0),
                DVec3::new(x1, 0.5, 1.0),
                DVec3::new(x0, 0.5, 1.0),
            ],
            Rgb::splat(0.5),
        )
    };
    scene(
        "close_wedges",
        vec![
            light(DVec3::new(0.2, 0.1, 3.0), 0.5),
            rect(-0.6, 0.0, "left_blocker"),
            rect(gap, 0.6, "right_blocker"),
            Surface::new("floor", square(DVec3::ZERO, 3.0), Rgb::splat(0.5)),
        ],
    )
}
