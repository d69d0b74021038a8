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
//! A [`DynModel`](crate::model::DynModel), whose sizes are known at run time, states `r` and `ω`
//! on slices ([`DynPointPosition`], [`DynAngularVelocity`]); [`add_point_load`] and
//! [`add_body_torque`] add their `Q` to the forces it writes, with the same dual numbers.
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

/// Where a point is, `r(t, q)`, for a model with sizes known at run time: `q` has the model's `N`
/// components and `r` the point's `D` (3 in space, 2 in the plane).
pub trait DynPointPosition {
    /// Writes `r(t, q)` (length `D`) to `r`.
    fn position<S: Real>(&self, t: S, q: &[S], r: &mut [S]);
}

/// How fast a body turns, `ω(t, q, q̇)`, for a model with sizes known at run time: `q` and `q̇`
/// have the model's `N` components and `ω` the body's `D` (3 in space, 1 in the plane).
pub trait DynAngularVelocity {
    /// Writes `ω(t, q, q̇)` (length `D`) to `w`.
    fn angular_velocity<S: Real>(&self, t: S, q: &[S], qd: &[S], w: &mut [S]);
}

/// Adds the generalised force of a force `force` (`F`, `D` components) on the point `point` at
/// `(t, q)` to `out` (length `N`, that of `q`): `out_i += F · ∂r/∂q_i`, with `∂r/∂q_i` by dual
/// numbers (one evaluation of `r` per coordinate).
///
/// ```
/// use chetaev::loads::{add_point_load, DynPointPosition};
/// use chetaev::prelude::*;
///
/// /// A bob at `r = (l sin θ, −l cos θ)`.
/// struct Bob { l: f64 }
/// impl DynPointPosition for Bob {
///     fn position<S: Real>(&self, _t: S, q: &[S], r: &mut [S]) {
///         r[0] = q[0].sin() * self.l;
///         r[1] = -q[0].cos() * self.l;
///     }
/// }
/// // A horizontal force F = 3 at the bob of a pendulum of length 2: Q = F l cos θ.
/// let mut q_force = [0.0];
/// add_point_load(&Bob { l: 2.0 }, 0.0, &[0.3], &[3.0, 0.0], &mut q_force);
/// assert!((q_force[0] - 3.0 * 2.0 * 0.3f64.cos()).abs() < 1e-15);
/// ```
pub fn add_point_load<R, P>(point: &P, t: R, q: &[R], force: &[R], out: &mut [R])
where
    R: Real,
    P: DynPointPosition + ?Sized,
{
    let td = Dual::from_re(t);
    let mut qi: Vec<Dual<R, f64>> = q.iter().map(|&x| Dual::from_re(x)).collect();
    let mut r = vec![Dual::from_re(R::zero()); force.len()];
    for (i, o) in out.iter_mut().enumerate().take(q.len()) {
        qi[i].eps = R::one();
        point.position(td, &qi, &mut r);
        qi[i].eps = R::zero();
        *o += dot_eps_slice(force, &r);
    }
}

/// Adds the generalised force of a torque `torque` (`T`, `D` components) on the body turning at
/// `body`'s `ω` at `(t, q, q̇)` to `out` (length `N`, that of `q`): `out_i += T · ∂ω/∂q̇_i`, with
/// `∂ω/∂q̇_i` by dual numbers (one evaluation of `ω` per coordinate).
pub fn add_body_torque<R, B>(body: &B, t: R, q: &[R], qd: &[R], torque: &[R], out: &mut [R])
where
    R: Real,
    B: DynAngularVelocity + ?Sized,
{
    let td = Dual::from_re(t);
    let qs: Vec<Dual<R, f64>> = q.iter().map(|&x| Dual::from_re(x)).collect();
    let mut qdi: Vec<Dual<R, f64>> = qd.iter().map(|&x| Dual::from_re(x)).collect();
    let mut w = vec![Dual::from_re(R::zero()); torque.len()];
    for (i, o) in out.iter_mut().enumerate().take(qd.len()) {
        qdi[i].eps = R::one();
        body.angular_velocity(td, &qs, &qdi, &mut w);
        qdi[i].eps = R::zero();
        *o += dot_eps_slice(torque, &w);
    }
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

/// `Σ_d a_d · b_d.eps` on slices of one length.
fn dot_eps_slice<R: Real>(a: &[R], b: &[Dual<R, f64>]) -> R {
    a.iter()
        .zip(b)
        .fold(R::zero(), |acc, (a, b)| acc + *a * b.eps)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The elbow of a two-link arm in space, links `a` and `b`, shoulder angle `q0` about `z`,
    /// elbow angle `q1` lifting out of the plane: `r = (a cos q0 + b cos q0 cos q1,
    /// a sin q0 + b sin q0 cos q1, b sin q1)`.
    struct Arm {
        a: f64,
        b: f64,
    }

    impl DynPointPosition for Arm {
        fn position<S: Real>(&self, _t: S, q: &[S], r: &mut [S]) {
            let reach = q[1].cos() * self.b + self.a;
            r[0] = q[0].cos() * reach;
            r[1] = q[0].sin() * reach;
            r[2] = q[1].sin() * self.b;
        }
    }

    /// A body spinning at `ω = (q̇1 cos q0, q̇1 sin q0, q̇0 + t)`.
    struct Spinner;

    impl DynAngularVelocity for Spinner {
        fn angular_velocity<S: Real>(&self, t: S, q: &[S], qd: &[S], w: &mut [S]) {
            w[0] = qd[1] * q[0].cos();
            w[1] = qd[1] * q[0].sin();
            w[2] = qd[0] + t;
        }
    }

    #[test]
    fn a_point_load_on_slices_is_the_force_dotted_with_the_partial_velocities() {
        let (a, b, q0, q1) = (1.5, 0.75, 0.4, -0.9);
        let f = [0.3, -2.0, 1.25];
        let mut out = [10.0, 20.0];
        add_point_load(&Arm { a, b }, 0.0, &[q0, q1], &f, &mut out);
        // ∂r/∂q0 = (−sin q0 (a + b cos q1), cos q0 (a + b cos q1), 0),
        // ∂r/∂q1 = (−b cos q0 sin q1, −b sin q0 sin q1, b cos q1), added to what `out` held.
        let reach = a + b * q1.cos();
        let dr0 = [-q0.sin() * reach, q0.cos() * reach, 0.0];
        let dr1 = [
            -b * q0.cos() * q1.sin(),
            -b * q0.sin() * q1.sin(),
            b * q1.cos(),
        ];
        let dot = |d: [f64; 3]| f.iter().zip(d).map(|(f, d)| f * d).sum::<f64>();
        assert!((out[0] - 10.0 - dot(dr0)).abs() < 1e-14, "{out:?}");
        assert!((out[1] - 20.0 - dot(dr1)).abs() < 1e-14, "{out:?}");
    }

    #[test]
    fn a_body_torque_on_slices_is_the_torque_dotted_with_the_partial_angular_velocities() {
        let (q0, q1) = (0.4, -0.9);
        let tau = [0.5, -1.5, 2.0];
        let mut out = [0.0, 0.0];
        add_body_torque(&Spinner, 3.0, &[q0, q1], &[7.0, -4.0], &tau, &mut out);
        // ∂ω/∂q̇0 = (0, 0, 1), ∂ω/∂q̇1 = (cos q0, sin q0, 0).
        assert!((out[0] - 2.0).abs() < 1e-15, "{out:?}");
        let expected = 0.5 * q0.cos() - 1.5 * q0.sin();
        assert!((out[1] - expected).abs() < 1e-15, "{out:?}");
    }

    #[test]
    fn the_loads_on_slices_agree_with_those_of_fixed_sizes() {
        struct Bob;
        impl PointPosition<2, 3> for Bob {
            fn position<S: Real>(&self, t: S, q: &SVector<S, 2>) -> SVector<S, 3> {
                let mut r = [S::zero(); 3];
                Arm { a: 1.5, b: 0.75 }.position(t, q.as_slice(), &mut r);
                SVector::from(r)
            }
        }
        let q = SVector::from([0.4, -0.9]);
        let f = SVector::from([0.3, -2.0, 1.25]);
        let fixed = point_load(&Bob, 0.0, &q, &f);
        let mut dynamic = [0.0; 2];
        add_point_load(
            &Arm { a: 1.5, b: 0.75 },
            0.0,
            q.as_slice(),
            f.as_slice(),
            &mut dynamic,
        );
        assert_eq!(fixed.as_slice(), &dynamic);
    }
}
