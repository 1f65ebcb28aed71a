//! Shards: a scene's surfaces split into runs of consecutive surfaces of about equal cost, each
//! lit by a process of its own ([`crate::shard`] writes and joins them).

use penumbra_meshing::{ElementBudget, polygon_minimum};
use penumbra_scenes::Scene;
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
        self.surfaces(&surface_costs(scene, options))
    }

    /// This shard's part of the estimated cost of a run of `options` on `scene`: about one
    /// shard's worth, as the runs of surfaces are balanced by it.
    pub fn cost_share(self, scene: &Scene, options: &RunOptions) -> f64 {
        let costs = surface_costs(scene, options);
        let total: f64 = costs.iter().sum();
        let own: f64 = (costs.iter().zip(self.surfaces(&costs)))
            .filter(|(_, own)| *own)
            .map(|(c, _)| c)
            .sum();
        if total > 0.0 { own / total } else { 0.0 }
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
/// gives each surface its own triangles and a fitted budget's triangles per surface, spent where
/// the measured error is largest, which nothing tells before; a surface's search for
/// discontinuities and its lines' triangles grow with its size, here as the square root of its
/// area in typical elements (on the Crytek Sponza the search's time per surface grew about so,
/// summed over a shard). The same for every shard of a run, from the scene and the options
/// alone.
pub fn surface_costs(scene: &Scene, options: &RunOptions) -> Vec<f64> {
    // A cap below the polygons' needs is refused before any shard runs.
    let planned = options
        .planned_elements(scene)
        .unwrap_or_else(|_| polygon_minimum(scene)) as f64;
    let area = scene.total_area();
    let per_surface = match options.max_elements {
        ElementBudget::Fit { per_surface, .. } => per_surface as f64,
        ElementBudget::AtMost(_) => 0.0,
    };
    scene
        .surfaces
        .iter()
        .map(|s| {
            let own = s.polygon.len().saturating_sub(2).max(1) as f64;
            if options.error_driven() {
                own + per_surface + (planned * s.area() / area.max(f64::MIN_POSITIVE)).sqrt()
            } else if area > 0.0 {
                own.max(planned * s.area() / area)
            } else {
                own
            }
        })
        .collect()
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
        let error_driven = surface_costs(&scene, &RunOptions::default());
        let area = scene.total_area();
        for (s, cost) in scene.surfaces.iter().zip(&error_driven) {
            let per_surface = penumbra_meshing::FIT_TRIANGLES_PER_SURFACE as f64;
            let size = (planned * s.area() / area).sqrt();
            assert_eq!(*cost, (s.polygon.len() - 2) as f64 + per_surface + size);
        }
    }
}
