//! The models of the study beyond the paper's own (which live in `uniform_projectile::model`):
//! a three-dimensional particle at constant speed, two particles under three constraints, the
//! classical projectile with a constraint that does nothing, and a chain of any static size for
//! the cost of one right-hand side.

use chetaev::prelude::*;
use uniform_projectile::closed_form::{uniform, Params};
use uniform_projectile::model::Projectile;

/// A particle of unit mass in homogeneous gravity `(0, 0, −g)`, held at constant speed `v0` by
/// `f = |q̇|² − v0² = 0`: `L = ½|q̇|² − g z`, coordinates `(x, y, z)`.
///
/// The motion stays in the vertical plane of the initial velocity and is the paper's uniform
/// motion (42.29)–(42.30) shifted in time ([`Launch3d::closed_form`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Particle3d {
    /// Gravitational acceleration.
    pub g: f64,
    /// The constant speed.
    pub v0: f64,
}

impl Lagrangian<3> for Particle3d {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 3>, qd: &SVector<R, 3>) -> R {
        qd.dot(qd) * 0.5 - q[2] * self.g
    }
}

impl Constraints<3, 1> for Particle3d {
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 3>, qd: &SVector<R, 3>) -> SVector<R, 1> {
        SVector::from([qd.dot(qd) - self.v0 * self.v0])
    }
}

/// The scene of a [`Particle3d`]: start at `(0, 0, h0)` with speed `v0` at elevation `theta`
/// (radians, upwards positive) and azimuth `phi` from the `x` axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Launch3d {
    /// The particle.
    pub particle: Particle3d,
    /// Initial height.
    pub h0: f64,
    /// Elevation of the initial velocity.
    pub theta: f64,
    /// Azimuth of the initial velocity.
    pub phi: f64,
}

impl Launch3d {
    /// The initial state `(q0, q̇0)`.
    pub fn initial_state(&self) -> (SVector<f64, 3>, SVector<f64, 3>) {
        let v0 = self.particle.v0;
        let (st, ct) = self.theta.sin_cos();
        let (sp, cp) = self.phi.sin_cos();
        (
            SVector::from([0.0, 0.0, self.h0]),
            SVector::from([v0 * ct * cp, v0 * ct * sp, v0 * st]),
        )
    }

    /// The problem, started at `t = 0`.
    pub fn problem(&self) -> Result<Problem<Particle3d, 3, 1>, chetaev::Error> {
        let (q0, qd0) = self.initial_state();
        Problem::new(self.particle, 0.0, q0, qd0)
    }

    /// The exact motion `(q(t), q̇(t))`.
    ///
    /// With `τ0 = −(v0/g) artanh(sin θ)`, the paper's solution at `τ = t + τ0` has the initial
    /// velocity `(v0 cos θ, v0 sin θ)` at `t = 0`: the horizontal distance travelled along the
    /// azimuth is `x_u(t + τ0) − x_u(τ0)` and the height `h0 + y_u(t + τ0) − y_u(τ0)`.
    pub fn closed_form(&self, t: f64) -> (SVector<f64, 3>, SVector<f64, 3>) {
        let p = Params {
            v0: self.particle.v0,
            g: self.particle.g,
            h0: 0.0,
            m: 1.0,
        };
        let tau0 = -(p.v0 / p.g) * self.theta.sin().atanh();
        let (a, b) = (uniform::position(&p, t + tau0), uniform::position(&p, tau0));
        let v = uniform::velocity(&p, t + tau0);
        let s = a[0] - b[0];
        let (sp, cp) = self.phi.sin_cos();
        (
            SVector::from([s * cp, s * sp, self.h0 + a[1] - b[1]]),
            SVector::from([v[0] * cp, v[0] * sp, v[1]]),
        )
    }
}

/// Two particles in gravity, masses `m1`, `m2`, coordinates `(x1, y1, x2, y2)`, joined by a
/// vertical spring `½ k (y1 − y2 − d)²`, under three constraints: each at its own constant speed,
/// `ẋ1² + ẏ1² − c1 = 0`, `ẋ2² + ẏ2² − c2 = 0` (nonlinear), and the same horizontal velocity,
/// `ẋ1 − ẋ2 = 0` (linear).
///
/// No closed form is known; the study compares with a reference computed at a much tighter
/// setting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwoRunners {
    /// Mass of the first particle.
    pub m1: f64,
    /// Mass of the second particle.
    pub m2: f64,
    /// Gravitational acceleration.
    pub g: f64,
    /// Spring constant.
    pub k: f64,
    /// Rest length of the spring.
    pub d: f64,
    /// Squared speed of the first particle.
    pub c1: f64,
    /// Squared speed of the second particle.
    pub c2: f64,
}

impl Lagrangian<4> for TwoRunners {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 4>, qd: &SVector<R, 4>) -> R {
        let t1 = (qd[0] * qd[0] + qd[1] * qd[1]) * (0.5 * self.m1);
        let t2 = (qd[2] * qd[2] + qd[3] * qd[3]) * (0.5 * self.m2);
        let stretch = q[1] - q[3] - self.d;
        t1 + t2
            - q[1] * (self.m1 * self.g)
            - q[3] * (self.m2 * self.g)
            - stretch * stretch * (0.5 * self.k)
    }
}

impl Constraints<4, 3> for TwoRunners {
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 4>, qd: &SVector<R, 4>) -> SVector<R, 3> {
        SVector::from([
            qd[0] * qd[0] + qd[1] * qd[1] - self.c1,
            qd[2] * qd[2] + qd[3] * qd[3] - self.c2,
            qd[0] - qd[2],
        ])
    }
}

impl TwoRunners {
    /// The scene of the study: `m1 = 1`, `m2 = 2`, `g = 9.81`, `k = 20`, `d = 1`, started at
    /// `(0, 10)` and `(0, 8)` with velocities `(3, −1)` and `(3, −2)` (so `c1 = 10`, `c2 = 13`).
    pub fn scene() -> Result<Problem<TwoRunners, 4, 3>, chetaev::Error> {
        let qd0 = SVector::from([3.0, -1.0, 3.0, -2.0]);
        let model = TwoRunners {
            m1: 1.0,
            m2: 2.0,
            g: 9.81,
            k: 20.0,
            d: 1.0,
            c1: qd0[0] * qd0[0] + qd0[1] * qd0[1],
            c2: qd0[2] * qd0[2] + qd0[3] * qd0[3],
        };
        Problem::new(model, 0.0, SVector::from([0.0, 10.0, 0.0, 8.0]), qd0)
    }
}

/// The classical projectile (42.2) with the linear constraint `ẋ − v0 = 0`, which the classical
/// motion satisfies anyway: the motion is the classical one and the multiplier vanishes. The
/// constrained path at the cost of a constraint that does nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SteadyHorizontal {
    /// The free particle.
    pub particle: Projectile,
    /// The horizontal speed.
    pub v0: f64,
}

impl Lagrangian<2> for SteadyHorizontal {
    fn lagrangian<R: Real>(&self, t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        self.particle.lagrangian(t, q, qd)
    }
}

impl Constraints<2, 1> for SteadyHorizontal {
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
        SVector::from([qd[0] - self.v0])
    }
}

/// The classical projectile of `p` through the constrained path ([`SteadyHorizontal`]).
pub fn steady_horizontal_problem(
    p: &Params,
) -> Result<Problem<SteadyHorizontal, 2, 1>, chetaev::Error> {
    let model = SteadyHorizontal {
        particle: Projectile { m: p.m, g: p.g },
        v0: p.v0,
    };
    Problem::new(
        model,
        0.0,
        SVector::from([0.0, p.h0]),
        SVector::from([p.v0, 0.0]),
    )
}

/// A chain of `N` unit masses on a line joined by anharmonic springs,
/// `L = ½ Σ q̇_i² − Σ_i (½ (q_{i+1} − q_i − 1)² + ¼ ε (q_{i+1} − q_i − 1)⁴)`, with `K ≤ N/2`
/// constraints holding the speed of the pairs `(2a, 2a+1)`: `q̇_{2a}² + q̇_{2a+1}² − c_a = 0`.
///
/// Static sizes throughout: the model API takes `N` and `K` as const generics, so each size is
/// its own type.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chain<const N: usize, const K: usize> {
    /// The quartic coefficient `ε`.
    pub epsilon: f64,
    /// The squared pair speeds `c_a`.
    pub c: [f64; K],
}

impl<const N: usize, const K: usize> Chain<N, K> {
    /// A consistent state: `q_i = i` stretched by `0.1 sin(i)`, `q̇_i = 0.3 + 0.2 cos(i)`, with
    /// `c_a` taken from it.
    pub fn at_rest_shape() -> (Self, SVector<f64, N>, SVector<f64, N>) {
        let q = SVector::<f64, N>::from_fn(|i, _| i as f64 + 0.1 * (i as f64).sin());
        let qd = SVector::<f64, N>::from_fn(|i, _| 0.3 + 0.2 * (i as f64).cos());
        let c = std::array::from_fn(|a| qd[2 * a] * qd[2 * a] + qd[2 * a + 1] * qd[2 * a + 1]);
        (Self { epsilon: 0.5, c }, q, qd)
    }
}

impl<const N: usize, const K: usize> Lagrangian<N> for Chain<N, K> {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, N>, qd: &SVector<R, N>) -> R {
        let mut l = qd.dot(qd) * 0.5;
        for i in 0..N.saturating_sub(1) {
            let s = q[i + 1] - q[i] - 1.0;
            let s2 = s * s;
            l -= s2 * 0.5 + s2 * s2 * (0.25 * self.epsilon);
        }
        l
    }
}

impl<const N: usize, const K: usize> Constraints<N, K> for Chain<N, K> {
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, N>, qd: &SVector<R, N>) -> SVector<R, K> {
        SVector::from_fn(|a, _| qd[2 * a] * qd[2 * a] + qd[2 * a + 1] * qd[2 * a + 1] - self.c[a])
    }
}

/// The chain of [`Chain`] with its sizes known only at run time: `n` masses, `k ≤ n/2` pair-speed
/// constraints, through [`chetaev::dynamic::DynModel`].
#[derive(Clone, Debug, PartialEq)]
pub struct DynChain {
    /// The quartic coefficient `ε`.
    pub epsilon: f64,
    /// The squared pair speeds `c_a`, one per constraint.
    pub c: Vec<f64>,
    /// The number of masses.
    pub n: usize,
}

impl DynChain {
    /// The state of [`Chain::at_rest_shape`] for `n` masses and `k ≤ n/2` constraints.
    pub fn at_rest_shape(n: usize, k: usize) -> (Self, Vec<f64>, Vec<f64>) {
        let q: Vec<f64> = (0..n).map(|i| i as f64 + 0.1 * (i as f64).sin()).collect();
        let qd: Vec<f64> = (0..n).map(|i| 0.3 + 0.2 * (i as f64).cos()).collect();
        let c = (0..k)
            .map(|a| qd[2 * a] * qd[2 * a] + qd[2 * a + 1] * qd[2 * a + 1])
            .collect();
        (Self { epsilon: 0.5, c, n }, q, qd)
    }
}

impl chetaev::dynamic::DynModel for DynChain {
    fn sizes(&self) -> (usize, usize) {
        (self.n, self.c.len())
    }
    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        let mut l = qd.iter().fold(R::zero(), |acc, v| acc + *v * *v) * 0.5;
        for i in 0..self.n.saturating_sub(1) {
            let s = q[i + 1] - q[i] - 1.0;
            let s2 = s * s;
            l -= s2 * 0.5 + s2 * s2 * (0.25 * self.epsilon);
        }
        l
    }
    fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
        for (a, fa) in f.iter_mut().enumerate() {
            *fa = qd[2 * a] * qd[2 * a] + qd[2 * a + 1] * qd[2 * a + 1] - self.c[a];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_3d_closed_form_starts_at_the_initial_state_and_keeps_the_speed() {
        let launch = Launch3d {
            particle: Particle3d { g: 9.81, v0: 10.0 },
            h0: 5.0,
            theta: 0.7,
            phi: 0.5,
        };
        let (q0, qd0) = launch.initial_state();
        let (q, qd) = launch.closed_form(0.0);
        assert!((q - q0).norm() < 1e-14);
        assert!((qd - qd0).norm() < 1e-13);
        for t in [0.3, 1.0, 2.5] {
            let (_, qd) = launch.closed_form(t);
            assert!((qd.norm() - 10.0).abs() < 1e-13);
        }
    }

    #[test]
    fn the_run_time_chain_has_the_static_chain_dynamics() {
        use chetaev::equations::{dynamics, saddle::SaddleWorkspace};
        let (chain, q, qd) = Chain::<6, 3>::at_rest_shape();
        let d = dynamics::<_, f64, 6, 3>(&chain, &mut SaddleWorkspace::default(), 0.0, &q, &qd)
            .expect("regular");
        let (dyn_chain, qv, qdv) = DynChain::at_rest_shape(6, 3);
        let e =
            chetaev::dynamic::dynamics(&dyn_chain, &mut SaddleWorkspace::default(), 0.0, &qv, &qdv)
                .expect("regular");
        for i in 0..6 {
            assert!(
                (d.qdd[i] - e.qdd[i]).abs() < 1e-13,
                "{i}: {} {}",
                d.qdd[i],
                e.qdd[i]
            );
        }
    }

    #[test]
    fn the_chain_state_is_consistent() {
        let (chain, q, qd) = Chain::<6, 3>::at_rest_shape();
        assert!(Problem::new(chain, 0.0, q, qd).is_ok());
    }
}
