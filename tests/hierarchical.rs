//! The hierarchical solver's full solution of the Cornell box against the project's own
//! path-traced reference.

use penumbra::experiments::sweep::sample_points;
use penumbra::{RunOptions, run};
use penumbra_meshing::TriangleLocator;
use penumbra_scenes::{Visibility, load_scene};
use penumbra_solver::path_trace::{PathTraceOptions, PathTracer};
use penumbra_solver::{NoProgress, SolverMethod};

/// At seeded random points over the box's surfaces (inside the triangles, as a user reads the
/// solution), the default hierarchical run is within 1 % RMS of path tracing, with the
/// reference's own noise taken out (its standard errors, in quadrature). Measured: 0.88 % on
/// the error-driven mesh, which meets its tolerance at 11,500 triangles (0.54 % on the
/// discontinuity mesh of 24,300 the budget gave before). Over the 1,000 points of `penumbra
/// sweep` it is 0.92 %: most of what is left is the mesh's linear interpolation where the
/// light bends fastest, at the blocks' feet and along concave junctions, not the vertex values.
#[test]
fn cornell_box_within_1_percent_of_path_tracing() {
    let loaded = load_scene("cornell").expect("built in");
    let options = RunOptions {
        method: SolverMethod::Hierarchical,
        max_elements: penumbra::default_budget(SolverMethod::Hierarchical, false),
        render: penumbra_viz::RenderOptions {
            width: 1,
            height: 1,
            ..Default::default()
        },
        ..RunOptions::default()
    };
    let result = run(loaded.clone(), &options, &NoProgress).expect("runs");
    let scene = &loaded.scene;
    let vis = Visibility::build(scene);
    let samples = sample_points(scene, &vis, &[], 300, 11);
    let points: Vec<_> = samples.iter().map(|s| (s.point, s.surface)).collect();
    let reference = PathTracer::new(scene, &vis).radiosity(
        &points,
        &PathTraceOptions {
            paths: 30_000,
            seed: 11,
        },
    );
    let locators: Vec<TriangleLocator> = result
        .mesh
        .surfaces
        .iter()
        .map(TriangleLocator::new)
        .collect();
    let n = samples.len() as f64;
    let (mut squared, mut noise, mut mean) = (0.0, 0.0, 0.0);
    for (s, r) in samples.iter().zip(&reference) {
        let value = locators[s.surface]
            .interpolate(
                &result.mesh.surfaces[s.surface],
                &result.solution.radiosity[s.surface],
                s.point,
            )
            .mean();
        squared += (value - r.radiosity.mean()).powi(2) / n;
        noise += r.standard_error.powi(2) / n;
        mean += r.radiosity.mean() / n;
    }
    let rms = (squared - noise).max(0.0).sqrt() / mean;
    eprintln!(
        "RMS {:.3} % of the mean, the reference's noise {:.3} % taken out",
        100.0 * rms,
        100.0 * noise.sqrt() / mean
    );
    assert!(rms < 0.01, "{rms}");
}
