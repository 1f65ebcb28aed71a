//! The CIE 171:2006 analytic test cases that fit diffuse polygon scenes (5.3, 5.6, 5.8; the scenes
//! are `penumbra_scenes::cie`), held to the CIE's pass criteria: every point within 5 % of the
//! reference and the points' mean error within 10 %. The references are closed forms: the
//! corner-rectangle form factors of `docs/closed-forms.md`, "Rectangles by superposition", combined
//! by superposition, and for 5.8 the flux balance of the enclosure ("An enclosure lit inside").
//! penumbra is far inside the criteria, so each test also holds it to its own measured accuracy.

use std::f64::consts::PI;

use glam::DVec3;
use penumbra::{RunOptions, run};
use penumbra_meshing::TriangleLocator;
use penumbra_meshing::{SceneMesh, mesh_scene_uniform};
use penumbra_scenes::{LoadedScene, Rgb, Scene, Visibility, cie};
use penumbra_solver::PatchSystem;
use penumbra_solver::{
    NoProgress, SolverMethod, SolverOptions, solve_hierarchical, solve_progressive,
};

/// `docs/closed-forms.md`, "Rectangles by superposition": a point under the corner of an a × b
/// rectangle in a parallel plane at distance c.
fn parallel_corner(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * PI)
}

/// `docs/closed-forms.md`, "Rectangles by superposition": a point whose plane holds one edge
/// (of width b, starting at the foot of the perpendicular) of an a (height) × b rectangle at
/// distance c.
fn perpendicular_corner(a: f64, b: f64, c: f64) -> f64 {
    if a <= 0.0 || b <= 0.0 {
        return 0.0;
    }
    let (x, y) = (a / b, c / b);
    let r = (x * x + y * y).sqrt();
    ((1.0 / y).atan() - y / r * (1.0 / r).atan()) / (2.0 * PI)
}

/// Corner form factors with signed extents, for superposition.
fn signed(f: impl Fn(f64, f64) -> f64, u: f64, w: f64) -> f64 {
    u.signum() * w.signum() * f(u.abs(), w.abs())
}

/// From a point to the rectangle [x0, x1] × [y0, y1] of a parallel plane at distance c, in the
/// point's own coordinates (the point at the origin).
fn parallel(x: [f64; 2], y: [f64; 2], c: f64) -> f64 {
    let g = |u: f64, w: f64| signed(|a, b| parallel_corner(a, b, c), u, w);
    g(x[1], y[1]) - g(x[0], y[1]) - g(x[1], y[0]) + g(x[0], y[0])
}

/// From a point to a rectangle in a perpendicular plane at distance c: `height` is its extent
/// away from the point's plane (along the point's normal), `width` its extent along the line
/// where the planes meet, both relative to the point.
fn perpendicular(height: [f64; 2], width: [f64; 2], c: f64) -> f64 {
    let g = |h: f64, w: f64| w.signum() * perpendicular_corner(h, w.abs(), c);
    (g(height[1], width[1]) - g(height[1], width[0]))
        - (g(height[0], width[1]) - g(height[0], width[0]))
}

/// A measuring point: where it is, on which surface, and its reference illuminance.
struct Point {
    at: DVec3,
    surface: &'static str,
    reference: f64,
}

/// Interpolated values of a per-vertex field at the points.
fn interpolate(scene: &Scene, mesh: &SceneMesh, field: &[Vec<Rgb>], points: &[Point]) -> Vec<f64> {
    points
        .iter()
        .map(|p| {
            let s = scene.surface_id(p.surface).expect("surface");
            let m = &mesh.surfaces[s];
            TriangleLocator::new(m)
                .interpolate(m, &field[s], p.at)
                .mean()
        })
        .collect()
}

/// Relative errors, checked against the CIE's criteria (5 % per point, 10 % in the mean) and
/// against `bound`, penumbra's own; returns the worst.
fn check(case: &str, points: &[Point], values: &[f64], bound: f64) -> f64 {
    let errors: Vec<f64> = points
        .iter()
        .zip(values)
        .map(|(p, v)| (v - p.reference) / p.reference)
        .collect();
    for (p, (v, e)) in points.iter().zip(values.iter().zip(&errors)) {
        eprintln!(
            "{case} {} {:?}: {v:.4} lx against {:.4} ({:+.4} %)",
            p.surface,
            p.at,
            p.reference,
            100.0 * e
        );
        assert!(v.is_finite() && *v >= 0.0);
    }
    let worst = errors.iter().fold(0.0f64, |w, e| w.max(e.abs()));
    let mean = errors.iter().map(|e| e.abs()).sum::<f64>() / errors.len() as f64;
    assert!(worst <= 0.05, "{case}: a point is {worst} off (CIE: 5 %)");
    assert!(mean <= 0.10, "{case}: mean error {mean} (CIE: 10 %)");
    assert!(
        worst <= bound,
        "{case}: worst {worst} over penumbra's own bound {bound}"
    );
    worst
}

/// Runs the pipeline on `scene` with default options; the illuminance at the points,
/// interpolated on the mesh.
fn solve_at(scene: Scene, points: &[Point]) -> Vec<f64> {
    let loaded = LoadedScene {
        scene,
        source: "cie".into(),
        warnings: Vec::new(),
    };
    let options = RunOptions {
        render: penumbra_viz::RenderOptions {
            width: 16,
            height: 16,
            ..Default::default()
        },
        ..RunOptions::default()
    };
    let result = run(loaded, &options, &NoProgress).expect("solves");
    interpolate(
        &result.loaded.scene,
        &result.mesh,
        &result.solution.irradiance,
        points,
    )
}

/// 5.3: the 1 m square source (exitance π × 1000) in the ceiling at height 3, over floor points
/// (a parallel plane) and points of the wall x = 0 (perpendicular: the source lies 1.5 to 2.5 m
/// out from the wall, 3 − z above the point).
#[test]
fn cie_5_3_area_source() {
    let m = cie::SOURCE_EXITANCE;
    let (s0, s1) = (1.5, 2.5);
    let floor = |x: f64, y: f64| Point {
        at: DVec3::new(x, y, 0.0),
        surface: "floor",
        reference: m * parallel([s0 - x, s1 - x], [s0 - y, s1 - y], 3.0),
    };
    let wall = |y: f64, z: f64| Point {
        at: DVec3::new(0.0, y, z),
        surface: "wall_x0",
        reference: m * perpendicular([s0, s1], [s0 - y, s1 - y], 3.0 - z),
    };
    let points = vec![
        floor(2.0, 2.0),
        floor(2.5, 2.0),
        floor(3.0, 2.0),
        floor(3.5, 2.0),
        floor(3.0, 3.0),
        floor(3.5, 3.5),
        floor(1.0, 0.5),
        wall(2.0, 0.5),
        wall(2.0, 1.5),
        wall(2.0, 2.5),
        wall(1.0, 1.5),
        wall(0.5, 2.5),
    ];
    // The centre of the floor: 1000 π × F(1.1, four 0.5 × 0.5 corners at 3) ≈ 103.5 lx.
    assert!((points[0].reference - 4.0 * m * parallel_corner(0.5, 0.5, 3.0)).abs() < 1e-9);
    let values = solve_at(cie::area_source(), &points);
    check("5.3", &points, &values, 1e-2);
}

/// 5.6: the uniformly lit floor (exitance 500) seen from the ceiling (parallel, 3 m) and from the
/// wall x = 0 (perpendicular: the floor reaches 4 m out from the wall, z below the point).
#[test]
fn cie_5_6_floor_reflection() {
    let m = cie::FLOOR_EXITANCE;
    let ceiling = |x: f64, y: f64| Point {
        at: DVec3::new(x, y, 3.0),
        surface: "ceiling",
        reference: m * parallel([-x, 4.0 - x], [-y, 4.0 - y], 3.0),
    };
    let wall = |y: f64, z: f64| Point {
        at: DVec3::new(0.0, y, z),
        surface: "wall_x0",
        reference: m * perpendicular([0.0, 4.0], [-y, 4.0 - y], z),
    };
    let points = vec![
        ceiling(2.0, 2.0),
        ceiling(3.0, 2.0),
        ceiling(3.5, 3.5),
        ceiling(1.0, 0.5),
        wall(2.0, 0.5),
        wall(2.0, 1.5),
        wall(2.0, 2.5),
        wall(0.5, 1.5),
        wall(3.5, 2.5),
    ];
    let values = solve_at(cie::floor_reflection(), &points);
    check("5.6", &points, &values, 2e-3);
}

/// The area means of `values` (per surface and vertex, linear over each triangle) over the six
/// faces of 5.8's cube, checked against `reference` by [`check`].
fn check_face_means(
    case: &str,
    scene: &Scene,
    mesh: &SceneMesh,
    values: &[Vec<f64>],
    reference: f64,
    bound: f64,
) {
    let faces = [
        "floor", "wall_x0", "wall_x1", "wall_y0", "wall_y1", "ceiling",
    ];
    let means: Vec<f64> = faces
        .iter()
        .map(|&face| {
            let s = scene.surface_id(face).expect("face");
            let m = &mesh.surfaces[s];
            let (mut sum, mut covered) = (0.0, 0.0);
            for (t, tri) in m.triangles.iter().enumerate() {
                let a = m.triangle_area(t);
                sum += a * tri.iter().map(|&v| values[s][v as usize]).sum::<f64>() / 3.0;
                covered += a;
            }
            sum / covered
        })
        .collect();
    let points: Vec<Point> = faces
        .iter()
        .map(|&surface| Point {
            at: DVec3::ZERO,
            surface,
            reference,
        })
        .collect();
    check(case, &points, &means, bound);
}

/// 5.8: the 4 m cube at reflectances 0.05 to 0.95, solved exactly (the dense solve of the patch
/// system, since at 0.95 shooting takes thousands of shots). The reflected illuminance (total
/// less the exact direct light, vertex by vertex) against Φ ρ / (S (1 − ρ)).
///
/// That formula is the flux balance of an enclosure: exact for the mean over its surfaces, and
/// for each face's mean here (the source sits at the cube's centre, so the faces are alike). The
/// CIE criteria are applied to the six face means. At single points it holds only where the
/// light has bounced often enough to even out: the first bounce keeps the direct light's
/// unevenness (under a point source at the centre a face is lit five times more at its centre
/// than at its corners), so at 0.05 the face centres get 8.5 % more than the mean, and the excess
/// shrinks as ρ grows. The test holds the points to that physics: the worst point's deviation
/// falls with every step of ρ and is under 1 % at 0.95.
#[test]
fn cie_5_8_inter_reflection() {
    let area = 6.0 * cie::CUBE_SIDE * cie::CUBE_SIDE;
    let mut previous = f64::INFINITY;
    for rho in [0.05, 0.2, 0.5, 0.8, 0.95] {
        let scene = cie::reflecting_cube(rho);
        let visibility = Visibility::build(&scene);
        let mesh = mesh_scene_uniform(&scene, 6000).expect("meshes");
        let options = SolverOptions::default();
        let system = PatchSystem::assemble(&scene, &mesh, &visibility, &options, &NoProgress)
            .expect("assembles");
        let solved = system
            .solve(SolverMethod::Direct, 1e-12, 1, &|| None)
            .expect("solves");
        let total = system.irradiance(&solved.patch_radiosity);
        let reflected: Vec<Rgb> = total
            .iter()
            .zip(&system.direct)
            .map(|(&h, &d)| h - d)
            .collect();
        let reference = cie::reflected_illuminance(cie::CUBE_FLUX, area, rho);
        let means: Vec<Vec<f64>> = system
            .disc
            .per_surface(&reflected.iter().map(|h| h.mean()).collect::<Vec<_>>());
        let case = format!("5.8 rho {rho}, face means");
        check_face_means(&case, &scene, &mesh, &means, reference, 5e-3);
        // Points: the centre of every face, and off-centre floor and wall points.
        let field = system.disc.per_surface(&reflected);
        let point = |x: f64, y: f64, z: f64, surface: &'static str| Point {
            at: DVec3::new(x, y, z),
            surface,
            reference,
        };
        let points = vec![
            point(2.0, 2.0, 0.0, "floor"),
            point(2.0, 2.0, 4.0, "ceiling"),
            point(0.0, 2.0, 2.0, "wall_x0"),
            point(4.0, 2.0, 2.0, "wall_x1"),
            point(2.0, 0.0, 2.0, "wall_y0"),
            point(2.0, 4.0, 2.0, "wall_y1"),
            point(1.0, 1.0, 0.0, "floor"),
            point(3.0, 2.0, 0.0, "floor"),
            point(0.0, 1.0, 3.0, "wall_x0"),
        ];
        let values = interpolate(&scene, &mesh, &field, &points);
        let worst = points
            .iter()
            .zip(&values)
            .map(|(p, v)| ((v - p.reference) / p.reference).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "5.8 rho {rho}: worst point {:.3} % from the mean",
            100.0 * worst
        );
        assert!(values.iter().all(|v| v.is_finite() && *v > 0.0));
        assert!(worst < previous, "rho {rho}: {worst} after {previous}");
        previous = worst;
    }
    assert!(previous < 1e-2, "{previous}");
}

/// 5.8 with the hierarchical solver at its default tolerances: the six face means of the
/// reflected illuminance (its total less the exact direct light, vertex by vertex) within 0.5 %
/// of the flux balance, at every reflectance up to 0.99, where the light bounces a hundred
/// times. A link that delivers a little less of a bright source's light than it sends loses
/// that at every bounce; the solver gives the light its links lose back as ambient light
/// (measured: within 0.12 % at ρ = 0.05 and 0.5, 0.16 % at 0.95; before, 0.6 to 1.8 %).
#[test]
fn cie_5_8_inter_reflection_hierarchical() {
    let area = 6.0 * cie::CUBE_SIDE * cie::CUBE_SIDE;
    for rho in [0.05, 0.2, 0.5, 0.8, 0.95, 0.99] {
        let scene = cie::reflecting_cube(rho);
        let visibility = Visibility::build(&scene);
        let mesh = mesh_scene_uniform(&scene, 6000).expect("meshes");
        let options = SolverOptions::default();
        let full =
            solve_hierarchical(&scene, &mesh, &visibility, &options, &NoProgress).expect("solves");
        let direct_only = SolverOptions {
            direct_only: true,
            ..options
        };
        let direct = solve_progressive(&scene, &mesh, &visibility, &direct_only, &NoProgress)
            .expect("solves");
        let reference = cie::reflected_illuminance(cie::CUBE_FLUX, area, rho);
        let reflected: Vec<Vec<f64>> = full
            .irradiance
            .iter()
            .zip(&direct.irradiance)
            .map(|(f, d)| f.iter().zip(d).map(|(&f, &d)| (f - d).mean()).collect())
            .collect();
        let case = format!("5.8 hierarchical, rho {rho}, face means");
        check_face_means(&case, &scene, &mesh, &reflected, reference, 5e-3);
    }
}
