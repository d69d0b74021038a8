//! Generalised forces not derivable from `L` and Rayleigh dissipation, against closed forms.
//!
//! 1. The paper's particle with linear drag `Q = −c q̇` (Rayleigh `D = ½ c |q̇|²`) under the
//!    constant-speed constraint. With `J = 2 q̇` the Chetaev equations `m q̈ = (0, −m g) − c q̇ + 2μ q̇`
//!    and `q̇·q̈ = 0` give `2μ v0² = c v0² + m g ẏ`, so `μ = μ_paper + c/2` and
//!    `q̈ = (0, −g) + (g ẏ / v0²) q̇`: the constraint force absorbs the drag, which is along the
//!    velocity, and the motion is the paper's (42.29) unchanged. The work of the drag is
//!    `W_Q = −c v0² t`, and the energy balance `ΔE = W_Φ + W_Q` gives `W_Φ = m g (y − h0) + c v0² t`.
//! 2. The damped oscillator `L = ½ ẋ² − ½ ω² x²`, `D = ½ c ẋ²`: `ẍ + c ẋ + ω² x = 0`, underdamped
//!    solution `x = e^(−ct/2) (x0 cos ω_d t + ((v0 + c x0/2)/ω_d) sin ω_d t)`, `ω_d² = ω² − c²/4`,
//!    written with the force directly, with Rayleigh's function, and on run-time sizes.

use chetaev::prelude::*;
use uniform_projectile::closed_form::{uniform, Params};

struct DraggedUniform {
    p: Params,
    c: f64,
}

impl Lagrangian<2> for DraggedUniform {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        qd.dot(qd) * (0.5 * self.p.m) - q[1] * (self.p.m * self.p.g)
    }
    fn dissipation<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> Option<R> {
        Some(qd.dot(qd) * (0.5 * self.c))
    }
}

impl Constraints<2, 1> for DraggedUniform {
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
        SVector::from([qd.dot(qd) - self.p.v0 * self.p.v0])
    }
}

#[test]
fn drag_under_the_constant_speed_constraint_shifts_mu_by_c_over_2_and_leaves_the_motion(
) -> Result<(), Error> {
    let p = Params::PAPER;
    let c = 0.7;
    let model = DraggedUniform { p, c };
    let problem = Problem::new(
        model,
        0.0,
        SVector::from([0.0, p.h0]),
        SVector::from([p.v0, 0.0]),
    )?;
    let impact = Event::new("impact", |_t, q, _qd| q[1]).falling().terminal();
    let tol = 1e-12;
    let sol = solve(
        &problem,
        Dop853::default(),
        &Options::until(10.0).tolerances(tol, tol).event(impact),
    )?
    .ok()?;
    let balance = sol.energy_balance();
    for (i, &t) in sol.t.iter().enumerate() {
        let (x, v) = (uniform::position(&p, t), uniform::velocity(&p, t));
        assert!((sol.q[i][0] - x[0]).abs() < 1e-10 * p.h0, "x at t = {t}");
        assert!((sol.q[i][1] - x[1]).abs() < 1e-10 * p.h0, "y at t = {t}");
        assert!((sol.qd[i][1] - v[1]).abs() < 1e-10 * p.v0, "ẏ at t = {t}");
        let mu = uniform::multiplier(&p, t) + c / 2.0;
        assert!(
            (sol.mu[i][0] - mu).abs() < 1e-10,
            "μ at t = {t}: {}",
            sol.mu[i][0]
        );
        let w_q = -c * p.v0 * p.v0 * t;
        assert!((sol.work_forces[i] - w_q).abs() < 1e-9, "W_Q at t = {t}");
        let w_phi = p.m * p.g * (sol.q[i][1] - p.h0) + c * p.v0 * p.v0 * t;
        assert!((sol.work[i] - w_phi).abs() < 1e-9, "W_Φ at t = {t}");
        assert!(balance[i].abs() < 1e-9, "energy balance at t = {t}");
    }
    // The impact is the paper's (42.38).
    let t_impact = p.v0 / p.g * (p.z()).exp().acosh();
    assert!((sol.events[0].t - t_impact).abs() < 1e-11);
    Ok(())
}

/// The damped oscillator's closed form: `(x, ẋ)` at `t`.
fn damped(omega: f64, c: f64, x0: f64, v0: f64, t: f64) -> (f64, f64) {
    let wd = (omega * omega - c * c / 4.0).sqrt();
    let (a, b) = (x0, (v0 + c * x0 / 2.0) / wd);
    let e = (-c * t / 2.0).exp();
    let (s, co) = (wd * t).sin_cos();
    let x = e * (a * co + b * s);
    let xd = -c / 2.0 * x + e * (-a * wd * s + b * wd * co);
    (x, xd)
}

struct Oscillator {
    omega: f64,
    c: f64,
    rayleigh: bool,
}

impl Lagrangian<1> for Oscillator {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 1>, qd: &SVector<R, 1>) -> R {
        (qd[0] * qd[0] - q[0] * q[0] * (self.omega * self.omega)) * 0.5
    }
    fn forces<R: Real>(
        &self,
        _t: R,
        _q: &SVector<R, 1>,
        qd: &SVector<R, 1>,
    ) -> Option<SVector<R, 1>> {
        (!self.rayleigh).then(|| SVector::from([qd[0] * -self.c]))
    }
    fn dissipation<R: Real>(&self, _t: R, _q: &SVector<R, 1>, qd: &SVector<R, 1>) -> Option<R> {
        self.rayleigh.then(|| qd[0] * qd[0] * (0.5 * self.c))
    }
}

struct DynOscillator {
    omega: f64,
    c: f64,
}

impl DynModel for DynOscillator {
    fn sizes(&self) -> (usize, usize) {
        (1, 0)
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        (qd[0] * qd[0] - q[0] * q[0] * (self.omega * self.omega)) * 0.5
    }
    fn dissipation<R: Real>(&self, _t: R, _q: &[R], qd: &[R]) -> Option<R> {
        Some(qd[0] * qd[0] * (0.5 * self.c))
    }
}

fn check_damped(sol: &Solution, omega: f64, c: f64, what: &str) {
    assert!(sol.is_success(), "{what}: {:?}", sol.status);
    let balance = sol.energy_balance();
    for (i, &t) in sol.t.iter().enumerate() {
        let (x, xd) = damped(omega, c, 1.0, 0.0, t);
        assert!((sol.q[i][0] - x).abs() < 1e-9, "{what}: x at t = {t}");
        assert!((sol.qd[i][0] - xd).abs() < 1e-9, "{what}: ẋ at t = {t}");
        // The force is −c ẋ, its work the energy lost: E(t) − E(0) = W_Q.
        assert!((sol.work_forces[i] - (sol.energy[i] - sol.energy[0])).abs() < 1e-9);
        assert!(balance[i].abs() < 1e-9, "{what}: balance at t = {t}");
    }
}

#[test]
fn a_damped_oscillator_follows_its_closed_form_with_the_force_or_rayleighs_function(
) -> Result<(), Error> {
    let (omega, c) = (2.0, 0.3);
    let o = Options::until(10.0)
        .tolerances(1e-12, 1e-12)
        .output_grid(0.0, 41);
    for rayleigh in [false, true] {
        let model = Oscillator { omega, c, rayleigh };
        let problem =
            Problem::unconstrained(model, 0.0, SVector::from([1.0]), SVector::from([0.0]))?;
        for method in [
            AnyMethod::Dop853(Dop853::default()),
            AnyMethod::Rodas4(Rodas4),
        ] {
            let o = if method.info().needs_jacobian {
                o.clone().tolerances(1e-11, 1e-11)
            } else {
                o.clone()
            };
            let sol = solve(&problem, method, &o)?;
            check_damped(
                &sol,
                omega,
                c,
                &format!("{} rayleigh = {rayleigh}", method.name()),
            );
        }
    }
    let problem = Problem::dynamic(DynOscillator { omega, c }, 0.0, vec![1.0], vec![0.0])?;
    let sol = solve(&problem, Dop853::default(), &o)?;
    check_damped(&sol, omega, c, "run-time sizes");
    // The equations at a state carry the force.
    let eq = problem.equations_at(0.0, &[0.5], &[2.0])?;
    assert!((eq.forces[0] + c * 2.0).abs() < 1e-15);
    assert!((eq.qdd[0] - (-c * 2.0 - omega * omega * 0.5)).abs() < 1e-14);
    Ok(())
}

#[test]
fn a_model_without_forces_records_zero_work_of_forces() -> Result<(), Error> {
    let problem = uniform_projectile::model::uniform_problem(&Params::PAPER)?;
    let sol = solve(&problem, Dopri5::default(), &Options::until(1.0))?;
    assert!(sol.work_forces.iter().all(|&w| w == 0.0));
    assert_eq!(sol.work_forces.len(), sol.len());
    Ok(())
}

/// A free particle pushed by a unit force from `t = 1/2` on only, stated as `None` before: with
/// `q̇(0) = 1`, `q̇ = 1 + (t − ½)` after it, and the force's work to `t = 1` is
/// `∫_{½}^{1} q̇ dt = ½ + ⅛`. The switch is a comparison of the recorded time (`t > ½`), which the
/// compiled equations keep as a guard, or, `by_value`, of the value taken out with `re()`, which
/// they cannot follow.
struct PushedLate {
    by_value: bool,
}

impl Lagrangian<1> for PushedLate {
    fn lagrangian<R: Real>(&self, _t: R, _q: &SVector<R, 1>, qd: &SVector<R, 1>) -> R {
        qd[0] * qd[0] * 0.5
    }
    fn forces<R: Real>(
        &self,
        t: R,
        _q: &SVector<R, 1>,
        _qd: &SVector<R, 1>,
    ) -> Option<SVector<R, 1>> {
        let on = if self.by_value { t.re() > 0.5 } else { t > 0.5 };
        on.then(|| SVector::from([R::one()]))
    }
}

impl Constraints<1, 0> for PushedLate {}

/// The late push's work and the energy balance to `t = 1`, by every method.
fn late_push_work<M: chetaev::model::Model>(problem: &Problem<M>) -> Result<(), Error> {
    for method in AnyMethod::all(1e-3) {
        let options = Options::until(1.0)
            .tolerances(1e-12, 1e-12)
            .record(Record::Energy)
            .output_final();
        let sol = solve(problem, method, &options)?;
        assert!(sol.is_success(), "{:?}", sol.status);
        let w = *sol.work_forces.last().expect("recorded");
        // The jump of the force at t = ½ costs the adaptive methods a few digits; Rk4's fixed
        // steps of 1e-3 meet it at a step's end, to rounding of t, and err by a fraction of h.
        let tol = method.info().fixed_step.unwrap_or(1e-6);
        assert!((w - 0.625).abs() < tol, "{}: W_Q = {w}", method.name());
        let balance = sol.energy_balance().last().copied().expect("recorded");
        assert!(balance.abs() < tol, "{}: balance {balance}", method.name());
    }
    Ok(())
}

#[test]
fn forces_that_begin_after_the_start_have_their_work_recorded() -> Result<(), Error> {
    let (q0, qd0) = (SVector::zeros(), SVector::from([1.0]));
    for by_value in [true, false] {
        late_push_work(&Problem::new(PushedLate { by_value }, 0.0, q0, qd0)?)?;
    }
    Ok(())
}

/// The state carries the forces' work `W_Q` with the energy balance unless the compiled
/// equations prove the model has no forces anywhere: not for the paper's model, but for a force
/// behind a comparison, a force the recording cannot follow, a dissipation function, and on the
/// dual-number route, which proves nothing.
#[test]
fn the_forces_work_is_left_out_only_where_the_model_provably_has_no_forces() -> Result<(), Error> {
    use chetaev::integrate::system::ReducedOde;
    fn carries<M: chetaev::model::Model>(problem: &Problem<M>) -> bool {
        let ode = ReducedOde::for_problem(problem, true);
        assert!(ode.has_energy());
        ode.has_forces_quadrature()
    }
    let paper = uniform_projectile::model::uniform_problem(&Params::PAPER)?;
    assert!(!carries(&paper));
    assert!(carries(&paper.clone().with_route(Route::Dual)));
    let (q0, qd0) = (SVector::zeros(), SVector::from([1.0]));
    for by_value in [true, false] {
        assert!(carries(&Problem::new(
            PushedLate { by_value },
            0.0,
            q0,
            qd0
        )?));
    }
    let dragged = DraggedUniform {
        p: Params::PAPER,
        c: 0.7,
    };
    let (q0, qd0) = (SVector::from([0.0, 5.0]), SVector::from([10.0, 0.0]));
    assert!(carries(&Problem::new(dragged, 0.0, q0, qd0)?));
    Ok(())
}
