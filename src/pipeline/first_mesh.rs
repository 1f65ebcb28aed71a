//! The mesh of the plan's first budget, described by what it owns so that it can be made on
//! threads of its own and abandoned when the run is interrupted ([`super::abandon`]).

use std::sync::Arc;

use penumbra_meshing::discontinuity::Discontinuities;
use penumbra_meshing::{
    DiscontinuityMeshing, ElementBudget, Interrupt, MeshError, SceneMesh,
    mesh_scene_discontinuity_on, mesh_scene_uniform_until,
};
use penumbra_scenes::{Scene, Visibility};

/// A first mesh to make: by discontinuities when they are given, else uniform.
pub(super) struct FirstMesh {
    pub(super) scene: Arc<Scene>,
    pub(super) visibility: Arc<Visibility>,
    /// The discontinuities to mesh along; `None`: a uniform mesh.
    pub(super) found: Option<Discontinuities>,
    pub(super) budget: ElementBudget,
    /// Triangles this many times smaller in area where the light varies.
    pub(super) penumbra_density: f64,
    pub(super) min_angle_deg: f64,
    /// The surfaces meshed alone (a shard's), if only those are meshed.
    pub(super) on: Option<Vec<bool>>,
}

impl FirstMesh {
    /// The mesh, or [`MeshError::Interrupted`] once `interrupt` is set.
    pub(super) fn make(self, interrupt: Option<&Interrupt>) -> Result<SceneMesh, MeshError> {
        let scene = &self.scene;
        let Some(found) = self.found else {
            return mesh_scene_uniform_until(scene, self.budget, interrupt);
        };
        let meshing = DiscontinuityMeshing {
            penumbra_density: self.penumbra_density,
            min_angle_deg: self.min_angle_deg,
            on: self.on.as_deref(),
            interrupt,
        };
        mesh_scene_discontinuity_on(scene, &self.visibility, found, self.budget, &meshing)
    }
}
