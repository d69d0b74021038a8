//! Autodiff derivatives against hand-derived ones, for a Lagrangian in which every block is non-zero:
//! a configuration-dependent mass matrix with off-diagonal terms, a time-dependent term linear in
//! the velocities (magnetic-like), and a time-dependent potential; and a constraint that is
//! nonlinear in `q̇` and depends on `q` and `t`.

use approx::assert_relative_eq;
use chetaev::equations::derivatives::{constraint_derivatives, lagrangian_derivatives};
use chetaev::equations::{evaluate, Workspace};
use chetaev::model::Fixed;
use chetaev::prelude::*;
use nalgebra::{Matrix3, Vector3};

/// L = ½ a(q) ẋ² + ½ b(q) ẏ² + c(q) ẋ ẏ + β(t)(x ẏ − y ẋ) − V(t, q), with q = (x, y),
/// a = 1 + x², b = 2 + sin y, c = 0.3 x y, β = cos t, V = (1 + 0.1 t)(x² + y⁴)/2;
/// f = ẋ² + eᵗ x ẏ − t sin y.
struct Everything;

impl Lagrangian<2> for Everything {
    fn lagrangian<R: Real>(&self, t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        let (x, y, xd, yd) = (q[0], q[1], qd[0], qd[1]);
        let a = x * x + 1.0;
        let b = y.sin() + 2.0;
        let c = x * y * 0.3;
        let beta = t.cos();
        let v = (t * 0.1 + 1.0) * (x * x + y.powi(4)) * 0.5;
        a * xd * xd * 0.5 + b * yd * yd * 0.5 + c * xd * yd + beta * (x * yd - y * xd) - v
    }
}

impl Constraints<2, 1> for Everything {
    fn constraints<R: Real>(&self, t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
        SVector::from([qd[0] * qd[0] + t.exp() * q[0] * qd[1] - t * q[1].sin()])
    }
}

const T: f64 = 0.7;
const Q: [f64; 2] = [0.4, -1.1];
const QD: [f64; 2] = [1.3, 0.6];

#[test]
fn lagrangian_blocks_match_hand_derivation() {
    let (t, [x, y], [xd, yd]) = (T, Q, QD);
    let d = lagrangian_derivatives(&Everything, t, &SVector::from(Q), &SVector::from(QD));
    let (a, b, c, beta, dbeta) = (1.0 + x * x, 2.0 + y.sin(), 0.3 * x * y, t.cos(), -t.sin());
    let s = 1.0 + 0.1 * t;

    let p = [a * xd + c * yd - beta * y, b * yd + c * xd + beta * x];
    let w = [[a, c], [c, b]];
    let dl_dq = [
        x * xd * xd + 0.3 * y * xd * yd + beta * yd - s * x,
        0.5 * y.cos() * yd * yd + 0.3 * x * xd * yd - beta * xd - s * 2.0 * y.powi(3),
    ];
    // ∂p/∂q q̇ + ∂p/∂t
    let g = [
        (2.0 * x * xd + 0.3 * y * yd) * xd + (0.3 * x * yd - beta) * yd - dbeta * y,
        (0.3 * y * xd + beta) * xd + (y.cos() * yd + 0.3 * x * xd) * yd + dbeta * x,
    ];
    let dl_dt = dbeta * (x * yd - y * xd) - 0.05 * (x * x + y.powi(4));

    for i in 0..2 {
        assert_relative_eq!(d.p[i], p[i], max_relative = 1e-14);
        assert_relative_eq!(d.dl_dq[i], dl_dq[i], max_relative = 1e-14);
        assert_relative_eq!(d.g[i], g[i], max_relative = 1e-14);
        for (k, wik) in w[i].iter().enumerate() {
            assert_relative_eq!(d.w[(i, k)], *wik, max_relative = 1e-14);
        }
    }
    assert_relative_eq!(d.dl_dt, dl_dt, max_relative = 1e-13);
    // Every block is really exercised.
    assert!(d.w[(0, 1)] != 0.0 && d.g.iter().all(|v| *v != 0.0) && d.dl_dt != 0.0);
}

#[test]
fn constraint_blocks_match_hand_derivation() {
    let (t, [x, y], [xd, yd]) = (T, Q, QD);
    let d = constraint_derivatives::<_, f64, 2, 1>(
        &Everything,
        t,
        &SVector::from(Q),
        &SVector::from(QD),
    );
    let e = t.exp();
    assert_relative_eq!(
        d.f[0],
        xd * xd + e * x * yd - t * y.sin(),
        max_relative = 1e-15
    );
    assert_relative_eq!(d.j[(0, 0)], 2.0 * xd, max_relative = 1e-15);
    assert_relative_eq!(d.j[(0, 1)], e * x, max_relative = 1e-15);
    // (∂f/∂q) q̇ + ∂f/∂t
    let c = e * yd * xd - t * y.cos() * yd + e * x * yd - y.sin();
    assert_relative_eq!(d.c[0], c, max_relative = 1e-14);
}

#[test]
fn block_solve_matches_a_dense_solve_of_the_hand_derived_system() {
    let (q, qd) = (SVector::from(Q), SVector::from(QD));
    let ld = lagrangian_derivatives(&Everything, T, &q, &qd);
    let cd = constraint_derivatives::<_, f64, 2, 1>(&Everything, T, &q, &qd);
    let model = Fixed::<_, 2, 1>(Everything);
    let mut ws = Workspace::for_model(&model);
    let d = evaluate(&model, &mut ws, T, &Q, &QD).expect("regular");
    // [W −Jᵀ; J 0] [q̈; μ] = [∂L/∂q − g; −c]  (Newton form)
    let m = Matrix3::new(
        ld.w[(0, 0)],
        ld.w[(0, 1)],
        -cd.j[(0, 0)],
        ld.w[(1, 0)],
        ld.w[(1, 1)],
        -cd.j[(0, 1)],
        cd.j[(0, 0)],
        cd.j[(0, 1)],
        0.0,
    );
    let rhs = Vector3::new(ld.dl_dq[0] - ld.g[0], ld.dl_dq[1] - ld.g[1], -cd.c[0]);
    let x = m.lu().solve(&rhs).expect("regular");
    assert_relative_eq!(d.qdd[0], x[0], max_relative = 1e-13);
    assert_relative_eq!(d.qdd[1], x[1], max_relative = 1e-13);
    assert_relative_eq!(d.mu[0], x[2], max_relative = 1e-13);
    // Φ = μ ∂f/∂q̇ and E = q̇·p − L.
    assert_relative_eq!(d.phi[0], x[2] * cd.j[(0, 0)], max_relative = 1e-13);
    assert_relative_eq!(d.energy, qd.dot(&ld.p) - ld.l, max_relative = 1e-14);
}

/// `L = ½|q̇|² − k θ` with the polar angle `θ = atan2(y, x)`, from a point of the `y` axis, where
/// the derivatives of num-dual's own `atan2` are NaN. The force `k (y, −x)/r²` has the torque
/// `−k`, so the angular momentum `ℓ = x ẏ − y ẋ` falls as `ℓ0 − k t`, and `∂ℓ/∂k = −t`.
struct AngleSpring {
    k: f64,
}

impl Lagrangian<2> for AngleSpring {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        qd.dot(qd) * 0.5 - q[1].atan2(q[0]) * R::parameter("k", self.k)
    }
}

#[test]
fn atan2_has_derivatives_on_the_axis_its_ratio_divides_by() -> Result<(), chetaev::Error> {
    let k = 0.3;
    for route in [Route::Graph, Route::Dual] {
        let (q0, qd0) = (SVector::from([0.0, 1.0]), SVector::from([1.0, 0.0]));
        let problem = Problem::unconstrained(AngleSpring { k }, 0.0, q0, qd0)?.with_route(route);
        let eq = problem.equations_at(0.0, q0.as_slice(), qd0.as_slice())?;
        assert_relative_eq!(eq.qdd[0], k, max_relative = 1e-15);
        assert!(eq.qdd[1].abs() < 1e-15, "{route:?}: {:?}", eq.qdd);

        let opts = Options::until(1.0)
            .tolerances(1e-12, 1e-12)
            .output_times(vec![0.25, 0.5, 1.0])
            .sensitivity(Seed::parameter("k"))
            .sensitivity_control(true);
        let sol = solve(&problem, Dop853::default(), &opts)?.ok()?;
        let s = sol.sensitivities.as_ref().expect("asked for");
        for i in 0..sol.len() {
            let (t, q, qd) = (sol.t[i], &sol.q[i], &sol.qd[i]);
            let (dq, dqd) = (s.q(i, 0), s.qd(i, 0));
            let l = q[0] * qd[1] - q[1] * qd[0];
            let dl = dq[0] * qd[1] + q[0] * dqd[1] - dq[1] * qd[0] - q[1] * dqd[0];
            assert!(
                (l - (-1.0 - k * t)).abs() < 1e-10,
                "{route:?} t = {t}: ℓ = {l}"
            );
            assert!((dl + t).abs() < 1e-9, "{route:?} t = {t}: ∂ℓ/∂k = {dl}");
        }
    }
    Ok(())
}
