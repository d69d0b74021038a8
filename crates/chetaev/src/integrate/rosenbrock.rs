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
use super::{ErrorNorm, Step, Stepper, Trial};
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
        sys.count_lu();
        self.lu
            .factor(1.0 / (h * self.tableau.gamma), &self.jacobian.dy)
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
            self.lu.weigh(norm, y);
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

/// The widest spread of the row weights of [`Lu::weigh`], as a power of two: `2^100 ≈ 1.3e30`,
/// room for any change of units between the components, and far from the end of the
/// floating-point range, so that a weighted magnitude overflows only where the matrix's entries
/// are themselves beyond `1e278`.
const SCALE_SPREAD: i32 = 100;

/// LU factors with partial pivoting of a small dense `n × n` iteration matrix, in place and
/// without allocating after [`Lu::new`]: the iteration matrix of a stiff problem of a few
/// coordinates is factored at every step and solved with at every stage.
///
/// The pivots are chosen in the units of the error norm: as partial pivoting would choose them for
/// `S⁻¹ A S`, with `S` the diagonal of the error norm's weights at the step's start rounded to
/// powers of two ([`Lu::weigh`]). Partial pivoting depends on the scales of the rows; with them in
/// the norm's units, the pivots, and so the rounding of the solves measured in the norm the
/// step-size control reads, are the same in any units in which the tolerances are given. Chosen
/// on the matrix as it is, in mixed units (for `y = [q, q̇]`, `∂q̈/∂q` is a rate squared where
/// `∂q̇/∂q̇` is one), the pivots changed with the rates, and the rounding with them: on a ring held
/// at the speed `v0` by a holonomic and a speed constraint, 100 turns at `rtol = 1e-10` on the same
/// steps, Rodas5P ended `2.2e-6` off at `v0 = 1e6` against `3.8e-9` at `v0 = 1`
/// (`the_implicit_methods_do_not_depend_on_the_unit_of_time` in `tests/reliability.rs`).
///
/// Elimination commutes with a diagonal similarity by powers of two (every product by such a scale
/// is exact), so factoring `A` with the pivots of `S⁻¹ A S` gives the factors of `S⁻¹ A S` scaled
/// back, to the last digit short of underflow: the scaling is needed only to compare candidate
/// pivots, one product each, and the matrix and the solves are left as they are.
#[derive(Clone, Debug)]
struct Lu {
    n: usize,
    /// The matrix before [`Lu::factor`]; after it, `L` below the diagonal (unit diagonal implied)
    /// and `U` on and above it, of the rows as permuted. Row-major.
    a: Vec<f64>,
    /// Row `k` was swapped with row `swap[k] ≥ k` at elimination step `k`.
    swap: Vec<usize>,
    /// One past the last row of the diagonal block of row `k` (see [`Lu::factor`]).
    block_end: Vec<usize>,
    /// The weight `1/s_i ≥ 1` of each row's magnitude in the choice of pivots ([`Lu::weigh`]),
    /// and the same for the rows as permuted during a factorisation.
    row_weight: Vec<f64>,
    permuted_weight: Vec<f64>,
    /// `m > 0` when the last factorisation took the rows of `q' = q̇` as its first `m` pivots
    /// ([`Lu::factor`]); 0 otherwise.
    first_order_rows: usize,
}

impl Lu {
    fn new(n: usize) -> Self {
        Self {
            n,
            a: vec![0.0; n * n],
            swap: vec![0; n],
            block_end: vec![0; n],
            row_weight: vec![1.0; n],
            permuted_weight: vec![1.0; n],
            first_order_rows: 0,
        }
    }

    /// Sets the scales `s_i` of the next factorisations to the error norm's weights at `y`,
    /// rounded down to powers of two, relative to the largest, and at least `2^−SCALE_SPREAD` of
    /// it (a weight at the floor of [`ErrorNorm::new`], of a component at zero under a purely
    /// relative tolerance, is as far below the others as `f64` reaches). The components outside
    /// the norm (the quadratures and sensitivities carried along) get the scale of the largest.
    fn weigh(&mut self, norm: &ErrorNorm, y: &[f64]) {
        // The binary exponent of a positive weight (one past the largest where it overflowed).
        let exponent = |i: usize| {
            let w = norm.scale(i, y[i], y[i]);
            if w.is_finite() {
                ((w.to_bits() >> 52) & 0x7ff) as i32 - 1023
            } else {
                1024
            }
        };
        let controlled = norm.len().min(self.n);
        let top = (0..controlled).map(exponent).max().unwrap_or(0);
        for (i, w) in self.row_weight.iter_mut().enumerate() {
            let below = if i < controlled {
                (top - exponent(i)).min(SCALE_SPREAD)
            } else {
                0
            };
            // 2^below, 0 ≤ below ≤ SCALE_SPREAD.
            *w = f64::from_bits(((1023 + below) as u64) << 52);
        }
    }

    /// Factors `fac·I − J` (`J` row-major) in place, choosing at each step the row of largest
    /// weighted magnitude in the column (the first of them) among the rows of its diagonal block.
    /// Returns `false` when a pivot is zero (the matrix is singular).
    ///
    /// The blocks are those of the matrix's block lower triangular form: a block ends after row
    /// `r` when no row up to `r` has an entry beyond column `r`. The quantities carried along
    /// with the motion (the energy balance's quadratures, sensitivities) have such rows after the
    /// state's, since the state does not depend on them. Pivoting within blocks keeps them out of
    /// the state's elimination, so that carrying them does not change the state's steps however
    /// large their entries, and it is the same partial pivoting where the matrix is one block.
    ///
    /// A second-order system, `y = [q, q̇, …]` with `q' = q̇` (the reduced equations), has the
    /// first `m` rows of `J` equal to `[0, I, 0]` ([`first_order_rows`]), so row `k < m` of the
    /// matrix is `fac` at `k` and `−1` at `k + m`. Where partial pivoting takes those rows as the
    /// first `m` pivots (it does unless a step is long against the motion's rates, as in a stiff
    /// problem), their elimination updates one entry per row, not a whole row: the factors are
    /// those of the general elimination to the last digit (it adds only products with zeros),
    /// at a fraction of its cost, `O(m n)` for the first `m` columns of `O(m n²)`.
    fn factor(&mut self, fac: f64, jac: &[f64]) -> bool {
        let m = first_order_rows(self.n, jac);
        let (n, a) = (self.n, &mut self.a);
        for (m, j) in a.iter_mut().zip(jac) {
            *m = -j;
        }
        for d in a.iter_mut().step_by(n + 1) {
            *d += fac;
        }
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
        let weight = &mut self.permuted_weight;
        weight.copy_from_slice(&self.row_weight);
        // The rows of `q' = q̇` as the first pivots, if partial pivoting would choose them: no row
        // below weighs more in its column (the other rows of `q'` are zero there, and before the
        // elimination of column `k` no other column of those rows has touched column `k`).
        let first = if m > 0
            && (0..m).all(|k| {
                let pivot = a[k * n + k].abs() * weight[k];
                (m..self.block_end[k]).all(|r| a[r * n + k].abs() * weight[r] <= pivot)
            }) {
            m
        } else {
            0
        };
        for k in 0..first {
            self.swap[k] = k;
            let pivot = a[k * n + k];
            if pivot == 0.0 {
                return false;
            }
            let inv = 1.0 / pivot;
            for row in a[m * n..].chunks_exact_mut(n) {
                let l = row[k] * inv;
                row[k] = l;
                // Row k of U is `fac` at k and −1 at k + m.
                row[k + m] += l;
            }
        }
        self.first_order_rows = first;
        for k in first..n {
            let mut p = k;
            let mut largest = a[k * n + k].abs() * weight[k];
            for r in k + 1..self.block_end[k] {
                let m = a[r * n + k].abs() * weight[r];
                if m > largest {
                    (p, largest) = (r, m);
                }
            }
            self.swap[k] = p;
            if p != k {
                for c in 0..n {
                    a.swap(k * n + c, p * n + c);
                }
                weight.swap(k, p);
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

    /// Solves `(fac·I − J) x = b` in place with the factors of [`Lu::factor`]: the permutation
    /// and the two triangular solves (the rows of `q' = q̇` taken first have no entries in `L` and
    /// one beside the diagonal in `U`).
    fn solve(&self, b: &mut [f64]) {
        let (n, a, m) = (self.n, &self.a, self.first_order_rows);
        for (k, &p) in self.swap.iter().enumerate() {
            b.swap(k, p);
        }
        for i in m..n {
            let mut x = b[i];
            for (l, bj) in a[i * n..i * n + i].iter().zip(&b[..i]) {
                x -= l * bj;
            }
            b[i] = x;
        }
        for i in (m..n).rev() {
            let mut x = b[i];
            for j in (i + 1..n).rev() {
                x -= a[i * n + j] * b[j];
            }
            b[i] = x / a[i * n + i];
        }
        for i in (0..m).rev() {
            b[i] = (b[i] + b[i + m]) / a[i * n + i];
        }
    }
}

/// `m > 0` where the first `m` rows of the row-major `n × n` Jacobian `jac` are `[0, I, 0]`
/// (`y'_k = y_{k+m}`, the rows `q' = q̇` of a second-order system, `2m ≤ n`); 0 otherwise.
fn first_order_rows(n: usize, jac: &[f64]) -> usize {
    let Some(m) = jac[..n].iter().position(|&v| v != 0.0) else {
        return 0;
    };
    let identity = |k: usize| {
        jac[k * n..(k + 1) * n]
            .iter()
            .enumerate()
            .all(|(c, &v)| v == if c == k + m { 1.0 } else { 0.0 })
    };
    if m == 0 || 2 * m > n || !(0..m).all(identity) {
        return 0;
    }
    m
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

    #[test]
    fn first_order_rows_are_found_only_where_they_are_exact() {
        #[rustfmt::skip]
        let second_order = [
            0.0, 0.0, 1.0, 0.0, 0.0,
            0.0, 0.0, 0.0, 1.0, 0.0,
            3.0, 1.0, 2.0, 0.5, 0.0,
            1.0, 4.0, 0.1, 1.5, 0.0,
            0.2, 0.3, 0.4, 0.5, 0.0,
        ];
        assert_eq!(first_order_rows(5, &second_order), 2);
        for (entry, value) in [(2, 1.0 + f64::EPSILON), (4, 1e-300), (7, 1.0), (0, 1.0)] {
            let mut jac = second_order;
            jac[entry] = value;
            assert_eq!(first_order_rows(5, &jac), 0, "entry {entry} = {value}");
        }
        // Not more rows of q' than of q̇; a zero first row is no structure.
        assert_eq!(
            first_order_rows(3, &[0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
            0
        );
        assert_eq!(first_order_rows(2, &[0.0; 4]), 0);
        assert_eq!(first_order_rows(2, &[0.0, 1.0, 5.0, 6.0]), 1);
    }

    #[test]
    fn weighted_pivots_factor_as_the_scaled_matrix_would() {
        // y = [q, q̇] of two coordinates in fast units: J = [[0, I], [K, C]] with K a rate squared
        // (1e12) and C a rate (1e6), fac = 1/(hγ) a rate. The error norm's weights of q̇ are 2^20
        // those of q, so S = diag(2^-20, 2^-20, 1, 1) and the row weights 1/s = (2^20, 2^20, 1, 1).
        let fac = 3e6;
        #[rustfmt::skip]
        let jac = [
            0.0, 0.0, 1.0, 0.0,
            0.0, 0.0, 0.0, 1.0,
            -1.0e12, 0.3e12, 2.0e6, -0.5e6,
            0.2e12, -0.7e12, 0.1e6, 1.5e6,
        ];
        let s = [2f64.powi(-20), 2f64.powi(-20), 1.0, 1.0];
        let mut weighted = Lu::new(4);
        for (w, s) in weighted.row_weight.iter_mut().zip(&s) {
            *w = 1.0 / s;
        }
        assert!(weighted.factor(fac, &jac));
        // S⁻¹ (fac·I − J) S = fac·I − S⁻¹ J S, factored with plain partial pivoting.
        let scaled_jac: Vec<f64> = (0..16).map(|e| jac[e] * s[e % 4] / s[e / 4]).collect();
        let mut scaled = Lu::new(4);
        assert!(scaled.factor(fac, &scaled_jac));
        assert_eq!(weighted.swap, scaled.swap);
        // The weighted factorisation takes the rows q' = q̇ first, by the short elimination; the
        // scaled one, whose rows q' are not `[0, I]` (`2^20` in place of 1), by the general one.
        assert_eq!((weighted.first_order_rows, scaled.first_order_rows), (2, 0));
        // The pivots are not those of the matrix as it is: its rows of K outweigh fac.
        let mut plain = Lu::new(4);
        assert!(plain.factor(fac, &jac));
        assert_ne!(plain.swap, weighted.swap);
        assert_eq!(plain.first_order_rows, 0);
        // The same solution to the last bit: x = S (S⁻¹ A S)⁻¹ S⁻¹ b (and so the short
        // elimination is the general one).
        let b = [0.7, -1.3, 2.9e6, 0.4e6];
        let mut x = b;
        weighted.solve(&mut x);
        let mut x_scaled: Vec<f64> = b.iter().zip(&s).map(|(b, s)| b / s).collect();
        scaled.solve(&mut x_scaled);
        for ((x, xs), s) in x.iter().zip(&x_scaled).zip(&s) {
            assert_eq!(*x, xs * s);
        }
        // And a solution: the residual of the weighted factors is at rounding.
        for (i, row) in jac.chunks_exact(4).enumerate() {
            let ax: f64 = (0..4)
                .map(|j| (if i == j { fac } else { 0.0 } - row[j]) * x[j])
                .sum();
            assert!(
                (ax - b[i]).abs() <= 1e-9 * b[i].abs().max(1.0),
                "row {i}: {ax} ≠ {}",
                b[i]
            );
        }
    }
}
