//! The renderer: a z-buffered software rasterizer of the meshed scene, shaded by interpolating
//! the radiosity at mesh vertices (Gouraud shading, linear in 3D).
//!
//! The image is cut into bands of rows; each band is drawn on its own by going through every
//! triangle that reaches it, always in the mesh's order. The result is therefore the same
//! whatever the number of threads.

use std::collections::HashMap;

use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder, RgbImage};
use penumbra_meshing::{SceneMesh, SurfaceMesh};
use penumbra_scenes::{Rgb, Scene};
use rayon::prelude::*;

use crate::camera::{View, default_camera};
use crate::clip::{ClipTriangle, ClipVertex, clip_near};
use crate::error::VizError;
use crate::raster::{ScreenTriangle, rasterize, row_range};
use crate::tonemap::{auto_exposure, luminance, to_srgb8};

/// Distance of the near clipping plane from the eye, as a fraction of the scene's bounding-box
/// diagonal: small enough that a camera standing close to a wall still sees it.
pub(crate) const NEAR_PLANE_FRACTION: f64 = 1e-4;
/// The largest image [`render`] draws, in pixels (8192 x 8192).
pub const MAX_PIXELS: u64 = 1 << 26;
/// Rows per band: the unit of parallel work.
const BAND_ROWS: u32 = 16;

/// How to render: the image size, the exposure and a display-only ambient term.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Multiplies radiosity (W/m^2) into display values in `[0, 1]` before the sRGB curve.
    /// `None` chooses it from the image: the 95th percentile of the luminance of the lit
    /// surfaces' pixels maps to 0.8, emitters left out.
    pub exposure: Option<f64>,
    /// Added to every surface's radiosity, front and back, for display only: it shows shapes in
    /// regions that receive no light. It takes part in automatic exposure.
    pub ambient: Rgb,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 640,
            height: 640,
            exposure: None,
            ambient: Rgb::ZERO,
        }
    }
}

/// A rendered image and the exposure it was made with.
#[derive(Clone, Debug)]
pub struct Render {
    /// The image, sRGB.
    pub image: RgbImage,
    /// The exposure used: display value per unit of radiosity.
    pub exposure: f64,
}

/// What a pixel shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Shows {
    Nothing,
    /// The front of a surface that does not emit.
    Lit,
    /// The front of an emitter.
    Emitter,
    /// The back of a surface, which sends no light towards the eye.
    Back,
}

/// The nearest surface seen so far at a pixel.
#[derive(Clone, Copy, Debug)]
struct Sample {
    /// 1 / depth: larger is nearer, and 0 is the empty background.
    inverse_depth: f64,
    radiosity: Rgb,
    shows: Shows,
}

const BACKGROUND: Sample = Sample {
    inverse_depth: 0.0,
    radiosity: Rgb::ZERO,
    shows: Shows::Nothing,
};

/// A triangle ready to draw. Depth and values are interpolated in perspective-correct form:
/// `1 / z` and `value / z` are linear in screen space.
#[derive(Clone, Copy, Debug)]
struct Primitive {
    screen: ScreenTriangle,
    inverse_depth: [f64; 3],
    value_over_depth: [Rgb; 3],
    shows: Shows,
}

/// Renders the meshed scene from `scene.camera` (or [`default_camera`]) with `radiosity[s][v]`,
/// the radiosity of vertex `v` of `mesh.surfaces[s]`.
///
/// Both sides of every surface are drawn and occlude. Light leaves a surface from its front only,
/// so the back shows black (plus `options.ambient`). Background pixels are black.
/// Pixel values are `(radiosity + ambient) * exposure` through the sRGB curve, clamped to 8 bits.
pub fn render(
    scene: &Scene,
    mesh: &SceneMesh,
    radiosity: &[Vec<Rgb>],
    options: &RenderOptions,
) -> Result<Render, VizError> {
    check_options(options)?;
    check_inputs(scene, mesh, radiosity)?;
    let camera = scene.camera.unwrap_or_else(|| default_camera(scene));
    let view = View::new(&camera, options.width, options.height)?;
    let diagonal = scene.diagonal();
    let near = if diagonal > 0.0 && diagonal.is_finite() {
        NEAR_PLANE_FRACTION * diagonal
    } else {
        f64::MIN_POSITIVE
    };

    let per_surface: Vec<Vec<Primitive>> = mesh
        .surfaces
        .par_iter()
        .zip(radiosity)
        .map(|(surface_mesh, values)| {
            let emitter = scene.surfaces[surface_mesh.surface].is_emitter();
            primitives(&view, near, surface_mesh, values, emitter)
        })
        .collect();
    let primitives: Vec<Primitive> = per_surface.into_iter().flatten().collect();

    let samples = draw(&primitives, options.width, options.height);
    let exposure = match options.exposure {
        Some(exposure) => exposure,
        None => choose_exposure(&samples, options.ambient),
    };
    let pixels: Vec<u8> = samples
        .par_iter()
        .flat_map_iter(|s| match s.shows {
            Shows::Nothing => [0; 3],
            Shows::Back => to_srgb8(options.ambient, exposure),
            Shows::Lit | Shows::Emitter => to_srgb8(s.radiosity + options.ambient, exposure),
        })
        .collect();
    let image = RgbImage::from_raw(options.width, options.height, pixels)
        .expect("one sample per pixel: this is a bug");
    Ok(Render { image, exposure })
}

/// PNG bytes of `image`, in memory.
pub fn encode_png(image: &RgbImage) -> Result<Vec<u8>, VizError> {
    let (width, height) = image.dimensions();
    if width == 0 || height == 0 {
        return Err(VizError::ImageSize {
            width,
            height,
            max_pixels: MAX_PIXELS,
        });
    }
    let mut bytes = Vec::new();
    PngEncoder::new(&mut bytes).write_image(
        image.as_raw(),
        width,
        height,
        ExtendedColorType::Rgb8,
    )?;
    Ok(bytes)
}

fn check_options(options: &RenderOptions) -> Result<(), VizError> {
    let pixels = u64::from(options.width) * u64::from(options.height);
    if pixels == 0 || pixels > MAX_PIXELS {
        return Err(VizError::ImageSize {
            width: options.width,
            height: options.height,
            max_pixels: MAX_PIXELS,
        });
    }
    if let Some(exposure) = options.exposure
        && !(exposure > 0.0 && exposure.is_finite())
    {
        return Err(VizError::InvalidExposure { exposure });
    }
    let Rgb { r, g, b } = options.ambient;
    if !options.ambient.is_finite() {
        return Err(VizError::InvalidAmbient { r, g, b });
    }
    Ok(())
}

fn check_inputs(scene: &Scene, mesh: &SceneMesh, radiosity: &[Vec<Rgb>]) -> Result<(), VizError> {
    if radiosity.len() != mesh.surfaces.len() {
        return Err(VizError::SurfaceCount {
            expected: mesh.surfaces.len(),
            found: radiosity.len(),
        });
    }
    for (index, (m, values)) in mesh.surfaces.iter().zip(radiosity).enumerate() {
        if m.surface >= scene.surfaces.len() {
            return Err(VizError::UnknownSurface {
                mesh_index: index,
                surface: m.surface,
                surfaces: scene.surfaces.len(),
            });
        }
        if values.len() != m.vertex_count() {
            return Err(VizError::VertexCount {
                surface: index,
                expected: m.vertex_count(),
                found: values.len(),
            });
        }
        let usable = values.len().min(m.points3.len());
        if let Some(triangle) = m
            .triangles
            .iter()
            .position(|t| t.iter().any(|&v| v as usize >= usable))
        {
            return Err(VizError::InvalidTriangle {
                surface: index,
                triangle,
            });
        }
        if let Some(vertex) =
            (0..usable).position(|v| !(values[v].is_finite() && m.points3[v].is_finite()))
        {
            return Err(VizError::NotFinite {
                surface: index,
                vertex,
            });
        }
    }
    Ok(())
}

/// The triangles of one surface, clipped and projected.
fn primitives(
    view: &View,
    near: f64,
    mesh: &SurfaceMesh,
    values: &[Rgb],
    emitter: bool,
) -> Vec<Primitive> {
    let side = mesh.frame.normal.dot(view.eye() - mesh.frame.origin);
    let shows = if side > 0.0 {
        if emitter { Shows::Emitter } else { Shows::Lit }
    } else if side < 0.0 {
        Shows::Back
    } else {
        // Seen edge-on (or not finite): the surface covers no pixel.
        return Vec::new();
    };
    let camera_points: Vec<_> = mesh.points3.iter().map(|&p| view.camera_space(p)).collect();
    let outline = outline_edges(mesh);
    let mut out = Vec::with_capacity(mesh.triangles.len());
    for triangle in &mesh.triangles {
        let corners = triangle.map(|v| ClipVertex {
            position: camera_points[v as usize],
            value: if shows == Shows::Back {
                Rgb::ZERO
            } else {
                values[v as usize]
            },
        });
        let edges = [0, 1, 2].map(|k| {
            let (a, b) = (triangle[k], triangle[(k + 1) % 3]);
            outline.get(&[a.min(b), a.max(b)]) == Some(&1)
        });
        let clip = ClipTriangle {
            corners,
            outline: edges,
        };
        for part in clip_near(&clip, near) {
            let inverse_depth = part.corners.map(|c| 1.0 / c.position.z);
            out.push(Primitive {
                screen: ScreenTriangle {
                    corners: part.corners.map(|c| view.project(c.position)),
                    outline: part.outline,
                },
                inverse_depth,
                value_over_depth: [0, 1, 2].map(|k| part.corners[k].value * inverse_depth[k]),
                shows,
            });
        }
    }
    out
}

/// How many triangles use each undirected edge: the edges used once are the surface's outline.
fn outline_edges(mesh: &SurfaceMesh) -> HashMap<[u32; 2], u32> {
    let mut uses = HashMap::with_capacity(3 * mesh.triangles.len());
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *uses.entry([a.min(b), a.max(b)]).or_insert(0) += 1;
        }
    }
    uses
}

/// Rasterizes with a depth test: one sample per pixel, row by row.
fn draw(primitives: &[Primitive], width: u32, height: u32) -> Vec<Sample> {
    let bands = height.div_ceil(BAND_ROWS) as usize;
    let mut bins: Vec<Vec<usize>> = vec![Vec::new(); bands];
    for (index, p) in primitives.iter().enumerate() {
        let rows = row_range(&p.screen, 0, height);
        if rows.is_empty() {
            continue;
        }
        for band in rows.start / BAND_ROWS..=(rows.end - 1) / BAND_ROWS {
            bins[band as usize].push(index);
        }
    }

    let row_len = width as usize;
    let mut samples = vec![BACKGROUND; row_len * height as usize];
    samples
        .par_chunks_mut(row_len * BAND_ROWS as usize)
        .zip(&bins)
        .enumerate()
        .for_each(|(band, (band_samples, bin))| {
            let first = band as u32 * BAND_ROWS;
            let rows = first..(first + BAND_ROWS).min(height);
            for &index in bin {
                let p = &primitives[index];
                rasterize(&p.screen, rows.clone(), width, |x, y, w| {
                    let total = w[0] + w[1] + w[2];
                    let inverse_depth = (0..3).map(|k| w[k] * p.inverse_depth[k]).sum::<f64>();
                    if !(total > 0.0 && inverse_depth > 0.0) {
                        return;
                    }
                    let sample = &mut band_samples[(y - first) as usize * row_len + x as usize];
                    if inverse_depth / total > sample.inverse_depth {
                        let value: Rgb = (0..3).map(|k| p.value_over_depth[k] * w[k]).sum();
                        *sample = Sample {
                            inverse_depth: inverse_depth / total,
                            radiosity: value / inverse_depth,
                            shows: p.shows,
                        };
                    }
                });
            }
        });
    samples
}

/// Automatic exposure from the lit surfaces; from everything visible if nothing lit is in view;
/// 1 if the image is black.
fn choose_exposure(samples: &[Sample], ambient: Rgb) -> f64 {
    let luminances = |keep: &dyn Fn(Shows) -> bool| -> Vec<f64> {
        samples
            .iter()
            .filter(|s| keep(s.shows))
            .map(|s| luminance(s.radiosity + ambient))
            .collect()
    };
    auto_exposure(&mut luminances(&|s| s == Shows::Lit))
        .or_else(|| auto_exposure(&mut luminances(&|s| s != Shows::Nothing)))
        .unwrap_or(1.0)
}

#[cfg(test)]
mod tests {
    use glam::DVec2;
    use penumbra_meshing::mesh_scene_uniform;
    use penumbra_scenes::builtin;

    use super::*;

    #[test]
    fn interpolation_is_perspective_correct() {
        // Radiosity linear in 3D over the floor must read, at every pixel, as the value at the
        // point the pixel's ray hits: linear in screen space would be wrong by up to tens of
        // percent at this oblique view.
        let scene = builtin::textbook();
        let mesh = mesh_scene_uniform(&scene, 400).expect("textbook meshes");
        let floor = &mesh.surfaces[scene.surface_id("floor").expect("floor")];
        let values: Vec<Rgb> = floor
            .points3
            .iter()
            .map(|p| Rgb::new(p.x + 3.0, 2.0 * p.y + 7.0, 1.0))
            .collect();
        let camera = scene.camera.expect("textbook has a camera");
        let (width, height) = (64, 48);
        let view = View::new(&camera, width, height).expect("valid camera");
        let samples = draw(
            &primitives(&view, 1e-6, floor, &values, false),
            width,
            height,
        );
        let mut checked = 0;
        for (i, s) in samples.iter().enumerate() {
            if s.shows != Shows::Lit {
                continue;
            }
            let (x, y) = (i % width as usize, i / width as usize);
            let ray = view.ray_direction(DVec2::new(x as f64 + 0.5, y as f64 + 0.5));
            let hit = camera.eye + ray * (-camera.eye.z / ray.z);
            assert!(
                (s.radiosity.r - (hit.x + 3.0)).abs() < 1e-9,
                "pixel ({x}, {y})"
            );
            assert!((s.radiosity.g - (2.0 * hit.y + 7.0)).abs() < 1e-9);
            assert!((s.radiosity.b - 1.0).abs() < 1e-12);
            let depth = view.camera_space(hit).z;
            assert!((s.inverse_depth * depth - 1.0).abs() < 1e-12);
            checked += 1;
        }
        assert!(checked > width as usize * height as usize / 4, "{checked}");
    }
}
