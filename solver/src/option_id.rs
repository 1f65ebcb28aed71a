//! The options a caller sets, named once: in words for messages, as the `penumbra` command's
//! flag and as the Python package's argument. Errors carry an [`OptionId`], so each front end
//! tells a refused value in its own spelling without a table of its own.

/// An option of a run (its mesh, solver, render or limits), or of a study that runs many.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum OptionId {
    /// The element budget.
    MaxElements,
    /// The starting mesh of adaptive refinement.
    InitialElements,
    /// Parallel random streams of a path-traced reference.
    Streams,
    /// Triangles of a cube face in form-factor studies.
    CubeElements,
    /// The progressive solver's convergence threshold.
    Epsilon,
    /// The hierarchical solver's link tolerance.
    LinkTolerance,
    /// Photons of the photon map.
    Photons,
    /// The photon map's elements.
    PhotonElements,
    /// Photons gathered per estimate.
    GatherPhotons,
    /// Final-gather rays per vertex.
    FinalGather,
    /// Rays per visibility estimate.
    VisibilityRays,
    /// Mesh elements per patch.
    ElementsPerPatch,
    /// Samples per Monte Carlo form factor.
    FormFactorSamples,
    /// The hemicube's resolution.
    HemicubeResolution,
    /// How form factors are computed.
    FormFactors,
    /// The solver.
    Solver,
    /// Direct light only.
    DirectOnly,
    /// Adaptive refinement for the indirect light too.
    RefineIndirect,
    /// Adaptive refinement's tolerance.
    RefineTolerance,
    /// Error-driven meshes' tolerance.
    Tolerance,
    /// The smallest angle meshes aim for.
    MinAngle,
    /// Rounds of adaptive refinement.
    RefineRounds,
    /// Graded meshes' density in penumbrae.
    PenumbraDensity,
    /// The event search's tolerance.
    EventTolerance,
    /// Seconds a run may take.
    TimeBudget,
    /// Memory a run may use.
    MemoryLimit,
    /// The render's width and height.
    RenderSize,
    /// Sample points of an error measurement.
    Samples,
}

impl OptionId {
    /// Every option.
    pub const ALL: [OptionId; 28] = {
        use OptionId as O;
        [
            O::MaxElements,
            O::InitialElements,
            O::Streams,
            O::CubeElements,
            O::Epsilon,
            O::LinkTolerance,
            O::Photons,
            O::PhotonElements,
            O::GatherPhotons,
            O::FinalGather,
            O::VisibilityRays,
            O::ElementsPerPatch,
            O::FormFactorSamples,
            O::HemicubeResolution,
            O::FormFactors,
            O::Solver,
            O::DirectOnly,
            O::RefineIndirect,
            O::RefineTolerance,
            O::Tolerance,
            O::MinAngle,
            O::RefineRounds,
            O::PenumbraDensity,
            O::EventTolerance,
            O::TimeBudget,
            O::MemoryLimit,
            O::RenderSize,
            O::Samples,
        ]
    };

    /// The option in words, as messages of the library name it.
    pub fn words(self) -> &'static str {
        self.names().0
    }

    /// The flag of `penumbra run` (and of the commands that share it) that sets the option.
    pub fn flag(self) -> &'static str {
        self.names().1
    }

    /// The argument of the Python package's `penumbra.run` (and of the functions that share
    /// it) that sets the option.
    pub fn argument(self) -> &'static str {
        self.names().2
    }

    /// (words, flag, Python argument).
    fn names(self) -> (&'static str, &'static str, &'static str) {
        use OptionId as O;
        match self {
            O::MaxElements => ("max elements", "--max-elements", "max_elements"),
            O::InitialElements => ("initial elements", "--initial-elements", "initial_elements"),
            O::Streams => ("streams", "--streams", "streams"),
            O::CubeElements => ("cube elements", "--cube-elements", "cube_elements"),
            O::Epsilon => ("epsilon", "--epsilon", "epsilon"),
            O::LinkTolerance => ("link tolerance", "--link-tol", "link_tol"),
            O::Photons => ("photons", "--photons", "photons"),
            O::PhotonElements => ("photon elements", "--photon-elements", "photon_elements"),
            O::GatherPhotons => ("gather photons", "--gather-photons", "gather_photons"),
            O::FinalGather => ("final gather", "--final-gather", "final_gather"),
            O::VisibilityRays => ("visibility rays", "--rays", "rays"),
            O::ElementsPerPatch => (
                "elements per patch",
                "--elements-per-patch",
                "elements_per_patch",
            ),
            O::FormFactorSamples => ("form-factor samples", "--ff-samples", "ff_samples"),
            O::HemicubeResolution => (
                "hemicube resolution",
                "--hemicube-resolution",
                "hemicube_resolution",
            ),
            O::FormFactors => ("form factors", "--form-factors", "form_factors"),
            O::Solver => ("solver", "--solver", "solver"),
            O::DirectOnly => ("direct only", "--direct-only", "direct_only"),
            O::RefineIndirect => ("refine indirect", "--refine-indirect", "refine_indirect"),
            O::RefineTolerance => ("refine tolerance", "--refine-tol", "refine_tol"),
            O::Tolerance => ("tolerance", "--tol", "tol"),
            O::MinAngle => ("min angle", "--min-angle", "min_angle"),
            O::RefineRounds => ("refine rounds", "--refine-rounds", "refine_rounds"),
            O::PenumbraDensity => ("penumbra density", "--penumbra-density", "penumbra_density"),
            O::EventTolerance => ("event tolerance", "--event-tol", "event_tol"),
            O::TimeBudget => ("time budget", "--time-budget", "time_budget"),
            O::MemoryLimit => ("memory limit", "--memory-limit", "memory_limit"),
            O::RenderSize => ("render size", "--width/--height", "width/height"),
            O::Samples => ("samples", "--samples", "samples"),
        }
    }
}

impl std::fmt::Display for OptionId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.words())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each option has its own words, flag and argument, spelled as each front end spells.
    #[test]
    fn every_option_has_its_own_names() {
        let mut seen = std::collections::HashSet::new();
        for option in OptionId::ALL {
            let (words, flag, argument) = option.names();
            assert!(seen.insert(words), "{words} twice");
            assert!(seen.insert(flag), "{flag} twice");
            assert!(flag.split('/').all(|f| f.starts_with("--")), "{flag}");
            let python = argument
                .split('/')
                .all(|a| a.chars().all(|c| c.is_ascii_lowercase() || c == '_') && !a.is_empty());
            assert!(python, "{argument}");
            assert_eq!(option.to_string(), words);
        }
    }
}
