//! Which surfaces of a run get an SVG, and the files' names.

use penumbra_scenes::{Scene, SurfaceId};

use crate::run_result::RunResult;

/// The directory, inside the output directory, of the surfaces' SVGs.
pub const SVG_DIR: &str = "surfaces";

/// Surfaces that get an SVG by default, at most: a figure a person can look through, not one
/// per face of a scanned statue or a cathedral (75,000 of them).
pub const DEFAULT_SVG_SURFACES: usize = 24;

/// Which surfaces get an SVG (`--svg`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum SvgSelection {
    /// The surfaces worth looking at: every surface of a scene of at most
    /// [`DEFAULT_SVG_SURFACES`]; else that many, those with the most discontinuity segments
    /// first, then the largest, then the first in the scene.
    #[default]
    Auto,
    /// Every surface.
    All,
    /// No surface.
    None,
    /// These surfaces, by index.
    Named(Vec<SurfaceId>),
}

impl SvgSelection {
    /// The surfaces of `scene` named in `names` (exact names), or the names it does not have.
    pub fn named(scene: &Scene, names: &[String]) -> Result<SvgSelection, Vec<String>> {
        let mut ids = Vec::new();
        let mut unknown = Vec::new();
        for name in names {
            match scene.surface_id(name) {
                Some(id) => ids.push(id),
                None => unknown.push(name.clone()),
            }
        }
        if !unknown.is_empty() {
            return Err(unknown);
        }
        ids.sort_unstable();
        ids.dedup();
        Ok(SvgSelection::Named(ids))
    }

    /// How `report.json` names the selection.
    pub fn name(&self) -> &'static str {
        match self {
            SvgSelection::Auto => "auto",
            SvgSelection::All => "all",
            SvgSelection::None => "none",
            SvgSelection::Named(_) => "named",
        }
    }

    /// The surfaces that get an SVG, in the scene's order.
    pub fn surfaces(&self, result: &RunResult) -> Vec<SurfaceId> {
        let scene = &result.loaded.scene;
        match self {
            SvgSelection::All => (0..scene.surfaces.len()).collect(),
            SvgSelection::None => Vec::new(),
            SvgSelection::Named(ids) => ids.clone(),
            SvgSelection::Auto => {
                let segments: Vec<usize> =
                    result.mesh.discontinuities.iter().map(Vec::len).collect();
                worth_looking_at(scene, &segments, DEFAULT_SVG_SURFACES)
            }
        }
    }
}

/// At most `count` surfaces of `scene`, in its order: those with the most discontinuity
/// segments (`segments[s]`), then the largest, then the first.
pub fn worth_looking_at(scene: &Scene, segments: &[usize], count: usize) -> Vec<SurfaceId> {
    let areas: Vec<f64> = scene
        .surfaces
        .iter()
        .map(penumbra_scenes::Surface::area)
        .collect();
    let mut ranked: Vec<SurfaceId> = (0..scene.surfaces.len()).collect();
    let segments_of = |s: SurfaceId| segments.get(s).copied().unwrap_or(0);
    ranked.sort_by(|&a, &b| {
        segments_of(b)
            .cmp(&segments_of(a))
            .then(areas[b].total_cmp(&areas[a]))
            .then(a.cmp(&b))
    });
    ranked.truncate(count);
    ranked.sort_unstable();
    ranked
}

/// A file name for a surface's SVG: its index (names may clash once sanitized) and its name.
pub fn svg_name(index: usize, name: &str) -> String {
    format!("{}.svg", file_safe_name(index, name))
}

/// A name for surface `index` called `name` that is safe in file names and OBJ materials: its
/// index, then its name with every character but ASCII letters, digits, `-` and `_` made `_`.
pub fn file_safe_name(index: usize, name: &str) -> String {
    let clean: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("{index:03}-{clean}")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The default SVGs: most discontinuity segments first, then the largest surface, then the
    /// first; in the scene's order; all of a small scene.
    #[test]
    fn the_surfaces_worth_looking_at_are_ranked_by_segments_then_area() {
        let scene = penumbra_scenes::builtin::boxworld(10, 1);
        let id = |name: &str| scene.surface_id(name).expect("named");
        let mut segments = vec![0; scene.surfaces.len()];
        segments[id("box7_side1")] = 5;
        segments[id("box3_top")] = 5;
        segments[id("box2_side0")] = 2;
        let picked = worth_looking_at(&scene, &segments, 4);
        // The floor is the largest surface without segments.
        let mut expected = vec![
            id("box7_side1"),
            id("box3_top"),
            id("box2_side0"),
            id("floor"),
        ];
        expected.sort_unstable();
        assert_eq!(picked, expected);
        // The textbook scene: the floor is largest; the light and the blocker are unit squares,
        // equal in area to rounding at most, and the first in the scene wins the tie.
        let textbook = penumbra_scenes::builtin::textbook();
        assert_eq!(textbook.surfaces[0].area(), textbook.surfaces[1].area());
        assert_eq!(worth_looking_at(&textbook, &[0, 0, 0], 2), [0, 2]);
        assert_eq!(
            worth_looking_at(&scene, &segments, 1000),
            (0..scene.surfaces.len()).collect::<Vec<_>>()
        );
        assert!(worth_looking_at(&scene, &[], 0).is_empty());
    }
}
