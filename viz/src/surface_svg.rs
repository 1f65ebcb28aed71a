//! A surface's mesh drawn in its own 2D coordinates, optionally filled with its radiosity.

use glam::DVec2;
use penumbra_meshing::SurfaceMesh;
use penumbra_meshing::discontinuity::{Boundary, DiscontinuitySegment};
use penumbra_scenes::{Rgb, Scene};

use crate::svg_plot::{LineStyle, SvgPlot};
use crate::tonemap::{auto_exposure, luminance, to_srgb8};

/// An SVG figure of `mesh` in its surface's plane-frame coordinates (`u` right, `v` up): the
/// triangles as thin outlines, the meshed polygon thicker, the frame's axes at its origin, a
/// title with the surface's name and counts, and a scale bar in scene units.
///
/// With `radiosity` (one value per mesh vertex), each triangle is filled with the mean of its
/// corners' radiosity, exposed so that the 95th percentile of the surface's own luminance maps
/// to 0.8. Values that do not match the mesh are left out, and the
/// figure says so.
///
/// `segments` (the surface's discontinuities, in 3D) are drawn over the mesh, coloured by the
/// boundary they are — umbra, outer penumbra, inner penumbra line — with value jumps (D0) drawn
/// dashed, and listed in the legend. The same input always gives the same bytes.
pub fn surface_svg(
    scene: &Scene,
    mesh: &SurfaceMesh,
    radiosity: Option<&[Rgb]>,
    segments: &[DiscontinuitySegment],
) -> String {
    let name = scene
        .surfaces
        .get(mesh.surface)
        .map_or_else(|| format!("surface {}", mesh.surface), |s| s.name.clone());
    let vertex_count = mesh.vertex_count();
    // Triangles with a corner out of range cannot be drawn; a sane mesh has none.
    let drawable: Vec<&[u32; 3]> = mesh
        .triangles
        .iter()
        .filter(|t| t.iter().all(|&v| (v as usize) < vertex_count))
        .collect();
    let triangles: Vec<[DVec2; 3]> = drawable
        .iter()
        .map(|t| t.map(|v| mesh.point2(v as usize)))
        .collect();

    let mut plot = SvgPlot::new(
        &format!(
            "{name}: {} triangles, {vertex_count} vertices",
            mesh.triangle_count()
        ),
        "scene units",
    );
    let fills = match radiosity {
        Some(values) if values.len() == vertex_count => {
            let means: Vec<Rgb> = drawable
                .iter()
                .map(|t| t.iter().map(|&v| values[v as usize]).sum::<Rgb>() / 3.0)
                .collect();
            let mut luminances: Vec<f64> = means
                .iter()
                .map(|&c| luminance(c))
                .filter(|l| l.is_finite())
                .collect();
            let exposure = auto_exposure(&mut luminances).unwrap_or(1.0);
            plot.add_note(&format!(
                "fill: mean radiosity of each triangle, exposure {exposure:.4e} m^2/W"
            ));
            Some(
                means
                    .iter()
                    .map(|&c| to_srgb8(c, exposure))
                    .collect::<Vec<_>>(),
            )
        }
        Some(values) => {
            plot.add_note(&format!(
                "radiosity not shown: {} values for {vertex_count} vertices",
                values.len()
            ));
            None
        }
        None => None,
    };

    plot.add_layer("triangles", LineStyle::solid("#505050", 0.5));
    plot.add_layer("boundary", LineStyle::solid("#000000", 2.0));
    plot.add_layer("axes", LineStyle::solid("#1f77b4", 1.0));
    plot.add_triangles(&triangles, fills.as_deref(), "triangles");
    let boundary: Vec<DVec2> = mesh.boundary.iter().map(|&p| p * mesh.scale).collect();
    plot.add_outline(&boundary, "boundary");

    // The frame's axes from its origin, a tenth of the polygon's extent long.
    let axis = 0.1 * mesh.scale;
    if axis > 0.0 && axis.is_finite() {
        plot.add_polyline(&[DVec2::ZERO, DVec2::new(axis, 0.0)], "axes");
        plot.add_polyline(&[DVec2::ZERO, DVec2::new(0.0, axis)], "axes");
        plot.add_label(DVec2::new(axis, 0.0), "u");
        plot.add_label(DVec2::new(0.0, axis), "v");
    }
    plot.add_legend_entry("mesh edges", "triangles");
    plot.add_legend_entry("surface boundary", "boundary");
    plot.add_legend_entry("frame axes u, v", "axes");

    // Discontinuities: one layer per kind, in a fixed order, only for kinds present.
    let kinds = [
        (Boundary::Umbra, false, "#6a1b9a", "umbra boundary"),
        (
            Boundary::Penumbra,
            false,
            "#e65100",
            "outer penumbra boundary",
        ),
        (Boundary::Inner, false, "#2e7d32", "inner penumbra line"),
        (Boundary::Umbra, true, "#6a1b9a", "contact (value jump, D0)"),
    ];
    for (boundary, jump, color, label) in kinds {
        let lines: Vec<[DVec2; 2]> = segments
            .iter()
            .filter(|g| g.boundary == boundary && (g.order == 0) == jump)
            .map(|g| [mesh.frame.to_2d(g.from), mesh.frame.to_2d(g.to)])
            .collect();
        if lines.is_empty() {
            continue;
        }
        let class = format!("{}{}", boundary.name(), if jump { "-jump" } else { "" });
        let mut style = LineStyle::solid(color, 2.5);
        if jump {
            style.dash_px = Some([7.0, 4.0]);
        }
        plot.add_layer(&class, style);
        for [a, b] in lines {
            plot.add_polyline(&[a, b], &class);
        }
        plot.add_legend_entry(label, &class);
    }
    plot.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use penumbra_meshing::mesh_scene_uniform;
    use penumbra_scenes::builtin;

    #[test]
    fn one_polygon_per_triangle_and_deterministic() {
        let scene = builtin::cornell();
        let mesh = mesh_scene_uniform(&scene, 300).expect("cornell meshes");
        let floor = scene.surface_id("floor").expect("floor");
        let m = &mesh.surfaces[floor];
        let values: Vec<Rgb> = (0..m.vertex_count())
            .map(|i| Rgb::new(1.0 + i as f64, 2.0, 0.5))
            .collect();
        for radiosity in [None, Some(values.as_slice())] {
            let svg = surface_svg(&scene, m, radiosity, &[]);
            assert!(svg.starts_with("<?xml") || svg.starts_with("<svg"));
            assert!(svg.trim_end().ends_with("</svg>"));
            assert_eq!(svg.matches("<polygon").count(), m.triangle_count());
            assert!(svg.contains("floor"));
            assert_eq!(svg, surface_svg(&scene, m, radiosity, &[]));
            let filled = svg
                .lines()
                .filter(|l| l.starts_with("<polygon") && l.contains("fill="))
                .count();
            let expected = if radiosity.is_some() {
                m.triangle_count()
            } else {
                0
            };
            assert_eq!(filled, expected);
        }
        let svg = surface_svg(&scene, m, Some(&values[1..]), &[]);
        assert!(svg.contains("radiosity not shown"));
    }
}
