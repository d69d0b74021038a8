//! The compiled equations (the model's expression graph, its structure, the Schur solve) against
//! the dual-number reference: the same numbers at any state, the same motions, the structure
//! proved where it holds, the fallback where a branch of the model flips, and no compiled
//! equations where a model takes a value out of the graph; with the `serde` feature, a solution as JSON.

use chetaev::equations::structure::Structure;
use chetaev::model::Fixed;
use chetaev::prelude::*;

use crate::common::Paper;

/// The paper's particle at `v0 = 10`.
fn uniform() -> Problem<Fixed<Paper, 2, 1>> {
    Problem::new(
        Paper { v0: 10.0 },
        0.0,
        [0.0, 5.0].into(),
        [10.0, 0.0].into(),
    )
    .expect("ok")
}

/// A double pendulum (angles) whose joint speeds keep `θ̇1² + θ̇2² = v²`: `W` depends on `q`.
#[derive(Clone)]
struct Pendulum {
    v: f64,
}
impl Lagrangian<2> for Pendulum {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        let (m1, m2, l1, l2, g) = (1.0, 0.7, 1.2, 0.9, 9.81);
        qd[0] * qd[0] * (0.5 * (m1 + m2) * l1 * l1)
            + qd[1] * qd[1] * (0.5 * m2 * l2 * l2)
            + qd[0] * qd[1] * (q[0] - q[1]).cos() * (m2 * l1 * l2)
            + q[0].cos() * ((m1 + m2) * g * l1)
            + q[1].cos() * (m2 * g * l2)
    }
}
impl Constraints<2, 1> for Pendulum {
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
        SVector::from([qd.dot(qd) - self.v * self.v])
    }
}

fn pendulum() -> Problem<Fixed<Pendulum, 2, 1>> {
    Problem::new(
        Pendulum { v: 1.0 },
        0.0,
        [0.3, -0.2].into(),
        [1.0, 0.0].into(),
    )
    .expect("ok")
}

/// The same pendulum with run-time sizes, and a driven pivot (`L` depends on `t`): evaluated by
/// the compiled tape, with `W` varying and factorised at each evaluation.
#[derive(Clone)]
struct DynPendulum {
    v: f64,
}
impl DynModel for DynPendulum {
    fn sizes(&self) -> (usize, usize) {
        (2, 1)
    }
    fn lagrangian<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> R {
        let qs = SVector::from([q[0], q[1]]);
        let qds = SVector::from([qd[0], qd[1]]);
        Pendulum { v: self.v }.lagrangian(t, &qs, &qds) + qd[0] * q[1].sin() * (t * 1.3).cos()
    }
    fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
        f[0] = qd[0] * qd[0] + qd[1] * qd[1] - self.v * self.v;
    }
}

fn dyn_pendulum() -> Problem<DynPendulum> {
    Problem::dynamic(DynPendulum { v: 1.0 }, 0.0, vec![0.3, -0.2], vec![1.0, 0.0]).expect("ok")
}

/// Run-time sizes with everything at once: a particle on the sphere `|q| = ρ` (holonomic) at
/// constant speed `v`, in a gravity that varies in time, with drag (Rayleigh) and a driving force.
#[derive(Clone)]
struct Sphere {
    rho: f64,
    v: f64,
}
impl DynModel for Sphere {
    fn sizes(&self) -> (usize, usize) {
        (3, 1)
    }
    fn lagrangian<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> R {
        let kinetic = (qd[0] * qd[0] + qd[1] * qd[1] + qd[2] * qd[2]) * 0.5;
        kinetic - q[2] * ((t * 0.7).sin() * 0.5 + 9.81)
    }
    fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
        f[0] = qd[0] * qd[0] + qd[1] * qd[1] + qd[2] * qd[2] - self.v * self.v;
    }
    fn holonomic_count(&self) -> usize {
        1
    }
    fn holonomic<R: Real>(&self, _t: R, q: &[R], h: &mut [R]) {
        h[0] = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] - self.rho * self.rho;
    }
    fn forces<R: Real>(&self, t: R, _q: &[R], _qd: &[R], out: &mut [R]) -> bool {
        out[0] = t.sin() * 0.3;
        out[1] = R::zero();
        out[2] = R::zero();
        true
    }
    fn dissipation<R: Real>(&self, _t: R, _q: &[R], qd: &[R]) -> Option<R> {
        Some((qd[0] * qd[0] + qd[1] * qd[1] + qd[2] * qd[2]) * 0.05)
    }
}

fn sphere() -> Problem<Sphere> {
    let s = Sphere { rho: 2.0, v: 1.5 };
    Problem::dynamic(s, 0.0, vec![2.0, 0.0, 0.0], vec![0.0, 1.5, 0.0]).expect("consistent")
}

/// Compares the compiled and the dual-number equations of `problem` at states around
/// `(q0, q̇0)` (not on the constraints: the equations hold anywhere).
/// Six states `(t, q, q̇)` around `problem`'s initial one, by fixed irregular shifts.
fn states_around<M: Model>(problem: &Problem<M>) -> Vec<(f64, Vec<f64>, Vec<f64>)> {
    (0..6)
        .map(|s| {
            let shift = |x: &[f64], k: usize| -> Vec<f64> {
                x.iter()
                    .enumerate()
                    .map(|(i, v)| v + 0.1 * ((s * 7 + i * 3 + k) % 5) as f64 - 0.2)
                    .collect()
            };
            (
                0.3 * s as f64,
                shift(problem.q0(), 1),
                shift(problem.qd0(), 2),
            )
        })
        .collect()
}

fn compare_at_states<M: Model + Clone>(problem: &Problem<M>) {
    assert!(problem.compiled().is_some(), "the model should compile");
    let dual = problem.clone().with_route(Route::Dual);
    assert!(dual.compiled().is_none());
    for (t, q, qd) in states_around(problem) {
        let a = problem.equations_at(t, &q, &qd).expect("regular");
        let b = dual.equations_at(t, &q, &qd).expect("regular");
        let close = |x: &[f64], y: &[f64], what: &str| {
            let scale = y.iter().fold(1.0f64, |m, v| m.max(v.abs()));
            for (u, v) in x.iter().zip(y) {
                assert!(
                    (u - v).abs() <= 1e-11 * scale,
                    "{what}: {x:?} against {y:?}"
                );
            }
        };
        close(&a.qdd, &b.qdd, "q̈");
        close(&a.mu, &b.mu, "μ");
        close(&a.phi, &b.phi, "Φ");
        close(&a.f, &b.f, "f");
        close(&a.forces, &b.forces, "Q");
        close(
            &[a.energy, a.dl_dt, a.power, a.power_forces, a.l],
            &[b.energy, b.dl_dt, b.power, b.power_forces, b.l],
            "E, ∂L/∂t, q̇·Φ, q̇·Q, L",
        );
    }
}

/// A particle in a constant, coupled metric (`W` constant, positive definite, not diagonal: factorised
/// once) at constant speed, in gravity.
#[derive(Clone)]
struct Coupled;
impl DynModel for Coupled {
    fn sizes(&self) -> (usize, usize) {
        (3, 1)
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        (qd[0] * qd[0] * 2.0 + qd[1] * qd[1] + qd[2] * qd[2] * 3.0) * 0.5
            + qd[0] * qd[1] * 0.4
            + qd[1] * qd[2] * 0.3
            - q[2] * 9.81
    }
    fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
        f[0] = qd[0] * qd[0] + qd[1] * qd[1] + qd[2] * qd[2] - 4.0;
    }
}

fn coupled() -> Problem<Coupled> {
    Problem::dynamic(Coupled, 0.0, vec![0.0, 0.0, 1.0], vec![2.0, 0.0, 0.0]).expect("consistent")
}

/// Asserts that `x` and `y` agree to `tol` relative to the largest entry of `y` (at least 1).
fn agree(x: &[f64], y: &[f64], tol: f64, what: &str) {
    let scale = y.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    for (i, (u, v)) in x.iter().zip(y).enumerate() {
        assert!(
            (u - v).abs() <= tol * scale,
            "{what}, entry {i}: {u} against {v}"
        );
    }
}

/// The integrator's right-hand side and its Jacobian by machine code (the graph route's; the
/// Jacobian by forward derivatives of the right-hand side's program) against the dual-number
/// route's, with the energy quadratures and without, at states around the initial one.
fn compare_integrator_functions<M: Model + Clone>(problem: &Problem<M>) {
    use chetaev::integrate::system::{OdeSystem, ReducedOde};
    let compiled = problem.compiled().expect("the model should compile");
    let native = compiled.native_operations();
    if cfg!(any(target_arch = "x86_64", target_arch = "aarch64")) {
        assert!(native.is_some(), "this host has machine code");
    }
    let dual = problem.clone().with_route(Route::Dual);
    for energy in [false, true] {
        // Both carry the forces' work, which the compiled route may leave out: the same layout.
        let mut a = ReducedOde::for_problem(problem, energy).with_forces_quadrature(true);
        let mut b = ReducedOde::for_problem(&dual, energy).with_forces_quadrature(true);
        let dim = a.dim();
        for (t, q, qd) in states_around(problem) {
            let mut y = [q, qd].concat();
            y.resize(dim, 0.0);
            let what = format!("energy {energy}, t = {t}");
            let (mut dya, mut dyb) = (vec![f64::NAN; dim], vec![f64::NAN; dim]);
            a.rhs(t, &y, &mut dya).expect("regular");
            b.rhs(t, &y, &mut dyb).expect("regular");
            agree(&dya, &dyb, 1e-11, &format!("F, {what}"));
            let (mut ja, mut jb) = (unset_jacobian(dim), unset_jacobian(dim));
            a.jacobian(t, &y, &mut ja).expect("regular");
            b.jacobian(t, &y, &mut jb).expect("regular");
            agree(
                &[ja.dy, ja.dt].concat(),
                &[jb.dy, jb.dt].concat(),
                1e-10,
                &format!("∂F/∂y then ∂F/∂t, {what}"),
            );
        }
        assert_eq!(a.stats.graph_fallbacks, 0);
    }
}

/// A particle in a potential made of every elementary function (each argument kept in its
/// domain near the initial state), at constant speed: the derivative rules of the Jacobian's
/// program, one per function.
#[derive(Clone)]
struct Elementary;
impl DynModel for Elementary {
    fn sizes(&self) -> (usize, usize) {
        (2, 1)
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        let (x, y) = (q[0] * 0.1 + 0.3, q[1] * 0.1 + 0.2);
        let v = x.tan()
            + y.exp()
            + (x + 1.0).ln()
            + x.atan()
            + y.sinh()
            + x.cosh()
            + y.tanh()
            + x.asinh()
            + (y + 1.5).acosh()
            + x.atanh()
            + y.asin()
            + x.acos()
            + (x + 1.0).powf(1.7)
            + y.powi(3)
            + y.atan2(x + 1.0)
            + (x + 2.0).sqrt()
            + y.cbrt()
            + x.exp2()
            + y.ln_1p()
            + x.exp_m1()
            + (y + 1.0).log2()
            + (x + 1.0).log10()
            + (x - 2.0).abs()
            + (y + 3.0).recip();
        (qd[0] * qd[0] + qd[1] * qd[1]) * 0.5 - v
    }
    fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
        f[0] = qd[0] * qd[0] + qd[1] * qd[1] - 1.0;
    }
}

fn elementary() -> Problem<Elementary> {
    Problem::dynamic(Elementary, 0.0, vec![0.1, -0.2], vec![0.6, 0.8]).expect("consistent")
}

/// On a fresh problem from `make`: the right-hand side and the Jacobian as machine code, and the
/// Jacobian by dual numbers in grouped passes, each against the dual-number route's.
fn compare_routes<M: Model + Clone>(make: fn() -> Problem<M>) {
    compare_integrator_functions(&make());
    same_jacobians(&make());
}

#[test]
fn the_machine_code_and_the_grouped_jacobian_equal_the_dual_number_ones() {
    compare_routes(elementary);
    compare_routes(uniform);
    compare_routes(pendulum);
    compare_routes(dyn_pendulum);
    compare_routes(sphere);
    compare_routes(coupled);
}

#[test]
fn compiled_equations_equal_the_dual_number_equations_at_any_state() {
    compare_at_states(&coupled());
    compare_at_states(&uniform());
    compare_at_states(&pendulum());
    compare_at_states(&sphere());
    compare_at_states(&dyn_pendulum());
}

/// Solves both routes with `method` and compares the motions and multipliers.
fn compare_motion<M: Model + Clone>(problem: &Problem<M>, method: impl Method + Copy, t_end: f64) {
    let o = Options::until(t_end)
        .tolerances(1e-11, 1e-11)
        .output_grid(0.0, 11);
    let a = solve(problem, method, &o).expect("valid options");
    let b = solve(&problem.clone().with_route(Route::Dual), method, &o).expect("valid options");
    assert!(
        a.is_success() && b.is_success(),
        "{:?} {:?}",
        a.status,
        b.status
    );
    assert_eq!(a.len(), b.len());
    for i in 0..a.len() {
        let state = |s: &Solution| [&s.q[i], &s.qd[i]].concat();
        close_at(a.t[i], "(q, q̇)", &state(&a), &state(&b));
        close_at(a.t[i], "μ", &a.mu[i], &b.mu[i]);
    }
}

/// Asserts that `x` and `y` agree to `1e-8` relative to each entry of `y` (absolute below 1).
fn close_at(t: f64, what: &str, x: &[f64], y: &[f64]) {
    for (u, v) in x.iter().zip(y) {
        assert!(
            (u - v).abs() < 1e-8 * v.abs().max(1.0),
            "{what} at {t}: {u} {v}"
        );
    }
}

#[test]
fn compiled_motions_equal_the_dual_number_motions_for_explicit_and_implicit_methods() {
    compare_motion(&pendulum(), Dop853::default(), 3.0);
    compare_motion(&pendulum(), Rodas4, 3.0);
    compare_motion(&dyn_pendulum(), Dop853::default(), 3.0);
    compare_motion(&dyn_pendulum(), Rodas4, 3.0);
    compare_motion(&sphere(), Dopri5::default(), 2.0);
    compare_motion(&sphere(), Rodas4, 2.0);
    compare_motion(&coupled(), Dop853::default(), 1.0);
}

/// `∂F/∂y` and `∂F/∂t` of the reduced equations (with the energy quadratures) at `(t, q, q̇)`.
fn jacobian<M: Model>(problem: &Problem<M>, t: f64, y: &[f64]) -> (Vec<f64>, Vec<f64>) {
    jacobian_with(problem, true, t, y)
}

/// The integrator's Jacobian at `(t, y)`, with the energy quadratures (all three, the forces' work
/// too, so that every route has the same layout) or without (`y` is padded with zeros for them).
fn jacobian_with<M: Model>(
    problem: &Problem<M>,
    energy: bool,
    t: f64,
    y: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    use chetaev::integrate::system::{OdeSystem, ReducedOde};
    let mut sys = ReducedOde::for_problem(problem, energy).with_forces_quadrature(true);
    let dim = sys.dim();
    let mut y = y.to_vec();
    y.resize(dim, 0.0);
    let mut jac = unset_jacobian(dim);
    sys.jacobian(t, &y, &mut jac).expect("evaluates");
    (jac.dy, jac.dt)
}

/// A Jacobian of NaNs, so that an entry left unwritten shows.
fn unset_jacobian(dim: usize) -> chetaev::integrate::system::Jacobian {
    chetaev::integrate::system::Jacobian {
        dy: vec![f64::NAN; dim * dim],
        dt: vec![f64::NAN; dim],
    }
}

#[test]
fn the_jacobian_skips_the_time_direction_only_where_nothing_depends_on_t() {
    fn check<M: Model + Clone>(problem: &Problem<M>, autonomous: bool) {
        let compiled = problem.compiled().expect("compiled");
        assert_eq!(compiled.autonomous(), autonomous);
        let y = [0.4, -0.3, 0.8, 0.6];
        let (jac, dfdt) = jacobian(problem, 0.7, &y);
        let (jac_dual, dfdt_dual) = jacobian(&problem.clone().with_route(Route::Dual), 0.7, &y);
        close_at(0.7, "∂F/∂y", &jac, &jac_dual);
        close_at(0.7, "∂F/∂t", &dfdt, &dfdt_dual);
        assert_eq!(dfdt.iter().any(|&v| v != 0.0), !autonomous, "{dfdt:?}");
    }
    check(&uniform(), true);
    check(&pendulum(), true);
    // The driven pivot: L depends on t, so ∂F/∂t is evaluated.
    check(&dyn_pendulum(), false);
    // A comparison in the model's code could switch to a branch that depends on t.
    let kinked = Problem::dynamic(Kinked, 0.0, vec![1.0], vec![0.0]).expect("ok");
    assert!(!kinked.compiled().expect("compiled").autonomous());
}

/// Eight masses on a line, each tied to its neighbours by springs with a quartic term, the last
/// one driven by `cos t`, and the speeds of the first two held: `q̈_i` reaches only `q_{i−1}`,
/// `q_i`, `q_{i+1}` (and the constraint's coordinates), so the Jacobian is sparse.
#[derive(Clone)]
struct Chain;
const CHAIN: usize = 8;
impl DynModel for Chain {
    fn sizes(&self) -> (usize, usize) {
        (CHAIN, 1)
    }
    fn lagrangian<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> R {
        let mut l = R::zero();
        for v in qd {
            l += *v * *v * 0.5;
        }
        for i in 1..CHAIN {
            let d = q[i] - q[i - 1] - 1.0;
            l -= d * d * 0.5 + d.powi(4) * 0.25;
        }
        l + q[CHAIN - 1] * t.cos()
    }
    fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
        f[0] = qd[0] * qd[0] + qd[1] * qd[1] - 1.0;
    }
}

/// The Jacobian of a fresh problem (by dual numbers, in compressed passes where the structure
/// allows them) against the dual-number route's (one pass per column) at states around the initial
/// one, with the energy quadratures and without; returns each state's `t` and `∂F/∂t`.
fn same_jacobians<M: Model + Clone>(problem: &Problem<M>) -> Vec<(f64, Vec<f64>)> {
    // The groups made at once, not after `COLOUR_AFTER` passes.
    problem.compiled().and_then(|c| c.jacobian_passes());
    let dual = problem.clone().with_route(Route::Dual);
    let mut out = Vec::new();
    for energy in [false, true] {
        for (t, q, qd) in states_around(problem) {
            let y = [q, qd].concat();
            let (jac, dfdt) = jacobian_with(problem, energy, t, &y);
            let (jac_dual, dfdt_dual) = jacobian_with(&dual, energy, t, &y);
            close_at(t, "∂F/∂y", &jac, &jac_dual);
            close_at(t, "∂F/∂t", &dfdt, &dfdt_dual);
            out.push((t, dfdt));
        }
    }
    out
}

#[test]
fn the_jacobian_by_dual_numbers_takes_one_pass_per_group_of_columns_that_share_no_row() {
    let q0: Vec<f64> = (0..CHAIN).map(|i| i as f64 * 1.1).collect();
    let mut qd0 = vec![0.0; CHAIN];
    qd0[0] = 0.6;
    qd0[1] = 0.8;
    let chain = Problem::dynamic(Chain, 0.0, q0, qd0).expect("consistent");
    let passes = chain
        .compiled()
        .and_then(|c| c.jacobian_passes())
        .expect("no guards, a metric that is positive definite");
    // 2n + 1 = 17 columns. Rows 0 and 1 (the held speeds, through μ) reach q_0 … q_2 and
    // q̇_0, q̇_1; every other row three neighbouring positions; each q̇ row its own velocity.
    assert!(passes <= 6, "{passes} passes");
    for (t, dfdt) in same_jacobians(&chain) {
        // ∂q̈_7/∂t = −sin t.
        assert!((dfdt[2 * CHAIN - 1] + t.sin()).abs() < 1e-12, "{dfdt:?}");
    }
    // The paper's particle: q̈ reaches q̇ alone, whose two columns share the rows of q̈.
    let uniform = uniform();
    assert_eq!(
        uniform.compiled().and_then(|c| c.jacobian_passes()),
        Some(2)
    );
    // A recorded branch could reach other entries on its other side: one pass per column.
    let kinked = Problem::dynamic(Kinked, 0.0, vec![1.0], vec![0.0]).expect("ok");
    assert_eq!(kinked.compiled().and_then(|c| c.jacobian_passes()), None);
}

fn structure<M: Model>(p: &Problem<M>) -> &Structure {
    p.compiled().expect("compiled").structure()
}

#[test]
fn the_structure_is_found_from_l_and_f_alone() {
    let uniform = uniform();
    let s = structure(&uniform);
    assert!(s.w.is_constant() && !s.w.zero);
    assert_eq!(s.w_pattern, vec![true, false, false, true]);
    assert!(s.dl_dq.is_constant() && s.g.zero && s.dl_dt.zero && s.c.zero && s.forces.zero);
    assert!(s.j.qd && !s.j.q && !s.j.t);
    assert!(uniform.compiled().expect("compiled").constant_metric());

    let pendulum = pendulum();
    let s = structure(&pendulum);
    assert!(s.w.q && !s.w.qd && !s.w.t);
    assert!(s.g.q && s.g.qd && !s.g.zero && s.c.zero);
    assert!(!pendulum.compiled().expect("compiled").constant_metric());

    let sphere = sphere();
    let s = structure(&sphere);
    assert_eq!((s.sizes, s.holonomic), ((3, 2), 1));
    assert!(s.dl_dt.t && s.dl_dq.t && !s.dl_dq.q);
    assert!(s.forces.t && s.forces.qd && !s.forces.q);
    // The holonomic row of J is ∂h/∂q = 2q; the velocity row 2q̇; c of ḣ = 2|q̇|².
    assert!(s.j.q && s.j.qd && s.c.qd && !s.c.q);
}

/// `V = k q²` with `k` chosen by a branch on the sign of `q`: the recorded branch is a guard.
#[derive(Clone)]
struct Kinked;
impl DynModel for Kinked {
    fn sizes(&self) -> (usize, usize) {
        (1, 0)
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        let k = if q[0] > 0.0 { 1.0 } else { 4.0 };
        qd[0] * qd[0] * 0.5 - q[0] * q[0] * (0.5 * k)
    }
}

#[test]
fn a_branch_that_flips_falls_back_to_dual_numbers_and_gives_the_same_motion() {
    let problem = Problem::dynamic(Kinked, 0.0, vec![1.0], vec![0.0]).expect("ok");
    let compiled = problem.compiled().expect("compiled");
    assert_eq!(compiled.guards(), 1);
    let o = Options::until(3.0).tolerances(1e-10, 1e-10);
    let a = solve(&problem, Dop853::default(), &o).expect("valid");
    let b = solve(
        &problem.clone().with_route(Route::Dual),
        Dop853::default(),
        &o,
    )
    .expect("ok");
    assert!(a.stats.graph_fallbacks > 0, "{:?}", a.stats);
    assert_eq!(b.stats.graph_fallbacks, 0);
    let (_, qa, _) = a.last().expect("recorded");
    let (_, qb, _) = b.last().expect("recorded");
    assert!((qa[0] - qb[0]).abs() < 1e-9, "{} {}", qa[0], qb[0]);
    // Exact: cos t until q = 0 at t = π/2, then an oscillation of frequency 2 with q̇ = −1.
    let t = 3.0 - std::f64::consts::FRAC_PI_2;
    assert!((qa[0] - (-(2.0 * t).sin() / 2.0)).abs() < 1e-8, "{}", qa[0]);
}

#[test]
fn a_branch_that_flips_under_machine_code_takes_the_interpreted_route_with_the_same_numbers() {
    // The machine code made at once: the solve starts on it, and its guard fails at q = 0. The
    // same solve of a fresh problem runs the interpreted tape throughout, whose numbers the
    // machine code equals bit for bit: the two solutions must be the same, counts included.
    let native = Problem::dynamic(Kinked, 0.0, vec![1.0], vec![0.0]).expect("ok");
    let ops = native.compiled().and_then(|c| c.native_operations());
    if cfg!(any(target_arch = "x86_64", target_arch = "aarch64")) {
        assert!(ops.is_some_and(|n| n > 0), "this host has machine code");
    }
    let interpreted = Problem::dynamic(Kinked, 0.0, vec![1.0], vec![0.0]).expect("ok");
    for energy in [false, true] {
        let mut o = Options::until(3.0).tolerances(1e-10, 1e-10);
        if energy {
            o = o.record(Record::Energy);
        }
        let a = solve(&native, Dop853::default(), &o).expect("valid");
        let b = solve(&interpreted, Dop853::default(), &o).expect("valid");
        assert!(a.stats.graph_fallbacks > 0, "{:?}", a.stats);
        assert_eq!(a.stats, b.stats, "energy {energy}");
        assert_eq!(a.t, b.t, "energy {energy}");
        assert_eq!(a.q, b.q, "energy {energy}");
        assert_eq!(a.qd, b.qd, "energy {energy}");
    }
}

/// A model that takes a value out of the graph (`re()`): it is not compiled, and still solves.
struct Escaping;
impl DynModel for Escaping {
    fn sizes(&self) -> (usize, usize) {
        (1, 0)
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        let k = if q[0].re() > 0.0 { 1.0 } else { 4.0 };
        qd[0] * qd[0] * 0.5 - q[0] * q[0] * (0.5 * k)
    }
}

#[test]
fn a_model_that_takes_values_out_of_the_graph_is_evaluated_by_dual_numbers() {
    let problem = Problem::dynamic(Escaping, 0.0, vec![1.0], vec![0.0]).expect("ok");
    assert!(problem.compiled().is_none());
    let sol = solve(&problem, Dop853::default(), &Options::until(1.0)).expect("valid");
    assert!(sol.is_success());
}

#[test]
fn the_derived_equations_print_as_text_and_latex() {
    let uniform = uniform();
    let c = uniform.compiled().expect("compiled");
    let text = c.equations_text(false);
    let find = |name: &str| text.iter().find(|(k, _)| k == name).map(|(_, v)| v.clone());
    assert_eq!(find("J[1,1]").as_deref(), Some("2·q̇1"));
    assert_eq!(find("W[1,1]").as_deref(), Some("1"));
    assert_eq!(find("W[1,2]"), None, "zero entries are left out");
    let latex = c.equations_text(true);
    assert!(latex
        .iter()
        .any(|(k, v)| k == "f_{1}" && v.contains("\\dot q_{1}")));
}

#[test]
fn problems_stay_send_and_sync_for_parallel_sweeps() {
    fn shared<T: Send + Sync>(_: &T) {}
    let uniform = uniform();
    let _ = uniform.compiled();
    shared(&uniform);
    shared(&sphere());
}

/// A static model whose mass depends on a branch: heavy for `x > 0`, light otherwise. The
/// structure recorded at `x > 0` (a constant `W`) does not hold past the switch, so the guard must
/// send those evaluations to dual numbers on the static route too.
#[derive(Clone)]
struct Switching;
impl Lagrangian<2> for Switching {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        let m = if q[0] > 0.0 { 3.0 } else { 1.0 };
        qd.dot(qd) * (0.5 * m) - q[1] * (m * 9.81)
    }
}
impl Constraints<2, 1> for Switching {
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
        SVector::from([qd.dot(qd) - 4.0])
    }
}

#[test]
fn a_static_model_whose_branch_changes_its_structure_is_followed_past_the_switch() {
    let problem = Problem::new(Switching, 0.0, [0.5, 1.0].into(), [-2.0, 0.0].into()).expect("ok");
    assert_eq!(problem.compiled().expect("compiled").guards(), 1);
    // Past x = 0 the mass is 1 instead of 3: q̈ differs only through W and ∂L/∂q scaled alike, so
    // compare the equations themselves at a state on the other side.
    let dual = problem.clone().with_route(Route::Dual);
    let (a, b) = (
        problem
            .equations_at(0.0, &[-0.5, 1.0], &[-1.2, -1.6])
            .expect("regular"),
        dual.equations_at(0.0, &[-0.5, 1.0], &[-1.2, -1.6])
            .expect("regular"),
    );
    for (x, y) in a.mu.iter().chain(&a.qdd).zip(b.mu.iter().chain(&b.qdd)) {
        assert!((x - y).abs() < 1e-12 * y.abs().max(1.0), "{a:?} {b:?}");
    }
    compare_motion(&problem, Dop853::default(), 1.0);
    let sol = solve(&problem, Dop853::default(), &Options::until(1.0)).expect("valid");
    assert!(sol.stats.graph_fallbacks > 0, "{:?}", sol.stats);
}

/// A solution written as JSON with the `serde` feature (which this package's tests turn on): every
/// series, the events, the statistics and the status, in the numbers recorded.
#[test]
fn a_solution_serialises_to_json_with_its_events_statistics_and_status() {
    let problem = uniform();
    let impact = Event::new("impact", |_t, q: &[f64], _qd: &[f64]| q[1])
        .falling()
        .terminal();
    let o = Options::until(10.0).tolerances(1e-10, 1e-10).event(impact);
    let sol = solve(&problem, Dop853::default(), &o).expect("valid");
    let json: serde_json::Value = serde_json::to_value(&sol).expect("serialisable");
    assert_eq!(json["method"], "Dop853");
    assert_eq!(json["t"].as_array().map(Vec::len), Some(sol.len()));
    assert_eq!(json["q"]["width"], 2);
    assert_eq!(json["q"]["data"][1].as_f64(), Some(sol.q[0][1]));
    assert_eq!(json["mu"]["data"].as_array().map(Vec::len), Some(sol.len()));
    assert_eq!(json["events"][0]["t"].as_f64(), Some(sol.events[0].t));
    assert_eq!(
        json["stats"]["rhs_evaluations"].as_u64(),
        Some(sol.stats.rhs_evaluations as u64)
    );
    assert_eq!(json["status"]["Terminated"]["event"], 0);
}

/// `L = ½|q̇|²` under `q̇0² = 1` and, with `two`, also `q̇1 = 1/2`: `J`'s first row vanishes where
/// `q̇0 = 0`.
#[derive(Clone)]
struct Vanishing {
    two: bool,
}
impl DynModel for Vanishing {
    fn sizes(&self) -> (usize, usize) {
        (2, if self.two { 2 } else { 1 })
    }
    fn lagrangian<R: Real>(&self, _t: R, _q: &[R], qd: &[R]) -> R {
        (qd[0] * qd[0] + qd[1] * qd[1]) * 0.5
    }
    fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
        f[0] = qd[0] * qd[0] - 1.0;
        if self.two {
            f[1] = qd[1] - 0.5;
        }
    }
}

#[test]
fn a_vanishing_constraint_row_is_reported_as_such_by_both_routes() {
    use chetaev::equations::saddle::SaddleFailure;
    use chetaev::equations::{evaluate_with, Need, Workspace};
    for two in [false, true] {
        let model = Vanishing { two };
        let problem = Problem::dynamic(model.clone(), 0.0, vec![0.0, 0.0], vec![1.0, 0.5])
            .expect("consistent");
        let plan = problem.compiled().expect("compiled");
        let (q, qd) = ([0.3, -0.1], [0.0, 0.5]);
        for need in [Need::Motion, Need::Rates, Need::All] {
            for route in [Some(plan), None] {
                let mut ws = Workspace::for_model(&model);
                let e = evaluate_with(&model, route, &mut ws, 0.0, &q, &qd, need).map(|_| ());
                assert_eq!(
                    e,
                    Err(SaddleFailure::ZeroConstraintRow { row: 0 }),
                    "k = {}, {need:?}, compiled: {}",
                    1 + usize::from(two),
                    route.is_some()
                );
            }
        }
    }
}

#[test]
fn the_machine_code_of_the_papers_particle_is_the_reduced_formula_with_its_checks() {
    // J = 2 q̇, S = |J|², μ = −(J·r)/S, q̈ = r + J μ with r = (0, −10) and W = 1, and the
    // checks: 26 operations when the structure's zeros and ones are folded, 34 when they are not.
    let ops = uniform().compiled().and_then(|c| c.native_operations());
    eprintln!("machine code: {ops:?} operations");
    if cfg!(any(target_arch = "x86_64", target_arch = "aarch64")) {
        let ops = ops.expect("this host has machine code");
        assert!(ops <= 30, "{ops} operations");
    }
}

/// `L` of a planar chain of pendulums (unit lengths and masses) in gravity, over slices so that
/// the static and the run-time flavours below record the same operations: `W` varies with `q`.
fn pendulums_lagrangian<R: Real>(q: &[R], qd: &[R]) -> R {
    let (mut xd, mut yd, mut y, mut l) = (R::zero(), R::zero(), R::zero(), R::zero());
    for (&a, &w) in q.iter().zip(qd) {
        xd += a.cos() * w;
        yd += a.sin() * w;
        y -= a.cos();
        l += (xd * xd + yd * yd) * 0.5 - y * 9.81;
    }
    l
}

/// The chain of [`pendulums_lagrangian`] with static sizes, the speed of its first two links held.
#[derive(Clone)]
struct Pendulums<const N: usize>;
impl<const N: usize> Lagrangian<N> for Pendulums<N> {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, N>, qd: &SVector<R, N>) -> R {
        pendulums_lagrangian(q.as_slice(), qd.as_slice())
    }
}
impl<const N: usize> Constraints<N, 1> for Pendulums<N> {
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, N>, qd: &SVector<R, N>) -> SVector<R, 1> {
        SVector::from([qd[0] * qd[0] + qd[1] * qd[1] - 0.08])
    }
}

/// The same chain with its size known at run time.
#[derive(Clone)]
struct DynPendulums(usize);
impl DynModel for DynPendulums {
    fn sizes(&self) -> (usize, usize) {
        (self.0, 1)
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        pendulums_lagrangian(q, qd)
    }
    fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
        f[0] = qd[0] * qd[0] + qd[1] * qd[1] - 0.08;
    }
}

/// The initial state of the chains of pendulums: `|(q̇1, q̇2)|² = 0.08`.
fn pendulums_state(n: usize) -> (Vec<f64>, Vec<f64>) {
    let q = (0..n).map(|i| 0.3 + 0.1 * i as f64).collect();
    let qd = (0..n)
        .map(|i| if i < 2 { 0.2 } else { 0.2 * (i as f64).cos() })
        .collect();
    (q, qd)
}

#[test]
fn a_large_static_model_is_evaluated_by_the_tape_as_the_same_model_with_run_time_sizes() {
    // Six coordinates with a metric that varies: past the sizes at which the static fixed-size
    // dual passes are the faster route, for values and for the Jacobian alike. The static model
    // then takes the compiled tape, the run-time one's route, to the last bit.
    const N: usize = 6;
    let (q, qd) = pendulums_state(N);
    let fixed = Problem::new(
        Pendulums::<N>,
        0.0,
        SVector::from_column_slice(&q),
        SVector::from_column_slice(&qd),
    )
    .expect("valid");
    let dynamic = Problem::dynamic(DynPendulums(N), 0.0, q.clone(), qd.clone()).expect("valid");
    for (t, q, qd) in states_around(&fixed) {
        let (a, b) = (
            fixed.equations_at(t, &q, &qd).expect("evaluates"),
            dynamic.equations_at(t, &q, &qd).expect("evaluates"),
        );
        assert_eq!((&a.qdd, &a.mu), (&b.qdd, &b.mu), "at t = {t}");
        let y = [q, qd].concat();
        assert_eq!(
            jacobian(&fixed, t, &y),
            jacobian(&dynamic, t, &y),
            "at t = {t}"
        );
    }
    same_motions(&fixed, &dynamic, Dop853::default());
    same_motions(&fixed, &dynamic, Rodas4);
    // And the tape agrees with the dual-number reference.
    compare_motion(&fixed, Dop853::default(), 2.0);
    compare_motion(&fixed, Rodas4, 2.0);
}

/// Solves `a` and `b` with `method` and asserts that the motions are the same to the last bit.
fn same_motions<A: Model, B: Model>(a: &Problem<A>, b: &Problem<B>, method: impl Method + Copy) {
    let o = Options::until(2.0).tolerances(1e-10, 1e-10);
    let (a, b) = (
        solve(a, method, &o).expect("valid options"),
        solve(b, method, &o).expect("valid options"),
    );
    assert!(a.is_success(), "{}: {:?}", a.method, a.status);
    assert_eq!((&a.t, &a.q, &a.mu), (&b.t, &b.q, &b.mu), "{}", a.method);
}

/// A chain of `PAIRED` masses `1 + q_i²/10` (a metric that varies) joined by springs, the speed of
/// each pair `(2a, 2a + 1)` held: constraints that share no velocity.
#[derive(Clone)]
struct PairedChain;
const PAIRED: usize = 8;
impl DynModel for PairedChain {
    fn sizes(&self) -> (usize, usize) {
        (PAIRED, PAIRED / 2)
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        let mut l = R::zero();
        for (x, v) in q.iter().zip(qd) {
            l += (*x * *x * 0.1 + 1.0) * *v * *v * 0.5;
        }
        for i in 1..PAIRED {
            let d = q[i] - q[i - 1] - 1.0;
            l -= d * d * 0.5;
        }
        l
    }
    fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
        for (a, f) in f.iter_mut().enumerate() {
            *f = qd[2 * a] * qd[2 * a] + qd[2 * a + 1] * qd[2 * a + 1] - 1.0;
        }
    }
}

fn paired_chain() -> Problem<PairedChain> {
    let q0 = (0..PAIRED).map(|i| i as f64 * 1.1).collect();
    let qd0 = (0..PAIRED).map(|i| [0.6, 0.8][i % 2]).collect();
    Problem::dynamic(PairedChain, 0.0, q0, qd0).expect("consistent")
}

#[test]
fn constraints_that_share_no_velocity_leave_the_jacobian_sparse() {
    // 2n + 1 = 17 columns. Row q̈_i reaches q_(i−1) … q_(i+1) through the springs and the metric,
    // and through its pair's μ the pair's velocities and the positions next to the pair: at most
    // four positions and two velocities. The factors of the Schur complement, whose entries
    // between two pairs are zero, must not couple the pairs (they did: 16 passes).
    let passes = paired_chain()
        .compiled()
        .and_then(|c| c.jacobian_passes())
        .expect("no guards, a metric that is positive definite");
    assert!(passes <= 8, "{passes} passes");
    compare_routes(paired_chain);
    compare_motion(&paired_chain(), Rodas4, 1.0);
}

/// A particle on the unit sphere of velocities in a potential with a kink at `x = 0`: `0.3 |x|`,
/// or `0.3 x |x|`, with a metric that varies with `q`.
#[derive(Clone)]
struct KinkAtZero {
    cube: bool,
}
impl DynModel for KinkAtZero {
    fn sizes(&self) -> (usize, usize) {
        (3, 1)
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        let (x, y) = (q[0], q[1]);
        let potential = if self.cube {
            x.abs() * x * 0.3
        } else {
            x.abs() * 0.3
        };
        let m = (x * x + y * y + 1.0).sqrt();
        m * (qd[0] * qd[0] + qd[1] * qd[1]) * 0.5 + qd[2] * qd[2] * 0.5 - potential
    }
    fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
        f[0] = qd[0] * qd[0] + qd[1] * qd[1] + qd[2] * qd[2] - 1.0;
    }
}

#[test]
fn at_a_coordinate_of_minus_zero_every_route_takes_the_same_side_of_a_kink() {
    // At x = −0.0 the slope of |x| is −1 for num-dual, for f64::signum and so for the machine
    // code: the interpreted equations' Jacobian must take the same side, as their own q̈ does.
    let y = [-0.0, 0.3, 0.2, 0.6, 0.1, 0.8];
    for cube in [false, true] {
        let make = || {
            Problem::dynamic(
                KinkAtZero { cube },
                0.0,
                vec![0.2, 0.3, 0.2],
                vec![0.6, 0.0, 0.8],
            )
            .expect("consistent")
        };
        let interpreted = make();
        assert!(interpreted.compiled().is_some());
        let machine = make();
        let has_machine_code = machine
            .compiled()
            .and_then(|c| c.native_operations())
            .is_some();
        let dual = make().with_route(Route::Dual);
        let (ja, ta) = jacobian_with(&interpreted, false, 0.0, &y);
        let (jd, td) = jacobian_with(&dual, false, 0.0, &y);
        let what = format!("cube {cube}");
        agree(
            &[ja.clone(), ta.clone()].concat(),
            &[jd, td].concat(),
            1e-12,
            &what,
        );
        if has_machine_code {
            let (jm, tm) = jacobian_with(&machine, false, 0.0, &y);
            agree(&[ja, ta].concat(), &[jm, tm].concat(), 1e-12, &what);
        }
    }
}

/// `L = ½ ẋ² − x^3.5/10`: smooth at `x = 0` to second order, but num-dual forms `x^p` from
/// `x^(p−3)·x³`, which is `∞·0` there for the `x^2.5` and `x^1.5` of the derivatives.
#[derive(Clone)]
struct Power;
impl DynModel for Power {
    fn sizes(&self) -> (usize, usize) {
        (1, 0)
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        qd[0] * qd[0] * 0.5 - q[0].powf(3.5) * 0.1
    }
}

/// Two particles in the potential of [`Power`] each: the powers of the two coordinates are
/// evaluated side by side, as one run of the tape.
#[derive(Clone)]
struct Powers;
impl DynModel for Powers {
    fn sizes(&self) -> (usize, usize) {
        (2, 0)
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        (qd[0] * qd[0] + qd[1] * qd[1]) * 0.5 - (q[0].powf(3.5) + q[1].powf(3.5)) * 0.1
    }
}

#[test]
fn fractional_powers_at_exactly_zero_side_by_side_have_their_jacobian() {
    let problem =
        Problem::dynamic(Powers, 0.0, vec![0.0, 0.0], vec![1.0, 1.0]).expect("finite at the start");
    let (jac, dfdt) = jacobian_with(&problem, false, 0.0, &[0.0, 0.0, 1.0, 1.0]);
    let mut expected = vec![0.0; 16];
    expected[2] = 1.0;
    expected[7] = 1.0;
    assert_eq!(jac, expected);
    assert_eq!(dfdt, [0.0; 4]);
}

#[test]
fn a_fractional_power_at_exactly_zero_has_its_jacobian_and_the_implicit_methods_pass_it() {
    let problem = Problem::dynamic(Power, 0.0, vec![0.0], vec![1.0]).expect("finite at the start");
    // ẍ = −0.35 x^2.5, so ∂(ẋ, ẍ)/∂(x, ẋ) = ((0, 1), (−0.875 x^1.5, 0)) = ((0, 1), (0, 0)) at 0.
    let (jac, dfdt) = jacobian_with(&problem, false, 0.0, &[0.0, 1.0]);
    assert_eq!(jac, [0.0, 1.0, 0.0, 0.0]);
    assert_eq!(dfdt, [0.0, 0.0]);
    // The energy ½ ẋ² + x^3.5/10 = ½ is kept, by every method.
    for method in [
        AnyMethod::Rodas4(Rodas4),
        AnyMethod::Rodas5P(Rodas5P),
        AnyMethod::Dop853(Dop853::default()),
    ] {
        let sol = solve(
            &problem,
            method,
            &Options::until(1.0).tolerances(1e-10, 1e-10),
        )
        .expect("valid options");
        assert!(sol.is_success(), "{}: {:?}", sol.method, sol.status);
        let (_, q, qd) = sol.last().expect("recorded");
        let (x, v) = (q[0], qd[0]);
        let energy = 0.5 * v * v + 0.1 * x.powf(3.5);
        assert!((energy - 0.5).abs() < 1e-8, "{}: E = {energy}", sol.method);
    }
}
