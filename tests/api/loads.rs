//! Loads on points and torques on bodies, mapped through their partial velocities, against the
//! same pendulum with its generalised forces written out, and against its equilibrium.

use chetaev::loads::{body_torque, point_load, AngularVelocity, PointPosition};
use chetaev::prelude::*;

/// A pendulum of mass `m` on a rod of length `l` (angle θ from the downward vertical), damped by
/// `D = ½ c θ̇²`, with a horizontal force `f` at the bob and a torque `tau` on the rod. `how`
/// chooses how the loads are stated.
struct Pendulum {
    m: f64,
    g: f64,
    l: f64,
    c: f64,
    f: f64,
    tau: f64,
    how: How,
}

#[derive(Clone, Copy)]
enum How {
    /// `Q = f l cos θ + tau`, written by hand.
    Explicit,
    /// A point load and a torque in the plane (`r` of 2 components, `ω` of 1).
    Plane,
    /// The same in space (`r` and `ω` of 3 components, `z` out of the plane).
    Space,
}

struct Bob {
    l: f64,
}

impl PointPosition<1, 2> for Bob {
    fn position<S: Real>(&self, _t: S, q: &SVector<S, 1>) -> SVector<S, 2> {
        SVector::from([q[0].sin() * self.l, -q[0].cos() * self.l])
    }
}

impl PointPosition<1, 3> for Bob {
    fn position<S: Real>(&self, _t: S, q: &SVector<S, 1>) -> SVector<S, 3> {
        SVector::from([q[0].sin() * self.l, -q[0].cos() * self.l, S::zero()])
    }
}

struct Rod;

impl AngularVelocity<1, 1> for Rod {
    fn angular_velocity<S: Real>(
        &self,
        _t: S,
        _q: &SVector<S, 1>,
        qd: &SVector<S, 1>,
    ) -> SVector<S, 1> {
        SVector::from([qd[0]])
    }
}

impl AngularVelocity<1, 3> for Rod {
    fn angular_velocity<S: Real>(
        &self,
        _t: S,
        _q: &SVector<S, 1>,
        qd: &SVector<S, 1>,
    ) -> SVector<S, 3> {
        SVector::from([S::zero(), S::zero(), qd[0]])
    }
}

impl Lagrangian<1> for Pendulum {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 1>, qd: &SVector<R, 1>) -> R {
        qd[0] * qd[0] * (0.5 * self.m * self.l * self.l) + q[0].cos() * (self.m * self.g * self.l)
    }

    fn dissipation<R: Real>(&self, _t: R, _q: &SVector<R, 1>, qd: &SVector<R, 1>) -> Option<R> {
        Some(qd[0] * qd[0] * (0.5 * self.c))
    }

    fn forces<R: Real>(
        &self,
        t: R,
        q: &SVector<R, 1>,
        qd: &SVector<R, 1>,
    ) -> Option<SVector<R, 1>> {
        let (f, tau) = (R::from(self.f), R::from(self.tau));
        let bob = Bob { l: self.l };
        Some(match self.how {
            How::Explicit => SVector::from([q[0].cos() * self.l * f + tau]),
            How::Plane => {
                point_load(&bob, t, q, &SVector::from([f, R::zero()]))
                    + body_torque(&Rod, t, q, qd, &SVector::from([tau]))
            }
            How::Space => {
                point_load(&bob, t, q, &SVector::from([f, R::zero(), R::zero()]))
                    + body_torque(&Rod, t, q, qd, &SVector::from([R::zero(), R::zero(), tau]))
            }
        })
    }
}

impl Constraints<1, 0> for Pendulum {
    fn constraints<R: Real>(
        &self,
        _t: R,
        _q: &SVector<R, 1>,
        _qd: &SVector<R, 1>,
    ) -> SVector<R, 0> {
        SVector::zeros()
    }
}

fn run(how: How, f: f64, tau: f64, t_end: f64) -> Result<Solution, Error> {
    let model = Pendulum {
        m: 1.5,
        g: 9.81,
        l: 2.0,
        c: 3.0,
        f,
        tau,
        how,
    };
    let problem = Problem::new(model, 0.0, SVector::from([0.1]), SVector::from([0.0]))?;
    solve(
        &problem,
        Dop853::default(),
        &Options::until(t_end).tolerances(1e-12, 1e-12),
    )?
    .ok()
}

#[test]
fn loads_mapped_through_partial_velocities_agree_with_the_generalised_forces_written_out(
) -> Result<(), Error> {
    let explicit = run(How::Explicit, 4.0, 1.5, 5.0)?;
    for how in [How::Plane, How::Space] {
        let loads = run(how, 4.0, 1.5, 5.0)?;
        // The same steps, and the same motion to rounding.
        assert_eq!(loads.len(), explicit.len());
        for i in 0..loads.len() {
            assert_eq!(loads.t[i], explicit.t[i]);
            let (a, b) = (&loads.q[i], &explicit.q[i]);
            assert!(
                (a[0] - b[0]).abs() <= 1e-14 * (1.0 + b[0].abs()),
                "{a:?} {b:?}"
            );
            assert!((loads.qd[i][0] - explicit.qd[i][0]).abs() <= 1e-13);
        }
        // The work of the loads is recorded as that of any generalised force.
        let (w, v) = (loads.work_forces.last(), explicit.work_forces.last());
        let (w, v) = (
            w.copied().unwrap_or(f64::NAN),
            v.copied().unwrap_or(f64::NAN),
        );
        assert!((w - v).abs() <= 1e-12 * v.abs() && v.abs() > 1.0, "{w} {v}");
    }
    Ok(())
}

#[test]
fn a_pendulum_pushed_sideways_at_the_bob_settles_at_atan_f_over_m_g() -> Result<(), Error> {
    let (m, g, f) = (1.5, 9.81, 4.0);
    for how in [How::Plane, How::Space] {
        let sol = run(how, f, 0.0, 200.0)?;
        let (_, q, qd) = sol.last().expect("recorded");
        let expected = (f / (m * g)).atan();
        assert!((q[0] - expected).abs() < 1e-9, "{} {expected}", q[0]);
        assert!(qd[0].abs() < 1e-9);
    }
    Ok(())
}

#[test]
fn a_torque_on_the_rod_holds_it_at_asin_tau_over_m_g_l() -> Result<(), Error> {
    let (m, g, l, tau) = (1.5, 9.81, 2.0, 7.0);
    for how in [How::Plane, How::Space] {
        let sol = run(how, 0.0, tau, 200.0)?;
        let (_, q, _) = sol.last().expect("recorded");
        let expected = (tau / (m * g * l)).asin();
        assert!((q[0] - expected).abs() < 1e-9, "{} {expected}", q[0]);
    }
    Ok(())
}
