//! Discontinuity meshing against the closed forms of the textbook scene, and against uniform
//! meshing at the same element count.

use glam::DVec3;
use penumbra::{MeshMethod, RunOptions, run};
use penumbra_meshing::discontinuity::{
    Boundary, DiscontinuityOptions, Event, find_discontinuities,
};
use penumbra_scenes::{LoadedScene, Scene, Visibility, builtin};
use penumbra_solver::measure::direct_interpolation_error;
use penumbra_solver::{DirectLight, NoProgress, SolverOptions};

fn loaded(scene: Scene) -> LoadedScene {
    LoadedScene {
        scene,
        source: "test".into(),
        warnings: Vec::new(),
    }
}

/// Section 3.1 of the analytic notes: on the textbook floor, 8 segments of order 1 at x, y = ±0.5
/// (umbra) and ±1 (outer penumbra), each running |other coordinate| <= 1.
#[test]
fn textbook_lines_are_the_analytic_ones() {
    let scene = builtin::textbook();
    let vis = Visibility::build(&scene);
    let found = find_discontinuities(&scene, &vis, &DiscontinuityOptions::default());
    let floor = scene.surface_id("floor").expect("floor");
    let segments = &found.segments[floor];
    assert_eq!(segments.len(), 8, "{segments:#?}");
    let mut seen = Vec::new();
    for s in segments {
        assert_eq!(s.order, 1);
        assert!(matches!(s.event, Event::Ev | Event::Ve));
        assert!(s.from.z == 0.0 && s.to.z == 0.0);
        // Which coordinate is constant along the segment, and its value.
        let (fixed, along) = if (s.from.x - s.to.x).abs() < (s.from.y - s.to.y).abs() {
            ((s.from.x, s.to.x), (s.from.y, s.to.y))
        } else {
            ((s.from.y, s.to.y), (s.from.x, s.to.x))
        };
        let level = fixed.0.abs();
        let expected = if level < 0.75 { 0.5 } else { 1.0 };
        for v in [fixed.0.abs(), fixed.1.abs()] {
            assert!(
                (v - expected).abs() <= 1e-9 * expected,
                "line at {v}, expected {expected}"
            );
        }
        let (lo, hi) = (along.0.min(along.1), along.0.max(along.1));
        assert!(
            (lo + 1.0).abs() <= 1e-9 && (hi - 1.0).abs() <= 1e-9,
            "extent {lo}..{hi}"
        );
        let kind = if expected == 0.5 {
            Boundary::Umbra
        } else {
            Boundary::Penumbra
        };
        assert_eq!(s.boundary, kind);
        seen.push((fixed.0.signum() * expected * 10.0) as i32);
    }
    seen.sort_unstable();
    assert_eq!(seen, [-10, -10, -5, -5, 5, 5, 10, 10]);

    // In the mesh, every line is a chain of edges whose vertices lie on it.
    let result = run(
        loaded(scene.clone()),
        &RunOptions {
            mesh: MeshMethod::Discontinuity,
            ..RunOptions::default()
        },
        &NoProgress,
    )
    .expect("runs");
    let mesh = &result.mesh.surfaces[floor];
    // The check covers every constraint: each is a chain of mesh edges.
    mesh.sanity_check().expect("sane mesh");
    // The 8 lines cross and meet; inserted, they are split where they do.
    assert!(mesh.constraints.len() >= 8);
    for &[a, b] in &mesh.constraints {
        for p in [a, b] {
            let p = mesh.frame.to_3d(p * mesh.scale);
            let near = [p.x.abs(), p.y.abs()]
                .into_iter()
                .map(|c| (c - 0.5).abs().min((c - 1.0).abs()))
                .fold(f64::INFINITY, f64::min);
            assert!(near <= 1e-9, "constraint end {p} is {near:e} off the lines");
        }
    }
    let on_lines: Vec<DVec3> = mesh
        .points3
        .iter()
        .copied()
        .filter(|p| {
            segments.iter().any(|s| {
                let d = s.to - s.from;
                let t = (*p - s.from).dot(d) / d.length_squared();
                (-1e-9..=1.0 + 1e-9).contains(&t) && (s.from + d * t).distance(*p) < 1e-6
            })
        })
        .collect();
    assert!(
        on_lines.len() > 8 * 10,
        "{} vertices on the lines",
        on_lines.len()
    );
    for p in on_lines {
        let near = [p.x.abs(), p.y.abs()]
            .into_iter()
            .map(|c| (c - 0.5).abs().min((c - 1.0).abs()))
            .fold(f64::INFINITY, f64::min);
        assert!(near <= 1e-9, "vertex {p} is {near:e} off its line");
    }
}

/// RMS error of the direct-only solution interpolated over `receiver`, for a mesh method.
fn direct_error(
    scene: &Scene,
    receiver: &str,
    method: MeshMethod,
    max_elements: usize,
) -> (f64, usize) {
    let options = RunOptions {
        mesh: method,
        max_elements,
        solver: SolverOptions {
            direct_only: true,
            ..SolverOptions::default()
        },
        ..RunOptions::default()
    };
    let result = run(loaded(scene.clone()), &options, &NoProgress).expect("runs");
    let vis = Visibility::build(scene);
    let direct = DirectLight::new(scene, &vis);
    let r = scene.surface_id(receiver).expect("receiver");
    let e = direct_interpolation_error(
        scene,
        &direct,
        &result.mesh.surfaces[r],
        &result.solution.radiosity[r],
        10_000,
        7,
    );
    eprintln!(
        "{} {receiver} {method:?}: {} triangles in the scene, RMS {:.3e} ({:.3} % of the mean), max {:.3e}",
        scene.name,
        result.mesh.triangle_count(),
        e.rms,
        100.0 * e.rms / e.mean_exact,
        e.max
    );
    (e.rms, result.mesh.triangle_count())
}

/// At the default budget, discontinuity meshes cut the RMS error of the direct light on the floor
/// by 4.4x (textbook) and 3.3x (Cornell box) against uniform meshes of the same size. The goal is
/// 5x; these bounds guard what is reached so far.
#[test]
fn discontinuity_meshes_beat_uniform_ones_at_the_same_size() {
    for (scene, receiver, factor) in [
        (builtin::textbook(), "floor", 4.0),
        (builtin::cornell(), "floor", 3.0),
    ] {
        let (uniform, n_uniform) = direct_error(&scene, receiver, MeshMethod::Uniform, 10_000);
        let (discontinuity, n_discontinuity) =
            direct_error(&scene, receiver, MeshMethod::Discontinuity, 10_000);
        // The same element count, within the budget's rounding.
        assert!((n_uniform as f64 - n_discontinuity as f64).abs() <= 0.1 * n_uniform as f64);
        assert!(
            discontinuity * factor <= uniform,
            "{}: discontinuity RMS {discontinuity:e} vs uniform {uniform:e}",
            scene.name
        );
    }
}
