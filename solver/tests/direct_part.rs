//! Every solver's solution carries the direct part of the irradiance at each vertex: the exact
//! direct light there, with the reflected light's part on top of it and never below.

use penumbra_meshing::mesh_scene_uniform;
use penumbra_scenes::polygon::closest_point_on_segment;
use penumbra_scenes::{Visibility, builtin};
use penumbra_solver::{
    DirectLight, NoProgress, ReceivingPoint, Solution, SolverMethod, SolverOptions,
    solve_gathering, solve_hierarchical, solve_progressive,
};

#[test]
fn every_solver_keeps_the_exact_direct_part() {
    let scene = builtin::cornell();
    let visibility = Visibility::build(&scene);
    let mesh = mesh_scene_uniform(&scene, 1500).expect("the Cornell box meshes");
    let options = SolverOptions::default();
    let solutions: Vec<(&str, Solution)> = vec![
        (
            "progressive",
            solve_progressive(&scene, &mesh, &visibility, &options, &NoProgress).expect("solves"),
        ),
        (
            "jacobi",
            solve_gathering(
                &scene,
                &mesh,
                &visibility,
                &options,
                SolverMethod::Jacobi,
                &NoProgress,
            )
            .expect("solves"),
        ),
        (
            "hierarchical",
            solve_hierarchical(&scene, &mesh, &visibility, &options, &NoProgress).expect("solves"),
        ),
    ];
    let exact = DirectLight::new(&scene, &visibility);
    let brightest = scene.emitted_power().mean() / scene.total_area();
    for (name, solution) in &solutions {
        let mut compared = 0;
        for (s, surface) in mesh.surfaces.iter().enumerate() {
            let normal = scene.surfaces[surface.surface].normal();
            let (h, hd) = (&solution.irradiance[s], &solution.direct_irradiance[s]);
            assert_eq!(hd.len(), surface.points3.len(), "{name}: surface {s}");
            for (k, &p) in surface.points3.iter().enumerate() {
                let reflected = h[k] - hd[k];
                assert!(
                    [reflected.r, reflected.g, reflected.b]
                        .iter()
                        .all(|&c| c >= -1e-12 * brightest),
                    "{name}: less light than its direct part at {p}"
                );
                // Vertices on edges and corners are evaluated as one-sided limits; interior
                // vertices as plain points.
                let local = surface.local[k];
                let outline = &surface.boundary;
                let on_outline = (0..outline.len()).any(|i| {
                    let (a, b) = (outline[i], outline[(i + 1) % outline.len()]);
                    closest_point_on_segment(local, a, b).distance(local) < 1e-9
                });
                if on_outline {
                    continue;
                }
                let fresh = exact.irradiance(&ReceivingPoint::interior(p, normal), surface.surface);
                assert!(
                    (fresh - hd[k]).mean().abs() <= 1e-9 * fresh.mean().max(brightest),
                    "{name}: direct part {:?} against {:?} at {p}",
                    hd[k],
                    fresh
                );
                compared += 1;
            }
        }
        assert!(compared > 500, "{name}: only {compared} vertices compared");
    }
}
