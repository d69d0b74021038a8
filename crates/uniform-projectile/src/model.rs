//! The paper's two motions as `chetaev` models: the reference problems of the verification.
//!
//! Both use the Lagrangian (42.2), `L = ½ m (ẋ² + ẏ²) − m g y`. The uniform motion adds the
//! isotachytonic constraint (42.23), `f = ẋ² + ẏ² − v0² = 0`. Nothing else is written by hand: the
//! Chetaev equations (42.26), the multiplier (42.27) and the reduced equation (42.28) come out of
//! `chetaev`'s automatic differentiation and block solve.

use chetaev::model::Fixed;
use chetaev::prelude::*;

use crate::closed_form::Params;

/// A particle of mass `m` in homogeneous gravity `g`, coordinates `(x, y)`: the Lagrangian (42.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projectile {
    /// Mass.
    pub m: f64,
    /// Gravitational acceleration.
    pub g: f64,
}

impl Lagrangian<2> for Projectile {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        // g is read as a parameter, so that sensitivities with respect to it can be asked for; in
        // every other evaluation it is the constant m g, as before.
        qd.dot(qd) * (0.5 * self.m) - q[1] * (R::parameter("g", self.g) * self.m)
    }
}

/// The same particle held at constant speed `v0` by the isotachytonic constraint (42.23).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UniformProjectile {
    /// The free particle.
    pub particle: Projectile,
    /// The constant speed.
    pub v0: f64,
}

impl Lagrangian<2> for UniformProjectile {
    fn lagrangian<R: Real>(&self, t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        self.particle.lagrangian(t, q, qd)
    }
}

impl Constraints<2, 1> for UniformProjectile {
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
        let v0 = R::parameter("v0", self.v0);
        SVector::from([qd.dot(qd) - v0 * v0])
    }
}

/// The uniform projectile as a problem.
pub type UniformProblem = Problem<Fixed<UniformProjectile, 2, 1>>;

/// The classical projectile as a problem.
pub type ClassicalProblem = Problem<Fixed<Unconstrained<Projectile>, 2, 0>>;

fn initial_state(p: &Params) -> (SVector<f64, 2>, SVector<f64, 2>) {
    (SVector::from([0.0, p.h0]), SVector::from([p.v0, 0.0]))
}

/// The uniform horizontal projectile from `(0, h0)` with velocity `(v0, 0)` at `t = 0`.
pub fn uniform_problem(p: &Params) -> Result<UniformProblem, chetaev::Error> {
    let (q0, qd0) = initial_state(p);
    let model = UniformProjectile {
        particle: Projectile { m: p.m, g: p.g },
        v0: p.v0,
    };
    Problem::new(model, 0.0, q0, qd0)
}

/// The classical horizontal projectile from the same initial state.
pub fn classical_problem(p: &Params) -> Result<ClassicalProblem, chetaev::Error> {
    let (q0, qd0) = initial_state(p);
    Problem::unconstrained(Projectile { m: p.m, g: p.g }, 0.0, q0, qd0)
}

/// The height `y`, whose zero is the impact.
struct Height;

impl EventFunction for Height {
    fn value<R: Real>(&self, _t: R, q: &[R], _qd: &[R]) -> R {
        q[1]
    }
}

/// The impact `y = 0`, reached from above; stops the integration. Written for any scalar, so that
/// the sensitivities of its time and place are exact.
pub fn impact() -> Event {
    Event::smooth("impact", Height).falling().terminal()
}

/// The seeds of the paper's sensitivities: `v0` (a parameter of the constraint and the initial
/// speed `ẋ(0) = v0`), `g`, and `h0` (the initial height).
pub fn seeds() -> [Seed; 3] {
    [
        Seed::parameter("v0").with_velocity(0, 1.0),
        Seed::parameter("g"),
        Seed::new("h0").with_position(1, 1.0),
    ]
}

/// Per-component absolute tolerances scaled to the motion: positions by `max(h0, R_classical)`,
/// velocities by `v0`, each times `rtol`. Needed where `h0` and the range differ by many orders of
/// magnitude (the stiff and extreme scenes).
pub fn scaled_atol(p: &Params, rtol: f64) -> ([f64; 2], [f64; 2]) {
    let t_fall = (2.0 * p.h0 / p.g).sqrt();
    let x_scale = (p.v0 * t_fall)
        .min(p.v0 * p.v0 / p.g)
        .max(f64::MIN_POSITIVE);
    let v_scale = p.v0.min((2.0 * p.g * p.h0).sqrt()).max(f64::MIN_POSITIVE);
    (
        [rtol * x_scale, rtol * p.h0],
        [rtol * v_scale, rtol * v_scale],
    )
}
