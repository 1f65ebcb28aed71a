//! The energy account of a solution, and whether it closes.
//!
//! Every watt the emitters put out is absorbed by a surface, escapes the scene, or is still
//! waiting to be shot: emitted = absorbed + escaped + unshot, per channel. How far a solver can
//! be held to that depends on how it finds each term:
//!
//! - The hierarchical solver measures what escapes from the solution itself: each vertex sends
//!   out of the scene its radiosity times the share of its view no surface's front covers (one
//!   minus its form factors' total). Its account is then a real check: the gap is the error of
//!   the solution's transport.
//! - The patch solvers and photon mapping take what escapes as what was shot less what the
//!   vertices received, so their account closes by construction. What it can still show is a
//!   *negative* escape: the receivers took in more power than was shot at them (large triangles
//!   whose corner lies next to a light interpolate that corner's irradiance over their area).
//!
//! Either way the account is flagged when a term is negative, when more is absorbed than was
//! emitted, when a closed scene (every vertex inside a room) lets light escape, or when the gap
//! exceeds [`CLOSURE_TOLERANCE`].

use penumbra_scenes::Rgb;
use penumbra_solver::SolveStats;
use serde::Serialize;

/// How far, relative to the emitted power (channel mean), a term may be negative, the absorbed
/// power may exceed the emitted power, or a closed scene may let light escape before the account
/// is flagged: the default `--epsilon`, the unshot power progressive refinement stops at. In
/// closed scenes the escaped power stays far smaller (the hierarchical solver's furnace: none;
/// progressive refinement's: 3.5e-7, its vertex-sampled form factors' error).
pub const ENERGY_BALANCE_TOLERANCE: f64 = 1e-3;

/// How far, relative to the emitted power (channel mean), emitted − absorbed − escaped − unshot
/// may be from zero: the accuracy the defaults aim at. Where each term is measured on its own
/// (the hierarchical solver), the gap is the solution's own error of transport: on the Cornell
/// box about 2·10⁻³.
pub const CLOSURE_TOLERANCE: f64 = 1e-2;

/// Where the emitted power went, per channel and as fractions of the emitted power (channel
/// means), and whether that account closes (`energy` in `report.json`). Powers are radiosity
/// times area: W/m² times the scene's units squared, so watts per channel for a scene in metres.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct EnergyBalance {
    /// Power leaving the emitters by their own emission, per channel.
    pub emitted: Rgb,
    /// Power absorbed by all surfaces, ∫ (1 − ρ) H, per channel.
    pub absorbed: Rgb,
    /// Power that leaves the scene or meets the black back of a surface, per channel: measured
    /// from the solution by the hierarchical solver (each vertex's radiosity times the share of
    /// its view no front covers); shot power that no vertex received for the other solvers.
    pub escaped: Rgb,
    /// Reflected power not propagated yet, per channel (see
    /// [`SolveStats::unshot`](penumbra_solver::SolveStats::unshot)); it can be negative.
    pub unshot: Rgb,
    /// Absorbed over emitted power (channel means).
    pub absorbed_fraction: f64,
    /// Escaped over emitted power (channel means).
    pub escaped_fraction: f64,
    /// Unshot over emitted power (channel means), with its sign (unlike
    /// [`SolveStats::unshot_fraction`](penumbra_solver::SolveStats::unshot_fraction), a
    /// magnitude).
    pub unshot_fraction: f64,
    /// Emitted − absorbed − escaped − unshot in the channel furthest from zero, with its sign,
    /// over the emitted power (channel mean).
    pub closure_error: f64,
    /// Whether every vertex lies inside a room, so that nothing can escape; `None` where the
    /// solver did not find out.
    pub closed: Option<bool>,
    /// No term is negative, no more is absorbed than emitted, a closed scene lets nothing
    /// escape (each within [`ENERGY_BALANCE_TOLERANCE`]), and the account closes within
    /// [`CLOSURE_TOLERANCE`].
    pub balanced: bool,
}

impl EnergyBalance {
    /// The account of a solve.
    pub fn of(stats: &SolveStats) -> EnergyBalance {
        EnergyBalance::new(
            stats.emitted,
            stats.absorbed,
            stats.escaped,
            stats.unshot,
            stats.closed,
        )
    }

    /// The account of these powers, per channel, of a scene that is `closed` (if known).
    /// Fractions are over the emitted power's channel mean; an account of no light at all has
    /// fractions of 0, and is balanced.
    pub fn new(
        emitted: Rgb,
        absorbed: Rgb,
        escaped: Rgb,
        unshot: Rgb,
        closed: Option<bool>,
    ) -> EnergyBalance {
        let scale = emitted.mean().max(f64::MIN_POSITIVE);
        let fraction = |p: Rgb| p.mean() / scale;
        let gap = emitted - absorbed - escaped - unshot;
        let closure_error =
            gap.to_array()
                .into_iter()
                .map(|g| g / scale)
                .fold(
                    0.0,
                    |worst: f64, g| if g.abs() > worst.abs() { g } else { worst },
                );
        let mut account = EnergyBalance {
            emitted,
            absorbed,
            escaped,
            unshot,
            absorbed_fraction: fraction(absorbed),
            escaped_fraction: fraction(escaped),
            unshot_fraction: fraction(unshot),
            closure_error,
            closed,
            balanced: true,
        };
        account.balanced = account.problems().is_empty();
        account
    }

    /// What is wrong with the account, each in words with its figure.
    fn problems(&self) -> Vec<String> {
        let scale = self.emitted.mean().max(f64::MIN_POSITIVE);
        let worst_low = |p: Rgb| p.min_channel().min(0.0) / scale;
        let mut problems = Vec::new();
        for (name, term) in [("absorbed", self.absorbed), ("escaped", self.escaped)] {
            let low = worst_low(term);
            if low < -ENERGY_BALANCE_TOLERANCE {
                problems.push(format!(
                    "the {name} power is negative ({low:.3e} of the emitted power): the mesh \
                     received more light than was shot, as where large triangles have a corner \
                     next to a light; a larger element budget makes those triangles smaller"
                ));
            }
        }
        let excess = (self.absorbed - self.emitted).max_channel() / scale;
        if excess > ENERGY_BALANCE_TOLERANCE {
            problems.push(format!(
                "more power is absorbed than was emitted, by {excess:.3e} of it: the solution \
                 is too bright"
            ));
        }
        let leak = self.escaped.max_channel() / scale;
        if self.closed == Some(true) && leak > ENERGY_BALANCE_TOLERANCE {
            problems.push(format!(
                "the scene is closed, yet {leak:.3e} of the emitted power escapes"
            ));
        }
        if self.closure_error.abs() > CLOSURE_TOLERANCE {
            problems.push(format!(
                "absorbed + escaped + unshot differs from the emitted power by {:.3e} of it \
                 (more than {CLOSURE_TOLERANCE})",
                self.closure_error
            ));
        }
        problems
    }

    /// What is wrong with the account, if anything, in words.
    pub fn warning(&self) -> Option<String> {
        let problems = self.problems();
        (!problems.is_empty()).then(|| {
            format!(
                "the energy account does not balance: {}",
                problems.join("; ")
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const EMITTED: Rgb = Rgb {
        r: 10.0,
        g: 10.0,
        b: 10.0,
    };

    fn account(absorbed: f64, escaped: f64, closed: Option<bool>) -> EnergyBalance {
        EnergyBalance::new(
            EMITTED,
            Rgb::splat(absorbed),
            Rgb::splat(escaped),
            Rgb::ZERO,
            closed,
        )
    }

    #[test]
    fn an_account_that_closes_is_balanced() {
        // An open box: two thirds absorbed, a third escaped, a little unshot.
        let open = EnergyBalance::new(
            EMITTED,
            Rgb::splat(6.6),
            Rgb::splat(3.39),
            Rgb::splat(0.01),
            Some(false),
        );
        assert!(open.balanced && open.warning().is_none(), "{open:?}");
        assert!((open.escaped_fraction - 0.339).abs() < 1e-12);
        // Rounding, and a negative escape within the tolerance, are not flagged.
        let half = 0.5 * ENERGY_BALANCE_TOLERANCE * 10.0;
        assert!(account(10.0 + half, -half, None).balanced);
        // A gap within the closure's tolerance is the solution's error, not a fault.
        assert!(account(6.0, 3.96, None).balanced);
        // No light at all: nothing to flag, and no division by zero.
        let dark = EnergyBalance::new(Rgb::ZERO, Rgb::ZERO, Rgb::ZERO, Rgb::ZERO, Some(true));
        assert!(dark.balanced && dark.escaped_fraction == 0.0);
    }

    #[test]
    fn each_fault_is_flagged_with_its_figure() {
        // Sponza under a low lamp: 19 % escaped "negatively", so 119 % absorbed.
        let sponza = account(11.9, -1.9, None);
        assert!(!sponza.balanced && sponza.closure_error.abs() < 1e-12);
        let warning = sponza.warning().expect("flagged");
        assert!(
            warning.contains("escaped power is negative (-1.900e-1"),
            "{warning}"
        );
        assert!(
            warning.contains("absorbed than was emitted, by 1.900e-1"),
            "{warning}"
        );
        // A furnace solved too bright: more absorbed than emitted, though the gap is small.
        let bright = account(10.22, -0.21, Some(true));
        let warning = bright.warning().expect("flagged");
        assert!(warning.contains("by 2.200e-2"), "{warning}");
        // A closed scene that leaks is flagged; the same figures in an open one are not.
        let leaking = account(9.8, 0.2, Some(true));
        let warning = leaking.warning().expect("flagged");
        assert!(warning.contains("closed, yet 2.000e-2"), "{warning}");
        assert!(account(9.8, 0.2, Some(false)).balanced);
        assert!(account(9.8, 0.2, None).balanced);
        // A gap beyond the closure's tolerance, in one channel.
        let lost = EnergyBalance::new(
            EMITTED,
            Rgb::new(6.0, 5.0, 5.0),
            Rgb::new(3.0, 5.0, 5.0),
            Rgb::ZERO,
            None,
        );
        assert!(!lost.balanced && (lost.closure_error - 0.1).abs() < 1e-12);
        assert!(lost.warning().expect("flagged").contains("differs"));
    }
}
