//! Statistics against calls counted independently, inside the user's model.

use std::cell::Cell;

use chetaev::model::Fixed;
use chetaev::prelude::*;

/// The paper's model, counting how often `chetaev` calls it.
struct Counting {
    l_calls: Cell<usize>,
    f_calls: Cell<usize>,
}

impl Lagrangian<2> for Counting {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        self.l_calls.set(self.l_calls.get() + 1);
        qd.dot(qd) * 0.5 - q[1] * 10.0
    }
}
impl Constraints<2, 1> for Counting {
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
        self.f_calls.set(self.f_calls.get() + 1);
        SVector::from([qd.dot(qd) - 100.0])
    }
}

fn problem() -> Problem<Fixed<Counting, 2, 1>> {
    problem_on(Route::Graph)
}

fn problem_on(route: Route) -> Problem<Fixed<Counting, 2, 1>> {
    let model = Counting {
        l_calls: Cell::new(0),
        f_calls: Cell::new(0),
    };
    let p = Problem::new(
        model,
        0.0,
        SVector::from([0.0, 5.0]),
        SVector::from([10.0, 0.0]),
    )
    .expect("valid")
    .with_route(route);
    // Compiling the equations (on the graph route) records L and f once and checks the result
    // against one dual-number evaluation; count from after that.
    let _ = p.compiled();
    p.model().l_calls.set(0);
    p.model().f_calls.set(0);
    p
}

#[test]
fn rhs_and_output_evaluations_match_model_calls() {
    // (route, machine code made before the solve, passes over L per right-hand side, per output
    // evaluation, passes over f per right-hand side, per output evaluation). The graph route's
    // right-hand side becomes machine code made from the recording, which calls the model not at
    // all, where the host has it: once the tiering finds that it pays (not within this short
    // solve), or at once when asked for (`native_operations`).
    let native = problem()
        .compiled()
        .and_then(|c| c.native_operations())
        .is_some();
    let f_native = if native { 0 } else { 1 };
    let routes = [
        (Route::Graph, true, 0, 1, f_native, 1),
        (Route::Graph, false, 0, 1, 1, 1),
        (Route::Dual, false, 3, 3, 2, 2),
    ];
    for (record, (route, made, l_rhs, l_output, f_rhs, f_output)) in
        [Record::State, Record::Dynamics, Record::Energy]
            .into_iter()
            .flat_map(|r| routes.map(|route| (r, route)))
    {
        let p = problem_on(route);
        if made {
            p.compiled().map(|c| c.native_operations());
        }
        let sol = solve(
            &p,
            Dopri5::default(),
            &Options::until(1.0).tolerances(1e-8, 1e-8).record(record),
        )
        .expect("valid");
        assert!(sol.is_success());
        let s = sol.stats;
        // Each evaluation of the equations by dual numbers: 3 passes over L, 2 over f. With the
        // structure found in the compiled equations (W and r constant, g = 0, c = 0), the
        // right-hand side needs no pass over L at all (not even with the energy balance, whose
        // rates ∂L/∂t and q̇·Q are proved zero), an output evaluation one (L, and p = ∂L/∂q̇ for
        // E), and one over f (f and J) where it is not machine code.
        assert_eq!(
            p.model().l_calls.get(),
            l_rhs * s.rhs_evaluations + l_output * s.output_evaluations,
            "{record:?} {route:?} machine code made first: {made}"
        );
        assert_eq!(
            p.model().f_calls.get(),
            f_rhs * s.rhs_evaluations + f_output * s.output_evaluations,
            "{record:?} {route:?} machine code made first: {made}"
        );
        // Dopri5 is FSAL: 6 new stages per step, plus 1 at the start and 2 for the initial step size.
        assert_eq!(
            s.rhs_evaluations,
            6 * (s.accepted_steps + s.rejected_steps) + 1 + 2
        );
        match record {
            Record::State => assert_eq!(s.output_evaluations, 0, "no diagnostics asked for"),
            _ => assert_eq!(s.output_evaluations, sol.len()),
        }
        assert_eq!(
            s.jacobian_evaluations, 0,
            "explicit methods never build a Jacobian"
        );
    }
}

#[test]
fn projection_work_is_counted() {
    let p = problem();
    // Machine code for the right-hand side from the first step, where the host has it.
    let native = p.compiled().and_then(|c| c.native_operations()).is_some();
    let sol = solve(
        &p,
        Rk4::new(0.05),
        &Options::until(1.0)
            .record(Record::State)
            .project(Projection::default()),
    )
    .expect("valid");
    let s = sol.stats;
    assert_eq!(s.projections, s.accepted_steps);
    assert!(s.projection_iterations >= 1);
    // Per projection: f evaluated at the start and after each iteration; W once per iteration;
    // and the stepper restarts (one right-hand side) after each projection that moved the
    // state. Per right-hand side one pass over f (J; c is zero), unless it is machine code.
    let per_rhs = if native { 0 } else { s.rhs_evaluations };
    assert!(p.model().f_calls.get() >= per_rhs + s.projections + s.projection_iterations);
}

#[test]
fn dop853_pays_for_its_dense_output_only_when_something_interpolates() {
    // A step costs 11 new stages and the derivative at the new point; the continuous extension
    // 3 more per accepted step, needed only for output times and events.
    let lean = solve(
        &problem(),
        Dop853::default(),
        &Options::until(1.0)
            .tolerances(1e-10, 1e-10)
            .record(Record::State),
    )
    .expect("valid");
    let s = lean.stats;
    assert_eq!(
        s.rhs_evaluations,
        11 * s.rejected_steps + 12 * s.accepted_steps + 1 + 2
    );
    let times = Options::until(1.0)
        .tolerances(1e-10, 1e-10)
        .record(Record::State)
        .output_times(vec![0.5]);
    let dense = solve(&problem(), Dop853::default(), &times).expect("valid");
    let d = dense.stats;
    assert_eq!(
        d.rhs_evaluations,
        11 * d.rejected_steps + 15 * d.accepted_steps + 1 + 2
    );
    assert_eq!(
        lean.last().map(|l| l.1),
        dense.last().map(|l| l.1),
        "the motion does not change"
    );
}

/// Whether this host makes machine code (where it does not, every solve is interpreted).
fn host_has_machine_code() -> bool {
    problem()
        .compiled()
        .and_then(|c| c.native_operations())
        .is_some()
}

/// Right-hand sides evaluated by the interpreted route (each calls `f` once) in one solve of `p`.
fn interpreted_in(p: &Problem<Fixed<Counting, 2, 1>>, o: &Options) -> (usize, Solution) {
    p.model().f_calls.set(0);
    let sol = solve(p, Dopri5::default(), o).expect("valid");
    assert!(sol.is_success(), "{:?}", sol.status);
    (p.model().f_calls.get(), sol)
}

#[test]
fn many_short_solves_of_one_problem_reach_machine_code_counted_across_them() {
    let native = host_has_machine_code();
    let p = problem();
    let o = Options::until(1.0)
        .tolerances(1e-8, 1e-8)
        .record(Record::State);
    let (mut interpreted, mut per_solve, mut last) = (0, 0, usize::MAX);
    for _ in 0..250 {
        let (calls, sol) = interpreted_in(&p, &o);
        per_solve = sol.stats.rhs_evaluations;
        last = calls;
        interpreted += calls;
    }
    assert!(per_solve < 256, "each solve is short: {per_solve}");
    if native {
        assert_eq!(last, 0, "the last solves run as machine code");
        // The first solves are interpreted (none of them alone pays for compiling), and the
        // count across them reaches the cost model's break-even, a few thousand at most.
        assert!(
            (10 * per_solve..10_000).contains(&interpreted),
            "{interpreted} interpreted right-hand sides, {per_solve} per solve"
        );
    } else {
        assert_eq!(last, per_solve);
    }
}

#[test]
fn a_long_first_solve_switches_to_machine_code_within_itself_and_repeats_itself_to_the_bit() {
    let native = host_has_machine_code();
    // The particle on a long horizon, falling on past the ground at its constant speed.
    let o = Options::until(1000.0)
        .tolerances(1e-12, 1e-12)
        .record(Record::State);
    let (a, first) = interpreted_in(&problem(), &o);
    let (b, second) = interpreted_in(&problem(), &o);
    let rhs = first.stats.rhs_evaluations;
    assert!(rhs > 4_000, "a long solve: {rhs}");
    if native {
        // Reported every 256 evaluations (the 256th already as machine code where it switches):
        // switched at one of the first reports, as soon as the evaluations still expected pay
        // for compiling.
        assert!((255..2_000).contains(&a), "{a} of {rhs} interpreted");
    } else {
        assert_eq!(a, rhs);
    }
    // Two fresh problems switch at the same evaluation, so they take the same steps to the bit.
    assert_eq!(a, b);
    assert_eq!(first.stats, second.stats);
    assert_eq!(first.t, second.t);
    let (last_a, last_b) = (
        first.last().expect("recorded"),
        second.last().expect("recorded"),
    );
    assert_eq!(last_a, last_b);
}

#[test]
fn machine_code_is_made_exactly_where_the_build_says_it_can() {
    if !MachineCode::available() {
        assert!(!host_has_machine_code(), "machine code without the feature");
    } else if cfg!(target_arch = "x86_64") {
        assert!(host_has_machine_code(), "the feature, yet no machine code");
    }
}

#[test]
fn machine_code_never_and_at_once_are_kept() {
    let native = host_has_machine_code();
    let o = Options::until(200.0)
        .tolerances(1e-12, 1e-12)
        .record(Record::State);
    let never = problem().with_machine_code(MachineCode::Never);
    let (calls, sol) = interpreted_in(&never, &o);
    assert_eq!(
        calls, sol.stats.rhs_evaluations,
        "never: every one interpreted"
    );
    let at_once = problem().with_machine_code(MachineCode::AtOnce);
    let (calls, sol) = interpreted_in(&at_once, &o);
    if native {
        assert_eq!(calls, 0, "at once: none interpreted");
        // And so every solve of it is the same to the bit.
        let (_, again) = interpreted_in(&at_once, &o);
        assert_eq!(sol.t, again.t);
    } else {
        assert_eq!(calls, sol.stats.rhs_evaluations);
    }
    // Set after the equations were compiled, the choice holds too.
    let late = problem();
    assert!(late.compiled().is_some());
    let late = late.with_machine_code(MachineCode::Never);
    let (calls, sol) = interpreted_in(&late, &o);
    assert_eq!(calls, sol.stats.rhs_evaluations);
}

#[test]
fn taking_up_the_full_machine_code_changes_no_step() {
    // A problem past its switch runs quick machine code, and after about 50,000 evaluations of
    // it (the 11th solve here) starts the full compile on another thread, taking it up at an
    // accepted step whenever it is ready. Quick and full code give the same bits, so every solve equals, to the bit, the
    // solve of a problem compiled with full effort before its first solve.
    let o = Options::until(1000.0)
        .tolerances(1e-12, 1e-12)
        .record(Record::State);
    let reference = problem().with_machine_code(MachineCode::AtOnce);
    let (_, want) = interpreted_in(&reference, &o);
    let p = problem();
    let _ = interpreted_in(&p, &o);
    for _ in 0..30 {
        let (calls, sol) = interpreted_in(&p, &o);
        if host_has_machine_code() {
            assert_eq!(calls, 0);
            assert_eq!(sol.t, want.t);
            assert_eq!(sol.last(), want.last());
        }
    }
}
