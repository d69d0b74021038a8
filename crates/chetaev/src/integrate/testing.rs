//! Test systems and helpers shared by the methods' unit tests and the conformance suite.

use super::system::{Jacobian, OdeSystem};
use super::{ErrorNorm, Method, Stepper};
use crate::error::Error;

/// A right-hand side `dy = F(t, y)`.
pub(crate) type Rhs = fn(f64, &[f64], &mut [f64]);
/// A Jacobian: `∂F/∂y` (row-major) into `jac`, `∂F/∂t` into `dfdt`.
pub(crate) type Jac = fn(f64, &[f64], &mut [f64], &mut [f64]);

/// `y' = f(t, y)` with its Jacobian `j` (`∂f/∂y` row-major, and `∂f/∂t`), counting evaluations
/// and LU decompositions.
pub(crate) struct Sys<F, J> {
    dim: usize,
    f: F,
    j: J,
    pub(crate) rhs_evaluations: usize,
    pub(crate) jacobian_evaluations: usize,
    pub(crate) lu_decompositions: usize,
}

impl<F, J> Sys<F, J>
where
    F: FnMut(f64, &[f64], &mut [f64]),
    J: FnMut(f64, &[f64], &mut [f64], &mut [f64]),
{
    pub(crate) fn new(dim: usize, f: F, j: J) -> Self {
        Self {
            dim,
            f,
            j,
            rhs_evaluations: 0,
            jacobian_evaluations: 0,
            lu_decompositions: 0,
        }
    }
}

impl<F: FnMut(f64, &[f64], &mut [f64])> Sys<F, Jac> {
    /// A system for explicit methods, which never ask for the Jacobian (it reads as zero).
    pub(crate) fn explicit(dim: usize, f: F) -> Self {
        Self::new(dim, f, |_, _, jac, dfdt| {
            jac.fill(0.0);
            dfdt.fill(0.0);
        })
    }
}

impl<F, J> OdeSystem for Sys<F, J>
where
    F: FnMut(f64, &[f64], &mut [f64]),
    J: FnMut(f64, &[f64], &mut [f64], &mut [f64]),
{
    fn dim(&self) -> usize {
        self.dim
    }
    fn controlled_dim(&self) -> usize {
        self.dim
    }
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Error> {
        self.rhs_evaluations += 1;
        (self.f)(t, y, dy);
        Ok(())
    }
    fn jacobian(&mut self, t: f64, y: &[f64], out: &mut Jacobian) -> Result<(), Error> {
        self.jacobian_evaluations += 1;
        (self.j)(t, y, &mut out.dy, &mut out.dt);
        Ok(())
    }
    fn count_lu(&mut self) {
        self.lu_decompositions += 1;
    }
}

/// A norm under which every step is accepted.
pub(crate) fn loose(dim: usize) -> ErrorNorm {
    ErrorNorm::new(0.0, vec![1e10; dim])
}

/// `n` steps of `method` of equal size from `(t0, y0)` to `t1`; the state at `t1`.
pub(crate) fn fixed_steps<M: Method, S: OdeSystem>(
    method: &M,
    sys: &mut S,
    (t0, y0): (f64, &[f64]),
    t1: f64,
    n: usize,
) -> Result<Vec<f64>, Error> {
    let dim = y0.len();
    let norm = loose(dim);
    let mut st = method.stepper(dim);
    let mut y = y0.to_vec();
    let mut y_new = vec![0.0; dim];
    let h = (t1 - t0) / n as f64;
    st.reset(sys, t0, &y)?;
    for i in 0..n {
        let t = t0 + i as f64 * h;
        st.try_step(sys, t, h, &y, &mut y_new, &norm)?;
        st.accept(sys, t, h, &y, &y_new)?;
        y.copy_from_slice(&y_new);
    }
    Ok(y)
}

/// `log2(e_h / e_{h/2})` for consecutive entries.
pub(crate) fn slopes(errors: &[f64]) -> Vec<f64> {
    errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect()
}
