//! A surface's SVG reads the same whatever the scene's units: its text is laid out in canvas
//! pixels. Checked by rendering with librsvg (`rsvg-convert`, Debian's `librsvg2-bin`; the
//! README's test command installs it), which lays fonts out at whole sizes and garbled text a
//! tenth of a scene unit tall.

use std::path::Path;
use std::process::Command;

use glam::DVec3;
use penumbra_meshing::mesh_scene_uniform;
use penumbra_scenes::{Rgb, Scene, Surface};
use penumbra_viz::surface_svg;

/// A square floor of side `side` under a light, as a scene.
fn floor_scene(side: f64) -> Scene {
    let square = |z: f64, up: bool| {
        let mut p = vec![
            DVec3::new(0.0, 0.0, z),
            DVec3::new(side, 0.0, z),
            DVec3::new(side, side, z),
            DVec3::new(0.0, side, z),
        ];
        if !up {
            p.reverse();
        }
        p
    };
    Scene {
        up: None,
        unit: None,
        name: "units".into(),
        camera: None,
        surfaces: vec![
            Surface {
                name: "floor".into(),
                polygon: square(0.0, true),
                emission: Rgb::ZERO,
                reflectance: Rgb::new(0.5, 0.5, 0.5),
            },
            Surface {
                name: "light".into(),
                polygon: square(side, false),
                emission: Rgb::new(1.0, 1.0, 1.0),
                reflectance: Rgb::ZERO,
            },
        ],
    }
}

/// The floor's SVG rendered by `rsvg-convert` into `dir`, as RGB rows.
fn rendered(side: f64, dir: &Path) -> (u32, u32, Vec<u8>) {
    let scene = floor_scene(side);
    let mesh = mesh_scene_uniform(&scene, 200).expect("the floor meshes");
    let floor = &mesh.surfaces[0];
    let values = vec![Rgb::new(0.3, 0.3, 0.3); floor.vertex_count()];
    let svg = dir.join(format!("floor-{side}.svg"));
    let png = dir.join(format!("floor-{side}.png"));
    std::fs::write(&svg, surface_svg(&scene, floor, Some(&values), &[])).expect("written");
    let status = Command::new("rsvg-convert")
        .arg("-o")
        .arg(&png)
        .arg(&svg)
        .status()
        .expect("rsvg-convert runs (Debian: apt-get install librsvg2-bin)");
    assert!(status.success());
    let image = image::open(&png).expect("a PNG").to_rgb8();
    (image.width(), image.height(), image.into_raw())
}

#[test]
fn text_reads_the_same_in_metres_and_millimetres() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (w, h, small) = rendered(2.0, dir.path());
    let (w2, h2, large) = rendered(2000.0, dir.path());
    assert_eq!((w, h), (w2, h2), "the same canvas");
    // The title and the note about the fill, above the plot.
    let band = (56 * w * 3) as usize;
    let dark = |rows: &[u8]| rows.chunks(3).filter(|p| p[0] < 128).count();
    assert!(dark(&large[..band]) > 500, "the text is drawn");
    let differing = small[..band]
        .chunks(3)
        .zip(large[..band].chunks(3))
        .filter(|(a, b)| a[0].abs_diff(b[0]) > 64)
        .count();
    assert!(
        differing * 50 < dark(&large[..band]),
        "{differing} pixels of the text differ between a 2-unit and a 2000-unit scene"
    );
}
