//! Rows of a solution as fixed-size nalgebra views, for models whose sizes are known at compile
//! time.

use chetaev::prelude::*;

/// The paper's uniform projectile (42.2), (42.23).
struct Uniform {
    m: f64,
    g: f64,
    v0: f64,
}

impl Lagrangian<2> for Uniform {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        qd.dot(qd) * (0.5 * self.m) - q[1] * (self.g * self.m)
    }
}

impl Constraints<2, 1> for Uniform {
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
        SVector::from([qd.dot(qd) - self.v0 * self.v0])
    }
}

fn solution(record: Record) -> Result<Solution, Error> {
    let (m, g, v0) = (1.0, 10.0, 10.0);
    let problem = Problem::new(
        Uniform { m, g, v0 },
        0.0,
        SVector::from([0.0, 5.0]),
        SVector::from([v0, 0.0]),
    )?;
    solve(
        &problem,
        Dop853::default(),
        &Options::until(0.5).tolerances(1e-12, 1e-12).record(record),
    )?
    .ok()
}

#[test]
fn a_row_read_as_a_fixed_size_view_is_the_recorded_row() -> Result<(), Error> {
    let sol = solution(Record::Dynamics)?;
    assert!(sol.len() > 2);
    for i in 0..sol.len() {
        let (q, qd) = (sol.q_row::<2>(i), sol.qd_row::<2>(i));
        let (q, qd) = (q.expect("2 coordinates"), qd.expect("2 velocities"));
        assert_eq!(q.as_slice(), &sol.q[i]);
        assert_eq!(qd.as_slice(), &sol.qd[i]);
        // It computes as an SVector: |q̇| = v0 along the motion, Φ = 2μ q̇ (J = 2q̇ᵀ).
        assert!((qd.norm() - 10.0).abs() < 1e-9, "{}", qd.norm());
        let mu = sol.mu_row::<1>(i).expect("1 constraint")[0];
        let phi: SVector<f64, 2> = sol.phi_row::<2>(i).expect("recorded").into_owned();
        assert!((phi - qd * (2.0 * mu)).norm() < 1e-12 * (1.0 + phi.norm()));
        let qdd = sol.qdd_row::<2>(i).expect("recorded");
        assert_eq!(qdd.as_slice(), &sol.qdd[i]);
    }
    let views: Vec<SVector<f64, 2>> = sol
        .q
        .fixed_iter::<2>()
        .expect("width 2")
        .map(|v| v.into_owned())
        .collect();
    assert_eq!(views.len(), sol.len());
    assert_eq!(views[1].as_slice(), &sol.q[1]);
    Ok(())
}

#[test]
fn a_row_of_another_size_or_past_the_end_or_not_recorded_is_none() -> Result<(), Error> {
    let sol = solution(Record::State)?;
    assert!(sol.q_row::<3>(0).is_none());
    assert!(sol.q_row::<1>(0).is_none());
    assert!(sol.q_row::<2>(sol.len()).is_none());
    assert!(sol.q.fixed_iter::<3>().is_none());
    // μ is not recorded at Record::State.
    assert!(sol.mu_row::<1>(0).is_none());
    assert!(sol.q_row::<2>(0).is_some());
    Ok(())
}
