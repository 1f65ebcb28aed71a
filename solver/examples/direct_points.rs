//! The exact direct irradiance at given points, beside an estimate by rays, with the time each
//! exact evaluation took (one thread).
//!
//! `cargo run --release -p penumbra-solver --example direct_points -- SCENE [RAYS] < POINTS`
//! reads one point per line from standard input, `x y z nx ny nz` (position and the receiving
//! surface's normal), and prints the irradiance's red channel both ways.
#![allow(clippy::print_stdout)]

use std::io::BufRead;
use std::process::ExitCode;
use std::time::Instant;

use glam::DVec3;
use penumbra_solver::{DirectLight, ReceivingPoint};

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let Some(path) = args.next() else {
        eprintln!("usage: direct_points SCENE [RAYS] < POINTS");
        return ExitCode::from(2);
    };
    let rays = match args.next().map(|r| r.parse::<usize>()) {
        None => 20_000,
        Some(Ok(rays)) => rays,
        Some(Err(err)) => {
            eprintln!("RAYS: {err}");
            return ExitCode::from(2);
        }
    };
    let loaded = match penumbra_scenes::load_scene(&path) {
        Ok(loaded) => loaded,
        Err(err) => {
            eprintln!("{path}: {err}");
            return ExitCode::from(2);
        }
    };
    let scene = &loaded.scene;
    let visibility = penumbra_scenes::Visibility::build(scene);
    let direct = DirectLight::new(scene, &visibility);
    // No surface of the scene receives: every occluder counts.
    let receiver = scene.surfaces.len();
    println!("point\tnormal\texact\trays\tms");
    for (number, line) in std::io::stdin().lock().lines().enumerate() {
        let Ok(line) = line else { break };
        let values: Result<Vec<f64>, _> = line.split_whitespace().map(str::parse).collect();
        let Ok(&[x, y, z, nx, ny, nz]) = values.as_deref() else {
            eprintln!("line {}: expected `x y z nx ny nz`", number + 1);
            return ExitCode::from(2);
        };
        let normal = DVec3::new(nx, ny, nz).normalize_or_zero();
        let at = ReceivingPoint::interior(DVec3::new(x, y, z), normal);
        let start = Instant::now();
        let exact = direct.irradiance(&at, receiver);
        let ms = start.elapsed().as_secs_f64() * 1e3;
        let sampled = direct.irradiance_sampled(&at, receiver, rays);
        println!(
            "{x} {y} {z}\t{nx} {ny} {nz}\t{:.6e}\t{:.6e}\t{ms:.1}",
            exact.r, sampled.r
        );
    }
    ExitCode::SUCCESS
}
