//! Discontinuity finding on floors of 10, 100 and 1000 boxes: how its time grows with the number
//! of blockers, and how many wedges and EEE triples it tests, for complete events (the default)
//! and extremal ones.

use std::hint::black_box;
use std::time::Instant;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use penumbra_meshing::discontinuity::{DiscontinuityOptions, EventSet, find_discontinuities};
use penumbra_scenes::{Visibility, builtin};

fn discontinuities(c: &mut Criterion) {
    for events in [EventSet::Complete, EventSet::Extremal] {
        let name = format!("discontinuities/{events:?}").to_lowercase();
        let mut group = c.benchmark_group(name);
        group.sample_size(10);
        for boxes in [10, 100, 1000] {
            bench_boxes(&mut group, boxes, events);
        }
        group.finish();
    }
}

fn bench_boxes(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    boxes: usize,
    events: EventSet,
) {
    {
        let scene = builtin::boxworld(boxes, 1);
        let vis = Visibility::build(&scene);
        let options = DiscontinuityOptions {
            events,
            ..DiscontinuityOptions::default()
        };
        // One timed run for the figures criterion does not report.
        let started = Instant::now();
        let found = find_discontinuities(&scene, &vis, &options);
        let seconds = started.elapsed().as_secs_f64();
        let s = &found.stats;
        eprintln!(
            "{boxes} boxes, {events:?}: {:.3} s, {} blockers in shafts, {} wedges considered ({:.2e}/s), {} culled, \
             {} kept, {} EEE triples considered, {} EEE events, {} segments",
            seconds,
            s.blockers_in_shafts,
            s.wedges_considered,
            s.wedges_considered as f64 / seconds,
            s.wedges_culled,
            s.wedges_kept,
            s.eee_considered,
            s.eee_events,
            s.segments
        );
        group.bench_with_input(BenchmarkId::from_parameter(boxes), &scene, |b, scene| {
            b.iter(|| find_discontinuities(black_box(scene), &vis, &options));
        });
    }
}

criterion_group!(benches, discontinuities);
criterion_main!(benches);
