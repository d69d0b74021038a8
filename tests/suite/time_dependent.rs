//! Models with explicit time dependence, in the Lagrangian and in the constraints, solved by every
//! method against closed forms. A method that evaluates a stage at the wrong time fails here.

use approx::assert_relative_eq;
use chetaev::prelude::*;
use chetaev_suite::norm;

/// L = ½ ẋ² + x sin t: ẍ = sin t, so x = t − sin t from x(0) = ẋ(0) = 0.
struct Driven;
impl Lagrangian<1> for Driven {
    fn lagrangian<R: Real>(&self, t: R, q: &SVector<R, 1>, qd: &SVector<R, 1>) -> R {
        qd[0] * qd[0] * 0.5 + q[0] * t.sin()
    }
}

/// A free particle with the linear, time-dependent constraint ẏ = ω t ẋ. Chetaev's equations give
/// ẋ = C / √(1 + ω²t²), so x = (C/ω) asinh(ω t), y = (C/ω)(√(1 + ω²t²) − 1) from the origin, ẋ(0) = C.
struct Tilting {
    omega: f64,
}
impl Lagrangian<2> for Tilting {
    fn lagrangian<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        qd.dot(qd) * 0.5
    }
}
impl Constraints<2, 1> for Tilting {
    fn constraints<R: Real>(&self, t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
        SVector::from([qd[1] - t * self.omega * qd[0]])
    }
}

/// A free particle whose speed is prescribed, |q̇|² = v(t)², v = v0 (1 + t²): nonlinear in q̇ and
/// time-dependent. Φ is parallel to q̇, so the path is straight: q = q0 + e v0 (t + t³/3).
struct Accelerated {
    v0: f64,
}
impl Lagrangian<2> for Accelerated {
    fn lagrangian<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        qd.dot(qd) * 0.5
    }
}
impl Constraints<2, 1> for Accelerated {
    fn constraints<R: Real>(&self, t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
        let v = (t * t + 1.0) * self.v0;
        SVector::from([qd.dot(qd) - v * v])
    }
}

fn check_all<Me: Method + Copy>(method: Me, tol: f64) {
    fn opts(t_end: f64, tol: f64) -> Options {
        Options::until(t_end).tolerances(tol, tol)
    }

    let p = Problem::unconstrained(Driven, 0.0, SVector::from([0.0]), SVector::from([0.0]))
        .expect("valid");
    let sol = solve(&p, method, &opts(3.0, tol)).expect("valid");
    assert!(sol.is_success(), "{:?}", sol.status);
    let (t, q, qd) = sol.last().expect("points");
    assert_eq!(t, 3.0);
    assert_relative_eq!(q[0], 3.0 - 3f64.sin(), max_relative = 100.0 * tol);
    assert_relative_eq!(qd[0], 1.0 - 3f64.cos(), max_relative = 100.0 * tol);

    let (omega, c) = (0.7, 1.3);
    let p = Problem::new(
        Tilting { omega },
        0.0,
        SVector::zeros(),
        SVector::from([c, 0.0]),
    )
    .expect("valid");
    let sol = solve(&p, method, &opts(2.0, tol)).expect("valid");
    assert!(sol.is_success(), "{:?}", sol.status);
    let (t, q, qd) = sol.last().expect("points");
    let s = (1.0 + (omega * t).powi(2)).sqrt();
    assert_relative_eq!(
        q[0],
        c / omega * (omega * t).asinh(),
        max_relative = 100.0 * tol
    );
    assert_relative_eq!(q[1], c / omega * (s - 1.0), max_relative = 100.0 * tol);
    assert_relative_eq!(qd[0], c / s, max_relative = 100.0 * tol);
    // A linear homogeneous constraint does no work: E stays ½C².
    assert!(sol.max_energy_balance().is_some_and(|b| b < 100.0 * tol));
    assert!(sol.work.iter().all(|w| w.abs() < 100.0 * tol));

    let (v0, a) = (2.0, 0.4f64);
    let e = SVector::from([a.cos(), a.sin()]);
    let p = Problem::new(Accelerated { v0 }, 0.0, SVector::zeros(), e * v0).expect("valid");
    let sol = solve(&p, method, &opts(1.5, tol)).expect("valid");
    assert!(sol.is_success(), "{:?}", sol.status);
    let (t, q, qd) = sol.last().expect("points");
    let s = v0 * (t + t.powi(3) / 3.0);
    assert_relative_eq!(q[0], e[0] * s, max_relative = 100.0 * tol);
    assert_relative_eq!(q[1], e[1] * s, max_relative = 100.0 * tol);
    assert_relative_eq!(norm(qd), v0 * (1.0 + t * t), max_relative = 100.0 * tol);
}

#[test]
fn dopri5_handles_explicit_time_dependence() {
    check_all(Dopri5::default(), 1e-10);
}

#[test]
fn dop853_handles_explicit_time_dependence() {
    check_all(Dop853::default(), 1e-11);
}

#[test]
fn rk4_handles_explicit_time_dependence() {
    // Fixed step: error ~ C h⁴; h = 1e-3 gives ~1e-12 here.
    check_all(Rk4::new(1e-3), 1e-10);
}

#[test]
fn tsit5_handles_explicit_time_dependence() {
    check_all(Tsit5::default(), 1e-10);
}

#[test]
fn rodas4_handles_explicit_time_dependence() {
    // A Rosenbrock method needs the time derivative of the reduced equations in every stage of a
    // non-autonomous problem; Rodas4 takes it exactly, by nested dual numbers.
    check_all(Rodas4, 1e-10);
}
