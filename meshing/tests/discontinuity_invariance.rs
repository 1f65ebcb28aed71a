//! The same scene moved, rotated and rescaled has the same discontinuities, mapped along.

use glam::{DAffine3, DQuat, DVec3, EulerRot};
use penumbra_meshing::discontinuity::{DiscontinuityOptions, find_discontinuities};
use penumbra_scenes::{Scene, Visibility, builtin};

fn segments(scene: &Scene) -> Vec<Vec<(DVec3, DVec3, String)>> {
    let vis = Visibility::build(scene);
    find_discontinuities(scene, &vis, &DiscontinuityOptions::default())
        .segments
        .into_iter()
        .map(|list| {
            list.into_iter()
                .map(|s| {
                    (
                        s.from,
                        s.to,
                        format!("{:?} {:?} {}", s.event, s.boundary, s.order),
                    )
                })
                .collect()
        })
        .collect()
}

#[test]
fn moved_rotated_and_scaled_scenes_have_the_same_segments() {
    for scene in [
        builtin::textbook(),
        builtin::cornell(),
        builtin::crossed_bars(),
    ] {
        let reference = segments(&scene);
        let size = scene.diagonal();
        let turn = DQuat::from_euler(EulerRot::XYZ, 0.7, -0.4, 2.1);
        for scale in [1e-3, 1.0, 1e3] {
            let map = DAffine3::from_scale_rotation_translation(
                DVec3::splat(scale),
                turn,
                DVec3::new(1.3, -2.9, 0.6) * size * scale,
            );
            let back = map.inverse();
            let moved = segments(&scene.transformed(&map));
            for (r, (a, b)) in reference.iter().zip(&moved).enumerate() {
                assert_eq!(
                    a.len(),
                    b.len(),
                    "{} surface {r}, scale {scale}",
                    scene.name
                );
                for (from, to, kind) in b {
                    let (p, q) = (back.transform_point3(*from), back.transform_point3(*to));
                    let found = a.iter().any(|(x, y, k)| {
                        let close = |u: DVec3, v: DVec3| u.distance(v) <= 1e-9 * size;
                        k == kind
                            && ((close(p, *x) && close(q, *y)) || (close(p, *y) && close(q, *x)))
                    });
                    assert!(
                        found,
                        "{} surface {r}, scale {scale}: {p} - {q} ({kind}) has no match",
                        scene.name
                    );
                }
            }
        }
    }
}
