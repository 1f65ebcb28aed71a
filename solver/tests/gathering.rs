//! The discrete radiosity system solved four ways: the dense direct solve is its exact answer,
//! Jacobi and Gauss–Seidel gathering converge to it, and progressive refinement (Southwell) does
//! too, sampling the very same form factors.

use penumbra_meshing::{SceneMesh, mesh_scene_uniform};
use penumbra_scenes::{Scene, Visibility, builtin};
use penumbra_solver::gathering::PatchSystem;
use penumbra_solver::{
    NoProgress, Solution, SolverMethod, SolverOptions, solve_gathering, solve_progressive,
};

fn solve(scene: &Scene, mesh: &SceneMesh, method: SolverMethod, epsilon: f64) -> Solution {
    let vis = Visibility::build(scene);
    let options = SolverOptions {
        epsilon,
        ..SolverOptions::default()
    };
    match method {
        SolverMethod::Progressive => {
            solve_progressive(scene, mesh, &vis, &options, &NoProgress).expect("solves")
        }
        _ => {
            solve_gathering(scene, mesh, &vis, &options, method, &NoProgress)
                .expect("solves")
                .0
        }
    }
}

/// Largest difference between two solutions' vertex radiosities, relative to the largest value.
fn difference(a: &Solution, b: &Solution) -> f64 {
    let largest = a
        .radiosity
        .iter()
        .flatten()
        .map(|x| x.mean())
        .fold(0.0, f64::max);
    a.radiosity
        .iter()
        .flatten()
        .zip(b.radiosity.iter().flatten())
        .map(|(x, y)| (*x - *y).mean().abs())
        .fold(0.0, f64::max)
        / largest
}

#[test]
fn every_method_reaches_the_direct_solution_of_the_cornell_box() {
    let scene = builtin::cornell();
    let mesh = mesh_scene_uniform(&scene, 1_500).expect("meshes");
    let direct = solve(&scene, &mesh, SolverMethod::Direct, 1e-12);
    assert!(direct.stats.residual < 1e-12, "{:?}", direct.stats);
    for (method, epsilon) in [
        (SolverMethod::Jacobi, 1e-10),
        (SolverMethod::GaussSeidel, 1e-10),
        (SolverMethod::Progressive, 1e-9),
    ] {
        let s = solve(&scene, &mesh, method, epsilon);
        let d = difference(&direct, &s);
        eprintln!(
            "{method:?}: {} iterations, residual {:.2e}, differs from the direct solve by {d:.2e}",
            s.stats.iterations, s.stats.residual
        );
        assert!(d < 1e-6, "{method:?}: {d:e}");
        for b in s.radiosity.iter().flatten() {
            assert!(b.r >= 0.0 && b.g >= 0.0 && b.b >= 0.0 && b.mean().is_finite());
        }
        let balance = (s.stats.emitted - s.stats.absorbed - s.stats.unshot - s.stats.escaped)
            .mean()
            .abs();
        assert!(
            balance < 1e-9 * s.stats.emitted.mean(),
            "{method:?}: {balance}"
        );
    }
}

/// Gauss–Seidel uses each new value at once and needs fewer sweeps than Jacobi; both need more
/// as the reflectance nears 1 (the system's spectral radius is about ρ), and the closed furnace
/// comes out at E / (1 − ρ).
#[test]
fn gathering_slows_as_reflectance_nears_one() {
    let mut last = [0usize; 2];
    for rho in [0.5, 0.9, 0.99] {
        let scene = builtin::furnace(1.0, rho);
        let mesh = mesh_scene_uniform(&scene, 1_200).expect("meshes");
        let vis = Visibility::build(&scene);
        let options = SolverOptions {
            epsilon: 1e-8,
            max_shots: 1_000_000,
            ..SolverOptions::default()
        };
        let system = PatchSystem::assemble(&scene, &mesh, &vis, &options, &NoProgress);
        let mut iterations = [0usize; 2];
        for (k, method) in [SolverMethod::Jacobi, SolverMethod::GaussSeidel]
            .into_iter()
            .enumerate()
        {
            let solved = system.solve(method, 1e-8, 1_000_000, None).expect("solves");
            iterations[k] = solved.history.len() - 1;
            let expected = rho / (1.0 - rho); // reflected radiosity of a furnace with E = 1
            for &x in &solved.patch_radiosity[0] {
                assert!(
                    (x - expected).abs() < 0.01 * expected,
                    "rho {rho}: {x} vs {expected}"
                );
            }
        }
        eprintln!(
            "rho {rho}: Jacobi {} sweeps, Gauss-Seidel {}",
            iterations[0], iterations[1]
        );
        assert!(iterations[1] < iterations[0]);
        assert!(iterations[0] > last[0] && iterations[1] > last[1]);
        last = iterations;
    }
}
