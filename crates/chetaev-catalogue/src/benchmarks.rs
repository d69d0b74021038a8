//! The models the performance study of `chetaev` runs (crate `chetaev-bench`: the work-precision
//! study and the benchmarks), beyond the paper's own (`uniform_projectile::model`) and the classic
//! systems of this catalogue.
//!
//! | model | `N` | `K` | constraints | reference |
//! |---|---|---|---|---|
//! | [`Particle3d`], started by [`Launch3d`] | 3 | 1 | quadratic: constant speed | closed form: the paper's uniform motion shifted in time and turned to the azimuth ([`Launch3d::closed_form`]) |
//! | [`TwoRunners`] | 4 | 3 | two quadratic, one linear | none known (the study computes one at a much tighter setting) |
//! | [`SteadyHorizontal`] | 2 | 1 | linear, satisfied by the free motion | closed form: the classical projectile, `μ = 0` ([`SteadyHorizontal::closed_form`]) |
//! | [`Chain`] | any, static | `K ≤ N/2`, static | quadratic: speeds of pairs | none: it measures the cost of one right-hand side |
//! | [`DynChain`] | any, at run time | `k ≤ n/2`, at run time | the same | the same equations as [`Chain`] |
//! | [`Gas`] | `3p`, at run time | 1 | quadratic: constant kinetic energy of all particles | none: it measures how the cost grows with one constraint on every velocity |

use std::f64::consts::{FRAC_PI_2, LN_2};

use chetaev::model::Fixed;
use chetaev::prelude::*;

use crate::error::{check, finite, positive, Error};
use crate::special::gd;

/// A particle of unit mass in homogeneous gravity `(0, 0, −g)`, held at constant speed `v0`,
/// coordinates `(x, y, z)`:
///
/// ```text
/// L = ½ |q̇|² − g z,      f = |q̇|² − v0² = 0.
/// ```
///
/// The motion stays in the vertical plane of the initial velocity and is the uniform motion of
/// Swaczyna and Volný, (42.29)–(42.30), shifted in time; see [`Launch3d`].
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

/// A [`Particle3d`] started at `(0, 0, h0)` with speed `v0` at elevation `theta` (radians,
/// upwards positive, `|theta| < π/2`) and azimuth `phi` from the `x` axis, at `t = 0`.
///
/// **Reference** (closed form). With `ℓ = v0²/g`, `u0 = −artanh(sin θ)` and `u = u0 + g t / v0`,
/// the paper's uniform motion (42.29)–(42.30) at the dimensionless time `u` has the initial
/// velocity `(v0 cos θ, v0 sin θ)` at `t = 0`; along the azimuth it travels
///
/// ```text
/// s(t) = ℓ (gd u − gd u0),                 ṡ(t) = v0 sech u,
/// z(t) = h0 − ℓ (ln cosh u − ln cosh u0),  ż(t) = −v0 tanh u,
/// ```
///
/// and `(x, y) = s (cos φ, sin φ)`. Source: Swaczyna and Volný, *Uniform horizontal projectile
/// motion*, (42.29)–(42.30).
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

    /// The problem, started at `t = 0`. Needs `g > 0`, `v0 > 0`, finite `h0` and `phi`, and
    /// `|theta| < π/2` (straight up or down the motion is a fall along a line at speed `v0`, where
    /// the closed form is not defined).
    pub fn problem(&self) -> Result<Problem<Fixed<Particle3d, 3, 1>>, Error> {
        positive("g", self.particle.g)?;
        positive("v0", self.particle.v0)?;
        finite("h0", self.h0)?;
        finite("phi", self.phi)?;
        check(
            "theta",
            self.theta,
            |t| t.abs() < FRAC_PI_2,
            "the elevation must lie in (−π/2, π/2)",
        )?;
        let (q0, qd0) = self.initial_state();
        Ok(Problem::new(self.particle, 0.0, q0, qd0)?)
    }

    /// The exact motion `(q(t), q̇(t))` (see the type's documentation), for parameters that
    /// [`Launch3d::problem`] accepts.
    pub fn closed_form(&self, t: f64) -> (SVector<f64, 3>, SVector<f64, 3>) {
        let Particle3d { g, v0 } = self.particle;
        let l = v0 * v0 / g;
        let u0 = -self.theta.sin().atanh();
        let u = u0 + g * t / v0;
        let s = l * (gd(u) - gd(u0));
        let z = self.h0 - l * (ln_cosh(u) - ln_cosh(u0));
        let (sd, zd) = (v0 * sech(u), -v0 * u.tanh());
        let (sp, cp) = self.phi.sin_cos();
        (
            SVector::from([s * cp, s * sp, z]),
            SVector::from([sd * cp, sd * sp, zd]),
        )
    }
}

/// `ln cosh u` without overflow or cancellation: `ln1p(2 sinh²(u/2))` for `|u| < 1`,
/// `|u| − ln 2 + ln1p(e^(−2|u|))` beyond.
fn ln_cosh(u: f64) -> f64 {
    let a = u.abs();
    if a < 1.0 {
        let s = (0.5 * u).sinh();
        (2.0 * s * s).ln_1p()
    } else {
        a - LN_2 + (-2.0 * a).exp().ln_1p()
    }
}

/// `sech u = 2 e^(−|u|) / (1 + e^(−2|u|))`, which underflows gracefully instead of overflowing.
fn sech(u: f64) -> f64 {
    let e = (-u.abs()).exp();
    2.0 * e / (1.0 + e * e)
}

/// Two particles in gravity, masses `m1`, `m2`, coordinates `(x1, y1, x2, y2)`, joined by a
/// vertical spring, under three constraints: each at its own constant speed (nonlinear) and both
/// with the same horizontal velocity (linear):
///
/// ```text
/// L = ½ m1 (ẋ1² + ẏ1²) + ½ m2 (ẋ2² + ẏ2²) − m1 g y1 − m2 g y2 − ½ k (y1 − y2 − d)²,
/// f = (ẋ1² + ẏ1² − c1,  ẋ2² + ẏ2² − c2,  ẋ1 − ẋ2) = 0.
/// ```
///
/// **Reference**: no closed form is known; the work-precision study compares with an end state
/// computed at a much tighter setting and checked against a second method.
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
    /// The problem of the study: `m1 = 1`, `m2 = 2`, `g = 9.81`, `k = 20`, `d = 1`, started at
    /// `t = 0` at `(0, 10)` and `(0, 8)` with velocities `(3, −1)` and `(3, −2)` (so `c1 = 10`,
    /// `c2 = 13`).
    pub fn problem() -> Result<Problem<Fixed<TwoRunners, 4, 3>>, Error> {
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
        Ok(Problem::new(
            model,
            0.0,
            SVector::from([0.0, 10.0, 0.0, 8.0]),
            qd0,
        )?)
    }
}

/// The classical projectile of mass `m`, Lagrangian (42.2) of Swaczyna and Volný, with the linear
/// constraint `ẋ − v0 = 0`, which the classical motion satisfies anyway, coordinates `(x, y)`:
///
/// ```text
/// L = ½ m (ẋ² + ẏ²) − m g y,      f = ẋ − v0 = 0.
/// ```
///
/// The constrained path at the cost of a constraint that does nothing: the motion is the
/// classical one and the multiplier vanishes ([`SteadyHorizontal::closed_form`]). `L` is written
/// as in `uniform_projectile::model::Projectile`, so the two differ only by the constraint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SteadyHorizontal {
    /// Mass.
    pub m: f64,
    /// Gravitational acceleration.
    pub g: f64,
    /// The horizontal speed.
    pub v0: f64,
}

impl Lagrangian<2> for SteadyHorizontal {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        qd.dot(qd) * (0.5 * self.m) - q[1] * (self.m * self.g)
    }
}

impl Constraints<2, 1> for SteadyHorizontal {
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
        SVector::from([qd[0] - self.v0])
    }
}

impl SteadyHorizontal {
    /// The problem from `(0, h0)` with velocity `(v0, 0)` at `t = 0`. Needs `m > 0` and finite
    /// `g`, `v0`, `h0`.
    pub fn problem(&self, h0: f64) -> Result<Problem<Fixed<SteadyHorizontal, 2, 1>>, Error> {
        positive("m", self.m)?;
        finite("g", self.g)?;
        finite("v0", self.v0)?;
        finite("h0", h0)?;
        Ok(Problem::new(
            *self,
            0.0,
            SVector::from([0.0, h0]),
            SVector::from([self.v0, 0.0]),
        )?)
    }

    /// The exact motion from [`SteadyHorizontal::problem`]`(h0)`: the classical projectile
    /// (42.4)–(42.5), `x = v0 t`, `y = h0 − g t²/2`, `ẋ = v0`, `ẏ = −g t`, with `μ = 0`.
    pub fn closed_form(&self, h0: f64, t: f64) -> (SVector<f64, 2>, SVector<f64, 2>) {
        (
            SVector::from([self.v0 * t, h0 - 0.5 * self.g * t * t]),
            SVector::from([self.v0, -self.g * t]),
        )
    }
}

/// A chain of `N` unit masses on a line joined by anharmonic springs, with `K ≤ N/2` constraints
/// holding the speed of the pairs of masses `(2a, 2a + 1)`:
///
/// ```text
/// L = ½ Σ_i q̇_i² − Σ_{i<N−1} (½ s_i² + ¼ ε s_i⁴),   s_i = q_{i+1} − q_i − 1,
/// f_a = q̇_{2a}² + q̇_{2a+1}² − c_a = 0,   a < K.
/// ```
///
/// Static sizes: every `(N, K)` is its own type. **Reference**: none; the chain measures how the
/// cost of one right-hand side grows with `N` and `K`. [`DynChain`] is the same chain with its
/// sizes known at run time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chain<const N: usize, const K: usize> {
    /// The quartic coefficient `ε`.
    pub epsilon: f64,
    /// The squared pair speeds `c_a`.
    pub c: [f64; K],
}

/// The state of the benchmark chains: `q_i = i + 0.1 sin i`, `q̇_i = 0.3 + 0.2 cos i`.
fn chain_state(i: usize) -> (f64, f64) {
    let x = i as f64;
    (x + 0.1 * x.sin(), 0.3 + 0.2 * x.cos())
}

/// `ε` of the benchmark chains.
const CHAIN_EPSILON: f64 = 0.5;

impl<const N: usize, const K: usize> Chain<N, K> {
    /// The chain of the benchmarks with a consistent state: `ε = 0.5`, `q_i = i + 0.1 sin i`,
    /// `q̇_i = 0.3 + 0.2 cos i`, and the pair speeds `c_a` taken from that state.
    pub fn standard() -> (Self, SVector<f64, N>, SVector<f64, N>) {
        const { assert!(2 * K <= N, "Chain<N, K> needs K ≤ N/2") };
        let q = SVector::<f64, N>::from_fn(|i, _| chain_state(i).0);
        let qd = SVector::<f64, N>::from_fn(|i, _| chain_state(i).1);
        let c = std::array::from_fn(|a| qd[2 * a] * qd[2 * a] + qd[2 * a + 1] * qd[2 * a + 1]);
        (
            Self {
                epsilon: CHAIN_EPSILON,
                c,
            },
            q,
            qd,
        )
    }

    /// The problem of [`Chain::standard`], started at `t = 0`.
    pub fn problem() -> Result<Problem<Fixed<Self, N, K>>, Error> {
        let (model, q, qd) = Self::standard();
        Ok(Problem::new(model, 0.0, q, qd)?)
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
        const { assert!(2 * K <= N, "Chain<N, K> needs K ≤ N/2") };
        SVector::from_fn(|a, _| qd[2 * a] * qd[2 * a] + qd[2 * a + 1] * qd[2 * a + 1] - self.c[a])
    }
}

/// The chain of [`Chain`] with its sizes known only at run time: `n` masses and `k ≤ n/2`
/// pair-speed constraints, a [`DynModel`] whose problem is built with [`Problem::dynamic`].
/// Built by [`DynChain::standard`], which checks the sizes.
#[derive(Clone, Debug, PartialEq)]
pub struct DynChain {
    epsilon: f64,
    c: Vec<f64>,
    n: usize,
}

impl DynChain {
    /// The state of [`Chain::standard`] for `n` masses and `k` constraints: the model and
    /// `(q, q̇)`. Fails unless `1 ≤ n` and `2k ≤ n` (constraint `a` holds the masses `2a` and
    /// `2a + 1`).
    pub fn standard(n: usize, k: usize) -> Result<(Self, Vec<f64>, Vec<f64>), Error> {
        check(
            "n",
            n as f64,
            |n| n >= 1.0,
            "the chain needs at least one mass",
        )?;
        if 2 * k > n {
            return Err(Error::InvalidParameter {
                name: "k",
                value: k as f64,
                hint:
                    "at most n/2 constraints: constraint a holds the speed of masses 2a and 2a + 1",
            });
        }
        let (q, qd): (Vec<f64>, Vec<f64>) = (0..n).map(chain_state).unzip();
        let c = (0..k)
            .map(|a| qd[2 * a] * qd[2 * a] + qd[2 * a + 1] * qd[2 * a + 1])
            .collect();
        Ok((
            Self {
                epsilon: CHAIN_EPSILON,
                c,
                n,
            },
            q,
            qd,
        ))
    }

    /// The problem of [`DynChain::standard`]`(n, k)`, started at `t = 0`.
    pub fn problem(n: usize, k: usize) -> Result<Problem<DynChain>, Error> {
        let (model, q, qd) = Self::standard(n, k)?;
        Ok(Problem::dynamic(model, 0.0, q, qd)?)
    }

    /// The quartic coefficient `ε`.
    pub fn epsilon(&self) -> f64 {
        self.epsilon
    }

    /// The squared pair speeds `c_a`, one per constraint.
    pub fn speeds(&self) -> &[f64] {
        &self.c
    }
}

impl DynModel for DynChain {
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
        for (a, (fa, c)) in f.iter_mut().zip(&self.c).enumerate() {
            *fa = qd[2 * a] * qd[2 * a] + qd[2 * a + 1] * qd[2 * a + 1] - *c;
        }
    }
}

/// `p = n / 3` unit-mass particles in 3D in harmonic wells, held at constant total kinetic energy
/// `K` (an isokinetic thermostat), a [`DynModel`]:
///
/// ```text
/// L = ½ |q̇|² − ½ |q|²,      f = |q̇|² − 2K = 0.
/// ```
///
/// Its one constraint reaches every velocity, so the Jacobian of the reduced equations has a row
/// reached by every column: no two columns can share a pass. Built by [`Gas::standard`].
#[derive(Clone, Debug, PartialEq)]
pub struct Gas {
    n: usize,
    /// `2K = |q̇0|²`.
    two_k: f64,
}

impl Gas {
    /// The gas with `n` coordinates at a fixed, irregular state: the model and `(q, q̇)`, with
    /// `2K = |q̇|²`. Fails unless `n` is a positive multiple of 3.
    pub fn standard(n: usize) -> Result<(Self, Vec<f64>, Vec<f64>), Error> {
        if n == 0 || n % 3 != 0 {
            return Err(Error::InvalidParameter {
                name: "n",
                value: n as f64,
                hint: "the gas has three coordinates per particle: give a positive multiple of 3",
            });
        }
        let q: Vec<f64> = (0..n).map(|i| (0.7 * i as f64).sin()).collect();
        let qd: Vec<f64> = (0..n).map(|i| 0.4 + 0.3 * (1.3 * i as f64).cos()).collect();
        let two_k = qd.iter().map(|v| v * v).sum();
        Ok((Self { n, two_k }, q, qd))
    }

    /// The problem of [`Gas::standard`]`(n)`, started at `t = 0`.
    pub fn problem(n: usize) -> Result<Problem<Gas>, Error> {
        let (model, q, qd) = Self::standard(n)?;
        Ok(Problem::dynamic(model, 0.0, q, qd)?)
    }

    /// Twice the kinetic energy the constraint holds, `2K`.
    pub fn two_k(&self) -> f64 {
        self.two_k
    }
}

impl DynModel for Gas {
    fn sizes(&self) -> (usize, usize) {
        (self.n, 1)
    }

    fn lagrangian<R: Real>(&self, _t: R, q: &[R], qd: &[R]) -> R {
        let kinetic = qd.iter().fold(R::zero(), |acc, v| acc + *v * *v);
        let potential = q.iter().fold(R::zero(), |acc, x| acc + *x * *x);
        (kinetic - potential) * 0.5
    }

    fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
        f[0] = qd.iter().fold(R::zero(), |acc, v| acc + *v * *v) - self.two_k;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use chetaev::equations::{evaluate, Workspace};
    use uniform_projectile::closed_form::{uniform, Params};

    fn launch() -> Launch3d {
        Launch3d {
            particle: Particle3d { g: 9.81, v0: 10.0 },
            h0: 5.0,
            theta: 0.7,
            phi: 0.5,
        }
    }

    #[test]
    fn the_3d_closed_form_starts_at_the_initial_state_and_keeps_the_speed() {
        let launch = launch();
        let (q0, qd0) = launch.initial_state();
        let (q, qd) = launch.closed_form(0.0);
        assert!((q - q0).norm() < 1e-14);
        assert!((qd - qd0).norm() < 1e-13);
        for t in [0.3, 1.0, 2.5] {
            let (_, qd) = launch.closed_form(t);
            assert!((qd.norm() - 10.0).abs() < 1e-13);
        }
    }

    /// The closed form is the paper's (uniform_projectile's) shifted by `τ0 = −(v0/g) artanh(sin θ)`.
    #[test]
    fn the_3d_closed_form_is_the_papers_motion_shifted_and_turned() {
        let launch = launch();
        let p = Params {
            v0: 10.0,
            g: 9.81,
            h0: 0.0,
            m: 1.0,
        };
        let tau0 = -(p.v0 / p.g) * launch.theta.sin().atanh();
        let b = uniform::position(&p, tau0);
        let (sp, cp) = launch.phi.sin_cos();
        for t in [0.0, 0.4, 1.0, 2.0, 3.5] {
            let (a, v) = (
                uniform::position(&p, t + tau0),
                uniform::velocity(&p, t + tau0),
            );
            let s = a[0] - b[0];
            let expected_q = [s * cp, s * sp, launch.h0 + a[1] - b[1]];
            let expected_qd = [v[0] * cp, v[0] * sp, v[1]];
            let (q, qd) = launch.closed_form(t);
            for i in 0..3 {
                assert!((q[i] - expected_q[i]).abs() < 1e-13, "{t} q{i}");
                assert!((qd[i] - expected_qd[i]).abs() < 1e-13, "{t} qd{i}");
            }
        }
    }

    #[test]
    fn the_3d_motion_follows_the_closed_form() {
        let launch = launch();
        let problem = launch.problem().expect("valid");
        let tol = 1e-11;
        let sol = solve(
            &problem,
            Dop853::default(),
            &Options::until(2.0).tolerances(tol, tol),
        )
        .expect("runs")
        .ok()
        .expect("integrates");
        // rtol times the size of the motion (about 10), times a growth of the global error over
        // the local one of at most 100.
        let bound = 1e3 * tol;
        for (i, &t) in sol.t.iter().enumerate() {
            let (q, qd) = launch.closed_form(t);
            for j in 0..3 {
                assert!((sol.q[i][j] - q[j]).abs() < bound, "{t} q{j}");
                assert!((sol.qd[i][j] - qd[j]).abs() < bound, "{t} qd{j}");
            }
        }
    }

    #[test]
    fn a_vertical_launch_is_refused() {
        let mut launch = launch();
        launch.theta = FRAC_PI_2;
        assert!(matches!(
            launch.problem(),
            Err(Error::InvalidParameter { name: "theta", .. })
        ));
    }

    #[test]
    fn the_steady_horizontal_motion_is_classical_with_no_multiplier() {
        let model = SteadyHorizontal {
            m: 1.0,
            g: 10.0,
            v0: 10.0,
        };
        let problem = model.problem(5.0).expect("valid");
        let tol = 1e-12;
        let sol = solve(
            &problem,
            Dopri5::default(),
            &Options::until(1.0).tolerances(tol, tol),
        )
        .expect("runs")
        .ok()
        .expect("integrates");
        for (i, &t) in sol.t.iter().enumerate() {
            let (q, qd) = model.closed_form(5.0, t);
            assert!((sol.q[i][0] - q[0]).abs() < 1e-9 && (sol.q[i][1] - q[1]).abs() < 1e-9);
            assert!((sol.qd[i][0] - qd[0]).abs() < 1e-9 && (sol.qd[i][1] - qd[1]).abs() < 1e-9);
            assert!(sol.mu[i][0].abs() < 1e-9, "μ = {} at {t}", sol.mu[i][0]);
        }
    }

    #[test]
    fn the_two_runners_start_consistent() {
        let problem = TwoRunners::problem().expect("consistent");
        assert_eq!(problem.sizes(), (4, 3));
    }

    #[test]
    fn the_run_time_chain_has_the_static_chain_dynamics() {
        let static_problem = Chain::<6, 3>::problem().expect("consistent");
        let model = static_problem.model();
        let d = evaluate(
            model,
            &mut Workspace::for_model(model),
            0.0,
            static_problem.q0(),
            static_problem.qd0(),
        )
        .expect("regular")
        .clone();
        let dyn_problem = DynChain::problem(6, 3).expect("consistent");
        assert_eq!(dyn_problem.q0(), static_problem.q0());
        assert_eq!(dyn_problem.qd0(), static_problem.qd0());
        let model = dyn_problem.model();
        let e = evaluate(
            model,
            &mut Workspace::for_model(model),
            0.0,
            dyn_problem.q0(),
            dyn_problem.qd0(),
        )
        .expect("regular")
        .clone();
        for i in 0..6 {
            assert!(
                (d.qdd[i] - e.qdd[i]).abs() < 1e-13,
                "{i}: {} {}",
                d.qdd[i],
                e.qdd[i]
            );
        }
        for a in 0..3 {
            assert!((d.mu[a] - e.mu[a]).abs() < 1e-13, "{a}");
        }
    }

    #[test]
    fn a_run_time_chain_with_too_many_constraints_is_refused() {
        assert!(DynChain::standard(6, 3).is_ok());
        assert!(matches!(
            DynChain::standard(5, 3),
            Err(Error::InvalidParameter { name: "k", .. })
        ));
        assert!(matches!(
            DynChain::standard(0, 0),
            Err(Error::InvalidParameter { name: "n", .. })
        ));
    }

    /// The gas's state satisfies its constraint, and its equations are those of the thermostat
    /// written out: `q̈ = F − α q̇` with `F = −q`, `α = F·q̇ / |q̇|²`, and in the Newton form
    /// (`q̈ = F + 2 μ q̇`) `μ = −α / 2`.
    #[test]
    fn the_gas_keeps_its_kinetic_energy_with_the_thermostat_written_out() {
        for n in [3, 30] {
            let problem = Gas::problem(n).expect("consistent");
            let (q, qd) = (problem.q0(), problem.qd0());
            let d = problem.equations_at(0.0, q, qd).expect("regular");
            let (fv, vv) = q
                .iter()
                .zip(qd)
                .fold((0.0, 0.0), |(fv, vv), (x, v)| (fv - x * v, vv + v * v));
            let alpha = fv / vv;
            for i in 0..n {
                assert!((d.qdd[i] - (-q[i] - alpha * qd[i])).abs() < 1e-13, "{i}");
            }
            assert!((d.mu[0] - (-0.5 * alpha)).abs() < 1e-13);
            assert!(d.f[0].abs() < 1e-12);
        }
        for n in [0, 4] {
            assert!(matches!(
                Gas::standard(n),
                Err(Error::InvalidParameter { name: "n", .. })
            ));
        }
    }
}
