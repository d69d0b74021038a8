//! The conformance suite every method runs, without copying: a method added to
//! [`AnyMethod::all`] is checked here against the facts it declares in its [`MethodInfo`].
//!
//! - the step converges with the declared order (fixed steps; see [`within_order`]);
//! - under error control, the error is proportional to the tolerance (`tol^(order/control_order)`,
//!   exponent ±0.2);
//! - the dense output has the declared order (local error `O(h^(dense_order + 1))`);
//! - the driver's features work with it: events, backward integration, a right-hand side that
//!   depends explicitly on `t`, and statistics equal to calls counted independently.

use std::cell::Cell;

use super::driver::solve_ode;
use super::options::Options;
use super::testing::{fixed_steps, loose, Jac, Rhs, Sys};
use super::{AnyMethod, Method, MethodInfo, Stepper};
use crate::equations::derivatives::{ConstraintBlocks, LagrangianBlocks};
use crate::error::Error;
use crate::integrate::events::Event;
use crate::model::{DynModel, Model, Point, Real};
use crate::{solve, Problem};

/// The step size Rk4 runs with in the driver-level checks.
const RK4_STEP: f64 = 1e-3;

fn methods() -> Vec<AnyMethod> {
    AnyMethod::all(RK4_STEP)
}

/// `y1' = a(t)·y1`, `y2' = −a(t)·y2` with `a(t) = 1 + A cos ωt`, from `(1, 1)` at `t = 0`, with
/// the solution `(exp(s), exp(−s))`, `s = t + (A/ω) sin ωt`: an explicit time dependence, one
/// growing and one decaying component, and the exact
/// Jacobian and `∂F/∂t` for the implicit methods. Errors are relative, so the study stays in the
/// asymptotic range over many orders of magnitude; `A` and `ω` make the error constants large
/// enough that eighth order stays well above rounding.
fn test_ode() -> Sys<Rhs, Jac> {
    Sys::new(
        2,
        |t, y, dy| {
            let a = 1.0 + A * (OMEGA * t).cos();
            dy[0] = a * y[0];
            dy[1] = -a * y[1];
        },
        |t, y, jac, dfdt| {
            let a = 1.0 + A * (OMEGA * t).cos();
            let da = -A * OMEGA * (OMEGA * t).sin();
            jac.copy_from_slice(&[a, 0.0, 0.0, -a]);
            dfdt[0] = da * y[0];
            dfdt[1] = -da * y[1];
        },
    )
}

const A: f64 = 2.0;
const OMEGA: f64 = 4.0;

/// The solution of [`test_ode`].
fn exact(t: f64) -> [f64; 2] {
    let s = t + A / OMEGA * (OMEGA * t).sin();
    [s.exp(), (-s).exp()]
}

/// The largest relative error of the components.
fn max_error(y: &[f64], exact: [f64; 2]) -> f64 {
    ((y[0] - exact[0]) / exact[0])
        .abs()
        .max(((y[1] - exact[1]) / exact[1]).abs())
}

/// Least-squares slope of `log(err)` against `log(x)`.
fn slope(points: &[(f64, f64)]) -> f64 {
    let m = points.len() as f64;
    let (lx, ly): (Vec<f64>, Vec<f64>) = points.iter().map(|(x, e)| (x.ln(), e.ln())).unzip();
    let (mx, my) = (lx.iter().sum::<f64>() / m, ly.iter().sum::<f64>() / m);
    let num: f64 = lx.iter().zip(&ly).map(|(x, y)| (x - mx) * (y - my)).sum();
    let den: f64 = lx.iter().map(|x| (x - mx) * (x - mx)).sum();
    num / den
}

/// A scalar test equation `y' = F(t, y)` with its solution, for fixed-step studies.
struct Scalar {
    f: fn(f64, f64) -> f64,
    dfdy: fn(f64, f64) -> f64,
    dfdt: fn(f64, f64) -> f64,
    exact: fn(f64) -> f64,
    t_end: f64,
}

/// `y' = cos(t)·y` (`y = exp(sin t)`) over `[0, 2]` and `y' = t·y` (`y = exp(t²/2)`) over
/// `[0, 3]`: the problems on which Hairer, Nørsett and Wanner show orders, both non-autonomous.
const SCALARS: [Scalar; 2] = [
    Scalar {
        f: |t, y| t.cos() * y,
        dfdy: |t, _| t.cos(),
        dfdt: |t, y| -t.sin() * y,
        exact: |t| t.sin().exp(),
        t_end: 2.0,
    },
    Scalar {
        f: |t, y| t * y,
        dfdy: |t, _| t,
        dfdt: |_, y| y,
        exact: |t| (0.5 * t * t).exp(),
        t_end: 3.0,
    },
];

/// `n` fixed steps of `problem` from 0; the relative error at the end.
fn fixed_step_error(method: &AnyMethod, problem: &Scalar, n: usize) -> Result<f64, Error> {
    let mut sys = Sys::new(
        1,
        |t, y: &[f64], dy: &mut [f64]| dy[0] = (problem.f)(t, y[0]),
        |t, y: &[f64], jac: &mut [f64], dfdt: &mut [f64]| {
            jac[0] = (problem.dfdy)(t, y[0]);
            dfdt[0] = (problem.dfdt)(t, y[0]);
        },
    );
    let y = fixed_steps(method, &mut sys, (0.0, &[1.0]), problem.t_end, n)?;
    let exact = (problem.exact)(problem.t_end);
    Ok(((y[0] - exact) / exact).abs())
}

/// The points of a convergence study in its asymptotic range: relative errors between 1e-13
/// (above rounding: about 1e-16 per step over at most a thousand steps) and 1e-3, the last
/// (smallest) `count`. The last pair is the cleanest estimate of the order: higher-order terms
/// have faded and rounding has not yet set in (Dopri5, for example, shows 5.2 on coarser steps).
fn asymptotic(points: Vec<(f64, f64)>, count: usize) -> Vec<(f64, f64)> {
    let inside: Vec<(f64, f64)> = points
        .into_iter()
        .filter(|&(_, e)| e > 1e-13 && e < 1e-3)
        .collect();
    inside[inside.len().saturating_sub(count)..].to_vec()
}

/// Whether an observed order `p` confirms the declared order: at least `declared − 0.2`, and at
/// most `declared + 0.5`. The upper margin is wider because a method with a small principal error
/// coefficient (Tsit5 is built for one) is still in its pre-asymptotic range, approaching its order
/// from above, when rounding sets in; a method of one order more would show about `declared + 1`.
fn within_order(p: f64, declared: u32) -> bool {
    let d = declared as f64;
    p >= d - 0.2 && p <= d + 0.5
}

/// Reports the observed order `p` of `what` and checks it against the declared one.
fn check_order(info: &MethodInfo, what: &str, points: &[(f64, f64)], p: f64, declared: u32) {
    eprintln!(
        "{}: {what}: observed {p:.3}, declared {declared}, points {points:?}",
        info.name
    );
    assert!(
        within_order(p, declared),
        "{}: {what} of observed order {p}, declared {declared}",
        info.name
    );
}

/// The facts every method declares are complete and consistent with one another
/// ([`MethodInfo::validate`], which the driver runs too).
#[test]
fn every_method_declares_consistent_facts() -> Result<(), Error> {
    for method in methods() {
        method.info().validate()?;
    }
    Ok(())
}

#[test]
fn every_method_converges_with_its_declared_order_on_fixed_steps() -> Result<(), Error> {
    for method in methods() {
        let info = method.info();
        for problem in &SCALARS {
            let mut points = Vec::new();
            for n in [2, 4, 8, 16, 32, 64, 128, 256, 512, 1024, 2048] {
                points.push((1.0 / n as f64, fixed_step_error(&method, problem, n)?));
            }

            let points = asymptotic(points, 2);
            assert!(points.len() >= 2, "{}: too few points", info.name);
            let p = slope(&points);
            check_order(&info, "fixed steps", &points, p, info.order);
        }
    }
    Ok(())
}

#[test]
fn every_adaptive_method_has_an_error_proportional_to_its_tolerance() -> Result<(), Error> {
    // With `h ∝ err^(1/q)` per step, the global error of a method of order `p` goes like
    // `tol^(p/q)`: exponent 1 for every method here.
    for method in methods() {
        let info = method.info();
        if info.fixed_step.is_some() {
            continue;
        }
        let mut points = Vec::new();
        for e in 3..=13 {
            let tol = 10f64.powi(-e);
            let mut sys = test_ode();
            let o = Options::until(5.0).tolerances(tol, tol).output_final();
            let sol = solve_ode(&mut sys, method, 0.0, &[1.0, 1.0], &o)?;
            assert!(sol.error.is_none(), "{}: {:?}", info.name, sol.error);
            let y = sol.y.last().expect("the final state is recorded");
            points.push((tol, max_error(y, exact(5.0))));
        }
        let points = asymptotic(points, 8);
        let p = slope(&points);
        let expected = info.order as f64 / info.control_order as f64;
        eprintln!(
            "{}: error against tolerance: exponent {p:.3}, expected {expected}, points {points:?}",
            info.name
        );
        assert!(
            (p - expected).abs() <= 0.2,
            "{}: error ∝ tol^{p}, expected tol^{expected}",
            info.name
        );
    }
    Ok(())
}

#[test]
fn every_dense_output_has_its_declared_order() -> Result<(), Error> {
    let t0 = 0.3;
    for method in methods() {
        let info = method.info();
        let mut points = Vec::new();
        for h in [0.8, 0.4, 0.2, 0.1, 0.05, 0.025, 0.0125, 0.00625] {
            let mut sys = test_ode();
            let mut st = method.stepper(2);
            st.set_dense_output(true);
            let y = exact(t0);
            let mut y_new = [0.0; 2];
            st.reset(&mut sys, t0, &y)?;
            st.try_step(&mut sys, t0, h, &y, &mut y_new, &loose(2))?;
            st.accept(&mut sys, t0, h, &y, &y_new)?;
            let mut out = [0.0; 2];
            // The end points are reproduced.
            st.interpolate(0.0, &mut out);
            assert_eq!(out, y, "{}: θ = 0", info.name);
            st.interpolate(1.0, &mut out);
            assert!(max_error(&out, y_new) < 1e-14, "{}: θ = 1", info.name);
            // The interpolant against the exact solution inside the step.
            let mut e = 0.0f64;
            for theta in [0.3, 0.5, 0.7] {
                st.interpolate(theta, &mut out);
                e = e.max(max_error(&out, exact(t0 + theta * h)));
            }
            points.push((h, e));
        }
        let points = asymptotic(points, 2);
        let p = slope(&points) - 1.0;
        check_order(&info, "dense output", &points, p, info.dense_order);
    }
    Ok(())
}

/// `L = ½ q̇² − ½ q² + q·sin(2t)` (run-time sizes): `q̈ = −q + sin 2t`, from `q = 0`,
/// `q̇ = 1`, with the solution `q = (5/3) sin t − (1/3) sin 2t`. Counts the evaluations of its
/// derivative blocks independently of the library's statistics.
struct Forced {
    values: Cell<usize>,
    duals: Cell<usize>,
}

impl Forced {
    fn new() -> Self {
        Self {
            values: Cell::new(0),
            duals: Cell::new(0),
        }
    }
    fn exact(t: f64) -> (f64, f64) {
        (
            5.0 / 3.0 * t.sin() - (2.0 * t).sin() / 3.0,
            5.0 / 3.0 * t.cos() - 2.0 * (2.0 * t).cos() / 3.0,
        )
    }
}

impl DynModel for Forced {
    fn sizes(&self) -> (usize, usize) {
        (1, 0)
    }
    fn lagrangian<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> R {
        qd[0] * qd[0] * 0.5 - q[0] * q[0] * 0.5 + q[0] * (t * 2.0).sin()
    }
}

/// [`Forced`] seen through a counting [`Model`].
struct Counted<'a>(&'a Forced);

impl Model for Counted<'_> {
    fn sizes(&self) -> (usize, usize) {
        (1, 0)
    }
    fn lagrangian_blocks<T: Real>(&self, x: Point<T>, out: &mut LagrangianBlocks<T>) {
        if std::any::type_name::<T>() == "f64" {
            self.0.values.set(self.0.values.get() + 1);
        } else {
            self.0.duals.set(self.0.duals.get() + 1);
        }
        Model::lagrangian_blocks(self.0, x, out);
    }
    fn velocity_hessian<T: Real>(&self, x: Point<T>, w: &mut [T]) {
        Model::velocity_hessian(self.0, x, w);
    }
    fn constraint_blocks<T: Real>(&self, x: Point<T>, with_c: bool, out: &mut ConstraintBlocks<T>) {
        Model::constraint_blocks(self.0, x, with_c, out);
    }
    fn constraint_values(&self, x: Point<f64>, f: &mut [f64]) {
        Model::constraint_values(self.0, x, f);
    }
    fn force_blocks<T: Real>(&self, x: Point<T>, out: &mut [T]) -> bool {
        Model::force_blocks(self.0, x, out)
    }
}

fn tolerance_of(info: &MethodInfo) -> f64 {
    // Rk4 at h = 1e-3 has a global error of about 1e-13 on these problems.
    if info.fixed_step.is_some() {
        1e-9
    } else {
        1e-7
    }
}

#[test]
fn every_method_follows_an_explicit_time_dependence_forward_and_backward() -> Result<(), Error> {
    for method in methods() {
        let info = method.info();
        let (q0, qd0) = Forced::exact(0.0);
        let forced = Forced::new();
        let problem = Problem::from_model(Counted(&forced), 0.0, vec![q0], vec![qd0])?;
        let o = Options::until(3.0).tolerances(1e-11, 1e-11);
        let sol = solve(&problem, method, &o)?;
        assert!(sol.is_success(), "{}: {:?}", info.name, sol.status);
        let (t, q, qd) = sol.last().expect("recorded");
        assert_eq!(t, 3.0);
        let (qe, qde) = Forced::exact(3.0);
        let tol = tolerance_of(&info);
        assert!((q[0] - qe).abs() < tol, "{}: {}", info.name, q[0] - qe);
        assert!((qd[0] - qde).abs() < tol, "{}: {}", info.name, qd[0] - qde);

        // Backward from t = 3 to t = 0.5.
        let (q3, qd3) = Forced::exact(3.0);
        let problem = Problem::dynamic(Forced::new(), 3.0, vec![q3], vec![qd3])?;
        let sol = solve(
            &problem,
            method,
            &Options::until(0.5).tolerances(1e-11, 1e-11),
        )?;
        assert!(sol.is_success(), "{}: {:?}", info.name, sol.status);
        let (t, q, _) = sol.last().expect("recorded");
        assert_eq!(t, 0.5);
        assert!(
            (q[0] - Forced::exact(0.5).0).abs() < tol,
            "{} backward: {}",
            info.name,
            q[0] - Forced::exact(0.5).0
        );
        assert!(sol.t.windows(2).all(|w| w[1] < w[0]), "{}", info.name);
    }
    Ok(())
}

#[test]
fn every_method_locates_events() -> Result<(), Error> {
    for method in methods() {
        let info = method.info();
        let (q0, qd0) = Forced::exact(0.0);
        let problem = Problem::dynamic(Forced::new(), 0.0, vec![q0], vec![qd0])?;
        // q̇ = 0 at the turning points; q = 0.5 rising and falling; stop at q = −0.5.
        let o = Options::until(20.0)
            .tolerances(1e-11, 1e-11)
            .output_final()
            .event(Event::new("turning", |_t, _q, qd| qd[0]))
            .event(Event::new("half", |_t, q, _qd| q[0] - 0.5))
            .event(
                Event::new("stop", |_t, q, _qd| q[0] + 0.5)
                    .falling()
                    .terminal(),
            );
        let sol = solve(&problem, method, &o)?;
        assert_eq!(
            sol.status,
            crate::Status::Terminated { event: 2 },
            "{}",
            info.name
        );
        let tol = tolerance_of(&info);
        for hit in &sol.events {
            let (q, qd) = Forced::exact(hit.t);
            let g = [qd, q - 0.5, q + 0.5][hit.index];
            assert!(g.abs() < 10.0 * tol, "{}: {hit:?}: g = {g}", info.name);
        }
        let count = |i: usize| sol.events.iter().filter(|h| h.index == i).count();
        assert!(
            count(0) >= 1 && count(1) >= 2 && count(2) == 1,
            "{}",
            info.name
        );
        assert!(
            sol.events.windows(2).all(|w| w[0].t <= w[1].t),
            "{}",
            info.name
        );
    }
    Ok(())
}

#[test]
fn every_method_counts_its_work_where_the_model_is_called() -> Result<(), Error> {
    for method in methods() {
        let info = method.info();
        let forced = Forced::new();
        let (q0, qd0) = Forced::exact(0.0);
        let problem = Problem::from_model(Counted(&forced), 0.0, vec![q0], vec![qd0])?;
        // The problem's own validation evaluates once; start counting after it.
        forced.values.set(0);
        let o = Options::until(2.0)
            .tolerances(1e-8, 1e-8)
            .output_times(vec![0.5, 1.0, 1.5]);
        let sol = solve(&problem, method, &o)?;
        let s = sol.stats;
        assert_eq!(
            forced.values.get(),
            s.rhs_evaluations + s.output_evaluations,
            "{}: {s:?}",
            info.name
        );
        // One dual evaluation per direction (q, q̇, t) per Jacobian.
        assert_eq!(
            forced.duals.get(),
            3 * s.jacobian_evaluations,
            "{}",
            info.name
        );
        assert_eq!(
            s.jacobian_evaluations > 0,
            info.needs_jacobian,
            "{}",
            info.name
        );
        assert_eq!(s.output_evaluations, sol.len(), "{}", info.name);
        assert_eq!(sol.len(), 5, "{}", info.name);
    }
    Ok(())
}
