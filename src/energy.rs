//! The energy account of a solution, and whether it closes.
//!
//! Every watt the emitters put out is absorbed by a surface, escapes the scene, or is still
//! waiting to be shot: emitted = absorbed + escaped + unshot, per channel. The solvers keep the
//! account so that it closes by construction, to rounding. What it cannot show by itself is a
//! *negative* escape: the receivers took in more power than was shot at them. That happens
//! where form factors sampled at mesh vertices overstate what whole triangles receive: large
//! triangles whose corner lies next to a light (a sliver of wall meshed with three to five
//! triangles right beside a lamp) interpolate the irradiance of that corner over their whole
//! area. The solution then has light that no emitter gave, and the report says so.

use penumbra_scenes::Rgb;
use penumbra_solver::SolveStats;
use serde::Serialize;

/// How far, relative to the emitted power (channel mean), the account may be off before it is
/// flagged: a negative escaped power, or emitted − absorbed − escaped − unshot, in any channel.
/// It is the default `--epsilon`, the unshot power progressive refinement stops at: an error
/// that large would change a converged solution's figures. In closed scenes the escaped power,
/// which there is only the form factors' discretization error, stays far smaller (the furnace,
/// 3.5e-7).
pub const ENERGY_BALANCE_TOLERANCE: f64 = 1e-3;

/// Where the emitted power went, per channel and as fractions of the emitted power (channel
/// means), and whether that account closes (`energy` in `report.json`). Powers are radiosity
/// times area: W/m² times the scene's units squared, so watts per channel for a scene in metres.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EnergyBalance {
    /// Power leaving the emitters by their own emission, per channel.
    pub emitted: Rgb,
    /// Power absorbed by all surfaces, ∫ (1 − ρ) H, per channel.
    pub absorbed: Rgb,
    /// Shot power that no vertex received, per channel: light leaving an open scene, plus the
    /// discretization error of vertex-sampled form factors. Negative where the mesh received
    /// more light than was shot.
    pub escaped: Rgb,
    /// Reflected power not propagated yet, per channel (see
    /// [`SolveStats::unshot`](penumbra_solver::SolveStats::unshot)); it can be negative.
    pub unshot: Rgb,
    /// Absorbed over emitted power (channel means); above 1 when the mesh received more light
    /// than was shot.
    pub absorbed_fraction: f64,
    /// Escaped over emitted power (channel means); negative when the mesh received more light
    /// than was shot.
    pub escaped_fraction: f64,
    /// Unshot over emitted power (channel means), with its sign (unlike
    /// [`SolveStats::unshot_fraction`](penumbra_solver::SolveStats::unshot_fraction), a
    /// magnitude).
    pub unshot_fraction: f64,
    /// Emitted − absorbed − escaped − unshot in the channel furthest from zero, with its sign,
    /// over the emitted power (channel mean). Zero to rounding: the solvers keep the account
    /// so that it closes.
    pub closure_error: f64,
    /// The account closes within [`ENERGY_BALANCE_TOLERANCE`] and nothing escaped negatively.
    pub balanced: bool,
}

impl EnergyBalance {
    /// The account of a solve.
    pub fn of(stats: &SolveStats) -> EnergyBalance {
        EnergyBalance::new(stats.emitted, stats.absorbed, stats.escaped, stats.unshot)
    }

    /// The account of these powers, per channel. Fractions are over the emitted power's
    /// channel mean; an account of no light at all has fractions of 0, and is balanced.
    pub fn new(emitted: Rgb, absorbed: Rgb, escaped: Rgb, unshot: Rgb) -> EnergyBalance {
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
        let most_negative_escape = escaped.min_channel().min(0.0) / scale;
        let balanced = closure_error.abs() <= ENERGY_BALANCE_TOLERANCE
            && most_negative_escape >= -ENERGY_BALANCE_TOLERANCE;
        EnergyBalance {
            emitted,
            absorbed,
            escaped,
            unshot,
            absorbed_fraction: fraction(absorbed),
            escaped_fraction: fraction(escaped),
            unshot_fraction: fraction(unshot),
            closure_error,
            balanced,
        }
    }

    /// What is wrong with the account, if anything, in words.
    pub fn warning(&self) -> Option<String> {
        if self.balanced {
            return None;
        }
        let scale = self.emitted.mean().max(f64::MIN_POSITIVE);
        let most_negative_escape = self.escaped.min_channel().min(0.0) / scale;
        let mut problems = Vec::new();
        if most_negative_escape < -ENERGY_BALANCE_TOLERANCE {
            problems.push(format!(
                "the escaped power is negative ({:.3} of the emitted power): the mesh received \
                 more light than was shot, as where large triangles have a corner next to a \
                 light; a larger element budget makes those triangles smaller",
                self.escaped_fraction.min(most_negative_escape)
            ));
        }
        if self.closure_error.abs() > ENERGY_BALANCE_TOLERANCE {
            problems.push(format!(
                "absorbed + escaped + unshot differs from the emitted power by {:.3e} of it",
                self.closure_error
            ));
        }
        Some(format!(
            "the energy balance does not close within {ENERGY_BALANCE_TOLERANCE} of the emitted \
             power: {}",
            problems.join("; ")
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_account_that_closes_is_balanced_and_one_that_does_not_is_flagged() {
        let emitted = Rgb::new(10.0, 10.0, 10.0);
        // An open box: two thirds absorbed, a third escaped, a little unshot.
        let open = EnergyBalance::new(emitted, Rgb::splat(6.6), Rgb::splat(3.39), Rgb::splat(0.01));
        assert!(open.balanced && open.warning().is_none(), "{open:?}");
        assert!((open.escaped_fraction - 0.339).abs() < 1e-12);
        // Rounding, and a negative escape within the tolerance, are not flagged.
        let tight = EnergyBalance::new(
            emitted,
            Rgb::splat(10.0 + 0.5 * ENERGY_BALANCE_TOLERANCE * 10.0),
            Rgb::splat(-0.5 * ENERGY_BALANCE_TOLERANCE * 10.0),
            Rgb::ZERO,
        );
        assert!(tight.balanced, "{tight:?}");
        // Sponza under a low lamp: 19 % escaped "negatively", so 119 % absorbed.
        let sponza = EnergyBalance::new(emitted, Rgb::splat(11.9), Rgb::splat(-1.9), Rgb::ZERO);
        assert!(!sponza.balanced);
        assert!(sponza.closure_error.abs() < 1e-12);
        let warning = sponza.warning().expect("flagged");
        assert!(
            warning.contains("negative") && warning.contains("-0.190"),
            "{warning}"
        );
        // One channel is enough.
        let red = EnergyBalance::new(
            emitted,
            Rgb::new(6.0, 5.0, 5.0),
            Rgb::new(4.0, 5.0, 5.0),
            Rgb::ZERO,
        );
        assert!(red.balanced);
        let lost = EnergyBalance::new(
            emitted,
            Rgb::new(6.0, 5.0, 5.0),
            Rgb::new(3.0, 5.0, 5.0),
            Rgb::ZERO,
        );
        assert!(!lost.balanced && (lost.closure_error - 0.1).abs() < 1e-12);
        assert!(lost.warning().expect("flagged").contains("differs"));
        // No light at all: nothing to flag, and no division by zero.
        let dark = EnergyBalance::new(Rgb::ZERO, Rgb::ZERO, Rgb::ZERO, Rgb::ZERO);
        assert!(dark.balanced && dark.escaped_fraction == 0.0);
    }
}
