//! Sensitivities: derivatives of the motion, of event times and of event states with respect to
//! model parameters and initial values, by forward-mode automatic differentiation through the
//! solve.
//!
//! A [`Seed`] is one direction `θ` in which the problem is moved: parameters the model reads with
//! [`Real::parameter`](crate::model::Real::parameter), initial positions and initial velocities,
//! each with a rate. Along the motion `y = (q, q̇)` of `y' = F(t, y, p)` the sensitivity
//! `S = ∂y/∂θ` obeys the variational equation
//!
//! ```text
//! S' = ∂F/∂y · S + ∂F/∂p · δp,      S(t0) = (δq0, δq̇0)
//! ```
//!
//! whose right-hand side is one directional derivative of `F`: the compiled equations
//! ([`Compiled::with_parameters`]) evaluated with dual numbers whose derivative parts are `(S, δp)`.
//! `S` is integrated with the motion by the same method and steps (Rodas4 gets the exact Jacobian
//! of the whole system, by hyper-dual numbers), under error control when
//! [`Options::sensitivity_control`](crate::integrate::options::Options::sensitivity_control) asks.
//!
//! An event `g(t, q, q̇) = 0` at time `T` moves with `θ` by
//!
//! ```text
//! dT/dθ = −(∂g/∂q · S_q + ∂g/∂q̇ · S_q̇ + ∂g/∂p · δp) / ġ,   ġ = ∂g/∂t + ∂g/∂q · q̇ + ∂g/∂q̇ · q̈,
//! dq(T)/dθ = S_q(T) + q̇(T) dT/dθ,   dq̇(T)/dθ = S_q̇(T) + q̈(T) dT/dθ,
//! ```
//!
//! with the gradient of `g` exact for events made by [`Event::smooth`].

use num_dual::HyperDual64;

use crate::equations::compiled::{Compiled, CompiledFailure};
use crate::equations::graph::{record_with_parameters, Graph, Sym, DEP_P, DEP_Q, DEP_QD, DEP_T};
use crate::equations::{evaluate_compiled, lane, lanes, Dynamics, Lanes, Need, Workspace, LANES};
use crate::error::{Error, SeedPart};
use crate::integrate::events::{Event, EventFunction};
use crate::integrate::system::locate;
use crate::model::{Functions, Model, Point};
use crate::solution::Series;

/// One direction in which sensitivities are taken: rates of parameters, of initial positions and
/// of initial velocities, moved together.
///
/// ```
/// use chetaev::Seed;
/// // ∂/∂g, g read by the model as R::parameter("g", ...).
/// let g = Seed::parameter("g");
/// // ∂/∂v0 where v0 is both a parameter of the constraint and the initial speed ẋ(0) = v0.
/// let v0 = Seed::parameter("v0").with_velocity(0, 1.0);
/// // ∂/∂h0, the initial height y(0) = h0.
/// let h0 = Seed::new("h0").with_position(1, 1.0);
/// # let _ = (g, v0, h0);
/// ```
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Clone, Debug, PartialEq)]
pub struct Seed {
    /// A name for reports and lookups.
    pub name: String,
    /// Rates of parameters, by the names the model reads them with.
    pub parameters: Vec<(String, f64)>,
    /// Rates of initial positions `(index from 0, δq0_i)`.
    pub positions: Vec<(usize, f64)>,
    /// Rates of initial velocities `(index from 0, δq̇0_i)`.
    pub velocities: Vec<(usize, f64)>,
}

impl Seed {
    /// A direction named `name` that moves nothing yet; add rates with the `with_` methods.
    pub fn new(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            parameters: Vec::new(),
            positions: Vec::new(),
            velocities: Vec::new(),
        }
    }

    /// `∂/∂p` for the parameter `name` (rate 1), named after it.
    pub fn parameter(name: &str) -> Self {
        Self::new(name).with_parameter(name, 1.0)
    }

    /// `∂/∂q_i(t0)` (index from 0), named `q{i+1}(t0)`.
    pub fn position(i: usize) -> Self {
        Self::new(format!("q{}(t0)", i as u128 + 1)).with_position(i, 1.0)
    }

    /// `∂/∂q̇_i(t0)` (index from 0), named `q̇{i+1}(t0)`.
    pub fn velocity(i: usize) -> Self {
        Self::new(format!("q̇{}(t0)", i as u128 + 1)).with_velocity(i, 1.0)
    }

    /// Also moves the parameter `name` at rate `rate`.
    pub fn with_parameter(mut self, name: &str, rate: f64) -> Self {
        self.parameters.push((name.to_string(), rate));
        self
    }

    /// Also moves the initial position `i` (from 0) at rate `rate`.
    pub fn with_position(mut self, i: usize, rate: f64) -> Self {
        self.positions.push((i, rate));
        self
    }

    /// Also moves the initial velocity `i` (from 0) at rate `rate`.
    pub fn with_velocity(mut self, i: usize, rate: f64) -> Self {
        self.velocities.push((i, rate));
        self
    }

    /// The rate of parameter `name` in this direction.
    fn rate(&self, name: &str) -> f64 {
        self.parameters
            .iter()
            .filter(|(p, _)| p == name)
            .map(|(_, r)| r)
            .sum()
    }
}

/// How an event moves with each seed: `dT/dθ`, `dq(T)/dθ`, `dq̇(T)/dθ`.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Clone, Debug, PartialEq)]
pub struct EventSensitivity {
    /// `dT/dθ`, one per seed.
    pub t: Vec<f64>,
    /// `dq(T)/dθ`, one vector (length `n`) per seed.
    pub q: Vec<Vec<f64>>,
    /// `dq̇(T)/dθ`, one vector (length `n`) per seed.
    pub qd: Vec<Vec<f64>>,
}

/// The sensitivities of a solution ([`Solution::sensitivities`](crate::Solution::sensitivities)):
/// `∂q/∂θ` and `∂q̇/∂θ` at every recorded point for each seed `θ`, with `∂μ/∂θ` and `∂Φ/∂θ` where
/// the multipliers are recorded, and how each event moved.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Clone, Debug, PartialEq)]
pub struct Sensitivities {
    /// The seeds' names, in the order given.
    pub names: Vec<String>,
    /// At each recorded point, for each seed in turn, `∂q/∂θ` (n) then `∂q̇/∂θ` (n).
    pub values: Series,
    /// At each recorded point, for each seed in turn, the total derivative of the multipliers
    /// `dμ/dθ` (k, Newton form as [`Solution::mu`](crate::Solution::mu)); recorded with `μ`
    /// ([`Record::Dynamics`](crate::integrate::options::Record::Dynamics) and above), empty otherwise.
    pub mu: Series,
    /// At each recorded point, for each seed in turn, the total derivative of the Chetaev force
    /// `dΦ/dθ = d(Jᵀμ)/dθ` (n); recorded with `Φ`, empty otherwise.
    pub phi: Series,
    /// For each hit of [`Solution::events`](crate::Solution::events), in the same order, how it
    /// moved; `None` for an event made by [`Event::new`] (its function is a plain closure that
    /// cannot be differentiated: make it with [`Event::smooth`]) or one crossed tangentially
    /// (`ġ = 0`, where `T` is not differentiable).
    pub events: Vec<Option<EventSensitivity>>,
}

impl Sensitivities {
    pub(crate) fn new(names: Vec<String>, n: usize, k: usize) -> Self {
        Self {
            values: Series::new(2 * n * names.len()),
            mu: Series::new(k * names.len()),
            phi: Series::new(n * names.len()),
            names,
            events: Vec::new(),
        }
    }

    /// The number of coordinates `n`: each seed takes `2n` of the width.
    fn n(&self) -> usize {
        self.values.width() / (2 * self.names.len()).max(1)
    }

    /// The index of the seed named `name`.
    pub fn seed(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|s| s == name)
    }

    /// `∂q/∂θ` at recorded point `point` for seed `seed`.
    ///
    /// # Panics
    ///
    /// If `point` is not below the number of recorded points or `seed` not below the number of
    /// seeds, as slice indexing does.
    pub fn q(&self, point: usize, seed: usize) -> &[f64] {
        let n = self.n();
        &self.values[point][2 * n * seed..2 * n * seed + n]
    }

    /// `∂q̇/∂θ` at recorded point `point` for seed `seed`.
    ///
    /// # Panics
    ///
    /// As [`Sensitivities::q`].
    pub fn qd(&self, point: usize, seed: usize) -> &[f64] {
        let n = self.n();
        &self.values[point][2 * n * seed + n..2 * n * (seed + 1)]
    }

    /// `dμ/dθ` at recorded point `point` for seed `seed` (length `k`): the total derivative of the
    /// multipliers, through the motion (`∂μ/∂q · ∂q/∂θ + ∂μ/∂q̇ · ∂q̇/∂θ`) and through the
    /// parameters (`∂μ/∂p · δp`). `None` where the multipliers were not recorded (below
    /// [`Record::Dynamics`](crate::integrate::options::Record::Dynamics)) or `point` or `seed` is out of range.
    pub fn mu(&self, point: usize, seed: usize) -> Option<&[f64]> {
        let k = self.mu.width() / self.names.len().max(1);
        (seed < self.names.len())
            .then(|| self.mu.get(point))
            .flatten()
            .map(|row| &row[k * seed..k * (seed + 1)])
    }

    /// `dΦ/dθ` at recorded point `point` for seed `seed` (length `n`), as [`Sensitivities::mu`].
    pub fn phi(&self, point: usize, seed: usize) -> Option<&[f64]> {
        let n = self.n();
        (seed < self.names.len())
            .then(|| self.phi.get(point))
            .flatten()
            .map(|row| &row[n * seed..n * (seed + 1)])
    }
}

/// The gradient of an event function at a point.
pub(crate) struct EventGradient {
    t: f64,
    q: Vec<f64>,
    qd: Vec<f64>,
    /// With respect to the parameters it reads: `(name, value read, derivative)`.
    params: Vec<(String, f64, f64)>,
}

/// Records `f` at `(t, q, q̇)` with its parameters as inputs and differentiates it; `None` where a
/// value leaves the recording (`re()`) or a parameter is read with two values.
pub(crate) fn event_gradient<F: EventFunction>(
    f: &F,
    t: f64,
    q: &[f64],
    qd: &[f64],
) -> Option<EventGradient> {
    let n = q.len();
    let (mut g, inputs, value, params) =
        record_at(t, q, qd, |ts, qs, qds| f.value(ts, qs, qds).node())?;
    let wrt: Vec<u32> = inputs
        .iter()
        .copied()
        .chain(params.iter().map(|p| p.3))
        .collect();
    let grad: Vec<f64> = g
        .gradient(value, &wrt, DEP_T | DEP_Q | DEP_QD | DEP_P)
        .into_iter()
        .map(|id| g.value(id))
        .collect();
    Some(EventGradient {
        t: grad[0],
        q: grad[1..=n].to_vec(),
        qd: grad[n + 1..=2 * n].to_vec(),
        params: params
            .into_iter()
            .zip(&grad[2 * n + 1..])
            .map(|(p, &d)| (p.0, p.1, d))
            .collect(),
    })
}

/// A parameter as [`record_with_parameters`] lists it: `(name, value, input number, node)`.
type Read = (String, f64, u32, u32);

/// Records `f` of the inputs `(t, q, q̇)` with every parameter it reads an input too: the graph,
/// the input nodes (`t`, then `q`, then `q̇`), what `f` returns, and the parameters read; `None`
/// where a parameter is read with two values or a value leaves the recording (`re()`).
pub(crate) fn record_at<O>(
    t: f64,
    q: &[f64],
    qd: &[f64],
    f: impl FnOnce(Sym, &[Sym], &[Sym]) -> O,
) -> Option<(Graph, Vec<u32>, O, Vec<Read>)> {
    let (g, (inputs, out), params) = record_with_parameters(|| {
        let ts = Sym::input(DEP_T, t);
        let qs: Vec<Sym> = q.iter().map(|&v| Sym::input(DEP_Q, v)).collect();
        let qds: Vec<Sym> = qd.iter().map(|&v| Sym::input(DEP_QD, v)).collect();
        let out = f(ts, &qs, &qds);
        let inputs: Vec<u32> = std::iter::once(ts)
            .chain(qs)
            .chain(qds)
            .map(Sym::node)
            .collect();
        (inputs, out)
    })
    .ok()?;
    (!g.escaped()).then_some((g, inputs, out, params))
}

fn invalid(what: String) -> Error {
    Error::Sensitivity { what }
}

/// The first seed that moves the initial position off a holonomic constraint to first order:
/// `(seed, b, ∂h_b/∂q δq0 + ∂h_b/∂p δp)` for the seeds' initial `δq0` (in `s0`, `2n` a seed) and
/// parameter rates, beyond `1e-8` of the seed's and the row's scales (as the velocity-level
/// check). From `h` recorded with its parameters as inputs and differentiated; `None` also where
/// the model offers no recording of its functions or a value leaves it (`re()`).
fn position_off_holonomic<M: Model + ?Sized>(
    model: &M,
    (t0, q0, qd0): (f64, &[f64], &[f64]),
    seeds: &[Seed],
    s0: &[f64],
    scales: &[f64],
) -> Option<(usize, usize, f64, SeedPart)> {
    let (n, k) = model.sizes();
    let holonomic = model.holonomic_count();
    if holonomic == 0 {
        return None;
    }
    let (mut g, inputs, (offered, h), params) = record_at(t0, q0, qd0, |ts, qs, qds| {
        let mut out = Functions::<Sym>::new(n, k - holonomic, holonomic);
        let offered = model.functions(Point::new(ts, qs, qds), &mut out);
        (
            offered,
            out.h.iter().map(|s| s.node()).collect::<Vec<u32>>(),
        )
    })?;
    if !offered {
        return None;
    }
    let wrt: Vec<u32> = inputs[1..=n]
        .iter()
        .copied()
        .chain(params.iter().map(|p| p.3))
        .collect();
    for (b, &hb) in h.iter().enumerate() {
        let grad: Vec<f64> = g
            .gradient(hb, &wrt, DEP_Q | DEP_P)
            .into_iter()
            .map(|id| g.value(id))
            .collect();
        let size = grad[..n]
            .iter()
            .map(|x| x.abs())
            .sum::<f64>()
            .max(g.value(hb).abs());
        for (j, seed) in seeds.iter().enumerate() {
            let dq = &s0[2 * n * j..2 * n * j + n];
            let by_position = grad[..n].iter().zip(dq).map(|(a, b)| a * b).sum::<f64>();
            let by_parameter = params
                .iter()
                .zip(&grad[n..])
                .map(|(p, d)| d * seed.rate(&p.0))
                .sum::<f64>();
            let moved = by_position + by_parameter;
            if moved.abs() > 1e-8 * scales[j] * size.max(1.0) {
                let part = if by_position.abs() >= by_parameter.abs() {
                    SeedPart::Position
                } else {
                    SeedPart::Parameter
                };
                return Some((j, b, moved, part));
            }
        }
    }
    None
}

/// The variational equations of a problem's motion for a set of seeds: what the reduced ODE
/// carries after `(q, q̇)` when sensitivities are asked for.
pub(crate) struct Variational {
    n: usize,
    compiled: Compiled,
    seeds: Vec<Seed>,
    /// Per seed, the rates of the compiled equations' parameters (in their input order).
    dp: Vec<Vec<f64>>,
    /// Whether `S` is under error control.
    pub(crate) controlled: bool,
    /// The right-hand side's workspace: [`LANES`] seeds per pass.
    lanes: Workspace<Lanes>,
    hyper: Option<Workspace<HyperDual64>>,
    /// Scratch: the dual inputs.
    lq: Vec<Lanes>,
    lqd: Vec<Lanes>,
    lp: Vec<Lanes>,
    /// Recordings made again where a branch of the model's code flipped.
    pub(crate) rerecords: usize,
}

impl Variational {
    /// The variational equations of `model` at its initial state for `seeds`; checks that every
    /// parameter named is read by the model or a smooth event, and that each seed keeps the
    /// initial state on the constraints to first order.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new<M: Model + ?Sized>(
        model: &M,
        t0: f64,
        q0: &[f64],
        qd0: &[f64],
        seeds: &[Seed],
        events: &[Event],
        controlled: bool,
    ) -> Result<Self, Error> {
        let n = q0.len();
        for (j, seed) in seeds.iter().enumerate() {
            if seeds[..j].iter().any(|s| s.name == seed.name) {
                return Err(invalid(format!(
                    "two seeds are named {:?}; give each a name of its own",
                    seed.name
                )));
            }
            if let Some(&(i, _)) = seed
                .positions
                .iter()
                .chain(&seed.velocities)
                .find(|(i, _)| *i >= n)
            {
                return Err(invalid(format!(
                    "seed \"{}\" moves coordinate index {i}, but the model has {n} coordinates \
                     (indices 0 to {})",
                    seed.name,
                    n.saturating_sub(1)
                )));
            }
            let rates = seed
                .parameters
                .iter()
                .map(|p| p.1)
                .chain(seed.positions.iter().chain(&seed.velocities).map(|p| p.1));
            if let Some(r) = rates.into_iter().find(|r| !r.is_finite()) {
                return Err(invalid(format!(
                    "seed \"{}\" has a rate {r}; rates must be finite",
                    seed.name
                )));
            }
        }
        let compiled = Compiled::with_parameters(model, t0, q0, qd0)?;
        // Every parameter read, by the model and the smooth events, with the value and who read it
        // first: one name stands for one value, wherever it is read.
        let mut read: Vec<(String, f64, String)> = compiled
            .parameters()
            .iter()
            .map(|p| (p.0.clone(), p.1, "the model".to_string()))
            .collect();
        for e in events {
            let Some(grad) = e.gradient.as_ref().and_then(|g| g(t0, q0, qd0)) else {
                continue;
            };
            for (name, value, _) in grad.params {
                match read.iter().find(|r| r.0 == name) {
                    Some((_, first, by)) if first.to_bits() != value.to_bits() => {
                        return Err(invalid(format!(
                            "parameter {name:?} is read as {first} by {by} and as {value} by \
                             event {:?}; one name stands for one value: read both as the same \
                             value, or give them different names",
                            e.name
                        )));
                    }
                    Some(_) => {}
                    None => read.push((name, value, format!("event {:?}", e.name))),
                }
            }
        }
        let known: Vec<String> = read.into_iter().map(|r| r.0).collect();
        // A model with branches may read a parameter only on a branch not taken at the start.
        let branches = compiled.branches() > 0;
        for seed in seeds.iter().filter(|_| !branches) {
            if let Some((name, _)) = seed.parameters.iter().find(|(p, _)| !known.contains(p)) {
                let list = if known.is_empty() {
                    "none".to_string()
                } else {
                    known.join(", ")
                };
                return Err(invalid(format!(
                    "seed \"{}\" moves parameter {name:?}, which neither the model nor a smooth \
                     event reads (they read: {list}); read it as R::parameter({name:?}, value)",
                    seed.name
                )));
            }
        }
        let k = model.sizes().1;
        let mut v = Self {
            n,
            dp: Vec::new(),
            compiled,
            seeds: seeds.to_vec(),
            controlled,
            lanes: Workspace::new(n, k),
            hyper: None,
            lq: vec![Lanes::from_re(0.0); n],
            lqd: vec![Lanes::from_re(0.0); n],
            lp: Vec::new(),
            rerecords: 0,
        };
        v.rates();
        let mut s0 = vec![0.0; v.len()];
        v.initial(&mut s0);
        let scales: Vec<f64> = (0..seeds.len())
            .map(|j| {
                let s = &s0[2 * n * j..2 * n * (j + 1)];
                1.0 + s.iter().chain(&v.dp[j]).map(|x| x.abs()).sum::<f64>()
            })
            .collect();
        // The position first: a seed that moves it off `h = 0` would be reported, less clearly,
        // through `ḣ`, or not at all.
        if let Some((j, b, residual, moved_by)) =
            position_off_holonomic(model, (t0, q0, qd0), seeds, &s0, &scales)
        {
            return Err(Error::InconsistentSeed {
                seed: seeds[j].name.clone(),
                constraint: k - model.holonomic_count() + b + 1,
                holonomic: Some(b + 1),
                position: true,
                residual,
                moved_by,
            });
        }
        // The rows of `f` are the velocity constraints, then `ḣ` of the holonomic ones.
        let velocity = k - model.holonomic_count();
        // Whether each seed moves a parameter that the equations read.
        let moves_parameters: Vec<bool> =
            v.dp.iter()
                .map(|rates| rates.iter().any(|r| *r != 0.0))
                .collect();
        for first in (0..seeds.len()).step_by(LANES) {
            let d = v.lanes(model, Point::new(t0, q0, qd0), &s0, first, Need::All)?;
            for (a, fa) in d.f.iter().enumerate() {
                let row = &d.j[a * n..(a + 1) * n];
                let size = row.iter().map(|x| x.abs()).sum::<f64>().max(fa.re.abs());
                for (l, j) in (first..seeds.len().min(first + LANES)).enumerate() {
                    let rate = lane(fa, l);
                    if rate.abs() > 1e-8 * scales[j] * size.max(1.0) {
                        // The velocity's term is `∂f_a/∂q̇·δq̇0`; the rest is the position's or the
                        // parameters', told apart by what the seed moves.
                        let dqd = &s0[2 * n * j + n..2 * n * (j + 1)];
                        let by_velocity: f64 = row.iter().zip(dqd).map(|(a, b)| a * b).sum();
                        let rest = rate - by_velocity;
                        let seed = &seeds[j];
                        let moved_by = if by_velocity.abs() >= rest.abs() {
                            SeedPart::Velocity
                        } else if moves_parameters[j] {
                            SeedPart::Parameter
                        } else {
                            SeedPart::Position
                        };
                        return Err(Error::InconsistentSeed {
                            seed: seed.name.clone(),
                            constraint: a + 1,
                            holonomic: a.checked_sub(velocity).map(|b| b + 1),
                            position: false,
                            residual: rate,
                            moved_by,
                        });
                    }
                }
            }
        }
        Ok(v)
    }

    /// The seeds' parameter rates in the compiled equations' input order.
    fn rates(&mut self) {
        let params = self.compiled.parameters();
        self.dp = self
            .seeds
            .iter()
            .map(|s| params.iter().map(|(name, _)| s.rate(name)).collect())
            .collect();
    }

    /// The seeds' names.
    pub(crate) fn names(&self) -> Vec<String> {
        self.seeds.iter().map(|s| s.name.clone()).collect()
    }

    /// Length of `S`: `2n` per seed.
    pub(crate) fn len(&self) -> usize {
        2 * self.n * self.seeds.len()
    }

    /// `S(t0)`.
    pub(crate) fn initial(&self, s: &mut [f64]) {
        s.fill(0.0);
        let n = self.n;
        for (j, seed) in self.seeds.iter().enumerate() {
            for &(i, r) in &seed.positions {
                s[2 * n * j + i] += r;
            }
            for &(i, r) in &seed.velocities {
                s[2 * n * j + n + i] += r;
            }
        }
    }

    /// Records the equations again at `(t, q, q̇)`, where a branch of the model's code flipped.
    fn rerecord<M: Model + ?Sized>(&mut self, model: &M, x: Point<f64>) -> Result<(), Error> {
        self.compiled = Compiled::with_parameters(model, x.t, x.q, x.qd)?;
        let k = model.sizes().1;
        self.lanes = Workspace::new(self.n, k);
        self.hyper = None;
        self.rates();
        self.rerecords += 1;
        Ok(())
    }

    /// The equations at `(t, q, q̇)` with the derivative parts of seeds `first..first + LANES`
    /// (those that exist): `(S, δp)` of each in its lane. Where a branch of the model's code goes
    /// the other way than when recorded, the equations are recorded again there.
    fn lanes<M: Model + ?Sized>(
        &mut self,
        model: &M,
        x: Point<f64>,
        s: &[f64],
        first: usize,
        need: Need,
    ) -> Result<&Dynamics<Lanes>, Error> {
        let (n, t, q, qd) = (self.n, x.t, x.q, x.qd);
        let count = (self.seeds.len() - first).min(LANES);
        let rate = |l: usize, i: usize| {
            if l < count {
                s[2 * n * (first + l) + i]
            } else {
                0.0
            }
        };
        for i in 0..n {
            self.lq[i] = lanes(q[i], |l| rate(l, i));
            self.lqd[i] = lanes(qd[i], |l| rate(l, n + i));
        }
        self.with_recording(model, x, |v| {
            let dp = &v.dp;
            v.lp.clear();
            v.lp.extend(
                v.compiled
                    .parameters()
                    .iter()
                    .enumerate()
                    .map(|(k, p)| lanes(p.1, |l| if l < count { dp[first + l][k] } else { 0.0 })),
            );
            let point = Point::new(Lanes::from_re(t), &v.lq, &v.lqd);
            evaluate_compiled(&v.compiled, &mut v.lanes, &v.lp, point, need).map(|_| ())
        })?;
        Ok(self.lanes.dynamics())
    }

    /// Runs `eval`, an evaluation of the compiled equations at `(t, q, q̇)`; where a branch of
    /// the model's code goes the other way than when recorded, records the equations again there
    /// and runs it once more.
    fn with_recording<M: Model + ?Sized>(
        &mut self,
        model: &M,
        x: Point<f64>,
        mut eval: impl FnMut(&mut Self) -> Result<(), CompiledFailure>,
    ) -> Result<(), Error> {
        let t = x.t;
        for again in [false, true] {
            match eval(self) {
                Ok(()) => return Ok(()),
                Err(CompiledFailure::Saddle(e)) => return Err(locate(e, t, x.q, x.qd)),
                Err(CompiledFailure::Guard(_)) if !again => self.rerecord(model, x)?,
                Err(CompiledFailure::Guard(_)) => {}
            }
        }
        Err(invalid(format!(
            "the model's branches at t = {t} are not those of its own recording there"
        )))
    }

    /// The total derivatives `dμ/dθ = ∂μ/∂y · S + ∂μ/∂p · δp` (k per seed, into `dmu`) and
    /// `dΦ/dθ` (n per seed, into `dphi`) at `(t, q, q̇)` given `S` there: the equations evaluated
    /// with the same dual numbers as the right-hand side, [`LANES`] seeds per evaluation.
    pub(crate) fn multipliers<M: Model + ?Sized>(
        &mut self,
        model: &M,
        x: Point<f64>,
        s: &[f64],
        (dmu, dphi): (&mut Vec<f64>, &mut Vec<f64>),
    ) -> Result<(), Error> {
        let (n, m, k) = (self.n, self.seeds.len(), model.sizes().1);
        dmu.clear();
        dmu.resize(k * m, 0.0);
        dphi.clear();
        dphi.resize(n * m, 0.0);
        for first in (0..m).step_by(LANES) {
            let d = self.lanes(model, x, s, first, Need::All)?;
            for (l, j) in (first..m.min(first + LANES)).enumerate() {
                for (a, mu) in d.mu.iter().enumerate() {
                    dmu[k * j + a] = lane(mu, l);
                }
                for (i, phi) in d.phi.iter().enumerate() {
                    dphi[n * j + i] = lane(phi, l);
                }
            }
        }
        Ok(())
    }

    /// `dS = (S_q̇, ∂F/∂y · S + ∂F/∂p · δp)` for every seed at `(t, q, q̇)`, [`LANES`] seeds per
    /// evaluation of the equations.
    pub(crate) fn rhs<M: Model + ?Sized>(
        &mut self,
        model: &M,
        x: Point<f64>,
        s: &[f64],
        ds: &mut [f64],
    ) -> Result<(), Error> {
        let (n, m) = (self.n, self.seeds.len());
        for first in (0..m).step_by(LANES) {
            let d = self.lanes(model, x, s, first, Need::Motion)?;
            for (i, a) in d.qdd.iter().enumerate() {
                for (l, j) in (first..m.min(first + LANES)).enumerate() {
                    ds[2 * n * j + n + i] = lane(a, l);
                }
            }
        }
        for j in 0..m {
            // d(∂q/∂θ)/dt = ∂q̇/∂θ.
            let at = 2 * n * j;
            ds[at..at + n].copy_from_slice(&s[at + n..at + 2 * n]);
        }
        if ds.iter().any(|v| !v.is_finite()) {
            let non_finite = crate::equations::saddle::SaddleFailure::NonFinite;
            return Err(locate(non_finite, x.t, x.q, x.qd));
        }
        Ok(())
    }

    /// The rows of `S` in the Jacobian of the whole system (row-major, `dim × dim`, with `S` at
    /// offset `2n`) and in `∂F/∂t`: the base block `∂F/∂y` (already in rows and columns `0..2n`) on
    /// the diagonal, and `∂/∂y (∂F/∂y · S + ∂F/∂p · δp)` by hyper-dual numbers.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn jacobian<M: Model + ?Sized>(
        &mut self,
        model: &M,
        t: f64,
        y: &[f64],
        dim: usize,
        jac: &mut [f64],
        dfdt: &mut [f64],
    ) -> Result<(), Error> {
        let n = self.n;
        let k = model.sizes().1;
        let (q, qd) = (&y[..n], &y[n..2 * n]);
        let h = |re: f64| HyperDual64::new(re, 0.0, 0.0, 0.0);
        let mut hq: Vec<HyperDual64> = q.iter().map(|&v| h(v)).collect();
        let mut hqd: Vec<HyperDual64> = qd.iter().map(|&v| h(v)).collect();
        let mut hp: Vec<HyperDual64> = Vec::new();
        for j in 0..self.seeds.len() {
            let off = 2 * n + 2 * n * j;
            for r in 0..2 * n {
                for c in 0..2 * n {
                    jac[(off + r) * dim + off + c] = jac[r * dim + c];
                }
            }
            let s = &y[off..off + 2 * n];
            for dir in 0..=2 * n {
                let seed = |i: usize| if i == dir { 1.0 } else { 0.0 };
                for i in 0..n {
                    hq[i] = HyperDual64::new(q[i], seed(i), s[i], 0.0);
                    hqd[i] = HyperDual64::new(qd[i], seed(n + i), s[n + i], 0.0);
                }
                let ht = HyperDual64::new(t, seed(2 * n), 0.0, 0.0);
                self.with_recording(model, Point::new(t, q, qd), |v| {
                    // The parameters in the equations' input order (they change where the
                    // equations are recorded again).
                    hp.clear();
                    hp.extend(
                        v.compiled
                            .parameters()
                            .iter()
                            .zip(&v.dp[j])
                            .map(|(p, &r)| HyperDual64::new(p.1, 0.0, r, 0.0)),
                    );
                    let ws = v.hyper.get_or_insert_with(|| Workspace::new(n, k));
                    let point = Point::new(ht, &hq, &hqd);
                    evaluate_compiled(&v.compiled, ws, &hp, point, Need::Motion).map(|_| ())
                })?;
                let d = self.hyper.as_ref().map(Workspace::dynamics);
                for (i, a) in d.iter().flat_map(|d| d.qdd.iter()).enumerate() {
                    if dir < 2 * n {
                        jac[(off + n + i) * dim + dir] = a.eps1eps2;
                    } else {
                        dfdt[off + n + i] = a.eps1eps2;
                    }
                }
            }
            for i in 0..n {
                dfdt[off + i] = 0.0;
            }
        }
        Ok(())
    }

    /// How the event `event` at `(t, q, q̇)` with `q̈` moves with each seed, given `S` there.
    pub(crate) fn at_event(
        &self,
        event: &Event,
        t: f64,
        (q, qd, qdd): (&[f64], &[f64], &[f64]),
        s: &[f64],
    ) -> Option<EventSensitivity> {
        let n = self.n;
        let grad = (event.gradient.as_ref()?)(t, q, qd)?;
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let rate = grad.t + dot(&grad.q, qd) + dot(&grad.qd, qdd);
        if rate == 0.0 || !rate.is_finite() {
            return None;
        }
        let mut out = EventSensitivity {
            t: Vec::new(),
            q: Vec::new(),
            qd: Vec::new(),
        };
        for (j, seed) in self.seeds.iter().enumerate() {
            let sj = &s[2 * n * j..2 * n * (j + 1)];
            let dp: f64 = grad
                .params
                .iter()
                .map(|(name, _, d)| d * seed.rate(name))
                .sum();
            let dt = -(dot(&grad.q, &sj[..n]) + dot(&grad.qd, &sj[n..]) + dp) / rate;
            out.t.push(dt);
            out.q.push((0..n).map(|i| sj[i] + qd[i] * dt).collect());
            out.qd
                .push((0..n).map(|i| sj[n + i] + qdd[i] * dt).collect());
        }
        out.t
            .iter()
            .chain(out.q.iter().flatten())
            .chain(out.qd.iter().flatten())
            .all(|v| v.is_finite())
            .then_some(out)
    }
}
