//! What a catalogue motion is compared with: a closed form or an invariant, where it comes from,
//! and the comparison of a recorded [`Solution`] with it.

use std::fmt;

use chetaev::prelude::*;

/// A ready problem and its reference.
#[derive(Clone, Debug)]
pub struct Entry<M, R, const N: usize, const K: usize> {
    /// The problem: model, initial time and a consistent initial state.
    pub problem: Problem<M, N, K>,
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
pub fn compare<R, const N: usize, const K: usize>(
    solution: &Solution<N, K>,
    reference: &R,
) -> Comparison
where
    R: Reference<N, K> + ?Sized,
{
    let mut out = Comparison::default();
    for i in 0..solution.len() {
        let mu = solution.mu.get(i);
        let checks = reference.checks(solution.t[i], &solution.q[i], &solution.qd[i], mu);
        for c in checks {
            // A NaN (a reference or a motion that left its domain) counts as the worst error.
            let e = if c.error().is_nan() {
                f64::INFINITY
            } else {
                c.error()
            };
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
    out
}

/// The largest `|E(t) − E(t0) − W_Φ(t) + ∫∂L/∂t dt|` over the motion
/// ([`Solution::energy_balance`]; 0 if the energy was not recorded).
pub fn max_energy_balance<const N: usize, const K: usize>(solution: &Solution<N, K>) -> f64 {
    solution.energy_balance().iter().fold(0.0f64, |acc, b| {
        if b.is_nan() {
            f64::INFINITY
        } else {
            acc.max(b.abs())
        }
    })
}

/// `∫ |Φ|·|q̇| dt` over the recorded points (trapezoidal rule; 0 if `Φ` was not recorded): the
/// size of the power the work `W_Φ = ∫ q̇·Φ dt` is integrated from, and so the scale of the error of
/// that quadrature and of the energy balance. For a constraint linear and homogeneous in `q̇`,
/// `q̇·Φ = μ·f` vanishes on the constraints although neither `Φ` nor `q̇` does.
pub fn absolute_work<const N: usize, const K: usize>(solution: &Solution<N, K>) -> f64 {
    if solution.phi.len() != solution.len() {
        return 0.0;
    }
    let power = |i: usize| solution.phi[i].norm() * solution.qd[i].norm();
    (1..solution.len())
        .map(|i| 0.5 * (power(i - 1) + power(i)) * (solution.t[i] - solution.t[i - 1]).abs())
        .sum()
}
