//! A model with its initial state, validated.

use nalgebra::SVector;

use crate::equations::{dynamics, saddle::SaddleWorkspace};
use crate::error::Error;
use crate::model::Model;

/// Relative tolerance on the initial constraint residual: `|f_a| ≤ tol · |J_a|·|q̇|` with
/// `J_a = ∂f_a/∂q̇` (or `≤ tol` where `|J_a|·|q̇|` vanishes) is accepted as consistent.
pub const INITIAL_RESIDUAL_TOLERANCE: f64 = 1e-10;

/// A model, an initial time and a consistent initial state `(q0, q̇0)`.
#[derive(Clone, Debug)]
pub struct Problem<M, const N: usize, const K: usize> {
    model: M,
    t0: f64,
    q0: SVector<f64, N>,
    qd0: SVector<f64, N>,
}

impl<M: Model<N, K>, const N: usize, const K: usize> Problem<M, N, K> {
    /// Builds a problem after checking that `t0`, `q0`, `q̇0` are finite, that `q̇0` satisfies the
    /// constraints (see [`INITIAL_RESIDUAL_TOLERANCE`]) and that the Chetaev block system is regular
    /// at the start.
    pub fn new(
        model: M,
        t0: f64,
        q0: SVector<f64, N>,
        qd0: SVector<f64, N>,
    ) -> Result<Self, Error> {
        check_finite("t0", std::slice::from_ref(&t0))?;
        check_finite("q0", q0.as_slice())?;
        check_finite("q̇0", qd0.as_slice())?;
        let problem = Self { model, t0, q0, qd0 };
        let d = problem.initial_dynamics()?;
        let cd = crate::equations::derivatives::constraint_derivatives::<M, f64, N, K>(
            &problem.model,
            t0,
            &q0,
            &qd0,
        );
        if d.f.iter().any(|f| !f.is_finite()) || !d.energy.is_finite() {
            return Err(Error::NonFiniteEvaluation {
                t: t0,
                q: q0.as_slice().to_vec(),
                qd: qd0.as_slice().to_vec(),
            });
        }
        for a in 0..K {
            let scale =
                crate::integrate::projection::constraint_scale(cd.j.row(a).norm(), qd0.norm());
            let tolerance = INITIAL_RESIDUAL_TOLERANCE * scale;
            if d.f[a].is_nan() || d.f[a].abs() > tolerance {
                return Err(Error::InconsistentInitialState {
                    t: t0,
                    index: a,
                    residual: d.f[a],
                    tolerance,
                });
            }
        }
        Ok(problem)
    }

    /// Builds a problem whose initial velocity is first projected onto `f(t0, q0, ·) = 0`: the
    /// smallest change of `q̇0` in the metric `W = ∂²L/∂q̇²`, by Newton iteration. This is an explicit
    /// opt-in; [`Problem::new`] never changes the state it is given. The applied correction is
    /// `problem.qd0() − qd0`.
    pub fn with_projected_velocity(
        model: M,
        t0: f64,
        q0: SVector<f64, N>,
        qd0: SVector<f64, N>,
    ) -> Result<Self, Error> {
        check_finite("t0", std::slice::from_ref(&t0))?;
        check_finite("q0", q0.as_slice())?;
        check_finite("q̇0", qd0.as_slice())?;
        let mut ws = SaddleWorkspace::default();
        let projected = crate::integrate::projection::project_velocity(
            &model, &mut ws, t0, &q0, &qd0, 1e-14, 20,
        )?;
        Self::new(model, t0, q0, projected.qd)
    }

    /// The model.
    pub fn model(&self) -> &M {
        &self.model
    }
    /// The initial time.
    pub fn t0(&self) -> f64 {
        self.t0
    }
    /// The initial position.
    pub fn q0(&self) -> &SVector<f64, N> {
        &self.q0
    }
    /// The initial velocity.
    pub fn qd0(&self) -> &SVector<f64, N> {
        &self.qd0
    }

    fn initial_dynamics(&self) -> Result<crate::equations::Dynamics<f64, N, K>, Error> {
        let mut ws = SaddleWorkspace::default();
        dynamics(&self.model, &mut ws, self.t0, &self.q0, &self.qd0)
            .map_err(|e| crate::integrate::system::locate(e, self.t0, &self.q0, &self.qd0))
    }
}

impl<M: crate::model::Lagrangian<N>, const N: usize> Problem<crate::model::Unconstrained<M>, N, 0> {
    /// The motion of `model` without constraints (`K = 0`): plain Euler–Lagrange equations.
    pub fn unconstrained(
        model: M,
        t0: f64,
        q0: SVector<f64, N>,
        qd0: SVector<f64, N>,
    ) -> Result<Self, Error> {
        Self::new(crate::model::Unconstrained(model), t0, q0, qd0)
    }
}

/// Checks that every number in `values` is finite.
pub(crate) fn check_finite(what: &str, values: &[f64]) -> Result<(), Error> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) if values.len() == 1 => Err(Error::NonFiniteInput {
            what: what.to_string(),
            value: values[i],
        }),
        Some(i) => Err(Error::NonFiniteInput {
            what: format!("{what}[{i}]"),
            value: values[i],
        }),
    }
}
