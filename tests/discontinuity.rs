//! Discontinuity meshing against the closed forms of the textbook scene, and against uniform
//! meshing at the same element count.

use glam::DVec3;
use penumbra::{MeshMethod, RunOptions, run};
use penumbra_meshing::discontinuity::{
    Boundary, DiscontinuityOptions, Event, find_discontinuities,
};
use penumbra_scenes::polygon::closest_point_on_segment;
use penumbra_scenes::{LoadedScene, Scene, Visibility, builtin};
use penumbra_solver::direct_interpolation_error;
use penumbra_solver::{DirectLight, NoProgress, SolverOptions};

fn loaded(scene: Scene) -> LoadedScene {
    LoadedScene {
        scene,
        source: "test".into(),
        warnings: Vec::new(),
    }
}

/// `docs/closed-forms.md`, "Boundary lines": on the textbook floor, 8 segments of order 1 at
/// x, y = ±0.5 (umbra) and ±1 (outer penumbra), each running |other coordinate| <= 1.
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
        max_elements: max_elements.into(),
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

/// At the default budget, discontinuity meshes (lines as constraint edges, penumbrae graded 8x
/// finer) cut the RMS error of the direct light on the floor at least 5-fold against uniform
/// meshes of the same size: 13x on the textbook scene, 6x in the Cornell box.
#[test]
fn discontinuity_meshes_beat_uniform_ones_at_the_same_size() {
    for (scene, receiver, factor) in [
        (builtin::textbook(), "floor", 5.0),
        (builtin::cornell(), "floor", 5.0),
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

/// Jumps across a line at `x` (direction `across`, in the receiver's plane) of the first and
/// second derivatives of the direct light, each divided by the same difference taken over a
/// stretch beside the line (where the light is smooth, so that difference is only its higher
/// derivatives times the stretch).
fn derivative_jumps(
    direct: &DirectLight,
    receiver: usize,
    normal: DVec3,
    x: DVec3,
    across: DVec3,
    h: f64,
) -> (f64, f64) {
    let f = |t: f64| {
        direct
            .irradiance(
                &penumbra_solver::ReceivingPoint::interior(x + across * (t * h), normal),
                receiver,
            )
            .mean()
    };
    let slope = |a: f64, b: f64| (f(b) - f(a)) / ((b - a) * h);
    let curvature = |c: f64| (f(c - 1.0) - 2.0 * f(c) + f(c + 1.0)) / (h * h);
    // Across the line: one-sided differences at -2h and +2h; beside it, the same 4h apart
    // but centred 10h away.
    let d1 = (slope(1.0, 3.0) - slope(-3.0, -1.0)).abs();
    let d1_beside = (slope(11.0, 13.0) - slope(7.0, 9.0)).abs();
    let d2 = (curvature(2.5) - curvature(-2.5)).abs();
    let d2_beside = (curvature(12.5) - curvature(7.5)).abs();
    (d1 / d1_beside.max(1e-300), d2 / d2_beside.max(1e-300))
}

/// EEE curves are where the light's second derivative jumps (D2); the planar ones, where a
/// blocker face's plane cuts the emitter, are where its slope jumps (D1). Both are checked with
/// the exact evaluator, which knows nothing of events: differences across each curve against
/// the same differences beside it.
#[test]
fn eee_curves_are_where_the_light_changes_form() {
    for (scene, receiver, want_order) in [
        (builtin::crossed_bars(), "floor", 2u8),
        (builtin::cornell(), "floor", 1u8),
    ] {
        let vis = Visibility::build(&scene);
        let found = find_discontinuities(&scene, &vis, &DiscontinuityOptions::default());
        assert!(
            found.stats.eee_events > 0,
            "{}: {:?}",
            scene.name,
            found.stats
        );
        let direct = DirectLight::new(&scene, &vis);
        let r = scene.surface_id(receiver).expect("receiver");
        let normal = scene.surfaces[r].normal();
        let curves: Vec<_> = found.segments[r]
            .iter()
            .filter(|s| s.event == Event::Eee && s.order == want_order)
            .collect();
        assert!(
            !curves.is_empty(),
            "{}: no EEE of order {want_order}: {:?}",
            scene.name,
            found.stats
        );
        let h = 1e-6 * scene.diagonal();
        let mut checked = 0;
        for s in curves {
            let mid = 0.5 * (s.from + s.to);
            let across = normal.cross(s.to - s.from).normalize();
            // Other lines within the stencil would confuse the check; skip those spots.
            let crowded = found.segments[r].iter().any(|o| {
                !std::ptr::eq(o, s)
                    && closest_point_on_segment(mid, o.from, o.to).distance(mid) < 20.0 * h
            });
            if crowded || s.from.distance(s.to) < 100.0 * h {
                continue;
            }
            let (d1, d2) = derivative_jumps(&direct, r, normal, mid, across, h);
            let jump = if want_order == 1 { d1 } else { d2 };
            assert!(
                jump > 20.0,
                "{}: {:?} segment {:.4} -> {:.4}: derivative jump only {jump:.2} times the \
                 difference beside it (d1 {d1:.2}, d2 {d2:.2})",
                scene.name,
                s.event,
                s.from,
                s.to
            );
            checked += 1;
        }
        assert!(checked > 0, "{}: every EEE segment was crowded", scene.name);
        eprintln!(
            "{}: {checked} EEE segments of order {want_order} checked",
            scene.name
        );
    }
}

/// The Cornell light hangs 0.1 below the ceiling: its outline, projected onto the ceiling, is a
/// contact line (the ceiling above it sees almost nothing), and the vertices on it are evaluated
/// ten gaps (1.0) off the line, each on its own side. Nothing else hovers.
#[test]
fn a_hovering_light_casts_contact_lines_on_the_ceiling() {
    let scene = builtin::cornell();
    let vis = Visibility::build(&scene);
    let found = find_discontinuities(&scene, &vis, &DiscontinuityOptions::default());
    let ceiling = scene.surface_id("ceiling").expect("ceiling");
    let light = &scene.surfaces[scene.surface_id("light").expect("light")].polygon;
    let on_outline = |p: DVec3| {
        (0..light.len()).any(|i| {
            let (a, b) = (light[i], light[(i + 1) % light.len()]);
            let (a, b) = (DVec3::new(a.x, 548.8, a.z), DVec3::new(b.x, 548.8, b.z));
            p.distance(closest_point_on_segment(p, a, b)) < 1e-9 * 1000.0
        })
    };
    let contacts: Vec<_> = found.segments[ceiling]
        .iter()
        .filter(|s| s.event == Event::Contact)
        .collect();
    assert_eq!(contacts.len(), 4, "{contacts:#?}");
    for s in &contacts {
        assert_eq!(s.order, 0);
        assert!(on_outline(s.from) && on_outline(s.to), "{s:?}");
    }
    assert_eq!(found.hovering[ceiling].len(), 4);
    for (gap, hovering) in found.hovering.iter().enumerate().map(|(s, h)| (s, h.len())) {
        assert!(gap == ceiling || hovering == 0);
    }
    for h in &found.hovering[ceiling] {
        assert!((h.2 - 0.1).abs() < 1e-9, "gap {}", h.2);
    }
    // Vertices on the outline are split, and each copy is evaluated 1.0 into its own triangles.
    let mesh = penumbra_meshing::mesh_scene_discontinuity(&scene, &vis, found, 10_000, 8.0)
        .expect("meshes");
    let disc = penumbra_solver::Discretization::new(&scene, &mesh, 24);
    let m = &mesh.surfaces[ceiling];
    let offset = disc.offsets[ceiling];
    let mut lifted = 0;
    for v in 0..m.vertex_count() {
        let x = &disc.receivers[offset + v];
        if on_outline(m.points3[v]) {
            let lift = x.point.distance(m.points3[v]);
            assert!(
                lift > 0.0 && lift <= 1.0 + 1e-9,
                "vertex {v}: lifted {lift}"
            );
            lifted += 1;
        } else {
            assert_eq!(x.point, m.points3[v]);
        }
    }
    assert!(lifted >= 8, "{lifted} vertices on the outline");
}

/// Complete events are classified by what each side of them sees: a square blocker turned 45°
/// under a square light, and a pentagon under a triangle, in parallel planes. A line with one
/// side in full light is an outer penumbra boundary, one with a side in full shadow an umbra
/// boundary, and the lines that completeness adds lie inside the penumbra, of order 2 (no edge of
/// the blocker is parallel to one of the light's).
#[test]
fn complete_events_are_classified_by_what_each_side_sees() {
    use penumbra_meshing::discontinuity::EventSet;
    use penumbra_scenes::{Rgb, Surface};
    use penumbra_solver::ReceivingPoint;
    let regular = |n: usize, radius: f64, center: DVec3, turn: f64| -> Vec<DVec3> {
        // Listed clockwise seen from above: facing down.
        (0..n)
            .rev()
            .map(|i| {
                let a = turn + std::f64::consts::TAU * i as f64 / n as f64;
                center + DVec3::new(radius * a.cos(), radius * a.sin(), 0.0)
            })
            .collect()
    };
    for (n, k, blocker_turn) in [(4, 4, std::f64::consts::FRAC_PI_4), (3, 5, 1.3)] {
        let grey = Rgb::splat(0.5);
        let mut floor = regular(4, 20.0, DVec3::ZERO, 0.3);
        floor.reverse();
        let scene = Scene {
            up: None,
            unit: None,
            name: "parallel".into(),
            camera: None,
            surfaces: vec![
                Surface::new(
                    "light",
                    regular(n, 0.6, DVec3::new(0.0, 0.0, 3.0), 0.0),
                    Rgb::ZERO,
                )
                .with_emission(Rgb::splat(1.0)),
                Surface::new(
                    "blocker",
                    regular(k, 0.45, DVec3::new(0.05, -0.02, 1.2), blocker_turn),
                    grey,
                ),
                Surface::new("floor", floor, grey),
            ],
        };
        let vis = Visibility::build(&scene);
        let options = DiscontinuityOptions {
            events: EventSet::Complete,
            ..DiscontinuityOptions::default()
        };
        let found = find_discontinuities(&scene, &vis, &options);
        let direct = DirectLight::new(&scene, &vis);
        let light = &scene.surfaces[0].polygon;
        let tol = vis.contact_distance();
        // The share of the light seen from a floor point.
        let seen = |p: DVec3| {
            let x = ReceivingPoint::interior(p, DVec3::Z);
            direct.form_factor_visible(&x, 2, 0) / penumbra_solver::form_factor(&x, light, tol)
        };
        let mut inner = 0;
        for g in &found.segments[2] {
            let mid = (g.from + g.to) / 2.0;
            let across = (g.to - g.from).cross(DVec3::Z).normalize() * 1e-6;
            let sides = [seen(mid + across), seen(mid - across)];
            let expected = if sides.iter().any(|&f| f < 1e-9) {
                Boundary::Umbra
            } else if sides.iter().any(|&f| f > 1.0 - 1e-9) {
                Boundary::Penumbra
            } else {
                Boundary::Inner
            };
            assert_eq!(
                g.boundary, expected,
                "{n}-gon over {k}-gon: {g:?} sees {sides:?}"
            );
            // No edge of the blocker is parallel to one of the light's: the curvature jumps.
            if expected == Boundary::Inner {
                assert_eq!(g.order, 2, "{n}-gon over {k}-gon: {g:?}");
                inner += 1;
            }
        }
        assert!(inner > 0, "{n}-gon over {k}-gon: no inner lines");
    }
}
