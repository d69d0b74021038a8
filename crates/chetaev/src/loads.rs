//! Loads given where they act: a force on a point and a torque on a body, mapped to generalised
//! forces through their partial velocities, the derivatives by automatic differentiation.
//!
//! A force `F` on a point at `r(t, q)` does the virtual work `F · δr = Σ_i F · ∂r/∂q_i δq_i`, so
//! its generalised force is
//!
//! ```text
//! Q_i = F · ∂r/∂q_i        (= F · ∂ṙ/∂q̇_i, the point's partial velocity),
//! ```
//!
//! and a torque `T` on a body of angular velocity `ω(t, q, q̇)` gives `Q_i = T · ∂ω/∂q̇_i`. The model
//! states `r` or `ω` once, over any scalar ([`PointPosition`], [`AngularVelocity`]); [`point_load`]
//! and [`body_torque`] take `∂r/∂q_i` and `∂ω/∂q̇_i` by dual numbers (one evaluation per
//! coordinate) and return `Q`, to be added in [`Lagrangian::forces`](crate::model::Lagrangian::forces).
//! `F` and `T` are any functions of `(t, q, q̇)` the model computes; in the plane, `r` has two
//! components and `ω` one (the rate about the normal).
//!
//! ```
//! use chetaev::loads::{point_load, PointPosition};
//! use chetaev::prelude::*;
//!
//! /// A pendulum of length `l`, angle θ from the downward vertical, pushed sideways at the bob.
//! struct Pushed { m: f64, g: f64, l: f64, f: f64 }
//!
//! /// The bob at `r = (l sin θ, −l cos θ)`.
//! struct Bob { l: f64 }
//! impl PointPosition<1, 2> for Bob {
//!     fn position<S: Real>(&self, _t: S, q: &SVector<S, 1>) -> SVector<S, 2> {
//!         SVector::from([q[0].sin() * self.l, -q[0].cos() * self.l])
//!     }
//! }
//!
//! impl Lagrangian<1> for Pushed {
//!     fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 1>, qd: &SVector<R, 1>) -> R {
//!         qd[0] * qd[0] * (0.5 * self.m * self.l * self.l) + q[0].cos() * (self.m * self.g * self.l)
//!     }
//!     fn forces<R: Real>(&self, t: R, q: &SVector<R, 1>, _qd: &SVector<R, 1>)
//!         -> Option<SVector<R, 1>> {
//!         // A horizontal force F: Q = F l cos θ.
//!         let force = SVector::from([R::from(self.f), R::zero()]);
//!         Some(point_load(&Bob { l: self.l }, t, q, &force))
//!     }
//! }
//!
//! let model = Pushed { m: 1.0, g: 9.81, l: 2.0, f: 3.0 };
//! let q: SVector<f64, 1> = SVector::from([0.3]);
//! let qf = model.forces(0.0, &q, &SVector::zeros()).expect("stated");
//! assert!((qf[0] - 3.0 * 2.0 * 0.3f64.cos()).abs() < 1e-15);
//! ```

use nalgebra::SVector;
use num_dual::Dual;

use crate::model::Real;

/// Where a point is, `r(t, q)` with `D` components (3 in space, 2 in the plane), over any scalar.
pub trait PointPosition<const N: usize, const D: usize> {
    /// `r(t, q)`.
    fn position<S: Real>(&self, t: S, q: &SVector<S, N>) -> SVector<S, D>;
}

/// How fast a body turns, `ω(t, q, q̇)` with `D` components (3 in space, 1 in the plane: the
/// rate about the plane's normal), over any scalar.
pub trait AngularVelocity<const N: usize, const D: usize> {
    /// `ω(t, q, q̇)`.
    fn angular_velocity<S: Real>(
        &self,
        t: S,
        q: &SVector<S, N>,
        qd: &SVector<S, N>,
    ) -> SVector<S, D>;
}

/// The generalised force of a force `force` (`F`, `D` components) on the point `point` at
/// `(t, q)`: `Q_i = F · ∂r/∂q_i` (length `N`), with `∂r/∂q_i` by dual numbers.
pub fn point_load<R, P, const N: usize, const D: usize>(
    point: &P,
    t: R,
    q: &SVector<R, N>,
    force: &SVector<R, D>,
) -> SVector<R, N>
where
    R: Real,
    P: PointPosition<N, D> + ?Sized,
{
    let mut out = SVector::<R, N>::zeros();
    let td = Dual::from_re(t);
    for i in 0..N {
        let qi = SVector::<Dual<R, f64>, N>::from_fn(|j, _| seeded(q[j], i == j));
        let r = point.position(td, &qi);
        out[i] = dot_eps(force, &r);
    }
    out
}

/// The generalised force of a torque `torque` (`T`, `D` components) on the body turning at
/// `angular`'s `ω` at `(t, q, q̇)`: `Q_i = T · ∂ω/∂q̇_i` (length `N`), with `∂ω/∂q̇_i` by dual
/// numbers.
pub fn body_torque<R, B, const N: usize, const D: usize>(
    body: &B,
    t: R,
    q: &SVector<R, N>,
    qd: &SVector<R, N>,
    torque: &SVector<R, D>,
) -> SVector<R, N>
where
    R: Real,
    B: AngularVelocity<N, D> + ?Sized,
{
    let mut out = SVector::<R, N>::zeros();
    let td = Dual::from_re(t);
    let qs = q.map(Dual::from_re);
    for i in 0..N {
        let qdi = SVector::<Dual<R, f64>, N>::from_fn(|j, _| seeded(qd[j], i == j));
        let w = body.angular_velocity(td, &qs, &qdi);
        out[i] = dot_eps(torque, &w);
    }
    out
}

/// `x` with derivative part 1 where `seed`, else 0.
fn seeded<R: Real>(x: R, seed: bool) -> Dual<R, f64> {
    Dual::new(x, if seed { R::one() } else { R::zero() })
}

/// `Σ_d a_d · b_d.eps`.
fn dot_eps<R: Real, const D: usize>(a: &SVector<R, D>, b: &SVector<Dual<R, f64>, D>) -> R {
    a.iter()
        .zip(b.iter())
        .fold(R::zero(), |acc, (a, b)| acc + *a * b.eps)
}
