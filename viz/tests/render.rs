//! The renderer on the built-in scenes: orientation, coverage, determinism and errors.

use glam::DVec3;
use image::RgbImage;
use penumbra_meshing::{SceneMesh, mesh_scene_uniform};
use penumbra_scenes::{Camera, Rgb, Scene, builtin};
use penumbra_viz::{RenderOptions, VizError, encode_png, render};

/// Synthetic radiosity: ten times the reflectance plus the emission, at every vertex.
fn synthetic_radiosity(scene: &Scene, mesh: &SceneMesh) -> Vec<Vec<Rgb>> {
    mesh.surfaces
        .iter()
        .map(|m| {
            let s = &scene.surfaces[m.surface];
            vec![s.reflectance * 10.0 + s.emission; m.vertex_count()]
        })
        .collect()
}

fn cornell_render(size: u32) -> RgbImage {
    let scene = builtin::cornell();
    let mesh = mesh_scene_uniform(&scene, 2000).expect("cornell meshes");
    let radiosity = synthetic_radiosity(&scene, &mesh);
    let options = RenderOptions {
        width: size,
        height: size,
        ..RenderOptions::default()
    };
    render(&scene, &mesh, &radiosity, &options)
        .expect("cornell renders")
        .image
}

/// Mean colour of a block of pixels.
fn mean(image: &RgbImage, xs: std::ops::Range<u32>, ys: std::ops::Range<u32>) -> [f64; 3] {
    let mut sum = [0.0; 3];
    let mut n = 0.0;
    for y in ys {
        for x in xs.clone() {
            let p = image.get_pixel(x, y).0;
            for c in 0..3 {
                sum[c] += f64::from(p[c]);
            }
            n += 1.0;
        }
    }
    sum.map(|s| s / n)
}

#[test]
fn cornell_box_is_the_right_way_round() {
    let image = cornell_render(128);
    let first = image.get_pixel(0, 0);
    assert!(image.pixels().any(|p| p != first), "the image is uniform");
    // Red wall on the left, green wall on the right, at mid-height.
    let [r, g, b] = mean(&image, 4..12, 60..68);
    assert!(
        r > 1.5 * g && r > 1.5 * b && r > 120.0,
        "left wall {r} {g} {b}"
    );
    let [r, g, b] = mean(&image, 116..124, 60..68);
    assert!(
        g > 1.5 * r && g > 1.5 * b && g > 100.0,
        "right wall {r} {g} {b}"
    );
    // The floor at the bottom centre is a bright, neutral grey.
    let [r, g, b] = mean(&image, 56..72, 118..124);
    assert!(
        r > 180.0 && (r - g).abs() < 2.0 && (r - b).abs() < 2.0,
        "floor {r} {g} {b}"
    );
    // The light is in the top half, near the centre: the brightest pixel there is pure white.
    let light_seen = (0..40u32)
        .flat_map(|y| (44..84u32).map(move |x| (x, y)))
        .any(|(x, y)| image.get_pixel(x, y).0 == [255, 255, 255]);
    assert!(light_seen, "no emitter in the top centre");
    // The open front of the box shows background only at the image's edges.
    for (x, y, p) in image.enumerate_pixels() {
        if (8..120).contains(&x) && (8..120).contains(&y) {
            assert_ne!(p.0, [0, 0, 0], "background at ({x}, {y})");
        }
    }
    assert_eq!(image.get_pixel(64, 0).0, [0, 0, 0]);
}

#[test]
fn furnace_from_inside_covers_every_pixel() {
    // The camera stands inside a closed cube, 0.02 from a wall: the side walls pass behind the eye
    // and must be clipped, and no seam between triangles or walls may let the background through.
    let scene = builtin::furnace(1.0, 0.5);
    let mesh = mesh_scene_uniform(&scene, 1200).expect("furnace meshes");
    let radiosity: Vec<Vec<Rgb>> = mesh
        .surfaces
        .iter()
        .map(|m| vec![Rgb::splat(2.0); m.vertex_count()])
        .collect();
    for size in [64, 128, 131] {
        let options = RenderOptions {
            width: size,
            height: size,
            ..RenderOptions::default()
        };
        let out = render(&scene, &mesh, &radiosity, &options).expect("furnace renders");
        // Every face emits, so exposure falls back to all visible surfaces: 2 maps to 0.8.
        assert!((out.exposure * 2.0 - 0.8).abs() < 1e-12);
        let expected = (penumbra_viz::srgb_encode(0.8) * 255.0).round() as u8;
        for (x, y, p) in out.image.enumerate_pixels() {
            assert_eq!(p.0, [expected; 3], "pixel ({x}, {y}) at size {size}");
        }
    }
}

#[test]
fn same_bytes_whatever_the_threads() {
    let scene = builtin::cornell();
    let mesh = mesh_scene_uniform(&scene, 2000).expect("cornell meshes");
    let radiosity = synthetic_radiosity(&scene, &mesh);
    let options = RenderOptions {
        width: 96,
        height: 80,
        ..RenderOptions::default()
    };
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool")
            .install(|| render(&scene, &mesh, &radiosity, &options))
            .expect("renders")
    };
    let one = run(1);
    let two = run(2);
    let again = run(2);
    assert_eq!(one.image.as_raw(), two.image.as_raw());
    assert_eq!(two.image.as_raw(), again.image.as_raw());
    assert_eq!(one.exposure.to_bits(), two.exposure.to_bits());
}

#[test]
fn fixed_exposure_and_ambient() {
    let scene = builtin::cornell();
    let mesh = mesh_scene_uniform(&scene, 500).expect("cornell meshes");
    let radiosity = synthetic_radiosity(&scene, &mesh);
    let dark = RenderOptions {
        width: 32,
        height: 32,
        exposure: Some(1e-9),
        ambient: Rgb::ZERO,
    };
    let out = render(&scene, &mesh, &radiosity, &dark).expect("renders");
    assert_eq!(out.exposure, 1e-9);
    assert!(out.image.pixels().all(|p| p.0 == [0, 0, 0]));
    // Ambient alone (radiosity zero) gives one grey wherever there is a surface.
    let zero: Vec<Vec<Rgb>> = radiosity.iter().map(|v| vec![Rgb::ZERO; v.len()]).collect();
    let grey = RenderOptions {
        exposure: Some(1.0),
        ambient: Rgb::splat(0.5),
        ..dark
    };
    let out = render(&scene, &mesh, &zero, &grey).expect("renders");
    let expected = (penumbra_viz::srgb_encode(0.5) * 255.0).round() as u8;
    assert!(
        out.image
            .pixels()
            .all(|p| p.0 == [expected; 3] || p.0 == [0, 0, 0])
    );
    assert_eq!(out.image.get_pixel(16, 16).0, [expected; 3]);
}

#[test]
fn backs_of_surfaces_are_black() {
    // From below, the camera sees the floor's back: no light leaves it, only ambient shows.
    let mut scene = builtin::textbook();
    scene.camera = Some(Camera {
        eye: DVec3::new(0.0, 0.0, -4.0),
        target: DVec3::ZERO,
        up: DVec3::Y,
        fov_deg: 30.0,
    });
    let mesh = mesh_scene_uniform(&scene, 300).expect("textbook meshes");
    let radiosity = synthetic_radiosity(&scene, &mesh);
    let mut options = RenderOptions {
        width: 32,
        height: 32,
        exposure: Some(0.1),
        ambient: Rgb::ZERO,
    };
    let dark = render(&scene, &mesh, &radiosity, &options).expect("renders");
    assert!(dark.image.pixels().all(|p| p.0 == [0, 0, 0]));
    options.ambient = Rgb::splat(2.0);
    let grey = render(&scene, &mesh, &radiosity, &options).expect("renders");
    let expected = (penumbra_viz::srgb_encode(0.2) * 255.0).round() as u8;
    assert!(grey.image.pixels().all(|p| p.0 == [expected; 3]));
}

#[test]
fn scene_without_camera_uses_the_default_view() {
    let mut scene = builtin::textbook();
    scene.camera = None;
    let mesh = mesh_scene_uniform(&scene, 300).expect("textbook meshes");
    let radiosity = synthetic_radiosity(&scene, &mesh);
    let options = RenderOptions {
        width: 64,
        height: 48,
        ..RenderOptions::default()
    };
    let out = render(&scene, &mesh, &radiosity, &options).expect("renders");
    let lit = out.image.pixels().filter(|p| p.0 != [0, 0, 0]).count();
    // The whole scene is in view, with background around it.
    assert!(lit > 64 * 48 / 10 && lit < 64 * 48, "{lit} lit pixels");
    for x in 0..64 {
        assert_eq!(out.image.get_pixel(x, 0).0, [0, 0, 0]);
    }
}

#[test]
fn mismatched_inputs_are_errors() {
    let scene = builtin::textbook();
    let mesh = mesh_scene_uniform(&scene, 100).expect("textbook meshes");
    let good = synthetic_radiosity(&scene, &mesh);
    let options = RenderOptions {
        width: 16,
        height: 16,
        ..RenderOptions::default()
    };
    assert!(matches!(
        render(&scene, &mesh, &good[1..], &options),
        Err(VizError::SurfaceCount { .. })
    ));
    let mut short = good.clone();
    short[1].pop();
    assert!(matches!(
        render(&scene, &mesh, &short, &options),
        Err(VizError::VertexCount { surface: 1, .. })
    ));
    let mut nan = good.clone();
    nan[2][0] = Rgb::new(f64::NAN, 0.0, 0.0);
    assert!(matches!(
        render(&scene, &mesh, &nan, &options),
        Err(VizError::NotFinite {
            surface: 2,
            vertex: 0
        })
    ));
    for (width, height) in [(0, 16), (16, 0), (100_000, 100_000)] {
        let sized = RenderOptions {
            width,
            height,
            ..options
        };
        assert!(matches!(
            render(&scene, &mesh, &good, &sized),
            Err(VizError::ImageSize { .. })
        ));
    }
    for exposure in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let exposed = RenderOptions {
            exposure: Some(exposure),
            ..options
        };
        assert!(matches!(
            render(&scene, &mesh, &good, &exposed),
            Err(VizError::InvalidExposure { .. })
        ));
    }
    let mut blind = scene.clone();
    if let Some(camera) = &mut blind.camera {
        camera.target = camera.eye;
    }
    assert!(matches!(
        render(&blind, &mesh, &good, &options),
        Err(VizError::InvalidCamera { .. })
    ));
}

/// `render.png` is 8-bit RGB at the render's size (read from the file's own header), and an
/// image with no pixels is refused rather than written.
#[test]
fn png_files_hold_the_render_as_8_bit_rgb() {
    let image = cornell_render(32);
    let bytes = encode_png(&image).expect("encodes");
    assert!(bytes.starts_with(&[0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a]));
    // The IHDR chunk: length, "IHDR", width and height (big-endian), bit depth, colour type.
    assert_eq!(&bytes[12..16], b"IHDR");
    let word =
        |at: usize| u32::from_be_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    assert_eq!((word(16), word(20)), (image.width(), image.height()));
    assert_eq!((bytes[24], bytes[25]), (8, 2), "8 bits per channel, RGB");
    assert!(matches!(
        encode_png(&RgbImage::new(0, 3)),
        Err(VizError::ImageSize { .. })
    ));
}
