//! Times the exact direct light at random vertices of a scene's mesh, one point at a time, sorts
//! the points into dark, fully lit and partly lit, and writes the values (vertex, sum of the
//! channels) for comparison between builds.
//!
//! `cargo run --release --example direct_profile -- SCENE [TRIANGLES] [POINTS] [VALUES_FILE]`
//! (defaults: 100,000 triangles, 1,500 points; 0 points: every vertex). The mesh is uniform, or
//! with `DISCONTINUITIES=1` by discontinuities (vertices on shadow boundaries).
//! `CHECK=v,v,...` prints those vertices' exact values (red channel) beside an estimate by a
//! million rays instead, and beside the value with no shaft narrowed. `NEVER_NARROW=1` times and
//! writes the values with no shaft narrowed. `RAYON_NUM_THREADS=1` times one core.

use std::io::Write;
use std::time::Instant;

use penumbra_meshing::discontinuity::{DiscontinuityOptions, find_discontinuities};
use penumbra_meshing::{ElementBudget, mesh_scene_discontinuity, mesh_scene_uniform};
use penumbra_scenes::{SplitMix64, Visibility, load_scene};
use penumbra_solver::{DirectLight, Discretization, OVERLAY_CAP, form_factor};
use rayon::prelude::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let spec = args
        .first()
        .ok_or("usage: direct_profile SCENE [TRIANGLES] [POINTS] [FILE]")?;
    let triangles: usize = args.get(1).map_or(Ok(100_000), |a| a.parse())?;
    let points: usize = args.get(2).map_or(Ok(1_500), |a| a.parse())?;
    let scene = load_scene(spec)?.scene;
    let visibility = Visibility::build(&scene);
    // DISCONTINUITIES=1: the discontinuity mesh, whose vertices lie on shadow boundaries.
    let mesh = if std::env::var_os("DISCONTINUITIES").is_some() {
        let search = DiscontinuityOptions {
            element_area: Some(scene.total_area() / triangles as f64),
            ..DiscontinuityOptions::default()
        };
        let found = find_discontinuities(&scene, &visibility, &search);
        mesh_scene_discontinuity(&scene, &visibility, found, triangles, 1.0)?
    } else {
        mesh_scene_uniform(&scene, ElementBudget::AtMost(triangles))?
    };
    let disc = Discretization::new(&scene, &mesh, 1);
    let direct = DirectLight::new(&scene, &visibility).with_overlay_cap(OVERLAY_CAP);
    let wide = DirectLight::new(&scene, &visibility)
        .with_overlay_cap(OVERLAY_CAP)
        .with_window_faces(usize::MAX);
    // NEVER_NARROW=1: every shaft subtracted whole, for comparison with the narrowed ones.
    let evaluator = match std::env::var_os("NEVER_NARROW") {
        Some(_) => &wide,
        None => &direct,
    };
    let mut rng = SplitMix64::new(35);
    let count = disc.receiver_count();
    // CHECK=v,v,...: those vertices' values, against an estimate by a million rays.
    if let Ok(list) = std::env::var("CHECK") {
        let mut out = std::io::stdout().lock();
        for v in list.split(',').filter_map(|v| v.parse::<usize>().ok()) {
            let (x, r) = (&disc.receivers[v], disc.receiver_surface[v]);
            let exact = direct.irradiance(x, r);
            let rays = direct.irradiance_sampled(x, r, 1 << 20);
            let plain = wide.irradiance(x, r);
            writeln!(
                out,
                "{v} on {r} ({}) at {:?} inward {:?}: exact {:e} never narrowed {:e} rays {:e}",
                scene.surfaces[r].name, x.point, x.inward, exact.r, plain.r, rays.r
            )?;
        }
        return Ok(());
    }
    // POINTS=0: every vertex.
    let chosen: Vec<usize> = match points {
        0 => (0..count).collect(),
        _ => (0..points)
            .map(|_| (rng.next_f64() * count as f64) as usize % count)
            .collect(),
    };
    let points = chosen.len();
    let started = Instant::now();
    let timed: Vec<(f64, f64)> = chosen
        .par_iter()
        .map(|&v| {
            let t = Instant::now();
            let h = evaluator.irradiance(&disc.receivers[v], disc.receiver_surface[v]);
            (t.elapsed().as_secs_f64(), h.r + h.g + h.b)
        })
        .collect();
    let wall = started.elapsed().as_secs_f64();
    let mut times: Vec<f64> = timed.iter().map(|t| t.0).collect();
    times.sort_by(f64::total_cmp);
    let total: f64 = times.iter().sum();
    let at = |q: f64| times[((times.len() - 1) as f64 * q) as usize] * 1e3;
    // Each point as dark, fully lit (its value the unoccluded one) or partly lit: count, seconds.
    let tol = 1e-9 * direct.scene_diagonal();
    let unoccluded = |v: usize| -> f64 {
        scene
            .emitters()
            .map(|(e, s)| {
                let f = form_factor(&disc.receivers[v], &s.polygon, tol);
                let h = s.emission * f;
                if e == disc.receiver_surface[v] {
                    0.0
                } else {
                    h.r + h.g + h.b
                }
            })
            .sum()
    };
    let mut kinds = [(0usize, 0.0f64); 3];
    for (&v, &(t, h)) in chosen.iter().zip(&timed) {
        let full = unoccluded(v);
        let kind = match h {
            0.0 => 0,
            _ if (h - full).abs() <= 1e-9 * full.abs() => 1,
            _ => 2,
        };
        kinds[kind].0 += 1;
        kinds[kind].1 += t;
    }
    let dark = kinds[0].0;
    if let Some(file) = args.get(3) {
        let text: String = chosen
            .iter()
            .zip(&timed)
            .map(|(v, t)| format!("{v} {:e}\n", t.1))
            .collect();
        std::fs::write(file, text)?;
    }
    let mut out = std::io::stdout().lock();
    writeln!(
        out,
        "{points} of {count} vertices: {wall:.2} s wall, {total:.2} s of work; \
         per point median {:.2} ms, p90 {:.2} ms, p99 {:.2} ms, max {:.1} ms; {dark} dark",
        at(0.5),
        at(0.9),
        at(0.99),
        at(1.0)
    )?;
    for (name, (n, t)) in ["dark", "fully lit", "partly lit"].iter().zip(kinds) {
        writeln!(
            out,
            "  {name}: {n} points, {t:.2} s ({:.0} %)",
            100.0 * t / total
        )?;
    }
    Ok(())
}
