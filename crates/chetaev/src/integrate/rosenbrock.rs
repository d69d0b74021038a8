//! The stepper shared by the stiffly accurate Rosenbrock methods of the RODAS family ([`Rodas4`],
//! [`Rodas5P`]): each of them is a [`Tableau`] and a `MethodInfo`, and steps with
//! [`RosenbrockStepper`].
//!
//! Method: E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer
//! 1996, Section IV.7 (the implementation in the variables `u_i`, which avoids a matrix-vector
//! product per stage) and Section VI.4 (the stiffly accurate code RODAS). With `E = I/(hγ) − J`,
//! `J = ∂F/∂y (t, y)` and `F_t = ∂F/∂t (t, y)`, both evaluated once at the start of the step, the
//! `s` stages are
//!
//! ```text
//! E u_i = F(t + c_i h, Y_i) + h d_i F_t + Σ_{j<i} (c_ij / h) u_j,   i = 1..s,
//! ```
//!
//! with `Y_1 = y`, `Y_i = y + Σ_{j<i} a_ij u_j` for the first `m` stages (their rows of `a`), and
//! `Y_i = Y_{i−1} + u_{i−1}` for the others, which all sit at `c_i = 1` with `d_i = 0`. The step is
//! `y_1 = Y_s + u_s`; `Y_s` is the embedded solution, so `u_s` is the error estimate. The dense
//! output, with `D` rows `h_r` of dense coefficients, is
//!
//! ```text
//! y(t + θh) = (1 − θ) y + θ (y_1 + (1 − θ)(w_1 + θ (w_2 + … + θ w_D))),   w_r = Σ_j h_rj u_j.
//! ```
//!
//! One step costs one Jacobian (reused when a rejected step is retried from the same point, as in
//! RODAS), one LU decomposition of `E` with partial pivoting, `s` right-hand sides (`s − 1` when
//! the Jacobian is reused) and `s` triangular solves.
//!
//! [`Rodas4`]: super::Rodas4
//! [`Rodas5P`]: super::Rodas5P

use super::system::{Jacobian, OdeSystem};
use super::{Step, Stepper, Trial};
use crate::error::Error;

/// The coefficients of an `S`-stage method of the family (`S ≥ 1`), with `D` rows of dense output;
/// see the module docs. Rows and columns are stages, counted from 0; entries on and above the
/// diagonal of `a` and `coupling`, and the rows of `a` from `m` on, are not read.
#[derive(Debug)]
pub struct Tableau<const S: usize, const D: usize> {
    /// `γ`, the diagonal of the method.
    pub gamma: f64,
    /// `m`: the stages whose arguments come from their row of `a` (stage 0 included).
    pub m: usize,
    /// The nodes `c_i`.
    pub c: [f64; S],
    /// The coefficients `d_i` of `h F_t` (`γ_i = Σ_j γ_ij`).
    pub d: [f64; S],
    /// The stage arguments `a_ij`, `j < i < m`.
    pub a: [[f64; S]; S],
    /// The couplings `c_ij` of the stage increments, `j < i`.
    pub coupling: [[f64; S]; S],
    /// The dense-output rows `h_rj`.
    pub dense: [[f64; S]; D],
}

/// A row of `a` or `coupling` from its entries below the diagonal, `row = [x_0, …, x_{i−1}]`,
/// padded with zeros to the stage count (the entries on and above the diagonal are not read).
pub(crate) const fn lower<const S: usize>(row: &[f64]) -> [f64; S] {
    let mut out = [0.0; S];
    let mut j = 0;
    while j < row.len() {
        out[j] = row[j];
        j += 1;
    }
    out
}

/// The working state of a RODAS-type method.
#[derive(Clone, Debug)]
pub struct RosenbrockStepper<const S: usize, const D: usize> {
    tableau: &'static Tableau<S, D>,
    /// `∂F/∂y` and `∂F/∂t`.
    jacobian: Jacobian,
    /// `F(t, y)` at the point of the Jacobian.
    f0: Vec<f64>,
    /// The point `(t, y)` of `jacobian` and `f0`, valid when `jac_valid`.
    jac_t: f64,
    jac_y: Vec<f64>,
    jac_valid: bool,
    /// The LU factors of `I/(hγ) − J`.
    lu: Lu,
    /// The stage increments `u_i`.
    k: [Vec<f64>; S],
    ytmp: Vec<f64>,
    dy: Vec<f64>,
    /// Dense output of the last accepted step: `y`, `y_1` and the rows `w_r`.
    y0: Vec<f64>,
    y1: Vec<f64>,
    w: [Vec<f64>; D],
    dense: bool,
}

impl<const S: usize, const D: usize> RosenbrockStepper<S, D> {
    /// The stepper of `tableau` for states of dimension `dim`: what `Method::stepper` of a method
    /// of the family returns.
    pub(crate) fn new(tableau: &'static Tableau<S, D>, dim: usize) -> Self {
        Self {
            tableau,
            jacobian: Jacobian::new(dim),
            f0: vec![0.0; dim],
            jac_t: f64::NAN,
            jac_y: vec![0.0; dim],
            jac_valid: false,
            lu: Lu::new(dim),
            k: std::array::from_fn(|_| vec![0.0; dim]),
            ytmp: vec![0.0; dim],
            dy: vec![0.0; dim],
            y0: vec![0.0; dim],
            y1: vec![0.0; dim],
            w: std::array::from_fn(|_| vec![0.0; dim]),
            dense: true,
        }
    }

    /// Factors `I/(hγ) − J` into `self.lu`. Returns whether the matrix is invertible.
    fn decompose<Sys: OdeSystem>(&mut self, sys: &mut Sys, h: f64) -> bool {
        let n = self.jacobian.dt.len();
        let fac = 1.0 / (h * self.tableau.gamma);
        let m = &mut self.lu.a;
        for (m, j) in m.iter_mut().zip(&self.jacobian.dy) {
            *m = -j;
        }
        for d in m.iter_mut().step_by(n + 1) {
            *d += fac;
        }
        sys.count_lu();
        self.lu.factor()
    }
}

impl<const S: usize, const D: usize> Stepper for RosenbrockStepper<S, D> {
    fn reset<Sys: OdeSystem>(&mut self, _sys: &mut Sys, _t: f64, _y: &[f64]) -> Result<(), Error> {
        // F, J and ∂F/∂t are evaluated by the step at its starting point, and reused only while
        // that point stays the same.
        Ok(())
    }

    fn attempt<Sys: OdeSystem>(&mut self, sys: &mut Sys, trial: Trial<'_>) -> Result<f64, Error> {
        let (t, h, y, y_new, norm) = trial.parts();
        let n = y.len();
        let tab = self.tableau;
        if !(self.jac_valid && self.jac_t == t && self.jac_y[..] == *y) {
            self.jac_valid = false;
            sys.rhs(t, y, &mut self.f0)?;
            // Taken where the step starts, the same whatever its size: not a reason to retry
            // shorter, as a non-finite stage is.
            sys.jacobian(t, y, &mut self.jacobian)
                .map_err(|e| match e {
                    Error::NonFiniteEvaluation { t, q, qd } => {
                        Error::NonFiniteJacobian { t, q, qd }
                    }
                    e => e,
                })?;
            self.jac_t = t;
            self.jac_y.copy_from_slice(y);
            self.jac_valid = true;
        }
        if !(1.0 / (h * tab.gamma)).is_finite() {
            // A step so short (subnormal) that 1/(hγ) overflows: the change of y is h·F(t, y) to
            // far below rounding, so one explicit Euler step is exact in floating point.
            for i in 0..n {
                y_new[i] = y[i] + h * self.f0[i];
            }
            return Ok(0.0);
        }
        if !self.decompose(sys, h) {
            // A singular iteration matrix: reject, so that the driver retries with a smaller h.
            return Ok(f64::INFINITY);
        }
        let Self {
            jacobian: Jacobian { dt: dfdt, .. },
            f0,
            lu,
            k,
            ytmp,
            dy,
            ..
        } = self;
        let hinv = 1.0 / h;
        ytmp.copy_from_slice(y);
        for i in 0..S {
            let (done, rest) = k.split_at_mut(i);
            let ki = &mut rest[0];
            let f: &[f64] = if i == 0 {
                f0
            } else {
                if i < tab.m {
                    let a = &tab.a[i][..i];
                    for e in 0..n {
                        let mut acc = 0.0;
                        for (a, u) in a.iter().zip(done.iter()) {
                            acc += a * u[e];
                        }
                        ytmp[e] = y[e] + acc;
                    }
                } else {
                    for (x, u) in ytmp.iter_mut().zip(&done[i - 1]) {
                        *x += u;
                    }
                }
                sys.rhs(t + tab.c[i] * h, ytmp, dy)?;
                dy
            };
            let hd = h * tab.d[i];
            let coupling = tab.coupling[i].map(|c| c * hinv);
            for e in 0..n {
                let mut acc = f[e] + hd * dfdt[e];
                for (c, u) in coupling[..i].iter().zip(done.iter()) {
                    acc += c * u[e];
                }
                ki[e] = acc;
            }
            lu.solve(ki);
        }
        // y_1 = Y_s + u_s; u_s is its difference from the embedded solution Y_s.
        let last = &k[S - 1];
        for e in 0..n {
            y_new[e] = ytmp[e] + last[e];
        }
        Ok(norm.norm(last, y, y_new))
    }

    fn commit<Sys: OdeSystem>(&mut self, _sys: &mut Sys, step: Step<'_>) -> Result<(), Error> {
        if !self.dense {
            return Ok(());
        }
        let Step { y, y_new, .. } = step;
        self.y0.copy_from_slice(y);
        self.y1.copy_from_slice(y_new);
        for (w, row) in self.w.iter_mut().zip(&self.tableau.dense) {
            for (e, we) in w.iter_mut().enumerate() {
                *we = row.iter().zip(&self.k).map(|(h, u)| h * u[e]).sum();
            }
        }
        Ok(())
    }

    fn interpolate(&self, theta: f64, out: &mut [f64]) {
        let th1 = 1.0 - theta;
        for (e, o) in out.iter_mut().enumerate() {
            let mut acc = 0.0;
            for w in self.w.iter().rev() {
                acc = w[e] + theta * acc;
            }
            *o = th1 * self.y0[e] + theta * (self.y1[e] + th1 * acc);
        }
    }

    fn set_dense_output(&mut self, needed: bool) {
        self.dense = needed;
    }
}

/// LU factors with partial pivoting of a small dense `n × n` matrix, in place and without
/// allocating after [`Lu::new`]: the iteration matrix of a stiff problem of a few coordinates is
/// factored at every step and solved with at every stage.
#[derive(Clone, Debug)]
struct Lu {
    n: usize,
    /// The matrix (row-major) before [`Lu::factor`]; after it, `L` below the diagonal (unit
    /// diagonal implied) and `U` on and above it, of the rows as permuted.
    a: Vec<f64>,
    /// Row `k` was swapped with row `swap[k] ≥ k` at elimination step `k`.
    swap: Vec<usize>,
    /// One past the last row of the diagonal block of row `k` (see [`Lu::factor`]).
    block_end: Vec<usize>,
    /// The matrix as it was before [`Lu::factor`], for the refinement of [`Lu::solve`], and the
    /// residual there.
    matrix: Vec<f64>,
    residual: Vec<f64>,
}

impl Lu {
    fn new(n: usize) -> Self {
        Self {
            n,
            a: vec![0.0; n * n],
            swap: vec![0; n],
            block_end: vec![0; n],
            matrix: vec![0.0; n * n],
            residual: vec![0.0; n],
        }
    }

    /// Factors `a` in place, choosing at each step the first row of largest magnitude in the
    /// column among the rows of its diagonal block. Returns `false` when a pivot is zero (the
    /// matrix is singular).
    ///
    /// The blocks are those of the matrix's block lower triangular form: a block ends after row
    /// `r` when no row up to `r` has an entry beyond column `r`. The quantities carried along
    /// with the motion (the energy balance's quadratures, sensitivities) have such rows after the
    /// state's, since the state does not depend on them. Pivoting within blocks keeps them out of
    /// the state's elimination, so that carrying them does not change the state's steps however
    /// large their entries, and it is the same partial pivoting where the matrix is one block.
    fn factor(&mut self) -> bool {
        self.matrix.copy_from_slice(&self.a);
        let (n, a) = (self.n, &mut self.a);
        // The furthest column reached by the rows so far, then each row's block end.
        let mut reach = 0;
        for r in 0..n {
            let last = (r..n).rev().find(|&c| a[r * n + c] != 0.0).unwrap_or(r);
            reach = reach.max(last);
            self.block_end[r] = reach;
        }
        let mut end = n;
        for r in (0..n).rev() {
            if self.block_end[r] <= r {
                end = r + 1;
            }
            self.block_end[r] = end;
        }
        for k in 0..n {
            let mut p = k;
            for r in k + 1..self.block_end[k] {
                if a[r * n + k].abs() > a[p * n + k].abs() {
                    p = r;
                }
            }
            self.swap[k] = p;
            if p != k {
                for c in 0..n {
                    a.swap(k * n + c, p * n + c);
                }
            }
            let pivot = a[k * n + k];
            if pivot == 0.0 {
                return false;
            }
            let inv = 1.0 / pivot;
            let (upper, lower) = a.split_at_mut((k + 1) * n);
            let row_k = &upper[k * n + k + 1..(k + 1) * n];
            for row in lower.chunks_exact_mut(n) {
                let l = row[k] * inv;
                row[k] = l;
                for (x, &u) in row[k + 1..].iter_mut().zip(row_k) {
                    *x -= l * u;
                }
            }
        }
        true
    }

    /// Solves `A x = b` in place with the factors of [`Lu::factor`], refined once: `x += A⁻¹(b −
    /// A x)`, with the residual in working precision.
    ///
    /// The refinement makes the solve backward stable entry by entry (R. D. Skeel, Math. Comp. 35,
    /// 1980, for a matrix not too ill-conditioned): the computed `x` solves `(A + δA) x = b` with
    /// `|δA| ≲ ε|A|`, whatever the scales of the rows and columns.
    /// The iteration matrix mixes units (for `y = [q, q̇]`, `∂q̈/∂q` is a rate squared where
    /// `∂q̇/∂q̇` is one), and without it the rounding of the solve grew with the rate: on a ring
    /// held at the speed `v0` by a holonomic and a speed constraint, 100 turns at `rtol = 1e-10`
    /// on the same steps, Rodas5P ended `2.2e-6` off at `v0 = 1e6` against `3.8e-9` at `v0 = 1`;
    /// refined, `3.3e-9` and `3.1e-9` (`the_implicit_methods_do_not_depend_on_the_unit_of_time`
    /// in `tests/reliability.rs`). It costs a product with `A` and one more pair of triangular
    /// solves per stage, against a factorisation and a Jacobian per step.
    fn solve(&mut self, b: &mut [f64]) {
        let n = self.n;
        let mut r = std::mem::take(&mut self.residual);
        r.copy_from_slice(b);
        self.substitute(b);
        for (ri, row) in r.iter_mut().zip(self.matrix.chunks_exact(n)) {
            *ri -= row.iter().zip(&*b).map(|(m, x)| m * x).sum::<f64>();
        }
        self.substitute(&mut r);
        for (x, d) in b.iter_mut().zip(&r) {
            *x += d;
        }
        self.residual = r;
    }

    /// `b ← A⁻¹ b` by the permutation and the two triangular solves of the factors.
    fn substitute(&self, b: &mut [f64]) {
        let (n, a) = (self.n, &self.a);
        for (k, &p) in self.swap.iter().enumerate() {
            b.swap(k, p);
        }
        for i in 0..n {
            let mut x = b[i];
            for (l, bj) in a[i * n..i * n + i].iter().zip(&b[..i]) {
                x -= l * bj;
            }
            b[i] = x;
        }
        for i in (0..n).rev() {
            let mut x = b[i];
            for j in (i + 1..n).rev() {
                x -= a[i * n + j] * b[j];
            }
            b[i] = x / a[i * n + i];
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Checks a tableau against `y' = 1` (`h = 1`, `J = 0`, `F_t = 0`): there
    /// `u_i = γ (1 + Σ_j c_ij u_j)`, every stage argument must be `y + c_i`, the step is exact, so
    /// the increments from stage `m − 1` on (among them the error estimate) and the dense-output
    /// rows must vanish.
    pub(crate) fn check_consistency<const S: usize, const D: usize>(tab: &Tableau<S, D>) {
        let mut u = [0.0f64; S];
        for i in 0..S {
            let s: f64 = (0..i).map(|j| tab.coupling[i][j] * u[j]).sum();
            u[i] = tab.gamma * (1.0 + s);
        }
        for i in 1..tab.m {
            let s: f64 = (0..i).map(|j| tab.a[i][j] * u[j]).sum();
            assert!(
                (s - tab.c[i]).abs() < 1e-13,
                "stage {i}: node {} ≠ {s}",
                tab.c[i]
            );
        }
        for i in tab.m..S {
            assert_eq!((tab.c[i], tab.d[i]), (1.0, 0.0), "stage {i}");
        }
        for (j, uj) in u.iter().enumerate().skip(tab.m - 1) {
            assert!(uj.abs() < 1e-13, "u_{j} = {uj}");
        }
        for (r, row) in tab.dense.iter().enumerate() {
            let w: f64 = row.iter().zip(&u).map(|(h, u)| h * u).sum();
            assert!(w.abs() < 1e-12, "dense row {r}: {w}");
        }
        // d_0 = γ: the first stage's F_t term.
        assert_eq!(tab.d[0], tab.gamma);
    }
}
