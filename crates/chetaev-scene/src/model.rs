//! A scene's Lagrangian and constraints as a `chetaev` model.

use chetaev::prelude::{Constraints, Lagrangian, Real, SVector};

use crate::expr::{Env, Expr};

/// `L` and `f` as expressions. It implements `Lagrangian<N>` for every `N` and
/// `Constraints<N, K>` for every `K`; the crate builds problems only with `N` equal to the number
/// of coordinates and `K` equal to the number of constraints, the sizes the expressions were
/// resolved with.
#[derive(Clone, Debug)]
pub(crate) struct ExprModel {
    pub lagrangian: Expr,
    pub constraints: Vec<Expr>,
}

impl<const N: usize> Lagrangian<N> for ExprModel {
    #[inline]
    fn lagrangian<R: Real>(&self, t: R, q: &SVector<R, N>, qd: &SVector<R, N>) -> R {
        self.lagrangian.eval(&Env {
            t,
            q: q.as_slice(),
            qd: qd.as_slice(),
        })
    }
}

impl<const N: usize, const K: usize> Constraints<N, K> for ExprModel {
    #[inline]
    fn constraints<R: Real>(&self, t: R, q: &SVector<R, N>, qd: &SVector<R, N>) -> SVector<R, K> {
        let env = Env {
            t,
            q: q.as_slice(),
            qd: qd.as_slice(),
        };
        SVector::from_fn(|a, _| self.constraints[a].eval(&env))
    }
}
