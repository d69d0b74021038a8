//! Models shared by the library's test files.

use chetaev::prelude::*;

/// The paper's particle (`m = 1`, `g = 10`) held at the speed `v0` by `ẋ² + ẏ² = v0²`: `W`
/// constant and diagonal, `∂L/∂q` constant, `g = 0`, `c = 0`.
#[derive(Clone, Copy, Debug)]
pub struct Paper {
    pub v0: f64,
}

impl Lagrangian<2> for Paper {
    fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
        qd.dot(qd) * 0.5 - q[1] * 10.0
    }
}

impl Constraints<2, 1> for Paper {
    fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
        SVector::from([qd.dot(qd) - self.v0 * self.v0])
    }
}
