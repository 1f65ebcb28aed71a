//! Closed furnaces with the default solver: enclosures whose every face emits E = 1 and reflects
//! ρ, so that B = E / (1 − ρ) exactly at every point, however the faces hide each other. Every
//! vertex is held to that at three budgets and at reflectances up to 0.999, where a form factor
//! sum off by δ is amplified ρ / (1 − ρ) = 999 times; and the energy account must show that
//! nothing escapes.

mod common;

use common::in_process;
use penumbra::energy::EnergyBalance;
use penumbra::{RunOptions, default_budget};
use penumbra_meshing::ElementBudget;
use penumbra_scenes::{Scene, builtin};
use penumbra_solver::{SolverMethod, StopReason};

/// The budgets of the table: about 600 and 3,000 triangles, and the default.
fn budgets() -> [ElementBudget; 3] {
    [
        600.into(),
        3000.into(),
        default_budget(SolverMethod::Hierarchical, false),
    ]
}

/// The largest relative difference of any vertex's radiosity from E / (1 − ρ), and the run's
/// energy account.
fn worst_vertex(scene: Scene, rho: f64, budget: ElementBudget) -> (f64, usize, EnergyBalance) {
    let options = RunOptions {
        max_elements: budget,
        ..RunOptions::default()
    };
    let result = in_process::run_scene(scene, options);
    let stats = &result.solution.stats;
    assert_eq!(stats.stop, StopReason::Converged, "rho {rho}");
    let exact = 1.0 / (1.0 - rho);
    let worst = result
        .solution
        .radiosity
        .iter()
        .flatten()
        .flat_map(|b| b.to_array())
        .map(|b| (b / exact - 1.0).abs())
        .fold(0.0, f64::max);
    let triangles = result
        .mesh
        .surfaces
        .iter()
        .map(|m| m.triangle_count())
        .sum();
    (worst, triangles, EnergyBalance::of(stats))
}

/// The unit cube, an L-shaped room (its inner corner hides part of the room from most points)
/// and a long thin box (most of it sees the far end at grazing angles), at ρ = 0.5 to 0.999:
/// every vertex within 0.5 % of the closed form (2 % at 0.999), no worse at larger budgets, and
/// an energy account that says the scene is closed and lets nothing escape.
#[test]
fn closed_furnaces_are_exact_at_every_vertex_budget_and_reflectance() {
    type Make = fn(f64, f64) -> Scene;
    let scenes: [(&str, Make); 3] = [
        ("cube", builtin::furnace),
        ("L-shaped room", builtin::l_room_furnace),
        ("long box", builtin::long_furnace),
    ];
    for (name, make) in scenes {
        for rho in [0.5, 0.9, 0.99, 0.999] {
            let bound = if rho > 0.995 { 2e-2 } else { 5e-3 };
            let mut previous = f64::INFINITY;
            for budget in budgets() {
                let (worst, triangles, account) = worst_vertex(make(1.0, rho), rho, budget);
                eprintln!(
                    "{name}, rho {rho}, {triangles} triangles: worst vertex {:.2e}, escaped {:.1e}",
                    worst, account.escaped_fraction
                );
                assert!(worst < bound, "{name}, rho {rho}: a vertex is {worst} off");
                // Not growing with the budget (beyond rounding, which grows with 1 / (1 − ρ)).
                assert!(
                    worst <= previous + 1e-9 / (1.0 - rho),
                    "{name}, rho {rho}: {worst} after {previous}"
                );
                previous = worst;
                assert_eq!(account.closed, Some(true), "{name}");
                assert!(account.escaped_fraction.abs() < 1e-3, "{account:?}");
                assert!(account.balanced, "{name}, rho {rho}: {account:?}");
            }
        }
    }
}
