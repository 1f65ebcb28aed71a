//! Shards: a scene's surfaces split into runs of consecutive surfaces of about equal cost, each
//! lit by a process of its own ([`crate::shard`] writes and joins them).

use penumbra_meshing::discontinuity::EmitterProbe;
use penumbra_meshing::{ElementBudget, polygon_minimum};
use penumbra_scenes::{Scene, SceneTriangle, Visibility, polygon};
use rayon::prelude::*;

use crate::error_mesh::refinable;
use serde::{Deserialize, Serialize};

use super::RunOptions;

/// One of `count` parts of a scene's surfaces: the `index`-th of `count` runs of consecutive
/// surfaces, balanced by their estimated cost ([`surface_costs`]), so that the many small faces
/// of a statue or a tessellated column stay together in a few shards.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// Which part, from 0 to `count - 1`.
    pub index: usize,
    /// How many parts the scene is split into, at least 1.
    pub count: usize,
}

/// Why a shard cannot be run as asked.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
#[non_exhaustive]
pub enum ShardError {
    /// The text given to [`Shard::parse`] is not `I/N`.
    #[error("a shard is written I/N with whole numbers I and N (I from 0 to N - 1), not {0:?}")]
    Syntax(String),
    /// A count of 0.
    #[error("a scene cannot be split into 0 shards")]
    NoShards,
    /// An index not below the count.
    #[error("there is no shard {index} of {count}: shards are numbered from 0 to {}", .count - 1)]
    OutOfRange {
        /// The index asked for.
        index: usize,
        /// The count of shards.
        count: usize,
    },
    /// A full solution was asked for: only the direct light can be split.
    #[error(
        "a full solution cannot be split by surface: light bounces between all surfaces, so each \
         one's radiosity depends on every other's; only the direct light can be split"
    )]
    NeedsDirectOnly,
    /// Adaptive refinement was asked for.
    #[error(
        "adaptive refinement cannot be split by surface: it spends one element budget over the \
         whole scene, against the scene's mean radiosity"
    )]
    Refinement,
    /// A time budget was given.
    #[error(
        "a time budget cannot be split by surface: it would cut the shards short at different \
         points, and their parts would not belong to one run"
    )]
    TimeBudget,
}

impl Shard {
    /// Shard `index` of `count`.
    pub fn new(index: usize, count: usize) -> Result<Shard, ShardError> {
        if count == 0 {
            return Err(ShardError::NoShards);
        }
        if index >= count {
            return Err(ShardError::OutOfRange { index, count });
        }
        Ok(Shard { index, count })
    }

    /// `I/N`, as a scheduler's task number gives it (`0/8` to `7/8`).
    pub fn parse(text: &str) -> Result<Shard, ShardError> {
        let syntax = || ShardError::Syntax(text.to_owned());
        let (i, n) = text.trim().split_once('/').ok_or_else(syntax)?;
        let number = |s: &str| s.trim().parse::<usize>().map_err(|_| syntax());
        Shard::new(number(i)?, number(n)?)
    }

    /// For each of a scene's surfaces, whether it is this shard's, given each one's estimated
    /// cost ([`surface_costs`]): a surface belongs to the shard whose share of the total cost
    /// holds the middle of the surface's own.
    pub fn surfaces(self, costs: &[f64]) -> Vec<bool> {
        let total: f64 = costs.iter().sum();
        let mut before = 0.0;
        costs
            .iter()
            .map(|&cost| {
                let middle = before + cost / 2.0;
                before += cost;
                let block = (middle / total * self.count as f64).floor();
                // Rounding may put the last middle at the very end: it is the last shard's.
                total > 0.0 && (block as usize).min(self.count - 1) == self.index
            })
            .collect()
    }

    /// This shard's surfaces of `scene` in a run of `options` ([`Self::surfaces`]).
    pub fn surfaces_of(self, scene: &Scene, options: &RunOptions) -> Vec<bool> {
        self.part(scene, options).surfaces
    }

    /// This shard's surfaces of `scene` in a run of `options`, and its part of the triangles a
    /// fitted budget adds to the least mesh ([`extra_shares`]): what its surfaces would get in
    /// the run not split, as far as the polygons tell.
    pub fn part(self, scene: &Scene, options: &RunOptions) -> ShardPart {
        let extra = error_driven_shares(scene, options);
        let surfaces = self.surfaces(&costs_with(scene, options, extra.as_deref()));
        let extra = extra.unwrap_or_default();
        let total: f64 = extra.iter().sum();
        let own: f64 = (extra.iter().zip(&surfaces))
            .filter(|(_, own)| **own)
            .map(|(c, _)| c)
            .sum();
        ShardPart {
            surfaces,
            budget_share: if total > 0.0 { own / total } else { 0.0 },
        }
    }

    /// Refuses options whose results cannot be split by surface.
    pub fn check(self, options: &RunOptions) -> Result<(), ShardError> {
        Shard::new(self.index, self.count)?;
        if !options.solver.direct_only {
            return Err(ShardError::NeedsDirectOnly);
        }
        if options.refine.is_some() {
            return Err(ShardError::Refinement);
        }
        if options.time_budget.is_some() {
            return Err(ShardError::TimeBudget);
        }
        Ok(())
    }
}

/// A shard's surfaces and its part of the budget ([`Shard::part`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ShardPart {
    /// For each of the scene's surfaces, whether it is the shard's.
    pub surfaces: Vec<bool>,
    /// The shard's share of the triangles a fitted budget adds to the least mesh.
    pub budget_share: f64,
}

/// Whether a shard of a run with these options finds the discontinuities of its own surfaces and
/// meshes them alone: a fitted budget of a scene whose polygons need more than the budget's
/// floor ([`penumbra_meshing::ElementBudget::shared_extra`]) gives each surface its least mesh
/// and a share that depends on nothing else (an error-driven mesh spends the shard's surfaces'
/// share on them alone). Otherwise each shard meshes the whole scene, as the run not split does.
pub fn meshed_alone(scene: &Scene, options: &RunOptions) -> bool {
    options.refine.is_none()
        && options
            .max_elements
            .shared_extra(polygon_minimum(scene), scene.surfaces.len())
            .is_some()
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// Each surface's estimated share of a shard's work, the points where it evaluates the direct
/// light: about the triangles meshing will give the surface. Spread by area, that is its share
/// of the planned budget, or its polygon's own triangles when that is more. An error-driven mesh
/// gives each surface its own triangles and its part of the fit's extra triangles
/// ([`extra_shares`]); a surface's search for discontinuities and its lines' triangles grow with
/// its size, here as the square root of its area in typical elements (on the Crytek Sponza the
/// search's time per surface grew about so, summed over a shard). The same for every shard of a
/// run, from the scene and the options alone.
pub fn surface_costs(scene: &Scene, options: &RunOptions) -> Vec<f64> {
    costs_with(
        scene,
        options,
        error_driven_shares(scene, options).as_deref(),
    )
}

/// The [`extra_shares`] of an error-driven run (none for other meshes, which spread their
/// budget by area).
fn error_driven_shares(scene: &Scene, options: &RunOptions) -> Option<Vec<f64>> {
    options.error_driven().then(|| extra_shares(scene, options))
}

/// [`surface_costs`], given an error-driven run's [`extra_shares`].
fn costs_with(scene: &Scene, options: &RunOptions, extra: Option<&[f64]>) -> Vec<f64> {
    let planned = planned_triangles(scene, options);
    let area = scene.total_area();
    scene
        .surfaces
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let own = s.polygon.len().saturating_sub(2).max(1) as f64;
            if let Some(extra) = extra {
                own + extra[i] + (planned * s.area() / area.max(f64::MIN_POSITIVE)).sqrt()
            } else if area > 0.0 {
                own.max(planned * s.area() / area)
            } else {
                own
            }
        })
        .collect()
}

/// Each surface's part of the triangles a fitted budget adds to the least mesh (its triangles
/// per surface, over all surfaces), as an error-driven mesh spends them: only on faces large
/// enough to refine ([`crate::error_mesh::refinable`], judged by the whole scene's typical
/// element) that reflect some light, where the measured error is largest, which nothing tells
/// before a run; so by the area of those faces that the light reaches ([`lit_shares`]). (Spread
/// one a surface, the Crytek Sponza's first shard of 16 held 61 % of the area and got 13,109 of
/// them, where the run not split spent 72,251 on the same surfaces: the merged mesh's energy
/// account was 2.6 % off; spread by area alone, four shards got a third of them for the
/// building's dark outer shell, which the sky does not reach.) Equal parts when no face is large
/// enough and lit; none for a cap.
pub fn extra_shares(scene: &Scene, options: &RunOptions) -> Vec<f64> {
    let surfaces = scene.surfaces.len();
    let ElementBudget::Fit { per_surface, .. } = options.max_elements else {
        return vec![0.0; surfaces];
    };
    let extra = per_surface.saturating_mul(surfaces) as f64;
    let element = scene.total_area() / planned_triangles(scene, options).max(1.0);
    let refined: Vec<bool> = (scene.surfaces.iter())
        .map(|s| {
            s.reflectance.max_channel() > 0.0
                && refinable(s.area(), polygon::diameter(&s.polygon), element)
        })
        .collect();
    let lit = lit_shares(scene, &refined);
    let weights: Vec<f64> = (scene.surfaces.iter().zip(&lit))
        .map(|(s, lit)| s.area() * lit)
        .collect();
    let total: f64 = weights.iter().sum();
    if total > 0.0 {
        weights.iter().map(|w| extra * w / total).collect()
    } else {
        vec![per_surface as f64; surfaces]
    }
}

/// For each of the `chosen` surfaces, about the share of its area that sees some light: rays
/// from points spread over its triangles ([`LIT_POINTS`] a triangle) to points spread over each
/// light ([`EmitterProbe`]); 0 for the others. Deterministic, from the scene alone.
fn lit_shares(scene: &Scene, chosen: &[bool]) -> Vec<f64> {
    let mut lit = vec![0.0; scene.surfaces.len()];
    let probes: Vec<EmitterProbe> = (scene.emitters())
        .map(|(e, _)| EmitterProbe::new(scene, e))
        .collect();
    if probes.is_empty() || !chosen.contains(&true) {
        return lit;
    }
    let visibility = Visibility::build(scene);
    let triangles: Vec<&SceneTriangle> = (visibility.triangles().iter())
        .filter(|t| chosen[t.surface])
        .collect();
    // Each triangle's area and lit area, in parallel, then summed in the triangles' order.
    let parts: Vec<(f64, f64)> = triangles
        .par_iter()
        .map(|t| {
            let [a, b, c] = t.vertices;
            let normal = (b - a).cross(c - a);
            let seen: f64 = (LIT_POINTS.iter())
                .map(|w| {
                    let x = a * w[0] + b * w[1] + c * w[2];
                    (probes.iter())
                        .map(|p| p.visible_fraction(&visibility, x, normal, t.surface))
                        .fold(0.0, f64::max)
                })
                .sum();
            let size = 0.5 * normal.length();
            (size, size * seen / LIT_POINTS.len() as f64)
        })
        .collect();
    let mut area = vec![0.0; scene.surfaces.len()];
    for (t, (size, seen)) in triangles.iter().zip(parts) {
        area[t.surface] += size;
        lit[t.surface] += seen;
    }
    for (l, a) in lit.iter_mut().zip(&area) {
        *l = if *a > 0.0 { *l / a } else { 0.0 };
    }
    lit
}

/// Where a triangle is probed for light, in barycentric coordinates: its centroid and a point
/// towards each corner.
const LIT_POINTS: [[f64; 3]; 4] = [
    [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
    [2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0],
    [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
    [1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0],
];

/// The triangles a run of `options` plans for `scene`'s polygons (their least mesh when the
/// cap is below it: that is refused before any shard runs).
fn planned_triangles(scene: &Scene, options: &RunOptions) -> f64 {
    options
        .planned_elements(scene)
        .unwrap_or_else(|_| polygon_minimum(scene)) as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use penumbra_scenes::SplitMix64;

    /// The shards of any count hold every surface once, in runs of consecutive surfaces in
    /// shard order, each within one surface's cost of an equal share.
    #[test]
    fn shards_split_the_surfaces_into_balanced_runs() {
        let mut rng = SplitMix64::new(3);
        for count in [1, 2, 3, 7, 16] {
            let costs: Vec<f64> = (0..200)
                .map(|_| 1.0 + 99.0 * rng.next_f64().powi(4))
                .collect();
            let total: f64 = costs.iter().sum();
            let most = costs.iter().copied().fold(0.0, f64::max);
            let owner: Vec<usize> = (0..costs.len())
                .map(|s| {
                    let owners: Vec<usize> = (0..count)
                        .filter(|&i| Shard { index: i, count }.surfaces(&costs)[s])
                        .collect();
                    assert_eq!(owners.len(), 1, "surface {s} in shards {owners:?}");
                    owners[0]
                })
                .collect();
            assert!(owner.windows(2).all(|w| w[0] <= w[1]), "{owner:?}");
            for i in 0..count {
                let cost: f64 = (0..costs.len())
                    .filter(|&s| owner[s] == i)
                    .map(|s| costs[s])
                    .sum();
                let share = total / count as f64;
                assert!(
                    (cost - share).abs() <= most,
                    "shard {i}/{count}: {cost} against {share}"
                );
            }
        }
    }

    /// A statue of a thousand small faces between a floor and walls lands in the shards its
    /// cost fills, not in every one (as every N-th surface would).
    #[test]
    fn many_small_faces_stay_together() {
        let mut costs = vec![400.0];
        costs.extend(std::iter::repeat_n(0.4, 1000));
        costs.extend(std::iter::repeat_n(100.0, 4));
        let count = 8;
        let holding_statue = (0..count)
            .filter(|&i| Shard { index: i, count }.surfaces(&costs)[1..1001].contains(&true))
            .count();
        // The statue is a third of the cost: the 2.7 shards that fills, and part of one more.
        assert!(holding_statue <= 4, "{holding_statue} shards");
    }

    /// The costs follow the triangles meshing spreads: about the planned budget in all, each
    /// surface at least its polygon's own triangles; an error-driven mesh's, its own, the fit's
    /// triangles per surface and its size in typical elements.
    #[test]
    fn costs_follow_the_planned_triangles() {
        let scene = penumbra_scenes::load_scene("cornell")
            .expect("built in")
            .scene;
        let options = RunOptions {
            mesh: crate::options::MeshMethod::Discontinuity,
            ..RunOptions::default()
        };
        let costs = surface_costs(&scene, &options);
        let planned = options.planned_elements(&scene).expect("resolves") as f64;
        let total: f64 = costs.iter().sum();
        assert!(
            total >= planned && total < 1.05 * planned,
            "{total} for {planned}"
        );
        for (s, cost) in scene.surfaces.iter().zip(&costs) {
            assert!(*cost >= (s.polygon.len() - 2) as f64);
        }
        let options = RunOptions::default();
        let error_driven = surface_costs(&scene, &options);
        let extra = extra_shares(&scene, &options);
        let area = scene.total_area();
        for ((s, cost), extra) in scene.surfaces.iter().zip(&error_driven).zip(&extra) {
            let size = (planned * s.area() / area).sqrt();
            assert_eq!(*cost, (s.polygon.len() - 2) as f64 + extra + size);
        }
    }

    /// The fit's extra triangles go to the faces large enough to refine, by area, and add up to
    /// its triangles per surface over all surfaces: a tessellated prism's hundreds of small
    /// faces get none, the floor under them most.
    #[test]
    fn extra_triangles_follow_the_refinable_area() {
        let scene = penumbra_scenes::load_scene("tessellated-8")
            .expect("built in")
            .scene;
        let options = RunOptions::default();
        let extra = extra_shares(&scene, &options);
        let per_surface = penumbra_meshing::FIT_TRIANGLES_PER_SURFACE as f64;
        let total: f64 = extra.iter().sum();
        let expected = per_surface * scene.surfaces.len() as f64;
        assert!(
            (total - expected).abs() < 1e-9 * expected,
            "{total} of {expected}"
        );
        let refined: Vec<(f64, f64)> = (scene.surfaces.iter().zip(&extra))
            .filter(|(_, e)| **e > 0.0)
            .map(|(s, e)| (s.area(), *e))
            .collect();
        assert!(
            refined.len() < scene.surfaces.len() / 10,
            "{} refined",
            refined.len()
        );
        let density = refined[0].1 / refined[0].0;
        for (area, e) in &refined {
            assert!((e / area - density).abs() < 1e-9 * density);
        }
    }
}
