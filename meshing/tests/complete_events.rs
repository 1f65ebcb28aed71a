//! Complete EV and VE events: a convex light over a convex blocker in a parallel plane puts on
//! the floor every one of its n x k EV and n x k VE segments, where the closed form says, and
//! no other segment.

use glam::DVec3;
use penumbra_meshing::discontinuity::{DiscontinuityOptions, EventSet, find_discontinuities};
use penumbra_scenes::polygon::closest_point_on_segment;
use penumbra_scenes::{Rgb, Scene, Surface, Visibility};

/// A regular `n`-gon of circumradius `radius` about (`x`, `y`) at height `z`, turned by `turn`,
/// listed counter-clockwise seen from above (`up`) or from below.
fn polygon(n: usize, radius: f64, (x, y, z): (f64, f64, f64), turn: f64, up: bool) -> Vec<DVec3> {
    let mut p: Vec<DVec3> = (0..n)
        .map(|i| {
            let a = turn + std::f64::consts::TAU * i as f64 / n as f64;
            DVec3::new(x + radius * a.cos(), y + radius * a.sin(), z)
        })
        .collect();
    if !up {
        p.reverse();
    }
    p
}

/// Light at height 3, blocker at height 1.2 facing the light, a floor at height 0.
fn scene(light: &[DVec3], blocker: &[DVec3]) -> Scene {
    let grey = Rgb::splat(0.5);
    Scene {
        up: None,
        unit: None,
        name: "parallel".into(),
        camera: None,
        surfaces: vec![
            Surface::new("light", light.to_vec(), Rgb::ZERO).with_emission(Rgb::splat(1.0)),
            Surface::new("blocker", blocker.to_vec(), grey),
            Surface::new("floor", polygon(4, 20.0, (0.0, 0.0, 0.0), 0.3, true), grey),
        ],
    }
}

/// The point where the ray from `q` through `p` meets the floor.
fn on_floor(q: DVec3, p: DVec3) -> DVec3 {
    q + (p - q) * (q.z / (q.z - p.z))
}

fn distance_to_segment(x: DVec3, [a, b]: [DVec3; 2]) -> f64 {
    x.distance(closest_point_on_segment(x, a, b))
}

#[test]
fn a_convex_blocker_parallel_to_a_convex_light_gets_every_ev_and_ve_line() {
    let cases = [
        (4, 0.1, 4, 0.9, (0.0, 0.0)),
        (4, 0.0, 4, std::f64::consts::FRAC_PI_4, (0.05, -0.02)),
        (3, 0.4, 5, 1.3, (0.3, 0.2)),
        (6, 0.2, 4, 0.5, (-0.2, 0.1)),
    ];
    for (n, light_turn, k, blocker_turn, (ox, oy)) in cases {
        let light = polygon(n, 0.6, (0.0, 0.0, 3.0), light_turn, false);
        let blocker = polygon(k, 0.45, (ox, oy, 1.2), blocker_turn, false);
        let scene = scene(&light, &blocker);
        let vis = Visibility::build(&scene);
        let options = DiscontinuityOptions {
            events: EventSet::Complete,
            ..DiscontinuityOptions::default()
        };
        let found = find_discontinuities(&scene, &vis, &options);
        let floor: Vec<[DVec3; 2]> = found.segments[2].iter().map(|g| [g.from, g.to]).collect();
        // Counted by kind: the blocker touches nothing, and every segment is of one kind.
        let st = &found.stats;
        assert_eq!(st.contact_lines, 0);
        assert_eq!(
            st.ev_segments + st.ve_segments + st.eee_segments,
            st.segments
        );
        assert_eq!(
            st.order_0_segments + st.order_1_segments + st.order_2_segments,
            st.segments
        );
        let mut expected = Vec::new();
        for i in 0..n {
            let (a, b) = (light[i], light[(i + 1) % n]);
            for &v in &blocker {
                expected.push([on_floor(a, v), on_floor(b, v)]);
            }
        }
        for &a in &light {
            for j in 0..k {
                let (u, w) = (blocker[j], blocker[(j + 1) % k]);
                expected.push([on_floor(a, u), on_floor(a, w)]);
            }
        }
        let tol = 1e-9 * scene.diagonal();
        let case = format!("{n}-gon light, {k}-gon blocker turned {blocker_turn}");
        // Events that coincide are one line: every point of a segment lies on some event, and
        // every point of an event on some segment.
        let on_some = |from: &[[DVec3; 2]], onto: &[[DVec3; 2]], what: &str| {
            for s in from {
                for step in 0..=20 {
                    let x = s[0].lerp(s[1], f64::from(step) / 20.0);
                    assert!(
                        onto.iter().any(|&e| distance_to_segment(x, e) <= tol),
                        "{case}: {x} of {s:?} is on no {what}"
                    );
                }
            }
        };
        on_some(&floor, &expected, "EV or VE event");
        on_some(&expected, &floor, "segment on the floor");
    }
}
