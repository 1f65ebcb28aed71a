//! What a run computed, in memory: the mesh, the solution, the render and the run's own
//! figures (stage times, memory, where it stopped). [`crate::pipeline`] makes it,
//! [`crate::outputs`] and [`crate::report`] write it.

use penumbra_meshing::SceneMesh;
use penumbra_scenes::{LoadedScene, Rgb, SurfaceId};
use penumbra_solver::{Solution, StopReason};
use penumbra_viz::Render;
use serde::{Deserialize, Serialize};

use crate::adaptive::RefineReport;
use crate::error_mesh::MeshErrorReport;
use crate::memory;
use crate::options::RunOptions;

/// The stages of a run, in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Stage {
    /// Checking the options, resolving the element budget, estimating memory.
    Plan,
    /// Building the visibility index.
    Visibility,
    /// Finding the discontinuities of the direct light.
    Discontinuities,
    /// Meshing, and refining the mesh where the direct light's error is largest.
    Mesh,
    /// The exact direct light at the mesh's vertices.
    Direct,
    /// Solving for the light reflected more than once.
    Solve,
    /// Adaptive refinement of the mesh against the solution.
    Refine,
    /// Rendering the image.
    Render,
}

/// What the outputs of a run that stopped early hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kept {
    /// The solution so far: the stage's mesh, with values it had time for.
    SolutionSoFar,
    /// The scene's least mesh with the direct light only (exact where it had time): no mesh with
    /// values existed yet when the run stopped.
    LeastMeshDirect,
}

/// Where and why a run stopped before it was done (`stopped` in `report.json`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stopped {
    /// The stage the run was in.
    pub stage: Stage,
    /// Why: `interrupted` or `time_budget`.
    pub reason: StopReason,
    /// What the outputs hold.
    pub kept: Kept,
}

/// Wall-clock seconds per stage (`times_seconds` in `report.json`).
#[derive(Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct StageTimes {
    /// Building the visibility index (the BVH).
    pub visibility: f64,
    /// The discontinuity search (0 for uniform meshes).
    pub discontinuities: f64,
    /// Meshing.
    pub mesh: f64,
    /// Adaptive refinement's own work, residuals and splits (its solving is counted in
    /// `direct`, `shooting` and `gather`); 0 without refinement.
    pub refine: f64,
    /// The exact direct light.
    pub direct: f64,
    /// Solving after the direct light: shooting, sweeps, the hierarchical solver's links.
    pub shooting: f64,
    /// Vertices gathering light: new vertices of refined meshes gathering what was shot
    /// before, the hierarchical solver's final gather.
    pub gather: f64,
    /// Rendering `render.png`.
    pub render: f64,
    /// The whole run, from its start to the end of the render (writing the files aside).
    pub total: f64,
    /// Joining shards (`penumbra merge` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub merge: Option<f64>,
}

impl std::ops::AddAssign<&StageTimes> for StageTimes {
    fn add_assign(&mut self, other: &StageTimes) {
        self.visibility += other.visibility;
        self.discontinuities += other.discontinuities;
        self.mesh += other.mesh;
        self.refine += other.refine;
        self.direct += other.direct;
        self.shooting += other.shooting;
        self.gather += other.gather;
        self.render += other.render;
        self.total += other.total;
    }
}

/// The most memory the process had held (its peak resident set, in bytes) by the end of each
/// stage; `None` where the system does not say ([`memory::peak_resident_bytes`]). The peak
/// is the whole process's, so it includes whatever the caller held before the run.
#[derive(Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct StagePeaks {
    /// After building the visibility index.
    pub visibility: Option<u64>,
    /// After the discontinuity search.
    pub discontinuities: Option<u64>,
    /// After meshing.
    pub mesh: Option<u64>,
    /// After solving (adaptive refinement included).
    pub solve: Option<u64>,
    /// After rendering.
    pub render: Option<u64>,
}

/// What the run was expected to need, what it could have, and what it used (`memory` in
/// `report.json`).
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct MemoryReport {
    /// Bytes the run could use: [`RunOptions::memory_limit`], or what the machine had
    /// available when the run started ([`memory::available_bytes`]); `None` where the system
    /// does not say.
    pub limit_bytes: Option<u64>,
    /// Bytes the run was estimated to need in all (`estimate`'s parts and a fixed base): from
    /// the mesh that was built or, with adaptive refinement, the most of that and of the mesh
    /// grown to the budget.
    pub estimate_bytes: u64,
    /// The estimate's parts, in bytes.
    pub estimate: memory::MemoryEstimate,
    /// Bytes allowed for the progressive solver's cache of vertex–patch form factors: what
    /// [`penumbra_solver::SolverOptions::cache_bytes`] asks for, within half of what the
    /// estimate leaves of `limit_bytes`.
    pub cache_bytes: usize,
    /// The process's peak resident set by the end of each stage, in bytes.
    pub peak_bytes: StagePeaks,
}

/// Everything a run computes: what [`crate::outputs`] writes, in memory.
#[derive(Debug)]
pub struct RunResult {
    /// The scene that was run, with its source and the loader's warnings.
    pub loaded: LoadedScene,
    /// The options the run was given (before [`crate::run`] resolved the budget and the
    /// deadline).
    pub options: RunOptions,
    /// The final mesh: per surface, its triangles and vertices, and the discontinuity segments
    /// built into it (the discontinuity search's figures, if one was made).
    pub mesh: SceneMesh,
    /// What adaptive refinement did, if it was asked for.
    pub refinement: Option<RefineReport>,
    /// What error-driven refinement of the mesh did, and the error it measured, if the mesh is
    /// error-driven ([`RunOptions::error_driven`]).
    pub mesh_error: Option<MeshErrorReport>,
    /// The element budget used, in triangles for the whole scene, resolved: the mesh's, or the
    /// cap of adaptive refinement. The mesh may have fewer.
    pub budget: usize,
    /// Radiosity (W/m² per channel) and irradiance at every vertex of `mesh`, per surface in
    /// the scene's order, with the solver's figures. It leaves out the display-only ambient
    /// term (`solution.ambient`), which only `render` adds.
    pub solution: Solution,
    /// The image from the scene's camera, and the exposure it was made with.
    pub render: Render,
    /// Wall-clock seconds per stage.
    pub times: StageTimes,
    /// The memory the run was expected to need, what it could have, and what it used.
    pub memory: MemoryReport,
    /// Where and why the run stopped before it was done (interrupted, or out of time), if it
    /// did.
    pub stopped: Option<Stopped>,
    /// The command line that asked for the run, if one did (set by the front end; recorded in
    /// `report.json`).
    pub invocation: Option<crate::options::Invocation>,
    /// For a shard (`RunOptions::shard`), which of the scene's surfaces are its own.
    pub shard_surfaces: Option<Vec<bool>>,
}

impl RunResult {
    /// Which of the scene's surfaces are `shard`'s: this run's own, when it was that shard.
    pub fn surfaces_of(&self, shard: crate::options::Shard) -> Vec<bool> {
        match &self.shard_surfaces {
            Some(on) if self.options.shard == Some(shard) => on.clone(),
            _ => shard.surfaces_of(&self.loaded.scene, &self.options),
        }
    }

    /// The light surface `s` reflects at its vertices, in two parts: straight from the lights,
    /// ρ·H_direct, and after more bounces, ρ·(H − H_direct).
    pub fn reflected_parts(&self, s: SurfaceId) -> (Vec<Rgb>, Vec<Rgb>) {
        let rho = self.loaded.scene.surfaces[s].reflectance;
        let (h, hd) = (
            &self.solution.irradiance[s],
            &self.solution.direct_irradiance[s],
        );
        let direct = hd.iter().map(|&d| rho.mul_rgb(d)).collect();
        let indirect = h
            .iter()
            .zip(hd)
            .map(|(&h, &d)| rho.mul_rgb(h - d))
            .collect();
        (direct, indirect)
    }
}
