//! The element budget: how many triangles a scene's mesh may have in all.
//!
//! A budget is either a cap the caller chose ([`ElementBudget::AtMost`]), which is an error when
//! the scene cannot be meshed within it, or "what the scene needs" ([`ElementBudget::Fit`]),
//! which grows with the scene. A scene's least mesh is known only once its discontinuity
//! segments are inserted as constraint edges (each constraint can only add triangles), so a
//! fitted budget is resolved then, inside [`crate::mesh_scene_discontinuity`] and
//! [`crate::mesh_scene_uniform`]. Before that, [`polygon_minimum`] is a lower bound known
//! from the polygons alone.
//!
//! ```
//! use penumbra_meshing::{ElementBudget, FIT_TRIANGLES_PER_SURFACE};
//! let fit = ElementBudget::fit(10_000);
//! // A small scene: the floor of the fitted budget.
//! assert_eq!(fit.resolve(40, 10).ok(), Some(10_000));
//! // A large one: its least mesh and a few triangles more per surface.
//! let fitted = fit.resolve(49_229, 30_000);
//! assert_eq!(fitted.ok(), Some(49_229 + FIT_TRIANGLES_PER_SURFACE * 30_000));
//! assert!(ElementBudget::AtMost(10_000).resolve(49_229, 30_000).is_err());
//! ```

use penumbra_scenes::Scene;

use crate::error::MeshError;

/// Triangles per surface that a budget fitted to the scene adds beyond the scene's least mesh,
/// so that the larger surfaces get some refinement (the budget is spread by area) while a scene
/// of tens of thousands of small faces stays close to its least mesh. (Four per surface gave a
/// tessellated statue in a box 133,000 triangles on the box's walls and tripled the time of its
/// direct light; the walls' light is exact at their vertices either way.)
pub const FIT_TRIANGLES_PER_SURFACE: usize = 1;

/// How many triangles the mesh of a whole scene may have.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ElementBudget {
    /// At most this many; a scene whose least mesh has more is refused
    /// ([`MeshError::BudgetTooSmall`]).
    AtMost(usize),
    /// What the scene needs: `at_least` triangles, or the scene's least mesh plus `per_surface`
    /// triangles per surface when that is more ([`ElementBudget::fit`]: the usual
    /// [`FIT_TRIANGLES_PER_SURFACE`]).
    Fit {
        /// The fewest triangles to give the scene.
        at_least: usize,
        /// Triangles per surface beyond the scene's least mesh.
        per_surface: usize,
    },
}

impl From<usize> for ElementBudget {
    fn from(max_elements: usize) -> Self {
        ElementBudget::AtMost(max_elements)
    }
}

impl ElementBudget {
    /// What the scene needs, at least `at_least` triangles, with [`FIT_TRIANGLES_PER_SURFACE`]
    /// beyond the least mesh.
    pub const fn fit(at_least: usize) -> ElementBudget {
        ElementBudget::Fit {
            at_least,
            per_surface: FIT_TRIANGLES_PER_SURFACE,
        }
    }

    /// The number of triangles for a scene of `surfaces` surfaces whose least mesh has
    /// `minimum` triangles (polygons only, or with their discontinuities as edges, as
    /// `discontinuities` says: it only words the error).
    pub fn resolve_for(
        self,
        minimum: usize,
        surfaces: usize,
        discontinuities: bool,
    ) -> Result<usize, MeshError> {
        match self {
            ElementBudget::AtMost(max_elements) if minimum > max_elements => {
                Err(MeshError::BudgetTooSmall {
                    max_elements,
                    needed: minimum,
                    discontinuities,
                })
            }
            ElementBudget::AtMost(max_elements) => Ok(max_elements),
            ElementBudget::Fit {
                at_least,
                per_surface,
            } => Ok(at_least.max(minimum.saturating_add(per_surface.saturating_mul(surfaces)))),
        }
    }

    /// [`Self::resolve_for`] a least mesh of the polygons alone.
    pub fn resolve(self, minimum: usize, surfaces: usize) -> Result<usize, MeshError> {
        self.resolve_for(minimum, surfaces, false)
    }

    /// For a fitted budget of a scene whose polygons alone need more than its floor (a large
    /// scene: `polygon_minimum` triangles over `surfaces` surfaces), the triangles it adds to the
    /// least mesh (`per_surface` for each surface). Each surface then gets its least mesh and
    /// its share of these by area: the budget the fit resolves to, spread
    /// so that each surface's part depends on nothing but the surface and the scene's polygons,
    /// and each surface can be meshed without the others' discontinuities (a sharded run).
    /// `None` for a cap, or a scene within the floor: one budget is spread over all surfaces by
    /// area.
    pub fn shared_extra(self, polygon_minimum: usize, surfaces: usize) -> Option<usize> {
        match self {
            ElementBudget::Fit {
                at_least,
                per_surface,
            } => {
                let extra = per_surface.saturating_mul(surfaces);
                (polygon_minimum.saturating_add(extra) > at_least).then_some(extra)
            }
            ElementBudget::AtMost(_) => None,
        }
    }

    /// The triangles of some of a large scene's surfaces meshed alone (a shard): their least
    /// mesh (`minimum`) and `share` of the fit's triangles per surface over all the scene's
    /// `surfaces`, so that parts whose shares add up to one add up to the scene's fit; `None`
    /// for a cap.
    pub fn part(self, minimum: usize, surfaces: usize, share: f64) -> Option<usize> {
        match self {
            ElementBudget::Fit { per_surface, .. } => {
                let extra = per_surface.saturating_mul(surfaces) as f64 * share.clamp(0.0, 1.0);
                Some(minimum.saturating_add(extra.round() as usize))
            }
            ElementBudget::AtMost(_) => None,
        }
    }

    /// The cap, if the caller chose one.
    pub fn at_most(self) -> Option<usize> {
        match self {
            ElementBudget::AtMost(n) => Some(n),
            ElementBudget::Fit { .. } => None,
        }
    }
}

/// Triangles a polygon of `vertices` corners needs at least: `vertices - 2` (and one for a
/// degenerate polygon, which validation refuses anyway).
pub(crate) fn polygon_triangles(vertices: usize) -> usize {
    vertices.saturating_sub(2).max(1)
}

/// The least number of triangles any mesh of `scene` has: each polygon of n corners needs
/// n - 2. Discontinuity segments inserted as edges can only add to it.
pub fn polygon_minimum(scene: &Scene) -> usize {
    scene
        .surfaces
        .iter()
        .map(|s| polygon_triangles(s.polygon.len()))
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cap_refuses_what_does_not_fit_and_a_fitted_budget_grows() {
        assert_eq!(ElementBudget::from(500), ElementBudget::AtMost(500));
        assert_eq!(ElementBudget::AtMost(500).resolve(500, 3).ok(), Some(500));
        assert!(matches!(
            ElementBudget::AtMost(499).resolve_for(500, 3, true),
            Err(MeshError::BudgetTooSmall {
                max_elements: 499,
                needed: 500,
                discontinuities: true
            })
        ));
        let fit = ElementBudget::fit(1000);
        assert_eq!(fit.resolve(10, 3).ok(), Some(1000));
        assert_eq!(
            fit.resolve(998, 3).ok(),
            Some(998 + 3 * FIT_TRIANGLES_PER_SURFACE)
        );
        assert_eq!(fit.resolve(usize::MAX, 3).ok(), Some(usize::MAX));
        assert_eq!(fit.at_most(), None);
        // The least mesh itself, when that is more than `at_least`.
        let least = ElementBudget::Fit {
            at_least: 1000,
            per_surface: 0,
        };
        assert_eq!(least.resolve(1500, 3).ok(), Some(1500));
        // Surfaces are meshed alone once the polygons need more than the floor.
        assert_eq!(fit.shared_extra(990, 10), None);
        assert_eq!(
            fit.shared_extra(999, 3),
            Some(3 * FIT_TRIANGLES_PER_SURFACE)
        );
        assert_eq!(ElementBudget::AtMost(10).shared_extra(999, 3), None);
        // Parts of a large scene meshed alone: each its least mesh and its share of the extra,
        // without the floor; shares adding up to one add up to the scene's fit.
        let fit = ElementBudget::Fit {
            at_least: 1000,
            per_surface: 2,
        };
        let parts: usize = [(700, 0.25), (500, 0.5), (300, 0.25)]
            .iter()
            .filter_map(|&(minimum, share)| fit.part(minimum, 1000, share))
            .sum();
        assert_eq!(Some(parts), fit.resolve(1500, 1000).ok());
        assert_eq!(fit.part(10, 1000, 0.0), Some(10));
        assert_eq!(ElementBudget::AtMost(5000).part(10, 1000, 0.5), None);
        let square = penumbra_scenes::builtin::textbook();
        // Three quadrilaterals: two triangles each.
        assert_eq!(polygon_minimum(&square), 6);
    }
}
