//! Every solver's options, each with its documented default, and their validation: the one
//! place a front end learns what a solve can be asked.

use std::time::Instant;

use crate::error::SolveError;
use crate::option_id::OptionId;
use crate::progress::Interrupt;
use crate::solution::StopReason;

/// Options of the progressive solver; every field is checked by [`SolverOptions::validate`].
#[derive(Clone, Debug, PartialEq)]
pub struct SolverOptions {
    /// Stop when the unshot power falls below this fraction of the emitted power.
    pub epsilon: f64,
    /// Stop after this many patch shots even if not converged.
    pub max_shots: usize,
    /// Rays per vertex–patch pair for visibility fractions.
    pub visibility_rays: usize,
    /// Elements grouped into one shooting patch.
    pub elements_per_patch: usize,
    /// One bounce only: B = E + ρ H_direct, exact.
    pub direct_only: bool,
    /// Seeds every random stream of the solve (visibility rays, Monte Carlo samples).
    pub seed: u64,
    /// Memory allowed for caching vertex–patch form factors, in bytes.
    pub cache_bytes: usize,
    /// Stop shooting at this moment, converged or not (an anytime solve).
    pub deadline: Option<Instant>,
    /// Stop shooting as soon as this is set (from a signal handler: Ctrl-C), keeping the
    /// solution so far.
    pub interrupt: Option<Interrupt>,
    /// How vertex-to-patch form factors are computed.
    pub form_factors: FormFactorMethod,
    /// The hierarchical solver's link tolerance: the light a link may carry wrongly, as a
    /// fraction of the light the surfaces reflect of the direct light.
    pub link_tol: f64,
    /// The photon-map solver's photons, estimates and final gather.
    pub photon_map: PhotonMapOptions,
}

/// The default of [`SolverOptions::epsilon`].
pub const DEFAULT_EPSILON: f64 = 1e-3;

/// Most visibility rays per vertex–patch pair: stratified rays then resolve a visibility
/// fraction to about 1/4096, beyond what the form factors' other errors allow; more only makes a
/// run look hung.
pub(crate) const MAX_VISIBILITY_RAYS: usize = 4096;

/// Most Monte Carlo samples per vertex–patch pair, for the same reason.
pub(crate) const MAX_FORM_FACTOR_SAMPLES: usize = 65_536;

impl Default for SolverOptions {
    fn default() -> Self {
        SolverOptions {
            epsilon: DEFAULT_EPSILON,
            max_shots: 100_000,
            visibility_rays: 16,
            elements_per_patch: 24,
            direct_only: false,
            seed: 0x5EED,
            cache_bytes: 1 << 30,
            deadline: None,
            interrupt: None,
            form_factors: FormFactorMethod::Analytic,
            link_tol: DEFAULT_LINK_TOL,
            photon_map: PhotonMapOptions::default(),
        }
    }
}

impl SolverOptions {
    /// Whether long work must stop now, and why: an interrupt, or the deadline passed.
    pub fn stop_now(&self) -> Option<StopReason> {
        if self.interrupt.as_ref().is_some_and(Interrupt::is_set) {
            return Some(StopReason::Interrupted);
        }
        if self.deadline.is_some_and(|d| Instant::now() >= d) {
            return Some(StopReason::TimeBudget);
        }
        None
    }

    /// Checks every field's range; the error names the option in words.
    pub fn validate(&self) -> Result<(), SolveError> {
        let bad = |option: OptionId, reason: &'static str| {
            Err(SolveError::InvalidOption { option, reason })
        };
        if !(self.epsilon > 0.0 && self.epsilon < 1.0) {
            return bad(OptionId::Epsilon, "must be in (0, 1)");
        }
        if !(self.link_tol > 0.0 && self.link_tol < 1.0) {
            return bad(OptionId::LinkTolerance, "must be in (0, 1)");
        }
        let photons = &self.photon_map;
        if !(1..=MAX_PHOTONS).contains(&photons.photons) {
            return bad(OptionId::Photons, "must be from 1 to 200,000,000");
        }
        if !(1..=MAX_GATHER_PHOTONS).contains(&photons.gather_photons) {
            return bad(OptionId::GatherPhotons, "must be from 1 to 100,000");
        }
        if photons.final_gather > MAX_FORM_FACTOR_SAMPLES {
            return bad(OptionId::FinalGather, "must be from 0 to 65,536 rays");
        }
        if !(1..=MAX_VISIBILITY_RAYS).contains(&self.visibility_rays) {
            return bad(OptionId::VisibilityRays, "must be from 1 to 4096");
        }
        if self.elements_per_patch == 0 {
            return bad(OptionId::ElementsPerPatch, "must be at least 1");
        }
        if let FormFactorMethod::MonteCarlo { samples } = self.form_factors
            && !(1..=MAX_FORM_FACTOR_SAMPLES).contains(&samples)
        {
            return bad(OptionId::FormFactorSamples, "must be from 1 to 65536");
        }
        if let FormFactorMethod::Hemicube { resolution } = self.form_factors {
            crate::hemicube::Hemicube::new(resolution)?;
        }
        Ok(())
    }
}

/// How point-to-patch form factors are computed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FormFactorMethod {
    /// Lambert's formula over the patch, exact, times a visibility fraction from rays.
    #[default]
    Analytic,
    /// Monte Carlo over the patch's area: cos cos / (π r²) at stratified points, each seen or
    /// not by a ray; unbiased, with an error that falls as one over the square root of samples.
    MonteCarlo {
        /// Sample points per point–patch pair.
        samples: usize,
    },
    /// A hemicube of `resolution` pixels across at each receiver: every patch's form factor
    /// from that point at once, occlusion by z-buffer (see [`crate::hemicube`]).
    Hemicube {
        /// Pixels across the top face.
        resolution: usize,
    },
}

impl FormFactorMethod {
    /// The method's name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            FormFactorMethod::Analytic => "analytic",
            FormFactorMethod::MonteCarlo { .. } => "monte-carlo",
            FormFactorMethod::Hemicube { .. } => "hemicube",
        }
    }

    /// Whether the method gives a receiver's form factors to all patches at once (a row), not
    /// one point–patch pair at a time.
    pub fn by_rows(self) -> bool {
        matches!(self, FormFactorMethod::Hemicube { .. })
    }
}

/// The light a link may carry wrongly by default, as a fraction of the light the surfaces reflect
/// of the direct light (the light the hierarchy carries in the first place: measured against the
/// emitted power instead, a dark room would get links too coarse for its little reflected light).
pub const DEFAULT_LINK_TOL: f64 = 2e-5;

/// Photons a solve emits unless told otherwise. With the defaults below the Cornell box is
/// within 1.5 % RMS of the path-traced reference at 10,000 triangles (the side-by-side table of
/// `docs/benchmarks.md`, `scripts/regen-docs --only methods`); its error is then the mesh's and the final
/// gather's, not the photons'.
pub const DEFAULT_PHOTONS: usize = 1_000_000;
/// Photons an irradiance estimate gathers unless told otherwise.
pub const DEFAULT_GATHER_PHOTONS: usize = 100;
/// Final-gather rays per vertex unless told otherwise.
pub const DEFAULT_FINAL_GATHER: usize = 1024;
/// Most photons a solve may emit: each stores about two landings of 72 bytes.
pub const MAX_PHOTONS: usize = 200_000_000;
/// Most photons an estimate may gather.
pub const MAX_GATHER_PHOTONS: usize = 100_000;

/// How the map is made and read.
#[derive(Clone, Debug, PartialEq)]
pub struct PhotonMapOptions {
    /// Photons emitted, shared among the emitters in proportion to their power.
    pub photons: usize,
    /// Photons each irradiance estimate gathers.
    pub gather_photons: usize,
    /// Rays per vertex of the final gather; 0 reads the map at the vertices themselves.
    pub final_gather: usize,
}

impl Default for PhotonMapOptions {
    fn default() -> Self {
        PhotonMapOptions {
            photons: DEFAULT_PHOTONS,
            gather_photons: DEFAULT_GATHER_PHOTONS,
            final_gather: DEFAULT_FINAL_GATHER,
        }
    }
}
