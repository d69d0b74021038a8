//! When a problem's right-hand side becomes machine code: the tiering policy.
//!
//! A problem's integrator's right-hand side starts on the interpreted route (the recorded tape
//! and a general block solve). Machine code is faster per evaluation but costs time to make, so it
//! is made when the evaluations still expected would save more than it costs, judged from the
//! program's size by a cost model:
//!
//! - **quick machine code** ([`Effort::Quick`](chetaev_native::Effort::Quick): no optimisation,
//!   a single-pass register allocator) when `expected × QUICK_GAIN(ops) > QUICK_COST(ops)`, where
//!   `expected` is the larger of a quarter of the right-hand sides the problem has evaluated so
//!   far (counted across its solves) and those the running solve still expects: its evaluations
//!   so far extrapolated over the time left to its end, at most four times as many again, and
//!   only where no terminal event may end it sooner. The problem then switches at once, in the
//!   middle of the solve;
//! - **full machine code** ([`Effort::Full`](chetaev_native::Effort::Full)) on another thread
//!   once the quick code's own evaluations so far (across solves) would repay its compile time,
//!   on the bet that as many again are still to come (a bolder bet than the quick one's: it is
//!   paid on another core); the solve takes it up at its next accepted step
//!   once it is ready. Evaluations so far, not an extrapolation: a solve's rate early on
//!   overestimates what is left where its steps grow, and this compile costs four times the quick
//!   one for a gain of a quarter.
//!
//! The implicit methods' Jacobian becomes quick machine code in the same way, once its right-hand
//! side runs as quick machine code, from its own counts: its program is about three times the
//! right-hand side's, and each of its evaluations by dual numbers takes a forward pass per group
//! of columns. Where the right-hand side was compiled with full effort at once
//! ([`MachineCode::AtOnce`](crate::MachineCode::AtOnce), `Compiled::native_operations`), so is
//! the Jacobian, at its first evaluation.
//!
//! The decisions depend on counts and times of the solve only, never on the clock, so a solve
//! repeats itself: the switch to quick machine code changes the rounding of the right-hand side
//! (the program's operations are the interpreted route's up to rounding), at the same evaluation
//! on every run. The switch to full machine code changes nothing: both efforts give the same bits,
//! so when the other thread finishes does not matter.
//!
//! The constants are one core of an AMD EPYC's (`examples/first_solve` of `chetaev-bench` prints
//! the parts): compiling costs a fixed part and a part per operation; an evaluation saves a part per
//! operation. Only their ratios matter, and a factor of two in any of them moves a decision by a
//! factor of two in the evaluations, which costs at most about as much as compiling.

/// Where nothing says how many evaluations are still to come (a solve that a terminal event may
/// end, or one that has not reported yet), the bet is that a quarter as many again as so far
/// are: a solve that ends right after the switch has then paid at most about a fifth more than
/// without it (each evaluation saves about four fifths of an interpreted one).
const CAUTION: f64 = 4.0;

/// The evaluations still expected: `remaining`, the running solve's estimate (0 where it has
/// none), or a quarter of the `so_far` (across solves), whichever is larger.
pub(crate) fn expected(so_far: usize, remaining: f64) -> f64 {
    (so_far as f64 / CAUTION).max(remaining)
}

/// Nanoseconds to compile a program quickly: fixed, and per operation.
const QUICK_COST: (f64, f64) = (150_000.0, 2_800.0);
/// Nanoseconds an evaluation as quick machine code saves against the interpreted route: fixed
/// (the block solve's loops and calls), and per operation of the program.
const QUICK_GAIN: (f64, f64) = (80.0, 3.5);
/// Nanoseconds to compile a program with full effort: fixed, and per operation.
const FULL_COST: (f64, f64) = (100_000.0, 11_000.0);
/// Nanoseconds an evaluation as full machine code saves against quick machine code, per
/// operation.
const FULL_GAIN: f64 = 0.3;

/// Whether quick machine code of some size could pay for itself over `expected` evaluations: the
/// evaluations it needs fall with its size towards the ratio of the parts per operation, so
/// below that none can, and the program need not be built to find its size.
pub(crate) fn quick_may_pay(expected: f64) -> bool {
    expected * QUICK_GAIN.1 > QUICK_COST.1
}

/// Whether quick machine code of `operations` pays for itself over `expected` evaluations.
pub(crate) fn quick_pays(operations: usize, expected: f64) -> bool {
    let ops = operations as f64;
    expected * (QUICK_GAIN.0 + QUICK_GAIN.1 * ops) > QUICK_COST.0 + QUICK_COST.1 * ops
}

/// Whether full machine code of `operations` pays for itself over `expected` evaluations as
/// quick machine code.
pub(crate) fn full_pays(operations: usize, expected: f64) -> bool {
    let ops = operations as f64;
    expected * FULL_GAIN * ops > FULL_COST.0 + FULL_COST.1 * ops
}

/// At most this many times the evaluations so far are expected to come: a solve's first steps are
/// its smallest (the first step is chosen small and grows), so its rate so far overestimates what
/// is left, most of all early on.
const AHEAD: f64 = 4.0;

/// The Jacobian's program is about this many times the right-hand side's (forward derivatives
/// along `q`, `q̇` and `t`): 3.3 for the paper's particle, 3.0 for the rolling disc.
const JACOBIAN_SIZE: f64 = 3.3;
/// A forward pass of the Jacobian by dual numbers costs about this many interpreted right-hand
/// sides.
const DUAL_PASS: f64 = 2.0;

/// Whether the Jacobian as quick machine code pays for itself over `expected` evaluations, for a
/// right-hand side of `operations` whose Jacobian takes `passes` forward passes by dual numbers.
pub(crate) fn jacobian_pays(operations: usize, passes: usize, expected: f64) -> bool {
    let ops = operations as f64;
    let gain = passes as f64 * DUAL_PASS * (QUICK_GAIN.0 + QUICK_GAIN.1 * ops);
    expected * gain > QUICK_COST.0 + QUICK_COST.1 * JACOBIAN_SIZE * ops
}

/// The evaluations a solve from `t0` to `t_end` still expects at `t`, having made `done`: the rate
/// so far over the time left, at most [`AHEAD`] times `done` (0 before it has moved, or past its
/// end).
pub(crate) fn expected_remaining(done: usize, t0: f64, t_end: f64, t: f64) -> f64 {
    let (gone, left) = (t - t0, t_end - t);
    let ratio = left / gone;
    if gone == 0.0 || ratio.is_nan() || ratio < 0.0 {
        return 0.0;
    }
    done as f64 * ratio.min(AHEAD)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quick_machine_code_pays_after_about_a_thousand_evaluations() {
        // The paper's particle (26 operations), the rolling disc (361), the snakeboard (149).
        for (ops, lower, upper) in [
            (26, 1000.0, 1500.0),
            (361, 700.0, 1000.0),
            (149, 800.0, 1100.0),
        ] {
            assert!(!quick_pays(ops, lower), "{ops} at {lower}");
            assert!(quick_pays(ops, upper), "{ops} at {upper}");
        }
    }

    #[test]
    fn below_the_least_break_even_no_size_pays() {
        for ops in [1, 26, 361, 2_500, 1 << 30] {
            assert!(!quick_pays(ops, 800.0), "{ops}");
        }
        assert!(!quick_may_pay(800.0));
        assert!(quick_may_pay(801.0));
    }

    #[test]
    fn the_jacobian_as_machine_code_pays_after_hundreds_of_evaluations() {
        // The paper's particle: 26 operations, 2 passes.
        assert!(!jacobian_pays(26, 2, 500.0));
        assert!(jacobian_pays(26, 2, 800.0));
    }

    #[test]
    fn without_an_end_a_quarter_of_the_evaluations_so_far_are_expected() {
        assert_eq!(expected(400, 0.0), 100.0);
        assert_eq!(expected(400, 250.0), 250.0);
    }

    #[test]
    fn full_machine_code_pays_after_tens_of_thousands_of_evaluations() {
        assert!(!full_pays(361, 30_000.0));
        assert!(full_pays(361, 50_000.0));
    }

    #[test]
    fn the_evaluations_left_are_the_rate_so_far_over_the_time_left() {
        assert_eq!(expected_remaining(100, 0.0, 10.0, 2.5), 300.0);
        assert_eq!(expected_remaining(100, 10.0, 0.0, 7.5), 300.0);
        assert_eq!(expected_remaining(100, 0.0, 10.0, 0.0), 0.0);
        assert_eq!(expected_remaining(100, 0.0, 10.0, 11.0), 0.0);
        assert_eq!(expected_remaining(100, 0.0, 10.0, f64::NAN), 0.0);
        // Never more than four times as many again.
        assert_eq!(expected_remaining(100, 0.0, 10.0, 1.0), 400.0);
        assert_eq!(expected_remaining(100, 0.0, f64::INFINITY, 1.0), 400.0);
    }
}
