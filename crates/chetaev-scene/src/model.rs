//! A scene's Lagrangian, constraints and forces as a `chetaev` model with sizes known at run time.

use chetaev::loads::{add_body_torque, add_point_load, DynAngularVelocity, DynPointPosition};
use chetaev::model::DynModel;
use chetaev::prelude::Real;

use crate::expr::{Env, Expr};
use crate::scene::LoadSpec;

/// `L` and `f` as expressions on `n` coordinates, resolved against the scene's coordinate names.
/// Made by [`Scene::problem`](crate::Scene::problem).
#[derive(Clone, Debug)]
pub struct ExprModel {
    /// `N`, the number of coordinates the expressions were resolved with.
    pub(crate) n: usize,
    /// `L(t, q, q̇)`.
    pub(crate) lagrangian: Expr,
    /// `f_a(t, q, q̇)`, `a = 1..K`.
    pub(crate) constraints: Vec<Expr>,
    /// `h_b(t, q)`, the holonomic constraints.
    pub(crate) holonomic: Vec<Expr>,
    /// `Q_i(t, q, q̇)`, one per coordinate, or none.
    pub(crate) forces: Vec<Expr>,
    /// `D(t, q, q̇)`, or none.
    pub(crate) dissipation: Option<Expr>,
    /// Forces on points and torques on bodies, whose `Q` adds to `forces`.
    pub(crate) loads: Vec<LoadSpec>,
}

/// A load's point `r(t, q)` as expressions (which use no velocities, checked when the scene is
/// read).
struct Position<'a>(&'a [Expr]);

impl DynPointPosition for Position<'_> {
    #[inline]
    fn position<S: Real>(&self, t: S, q: &[S], r: &mut [S]) {
        let qd = vec![S::zero(); q.len()];
        let env = Env { t, q, qd: &qd };
        for (ri, e) in r.iter_mut().zip(self.0) {
            *ri = e.eval(&env);
        }
    }
}

/// A load's angular velocity `ω(t, q, q̇)` as expressions.
struct Turning<'a>(&'a [Expr]);

impl DynAngularVelocity for Turning<'_> {
    #[inline]
    fn angular_velocity<S: Real>(&self, t: S, q: &[S], qd: &[S], w: &mut [S]) {
        let env = Env { t, q, qd };
        for (wi, e) in w.iter_mut().zip(self.0) {
            *wi = e.eval(&env);
        }
    }
}

impl LoadSpec {
    /// Adds the load's generalised force at `(t, q, q̇)` to `out` (length `N`): `F · ∂r/∂q_i` or
    /// `T · ∂ω/∂q̇_i`, the derivatives by dual numbers.
    pub(crate) fn add_to<R: Real>(&self, t: R, q: &[R], qd: &[R], out: &mut [R]) {
        let env = Env { t, q, qd };
        let (place, acting) = self.parts();
        let values: Vec<R> = acting.iter().map(|e| e.eval(&env)).collect();
        match self {
            LoadSpec::Force { .. } => add_point_load(&Position(place), t, q, &values, out),
            LoadSpec::Torque { .. } => add_body_torque(&Turning(place), t, q, qd, &values, out),
        }
    }
}

impl DynModel for ExprModel {
    fn sizes(&self) -> (usize, usize) {
        (self.n, self.constraints.len())
    }

    #[inline]
    fn lagrangian<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> R {
        self.lagrangian.eval(&Env { t, q, qd })
    }

    #[inline]
    fn constraints<R: Real>(&self, t: R, q: &[R], qd: &[R], f: &mut [R]) {
        let env = Env { t, q, qd };
        for (fa, c) in f.iter_mut().zip(&self.constraints) {
            *fa = c.eval(&env);
        }
    }

    fn holonomic_count(&self) -> usize {
        self.holonomic.len()
    }

    #[inline]
    fn holonomic<R: Real>(&self, t: R, q: &[R], h: &mut [R]) {
        // The expressions use no velocities (checked when the scene is read).
        let qd = vec![R::zero(); q.len()];
        let env = Env { t, q, qd: &qd };
        for (hb, e) in h.iter_mut().zip(&self.holonomic) {
            *hb = e.eval(&env);
        }
    }

    #[inline]
    fn forces<R: Real>(&self, t: R, q: &[R], qd: &[R], out: &mut [R]) -> bool {
        if self.forces.is_empty() && self.loads.is_empty() {
            return false;
        }
        if self.forces.is_empty() {
            out.fill(R::zero());
        } else {
            let env = Env { t, q, qd };
            for (o, f) in out.iter_mut().zip(&self.forces) {
                *o = f.eval(&env);
            }
        }
        for load in &self.loads {
            load.add_to(t, q, qd, out);
        }
        true
    }

    #[inline]
    fn dissipation<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> Option<R> {
        self.dissipation.as_ref().map(|d| d.eval(&Env { t, q, qd }))
    }
}
