//! The whole pipeline on small arbitrary scenes, shared by the `pipeline` fuzz target and the
//! seeded property test over the same generator: a scene may be rejected, but a run must never
//! panic, hang, or give a NaN, an infinity, a negative radiosity or an unbalanced energy account.

use penumbra_scenes::{LoadedScene, Scene};
use penumbra_solver::{NoProgress, SolverOptions};

use crate::{RunOptions, run};

/// Validates `scene` and, if it is valid, runs it with a small budget; `Err` says what broke.
pub fn run_small(scene: Scene) -> Result<(), String> {
    if !penumbra_scenes::validate(&scene).is_empty() {
        return Ok(()); // rejected, as the loader would
    }
    let options = RunOptions {
        max_elements: 400.into(),
        solver: SolverOptions {
            epsilon: 1e-2,
            max_shots: 300,
            ..SolverOptions::default()
        },
        render: penumbra_viz::RenderOptions {
            width: 8,
            height: 8,
            ..Default::default()
        },
        ..RunOptions::default()
    };
    let loaded = LoadedScene {
        scene,
        source: "fuzz".into(),
        warnings: Vec::new(),
    };
    let Ok(result) = run(loaded, &options, &NoProgress) else {
        return Ok(()); // a typed error is an answer
    };
    for (s, values) in result.solution.radiosity.iter().enumerate() {
        for b in values {
            if [b.r, b.g, b.b]
                .iter()
                .any(|c| !(c.is_finite() && *c >= 0.0))
            {
                return Err(format!("surface {s}: radiosity {b:?}"));
            }
        }
    }
    let stats = &result.solution.stats;
    let balance = stats.emitted - stats.absorbed - stats.unshot - stats.escaped;
    if !(balance.mean().abs() <= 1e-6 * stats.emitted.mean()) {
        return Err(format!("energy does not balance: {stats:?}"));
    }
    Ok(())
}
