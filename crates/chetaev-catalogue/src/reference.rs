//! What a catalogue motion is compared with: a closed form or an invariant, where it comes from,
//! and the comparison of a recorded [`Solution`] with it.

use std::fmt;

use chetaev::model::Fixed;
use chetaev::prelude::*;

use crate::error::Error;

/// A ready problem and its reference: a static model `M` on `N` coordinates with `K` constraints
/// (wrapped in [`Fixed`] by [`Problem::new`]; `entry.problem.model()` dereferences to `M`), and
/// what its motion must satisfy.
#[derive(Clone, Debug)]
pub struct Entry<M, R, const N: usize, const K: usize> {
    /// The problem: model, initial time and a consistent initial state.
    pub problem: Problem<Fixed<M, N, K>>,
    /// What its motion must satisfy.
    pub reference: R,
}

/// A published source of a reference.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Source {
    /// Authors, title, publisher or journal, year.
    pub work: &'static str,
    /// Where in the work: section, pages, equations.
    pub location: &'static str,
}

/// Works several entries cite, written once.
pub mod works {
    /// Bloch's book, which treats the knife edge, the rolling disk and the Chaplygin sleigh.
    pub const BLOCH: &str = "A. M. Bloch, Nonholonomic Mechanics and Control, Springer (2003)";
    /// Neimark and Fufaev's monograph.
    pub const NEIMARK_FUFAEV: &str =
        "Ju. I. Neimark, N. A. Fufaev, Dynamics of Nonholonomic Systems, AMS Translations of \
         Mathematical Monographs 33 (1972)";
}

impl fmt::Display for Source {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}, {}", self.work, self.location)
    }
}

/// What kind of quantity a [`Check`] compares; tests allow each kind its own tolerance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Kind {
    /// A coordinate, or a position on the orbit.
    Position,
    /// A velocity (generalised or body velocity).
    Velocity,
    /// A time predicted from the state (the time since a periapsis, say).
    Time,
    /// A Lagrange multiplier `μ` (Newton form).
    Multiplier,
    /// A quantity that stays at its initial value (energy, a momentum-like invariant).
    Invariant,
}

/// One predicted quantity at one recorded point of a motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Check {
    /// Symbol of the quantity (`"x"`, `"ẏ"`, `"μ"`, `"E"`, ...).
    pub name: &'static str,
    /// What kind of quantity it is.
    pub kind: Kind,
    /// The value taken from the integrated motion.
    pub computed: f64,
    /// The value the reference predicts.
    pub reference: f64,
    /// The scale against which the difference is measured: the size of the quantity along the
    /// motion (never zero).
    pub scale: f64,
}

impl Check {
    /// A check; a `scale` that is not finite and positive is replaced by 1.
    pub fn new(name: &'static str, kind: Kind, computed: f64, reference: f64, scale: f64) -> Self {
        let scale = if scale.is_finite() && scale > 0.0 {
            scale
        } else {
            1.0
        };
        Self {
            name,
            kind,
            computed,
            reference,
            scale,
        }
    }

    /// The check of the multiplier `μ` of a single constraint (named `"μ"`).
    pub fn multiplier(computed: f64, reference: f64, scale: f64) -> Self {
        Self::new("μ", Kind::Multiplier, computed, reference, scale)
    }

    /// `|computed − reference| / scale`.
    pub fn error(&self) -> f64 {
        (self.computed - self.reference).abs() / self.scale
    }
}

/// A reference for a motion with `N` coordinates and `K` constraints: a closed form or an
/// invariant, with its sources.
pub trait Reference<const N: usize, const K: usize> {
    /// Where the reference comes from.
    fn sources(&self) -> &[Source];

    /// The quantities predicted at the recorded point `(t, q, q̇)`, with the multipliers `μ` where
    /// they were recorded, each paired with the value taken from the motion.
    fn checks(
        &self,
        t: f64,
        q: &SVector<f64, N>,
        qd: &SVector<f64, N>,
        mu: Option<&SVector<f64, K>>,
    ) -> Vec<Check>;

    /// [`Reference::checks`] at a point given as slices, as a [`Solution`] records it:
    /// `checks_at(sol.t[i], &sol.q[i], &sol.qd[i], sol.mu.get(i))`.
    ///
    /// Fails with [`Error::WrongLength`] if `q` or `q̇` does not have `N` entries, or `μ` not `K`
    /// (the point of a motion of another model).
    fn checks_at(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        mu: Option<&[f64]>,
    ) -> Result<Vec<Check>, Error> {
        let q = vector::<N>("q", q)?;
        let qd = vector::<N>("q̇", qd)?;
        let mu = mu.map(|mu| vector::<K>("μ", mu)).transpose()?;
        Ok(self.checks(t, &q, &qd, mu.as_ref()))
    }

    /// The largest [`Check::error`] of [`Reference::checks_at`] at one recorded point; a NaN (a
    /// reference or a motion that left its domain) counts as infinite, as in [`compare`].
    fn error_at(&self, t: f64, q: &[f64], qd: &[f64], mu: Option<&[f64]>) -> Result<f64, Error> {
        Ok(self
            .checks_at(t, q, qd, mu)?
            .iter()
            .fold(0.0, |acc, c| acc.max(counted(c.error()))))
    }
}

/// An error as the comparisons count it: a NaN as the worst, infinite.
fn counted(e: f64) -> f64 {
    if e.is_nan() {
        f64::INFINITY
    } else {
        e
    }
}

/// `v` as an `SVector` of length `L`, or [`Error::WrongLength`].
fn vector<const L: usize>(what: &'static str, v: &[f64]) -> Result<SVector<f64, L>, Error> {
    if v.len() == L {
        Ok(SVector::from_column_slice(v))
    } else {
        Err(Error::WrongLength {
            what,
            got: v.len(),
            expected: L,
        })
    }
}

/// The largest error of one quantity over a motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuantityError {
    /// Symbol of the quantity.
    pub name: &'static str,
    /// Its kind.
    pub kind: Kind,
    /// The largest [`Check::error`] over the recorded points.
    pub error: f64,
    /// Where it occurred.
    pub t: f64,
}

/// A recorded motion compared with its reference: the largest error of each quantity.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Comparison {
    /// One entry per quantity, in the order the reference lists them.
    pub quantities: Vec<QuantityError>,
}

impl Comparison {
    /// The largest error over all quantities (0 if there are none).
    pub fn max(&self) -> f64 {
        self.quantities.iter().fold(0.0, |acc, q| acc.max(q.error))
    }

    /// The largest error over the quantities of one kind (0 if there are none).
    pub fn max_of(&self, kind: Kind) -> f64 {
        self.quantities
            .iter()
            .filter(|q| q.kind == kind)
            .fold(0.0, |acc, q| acc.max(q.error))
    }

    /// The quantity with the largest error.
    pub fn worst(&self) -> Option<&QuantityError> {
        self.quantities
            .iter()
            .max_by(|a, b| a.error.total_cmp(&b.error))
    }
}

/// Compares every recorded point of `solution` with `reference`.
///
/// Fails with [`Error::WrongLength`] if the solution is not a motion with `N` coordinates and `K`
/// constraints (the solution of another entry's problem).
pub fn compare<R, const N: usize, const K: usize>(
    solution: &Solution,
    reference: &R,
) -> Result<Comparison, Error>
where
    R: Reference<N, K> + ?Sized,
{
    for (what, got, expected) in [
        ("the solution's q", solution.n(), N),
        ("the solution's μ", solution.k(), K),
    ] {
        if got != expected {
            return Err(Error::WrongLength {
                what,
                got,
                expected,
            });
        }
    }
    let mut out = Comparison::default();
    for i in 0..solution.len() {
        let checks = reference.checks_at(
            solution.t[i],
            &solution.q[i],
            &solution.qd[i],
            solution.mu.get(i),
        )?;
        for c in checks {
            let e = counted(c.error());
            match out.quantities.iter_mut().find(|q| q.name == c.name) {
                Some(q) if e > q.error => {
                    q.error = e;
                    q.t = solution.t[i];
                }
                Some(_) => {}
                None => out.quantities.push(QuantityError {
                    name: c.name,
                    kind: c.kind,
                    error: e,
                    t: solution.t[i],
                }),
            }
        }
    }
    Ok(out)
}

/// The largest `|E(t) − E(t0) − W_Φ(t) + ∫∂L/∂t dt|` over the motion
/// ([`Solution::energy_balance`]; 0 if the energy was not recorded).
pub fn max_energy_balance(solution: &Solution) -> f64 {
    match solution.max_energy_balance() {
        None => 0.0,
        Some(b) if b.is_nan() => f64::INFINITY,
        Some(b) => b,
    }
}

/// `∫ |Φ|·|q̇| dt` over the recorded points (trapezoidal rule; 0 if `Φ` was not recorded): the
/// size of the power the work `W_Φ = ∫ q̇·Φ dt` is integrated from, and so the scale of the error of
/// that quadrature and of the energy balance. For a constraint linear and homogeneous in `q̇`,
/// `q̇·Φ = μ·f` vanishes on the constraints although neither `Φ` nor `q̇` does.
pub fn absolute_work(solution: &Solution) -> f64 {
    if solution.phi.len() != solution.len() {
        return 0.0;
    }
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let power = |i: usize| norm(&solution.phi[i]) * norm(&solution.qd[i]);
    (1..solution.len())
        .map(|i| 0.5 * (power(i - 1) + power(i)) * (solution.t[i] - solution.t[i - 1]).abs())
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{knife_edge, rolling_disk};

    #[test]
    fn a_motion_of_another_model_is_refused_with_its_sizes() {
        let knife = knife_edge::entry(&knife_edge::Params::default()).expect("valid");
        let disk = rolling_disk::entry(&rolling_disk::Params::default()).expect("valid");
        let options = Options::until(0.5);
        let sol = solve(&disk.problem, Dop853::default(), &options).expect("valid options");
        assert_eq!(
            compare(&sol, &knife.reference),
            Err(Error::WrongLength {
                what: "the solution's q",
                got: 4,
                expected: 3
            })
        );
        let mu = [0.0, 0.0];
        assert_eq!(
            knife
                .reference
                .checks_at(0.0, &[0.0; 3], &[0.0, 0.0, 1.0], Some(&mu)),
            Err(Error::WrongLength {
                what: "μ",
                got: 2,
                expected: 1
            })
        );
        // The entry's own motion compares, point by point as `checks` does.
        let sol = solve(&knife.problem, Dop853::default(), &options).expect("valid options");
        let cmp = compare(&sol, &knife.reference).expect("same sizes");
        assert_eq!(cmp.quantities.len(), 8);
        let i = sol.len() - 1;
        let by_slices = knife
            .reference
            .checks_at(sol.t[i], &sol.q[i], &sol.qd[i], sol.mu.get(i))
            .expect("same sizes");
        let by_vectors = knife.reference.checks(
            sol.t[i],
            &SVector::from_column_slice(&sol.q[i]),
            &SVector::from_column_slice(&sol.qd[i]),
            Some(&SVector::from_column_slice(&sol.mu[i])),
        );
        assert_eq!(by_slices, by_vectors);
        // The error at a point is the largest of its checks; a point outside the reference's
        // domain (here a NaN state) is the worst, not a NaN that every comparison would pass.
        let at = |q: &[f64]| {
            knife
                .reference
                .error_at(sol.t[i], q, &sol.qd[i], sol.mu.get(i))
        };
        let largest = by_slices.iter().map(Check::error).fold(0.0, f64::max);
        assert_eq!(at(&sol.q[i]), Ok(largest));
        assert_eq!(at(&[f64::NAN, 0.0, 0.0]), Ok(f64::INFINITY));
    }
}
