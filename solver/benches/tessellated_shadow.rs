//! The exact direct light on a floor under one solid tessellated ever finer (the L prism of the
//! `tessellated-N` scenes, 20 N² faces): the shadow is the same for every N, and so should the
//! cost be, about.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use glam::DVec3;
use penumbra_scenes::Visibility;
use penumbra_scenes::tessellated::tessellated;
use penumbra_solver::{DirectLight, ReceivingPoint};

/// A 20 x 20 grid of floor points across the shadow and around it.
fn floor_grid() -> Vec<ReceivingPoint> {
    (0..400)
        .map(|k| {
            let (i, j) = ((k % 20) as f64, (k / 20) as f64);
            ReceivingPoint::interior(DVec3::new(-2.0 + 0.2 * i, -2.0 + 0.2 * j, 0.0), DVec3::Z)
        })
        .collect()
}

fn tessellated_shadow(c: &mut Criterion) {
    let mut group = c.benchmark_group("tessellated_shadow");
    group.sample_size(10);
    let points = floor_grid();
    for n in [0, 2, 7, 22, 70] {
        let scene = tessellated(n);
        let vis = Visibility::build(&scene);
        let direct = DirectLight::new(&scene, &vis);
        let floor = scene.surface_id("floor").unwrap_or_default();
        let faces = scene.surfaces.len() - 2;
        group.bench_with_input(BenchmarkId::from_parameter(faces), &points, |b, points| {
            b.iter(|| {
                points
                    .iter()
                    .map(|x| direct.irradiance(black_box(x), floor).r)
                    .sum::<f64>()
            });
        });
    }
    group.finish();
}

criterion_group!(benches, tessellated_shadow);
criterion_main!(benches);
