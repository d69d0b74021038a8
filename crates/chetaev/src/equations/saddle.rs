//! The block solve for accelerations and multipliers.
//!
//! The Chetaev equations in Newton form, `d/dt(∂L/∂q̇) − ∂L/∂q = Jᵀμ`, together with the
//! differentiated constraints `df/dt = 0`, give at every instant the linear system (size `N + K`)
//!
//! ```text
//! [ W   −Jᵀ ] [ q̈ ]   [ ∂L/∂q − g ]        W = ∂²L/∂q̇²            (N × N)
//! [ J    0  ] [ μ ] = [    −c     ]        J = ∂f/∂q̇              (K × N)
//!                                          g = (∂²L/∂q̇∂q) q̇ + ∂²L/∂q̇∂t
//!                                          c = (∂f/∂q) q̇ + ∂f/∂t
//! ```
//!
//! It is regular exactly when `J` has full row rank and `W` is regular on the null space of `J`;
//! `W` itself may be singular. Each constraint row is first scaled so that `J` and `W` have
//! comparable magnitudes (which rescales `μ` and is undone afterwards), then the system is solved
//! by Gaussian elimination with complete pivoting. The ratio of the smallest to the largest pivot is
//! returned as a cheap conditioning estimate; below [`SINGULAR_PIVOT_RATIO`] the system is reported
//! as singular instead of producing a meaningless answer.
//!
//! Both the elimination and the Schur complement `J W⁻¹ Jᵀ` of the faster routes lose accuracy as
//! the square of the constraints' condition: with two constraint gradients nearly parallel the
//! multipliers grow as `1/sin θ`, and `q̈` is what is left when they nearly cancel. Below
//! [`NULL_SPACE_PIVOT_RATIO`] the system is therefore solved again by the null-space method
//! (`solve_null_space`), whose error grows as the condition itself:
//!
//! ```text
//! Jᵀ = Q [R; 0]  (Householder),   q̈ = Q [y; z],   Rᵀ y = s,
//! (QᵀWQ)₂₂ z = (Qᵀr)₂ − (QᵀWQ)₂₁ y,   R μ = (QᵀWQ)₁ [y; z] − (Qᵀr)₁
//! ```
//!
//! `y` is fixed by the constraints alone and `z` by the dynamics on their null space, so nothing
//! large cancels. It needs `W` regular on the null space of `J` only, as the elimination does.

use nalgebra::{SMatrix, SVector};

use crate::model::Real;

/// Pivot ratio (smallest over largest pivot magnitude) below which the block system is singular.
pub const SINGULAR_PIVOT_RATIO: f64 = 64.0 * f64::EPSILON;

/// Pivot ratio (of the elimination, or of the Schur complement's Cholesky factor) below which the
/// block system is solved again by the null-space method: two constraint gradients within about
/// `0.01` rad of each other (in the metric `W`). Above it the faster solve loses at most about
/// `ε/ratio` relative, `2e-12`.
pub const NULL_SPACE_PIVOT_RATIO: f64 = 1e-4;

/// Why the block system could not be solved.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SaddleFailure {
    /// A block held a NaN or an infinity.
    NonFinite,
    /// Constraint row `row` of `J` is zero: that constraint does not restrict the velocity here.
    ZeroConstraintRow {
        /// The constraint index `a`.
        row: usize,
    },
    /// The system is singular to working precision.
    Singular {
        /// Smallest over largest pivot magnitude.
        pivot_ratio: f64,
    },
    /// An argument's size does not fit the model: `q` or `q̇` not of length `n`, or a workspace
    /// (or [`Dynamics`](crate::equations::Dynamics)) made for other sizes. Nothing was evaluated.
    ///
    /// (A compiled workspace made for other compiled equations is [`SaddleFailure::ForeignWorkspace`].)
    SizeMismatch {
        /// Which argument, and which of its sizes.
        what: &'static str,
        /// The size the model calls for.
        expected: usize,
        /// The size given.
        got: usize,
    },
    /// A [`CompiledWorkspace`](crate::equations::compiled::CompiledWorkspace) made for other
    /// compiled equations, whose slots hold another tape's constants. Nothing was evaluated.
    ForeignWorkspace,
}

/// `Err(SizeMismatch)` for the first `(expected, got)` of `sizes` that differ, named by the same
/// entry of `names`. The comparisons are all the work when the sizes fit, so that callers on a
/// hot path can afford it.
#[inline(always)]
pub(crate) fn check_sizes<const M: usize>(
    names: &[&'static str; M],
    sizes: [(usize, usize); M],
) -> Result<(), SaddleFailure> {
    match sizes.iter().position(|&(expected, got)| expected != got) {
        None => Ok(()),
        Some(i) => Err(size_mismatch(names[i], sizes[i])),
    }
}

#[cold]
fn size_mismatch(what: &'static str, (expected, got): (usize, usize)) -> SaddleFailure {
    SaddleFailure::SizeMismatch {
        what,
        expected,
        got,
    }
}

/// Scratch storage for the elimination, reused across calls so the hot path never allocates.
#[derive(Clone, Debug)]
pub struct SaddleWorkspace<T> {
    a: Vec<T>,
    b: Vec<T>,
    x: Vec<T>,
    col: Vec<usize>,
    scale: Vec<f64>,
    det_sign: f64,
    /// Made on first use only: most systems never need it, and a workspace is moved by value.
    null: Option<Box<NullSpace<T>>>,
}

impl<T> Default for SaddleWorkspace<T> {
    fn default() -> Self {
        Self {
            a: Vec::new(),
            b: Vec::new(),
            x: Vec::new(),
            col: Vec::new(),
            scale: Vec::new(),
            det_sign: 1.0,
            null: None,
        }
    }
}

/// Scratch storage of [`solve_null_space`].
#[derive(Clone, Debug)]
struct NullSpace<T> {
    /// The rows of `J` (the columns of `Jᵀ`), scaled; then the Householder vectors below the
    /// diagonal of `R` and `R` above it, column `a` of `Jᵀ` at `a n ..`.
    h: Vec<T>,
    /// `2/(vᵀv)` of each Householder vector.
    beta: Vec<T>,
    /// The diagonal of `R`.
    diag: Vec<T>,
    /// `1/max_i |J_ai|`, the scale of each constraint row.
    scale: Vec<f64>,
    /// `QᵀWQ`, row-major `n × n`.
    wq: Vec<T>,
    /// `Qᵀr`.
    qr: Vec<T>,
    /// `[y; z]`, then `q̈`.
    x: Vec<T>,
    /// `μ` (scaled).
    mu: Vec<T>,
    /// The block on the null space, its right-hand side, solution and column permutation.
    red: Vec<T>,
    rhs: Vec<T>,
    z: Vec<T>,
    col: Vec<usize>,
    /// The Gram matrix of the scaled rows of `J` ([`nearly_dependent`]).
    gram: Vec<f64>,
}

impl<T> Default for NullSpace<T> {
    fn default() -> Self {
        Self {
            h: Vec::new(),
            beta: Vec::new(),
            diag: Vec::new(),
            scale: Vec::new(),
            wq: Vec::new(),
            qr: Vec::new(),
            x: Vec::new(),
            mu: Vec::new(),
            red: Vec::new(),
            rhs: Vec::new(),
            z: Vec::new(),
            col: Vec::new(),
            gram: Vec::new(),
        }
    }
}

impl<T> SaddleWorkspace<T> {
    /// The last solution of [`solve_blocks`]: `q̈` (first `n`), then `μ` (last `k`).
    pub fn solution(&self) -> &[T] {
        &self.x
    }

    /// The sign of the determinant of the block matrix `[W −Jᵀ; J 0]` at the last successful
    /// [`solve_blocks`]: `+1` where `W` is positive definite (and `J` of full rank), and wherever
    /// the matrix can be reached from such a state without passing through a singular one.
    pub fn det_sign(&self) -> f64 {
        self.det_sign
    }
}

/// The solution of the block system.
#[derive(Clone, Copy, Debug)]
pub struct SaddleSolution<T, const N: usize, const K: usize> {
    /// `q̈`, shape `N`.
    pub qdd: SVector<T, N>,
    /// `μ`, shape `K`.
    pub mu: SVector<T, K>,
    /// Smallest over largest pivot magnitude (1 is perfect; near [`SINGULAR_PIVOT_RATIO`] is bad).
    pub pivot_ratio: f64,
}

/// Solves `[W −Jᵀ; J 0] [q̈; μ] = [r; s]` for `q̈` and `μ`.
///
/// Shapes: `w` is `N × N`, `j` is `K × N`, `r` is `N`, `s` is `K`. With `K = 0` this is `W q̈ = r`.
pub fn solve<T: Real, const N: usize, const K: usize>(
    ws: &mut SaddleWorkspace<T>,
    w: &SMatrix<T, N, N>,
    j: &SMatrix<T, K, N>,
    r: &SVector<T, N>,
    s: &SVector<T, K>,
) -> Result<SaddleSolution<T, N, K>, SaddleFailure> {
    let pivot_ratio = solve_blocks(
        ws,
        N,
        K,
        |i, k| w[(i, k)],
        |a, i| j[(a, i)],
        |i| r[i],
        |a| s[a],
    )?;
    Ok(SaddleSolution {
        qdd: SVector::<T, N>::from_fn(|i, _| ws.x[i]),
        mu: SVector::<T, K>::from_fn(|a, _| ws.x[N + a]),
        pivot_ratio,
    })
}

/// The block solve for any sizes, with the blocks given element by element: `w(i, k)` (`n × n`),
/// `j(a, i)` (`k × n`), `r(i)` (`n`), `s(a)` (`k`). On success the solution is
/// [`SaddleWorkspace::solution`]: `q̈` then `μ`; the pivot ratio is returned.
pub fn solve_blocks<T: Real>(
    ws: &mut SaddleWorkspace<T>,
    n: usize,
    k: usize,
    w: impl Fn(usize, usize) -> T,
    j: impl Fn(usize, usize) -> T,
    r: impl Fn(usize) -> T,
    s: impl Fn(usize) -> T,
) -> Result<f64, SaddleFailure> {
    let m = n + k;
    ws.a.clear();
    ws.a.resize(m * m, T::zero());
    ws.b.clear();
    ws.b.resize(m, T::zero());
    ws.x.clear();
    ws.x.resize(m, T::zero());
    ws.col.clear();
    ws.col.extend(0..m);
    ws.scale.clear();

    // One pass over the blocks: assemble W, J and the right-hand side, check that every entry is
    // finite, and find the magnitudes that scale the constraint rows.
    let mut finite = true;
    let mut w_scale = 0.0f64;
    for i in 0..n {
        for (c, x) in ws.a[i * m..i * m + n].iter_mut().enumerate() {
            let v = w(i, c);
            let re = v.re();
            finite &= re.is_finite();
            w_scale = w_scale.max(re.abs());
            *x = v;
        }
        let v = r(i);
        finite &= v.re().is_finite();
        ws.b[i] = v;
    }
    for a in 0..k {
        let mut j_max = 0.0f64;
        for (i, x) in ws.a[(n + a) * m..(n + a) * m + n].iter_mut().enumerate() {
            let v = j(a, i);
            let re = v.re();
            finite &= re.is_finite();
            j_max = j_max.max(re.abs());
            *x = v;
        }
        ws.scale.push(j_max);
        let v = s(a);
        finite &= v.re().is_finite();
        ws.b[n + a] = v;
    }
    if !finite {
        return Err(SaddleFailure::NonFinite);
    }

    // Scale each constraint row to the magnitude of W, J̃ = D J, μ̃ = D⁻¹ μ, and mirror it into the
    // upper right block as −J̃ᵀ.
    let w_scale = if w_scale > 0.0 { w_scale } else { 1.0 };
    let a = &mut ws.a;
    for (c, d) in ws.scale.iter_mut().enumerate() {
        if *d == 0.0 {
            return Err(SaddleFailure::ZeroConstraintRow { row: c });
        }
        *d = w_scale / *d;
        let row = n + c;
        for i in 0..n {
            let v = a[row * m + i] * *d;
            a[row * m + i] = v;
            a[i * m + row] = -v;
        }
        ws.b[row] *= *d;
    }

    let (pivot_ratio, singular, det_sign) = eliminate(a, &mut ws.b, &mut ws.col, m);
    if singular {
        return Err(SaddleFailure::Singular { pivot_ratio });
    }
    ws.det_sign = det_sign;
    // A small pivot ratio may come from W alone (masses of very different sizes), which the
    // elimination handles better than an orthogonal transformation would: the null-space method
    // only where the constraint gradients themselves are nearly dependent.
    if k > 1
        && pivot_ratio < NULL_SPACE_PIVOT_RATIO
        && nearly_dependent(ws.null.get_or_insert_with(Default::default), n, k, &j)
    {
        solve_null_space(ws, (n, k), w, j, r, s)?;
        return Ok(pivot_ratio);
    }
    back_substitute(a, &ws.b, &ws.col, &mut ws.x, m);
    for (c, d) in ws.scale.iter().enumerate() {
        ws.x[n + c] *= *d;
    }
    Ok(pivot_ratio)
}

/// Whether the rows of `J`, each scaled to largest entry 1, are nearly dependent: the Cholesky
/// factor of their Gram matrix has a pivot ratio (the smallest `sin²` of the angle between a row
/// and the span of those before it) below [`NULL_SPACE_PIVOT_RATIO`].
#[cold]
#[inline(never)]
fn nearly_dependent<T: Real>(
    scratch: &mut NullSpace<T>,
    n: usize,
    k: usize,
    j: impl Fn(usize, usize) -> T,
) -> bool {
    let NullSpace {
        scale: rows, gram, ..
    } = scratch;
    rows.clear();
    for a in 0..k {
        let start = rows.len();
        rows.extend((0..n).map(|i| j(a, i).re()));
        let m = rows[start..].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        rows[start..].iter_mut().for_each(|v| *v /= m);
    }
    gram.clear();
    gram.resize(k * k, 0.0);
    for a in 0..k {
        for b in 0..=a {
            let g: f64 = (0..n).map(|i| rows[a * n + i] * rows[b * n + i]).sum();
            gram[a * k + b] = g;
            gram[b * k + a] = g;
        }
    }
    super::compiled::cholesky(gram, k).map_or(true, |ratio| ratio < NULL_SPACE_PIVOT_RATIO)
}

/// Solves `[W −Jᵀ; J 0] [q̈; μ] = [r; s]` by the null-space method (see the module docs), with the
/// blocks given as for [`solve_blocks`]; the solution goes to [`SaddleWorkspace::solution`]. Its
/// error in `q̈` grows as the condition of `J`, not as its square. It leaves the determinant's sign
/// as it was: the callers know it from their own factorisation. Out of line: it serves the rare
/// state, and the common path stays as compact as without it.
#[cold]
#[inline(never)]
pub(crate) fn solve_null_space<T: Real>(
    ws: &mut SaddleWorkspace<T>,
    (n, k): (usize, usize),
    w: impl Fn(usize, usize) -> T,
    j: impl Fn(usize, usize) -> T,
    r: impl Fn(usize) -> T,
    s: impl Fn(usize) -> T,
) -> Result<(), SaddleFailure> {
    if k > n {
        return Err(SaddleFailure::Singular { pivot_ratio: 0.0 });
    }
    let NullSpace {
        h,
        beta,
        diag,
        scale,
        wq,
        qr,
        x,
        mu,
        red,
        rhs,
        z,
        col,
        ..
    } = &mut **ws.null.get_or_insert_with(Default::default);

    // The scaled rows of J, each of largest entry 1.
    h.clear();
    scale.clear();
    for a in 0..k {
        let start = h.len();
        h.extend((0..n).map(|i| j(a, i)));
        let m = h[start..].iter().fold(0.0f64, |m, v| m.max(v.re().abs()));
        if !m.is_finite() {
            return Err(SaddleFailure::NonFinite);
        }
        if m == 0.0 {
            return Err(SaddleFailure::ZeroConstraintRow { row: a });
        }
        let d = 1.0 / m;
        h[start..].iter_mut().for_each(|v| *v *= d);
        scale.push(d);
    }

    // Householder QR of Jᵀ: column p becomes its Householder vector from entry p on, with R_pq
    // (q > p) left in column q above its own vector.
    beta.clear();
    diag.clear();
    for p in 0..k {
        let mut norm2 = T::zero();
        for i in p..n {
            norm2 += h[p * n + i] * h[p * n + i];
        }
        if norm2.re() == 0.0 {
            return Err(SaddleFailure::Singular { pivot_ratio: 0.0 });
        }
        let norm = norm2.sqrt();
        let alpha = if h[p * n + p].re() >= 0.0 {
            -norm
        } else {
            norm
        };
        h[p * n + p] -= alpha;
        let mut vtv = T::zero();
        for i in p..n {
            vtv += h[p * n + i] * h[p * n + i];
        }
        let b = T::from(2.0) / vtv;
        for q in p + 1..k {
            let mut t = T::zero();
            for i in p..n {
                t += h[p * n + i] * h[q * n + i];
            }
            t *= b;
            for i in p..n {
                let v = h[p * n + i];
                h[q * n + i] -= t * v;
            }
        }
        beta.push(b);
        diag.push(alpha);
    }
    let (lo, hi) = diag.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), d| {
        (lo.min(d.re().abs()), hi.max(d.re().abs()))
    });
    if lo <= SINGULAR_PIVOT_RATIO * hi {
        return Err(SaddleFailure::Singular {
            pivot_ratio: lo / hi.max(f64::MIN_POSITIVE),
        });
    }
    // x ← H_p x for the Householder reflection p, on the entries `at(i)` of `x`.
    let reflect = |p: usize, x: &mut [T], at: &dyn Fn(usize) -> usize| {
        let v = &h[p * n..(p + 1) * n];
        let mut t = T::zero();
        for i in p..n {
            t += v[i] * x[at(i)];
        }
        t *= beta[p];
        for i in p..n {
            x[at(i)] -= t * v[i];
        }
    };

    // QᵀWQ: Qᵀ applied to each row of W (giving WQ), then to each column.
    wq.clear();
    for i in 0..n {
        wq.extend((0..n).map(|c| w(i, c)));
    }
    for i in 0..n {
        for p in 0..k {
            reflect(p, wq, &|c| i * n + c);
        }
    }
    for c in 0..n {
        for p in 0..k {
            reflect(p, wq, &|i| i * n + c);
        }
    }
    qr.clear();
    qr.extend((0..n).map(&r));
    for p in 0..k {
        reflect(p, qr, &|i| i);
    }

    // Rᵀ y = D s, forward (R_qp, q < p, is entry q of column p).
    x.clear();
    for p in 0..k {
        let mut v = s(p) * scale[p];
        for (q, &xq) in x.iter().enumerate() {
            v -= h[p * n + q] * xq;
        }
        x.push(v / diag[p]);
    }
    // (QᵀWQ)₂₂ z = (Qᵀr)₂ − (QᵀWQ)₂₁ y, by the pivoted elimination.
    let m = n - k;
    if m > 0 {
        red.clear();
        rhs.clear();
        for i in k..n {
            red.extend_from_slice(&wq[i * n + k..(i + 1) * n]);
            let mut v = qr[i];
            for (p, &yp) in x.iter().enumerate() {
                v -= wq[i * n + p] * yp;
            }
            rhs.push(v);
        }
        col.clear();
        col.extend(0..m);
        z.clear();
        z.resize(m, T::zero());
        let (pivot_ratio, singular, _) = eliminate(red, rhs, col, m);
        if singular {
            return Err(SaddleFailure::Singular { pivot_ratio });
        }
        back_substitute(red, rhs, col, z, m);
        x.extend_from_slice(z);
    }
    // R μ̃ = (QᵀWQ)₁ [y; z] − (Qᵀr)₁, backward (R_pq, q > p, is entry p of column q).
    mu.clear();
    mu.resize(k, T::zero());
    for p in (0..k).rev() {
        let mut v = -qr[p];
        for (c, &xc) in x.iter().enumerate() {
            v += wq[p * n + c] * xc;
        }
        for q in p + 1..k {
            v -= h[q * n + p] * mu[q];
        }
        mu[p] = v / diag[p];
    }
    // q̈ = Q [y; z], and μ = D μ̃.
    for p in (0..k).rev() {
        reflect(p, x, &|i| i);
    }
    ws.x.clear();
    ws.x.extend_from_slice(x);
    ws.x.extend(mu.iter().zip(scale.iter()).map(|(&m, &d)| m * d));
    if ws.x.iter().any(|v| !v.re().is_finite()) {
        return Err(SaddleFailure::NonFinite);
    }
    Ok(())
}

/// In-place Gaussian elimination with complete pivoting on the row-major `m × m` matrix `a` and
/// right-hand side `b`; `col` records the column permutation. Pivots are chosen by the magnitude of
/// the real part. Returns the pivot ratio, whether the matrix is singular to working precision, and
/// the sign of its determinant (0 when singular).
fn eliminate<T: Real>(a: &mut [T], b: &mut [T], col: &mut [usize], m: usize) -> (f64, bool, f64) {
    let mut max_pivot = 0.0f64;
    let mut min_pivot = f64::INFINITY;
    // The sign of the determinant: of each pivot, and of each swap of rows or columns.
    let mut sign = 1.0f64;
    for k in 0..m {
        let (mut pr, mut pc, mut best) = (k, k, -1.0f64);
        for i in k..m {
            for c in k..m {
                let v = a[i * m + c].re().abs();
                if v > best {
                    (pr, pc, best) = (i, c, v);
                }
            }
        }
        max_pivot = max_pivot.max(best);
        min_pivot = min_pivot.min(best);
        if best == 0.0 || best <= SINGULAR_PIVOT_RATIO * max_pivot {
            return (best / max_pivot.max(f64::MIN_POSITIVE), true, 0.0);
        }
        if pr != k {
            sign = -sign;
            for c in 0..m {
                a.swap(k * m + c, pr * m + c);
            }
            b.swap(k, pr);
        }
        if pc != k {
            sign = -sign;
            for i in 0..m {
                a.swap(i * m + k, i * m + pc);
            }
            col.swap(k, pc);
        }
        let pivot = a[k * m + k];
        sign *= pivot.re().signum();
        for i in k + 1..m {
            // No skip where `l` is zero: a dual number whose value is zero may still carry a
            // derivative (a constraint gradient `2q̇` with `q̇_i = 0`, seeded along `q̇_i`), and
            // `==` compares values only.
            let l = a[i * m + k] / pivot;
            for c in k + 1..m {
                let u = a[k * m + c];
                a[i * m + c] -= l * u;
            }
            a[i * m + k] = T::zero();
            let bk = b[k];
            b[i] -= l * bk;
        }
    }
    (min_pivot / max_pivot, false, sign)
}

/// Solves the upper-triangular system left by [`eliminate`] and undoes the column permutation.
fn back_substitute<T: Real>(a: &[T], b: &[T], col: &[usize], x: &mut [T], m: usize) {
    for k in (0..m).rev() {
        let mut acc = b[k];
        for c in k + 1..m {
            acc -= a[k * m + c] * x[col[c]];
        }
        x[col[k]] = acc / a[k * m + k];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::{Matrix3, Vector3};

    /// `q̈` and `μ` of `W = [[2, 0.4, 0], [0.4, 1, 0.3], [0, 0.3, 3]]`, `J = 2 q̇ᵀ`,
    /// `r = (0, 0, −9.81)`, `s = 0`, at `q̇ = (u, v, 0.3)`.
    fn coupled<T: Real>(u: T, v: T) -> Vec<T> {
        let w = [[2.0, 0.4, 0.0], [0.4, 1.0, 0.3], [0.0, 0.3, 3.0]];
        let (j, r) = ([u * 2.0, v * 2.0, T::from(0.6)], [0.0, 0.0, -9.81]);
        let mut ws = SaddleWorkspace::default();
        solve_blocks(
            &mut ws,
            3,
            1,
            |i, k| T::from(w[i][k]),
            |_, i| j[i],
            |i| T::from(r[i]),
            |_| T::zero(),
        )
        .expect("regular");
        ws.solution().to_vec()
    }

    #[test]
    fn derivatives_pass_through_an_entry_whose_value_is_zero() {
        // At v = 0 the entry J_2 = 2v is zero in value but not in its derivative along v: the
        // elimination must not skip it. Against central differences of the f64 solve.
        use num_dual::Dual64;
        let (u, h) = (2.2, 1e-6);
        let x = coupled(Dual64::from_re(u), Dual64::new(0.0, 1.0));
        let (p, m) = (coupled(u, h), coupled(u, -h));
        for (i, xi) in x.iter().enumerate() {
            let fd = (p[i] - m[i]) / (2.0 * h);
            assert!(
                (xi.eps - fd).abs() < 1e-7 * fd.abs().max(1.0),
                "{i}: {} against {fd}",
                xi.eps
            );
        }
    }

    /// The failure of the block solve with `W` and `J` (and zero right-hand sides).
    fn failure<const N: usize, const K: usize>(
        w: &SMatrix<f64, N, N>,
        j: &SMatrix<f64, K, N>,
    ) -> SaddleFailure {
        let (r, s) = (SVector::zeros(), SVector::zeros());
        solve(&mut SaddleWorkspace::default(), w, j, &r, &s).expect_err("a failure")
    }

    #[test]
    fn solves_a_saddle_system_with_singular_w() {
        // W singular (no kinetic term in the second coordinate), but regular on ker J.
        let w = SMatrix::<f64, 2, 2>::new(2.0, 0.0, 0.0, 0.0);
        let j = SMatrix::<f64, 1, 2>::new(1.0, 3.0);
        let r = SVector::<f64, 2>::new(1.0, -2.0);
        let s = SVector::<f64, 1>::new(0.5);
        let sol = solve(&mut SaddleWorkspace::default(), &w, &j, &r, &s).expect("regular");
        let full = Matrix3::new(2.0, 0.0, -1.0, 0.0, 0.0, -3.0, 1.0, 3.0, 0.0);
        let x = full
            .full_piv_lu()
            .solve(&Vector3::new(1.0, -2.0, 0.5))
            .expect("regular");
        assert_relative_eq!(sol.qdd[0], x[0], max_relative = 1e-14);
        assert_relative_eq!(sol.qdd[1], x[1], max_relative = 1e-14);
        assert_relative_eq!(sol.mu[0], x[2], max_relative = 1e-14);
    }

    #[test]
    fn the_determinants_sign_is_that_of_the_full_block_matrix() {
        // Against nalgebra's determinant of [W −Jᵀ; J 0], over metrics of every inertia, with
        // and without a constraint (the sign of a positive definite W is +1 either way).
        let sign_of = |w: SMatrix<f64, 2, 2>, j: Option<SMatrix<f64, 1, 2>>| {
            let mut ws = SaddleWorkspace::default();
            let (r, s) = (
                SVector::<f64, 2>::new(1.0, -2.0),
                SVector::<f64, 1>::new(0.5),
            );
            match j {
                Some(j) => {
                    solve(&mut ws, &w, &j, &r, &s).expect("regular");
                    let full = Matrix3::new(
                        w[(0, 0)],
                        w[(0, 1)],
                        -j[0],
                        w[(1, 0)],
                        w[(1, 1)],
                        -j[1],
                        j[0],
                        j[1],
                        0.0,
                    );
                    (ws.det_sign(), full.determinant().signum())
                }
                None => {
                    let none = SMatrix::<f64, 0, 2>::zeros();
                    solve(&mut ws, &w, &none, &r, &SVector::<f64, 0>::zeros()).expect("regular");
                    (ws.det_sign(), w.determinant().signum())
                }
            }
        };
        let metrics = [
            SMatrix::<f64, 2, 2>::new(2.0, 0.4, 0.4, 1.0),
            SMatrix::<f64, 2, 2>::new(1.0, 0.0, 0.0, -0.5),
            SMatrix::<f64, 2, 2>::new(-1.0, 0.2, 0.2, -3.0),
            SMatrix::<f64, 2, 2>::new(0.0, 1.0, 1.0, 0.0),
        ];
        let j = SMatrix::<f64, 1, 2>::new(1.0, 3.0);
        for w in metrics {
            for j in [None, Some(j)] {
                let (got, want) = sign_of(w, j);
                assert_eq!(got, want, "W = {w}, J = {j:?}");
            }
        }
        assert_eq!(sign_of(metrics[0], Some(j)).0, 1.0);
    }

    /// The solution by elimination and by the null-space method of `[W −Jᵀ; J 0] x = [r; s]`, for
    /// `W` and `J` given row-major, with entries made from `u` (a dual number carries their
    /// derivative along `u`).
    fn both_ways<T: Real>(w: &[f64], j: &[f64], n: usize, k: usize, u: T) -> (Vec<T>, Vec<T>) {
        let wf = |i: usize, m: usize| u * w[i * n + m] + w[i * n + m] * w[i * n + m];
        let jf = |a: usize, i: usize| u * u * j[a * n + i] + (a + 2 * i) as f64;
        let rf = |i: usize| u * (i as f64 - 1.5);
        let sf = |a: usize| u * 0.5 + a as f64;
        let mut ws = SaddleWorkspace::default();
        solve_blocks(&mut ws, n, k, wf, jf, rf, sf).expect("regular");
        let eliminated = ws.solution().to_vec();
        solve_null_space(&mut ws, (n, k), wf, jf, rf, sf).expect("regular");
        (eliminated, ws.solution().to_vec())
    }

    #[test]
    fn the_null_space_method_agrees_with_the_elimination_values_and_derivatives() {
        // Well conditioned: positive definite, indefinite (regular on ker J) and singular W; as
        // many constraints as coordinates; one constraint.
        let cases: [(&[f64], &[f64], usize, usize); 5] = [
            (
                &[2.0, 0.4, 0.0, 0.4, 1.0, 0.3, 0.0, 0.3, 3.0],
                &[1.0, -2.0, 0.5, 0.3, 1.0, 2.0],
                3,
                2,
            ),
            (
                &[1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 2.0],
                &[1.0, 0.0, 1.0, 0.0, 2.0, 0.0],
                3,
                2,
            ),
            (&[1.0, 0.0, 0.0, 0.0], &[1.0, 3.0], 2, 1),
            (&[1.0, 0.5, 0.5, 2.0], &[1.0, 3.0, -2.0, 0.5], 2, 2),
            (
                &[
                    4.0, 1.0, 0.0, 0.0, 1.0, 3.0, 0.5, 0.0, 0.0, 0.5, 2.0, 0.1, 0.0, 0.0, 0.1, 1.0,
                ],
                &[0.2, -1.0, 0.7, 1.5],
                4,
                1,
            ),
        ];
        use num_dual::Dual64;
        for (w, j, n, k) in cases {
            let (a, b) = both_ways(w, j, n, k, 1.3);
            for (x, y) in a.iter().zip(&b) {
                assert!((x - y).abs() <= 1e-13 * x.abs().max(1.0), "{x} against {y}");
            }
            let (a, b) = both_ways(w, j, n, k, Dual64::new(1.3, 1.0));
            for (x, y) in a.iter().zip(&b) {
                assert!(
                    (x.eps - y.eps).abs() <= 1e-12 * x.eps.abs().max(1.0),
                    "{} against {}",
                    x.eps,
                    y.eps
                );
            }
        }
    }

    #[test]
    fn nearly_dependent_rows_are_told_by_their_angle_not_their_size() {
        let mut scratch = NullSpace::default();
        let mut dependent =
            |rows: [f64; 6]| nearly_dependent(&mut scratch, 3, 2, |a, i| rows[a * 3 + i]);
        assert!(!dependent([1.0, 0.0, 0.0, 0.0, 1e-9, 0.0]));
        assert!(!dependent([1.0, 2.0, 0.0, 1.0, 2.0, 0.05]));
        assert!(dependent([1.0, 2.0, 0.0, 1e9, 2e9, 1e6]));
        assert!(dependent([1.0, 2.0, 0.0, 1.0, 2.0, 0.0]));
    }

    #[test]
    fn the_null_space_method_reports_dependent_constraints_and_a_singular_block() {
        let mut ws = SaddleWorkspace::default();
        let w = |i: usize, m: usize| if i == m { 1.0 } else { 0.0 };
        let dependent = [1.0, 2.0, 2.0, 4.0];
        let err = solve_null_space(
            &mut ws,
            (2, 2),
            w,
            |a, i| dependent[a * 2 + i],
            |_| 1.0,
            |_| 0.0,
        )
        .expect_err("dependent rows");
        assert!(matches!(err, SaddleFailure::Singular { .. }), "{err:?}");
        let err = solve_null_space(&mut ws, (2, 1), w, |_, _| 0.0, |_| 1.0, |_| 0.0)
            .expect_err("zero row");
        assert_eq!(err, SaddleFailure::ZeroConstraintRow { row: 0 });
        // W vanishes on ker J = span (1, 0).
        let w = |i: usize, m: usize| if i == 1 && m == 1 { 1.0 } else { 0.0 };
        let err = solve_null_space(&mut ws, (2, 1), w, |_, i| i as f64, |_| 1.0, |_| 0.0)
            .expect_err("singular on ker J");
        assert!(matches!(err, SaddleFailure::Singular { .. }), "{err:?}");
    }

    #[test]
    fn duplicated_constraint_is_singular() {
        let w = SMatrix::<f64, 2, 2>::identity();
        let j = SMatrix::<f64, 2, 2>::new(1.0, 2.0, 1.0, 2.0);
        let err = failure(&w, &j);
        assert!(matches!(err, SaddleFailure::Singular { .. }), "{err:?}");
    }

    #[test]
    fn zero_constraint_row_is_named() {
        let w = SMatrix::<f64, 2, 2>::identity();
        let j = SMatrix::<f64, 1, 2>::zeros();
        let err = failure(&w, &j);
        assert_eq!(err, SaddleFailure::ZeroConstraintRow { row: 0 });
    }

    #[test]
    fn singular_w_on_the_tangent_space_is_singular() {
        // W = 0 in the direction (1, 0), and J = (0, 1) leaves exactly that direction free.
        let w = SMatrix::<f64, 2, 2>::new(0.0, 0.0, 0.0, 1.0);
        let j = SMatrix::<f64, 1, 2>::new(0.0, 1.0);
        let err = failure(&w, &j);
        assert!(matches!(err, SaddleFailure::Singular { .. }), "{err:?}");
    }

    #[test]
    fn non_finite_input_is_reported() {
        let w = SMatrix::<f64, 1, 1>::new(f64::NAN);
        let j = SMatrix::<f64, 0, 1>::zeros();
        let err = failure(&w, &j);
        assert_eq!(err, SaddleFailure::NonFinite);
    }
}
