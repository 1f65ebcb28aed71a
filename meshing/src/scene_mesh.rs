//! Meshes for a whole scene, with the element budget spread over the surfaces by area.

use std::collections::BTreeSet;

use rayon::prelude::*;

use glam::DVec3;
use penumbra_scenes::{PlaneFrame, Scene, SurfaceId, Visibility};

use crate::budget::{ElementBudget, polygon_minimum, polygon_triangles};
use crate::constrained::{ConstrainedSurface, Constraint, RefinableSurface};
use crate::discontinuity::{
    Discontinuities, DiscontinuitySegment, DiscontinuityStats, EmitterProbe, Event,
};
use crate::error::MeshError;
use crate::mesh::SurfaceMesh;
use crate::progress::Interrupt;
use crate::quality::{MeshQuality, quality_of};
use crate::tolerances::CONSTRAINED_MIN_ANGLE_DEG;

/// One mesh per surface, in the scene's surface order, and the discontinuities the meshes follow
/// (none for uniform meshes).
#[derive(Clone, Debug)]
pub struct SceneMesh {
    /// Each surface's mesh.
    pub surfaces: Vec<SurfaceMesh>,
    /// Each surface's triangulation, kept for adaptive refinement.
    pub refinable: Vec<RefinableSurface>,
    /// Each surface's discontinuity segments (empty lists for uniform meshes).
    pub discontinuities: Vec<Vec<DiscontinuitySegment>>,
    /// Each surface's contact lines under hovering faces, with their gaps (3D ends, gap).
    pub hovering: Vec<Vec<(DVec3, DVec3, f64)>>,
    /// What the discontinuity search did (`None` for uniform meshes).
    pub discontinuity_stats: Option<DiscontinuityStats>,
    /// The element budget the mesh was built to, resolved (see [`ElementBudget`]).
    pub budget: usize,
    /// The least number of triangles any mesh of the scene with these constraints has: each
    /// surface's constrained triangulation before refinement.
    pub minimum_triangles: usize,
    /// The exact direct irradiance at the vertices where it was measured while the mesh was
    /// made (error-driven meshes), per surface and vertex; empty, or `None`, where it was not.
    /// Solvers take these values instead of evaluating them again.
    pub measured_direct: Vec<Vec<Option<penumbra_scenes::Rgb>>>,
}

impl SceneMesh {
    /// Triangles of all the surfaces.
    pub fn triangle_count(&self) -> usize {
        self.surfaces.iter().map(SurfaceMesh::triangle_count).sum()
    }

    /// Vertices of all the surfaces (a vertex where surfaces meet counts once per surface).
    pub fn vertex_count(&self) -> usize {
        self.surfaces.iter().map(SurfaceMesh::vertex_count).sum()
    }

    /// Quality figures over every surface's mesh.
    pub fn quality(&self) -> MeshQuality {
        quality_of(&self.surfaces)
    }

    /// [`SurfaceMesh::sanity_check`] of every surface.
    pub fn sanity_check(&self) -> Result<(), MeshError> {
        self.surfaces.iter().try_for_each(SurfaceMesh::sanity_check)
    }

    /// Discontinuity segments of all the surfaces.
    pub fn segment_count(&self) -> usize {
        self.discontinuities.iter().map(Vec::len).sum()
    }

    /// Splits the listed triangles of surface `surface` (indices into its current mesh), never
    /// across a constraint, restores quality around them and rebuilds that surface's mesh.
    /// Returns how many vertices the triangulation gained.
    pub fn split_triangles(
        &mut self,
        scene: &Scene,
        surface: SurfaceId,
        triangles: &[usize],
    ) -> usize {
        let Some(mesh) = self.surfaces.get(surface) else {
            return 0;
        };
        let at: Vec<glam::DVec2> = triangles
            .iter()
            .filter_map(|&t| mesh.triangles.get(t))
            .map(|tri| {
                tri.iter()
                    .map(|&i| mesh.local[i as usize])
                    .sum::<glam::DVec2>()
                    / 3.0
            })
            .collect();
        // A mesh put together without its triangulations cannot be refined.
        let (Some(refinable), Some(s)) =
            (self.refinable.get_mut(surface), scene.surfaces.get(surface))
        else {
            return 0;
        };
        let added = refinable.split_at(&at);
        if added > 0 {
            self.surfaces[surface] = refinable.mesh(s);
        }
        added
    }
}

/// Splits a budget over the surfaces in proportion to their areas, giving each at least
/// `minimum[s]` triangles; `discontinuities` says whether the minima count discontinuity edges
/// (it only words the error). A fitted budget is resolved from the minima
/// ([`ElementBudget::resolve_for`]). Returns the resolved budget and the targets, which never
/// sum to more than it.
pub(crate) fn spread_by_area(
    areas: &[f64],
    minimum: &[usize],
    budget: impl Into<ElementBudget>,
    discontinuities: bool,
) -> Result<(usize, Vec<usize>), MeshError> {
    let needed: usize = minimum.iter().sum();
    let max_elements = budget
        .into()
        .resolve_for(needed, minimum.len(), discontinuities)?;
    let total: f64 = areas.iter().sum();
    let mut spread = max_elements;
    loop {
        let targets: Vec<usize> = areas
            .iter()
            .zip(minimum)
            .map(|(&a, &m)| ((spread as f64 * a / total).floor() as usize).max(m))
            .collect();
        let sum: usize = targets.iter().sum();
        if sum <= max_elements {
            return Ok((max_elements, targets));
        }
        spread -= (sum - max_elements).min(spread);
    }
}

/// A uniform mesh of every surface, about `budget` triangles in all, spread by area.
pub fn mesh_scene_uniform(
    scene: &Scene,
    budget: impl Into<ElementBudget>,
) -> Result<SceneMesh, MeshError> {
    mesh_scene_uniform_until(scene, budget, None)
}

/// [`mesh_scene_uniform`], the surfaces meshed in parallel, stopped with
/// [`MeshError::Interrupted`] once `interrupt` is set (between surfaces, and between one
/// surface's trial refinements).
pub fn mesh_scene_uniform_until(
    scene: &Scene,
    budget: impl Into<ElementBudget>,
    interrupt: Option<&Interrupt>,
) -> Result<SceneMesh, MeshError> {
    let areas: Vec<f64> = scene
        .surfaces
        .iter()
        .map(penumbra_scenes::Surface::area)
        .collect();
    // A polygon of n vertices needs n - 2 triangles.
    let minimum: Vec<usize> = scene
        .surfaces
        .iter()
        .map(|s| polygon_triangles(s.polygon.len()))
        .collect();
    let (budget, targets) = spread_by_area(&areas, &minimum, budget, false)?;
    let refinable = scene
        .surfaces
        .par_iter()
        .zip(targets)
        .enumerate()
        .map(|(id, (s, target))| {
            go_on(interrupt)?;
            RefinableSurface::uniform_until(id, s, target, interrupt)
        })
        .collect::<Result<Vec<_>, _>>()?;
    go_on(interrupt)?;
    let surfaces = refinable
        .par_iter()
        .zip(&scene.surfaces)
        .map(|(r, s)| r.mesh(s))
        .collect();
    Ok(SceneMesh {
        discontinuities: vec![Vec::new(); scene.surfaces.len()],
        hovering: vec![Vec::new(); scene.surfaces.len()],
        surfaces,
        refinable,
        discontinuity_stats: None,
        budget,
        minimum_triangles: minimum.iter().sum(),
        measured_direct: Vec::new(),
    })
}

/// Discontinuity meshes: each surface's discontinuity segments become constraint edges, then the
/// surfaces are refined to about `budget` triangles in all, spread by area, with triangles
/// `penumbra_density` times smaller in area where the light varies (1: no grading; see
/// [`DEFAULT_PENUMBRA_DENSITY`](crate::DEFAULT_PENUMBRA_DENSITY)).
pub fn mesh_scene_discontinuity(
    scene: &Scene,
    visibility: &Visibility,
    found: Discontinuities,
    budget: impl Into<ElementBudget>,
    penumbra_density: f64,
) -> Result<SceneMesh, MeshError> {
    let options = DiscontinuityMeshing {
        penumbra_density,
        ..DiscontinuityMeshing::default()
    };
    mesh_scene_discontinuity_on(scene, visibility, found, budget, &options)
}

/// How [`mesh_scene_discontinuity_on`] meshes.
#[derive(Clone, Copy, Debug)]
pub struct DiscontinuityMeshing<'a> {
    /// Triangles this many times smaller in area where the light varies (1: no grading).
    pub penumbra_density: f64,
    /// The smallest angle refinement aims for where the constraints allow (0: none; at most
    /// [`MAX_MIN_ANGLE_DEG`](crate::MAX_MIN_ANGLE_DEG)).
    pub min_angle_deg: f64,
    /// The surfaces to mesh, when each one's share of the budget depends on it alone (`None`:
    /// all).
    pub on: Option<&'a [bool]>,
    /// Meshing stops, with [`MeshError::Interrupted`], once this is set: between the surfaces'
    /// steps (one surface's refinement is not cut).
    pub interrupt: Option<&'a Interrupt>,
}

impl Default for DiscontinuityMeshing<'_> {
    fn default() -> Self {
        DiscontinuityMeshing {
            penumbra_density: 1.0,
            min_angle_deg: CONSTRAINED_MIN_ANGLE_DEG,
            on: None,
            interrupt: None,
        }
    }
}

impl DiscontinuityMeshing<'_> {
    /// [`MeshError::Interrupted`] once the interrupt is set.
    fn go_on(&self) -> Result<(), MeshError> {
        go_on(self.interrupt)
    }
}

/// [`MeshError::Interrupted`] once `interrupt` is set.
fn go_on(interrupt: Option<&Interrupt>) -> Result<(), MeshError> {
    match interrupt {
        Some(i) if i.is_set() => Err(MeshError::Interrupted),
        _ => Ok(()),
    }
}

/// Discontinuity segment ends within this many contact distances of another end or segment are
/// joined to it in the mesh: the search places a trimmed end to within a contact distance (where
/// hits stop counting) plus its trimming tolerance (at most one more).
pub(crate) const JOIN_CONTACT_DISTANCES: f64 = 4.0;

/// [`mesh_scene_discontinuity`] as `options` say: of the surfaces `options.on` holds (all when
/// `None`), when each surface's share of the budget depends on it alone
/// ([`ElementBudget::shared_extra`]): the others get an empty mesh, and the budget, counts and
/// least mesh are those of the surfaces meshed. A budget spread over all surfaces needs every
/// surface's least mesh, so then every surface is meshed. A surface's mesh is the same
/// whichever others are meshed.
pub fn mesh_scene_discontinuity_on(
    scene: &Scene,
    visibility: &Visibility,
    found: Discontinuities,
    budget: impl Into<ElementBudget>,
    options: &DiscontinuityMeshing,
) -> Result<SceneMesh, MeshError> {
    let (on, min_angle_deg) = (options.on, options.min_angle_deg);
    let budget = budget.into();
    let join = JOIN_CONTACT_DISTANCES * visibility.contact_distance();
    let alone = budget.shared_extra(polygon_minimum(scene), scene.surfaces.len());
    let meshed: Vec<bool> = (0..scene.surfaces.len())
        .map(|id| alone.is_none() || on.is_none_or(|on| on.get(id).copied().unwrap_or(false)))
        .collect();
    let mut constrained = scene
        .surfaces
        .par_iter()
        .enumerate()
        .map(|(id, s)| {
            if !meshed[id] {
                return Ok(None);
            }
            options.go_on()?;
            let segments = found.segments.get(id).map(Vec::as_slice).unwrap_or(&[]);
            constrained_surface(id, s, segments, join, min_angle_deg).map(Some)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let areas: Vec<f64> = scene
        .surfaces
        .iter()
        .map(penumbra_scenes::Surface::area)
        .collect();
    let minimum: Vec<usize> = constrained
        .iter()
        .map(|c| c.as_ref().map_or(0, ConstrainedSurface::minimum_triangles))
        .collect();
    let (budget, targets) = match alone {
        Some(extra) => share_alone(&areas, &minimum, &meshed, extra),
        None => spread_with_quality(&areas, &minimum, &mut constrained, budget, options)?,
    };
    options.go_on()?;
    let minimum_triangles = minimum.iter().sum();
    let grading = Grading {
        scene,
        visibility,
        segments: &found.segments,
        penumbra_density: options.penumbra_density,
        interrupt: options.interrupt,
    };
    let refinable: Vec<Option<RefinableSurface>> = constrained
        .into_par_iter()
        .zip(targets)
        .enumerate()
        .map(|(id, (c, target))| match c {
            Some(c) => options
                .go_on()
                .map(|()| Some(grading.refinable(id, c, target))),
            None => Ok(None),
        })
        .collect::<Result<_, _>>()?;
    options.go_on()?;
    let (surfaces, refinable) = meshes_of(scene, refinable)?;
    let mut discontinuities = found.segments;
    discontinuities.resize(scene.surfaces.len(), Vec::new());
    let mut hovering = found.hovering;
    hovering.resize(scene.surfaces.len(), Vec::new());
    Ok(SceneMesh {
        surfaces,
        refinable,
        discontinuities,
        hovering,
        discontinuity_stats: Some(found.stats),
        budget,
        minimum_triangles,
        measured_direct: Vec::new(),
    })
}

/// Surface `id`'s triangulation with its discontinuity `segments` as constraints (contact lines
/// among them split it), their ends within `join` of each other joined where spade allows,
/// refined later to angles of at least `min_angle_deg`.
fn constrained_surface(
    id: SurfaceId,
    surface: &penumbra_scenes::Surface,
    segments: &[DiscontinuitySegment],
    join: f64,
    min_angle_deg: f64,
) -> Result<ConstrainedSurface, MeshError> {
    let constraints: Vec<Constraint> = match PlaneFrame::of_polygon(&surface.polygon) {
        Some(frame) => segments
            .iter()
            .map(|g| Constraint {
                from: frame.to_2d(g.from),
                to: frame.to_2d(g.to),
                splits: g.event == Event::Contact,
            })
            .collect(),
        None => Vec::new(),
    };
    // Joined ends can leave two lines of nearly one direction from one point, which spade's
    // constraint insertion does not survive; those surfaces keep the ends apart.
    ConstrainedSurface::joining(id, surface, &constraints, join)
        .or_else(|_| ConstrainedSurface::new(id, surface, &constraints))
        .map(|c| c.with_min_angle(min_angle_deg))
}

/// `budget` spread over every surface by area, resolved ([`spread_by_area`]), with the least
/// meshes grown to least quality meshes where [`quality_minima`] finds room for them: the
/// resolved budget and the targets.
fn spread_with_quality(
    areas: &[f64],
    minimum: &[usize],
    constrained: &mut [Option<ConstrainedSurface>],
    budget: ElementBudget,
    options: &DiscontinuityMeshing,
) -> Result<(usize, Vec<usize>), MeshError> {
    let (budget, shares) = spread_by_area(areas, minimum, budget, true)?;
    let room = (QUALITY_EXTRA_SHARE * budget as f64) as usize;
    let quality: Vec<Option<usize>> = constrained
        .par_iter_mut()
        .zip(&shares)
        .map(|(c, &t)| {
            options.go_on()?;
            Ok(c.as_mut().and_then(|c| c.quality_triangles(t + room)))
        })
        .collect::<Result<_, MeshError>>()?;
    let minima = quality_minima(minimum, &shares, &quality, budget);
    spread_by_area(areas, &minima, budget, true)
}

/// How refinement grades a surface: triangles `penumbra_density` times smaller in area where
/// the light of an emitter whose discontinuities cross the surface varies.
struct Grading<'a> {
    scene: &'a Scene,
    visibility: &'a Visibility,
    /// Each surface's discontinuity segments, which name the emitters that shade it.
    segments: &'a [Vec<DiscontinuitySegment>],
    penumbra_density: f64,
    /// Refinement is given up once this is set.
    interrupt: Option<&'a Interrupt>,
}

impl Grading<'_> {
    /// Surface `id`'s triangulation `c` refined to about `target` triangles, graded where the
    /// light varies (not at all on a surface without a plane).
    fn refinable(&self, id: SurfaceId, c: ConstrainedSurface, target: usize) -> RefinableSurface {
        let surface = &self.scene.surfaces[id];
        let Some(frame) = PlaneFrame::of_polygon(&surface.polygon) else {
            return c.into_refinable(target, 1.0, &|_| false, self.interrupt);
        };
        let emitters: BTreeSet<SurfaceId> = self
            .segments
            .get(id)
            .into_iter()
            .flatten()
            .map(|g| g.emitter)
            .collect();
        let probes: Vec<EmitterProbe> = emitters
            .into_iter()
            .map(|e| EmitterProbe::new(self.scene, e))
            .collect();
        let varies = |points: &[DVec3]| {
            probes.iter().any(|probe| {
                let (lo, hi) = points.iter().fold((1.0f64, 0.0f64), |(lo, hi), &x| {
                    let f = probe.visible_fraction(self.visibility, x, frame.normal, id);
                    (lo.min(f), hi.max(f))
                });
                hi > 0.0 && lo < 1.0
            })
        };
        c.into_refinable(target, self.penumbra_density, &varies, self.interrupt)
    }
}

/// Each surface's mesh and its triangulation, kept for adaptive refinement; a surface not meshed
/// (`None`) gets an empty mesh and an unrefined triangulation.
fn meshes_of(
    scene: &Scene,
    refinable: Vec<Option<RefinableSurface>>,
) -> Result<(Vec<SurfaceMesh>, Vec<RefinableSurface>), MeshError> {
    let surfaces = refinable
        .par_iter()
        .zip(&scene.surfaces)
        .enumerate()
        .map(|(id, (r, s))| match r {
            Some(r) => Ok(r.mesh(s)),
            None => SurfaceMesh::empty(id, s),
        })
        .collect::<Result<Vec<_>, _>>()?;
    let refinable = refinable
        .into_iter()
        .zip(&scene.surfaces)
        .enumerate()
        .map(|(id, (r, s))| match r {
            Some(r) => Ok(r),
            None => RefinableSurface::uniform(id, s, 0),
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((surfaces, refinable))
}

/// At most this share of a budget goes to surfaces beyond their share by area, so that their
/// least meshes at the quality refinement's angle fit: a small face crossed by lines at a small
/// angle (a block's side in the Cornell box) needs a few hundred triangles for that.
pub(crate) const QUALITY_EXTRA_SHARE: f64 = 0.125;

/// The least meshes to spread a budget over: each surface's least quality mesh (`quality[s]`)
/// instead of its least mesh (`minimum[s]`) where that is within its share `targets[s]`, and
/// for as many others as [`QUALITY_EXTRA_SHARE`] of `budget` holds (and the least meshes
/// together fit it), those that need the fewest triangles beyond their share first.
pub(crate) fn quality_minima(
    minimum: &[usize],
    targets: &[usize],
    quality: &[Option<usize>],
    budget: usize,
) -> Vec<usize> {
    let mut minima = minimum.to_vec();
    // (triangles beyond the share, surface, least quality mesh)
    let mut beyond: Vec<(usize, usize, usize)> = Vec::new();
    for (s, q) in quality.iter().enumerate() {
        match *q {
            Some(q) if q <= targets[s] => minima[s] = q,
            Some(q) => beyond.push((q - targets[s], s, q)),
            None => {}
        }
    }
    beyond.sort_unstable();
    let mut room = (QUALITY_EXTRA_SHARE * budget as f64) as usize;
    let mut total: usize = minima.iter().sum();
    for (extra, s, q) in beyond {
        // The least meshes must still fit the budget together.
        let grown = total + (q - minima[s]);
        if extra > room || grown > budget {
            break;
        }
        room -= extra;
        total = grown;
        minima[s] = q;
    }
    minima
}

/// Each surface's least mesh (`minimum[s]`) and its share of `extra` triangles by area: a
/// target that depends on the surface alone, and targets that sum to the least mesh and at most
/// `extra`. Surfaces not `meshed` get none. Returns the targets' sum and the targets.
pub(crate) fn share_alone(
    areas: &[f64],
    minimum: &[usize],
    meshed: &[bool],
    extra: usize,
) -> (usize, Vec<usize>) {
    let total: f64 = areas.iter().sum();
    let targets: Vec<usize> = areas
        .iter()
        .zip(minimum)
        .zip(meshed)
        .map(|((&a, &m), &meshed)| match meshed {
            true => m + (extra as f64 * a / total).floor() as usize,
            false => 0,
        })
        .collect();
    (targets.iter().sum(), targets)
}

#[cfg(test)]
mod tests {
    use super::*;
    use penumbra_scenes::builtin;

    #[test]
    fn budget_is_a_cap_and_follows_area() {
        let (budget, t) =
            spread_by_area(&[1.0, 1.0, 2.0, 1e-6], &[2, 2, 2, 2], 1000, false).expect("fits");
        assert_eq!(budget, 1000);
        assert!(t.iter().sum::<usize>() <= 1000);
        assert!(t[2] > t[0] + t[0] / 2);
        assert_eq!(t[3], 2);
        assert!(matches!(
            spread_by_area(&[1.0, 1.0], &[5, 5], 8, false),
            Err(MeshError::BudgetTooSmall { needed: 10, .. })
        ));
        // Fitted to the scene: the minimum and a few triangles more per surface.
        let fit = ElementBudget::fit(8);
        let (budget, t) = spread_by_area(&[1.0, 3.0], &[5, 5], fit, false).expect("fits");
        assert_eq!(budget, 10 + 2 * crate::FIT_TRIANGLES_PER_SURFACE);
        assert!(t.iter().sum::<usize>() <= budget && t[1] > t[0], "{t:?}");
    }

    /// Shared alone: each surface's least mesh and its area's part of the extra triangles,
    /// whatever the other surfaces' minima; surfaces not meshed get nothing.
    #[test]
    fn shares_alone_depend_on_each_surface_alone() {
        let areas = [1.0, 3.0, 4.0];
        let (sum, t) = share_alone(&areas, &[5, 2, 40], &[true; 3], 80);
        assert_eq!(t, [5 + 10, 2 + 30, 40 + 40]);
        assert_eq!(sum, 127);
        let (sum, t) = share_alone(&areas, &[5, 900, 40], &[true, false, true], 80);
        assert_eq!(t, [15, 0, 80]);
        assert_eq!(sum, 95);
    }

    /// Least quality meshes within a surface's share are taken; beyond it, the cheapest first
    /// while an eighth of the budget lasts.
    #[test]
    fn quality_minima_fit_the_cheapest_first() {
        let minimum = [10, 10, 10, 10];
        let targets = [400, 100, 100, 100];
        let quality = [Some(300), Some(150), Some(200), None];
        // 87 triangles beyond the shares: the 50 of surface 1, not the 100 of surface 2.
        assert_eq!(
            quality_minima(&minimum, &targets, &quality, 700),
            [300, 150, 10, 10]
        );
        // 187: both.
        assert_eq!(
            quality_minima(&minimum, &targets, &quality, 1500),
            [300, 150, 200, 10]
        );
        // The least meshes together must fit the budget: 55 + 55 would not.
        assert_eq!(
            quality_minima(&[10, 10], &[50, 50], &[Some(55), Some(55)], 100),
            [55, 10]
        );
    }

    /// The Cornell box at the default budget: each surface's least mesh at 20 degrees fits (the
    /// short block's side, crossed by two lines at a small angle, needs about three times its
    /// share by area), so no angle the input does not force is under 20 degrees.
    #[test]
    fn cornell_keeps_unforced_angles_at_the_default_budget() {
        use crate::discontinuity::{DiscontinuityOptions, find_discontinuities};
        let scene = builtin::cornell();
        let vis = Visibility::build(&scene);
        let budget = 10_000;
        let options = DiscontinuityOptions {
            element_area: Some(scene.total_area() / budget as f64),
            ..DiscontinuityOptions::default()
        };
        let found = find_discontinuities(&scene, &vis, &options);
        let mesh = mesh_scene_discontinuity(
            &scene,
            &vis,
            found,
            budget,
            crate::grading::DEFAULT_PENUMBRA_DENSITY,
        )
        .expect("meshes");
        mesh.sanity_check().expect("sane");
        let q = mesh.quality();
        assert!(q.triangles <= budget, "{q:?}");
        assert_eq!(q.triangles_below_min_angle, 0, "{q:?}");
        assert!(q.min_angle_unforced_deg >= 20.0 - 1e-6, "{q:?}");
        assert!(
            q.min_angle_deg < 20.0,
            "the input forces smaller angles: {q:?}"
        );
    }

    #[test]
    fn cornell_meshes_within_budget() {
        let scene = builtin::cornell();
        for budget in [100, 2000, 10_000] {
            let mesh = mesh_scene_uniform(&scene, budget).expect("cornell meshes");
            mesh.sanity_check().expect("sane");
            let n = mesh.triangle_count();
            assert!(n <= budget, "{n} > {budget}");
            assert!(n as f64 >= 0.7 * budget as f64, "{n} for {budget}");
        }
    }
}
