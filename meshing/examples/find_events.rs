//! Finds the discontinuities of `boxworld(N, 1)` a few times (for profiling): `cargo run --release
//! -p penumbra-meshing --example find_events -- N [complete|extremal]`.

use penumbra_meshing::discontinuity::{DiscontinuityOptions, EventSet, find_discontinuities};
use penumbra_scenes::{Visibility, builtin};

fn main() {
    let mut args = std::env::args().skip(1);
    let boxes: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(1000);
    let events = match args.next().as_deref() {
        Some("extremal") => EventSet::Extremal,
        _ => EventSet::Complete,
    };
    let scene = builtin::boxworld(boxes, 1);
    let vis = Visibility::build(&scene);
    let options = DiscontinuityOptions {
        events,
        ..DiscontinuityOptions::default()
    };
    for _ in 0..5 {
        let found = find_discontinuities(&scene, &vis, &options);
        eprintln!(
            "{:.3} s, {} segments",
            found.stats.seconds, found.stats.segments
        );
    }
}
