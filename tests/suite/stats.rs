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
    // all, where the host has it: after NATIVE_AFTER interpreted right-hand sides of the problem
    // (many more than this short solve's), or at once when asked for (`native_operations`).
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

#[test]
fn many_short_solves_of_one_problem_reach_machine_code_after_native_after_right_hand_sides() {
    use chetaev::equations::compiled::NATIVE_AFTER;
    let native = problem()
        .compiled()
        .and_then(|c| c.native_operations())
        .is_some();
    let p = problem();
    let o = Options::until(1.0)
        .tolerances(1e-8, 1e-8)
        .record(Record::State);
    // Right-hand sides evaluated by the interpreted route (each calls f once), solve by solve.
    let (mut interpreted, mut per_solve, mut last_calls) = (0, 0, usize::MAX);
    for _ in 0..2 * NATIVE_AFTER / 80 {
        p.model().f_calls.set(0);
        let sol = solve(&p, Dopri5::default(), &o).expect("valid");
        assert!(sol.is_success());
        per_solve = sol.stats.rhs_evaluations;
        last_calls = p.model().f_calls.get();
        interpreted += last_calls;
    }
    if native {
        assert_eq!(last_calls, 0, "the last solves run as machine code");
        // Counted across solves (each shorter than NATIVE_AFTER), and switched at the first
        // solve that starts past it.
        assert!(
            (NATIVE_AFTER..NATIVE_AFTER + per_solve).contains(&interpreted),
            "{interpreted} interpreted right-hand sides, {per_solve} per solve"
        );
    } else {
        assert_eq!(last_calls, per_solve);
    }
}
