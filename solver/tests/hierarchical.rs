//! The hierarchical solver against closed forms, the dense solve and its own invariants.

use penumbra_meshing::mesh_scene_uniform;
use penumbra_scenes::{Visibility, builtin};
use penumbra_solver::{NoProgress, SolverOptions, StopReason, solve_hierarchical};

#[test]
fn furnace_gives_e_over_one_minus_rho() {
    for rho in [0.5, 0.9, 0.99] {
        let scene = builtin::furnace(1.0, rho);
        let vis = Visibility::build(&scene);
        let mesh = mesh_scene_uniform(&scene, 1200).expect("cube meshes");
        let options = SolverOptions {
            epsilon: 1e-5,
            ..SolverOptions::default()
        };
        let solution =
            solve_hierarchical(&scene, &mesh, &vis, &options, &NoProgress).expect("solves");
        assert_eq!(solution.stats.stop, StopReason::Converged);
        let expected = 1.0 / (1.0 - rho);
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for b in solution.radiosity.iter().flatten() {
            for c in b.to_array() {
                lo = lo.min(c / expected);
                hi = hi.max(c / expected);
            }
        }
        eprintln!("rho {rho}: {lo} .. {hi} {:?}", solution.stats.hierarchy);
        assert!(lo > 0.995 && hi < 1.005, "rho {rho}: {lo} .. {hi}");
    }
}

#[test]
fn debug_tol() {
    for tol in [1e-4, 1e-5, 1e-6, 1e-7] {
        let rho = 0.5;
        let scene = builtin::furnace(1.0, rho);
        let vis = Visibility::build(&scene);
        let mesh = mesh_scene_uniform(&scene, 1200).expect("cube meshes");
        let options = SolverOptions {
            epsilon: 1e-5,
            link_tol: tol,
            ..SolverOptions::default()
        };
        let t = std::time::Instant::now();
        let solution =
            solve_hierarchical(&scene, &mesh, &vis, &options, &NoProgress).expect("solves");
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for b in solution.radiosity.iter().flatten() {
            lo = lo.min(b.r / 2.0);
            hi = hi.max(b.r / 2.0);
        }
        eprintln!(
            "tol {tol}: {lo:.5} .. {hi:.5} links {} {:?}",
            solution.stats.hierarchy.as_ref().unwrap().links,
            t.elapsed()
        );
    }
}

#[test]
fn debug_furnace_worst() {
    let rho = 0.5;
    let scene = builtin::furnace(1.0, rho);
    let vis = Visibility::build(&scene);
    let mesh = mesh_scene_uniform(&scene, 1200).expect("cube meshes");
    let options = SolverOptions {
        epsilon: 1e-5,
        ..SolverOptions::default()
    };
    let solution = solve_hierarchical(&scene, &mesh, &vis, &options, &NoProgress).expect("solves");
    let mut all = vec![];
    for (m, b) in mesh.surfaces.iter().zip(&solution.radiosity) {
        for (p, c) in m.points3.iter().zip(b) {
            all.push((c.r / 2.0, *p, m.surface));
        }
    }
    all.sort_by(|a, b| a.0.total_cmp(&b.0));
    for x in all.iter().take(5).chain(all.iter().rev().take(10)) {
        eprintln!("{:.5} {:?} {}", x.0, x.1, x.2);
    }
}
