//! The paper's model written out by hand: the limit against which `chetaev` is measured.
//!
//! Both systems integrate the uniform motion of a particle of speed `v0` in gravity `g` with the
//! crate's own methods and step control
//! ([`solve_ode`](chetaev::integrate::driver::solve_ode)); only the right-hand side differs from
//! `chetaev`'s, which derives the same equations by automatic differentiation and a block solve at
//! every evaluation. Both have the exact Jacobian written out as well, for `Rodas4`.

use chetaev::integrate::system::{Jacobian, OdeSystem};
use chetaev::Error;

/// Evaluations counted by a hand-written system.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Right-hand sides.
    pub rhs: usize,
    /// Jacobians.
    pub jacobians: usize,
    /// LU decompositions of an implicit method's iteration matrix.
    pub lu: usize,
}

/// The reduced equation (42.28) with `ẋ` from the constraint (42.24):
///
/// ```text
/// y = (x, y, ẏ),   x' = √(v0² − ẏ²),   y' = ẏ,   ẏ' = −(g/v0²)(v0² − ẏ²)
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reduced {
    /// Gravitational acceleration.
    pub g: f64,
    /// The constant speed.
    pub v0: f64,
    /// Work counters.
    pub counts: Counts,
}

impl Reduced {
    /// The system for gravity `g` and speed `v0`.
    pub fn new(g: f64, v0: f64) -> Self {
        Self {
            g,
            v0,
            counts: Counts::default(),
        }
    }

    /// The full velocity `(ẋ, ẏ)` of a state `(x, y, ẏ)`, `ẋ` from the constraint (42.24).
    pub fn velocity(&self, y: &[f64]) -> [f64; 2] {
        [(self.v0 * self.v0 - y[2] * y[2]).max(0.0).sqrt(), y[2]]
    }
}

impl OdeSystem for Reduced {
    fn dim(&self) -> usize {
        3
    }
    fn controlled_dim(&self) -> usize {
        3
    }
    #[inline]
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Error> {
        self.counts.rhs += 1;
        let v2 = self.v0 * self.v0;
        let w = y[2];
        let s = v2 - w * w;
        dy[0] = s.max(0.0).sqrt();
        dy[1] = w;
        dy[2] = -(self.g / v2) * s;
        Ok(())
    }
    fn jacobian(&mut self, _t: f64, y: &[f64], out: &mut Jacobian) -> Result<(), Error> {
        let Jacobian { dy: jac, dt: dfdt } = out;
        self.counts.jacobians += 1;
        let v2 = self.v0 * self.v0;
        let w = y[2];
        let xd = (v2 - w * w).max(0.0).sqrt();
        jac.fill(0.0);
        dfdt.fill(0.0);
        jac[2] = if xd > 0.0 { -w / xd } else { 0.0 }; // ∂x'/∂ẏ
        jac[3 + 2] = 1.0; // ∂y'/∂ẏ
        jac[2 * 3 + 2] = 2.0 * self.g / v2 * w; // ∂ẏ'/∂ẏ
        Ok(())
    }
    fn count_lu(&mut self) {
        self.counts.lu += 1;
    }
}

/// The motion in full coordinates: gravity minus its component along the velocity,
///
/// ```text
/// y = (x, y, ẋ, ẏ),   a = g − (g·v) v / |v|²,   g = (0, −g)
/// ```
///
/// i.e. `ẍ = g ẏ ẋ / |v|²`, `ÿ = −g + g ẏ² / |v|²`, which is the Chetaev equation (42.26) with the
/// multiplier (42.27) eliminated by hand.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Full {
    /// Gravitational acceleration.
    pub g: f64,
    /// Work counters.
    pub counts: Counts,
}

impl Full {
    /// The system for gravity `g`.
    pub fn new(g: f64) -> Self {
        Self {
            g,
            counts: Counts::default(),
        }
    }
}

impl OdeSystem for Full {
    fn dim(&self) -> usize {
        4
    }
    fn controlled_dim(&self) -> usize {
        4
    }
    #[inline]
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Error> {
        self.counts.rhs += 1;
        let (xd, yd) = (y[2], y[3]);
        let c = self.g * yd / (xd * xd + yd * yd);
        dy[0] = xd;
        dy[1] = yd;
        dy[2] = c * xd;
        dy[3] = c * yd - self.g;
        Ok(())
    }
    fn jacobian(&mut self, _t: f64, y: &[f64], out: &mut Jacobian) -> Result<(), Error> {
        let Jacobian { dy: jac, dt: dfdt } = out;
        self.counts.jacobians += 1;
        let (xd, yd, g) = (y[2], y[3], self.g);
        let s = xd * xd + yd * yd;
        let s2 = s * s;
        jac.fill(0.0);
        dfdt.fill(0.0);
        jac[2] = 1.0; // ∂x'/∂ẋ
        jac[4 + 3] = 1.0; // ∂y'/∂ẏ
        jac[2 * 4 + 2] = g * yd * (s - 2.0 * xd * xd) / s2; // ∂ẍ/∂ẋ
        jac[2 * 4 + 3] = g * xd * (s - 2.0 * yd * yd) / s2; // ∂ẍ/∂ẏ
        jac[3 * 4 + 2] = -2.0 * g * yd * yd * xd / s2; // ∂ÿ/∂ẋ
        jac[3 * 4 + 3] = 2.0 * g * yd * xd * xd / s2; // ∂ÿ/∂ẏ
        Ok(())
    }
    fn count_lu(&mut self) {
        self.counts.lu += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use chetaev::equations::{evaluate, Workspace};
    use uniform_projectile::closed_form::Params;
    use uniform_projectile::model::uniform_problem;

    /// States on the constraint `|v| = v0`, at several angles below the horizontal.
    fn states(v0: f64) -> Vec<([f64; 2], [f64; 2])> {
        [0.0, 0.3, 0.9, 1.4]
            .iter()
            .map(|&a: &f64| ([1.5 * a, 5.0 - a], [v0 * a.cos(), -v0 * a.sin()]))
            .collect()
    }

    #[test]
    fn both_hand_written_forms_agree_with_chetaev_to_1e_14() {
        let p = Params::PAPER;
        let problem = uniform_problem(&p).expect("valid");
        let mut ws = Workspace::for_model(problem.model());
        for (q, v) in states(p.v0) {
            let d = evaluate(problem.model(), &mut ws, 0.0, &q, &v).expect("regular");

            let mut full = Full::new(p.g);
            let mut dy = [0.0; 4];
            full.rhs(0.0, &[q[0], q[1], v[0], v[1]], &mut dy)
                .expect("finite");
            for i in 0..2 {
                assert!((dy[i] - v[i]).abs() <= 1e-14 * p.v0);
                assert!(
                    (dy[2 + i] - d.qdd[i]).abs() <= 1e-14 * p.g,
                    "{i}: {dy:?} {d:?}"
                );
            }

            let mut reduced = Reduced::new(p.g, p.v0);
            let mut dz = [0.0; 3];
            reduced
                .rhs(0.0, &[q[0], q[1], v[1]], &mut dz)
                .expect("finite");
            assert!((dz[0] - v[0]).abs() <= 1e-14 * p.v0);
            assert!((dz[1] - v[1]).abs() <= 1e-14 * p.v0);
            assert!((dz[2] - d.qdd[1]).abs() <= 1e-14 * p.g, "{dz:?} {d:?}");
        }
    }

    /// Central differences of `rhs` against the hand-written Jacobian.
    fn check_jacobian<S: OdeSystem>(sys: &mut S, y: &[f64]) {
        let n = sys.dim();
        let mut jacobian = Jacobian::new(n);
        sys.jacobian(0.0, y, &mut jacobian).expect("finite");
        let jac = jacobian.dy;
        let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
        for j in 0..n {
            let h = 1e-6 * y[j].abs().max(1.0);
            let (mut yp, mut ym) = (y.to_vec(), y.to_vec());
            yp[j] += h;
            ym[j] -= h;
            sys.rhs(0.0, &yp, &mut fp).expect("finite");
            sys.rhs(0.0, &ym, &mut fm).expect("finite");
            for i in 0..n {
                let fd = (fp[i] - fm[i]) / (2.0 * h);
                assert!(
                    (fd - jac[i * n + j]).abs() <= 1e-6 * (1.0 + fd.abs()),
                    "({i}, {j}): {fd} vs {}",
                    jac[i * n + j]
                );
            }
        }
    }

    #[test]
    fn the_hand_written_jacobians_match_differences() {
        check_jacobian(&mut Reduced::new(10.0, 10.0), &[1.0, 4.0, -6.0]);
        check_jacobian(&mut Full::new(10.0), &[1.0, 4.0, 8.0, -6.0]);
    }
}
