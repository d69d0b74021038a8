//! What happened: the recorded motion, its diagnostics, statistics and why it stopped.

use nalgebra::SVectorView;

use crate::error::Error;
use crate::integrate::events::EventHit;
use crate::integrate::options::Record;
use crate::integrate::system::{ReducedOde, Stats};
use crate::model::Model;
use crate::sensitivity::Sensitivities;

/// Why the integration stopped.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Clone, Debug, PartialEq)]
pub enum Status {
    /// The end time was reached.
    Success,
    /// A terminal event fired; the last recorded point is the event.
    Terminated {
        /// Index of the event in the options.
        event: usize,
    },
    /// The integration failed; everything up to the failure is recorded.
    Failed(Error),
}

/// Something the run did that a user may not expect, though nothing failed: carried by the
/// solution ([`Solution::warnings`]), in the order it happened. Its text says what happened and
/// what it means for the results.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Warning {
    /// An event function was zero at the start time (exactly, or within the rounding of the
    /// initial state), so it was not armed there: no crossing is reported at the start, and the
    /// event counts crossings only once the function has left zero (see
    /// [`Event`](crate::prelude::Event)).
    EventZeroAtStart {
        /// The event's index, from 0, in the order of `Options::event`.
        index: usize,
        /// The event's name.
        name: String,
        /// The function's value at the start.
        value: f64,
        /// The end of the first stretch of the motion by which the function had left zero, where
        /// the event was armed; `None` when it had not left zero when the run ended.
        armed_by: Option<f64>,
    },
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Warning::EventZeroAtStart {
                index,
                name,
                value,
                armed_by,
            } => {
                write!(
                    f,
                    "event \"{name}\" (index {index}) is zero at the start (g = {value:e}, within \
                     the rounding of the initial state): a crossing there is not reported, and the event is armed \
                     only once its function leaves zero; "
                )?;
                match armed_by {
                    Some(t) => write!(
                        f,
                        "it had left zero by t = {t}, and crossings after that count as usual"
                    ),
                    None => write!(
                        f,
                        "it had not left zero when the run ended, so no crossing of it was counted"
                    ),
                }
            }
        }
    }
}

/// A sequence of vectors of one width (`q`, `μ`, ...), one per recorded point, stored in one flat
/// buffer so that recording never allocates a vector per point.
///
/// It reads like a `Vec` of slices: `sol.q[i][0]`, `sol.q.last()`, `sol.mu.iter()`; and by
/// component: `sol.q.component(1)` is the time series of the second coordinate.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Series {
    width: usize,
    rows: usize,
    data: Vec<f64>,
}

impl Series {
    /// An empty series of vectors of length `width`.
    pub fn new(width: usize) -> Self {
        Self {
            width,
            rows: 0,
            data: Vec::new(),
        }
    }

    /// Appends one vector (its length must be the width).
    pub fn push(&mut self, v: &[f64]) {
        debug_assert_eq!(v.len(), self.width);
        self.data.extend_from_slice(v);
        self.rows += 1;
    }

    /// An empty series of vectors of length `width`, with room for `rows` of them where memory
    /// allows.
    pub fn with_capacity(width: usize, rows: usize) -> Self {
        Self {
            width,
            rows: 0,
            data: room(rows.saturating_mul(width)),
        }
    }

    /// Makes room for `rows` more vectors without reallocating, where memory allows (room is only
    /// a saving: what cannot be had is left to grow as vectors do).
    pub fn reserve(&mut self, rows: usize) {
        let _ = self.data.try_reserve(rows.saturating_mul(self.width));
    }

    /// Removes every vector after the first `len`.
    pub fn truncate(&mut self, len: usize) {
        if len < self.rows {
            self.rows = len;
            self.data.truncate(len * self.width);
        }
    }

    /// The length of each vector.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Number of vectors.
    pub fn len(&self) -> usize {
        self.rows
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.rows == 0
    }

    /// Vector `i`, if there is one.
    pub fn get(&self, i: usize) -> Option<&[f64]> {
        (i < self.rows).then(|| &self.data[i * self.width..(i + 1) * self.width])
    }

    /// The first vector.
    pub fn first(&self) -> Option<&[f64]> {
        self.get(0)
    }

    /// The last vector.
    pub fn last(&self) -> Option<&[f64]> {
        self.rows.checked_sub(1).and_then(|i| self.get(i))
    }

    /// The vectors in order.
    pub fn iter(&self) -> SeriesIter<'_> {
        SeriesIter {
            series: self,
            front: 0,
            back: self.rows,
        }
    }

    /// Component `j` of every vector, in order.
    pub fn component(&self, j: usize) -> impl ExactSizeIterator<Item = f64> + '_ {
        assert!(
            j < self.width,
            "component {j} of vectors of length {}",
            self.width
        );
        (0..self.rows).map(move |i| self.data[i * self.width + j])
    }

    /// All values, vector after vector.
    pub fn as_flat(&self) -> &[f64] {
        &self.data
    }

    /// The vectors as owned `Vec`s.
    pub fn to_vecs(&self) -> Vec<Vec<f64>> {
        self.iter().map(<[f64]>::to_vec).collect()
    }

    /// Vector `i` as a fixed-size nalgebra view of length `N`, for sizes known at compile time
    /// (`sol.q.fixed::<2>(i)` for a model of `Lagrangian<2>`): it borrows the series' storage,
    /// and reads and computes as an `SVector` does (`.norm()`, `.dot(..)`, `into_owned()` for an
    /// `SVector<f64, N>`). `None` if there is no vector `i` or the width is not `N`.
    ///
    /// ```
    /// use chetaev::prelude::*;
    /// let mut q = Series::new(2);
    /// q.push(&[3.0, 4.0]);
    /// assert_eq!(q.fixed::<2>(0).map(|v| v.norm()), Some(5.0));
    /// assert!(q.fixed::<3>(0).is_none() && q.fixed::<2>(1).is_none());
    /// ```
    pub fn fixed<const N: usize>(&self, i: usize) -> Option<SVectorView<'_, f64, N>> {
        (self.width == N)
            .then(|| self.get(i))
            .flatten()
            .map(SVectorView::<f64, N>::from_slice)
    }

    /// Every vector in order as a fixed-size view of length `N` ([`Series::fixed`]); `None` if the
    /// width is not `N`.
    pub fn fixed_iter<const N: usize>(
        &self,
    ) -> Option<impl ExactSizeIterator<Item = SVectorView<'_, f64, N>> + '_> {
        (self.width == N).then(|| self.iter().map(SVectorView::<f64, N>::from_slice))
    }
}

impl<'a> IntoIterator for &'a Series {
    type Item = &'a [f64];
    type IntoIter = SeriesIter<'a>;
    /// The vectors in order (`for mu in &sol.mu { ... }`).
    fn into_iter(self) -> SeriesIter<'a> {
        self.iter()
    }
}

/// The vectors of a [`Series`] in order.
#[derive(Clone, Debug)]
pub struct SeriesIter<'a> {
    series: &'a Series,
    front: usize,
    back: usize,
}

impl<'a> Iterator for SeriesIter<'a> {
    type Item = &'a [f64];
    fn next(&mut self) -> Option<&'a [f64]> {
        (self.front < self.back).then(|| {
            self.front += 1;
            &self.series[self.front - 1]
        })
    }
    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.back - self.front;
        (n, Some(n))
    }
}

impl DoubleEndedIterator for SeriesIter<'_> {
    fn next_back(&mut self) -> Option<Self::Item> {
        (self.front < self.back).then(|| {
            self.back -= 1;
            &self.series[self.back]
        })
    }
}

impl ExactSizeIterator for SeriesIter<'_> {}

impl std::ops::Index<usize> for Series {
    type Output = [f64];
    fn index(&self, i: usize) -> &[f64] {
        assert!(
            i < self.rows,
            "index {i} out of a series of {} vectors",
            self.rows
        );
        &self.data[i * self.width..(i + 1) * self.width]
    }
}

/// The motion and everything recorded along it, for a model of `n` coordinates and `k = K + H`
/// constraints: `K` velocity constraints and `H` holonomic ones, one multiplier each. Series of diagnostics are empty when the [`Record`] level did not
/// ask for them.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Clone, Debug)]
#[must_use = "a solution carries a status that says whether the integration succeeded"]
pub struct Solution {
    /// The method that produced it.
    pub method: &'static str,
    /// What was recorded.
    pub record: Record,
    /// Output times.
    pub t: Vec<f64>,
    /// `q` at the output times (width `n`).
    pub q: Series,
    /// `q̇` at the output times (width `n`).
    pub qd: Series,
    /// `q̈` ([`Record::Dynamics`] and above; width `n`).
    pub qdd: Series,
    /// Multipliers `μ`, Newton form ([`Record::Dynamics`] and above; width `k = K + H`: the `K`
    /// multipliers of the velocity constraints, then the `H` of the holonomic ones).
    pub mu: Series,
    /// The Chetaev force `Φ = Jᵀμ` ([`Record::Dynamics`] and above; width `n`).
    pub phi: Series,
    /// The constraint residual ([`Record::Dynamics`] and above; width `k = K + H`): the `K`
    /// velocity constraints `f(t, q, q̇)`, then `ḣ` of the `H` holonomic ones.
    pub residual: Series,
    /// How far `q̇` misses the velocity constraints, relative to the terms that make them up
    /// ([`Record::Dynamics`] and above): `max_a |f_a| / (Σ_i |∂f_a/∂q̇_i · q̇_i| + |f_a|)`, the
    /// residual over the size of each constraint's velocity terms, so that coordinates of other
    /// units or a constraint's scale do not enter. Below 1 always; 0 without velocity constraints
    /// (the holonomic ones have their position residual). The absolute residual says little
    /// where the velocities are small: at speeds of `1e-12`, `|f| = 1e-19` can be a velocity far
    /// off, which this shows. It is a first-order measure: a velocity lost altogether reads
    /// about 1/3 under `|q̇|² = v0²` and at most 1/2 under a constraint linear in `q̇`, not how far
    /// off it is; and near rest it compares with a small velocity.
    pub relative_residual: Vec<f64>,
    /// The position residual `h(t, q)` of the holonomic constraints ([`Record::Dynamics`] and
    /// above; width the number of holonomic constraints, 0 without them).
    pub position_residual: Series,
    /// The energy `E = q̇·∂L/∂q̇ − L` ([`Record::Dynamics`] and above).
    pub energy: Vec<f64>,
    /// The work of the Chetaev force since the start, `W_Φ = ∫ q̇·Φ dt` ([`Record::Energy`]).
    pub work: Vec<f64>,
    /// `∫ ∂L/∂t dt` since the start ([`Record::Energy`]).
    pub dl_dt_integral: Vec<f64>,
    /// The work of the forces not derivable from `L` since the start, `W_Q = ∫ q̇·Q dt`
    /// ([`Record::Energy`]; zero for a model without such forces).
    pub work_forces: Vec<f64>,
    /// Located events, in the order they occurred.
    pub events: Vec<EventHit>,
    /// Derivatives of the motion and of the events with respect to the seeds of
    /// [`Options::sensitivity`](crate::integrate::options::Options::sensitivity) (`None` when none
    /// was asked for).
    pub sensitivities: Option<Sensitivities>,
    /// Work counters.
    pub stats: Stats,
    /// Why it stopped.
    pub status: Status,
    /// What the run did that a user may not expect, though nothing failed (an event zero at the
    /// start, armed only when it left zero); empty for an ordinary run.
    pub warnings: Vec<Warning>,
}

impl Solution {
    /// An empty solution for a model with `n` coordinates and `k = K + H` multipliers (velocity and
    /// holonomic constraints), recording at the
    /// level `record`: for integrators outside the crate, which fill it with [`Solution::record`].
    pub fn empty(method: &'static str, record: Record, n: usize, k: usize) -> Self {
        Self::with_capacity(method, record, n, k, 0)
    }

    /// [`Solution::empty`] with room for `rows` recorded points in every series that the level
    /// `record` fills, so that recording them does not reallocate; where memory does not allow it,
    /// the series start empty and grow as vectors do.
    pub fn with_capacity(
        method: &'static str,
        record: Record,
        n: usize,
        k: usize,
        rows: usize,
    ) -> Self {
        let at = |level: Record| if record >= level { rows } else { 0 };
        let (dynamics, energy) = (at(Record::Dynamics), at(Record::Energy));
        Self {
            method,
            record,
            t: room(rows),
            q: Series::with_capacity(n, rows),
            qd: Series::with_capacity(n, rows),
            qdd: Series::with_capacity(n, dynamics),
            mu: Series::with_capacity(k, dynamics),
            phi: Series::with_capacity(n, dynamics),
            residual: Series::with_capacity(k, dynamics),
            relative_residual: room(dynamics),
            position_residual: Series::new(0),
            energy: room(dynamics),
            work: room(energy),
            dl_dt_integral: room(energy),
            work_forces: room(energy),
            events: Vec::new(),
            sensitivities: None,
            stats: Stats::default(),
            status: Status::Success,
            warnings: Vec::new(),
        }
    }

    /// Records the state `y = [q, q̇, (W_Φ, ∫∂L/∂t dt)]` at `t`, with the diagnostics its
    /// [`Record`] level asks for (evaluated by `ode`). Every recorded quantity must be finite:
    /// otherwise nothing is recorded and the error is [`Error::NonFiniteSolution`], so every series
    /// keeps the same length and nothing recorded is NaN.
    pub fn record<M: Model + ?Sized>(
        &mut self,
        ode: &mut ReducedOde<'_, M>,
        t: f64,
        y: &[f64],
    ) -> Result<(), Error> {
        let n = self.n();
        let (q, qd) = (&y[..n], &y[n..2 * n]);
        let energy = self.record >= Record::Energy;
        let e = ode.quadratures();
        finite(t, "q", q)?;
        finite(t, "q̇", qd)?;
        finite(t, "∂(q, q̇)/∂θ", &y[2 * n..e])?;
        if energy {
            finite(t, "W_Φ", &y[e..e + 1])?;
            finite(t, "∫∂L/∂t dt", &y[e + 1..e + 2])?;
            if ode.has_forces_quadrature() {
                finite(t, "W_Q", &y[e + 2..e + 3])?;
            }
        }
        if self.record >= Record::Dynamics {
            let holonomic = ode.model.holonomic_count();
            let h = (holonomic > 0).then(|| {
                let mut h = vec![0.0; holonomic];
                ode.model.holonomic_blocks(t, q, &mut h, None);
                h
            });
            if let Some(h) = &h {
                finite(t, "h", h)?;
            }
            // The multipliers' and the force's sensitivities first: `ode.evaluate` lends its
            // workspace until the end of the recording.
            let moved = match ode.sens.as_mut() {
                Some(v) => {
                    let (mut dmu, mut dphi) = (Vec::new(), Vec::new());
                    let x = crate::model::Point::new(t, q, qd);
                    v.multipliers(ode.model, x, &y[2 * n..e], (&mut dmu, &mut dphi))?;
                    finite(t, "dμ/dθ", &dmu)?;
                    finite(t, "dΦ/dθ", &dphi)?;
                    Some((dmu, dphi))
                }
                None => None,
            };
            let d = ode.evaluate(t, q, qd)?;
            finite(t, "q̈", &d.qdd)?;
            finite(t, "μ", &d.mu)?;
            finite(t, "Φ", &d.phi)?;
            finite(t, "f", &d.f)?;
            finite(t, "E", std::slice::from_ref(&d.energy))?;
            self.qdd.push(&d.qdd);
            self.mu.push(&d.mu);
            self.phi.push(&d.phi);
            self.residual.push(&d.f);
            self.relative_residual
                .push(relative_residual(&d.f[..d.f.len() - holonomic], &d.j, qd));
            self.energy.push(d.energy);
            if let (Some(s), Some((dmu, dphi))) = (&mut self.sensitivities, moved) {
                s.mu.push(&dmu);
                s.phi.push(&dphi);
            }
            if let Some(h) = h {
                if self.position_residual.width() != h.len() {
                    self.position_residual = Series::new(h.len());
                }
                self.position_residual.push(&h);
            }
        }
        self.t.push(t);
        self.q.push(q);
        self.qd.push(qd);
        if let Some(s) = &mut self.sensitivities {
            s.values.push(&y[2 * n..e]);
        }
        if energy {
            self.work.push(y[e]);
            self.dl_dt_integral.push(y[e + 1]);
            self.work_forces.push(if ode.has_forces_quadrature() {
                y[e + 2]
            } else {
                0.0
            });
        }
        Ok(())
    }

    /// Writes the recorded motion as CSV: a header, then one row per recorded point with `t`, the
    /// coordinates `q_1..q_n`, the velocities `qd_1..qd_n`, and, where recorded, `qdd_i`, `mu_a`,
    /// `phi_i`, `f_a`, `E`, `W_Phi`, `W_Q`, `int_dLdt`, and `balance` (the energy balance), then with
    /// sensitivities `d(q_i)/d(θ)` and `d(qd_i)/d(θ)` for each seed `θ` by its name, and where the
    /// multipliers are recorded `d(mu_a)/d(θ)` and `d(phi_i)/d(θ)` for each seed. Numbers are
    /// written with full precision (Rust's shortest round-trip form).
    pub fn write_csv<W: std::io::Write>(&self, mut w: W) -> std::io::Result<()> {
        let (n, k) = (self.n(), self.k());
        let mut header = vec!["t".to_string()];
        fn names(prefix: &'static str, count: usize) -> impl Iterator<Item = String> {
            (1..=count).map(move |i| format!("{prefix}_{i}"))
        }
        header.extend(names("q", n));
        header.extend(names("qd", n));
        let dynamics = !self.energy.is_empty();
        let energy = !self.work.is_empty();
        if dynamics {
            header.extend(names("qdd", n));
            header.extend(names("mu", k));
            header.extend(names("phi", n));
            header.extend(names("f", k));
            header.push("E".to_string());
        }
        if energy {
            header.extend(["W_Phi", "W_Q", "int_dLdt", "balance"].map(String::from));
        }
        if let Some(s) = &self.sensitivities {
            // A name with a comma or a quote is quoted, as CSV wants.
            let quoted = |x: String| {
                if x.contains([',', '"']) {
                    format!("\"{}\"", x.replace('"', "\"\""))
                } else {
                    x
                }
            };
            for seed in &s.names {
                header.extend((1..=n).map(|i| quoted(format!("d(q_{i})/d({seed})"))));
                header.extend((1..=n).map(|i| quoted(format!("d(qd_{i})/d({seed})"))));
            }
            if !s.mu.is_empty() {
                for seed in &s.names {
                    header.extend((1..=k).map(|a| quoted(format!("d(mu_{a})/d({seed})"))));
                    header.extend((1..=n).map(|i| quoted(format!("d(phi_{i})/d({seed})"))));
                }
            }
        }
        writeln!(w, "{}", header.join(","))?;
        let balance = self.energy_balance();
        let mut row: Vec<f64> = Vec::with_capacity(header.len());
        for (i, &t) in self.t.iter().enumerate() {
            row.clear();
            row.push(t);
            row.extend_from_slice(&self.q[i]);
            row.extend_from_slice(&self.qd[i]);
            if dynamics {
                row.extend_from_slice(&self.qdd[i]);
                row.extend_from_slice(&self.mu[i]);
                row.extend_from_slice(&self.phi[i]);
                row.extend_from_slice(&self.residual[i]);
                row.push(self.energy[i]);
            }
            if let (true, Some(b)) = (energy, balance.get(i)) {
                row.extend([
                    self.work[i],
                    self.work_forces[i],
                    self.dl_dt_integral[i],
                    *b,
                ]);
            }
            if let Some(s) = &self.sensitivities {
                row.extend_from_slice(&s.values[i]);
                if let (Some(mu), Some(phi)) = (s.mu.get(i), s.phi.get(i)) {
                    for j in 0..s.names.len() {
                        row.extend_from_slice(&mu[k * j..k * (j + 1)]);
                        row.extend_from_slice(&phi[n * j..n * (j + 1)]);
                    }
                }
            }
            let text: Vec<String> = row.iter().map(|v| v.to_string()).collect();
            writeln!(w, "{}", text.join(","))?;
        }
        Ok(())
    }

    /// `q` at recorded point `i` as a fixed-size view ([`Series::fixed`]), for a model of `N`
    /// coordinates known at compile time: `sol.q_row::<2>(i)`. `None` if there is no point `i` or
    /// the model has not `N` coordinates.
    pub fn q_row<const N: usize>(&self, i: usize) -> Option<SVectorView<'_, f64, N>> {
        self.q.fixed(i)
    }

    /// `q̇` at recorded point `i` as a fixed-size view, as [`Solution::q_row`].
    pub fn qd_row<const N: usize>(&self, i: usize) -> Option<SVectorView<'_, f64, N>> {
        self.qd.fixed(i)
    }

    /// `q̈` at recorded point `i` as a fixed-size view, as [`Solution::q_row`] (`None` also where
    /// the accelerations were not recorded, below [`Record::Dynamics`]).
    pub fn qdd_row<const N: usize>(&self, i: usize) -> Option<SVectorView<'_, f64, N>> {
        self.qdd.fixed(i)
    }

    /// The multipliers `μ` at recorded point `i` as a fixed-size view of the `K` constraints:
    /// `sol.mu_row::<1>(i)`. `None` if there is no point `i`, the model has not `K` constraints,
    /// or `μ` was not recorded (below [`Record::Dynamics`]).
    pub fn mu_row<const K: usize>(&self, i: usize) -> Option<SVectorView<'_, f64, K>> {
        self.mu.fixed(i)
    }

    /// The Chetaev force `Φ` at recorded point `i` as a fixed-size view, as [`Solution::mu_row`]
    /// (length `N`, the number of coordinates).
    pub fn phi_row<const N: usize>(&self, i: usize) -> Option<SVectorView<'_, f64, N>> {
        self.phi.fixed(i)
    }

    /// Number of coordinates `n`.
    pub fn n(&self) -> usize {
        self.q.width()
    }

    /// Number of multipliers `k = K + H`: the `K` velocity constraints and the `H` holonomic
    /// ones (the width of [`Solution::mu`]); the same as [`Solution::multiplier_count`].
    pub fn k(&self) -> usize {
        self.mu.width()
    }

    /// Number of multipliers `k = K + H`, one per velocity constraint and per holonomic one.
    pub fn multiplier_count(&self) -> usize {
        self.mu.width()
    }

    /// Whether the end time or a terminal event was reached.
    pub fn is_success(&self) -> bool {
        !matches!(self.status, Status::Failed(_))
    }

    /// The error, if the integration failed.
    pub fn error(&self) -> Option<&Error> {
        match &self.status {
            Status::Failed(e) => Some(e),
            _ => None,
        }
    }

    /// The solution, or its error if the integration failed, so that `solve(...)?.ok()?` cannot
    /// miss a failure. The partial motion is dropped with the error; keep the solution and read
    /// [`Solution::error`] to have both.
    pub fn ok(self) -> Result<Self, Error> {
        match self.status {
            Status::Failed(e) => Err(e),
            _ => Ok(self),
        }
    }

    /// Number of recorded points.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether nothing was recorded.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The last recorded `(t, q, q̇)`.
    pub fn last(&self) -> Option<(f64, &[f64], &[f64])> {
        let i = self.t.len().checked_sub(1)?;
        Some((self.t[i], &self.q[i], &self.qd[i]))
    }

    /// The energy balance `E(t) − E(t0) − W_Φ(t) − W_Q(t) + ∫∂L/∂t dt`, which vanishes along an exact
    /// motion because `dE/dt = q̇·Φ + q̇·Q − ∂L/∂t` ([`Record::Energy`]; empty otherwise). Its
    /// quadratures are outside error control: at output times between steps they are the
    /// method's dense output, which can be far less accurate than the motion (`docs/where-it-breaks.md`,
    /// "The energy balance between steps"); at the steps (the default output) they are not.
    pub fn energy_balance(&self) -> Vec<f64> {
        if self.work.is_empty() {
            return Vec::new();
        }
        let e0 = self.energy[0];
        (0..self.work.len())
            .map(|i| {
                self.energy[i] - e0 - self.work[i] - self.work_forces[i] + self.dl_dt_integral[i]
            })
            .collect()
    }

    /// The largest `|b|` of [`Solution::energy_balance`] over the recorded points
    /// ([`Record::Energy`]; `None` when the energy was not recorded, so that a check of it cannot
    /// pass on nothing, as `energy_balance().iter().all(..)` does on its empty list). NaN if any
    /// point's balance is NaN.
    pub fn max_energy_balance(&self) -> Option<f64> {
        if self.work.is_empty() {
            return None;
        }
        Some(self.energy_balance().iter().fold(0.0f64, |acc, b| {
            if b.is_nan() || acc.is_nan() {
                f64::NAN
            } else {
                acc.max(b.abs())
            }
        }))
    }

    /// The largest [`Solution::relative_residual`] over the recorded points (`None` when the
    /// residual was not recorded).
    pub fn max_relative_residual(&self) -> Option<f64> {
        (self.record >= Record::Dynamics)
            .then(|| self.relative_residual.iter().copied().fold(0.0, f64::max))
    }

    /// `max_i max_a |f_a|` over the recorded points ([`Record::Dynamics`] and above; `None` when
    /// the residual was not recorded, so that a check of it cannot pass on nothing; 0 without
    /// constraints). NaN if any residual is NaN: a maximum never hides one.
    pub fn max_residual(&self) -> Option<f64> {
        if self.record < Record::Dynamics {
            return None;
        }
        Some(self.residual.as_flat().iter().fold(0.0f64, |acc, v| {
            if v.is_nan() || acc.is_nan() {
                f64::NAN
            } else {
                acc.max(v.abs())
            }
        }))
    }
}

/// `max_a |f_a| / (Σ_i |J_ai q̇_i| + |f_a|)` over the velocity constraints `f` (see
/// [`Solution::relative_residual`]).
fn relative_residual(f: &[f64], j: &[f64], qd: &[f64]) -> f64 {
    f.iter()
        .zip(j.chunks(qd.len().max(1)))
        .map(|(&fa, ja)| row_residual(fa, velocity_terms(ja, qd)))
        .fold(0.0, f64::max)
}

/// The size of a constraint's velocity terms, `Σ_i |J_ai q̇_i|`, for its gradient row `ja`.
pub(crate) fn velocity_terms(ja: &[f64], qd: &[f64]) -> f64 {
    ja.iter().zip(qd).map(|(a, v)| (a * v).abs()).sum()
}

/// A constraint's residual `f_a` relative to its velocity terms: `|f_a|/(terms + |f_a|)`, 0 where
/// `f_a = 0`.
pub(crate) fn row_residual(fa: f64, terms: f64) -> f64 {
    let fa = fa.abs();
    if fa > 0.0 {
        fa / (terms + fa)
    } else {
        0.0
    }
}

/// `Err(NonFiniteSolution)` unless every value is finite.
fn finite(t: f64, quantity: &'static str, values: &[f64]) -> Result<(), Error> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(Error::NonFiniteSolution { t, quantity })
    }
}

/// An empty vector with room for `len` numbers where memory allows (never a failure: the room is
/// only a saving).
fn room(len: usize) -> Vec<f64> {
    let mut v = Vec::new();
    let _ = v.try_reserve(len);
    v
}
