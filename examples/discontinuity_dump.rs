//! Runs the discontinuity search of `penumbra run SCENE` (default options) alone, prints its time
//! and figures, and, given a second argument, writes its segments there, one a line with every
//! coordinate's bits in hex (then the hovering contact lines), so that two builds can be compared
//! exactly with `cmp`.
//!
//! `cargo run --release --example discontinuity_dump SCENE [OUT]`
use std::io::Write;
use std::time::Instant;

use penumbra::DEFAULT_BUDGET;
use penumbra_meshing::discontinuity::{DiscontinuityOptions, find_discontinuities};
use penumbra_meshing::polygon_minimum;
use penumbra_scenes::{Visibility, load_scene};

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let scene = load_scene(&args[1])?.scene;
    let visibility = Visibility::build(&scene);
    let budget = DEFAULT_BUDGET.resolve(polygon_minimum(&scene), scene.surfaces.len())?;
    let options = DiscontinuityOptions {
        element_area: Some(scene.total_area() / budget.max(1) as f64),
        ..Default::default()
    };
    let t = Instant::now();
    let found = find_discontinuities(&scene, &visibility, &options);
    eprintln!("{:.3} s", t.elapsed().as_secs_f64());
    eprintln!("{:?}", found.stats);
    if let Some(path) = args.get(2) {
        let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
        for list in &found.segments {
            for s in list {
                let bits: Vec<String> = [s.from, s.to]
                    .iter()
                    .flat_map(|p| p.to_array())
                    .map(|x| format!("{:016x}", x.to_bits()))
                    .collect();
                writeln!(
                    out,
                    "{} {} {:?} {:?} {} {}",
                    s.surface,
                    s.emitter,
                    s.event,
                    s.boundary,
                    s.order,
                    bits.join(" ")
                )?;
            }
        }
        for (r, h) in found.hovering.iter().enumerate() {
            for c in h {
                writeln!(out, "hover {r} {:?}", c)?;
            }
        }
    }
    Ok(())
}
