//! The scenes of `penumbra_scenes::extremes`, each held to the behaviour it must show. Every
//! solve here is also checked for NaN, infinities and negative radiosity.

mod common;

use common::in_process;
use glam::DVec3;
use penumbra::{RunOptions, RunResult};
use penumbra_scenes::{Scene, Visibility, extremes};
use penumbra_solver::{DirectLight, ReceivingPoint, SolverOptions};

fn solve(scene: Scene, direct_only: bool) -> RunResult {
    let options = RunOptions {
        max_elements: 3_000.into(),
        solver: SolverOptions {
            direct_only,
            ..SolverOptions::default()
        },
        ..RunOptions::default()
    };
    let result = in_process::run_scene(scene, options);
    assert_physical(&result);
    result
}

/// No NaN, no infinity, no negative radiosity anywhere; the energy account balances.
fn assert_physical(result: &RunResult) {
    for (s, values) in result.solution.radiosity.iter().enumerate() {
        for b in values {
            for c in [b.r, b.g, b.b] {
                assert!(c.is_finite() && c >= 0.0, "surface {s}: {b:?}");
            }
        }
    }
    let account = penumbra::energy::EnergyBalance::of(&result.solution.stats);
    assert!(account.balanced, "{account:?}");
}

/// The direct light at (x, 0, 0) on the floor (normal +z).
fn floor_light(direct: &DirectLight, floor: usize, x: f64) -> f64 {
    direct
        .irradiance(
            &ReceivingPoint::interior(DVec3::new(x, 0.0, 0.0), DVec3::Z),
            floor,
        )
        .r
}

fn surface_values(result: &RunResult, name: &str) -> Vec<f64> {
    let s = result.loaded.scene.surface_id(name).expect("surface");
    result.solution.radiosity[s]
        .iter()
        .map(|b| b.mean())
        .collect()
}

/// Irradiance at `x` (normal +z) from a small light of area `area` and exitance 1 at `at`
/// facing down: the point-light formula.
fn point_light(x: DVec3, at: DVec3, area: f64) -> f64 {
    let d = at - x;
    let r2 = d.length_squared();
    let cos_receiver = d.z / r2.sqrt();
    let cos_light = d.z / r2.sqrt();
    area * cos_receiver * cos_light / (std::f64::consts::PI * r2)
}

/// A light 1e-6 the size of the scene: the direct light is the point light's, and the blocker's
/// shadow is hard (zero inside |x|, |y| < 0.75, full outside), both to 1e-5 of the light's
/// unshadowed value (measured: 1.7e-6 left in the umbra, slivers of the light narrower than the
/// scene's tolerance that the subtraction keeps).
#[test]
fn a_tiny_light_casts_the_hard_shadow_of_a_point_light() {
    let side = 6e-6;
    let scene = extremes::tiny_light(side);
    let vis = Visibility::build(&scene);
    let direct = DirectLight::new(&scene, &vis);
    let floor = scene.surface_id("floor").expect("floor");
    let at = DVec3::new(0.0, 0.0, 3.0);
    for x in [0.0, 0.5, 0.74, 0.76, 1.0, 2.0, 2.9] {
        for y in [0.0, 0.3, 1.5] {
            let p = DVec3::new(x, y, 0.0);
            let h = direct
                .irradiance(&ReceivingPoint::interior(p, DVec3::Z), floor)
                .r;
            let in_shadow = x < 0.75 && y < 0.75;
            let expected = if in_shadow {
                0.0
            } else {
                point_light(p, at, side * side)
            };
            assert!(h.is_finite() && h >= 0.0);
            assert!(
                (h - expected).abs() <= 1e-5 * point_light(DVec3::ZERO, at, side * side),
                "({x}, {y}): {h:e} vs {expected:e}"
            );
        }
    }
    let result = solve(scene, false);
    let values = surface_values(&result, "floor");
    assert!(values.iter().any(|&b| b > 0.0));
}

/// A light facing away from everything lights nothing: every surface but the light is zero.
#[test]
fn a_light_facing_away_lights_nothing() {
    let result = solve(extremes::light_facing_away(), false);
    for name in ["floor", "blocker"] {
        assert!(
            surface_values(&result, name).iter().all(|&b| b == 0.0),
            "{name}"
        );
    }
    assert!(surface_values(&result, "light").iter().all(|&b| b == 1.0));
}

/// A receiver behind the light gets nothing directly; the floor in front does, and lights the
/// receiver in turn once the light bounces.
#[test]
fn a_receiver_behind_the_light_sees_only_reflected_light() {
    let direct = solve(extremes::receiver_behind_light(), true);
    assert!(surface_values(&direct, "ceiling").iter().all(|&b| b == 0.0));
    assert!(surface_values(&direct, "floor").iter().all(|&b| b > 0.0));
    let full = solve(extremes::receiver_behind_light(), false);
    assert!(surface_values(&full, "ceiling").iter().any(|&b| b > 0.0));
}

/// A light sealed in a box lights the box's inside and nothing outside.
#[test]
fn a_hidden_emitter_lights_nothing_outside_its_box() {
    let result = solve(extremes::hidden_emitter(), false);
    assert!(surface_values(&result, "floor").iter().all(|&b| b == 0.0));
    assert!(surface_values(&result, "box0").iter().any(|&b| b > 0.0));
}

/// A light barely above the floor's plane (10⁻² to 10⁻⁵ of its distance): every floor point sees
/// it at a grazing angle, where Lambert's contour sum cancels all but a few of its digits (at
/// 10⁻⁵, 54 % error) and the evaluator integrates directly instead: the exact direct light
/// agrees with a 400 × 400 midpoint rule over the light to 10⁻⁸.
#[test]
fn grazing_light_keeps_its_digits() {
    for height in [1e-2, 1e-5] {
        let scene = extremes::grazing_light(height);
        let vis = Visibility::build(&scene);
        let direct = DirectLight::new(&scene, &vis);
        let floor = scene.surface_id("floor").expect("floor");
        for x in [2.0, 3.0, 6.0] {
            let p = DVec3::new(x, 0.5, 0.0);
            let h = direct
                .irradiance(&ReceivingPoint::interior(p, DVec3::Z), floor)
                .r;
            let n = 400;
            let cell = 0.01 / n as f64;
            let mut sum = 0.0;
            for i in 0..n {
                for j in 0..n {
                    let q = DVec3::new(
                        -0.005 + cell * (i as f64 + 0.5),
                        -0.005 + cell * (j as f64 + 0.5),
                        height,
                    );
                    let d = q - p;
                    let r2 = d.length_squared();
                    sum += d.z * d.z / (std::f64::consts::PI * r2 * r2);
                }
            }
            let expected = sum * cell * cell;
            assert!(
                h > 0.0 && (h - expected).abs() <= 1e-8 * expected,
                "height {height}, x {x}: {h:e} vs {expected:e}"
            );
        }
        solve(scene, false);
    }
}

/// A blocker lying in the floor's plane hides nothing: the floor's direct light is the same, to
/// the last digits, as without it.
#[test]
fn a_coplanar_blocker_hides_nothing() {
    let with = solve(extremes::coplanar_blocker(true), true);
    let without = solve(extremes::coplanar_blocker(false), true);
    let (a, b) = (
        surface_values(&with, "floor"),
        surface_values(&without, "floor"),
    );
    let largest = b.iter().copied().fold(0.0, f64::max);
    // The meshes may differ (the blocker adds no lines, but the budget is shared), so compare the
    // exact evaluator at the vertices of one mesh.
    let scene = extremes::coplanar_blocker(true);
    let bare = extremes::coplanar_blocker(false);
    let (vis, bare_vis) = (Visibility::build(&scene), Visibility::build(&bare));
    let (direct, bare_direct) = (
        DirectLight::new(&scene, &vis),
        DirectLight::new(&bare, &bare_vis),
    );
    let floor = scene.surface_id("floor").expect("floor");
    for p in &with.mesh.surfaces[floor].points3 {
        let x = ReceivingPoint::interior(*p, DVec3::Z);
        let (h, h0) = (
            direct.irradiance(&x, floor).r,
            bare_direct.irradiance(&x, floor).r,
        );
        assert!((h - h0).abs() <= 1e-12 * largest, "{p}: {h} vs {h0}");
    }
    assert!(a.iter().all(|&v| v > 0.0) && largest > 0.0);
}

/// A cube standing on the floor: its footprint is four contact lines (D0); just inside it the
/// floor gets no light (to 1e-9 of the light outside), just outside it gets the open floor's.
#[test]
fn a_touching_blocker_makes_the_light_jump() {
    let scene = extremes::touching_blocker();
    let vis = Visibility::build(&scene);
    let found =
        penumbra_meshing::discontinuity::find_discontinuities(&scene, &vis, &Default::default());
    let floor = scene.surface_id("floor").expect("floor");
    let contacts: Vec<_> = found.segments[floor]
        .iter()
        .filter(|s| s.event == penumbra_meshing::discontinuity::Event::Contact)
        .collect();
    assert_eq!(contacts.len(), 4, "{contacts:#?}");
    for s in &contacts {
        assert_eq!(s.order, 0);
        for p in [s.from, s.to] {
            assert!((p.x.abs() - 0.5).abs() < 1e-12 || (p.y.abs() - 0.5).abs() < 1e-12);
        }
    }
    let direct = DirectLight::new(&scene, &vis);
    let at = |x: f64| floor_light(&direct, floor, x);
    // Just inside, nothing but rounding (measured 3.5e-13 against 0.03 outside: a sliver of the
    // light narrower than the scene's tolerance).
    let eps = 1e-6;
    assert!(at(0.5 + eps) > 0.01, "{}", at(0.5 + eps));
    assert!(at(0.5 - eps) <= 1e-9 * at(0.5 + eps), "{}", at(0.5 - eps));
    let result = solve(scene, false);
    // The floor's vertices on the footprint come in pairs: one dark, one lit.
    let m = &result.mesh.surfaces[floor];
    let values = &result.solution.radiosity[floor];
    let on_edge: Vec<usize> = (0..m.vertex_count())
        .filter(|&v| {
            let p = m.points3[v];
            (p.x - 0.5).abs() < 1e-9 && p.y.abs() < 0.4
        })
        .collect();
    assert!(on_edge.iter().any(|&v| values[v].mean() > 0.0));
    assert!(on_edge.iter().any(|&v| values[v].mean() < 0.01 * values.iter().map(|b| b.mean()).fold(0.0, f64::max)));
}

/// Three floor tiles meeting in a T, each meshed on its own: on either side of every seam the
/// interpolated light agrees within the interpolation error of the meshes. Each tile is refined
/// to 0.5 % RMS of its mean (about half the peak), which leaves some points a few times that
/// off: 1 % of the peak (measured up to 0.72 %).
#[test]
fn light_is_continuous_across_t_junctions() {
    let scene = extremes::t_junction();
    let result = solve(scene.clone(), true);
    let locate = |name: &str, p: DVec3| {
        let s = scene.surface_id(name).expect("tile");
        let m = &result.mesh.surfaces[s];
        penumbra_meshing::TriangleLocator::new(m)
            .interpolate(m, &result.solution.radiosity[s], p)
            .mean()
    };
    let peak = surface_values(&result, "left")
        .iter()
        .copied()
        .fold(0.0, f64::max);
    let eps = 1e-9;
    for k in 0..=20 {
        let y = -1.9 + 3.8 * k as f64 / 20.0;
        let right = if y < 0.0 {
            "lower_right"
        } else {
            "upper_right"
        };
        let (l, r) = (
            locate("left", DVec3::new(-eps, y, 0.0)),
            locate(right, DVec3::new(eps, y, 0.0)),
        );
        assert!((l - r).abs() <= 1e-2 * peak, "y {y}: {l} vs {r}");
    }
    for k in 0..=10 {
        let x = 0.1 + 1.8 * k as f64 / 10.0;
        let (lo, hi) = (
            locate("lower_right", DVec3::new(x, -eps, 0.0)),
            locate("upper_right", DVec3::new(x, eps, 0.0)),
        );
        assert!((lo - hi).abs() <= 1e-2 * peak, "x {x}: {lo} vs {hi}");
    }
}

/// Wedge lines 1e-9 of the scene apart (two blockers whose edges almost touch) and, for
/// comparison, 1e-3 apart: the mesh is sane, every constraint a chain of edges, within budget,
/// with no triangle smaller than 1e-8 of the floor: no sliver chased between the lines, which
/// would be under 1e-9 (measured: 2.5e-5 for the billionth, where the lines merge; 2.4e-7 for
/// the thousandth, a real strip).
#[test]
fn wedge_lines_a_billionth_apart_mesh_sanely() {
    for gap in [1e-9 * 6.0, 1e-3] {
        let scene = extremes::close_wedges(gap);
        let vis = Visibility::build(&scene);
        let found = penumbra_meshing::discontinuity::find_discontinuities(
            &scene,
            &vis,
            &Default::default(),
        );
        let mesh = penumbra_meshing::mesh_scene_discontinuity(&scene, &vis, found, 3_000, 8.0)
            .expect("meshes");
        mesh.sanity_check().expect("sane");
        assert!(mesh.triangle_count() <= 3_000);
        let floor = scene.surface_id("floor").expect("floor");
        let m = &mesh.surfaces[floor];
        let smallest = (0..m.triangle_count())
            .map(|t| m.triangle_area(t))
            .fold(f64::INFINITY, f64::min);
        eprintln!(
            "gap {gap}: smallest triangle {:e} of the floor",
            smallest / m.area()
        );
        assert!(
            smallest > 1e-8 * m.area(),
            "gap {gap}: a triangle of {smallest:e}"
        );
        solve(scene, false);
    }
}

/// Light edges parallel to blocker edges (`docs/closed-forms.md`, "Boundary lines", blocker side
/// 1.2): the EV wedges of an edge's two ends coincide with its EE wedge. They merge into one line
/// each, no line drawn twice: the floor gets exactly the eight lines |x| or |y| = 0.65 (umbra) and
/// 1.15 (penumbra), each from -1.15 to 1.15, all D1. The direct light is D1 there in fact: zero at
/// x_u with slope 0 inside and 0.0691146221 outside (the closed form there).
#[test]
fn parallel_edges_give_single_d1_lines() {
    let scene = extremes::parallel_edges(1.2);
    let vis = Visibility::build(&scene);
    let found =
        penumbra_meshing::discontinuity::find_discontinuities(&scene, &vis, &Default::default());
    let floor = scene.surface_id("floor").expect("floor");
    let (x_u, x_p) = (0.65, 1.15);
    // Covered length per line: (axis, signed offset).
    let mut covered: std::collections::BTreeMap<(usize, i64), f64> = Default::default();
    for s in &found.segments[floor] {
        assert_eq!(s.order, 1, "{s:?}");
        let d = s.to - s.from;
        let axis = if d.x.abs() < 1e-12 { 0 } else { 1 }; // the coordinate that is constant
        let at = if axis == 0 { s.from.x } else { s.from.y };
        assert!(
            [x_u, x_p].iter().any(|&l| (at.abs() - l).abs() < 1e-12),
            "a segment off the eight lines: {s:?}"
        );
        for p in [s.from, s.to] {
            let along = if axis == 0 { p.y } else { p.x };
            assert!(along.abs() <= x_p + 1e-12, "{s:?}");
        }
        *covered
            .entry((axis, (at * 1e6).round() as i64))
            .or_default() += d.length();
    }
    assert_eq!(covered.len(), 8, "{covered:?}");
    for (line, length) in &covered {
        assert!(
            (length - 2.0 * x_p).abs() < 1e-9,
            "line {line:?} covered {length}"
        );
    }
    let direct = DirectLight::new(&scene, &vis);
    let at = |x: f64| floor_light(&direct, floor, x);
    let h = 1e-6;
    assert!(at(x_u).abs() < 1e-12 && at(x_u - h).abs() < 1e-12);
    let slope = (at(x_u + h) - at(x_u)) / h;
    assert!((slope - 0.0691146221).abs() < 1e-6, "{slope}");
    let result = solve(scene, false);
    let m = &result.mesh.surfaces[floor];
    let on_line = (0..m.vertex_count())
        .filter(|&v| (m.points3[v].x - x_u).abs() < 1e-9 && m.points3[v].y.abs() < x_p)
        .count();
    assert!(on_line >= 3, "{on_line} mesh vertices on the umbra line");
}
