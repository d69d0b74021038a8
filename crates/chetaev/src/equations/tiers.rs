//! When a problem's right-hand side becomes machine code: the tiering policy.
//!
//! A problem's integrator's right-hand side starts on the interpreted route (the recorded tape
//! and a general block solve). Machine code is faster per evaluation but costs time to make, so it
//! is made when the evaluations still expected would save more than it costs, judged from the
//! program's size by a cost model:
//!
//! - **quick machine code** ([`Effort::Quick`](chetaev_native::Effort::Quick): no optimisation,
//!   a single-pass register allocator) when `expected × QUICK_GAIN(ops) > QUICK_COST(ops)`, where
//!   `expected` is the larger of the right-hand sides the problem has evaluated so far (counted
//!   across its solves) and those the running solve still expects: its evaluations so far
//!   extrapolated over the time left to its end. The problem then switches at once, in the
//!   middle of the solve;
//! - **full machine code** ([`Effort::Full`](chetaev_native::Effort::Full)) on another thread
//!   once the quick code's own evaluations so far (across solves) would repay its compile time,
//!   on the bet that as many are still to come; the solve takes it up at its next accepted step
//!   once it is ready. Evaluations so far, not an extrapolation: a solve's rate early on
//!   overestimates what is left where its steps grow, and this compile costs four times the quick
//!   one for a gain of a quarter.
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

/// The evaluations a solve from `t0` to `t_end` still expects at `t`, having made `done`: the rate
/// so far over the time left (0 before it has moved, or past its end).
pub(crate) fn expected_remaining(done: usize, t0: f64, t_end: f64, t: f64) -> f64 {
    let (gone, left) = (t - t0, t_end - t);
    let ratio = left / gone;
    if gone == 0.0 || ratio.is_nan() || ratio < 0.0 {
        return 0.0;
    }
    done as f64 * ratio
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
        assert_eq!(
            expected_remaining(100, 0.0, f64::INFINITY, 1.0),
            f64::INFINITY
        );
        assert_eq!(expected_remaining(100, 0.0, 10.0, f64::NAN), 0.0);
    }
}
