//! Counts the segment queries on which the visibility index disagrees with exhaustive search:
//! segments that a triangle blocks by the exact test but that `Visibility::occluded` lets through
//! (leaks), and rays whose closest hit differs. For scenes too large to keep in the repository.
//!
//! `cargo run --release -p penumbra-scenes --example visibility_leaks SCENE [SEGMENTS] [RAYS]`
//! (SEGMENTS of each kind, 20,000 by default; RAYS 2,000)
use std::error::Error;
use std::io::Write;
use std::time::Instant;

use penumbra_scenes::SplitMix64;
use penumbra_scenes::visibility_check::{ProbeKind, closest_hit_mismatch, sample_segment};
use penumbra_scenes::{Visibility, load_scene};

fn main() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().collect();
    let spec = args
        .get(1)
        .ok_or("usage: visibility_leaks SCENE [SEGMENTS] [RAYS]")?;
    let segments: usize = args.get(2).map_or(Ok(20_000), |s| s.parse())?;
    let rays: usize = args.get(3).map_or(Ok(2_000), |s| s.parse())?;
    let mut out = std::io::stdout().lock();
    let scene = load_scene(spec)?.scene;
    let diagonal = scene.bounds().diagonal();
    let start = Instant::now();
    let visibility = Visibility::build(&scene);
    writeln!(
        out,
        "{}: {} triangles, diagonal {diagonal}, index built in {:.2} s",
        spec,
        visibility.triangles().len(),
        start.elapsed().as_secs_f64()
    )?;
    let mut rng = SplitMix64::new(1);
    let mut total_leaks = 0;
    for kind in ProbeKind::ALL {
        let start = Instant::now();
        let (mut leaks, mut blocked) = (0, 0);
        for _ in 0..segments {
            let Some(segment) = sample_segment(&visibility, kind, diagonal, &mut rng) else {
                break;
            };
            // The index tests a subset of the triangles with the same exact test: it can only
            // miss a blocker, never invent one.
            if visibility.occluded(segment.from, segment.to, segment.ignore) {
                blocked += 1;
            } else if visibility.occluded_exhaustive(segment.from, segment.to, segment.ignore) {
                leaks += 1;
                blocked += 1;
                if leaks <= 3 {
                    writeln!(out, "  leak: {segment:?}")?;
                }
            }
        }
        total_leaks += leaks;
        writeln!(
            out,
            "{kind:?}: {segments} segments, {blocked} blocked, {leaks} leaks ({:.1} s)",
            start.elapsed().as_secs_f64()
        )?;
    }
    let start = Instant::now();
    let mut hit_mismatches = 0;
    for i in 0..rays {
        let kind = ProbeKind::ALL[i % ProbeKind::ALL.len()];
        let Some(segment) = sample_segment(&visibility, kind, diagonal, &mut rng) else {
            break;
        };
        if closest_hit_mismatch(&visibility, &segment) {
            hit_mismatches += 1;
            if hit_mismatches <= 3 {
                writeln!(out, "  closest hit differs: {segment:?}")?;
            }
        }
    }
    writeln!(
        out,
        "closest hit: {rays} rays, {hit_mismatches} differ ({:.1} s)",
        start.elapsed().as_secs_f64()
    )?;
    writeln!(out, "leaks in all: {total_leaks}")?;
    Ok(())
}
