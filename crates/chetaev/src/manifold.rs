//! The constraint manifold: a state's dependent coordinates and speeds completed from the
//! independent ones, and the reduced equations linearised on it.
//!
//! A state `(q, q̇)` of a constrained system lies on the manifold
//!
//! ```text
//! h(t, q) = 0          kh holonomic constraints
//! f(t, q, q̇) = 0       kv velocity constraints, and ḣ = (∂h/∂q) q̇ + ∂h/∂t = 0
//! ```
//!
//! so `kh` coordinates and `k = kv + kh` speeds are fixed by the others. Kane's users name the
//! independent ones and let the constraints give the rest; [`complete`] does that by Newton's
//! method, first the dependent coordinates from `h = 0` with the independent coordinates held,
//! then the dependent speeds from the velocity-level rows with `q` and the independent speeds
//! held. The dependent values given serve as the first guess (a constraint nonlinear in the
//! speeds may have several solutions: the one nearest the guess is found).
//!
//! [`Problem::linearize`](crate::Problem::linearize) linearises the reduced equations
//! `ẏ = F(t, y)`, `y = (q, q̇)`, at a state on the manifold: with `A = ∂F/∂y` (exact, by automatic
//! differentiation, the Jacobian an implicit method uses) and the manifold's tangent space written
//! in the independent components `z` (`δy = T δz`, the dependent components from
//! `G_dep δy_dep = −G_ind δz`, `G` the gradient of the constraints above), the linearised motion is
//!
//! ```text
//! δż = A_z δz,    A_z = P A T    (P picks the independent components)
//! ```
//!
//! a matrix of size `p = 2n − kh − k`. Its eigenvalues are those of the motion on the manifold;
//! the directions off it (which the constraints forbid) are not among them. A coordinate on which
//! nothing depends there (a cyclic coordinate: a position on the ground, a wheel's angle) gives a
//! zero column of `A_z` and so an eigenvalue exactly zero, listed in [`Linearization::cyclic`];
//! so does a speed that nothing changes (a zero row). A neutral direction that is neither (a
//! heading, which the rolling constraints read, along a straight steady motion) also has an
//! eigenvalue zero, found by the eigenvalue solver to about the square root of the rounding where
//! it is repeated.

use nalgebra::{Complex, DMatrix};

use crate::equations::derivatives::ConstraintBlocks;
use crate::error::Error;
use crate::integrate::projection::constraint_scale;
use crate::integrate::system::{Jacobian, OdeSystem, ReducedOde};
use crate::model::{Model, Point};
use crate::problem::{check_state, holonomic_rounding, ROUNDING_ULPS, STATE};
use crate::Problem;

/// Which coordinates and speeds are independent (indices from 0). `None` lets them be chosen: the
/// dependent ones are those of the largest pivots of the constraints' gradient (complete
/// pivoting), which keeps the dependent block best conditioned.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Independent {
    /// The `n − kh` independent coordinates, or `None`.
    pub coordinates: Option<Vec<usize>>,
    /// The `n − kv − kh` independent speeds, or `None`.
    pub speeds: Option<Vec<usize>>,
}

impl Independent {
    /// Both chosen automatically.
    pub fn automatic() -> Self {
        Self::default()
    }

    /// These coordinates and speeds.
    pub fn new(coordinates: Vec<usize>, speeds: Vec<usize>) -> Self {
        Self {
            coordinates: Some(coordinates),
            speeds: Some(speeds),
        }
    }

    /// The dependent coordinates among `n` under `kh` holonomic constraints of gradient `hq`
    /// (row-major `kh × n`, read only where they are to be chosen).
    fn dependent_coordinates(&self, n: usize, kh: usize, hq: &[f64]) -> Result<Vec<usize>, Error> {
        match &self.coordinates {
            Some(ind) => dependent_of(ind, n, kh, "coordinates", "holonomic constraints"),
            None => Ok(pivot_columns(hq, kh, n)),
        }
    }

    /// The dependent speeds among `n` under `k` velocity-level rows of gradient `j` in `q̇`.
    fn dependent_speeds(&self, n: usize, k: usize, j: &[f64]) -> Result<Vec<usize>, Error> {
        match &self.speeds {
            Some(ind) => dependent_of(
                ind,
                n,
                k,
                "speeds",
                "velocity constraints and holonomic rates",
            ),
            None => Ok(pivot_columns(j, k, n)),
        }
    }
}

/// A completed state: `q` and `q̇` on the constraints, and which components were solved for.
#[derive(Clone, Debug, PartialEq)]
pub struct Completion {
    /// The coordinates, the dependent ones solved for.
    pub q: Vec<f64>,
    /// The speeds, the dependent ones solved for.
    pub qd: Vec<f64>,
    /// The dependent coordinates (solved from `h = 0`), increasing.
    pub dependent_coordinates: Vec<usize>,
    /// The dependent speeds (solved from `f = 0` and `ḣ = 0`), increasing.
    pub dependent_speeds: Vec<usize>,
    /// Newton iterations for the coordinates and for the speeds.
    pub iterations: (usize, usize),
}

/// Newton iterations before giving up.
pub const MAX_COMPLETION_ITERATIONS: usize = 50;

/// The relative residual at which a completion stops: `|g_a| ≤ 1e-14 · |∂g_a/∂x|·|x|` for every
/// row (or the rounding of `h`'s terms, for a position next to the coordinates' origin).
pub const COMPLETION_TOLERANCE: f64 = 1e-14;

/// Completes `(q, q̇)` at time `t`: the dependent coordinates from `h(t, q) = 0`, then the
/// dependent speeds from the velocity constraints and `ḣ = 0`, each by Newton's method from the
/// values given. See the [module](self) docs.
///
/// Errors: [`Error::InvalidModel`] for indices out of range, repeated, or of the wrong number;
/// [`Error::Completion`] where Newton's method does not converge or the dependent block is
/// singular, naming the constraint and why.
///
/// ```
/// use chetaev::manifold::{complete, Independent};
/// use chetaev::prelude::*;
///
/// // A particle on the circle x² + y² = 1 (holonomic): give x, complete y; give ẋ, complete ẏ.
/// struct Ring;
/// impl DynModel for Ring {
///     fn sizes(&self) -> (usize, usize) { (2, 0) }
///     fn lagrangian<R: Real>(&self, _t: R, _q: &[R], qd: &[R]) -> R {
///         (qd[0] * qd[0] + qd[1] * qd[1]) * 0.5
///     }
///     fn holonomic_count(&self) -> usize { 1 }
///     fn holonomic<R: Real>(&self, _t: R, q: &[R], h: &mut [R]) {
///         h[0] = q[0] * q[0] + q[1] * q[1] - 1.0;
///     }
/// }
/// let done = complete(&Ring, 0.0, &[0.6, 0.9], &[0.8, 0.0], &Independent::new(vec![0], vec![0]))?;
/// assert!((done.q[1] - 0.8).abs() < 1e-15 && (done.qd[1] + 0.6).abs() < 1e-15);
/// assert_eq!((done.dependent_coordinates, done.dependent_speeds), (vec![1], vec![1]));
/// # Ok::<(), chetaev::Error>(())
/// ```
pub fn complete<M: Model + ?Sized>(
    model: &M,
    t: f64,
    q: &[f64],
    qd: &[f64],
    independent: &Independent,
) -> Result<Completion, Error> {
    check_state(model, STATE, t, q, qd)?;
    let (n, k) = model.sizes();
    let kh = model.holonomic_count();
    let (mut q, mut qd) = (q.to_vec(), qd.to_vec());

    // Coordinates: h(t, q) = 0 for the dependent ones.
    let mut h = vec![0.0; kh];
    let mut hq = vec![0.0; kh * n];
    if independent.coordinates.is_none() {
        model.holonomic_blocks(t, &q, &mut h, Some(&mut hq));
    }
    let dep_q = independent.dependent_coordinates(n, kh, &hq)?;
    let it_q = newton(
        Stage::Coordinates,
        &mut q,
        &dep_q,
        kh,
        |q, g, dg| model.holonomic_blocks(t, q, g, Some(dg)),
        |q, g| {
            holonomic_rounding(model, t, q, &qd).is_some_and(|r| {
                g.iter()
                    .zip(r)
                    .all(|(g, r)| g.abs() <= ROUNDING_ULPS * f64::EPSILON * r)
            })
        },
        |row| (k - kh + row + 1, Some(row + 1)),
    )?;

    // Speeds: f(t, q, q̇) = 0 and ḣ = 0 for the dependent ones.
    let mut blocks = ConstraintBlocks::new(n, k);
    if independent.speeds.is_none() {
        model.constraint_blocks(Point::new(t, &q, &qd), false, &mut blocks);
    }
    let dep_qd = independent.dependent_speeds(n, k, &blocks.j)?;
    let it_qd = newton(
        Stage::Speeds,
        &mut qd,
        &dep_qd,
        k,
        |qd, g, dg| {
            model.constraint_blocks(Point::new(t, &q, qd), false, &mut blocks);
            g.copy_from_slice(&blocks.f);
            dg.copy_from_slice(&blocks.j);
        },
        |_, _| false,
        |row| {
            let holonomic = row.checked_sub(k - kh).map(|b| b + 1);
            (row + 1, holonomic)
        },
    )?;
    Ok(Completion {
        q,
        qd,
        dependent_coordinates: dep_q,
        dependent_speeds: dep_qd,
        iterations: (it_q, it_qd),
    })
}

/// The stage of a completion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    Coordinates,
    Speeds,
}

impl Stage {
    fn name(self) -> &'static str {
        match self {
            Stage::Coordinates => "coordinates",
            Stage::Speeds => "speeds",
        }
    }
}

/// The complement of the independent indices `ind` among `0..n`, after checking that they are in
/// range, distinct and `n − m` in number.
fn dependent_of(
    ind: &[usize],
    n: usize,
    m: usize,
    what: &str,
    rows: &str,
) -> Result<Vec<usize>, Error> {
    let mut seen = vec![false; n];
    for &i in ind {
        if i >= n {
            return Err(Error::InvalidModel {
                what: format!(
                    "independent {what}: index {i} is out of range for {n} coordinates (indices count from 0)"
                ),
            });
        }
        if std::mem::replace(&mut seen[i], true) {
            return Err(Error::InvalidModel {
                what: format!("independent {what}: index {i} is given twice"),
            });
        }
    }
    if ind.len() + m != n {
        return Err(Error::InvalidModel {
            what: format!(
                "{} independent {what} given, but {n} coordinates under {m} {rows} have {} (the others are solved for)",
                ind.len(),
                n.saturating_sub(m)
            ),
        });
    }
    Ok((0..n).filter(|&i| !seen[i]).collect())
}

/// The `m` columns of the row-major `m × n` matrix `g` that complete pivoting picks first,
/// increasing: the dependent components that keep their block best conditioned.
fn pivot_columns(g: &[f64], m: usize, n: usize) -> Vec<usize> {
    if m == 0 {
        return Vec::new();
    }
    let mut a = DMatrix::from_row_slice(m, n, g);
    let mut cols: Vec<usize> = (0..n).collect();
    for r in 0..m {
        // The largest entry of the remaining block.
        let (mut bi, mut bj, mut best) = (r, r, -1.0);
        for i in r..m {
            for j in r..n {
                let v = a[(i, j)].abs();
                if v > best {
                    (bi, bj, best) = (i, j, v);
                }
            }
        }
        a.swap_rows(r, bi);
        a.swap_columns(r, bj);
        cols.swap(r, bj);
        if best > 0.0 {
            for i in r + 1..m {
                let factor = a[(i, r)] / a[(r, r)];
                for j in r..n {
                    let v = a[(r, j)];
                    a[(i, j)] -= factor * v;
                }
            }
        }
    }
    let mut dep = cols[..m].to_vec();
    dep.sort_unstable();
    dep
}

/// Newton's method on `g(x) = 0` (`m` rows) for the components `dep` of `x`, the others held:
/// `eval(x, g, dg)` writes `g` and `∂g/∂x` (row-major `m × n`). `settled(x, g)` may accept a
/// residual at the rounding of the rows' terms; `row_name(a)` gives the row's number and, for a
/// holonomic one, its number among those. Returns the iterations done.
#[allow(clippy::too_many_arguments)]
fn newton(
    stage: Stage,
    x: &mut [f64],
    dep: &[usize],
    m: usize,
    mut eval: impl FnMut(&[f64], &mut [f64], &mut [f64]),
    mut settled: impl FnMut(&[f64], &[f64]) -> bool,
    row_name: impl Fn(usize) -> (usize, Option<usize>),
) -> Result<usize, Error> {
    if m == 0 {
        return Ok(0);
    }
    let n = x.len();
    let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
    let (mut g, mut dg) = (vec![0.0; m], vec![0.0; m * n]);
    // The worst row's residual relative to its scale `|∂g_a/∂x|·|x|` (as the projection measures
    // it), and the row.
    let worst = |g: &[f64], dg: &[f64], x: &[f64]| {
        let xn = norm(x);
        (0..m)
            .map(|a| {
                let r = g[a].abs() / constraint_scale(norm(&dg[a * n..(a + 1) * n]), xn);
                (if r.is_nan() { f64::INFINITY } else { r }, a)
            })
            .fold((0.0f64, 0usize), |acc, v| if v.0 > acc.0 { v } else { acc })
    };
    let fail = |iterations: usize, (residual, row): (f64, usize), why: String| {
        let (constraint, holonomic) = row_name(row);
        Error::Completion {
            stage: stage.name(),
            constraint,
            holonomic,
            residual,
            iterations,
            why,
        }
    };
    let mut previous_step = f64::INFINITY;
    for iteration in 0..=MAX_COMPLETION_ITERATIONS {
        eval(x, &mut g, &mut dg);
        let w = worst(&g, &dg, x);
        if !w.0.is_finite() || dg.iter().any(|v| !v.is_finite()) {
            return Err(fail(
                iteration,
                w,
                "a value is not finite there: the guess may lie outside the model's domain; give dependent values nearer a solution".into(),
            ));
        }
        if w.0 <= COMPLETION_TOLERANCE || (iteration > 0 && settled(x, &g)) {
            return Ok(iteration);
        }
        if iteration == MAX_COMPLETION_ITERATIONS {
            return Err(fail(
                iteration,
                w,
                "Newton's method did not converge: there may be no solution near the values given (a speed the constraints cannot reach), or the dependent block is nearly singular; give dependent values nearer a solution, or choose other independent ones".into(),
            ));
        }
        // The dependent block, solved with partial pivoting; its conditioning is checked.
        let block = DMatrix::from_fn(m, m, |a, j| dg[a * n + dep[j]]);
        let rhs = nalgebra::DVector::from_iterator(m, g.iter().map(|v| -v));
        let lu = block.clone().full_piv_lu();
        let pivots: Vec<f64> = (0..m).map(|i| lu.u()[(i, i)].abs()).collect();
        let (lo, hi) = pivots.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
        if !(hi > 0.0 && lo > 1e-13 * hi) {
            let names: Vec<String> = dep.iter().map(|i| (i + 1).to_string()).collect();
            return Err(fail(
                iteration,
                w,
                format!(
                    "the dependent {} (numbered from 1: {}) do not determine the constraints there (smallest over largest pivot {:.1e}): choose other independent {}, or let them be chosen",
                    stage.name(),
                    names.join(", "),
                    if hi > 0.0 { lo / hi } else { 0.0 },
                    stage.name()
                ),
            ));
        }
        let Some(step) = lu.solve(&rhs) else {
            return Err(fail(iteration, w, "the dependent block is singular".into()));
        };
        let step_norm = step.norm();
        for (j, &i) in dep.iter().enumerate() {
            x[i] += step[j];
        }
        // At the rounding floor a step no longer shrinks the residual: stop if it is tiny.
        let floor = 4.0 * f64::EPSILON * dep.iter().map(|&i| x[i] * x[i]).sum::<f64>().sqrt();
        if step_norm <= floor && previous_step <= floor.max(1e3 * f64::EPSILON) {
            eval(x, &mut g, &mut dg);
            return Ok(iteration + 1);
        }
        previous_step = step_norm;
    }
    unreachable!("the loop returns at its last iteration")
}

/// The reduced equations linearised on the constraint manifold at one state
/// ([`Problem::linearize`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Linearization {
    /// The time and state linearised about.
    pub t: f64,
    /// `q` there.
    pub q: Vec<f64>,
    /// `q̇` there.
    pub qd: Vec<f64>,
    /// The independent coordinates (indices from 0), the first components of `z`.
    pub coordinates: Vec<usize>,
    /// The independent speeds, the last components of `z`.
    pub speeds: Vec<usize>,
    /// `A_z`, row-major `p × p`, `p = coordinates.len() + speeds.len()`.
    pub a: Vec<f64>,
    /// The full Jacobian `A = ∂F/∂y`, `y = (q, q̇)`, row-major `2n × 2n`.
    pub full: Vec<f64>,
    /// The tangent basis `T`, row-major `2n × p`: `δy = T δz`.
    pub basis: Vec<f64>,
    /// The eigenvalues of `A_z`, sorted by real part, then imaginary part.
    pub eigenvalues: Vec<Complex<f64>>,
    /// The eigenvectors in `z`, one per eigenvalue in the same order, unit length.
    pub eigenvectors: Vec<Vec<Complex<f64>>>,
    /// The independent coordinates that neither `L` nor the constraints nor the forces depend on
    /// there (a zero column of `A_z`): each gives an eigenvalue zero.
    pub cyclic: Vec<usize>,
}

impl Linearization {
    /// The size `p` of `z`.
    pub fn dim(&self) -> usize {
        self.coordinates.len() + self.speeds.len()
    }
}

impl<M: Model> Problem<M> {
    /// The reduced equations linearised on the constraint manifold at `(t, q, q̇)`, in the
    /// independent coordinates and speeds of `independent` (chosen by pivoting where `None`):
    /// `A_z`, its eigenvalues and eigenvectors, and the cyclic coordinates. The state must lie on
    /// the constraints ([`complete`] puts it there); see the [module](self) docs.
    ///
    /// ```
    /// use chetaev::prelude::*;
    /// use chetaev::manifold::Independent;
    ///
    /// // A pendulum of length 1 in Cartesian coordinates, hanging at rest: eigenvalues ±i√g.
    /// struct Pendulum;
    /// impl Lagrangian<2> for Pendulum {
    ///     fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
    ///         qd.dot(qd) * 0.5 - q[1] * 9.81
    ///     }
    /// }
    /// impl Constraints<2, 0> for Pendulum {
    ///     fn holonomic_count(&self) -> usize { 1 }
    ///     fn holonomic<R: Real>(&self, _t: R, q: &SVector<R, 2>, h: &mut [R]) {
    ///         h[0] = q.dot(q) - 1.0;
    ///     }
    /// }
    /// let p = Problem::new(Pendulum, 0.0, SVector::from([0.0, -1.0]), SVector::zeros())?;
    /// let lin = p.linearize(0.0, &[0.0, -1.0], &[0.0, 0.0], &Independent::new(vec![0], vec![0]))?;
    /// assert_eq!(lin.dim(), 2);
    /// assert!((lin.eigenvalues[0].im + 9.81f64.sqrt()).abs() < 1e-12 && lin.eigenvalues[0].re.abs() < 1e-12);
    /// # Ok::<(), chetaev::Error>(())
    /// ```
    pub fn linearize(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        independent: &Independent,
    ) -> Result<Linearization, Error> {
        let model = self.model();
        check_state(model, STATE, t, q, qd)?;
        let (n, k) = model.sizes();
        let kh = model.holonomic_count();

        // A = ∂F/∂y of the reduced equations, exact.
        let mut ode = ReducedOde::for_problem(self, false);
        let dim = 2 * n;
        let mut jac = Jacobian::new(ode.dim());
        let y: Vec<f64> = q.iter().chain(qd).copied().collect();
        ode.jacobian(t, &y, &mut jac)?;
        let full_dim = ode.dim();
        let full: Vec<f64> = (0..dim)
            .flat_map(|i| jac.dy[i * full_dim..i * full_dim + dim].to_vec())
            .collect();

        // G = ∂(h; f, ḣ)/∂(q, q̇): m = kh + k rows.
        let m = kh + k;
        let mut g = vec![0.0; m * dim];
        if kh > 0 {
            let (mut h, mut hq) = (vec![0.0; kh], vec![0.0; kh * n]);
            model.holonomic_blocks(t, q, &mut h, Some(&mut hq));
            for b in 0..kh {
                g[b * dim..b * dim + n].copy_from_slice(&hq[b * n..(b + 1) * n]);
            }
        }
        if k > 0 {
            let mut blocks = ConstraintBlocks::<f64>::new(n, k);
            model.constraint_blocks(Point::new(t, q, qd), false, &mut blocks);
            for a in 0..k {
                let row = &mut g[(kh + a) * dim..(kh + a + 1) * dim];
                row[n..].copy_from_slice(&blocks.j[a * n..(a + 1) * n]);
            }
            // ∂f/∂q, a column at a time, by dual numbers.
            use num_dual::Dual64;
            let mut dual = ConstraintBlocks::<Dual64>::new(n, k);
            let tq = Dual64::from(t);
            let qdd: Vec<Dual64> = qd.iter().map(|&v| Dual64::from(v)).collect();
            for i in 0..n {
                let qq: Vec<Dual64> = q
                    .iter()
                    .enumerate()
                    .map(|(j, &v)| Dual64::new(v, if i == j { 1.0 } else { 0.0 }))
                    .collect();
                model.constraint_blocks(Point::new(tq, &qq, &qdd), false, &mut dual);
                for a in 0..k {
                    g[(kh + a) * dim + i] = dual.f[a].eps;
                }
            }
        }
        if g.iter().chain(&full).any(|v| !v.is_finite()) {
            return Err(Error::NonFiniteEvaluation {
                t,
                q: q.to_vec(),
                qd: qd.to_vec(),
            });
        }

        // The independent components.
        let mut hq = vec![0.0; kh * n];
        for b in 0..kh {
            hq[b * n..(b + 1) * n].copy_from_slice(&g[b * dim..b * dim + n]);
        }
        let dep_q = independent.dependent_coordinates(n, kh, &hq)?;
        let jqd: Vec<f64> = (0..k)
            .flat_map(|a| g[(kh + a) * dim + n..(kh + a + 1) * dim].to_vec())
            .collect();
        let dep_qd = independent.dependent_speeds(n, k, &jqd)?;
        let ind_q: Vec<usize> = (0..n).filter(|i| !dep_q.contains(i)).collect();
        let ind_qd: Vec<usize> = (0..n).filter(|i| !dep_qd.contains(i)).collect();
        let z: Vec<usize> = ind_q
            .iter()
            .copied()
            .chain(ind_qd.iter().map(|i| n + i))
            .collect();
        let d: Vec<usize> = dep_q
            .iter()
            .copied()
            .chain(dep_qd.iter().map(|i| n + i))
            .collect();
        let p = z.len();

        // T: identity on z, −G_d⁻¹ G_z on the dependent components.
        let gd = DMatrix::from_fn(m, m, |a, j| g[a * dim + d[j]]);
        let gz = DMatrix::from_fn(m, p, |a, j| g[a * dim + z[j]]);
        let lu = gd.full_piv_lu();
        let dz = if m > 0 {
            lu.solve(&(-gz)).ok_or_else(|| Error::Completion {
                stage: "speeds",
                constraint: 1,
                holonomic: None,
                residual: 0.0,
                iterations: 0,
                why: "the dependent components do not determine the constraints' tangent space there: choose other independent ones, or let them be chosen".into(),
            })?
        } else {
            DMatrix::zeros(0, p)
        };
        let mut basis = DMatrix::<f64>::zeros(dim, p);
        for (j, &zi) in z.iter().enumerate() {
            basis[(zi, j)] = 1.0;
        }
        for (r, &di) in d.iter().enumerate() {
            for j in 0..p {
                basis[(di, j)] = dz[(r, j)];
            }
        }
        let a_full = DMatrix::from_row_slice(dim, dim, &full);
        let pick = DMatrix::from_fn(p, dim, |i, j| if z[i] == j { 1.0 } else { 0.0 });
        let az = &pick * &a_full * &basis;

        let cyclic: Vec<usize> = ind_q
            .iter()
            .enumerate()
            .filter(|(j, _)| az.column(*j).iter().all(|v| *v == 0.0))
            .map(|(_, &i)| i)
            .collect();
        let (eigenvalues, eigenvectors) = eigen(&az);
        let row_major = |mat: &DMatrix<f64>| -> Vec<f64> {
            (0..mat.nrows())
                .flat_map(|i| (0..mat.ncols()).map(move |j| (i, j)))
                .map(|(i, j)| mat[(i, j)])
                .collect()
        };
        Ok(Linearization {
            t,
            q: q.to_vec(),
            qd: qd.to_vec(),
            coordinates: ind_q,
            speeds: ind_qd,
            a: row_major(&az),
            full,
            basis: row_major(&basis),
            eigenvalues,
            eigenvectors,
            cyclic,
        })
    }
}

/// The eigenvalues of a real square matrix, sorted by real then imaginary part, each with a unit
/// eigenvector (the right singular vector of `A − λI` for its smallest singular value).
///
/// A zero column or a zero row (a cyclic coordinate; a speed nothing changes) is an eigenvalue
/// exactly zero, and the others are those of the matrix without that row and column (expand the
/// determinant of `A − λI` along it): such rows and columns are taken out first, repeatedly, so
/// that their zeros are exact and do not spoil the rest (an iterative eigenvalue solver finds a
/// repeated zero only to about the square root of the rounding).
fn eigen(a: &DMatrix<f64>) -> (Vec<Complex<f64>>, Vec<Vec<Complex<f64>>>) {
    let p = a.nrows();
    if p == 0 {
        return (Vec::new(), Vec::new());
    }
    let mut keep: Vec<usize> = (0..p).collect();
    let mut values: Vec<Complex<f64>> = Vec::new();
    loop {
        let zero = keep.iter().position(|&i| {
            keep.iter().all(|&j| a[(j, i)] == 0.0) || keep.iter().all(|&j| a[(i, j)] == 0.0)
        });
        match zero {
            Some(at) => {
                keep.remove(at);
                values.push(Complex::new(0.0, 0.0));
            }
            None => break,
        }
    }
    if !keep.is_empty() {
        let rest = DMatrix::from_fn(keep.len(), keep.len(), |i, j| a[(keep[i], keep[j])]);
        values.extend(rest.complex_eigenvalues().iter().copied());
    }
    values.sort_by(|x, y| {
        x.re.partial_cmp(&y.re)
            .unwrap_or(std::cmp::Ordering::Equal)
            .then(x.im.partial_cmp(&y.im).unwrap_or(std::cmp::Ordering::Equal))
    });
    let ac = a.map(|v| Complex::new(v, 0.0));
    let vectors = values
        .iter()
        .map(|&lambda| {
            let shifted = &ac - DMatrix::<Complex<f64>>::identity(p, p) * lambda;
            let svd = shifted.svd(false, true);
            match svd.v_t {
                Some(vt) => {
                    // The smallest singular value's row (nalgebra sorts them decreasing).
                    let (i, _) = svd.singular_values.iter().enumerate().fold(
                        (0, f64::INFINITY),
                        |acc, (i, &s)| if s < acc.1 { (i, s) } else { acc },
                    );
                    vt.row(i).iter().map(|c| c.conj()).collect()
                }
                None => vec![Complex::new(f64::NAN, 0.0); p],
            }
        })
        .collect();
    (values, vectors)
}
