//! Running a scene in this process, for tests that look at the solution itself.

use penumbra::{RunOptions, RunResult, run};
use penumbra_scenes::{LoadedScene, Scene};
use penumbra_solver::NoProgress;

/// `scene` run with `options` and a render of a few pixels (the tests read the solution, not
/// the picture).
pub fn run_scene(scene: Scene, options: RunOptions) -> RunResult {
    let options = RunOptions {
        render: penumbra_viz::RenderOptions {
            width: 16,
            height: 16,
            ..Default::default()
        },
        ..options
    };
    let loaded = LoadedScene {
        scene,
        source: "test".into(),
        warnings: Vec::new(),
    };
    run(loaded, &options, &NoProgress).expect("solves")
}
