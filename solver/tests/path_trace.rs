//! The path-traced reference against closed forms and the exact direct light.

use glam::DVec3;
use penumbra_scenes::{Visibility, builtin};
use penumbra_solver::path_trace::{PathTraceOptions, PathTracer};
use penumbra_solver::{DirectLight, ReceivingPoint};

/// A closed cube whose faces all emit E = 1 and reflect ρ: B = E / (1 - ρ) everywhere. The
/// estimate must agree within 4 standard errors, and the error must be small.
#[test]
fn furnace_radiosity_is_e_over_one_minus_rho() {
    for rho in [0.5, 0.9] {
        let scene = builtin::furnace(1.0, rho);
        let vis = Visibility::build(&scene);
        let tracer = PathTracer::new(&scene, &vis);
        let floor = scene.surface_id("floor").expect("floor");
        let points: Vec<(DVec3, usize)> = [
            DVec3::new(0.5, 0.5, 0.0),
            DVec3::new(0.1, 0.8, 0.0),
            DVec3::new(0.97, 0.03, 0.0),
        ]
        .into_iter()
        .map(|p| (p, floor))
        .collect();
        let values = tracer.radiosity(
            &points,
            &PathTraceOptions {
                paths: 4000,
                seed: 3,
            },
        );
        let exact = 1.0 / (1.0 - rho);
        for v in values {
            let b = v.radiosity.mean();
            assert!(
                (b - exact).abs() <= 4.0 * v.standard_error + 1e-9,
                "rho {rho}: {b} ± {} against {exact}",
                v.standard_error
            );
            assert!(v.standard_error < 0.02 * exact, "{v:?}");
        }
    }
}

/// On the textbook floor nothing reflects light back (the blocker turns its back to the floor
/// and the light reflects nothing): the reference is the exact direct radiosity, without noise.
#[test]
fn where_nothing_reflects_the_reference_is_the_direct_light() {
    let scene = builtin::textbook();
    let vis = Visibility::build(&scene);
    let tracer = PathTracer::new(&scene, &vis);
    let direct = DirectLight::new(&scene, &vis);
    let floor = scene.surface_id("floor").expect("floor");
    let points: Vec<(DVec3, usize)> = [0.0, 0.6, 0.8, 1.5]
        .into_iter()
        .map(|x| (DVec3::new(x, 0.3, 0.0), floor))
        .collect();
    let values = tracer.radiosity(&points, &PathTraceOptions { paths: 64, seed: 1 });
    let rho = scene.surfaces[floor].reflectance;
    for ((p, _), v) in points.iter().zip(values) {
        let exact = rho.mul_rgb(direct.irradiance(&ReceivingPoint::interior(*p, DVec3::Z), floor));
        assert!(
            (v.radiosity - exact).mean().abs() <= 1e-12,
            "{p}: {v:?} vs {exact:?}"
        );
        assert!(v.standard_error <= 1e-9, "{v:?}");
    }
}

/// The same seed gives the same numbers whatever the thread count (each sample draws from its
/// own stream), and another seed other numbers.
#[test]
fn references_are_deterministic() {
    let scene = builtin::cornell();
    let vis = Visibility::build(&scene);
    let tracer = PathTracer::new(&scene, &vis);
    let floor = scene.surface_id("floor").expect("floor");
    let points: Vec<_> = (0..16)
        .map(|i| (DVec3::new(30.0 + 30.0 * f64::from(i), 0.0, 400.0), floor))
        .collect();
    let options = |seed| PathTraceOptions { paths: 200, seed };
    let with_threads = |threads: usize, seed: u64| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool")
            .install(|| tracer.radiosity(&points, &options(seed)))
    };
    let one = with_threads(1, 9);
    assert_eq!(one, with_threads(2, 9));
    assert_eq!(one, with_threads(3, 9));
    assert_ne!(one, with_threads(2, 10));
}
