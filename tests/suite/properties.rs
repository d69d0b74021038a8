//! Property tests over random constraint families and random consistent initial states:
//! with projection the residual stays within the projection's bound; forward then backward
//! integration returns to the start.

use chetaev::prelude::*;
use chetaev_suite::{distance, norm};
use proptest::prelude::*;

/// L = ½ Σ a_i q̇_i² + ε q̇_0 q_1 − ½ Σ k_i q_i² (a velocity-linear term and springs);
/// f_1 = Σ c_i q̇_i² − s² (an ellipsoidal speed: nonlinear in q̇),
/// f_2 = b·q̇ + β sin(q_0) q̇_2 − γ t (linear in q̇, position- and time-dependent; K = 2 only).
#[derive(Clone, Copy, Debug)]
struct Family {
    a: [f64; 3],
    eps: f64,
    k: [f64; 3],
    c: [f64; 3],
    s: f64,
    b: [f64; 3],
    beta: f64,
    gamma: f64,
}

impl Lagrangian<3> for Family {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 3>, qd: &SVector<R, 3>) -> R {
        let mut l = qd[0] * q[1] * self.eps;
        for i in 0..3 {
            l += qd[i] * qd[i] * (0.5 * self.a[i]) - q[i] * q[i] * (0.5 * self.k[i]);
        }
        l
    }
}

impl Family {
    fn speed<R: Real>(&self, qd: &SVector<R, 3>) -> R {
        (0..3).fold(R::zero(), |acc, i| acc + qd[i] * qd[i] * self.c[i]) - self.s * self.s
    }
}

impl Constraints<3, 1> for Family {
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 3>, qd: &SVector<R, 3>) -> SVector<R, 1> {
        SVector::from([self.speed(qd)])
    }
}

/// The same family with the second constraint.
#[derive(Clone, Copy, Debug)]
struct Family2(Family);

impl Lagrangian<3> for Family2 {
    fn lagrangian<R: Real>(&self, t: R, q: &SVector<R, 3>, qd: &SVector<R, 3>) -> R {
        self.0.lagrangian(t, q, qd)
    }
}

impl Constraints<3, 2> for Family2 {
    fn constraints<R: Real>(&self, t: R, q: &SVector<R, 3>, qd: &SVector<R, 3>) -> SVector<R, 2> {
        let f = &self.0;
        let lin = qd[0] * f.b[0] + qd[1] * f.b[1] + qd[2] * f.b[2] + q[0].sin() * qd[2] * f.beta
            - t * f.gamma;
        SVector::from([f.speed(qd), lin])
    }
}

fn family() -> impl Strategy<Value = Family> {
    (
        prop::array::uniform3(0.5f64..2.0),
        -0.5f64..0.5,
        prop::array::uniform3(0.0f64..2.0),
        prop::array::uniform3(0.5f64..2.0),
        0.5f64..2.0,
        prop::array::uniform3(-1.0f64..1.0),
        -0.5f64..0.5,
        -0.2f64..0.2,
    )
        .prop_map(|(a, eps, k, c, s, b, beta, gamma)| Family {
            a,
            eps,
            k,
            c,
            s,
            b,
            beta,
            gamma,
        })
}

fn state() -> impl Strategy<Value = ([f64; 3], [f64; 3])> {
    (
        prop::array::uniform3(-1.0f64..1.0),
        prop::array::uniform3(-1.0f64..1.0),
    )
        .prop_filter("a velocity direction", |(_, d)| {
            d.iter().map(|x| x * x).sum::<f64>() > 0.05
        })
}

/// The projection's bound on each constraint: |f_a| ≤ tol · |J_a|·|q̇|.
fn within_projection_bound<const K: usize>(
    sol: &Solution,
    model: &impl Constraints<3, K>,
    tol: f64,
) -> bool {
    (0..sol.len()).all(|i| {
        let t = sol.t[i];
        let q = SVector::<f64, 3>::from_column_slice(&sol.q[i]);
        let qd = SVector::<f64, 3>::from_column_slice(&sol.qd[i]);
        let cd = chetaev::equations::derivatives::constraint_derivatives::<_, f64, 3, K>(
            model, t, &q, &qd,
        );
        (0..K).all(|a| cd.f[a].abs() <= tol * cd.j.row(a).norm() * qd.norm())
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn projection_keeps_one_constraint_within_its_bound(f in family(), (q0, d) in state()) {
        let p = Problem::with_projected_velocity(f, 0.0, SVector::from(q0), SVector::from(d));
        prop_assume!(p.is_ok());
        let p = p.expect("checked");
        let proj = Projection::default();
        let sol = solve(&p, Dop853::default(), &Options::until(5.0).tolerances(1e-9, 1e-9).record(Record::State).project(proj)).expect("valid");
        prop_assert!(sol.is_success(), "{:?}", sol.status);
        prop_assert!(within_projection_bound(&sol, &p.model().0, proj.tol));
    }

    #[test]
    fn projection_keeps_two_constraints_within_their_bound(f in family(), (q0, d) in state()) {
        let p = Problem::with_projected_velocity(Family2(f), 0.0, SVector::from(q0), SVector::from(d));
        prop_assume!(p.is_ok());
        let p = p.expect("checked");
        let proj = Projection::default();
        let sol = solve(&p, Dop853::default(), &Options::until(3.0).tolerances(1e-9, 1e-9).record(Record::State).project(proj)).expect("valid");
        // A random family may reach a state where the two constraints become dependent; that must
        // be reported as such, never as a wrong motion.
        if let Some(e) = sol.error() {
            prop_assert!(matches!(e, Error::Singular { .. } | Error::DegenerateConstraint { .. } | Error::StepSizeTooSmall { .. }), "{e}");
        }
        prop_assert!(within_projection_bound(&sol, &p.model().0, proj.tol));
    }

    #[test]
    fn forward_then_backward_returns_to_the_start(f in family(), (q0, d) in state()) {
        let p = Problem::with_projected_velocity(f, 0.0, SVector::from(q0), SVector::from(d));
        prop_assume!(p.is_ok());
        let p = p.expect("checked");
        // The distance of the round trip's end from the start, in q and in q̇, at tolerance `tol`.
        let round_trip = |tol: f64| -> Result<(f64, f64), TestCaseError> {
            let o = |t_end: f64| Options::until(t_end).tolerances(tol, tol).record(Record::State).output_final();
            let fwd = solve(&p, Dop853::default(), &o(2.0)).expect("valid");
            prop_assert!(fwd.is_success());
            let (t1, q1, qd1) = fwd.last().expect("points");
            let back = Problem::new(f, t1, SVector::from_column_slice(q1), SVector::from_column_slice(qd1));
            prop_assert!(back.is_ok(), "the end state satisfies the constraint: {:?}", back.err());
            let sol = solve(&back.expect("checked"), Dop853::default(), &o(0.0)).expect("valid");
            prop_assert!(sol.is_success());
            let (t0, qb, qdb) = sol.last().expect("points");
            prop_assert_eq!(t0, 0.0);
            Ok((distance(qb, p.q0()), distance(qdb, p.qd0())))
        };
        // Two integrations of a smooth motion over 2 time units: the error is a modest multiple of
        // the tolerance, 1e3·tol, unless the motion contracts (these constraints need not
        // preserve phase-space volume: a velocity component decaying forward grows backward and
        // amplifies the forward run's error, by 4e3 on one motion found); then the round trip's
        // error must fall with the tolerance, as an error of the integration does.
        let (tol, fine) = (1e-11, 1e-13);
        let (eq, eqd) = round_trip(tol)?;
        let (fq, fqd) = round_trip(fine)?;
        for (e, e_fine, scale) in [(eq, fq, norm(p.q0())), (eqd, fqd, norm(p.qd0()))] {
            prop_assert!(
                e <= 1e3 * tol * (1.0 + scale) || e_fine <= e / 10.0,
                "at {tol:e}: {e:e}, at {fine:e}: {e_fine:e}"
            );
        }
    }
}
