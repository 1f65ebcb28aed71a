//! Why a run failed.

use penumbra_meshing::MeshError;
use penumbra_solver::SolveError;
use penumbra_viz::VizError;

use crate::memory;
use crate::options::{InvalidOption, ShardError};

/// Why a run failed. [`RunError::is_usage`] tells the errors a user fixes by changing the
/// options (a bad option, a budget or memory too small) from failures of the run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RunError {
    /// An option out of its range, or options that do not go together
    /// ([`RunOptions::validate`](crate::options::RunOptions::validate)).
    #[error(transparent)]
    InvalidOption(#[from] InvalidOption),
    /// Meshing failed, or the scene's least mesh does not fit a capped element budget
    /// ([`MeshError::BudgetTooSmall`]).
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// The starting mesh of adaptive refinement does not fit its budget
    /// ([`RefineOptions::initial_elements`](crate::adaptive::RefineOptions::initial_elements)),
    /// though the scene fits the run's budget.
    #[error("the starting mesh of adaptive refinement: {0}")]
    InitialBudget(MeshError),
    /// Solving failed, or the run was interrupted ([`SolveError::Interrupted`]) before a
    /// solution existed.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// The render failed.
    #[error(transparent)]
    Render(#[from] VizError),
    /// The options cannot be split into shards ([`crate::options::Shard::check`]).
    #[error(transparent)]
    Shard(#[from] ShardError),
    /// The run's estimated memory exceeds what it may use; refused before the stage that would
    /// allocate it. The message says what would fit.
    #[error("{}", memory_message(.needed, .limit, .suggestion, .link_tol))]
    Memory {
        /// Bytes the run was estimated to need.
        needed: u64,
        /// Bytes the run may use.
        limit: u64,
        /// The largest element budget that would fit, if any.
        suggestion: Option<usize>,
        /// With the hierarchical solver: the least link tolerance that would fit, if any.
        link_tol: Option<f64>,
    },
}

fn memory_message(
    needed: &u64,
    limit: &u64,
    suggestion: &Option<usize>,
    link_tol: &Option<f64>,
) -> String {
    let head = format!(
        "this run would need about {} of memory, and {} is available",
        memory::human(*needed),
        memory::human(*limit)
    );
    match (suggestion, link_tol) {
        (None, None) => format!("{head}; even the coarsest mesh of this scene does not fit"),
        _ => {
            let budget = suggestion.map(|n| format!("an element budget of {n} or fewer"));
            let links = link_tol.map(|t| format!("a link tolerance of {t:.1e} or more"));
            let fits: Vec<String> = budget.into_iter().chain(links).collect();
            format!("{head}; {} would fit", fits.join(", or "))
        }
    }
}

impl RunError {
    /// Whether the error is the user's to fix (bad options) rather than a failure of the run.
    pub fn is_usage(&self) -> bool {
        matches!(
            self,
            RunError::Mesh(MeshError::BudgetTooSmall { .. })
                | RunError::InitialBudget(MeshError::BudgetTooSmall { .. })
                | RunError::InvalidOption(_)
                | RunError::Solve(SolveError::InvalidOption { .. })
                | RunError::Memory { .. }
                | RunError::Shard(_)
        )
    }
}
