use super::*;
use penumbra_scenes::builtin;

/// Points spread over every face of a scene, corners and edges included: a jittered grid in
/// each surface's frame, kept where it falls inside the polygon.
fn points_on(scene: &Scene, per_side: usize) -> Vec<(DVec3, SurfaceId)> {
    let mut rng = SplitMix64::new(7);
    let mut points = Vec::new();
    for (s, surface) in scene.surfaces.iter().enumerate() {
        let Some(frame) = PlaneFrame::of_polygon(&surface.polygon) else {
            continue;
        };
        let flat: Vec<_> = surface.polygon.iter().map(|&p| frame.to_2d(p)).collect();
        let (lo, hi) = flat
            .iter()
            .fold((flat[0], flat[0]), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        for i in 0..per_side {
            for j in 0..per_side {
                let t = glam::DVec2::new(
                    (i as f64 + rng.next_f64()) / per_side as f64,
                    (j as f64 + rng.next_f64()) / per_side as f64,
                );
                let q = lo + (hi - lo) * t;
                if penumbra_scenes::polygon::inside_polygon(q, &flat) {
                    points.push((frame.to_3d(q), s));
                }
            }
        }
    }
    points
}

/// In the furnace every face emits E = 1 and reflects ρ: B = 1/(1 − ρ) everywhere, the direct
/// irradiance is E (the other faces fill the hemisphere), and the rest, ρ/(1 − ρ), came by
/// reflection. The photon estimate finds it at points all over the faces, corners included,
/// with no bias: its errors are the noise of k photons, about 1/√k.
#[test]
fn the_furnace_has_the_closed_form_indirect_light() {
    for (rho, photons) in [(0.5, 300_000), (0.9, 200_000)] {
        let scene = builtin::furnace(1.0, rho);
        let visibility = Visibility::build(&scene);
        let options = PhotonMapOptions {
            photons,
            gather_photons: 1000,
            seed: 3,
        };
        let map = PhotonMap::trace(&scene, &visibility, &options, None).expect("traced");
        assert_eq!(map.stats.emitted, photons);
        let exact = rho / (1.0 - rho);
        let spread = 1.0 / (options.gather_photons as f64).sqrt();
        let errors: Vec<f64> = points_on(&scene, 8)
            .iter()
            .map(|&(x, s)| {
                let h = map.indirect_irradiance(x, s);
                assert!(h.r == h.g && h.g == h.b, "grey in, grey out: {h:?}");
                let error = h.r / exact - 1.0;
                // A point may stray 4.5 times the noise.
                assert!(
                    error.abs() < 4.5 * spread,
                    "ρ {rho}: {} at {x}, exact {exact}",
                    h.r
                );
                error
            })
            .collect();
        let n = errors.len() as f64;
        let mean = errors.iter().sum::<f64>() / n;
        let rms = (errors.iter().map(|e| e * e).sum::<f64>() / n).sqrt();
        assert!(mean.abs() < 0.01, "ρ {rho}: mean error {mean}");
        assert!(
            rms < 1.3 * spread,
            "ρ {rho}: RMS error {rms} against noise {spread}"
        );
    }
}

/// The textbook's light faces down, the blocker up: what the floor reflects reaches the
/// blocker's back and the light's front, which reflects nothing, so no photon lands on the
/// floor or the blocker after a reflection.
#[test]
fn nothing_reflected_comes_back_in_the_textbook() {
    let scene = builtin::textbook();
    let visibility = Visibility::build(&scene);
    let options = PhotonMapOptions {
        photons: 20_000,
        ..PhotonMapOptions::default()
    };
    let map = PhotonMap::trace(&scene, &visibility, &options, None).expect("traced");
    let light = scene.surface_id("light").expect("a light");
    assert!(scene.surfaces[light].reflectance.is_zero());
    assert!(
        map.stats.stored > 0,
        "the light receives what the floor reflects"
    );
    for (x, s) in points_on(&scene, 5) {
        let h = map.indirect_irradiance(x, s);
        assert_eq!(
            h == Rgb::ZERO,
            s != light,
            "{} at {x}",
            scene.surfaces[s].name
        );
    }
}

/// The same photons and the same estimates on 1 and 2 threads.
#[test]
fn the_map_does_not_depend_on_the_thread_count() {
    let scene = builtin::cornell();
    let visibility = Visibility::build(&scene);
    let options = PhotonMapOptions {
        photons: 30_000,
        gather_photons: 50,
        seed: 5,
    };
    let points = points_on(&scene, 3);
    let estimates = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a pool");
        pool.install(|| {
            let map = PhotonMap::trace(&scene, &visibility, &options, None).expect("traced");
            let values: Vec<Rgb> = points
                .iter()
                .map(|&(x, s)| map.indirect_irradiance(x, s))
                .collect();
            (map.stats.clone(), values)
        })
    };
    let (one, two) = (estimates(1), estimates(2));
    assert!(one.0.stored > 0);
    assert_eq!(one.0, two.0);
    assert!(
        one.1.iter().zip(&two.1).all(|(a, b)| a == b),
        "estimates differ"
    );
}

/// Every photon's power leaves its emitter: the emitted photons carry the scene's emitted
/// power, and each stored one a share no larger than that.
#[test]
fn photons_carry_the_emitted_power() {
    let scene = builtin::cornell();
    let frames: Vec<_> = scene
        .surfaces
        .iter()
        .map(|s| PlaneFrame::of_polygon(&s.polygon))
        .collect();
    let emission = Emission::new(&scene, &frames, 10_001, 1);
    let total: Rgb = (0..emission.count())
        .map(|i| emission.photon(i).power)
        .sum();
    let emitted = scene.emitted_power();
    for (a, b) in [
        (total.r, emitted.r),
        (total.g, emitted.g),
        (total.b, emitted.b),
    ] {
        assert!((a / b - 1.0).abs() < 1e-12, "{a} against {b}");
    }
    // Every photon starts on its emitter and leaves through its front.
    for i in (0..emission.count()).step_by(97) {
        let p = emission.photon(i);
        let frame = frames[p.surface].expect("a frame");
        assert!((p.origin - frame.origin).dot(frame.normal).abs() < 1e-9 * scene.diagonal());
        assert!(p.direction.dot(frame.normal) > 0.0);
        assert!((p.direction.length() - 1.0).abs() < 1e-12);
    }
}
