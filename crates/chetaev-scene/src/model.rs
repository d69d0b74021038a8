//! A scene's Lagrangian, constraints and forces as a `chetaev` model with sizes known at run time.

use chetaev::model::DynModel;
use chetaev::prelude::Real;

use crate::expr::{Env, Expr};

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
        if self.forces.is_empty() {
            return false;
        }
        let env = Env { t, q, qd };
        for (o, f) in out.iter_mut().zip(&self.forces) {
            *o = f.eval(&env);
        }
        true
    }

    #[inline]
    fn dissipation<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> Option<R> {
        self.dissipation.as_ref().map(|d| d.eval(&Env { t, q, qd }))
    }
}
