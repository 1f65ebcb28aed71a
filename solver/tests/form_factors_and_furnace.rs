#![allow(clippy::needless_range_loop)] // matrix entries are clearest by index
//! Discrete form factors (vertex-sampled, as the progressive solver uses them) against the
//! enclosure identities and closed forms, and the furnace.

use penumbra_meshing::mesh_scene_uniform;
use penumbra_scenes::{Visibility, builtin};
use penumbra_solver::coupling::{FormFactorMethod, PatchCoupling};
use penumbra_solver::{Discretization, NoProgress, SolverOptions, StopReason, solve_progressive};

/// Vertex-to-patch coupling for a scene with nothing to occlude (few rays suffice).
fn unoccluded_coupling<'a>(disc: &'a Discretization, vis: &'a Visibility) -> PatchCoupling<'a> {
    PatchCoupling {
        disc,
        visibility: vis,
        rays: 4,
        seed: 1,
        method: Default::default(),
        interrupt: None,
    }
}

/// Patch-to-patch form factors F_ij from the pairwise couplings.
fn patch_matrix(disc: &Discretization, coupling: &PatchCoupling) -> Vec<Vec<f64>> {
    let n = disc.receiver_count();
    let columns: Vec<Vec<(u32, f32)>> = (0..disc.patches.len())
        .map(|j| {
            (0..n)
                .map(|v| (v as u32, coupling.coupling(v, j).0 as f32))
                .collect()
        })
        .collect();
    disc.patch_factors(&columns)
}

#[test]
fn closed_cube_patch_rows_sum_to_one() {
    let scene = builtin::furnace(1.0, 0.5);
    let vis = Visibility::build(&scene);
    let mesh = mesh_scene_uniform(&scene, 3000).expect("cube meshes");
    // Patches of about 30 elements: many patch pairs, adjacent and opposite, share edges.
    let disc = Discretization::new(&scene, &mesh, 30);
    let coupling = unoccluded_coupling(&disc, &vis);
    let f = patch_matrix(&disc, &coupling);
    let worst_row = f
        .iter()
        .map(|row| (row.iter().sum::<f64>() - 1.0).abs())
        .fold(0.0, f64::max);
    assert!(worst_row < 1e-3, "row sums off by {worst_row}");
}

/// `docs/closed-forms.md`, "The 1 × 2 × 3 box": the 1 x 2 x 3 box's face-to-face form factors,
/// their row sums and their reciprocity, from the solver's vertex quadrature.
#[test]
fn box_face_factors_match_closed_forms_sum_to_one_and_are_reciprocal() {
    let scene = builtin::closed_box(glam::DVec3::new(1.0, 2.0, 3.0), 1.0, 0.5);
    assert!(penumbra_scenes::validate(&scene).is_empty());
    let inward = scene.surfaces.iter().all(|s| {
        let c = s.polygon.iter().copied().sum::<glam::DVec3>() / 4.0;
        s.normal().dot(glam::DVec3::new(0.5, 1.0, 1.5) - c) > 0.0
    });
    assert!(inward, "box faces must face inward");
    let vis = Visibility::build(&scene);
    let mesh = mesh_scene_uniform(&scene, 8000).expect("box meshes");
    let disc = Discretization::new(&scene, &mesh, 1_000_000);
    assert_eq!(disc.patches.len(), 6, "one patch per face");
    let coupling = unoccluded_coupling(&disc, &vis);
    let f = patch_matrix(&disc, &coupling);
    let exact = |i: usize, j: usize| box_closed_form(&scene, i, j);
    for i in 0..6 {
        let (si, ai) = (disc.patches[i].surface, disc.patches[i].area);
        let row: f64 = f[i].iter().sum();
        assert!((row - 1.0).abs() < 1e-3, "row {i} sums to {row}");
        for j in 0..6 {
            let (sj, aj) = (disc.patches[j].surface, disc.patches[j].area);
            if si == sj {
                continue;
            }
            let e = exact(si, sj);
            assert!(
                (f[i][j] - e).abs() < 1e-3 * e.max(0.1),
                "F {} -> {} = {} vs {e}",
                scene.surfaces[si].name,
                scene.surfaces[sj].name,
                f[i][j]
            );
            assert!(
                (ai * f[i][j] - aj * f[j][i]).abs() < 1e-3 * ai * f[i][j],
                "reciprocity {i} {j}"
            );
        }
    }
}

#[test]
fn face_to_face_factors_match_the_closed_forms() {
    let scene = builtin::furnace(1.0, 0.5);
    let vis = Visibility::build(&scene);
    let mesh = mesh_scene_uniform(&scene, 6000).expect("cube meshes");
    // One patch per face.
    let disc = Discretization::new(&scene, &mesh, 100_000);
    assert_eq!(disc.patches.len(), 6);
    let coupling = unoccluded_coupling(&disc, &vis);
    let f = patch_matrix(&disc, &coupling);
    const F_OPP: f64 = 0.199_824_895_698_387_4;
    const F_ADJ: f64 = 0.200_043_776_075_403_15;
    for i in 0..6 {
        for j in 0..6 {
            if i == j {
                assert_eq!(f[i][j], 0.0);
                continue;
            }
            let (si, sj) = (disc.patches[i].surface, disc.patches[j].surface);
            let ni = scene.surfaces[si].normal();
            let nj = scene.surfaces[sj].normal();
            let exact = if ni.dot(nj) < -0.5 { F_OPP } else { F_ADJ };
            assert!(
                (f[i][j] - exact).abs() < 1e-3,
                "F[{i}][{j}] = {} vs {exact}",
                f[i][j]
            );
        }
    }
}

#[test]
fn furnace_gives_e_over_one_minus_rho() {
    for rho in [0.5, 0.9] {
        let scene = builtin::furnace(1.0, rho);
        let vis = Visibility::build(&scene);
        let mesh = mesh_scene_uniform(&scene, 1200).expect("cube meshes");
        let options = SolverOptions {
            epsilon: 1e-4,
            ..SolverOptions::default()
        };
        let solution =
            solve_progressive(&scene, &mesh, &vis, &options, &NoProgress).expect("solves");
        assert_eq!(solution.stats.stop, StopReason::Converged);
        let expected = 1.0 / (1.0 - rho);
        for b in solution.radiosity.iter().flatten() {
            for c in b.to_array() {
                assert!(
                    (c - expected).abs() < 5e-3 * expected,
                    "rho {rho}: B = {c}, expected {expected}"
                );
            }
        }
        // A closed box lets nothing escape: what the vertex quadrature loses is its own error.
        assert!(
            solution.stats.escaped.mean().abs()
                < 1e-3 * solution.stats.emitted.mean() / (1.0 - rho)
        );
    }
}

/// `docs/closed-forms.md`, "The 1 × 2 × 3 box": the form factor between faces `i` and `j` of the
/// closed 1 x 2 x 3 box.
fn box_closed_form(scene: &penumbra_scenes::Scene, i: usize, j: usize) -> f64 {
    // Closed forms by face size (dimensions of the emitting face, then of the receiving face).
    let dims = |s: usize| {
        let e = scene.surfaces[s].bounds();
        let d = e.max - e.min;
        let mut v = [d.x, d.y, d.z];
        v.sort_by(f64::total_cmp);
        (v[1], v[2]) // the face's two side lengths
    };
    let exact = |i: usize, j: usize| -> f64 {
        let (ni, nj) = (scene.surfaces[i].normal(), scene.surfaces[j].normal());
        let face = dims(i);
        if ni.dot(nj) < -0.5 {
            match face {
                (2.0, 3.0) => 0.475576436532953,
                (1.0, 3.0) => 0.146414577931196,
                _ => 0.0603313853699537,
            }
        } else {
            // The shared edge is the side the two faces have in common.
            let other = dims(j);
            let shared = if face.0 == other.0 || face.0 == other.1 {
                face.0
            } else {
                face.1
            };
            match (face, shared) {
                ((2.0, 3.0), 2.0) => 0.102713430993999,
                ((2.0, 3.0), _) => 0.159498350739525,
                ((1.0, 3.0), 1.0) => 0.107796009555352,
                ((1.0, 3.0), _) => 0.31899670147905,
                (_, 1.0) => 0.161694014333028,
                _ => 0.308140292981996,
            }
        }
    };
    exact(i, j)
}

/// Monte Carlo form factors (4,096 stratified samples per vertex and patch, each with a ray) on a
/// coarse mesh of the same box, against Lambert's formula on the same mesh (which isolates the
/// sampling error) and against the closed forms (which adds the coarse mesh's quadrature error):
/// within 1 % and 2 %, rows summing to 1 within 1 %. Vertices on a patch's plane (the box's
/// edges) take Lambert's one-sided limit in both.
#[test]
fn monte_carlo_form_factors_match_the_closed_forms() {
    let scene = builtin::closed_box(glam::DVec3::new(1.0, 2.0, 3.0), 1.0, 0.5);
    let vis = Visibility::build(&scene);
    let mesh = mesh_scene_uniform(&scene, 600).expect("box meshes");
    let disc = Discretization::new(&scene, &mesh, 1_000_000);
    let coupling = |method| PatchCoupling {
        disc: &disc,
        visibility: &vis,
        rays: 16,
        seed: 3,
        method,
        interrupt: None,
    };
    let monte_carlo = patch_matrix(
        &disc,
        &coupling(FormFactorMethod::MonteCarlo { samples: 4096 }),
    );
    let analytic = patch_matrix(&disc, &coupling(Default::default()));
    let (mut sampling, mut total): (f64, f64) = (0.0, 0.0);
    for i in 0..6 {
        let row: f64 = monte_carlo[i].iter().sum();
        assert!((row - 1.0).abs() < 1e-2, "row {i} sums to {row}");
        for j in 0..6 {
            let (si, sj) = (disc.patches[i].surface, disc.patches[j].surface);
            if si == sj {
                continue;
            }
            let e = box_closed_form(&scene, si, sj);
            sampling = sampling.max((monte_carlo[i][j] - analytic[i][j]).abs() / analytic[i][j]);
            total = total.max((monte_carlo[i][j] - e).abs() / e);
        }
    }
    eprintln!(
        "Monte Carlo form factors: worst relative error {sampling:.2e} against Lambert, \
         {total:.2e} against the closed forms"
    );
    assert!(sampling < 1e-2 && total < 2e-2, "{sampling} {total}");
}

/// Patch-to-patch factors from whole columns (the way the solvers get them, rows for the
/// hemicube).
fn patch_matrix_of(
    disc: &Discretization,
    vis: &Visibility,
    method: FormFactorMethod,
) -> Vec<Vec<f64>> {
    let (columns, _) = PatchCoupling {
        disc,
        visibility: vis,
        rays: 16,
        seed: 3,
        method,
        interrupt: None,
    }
    .columns(&NoProgress)
    .expect("valid method");
    disc.patch_factors(&columns)
}

/// The hemicube's face-to-face factors of the 1 x 2 x 3 box converge to Lambert's on the same
/// mesh as the resolution grows (the pixel grid is the only difference: no occluders), and their
/// rows sum to 1 as closely as the delta form factors do. The worst error is aliasing at the
/// pixels' edges and depends on where the mesh's vertices fall: it shrinks about twofold per
/// doubling but unevenly (16 to 32: 3 to 6 times, 32 to 64: 1.4 to 2 times, depending on the
/// mesh), so it is compared across three doublings.
#[test]
fn hemicube_form_factors_converge_to_lamberts() {
    let scene = builtin::closed_box(glam::DVec3::new(1.0, 2.0, 3.0), 1.0, 0.5);
    let vis = Visibility::build(&scene);
    let mesh = mesh_scene_uniform(&scene, 600).expect("box meshes");
    let disc = Discretization::new(&scene, &mesh, 1_000_000);
    let analytic = patch_matrix_of(&disc, &vis, FormFactorMethod::Analytic);
    let mut previous = f64::INFINITY;
    for resolution in [16, 128] {
        let hemicube = patch_matrix_of(&disc, &vis, FormFactorMethod::Hemicube { resolution });
        let delta_sum = penumbra_solver::hemicube::Hemicube::new(resolution)
            .expect("valid")
            .delta_sum();
        let mut worst: f64 = 0.0;
        for i in 0..6 {
            let row: f64 = hemicube[i].iter().sum();
            assert!(
                (row - delta_sum).abs() < 1e-6,
                "row {i}: {row} vs {delta_sum}"
            );
            for j in 0..6 {
                if i != j {
                    worst = worst.max((hemicube[i][j] - analytic[i][j]).abs() / analytic[i][j]);
                }
            }
        }
        eprintln!(
            "hemicube {resolution}: worst relative difference from Lambert {worst:.2e} delta_sum {delta_sum}"
        );
        assert!(worst < previous / 4.0, "{worst} after {previous}");
        previous = worst;
    }
    assert!(previous < 2e-3, "{previous}");
}

/// The furnace with hemicube form factors: B = E / (1 - rho) within what the delta form
/// factors' sum allows (rows short by δ give E / (1 - rho + rho δ)).
#[test]
fn hemicube_furnace() {
    let rho = 0.9;
    let scene = builtin::furnace(1.0, rho);
    let vis = Visibility::build(&scene);
    let mesh = mesh_scene_uniform(&scene, 600).expect("cube meshes");
    let resolution = 64;
    let delta = 1.0
        - penumbra_solver::hemicube::Hemicube::new(resolution)
            .expect("valid")
            .delta_sum();
    let options = SolverOptions {
        epsilon: 1e-7,
        form_factors: FormFactorMethod::Hemicube { resolution },
        ..SolverOptions::default()
    };
    let solution = solve_progressive(&scene, &mesh, &vis, &options, &NoProgress).expect("solves");
    let expected = 1.0 / (1.0 - rho + rho * delta);
    for b in solution.radiosity.iter().flatten() {
        assert!(
            (b.r - expected).abs() < 2e-3 * expected,
            "B = {} vs {expected}",
            b.r
        );
    }
    let exact = 1.0 / (1.0 - rho);
    assert!((expected - exact).abs() / exact < 5e-3, "delta {delta}");
}
