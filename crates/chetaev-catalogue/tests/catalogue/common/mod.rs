//! Shared by the catalogue tests: solve an entry and compare it with its reference.

#![allow(dead_code)]

use chetaev::prelude::*;
use chetaev_catalogue::{compare, Comparison, Entry, Kind, Reference};

/// Solves `entry` to `t_end` by `Dop853` at `rtol = atol = tol`, requires success, and compares
/// every recorded step with the reference.
pub fn run<M, R, const N: usize, const K: usize>(
    entry: &Entry<M, R, N, K>,
    t_end: f64,
    tol: f64,
) -> (Solution, Comparison)
where
    M: Lagrangian<N> + Constraints<N, K>,
    R: Reference<N, K>,
{
    let sol = solve(
        &entry.problem,
        Dop853::default(),
        &Options::until(t_end).tolerances(tol, tol),
    )
    .expect("valid options");
    assert!(sol.is_success(), "{:?}", sol.status);
    let cmp = compare(&sol, &entry.reference).expect("the entry's own motion");
    (sol, cmp)
}

/// The tolerances every reference test runs at.
pub const TOLERANCES: [f64; 3] = [1e-8, 1e-10, 1e-12];

/// The scale of the energy balance `E − E0 − W_Φ + ∫∂L/∂t`: the largest `|E|` plus
/// `∫ |Φ|·|q̇| dt`, the size of the power integrated into `W_Φ` (a quadrature carried outside error
/// control, whose error is a fraction of `tol` times this).
pub fn balance_scale(sol: &Solution) -> f64 {
    let e_max = sol.energy.iter().fold(0.0f64, |acc, e| acc.max(e.abs()));
    e_max + chetaev_catalogue::absolute_work(sol)
}

/// Asserts `|E − E0 − W_Φ| ≤ 5 tol · balance_scale` at every recorded point (observed ≤ 1.6 tol ·
/// balance_scale for every catalogue system, from 1e-6 to 1e-12).
pub fn assert_energy_balance(sol: &Solution, tol: f64) {
    let scale = balance_scale(sol);
    let balance = chetaev_catalogue::max_energy_balance(sol);
    assert!(
        balance <= 5.0 * tol * scale,
        "tol {tol:e}: energy balance {balance:e}, scale {scale:e}"
    );
}

/// Every kind of quantity but times: positions, velocities, multipliers, invariants.
pub const KINDS: [Kind; 4] = [
    Kind::Position,
    Kind::Velocity,
    Kind::Multiplier,
    Kind::Invariant,
];

/// Asserts that the largest error of each of `kinds` in `cmp` is at most `bound`; `what` names the
/// run in the message, which also names the kind and its error.
pub fn assert_within(cmp: &Comparison, kinds: &[Kind], bound: f64, what: &str) {
    for &kind in kinds {
        let err = cmp.max_of(kind);
        assert!(err <= bound, "{what}: {kind:?} error {err:e}");
    }
}
