//! `[sensitivities]`: from the parameters asked for to one [`Seed`] each.
//!
//! A seed for the parameter `p` moves, at their rates `dp_i/dp` (computed in
//! [`parameters`](super::parameters)), the parameters the model and the events read that are `p`
//! or are computed from it; and the initial values written as expressions of `p`, at the rates
//! of those expressions, evaluated with dual numbers:
//!
//! ```text
//! δq0_i = ∂q0_i/∂p,      δq̇0_i = ∂q̇0_i/∂p,      q0_i, q̇0_i as written under [initial]
//! ```
//!
//! So `q_dot = ["v0", 0.0]` makes the seed of `v0` move `ẋ(0)` at rate 1, and the initial state
//! stays on `ẋ² + ẏ² = v0²` to first order without anything more in the file.

use chetaev::Seed;
use num_dual::Dual64;
use toml::Spanned;

use super::parameters::Parameters;
use super::schema::{Number, RawSensitivities};
use super::spec::SensitivitySpec;
use super::validate::Builder;
use crate::error::Error;
use crate::expr::{Env, Expr, Symbols};

/// For each initial value and each parameter asked for, `∂x0/∂p`, or `None` where the value does
/// not depend on `p`.
pub(super) type InitialRates = Vec<Vec<Option<f64>>>;

impl Builder {
    /// The rates of the initial values `list` (`initial.q` or `initial.q_dot`, already checked)
    /// with respect to each parameter asked for, by dual numbers through their expressions;
    /// `varying` resolves the parameters that move as parameter nodes.
    pub(super) fn initial_rates(
        &self,
        list: &Spanned<Vec<Spanned<Number>>>,
        varying: &Symbols,
        parameters: &Parameters,
    ) -> Result<InitialRates, Error> {
        let asked = parameters.asked.len();
        let duals: Vec<Vec<Dual64>> = (0..asked).map(|a| parameters.duals(a)).collect();
        let env = Env {
            t: Dual64::from(0.0),
            q: &[],
            qd: &[],
        };
        list.get_ref()
            .iter()
            .map(|v| {
                let Number::Expr(text) = v.get_ref() else {
                    return Ok(vec![None; asked]);
                };
                let e = self.expr(&Spanned::new(v.span(), text.clone()), varying)?;
                let reads = e.varying_parameters();
                Ok((0..asked)
                    .map(|a| {
                        let moves = reads.iter().any(|&i| parameters.rates[i][a].is_some());
                        moves.then(|| e.eval_with_parameters(&env, &duals[a]).eps)
                    })
                    .collect())
            })
            .collect()
    }

    /// One seed per parameter asked for. `reads` are the indices of the parameters the model and
    /// the events read; `q_rates`, `qd_rates` the rates of the initial values.
    pub(super) fn seeds(
        &self,
        raw: &RawSensitivities,
        parameters: &Parameters,
        reads: &[usize],
        q_rates: &InitialRates,
        qd_rates: &InitialRates,
    ) -> Result<SensitivitySpec, Error> {
        let mut seeds = Vec::new();
        for (a, &p) in parameters.asked.iter().enumerate() {
            let name = &parameters.values[p].0;
            let mut seed = Seed::new(name.clone());
            for &i in reads {
                if let Some(rate) = parameters.rates[i][a] {
                    seed = seed.with_parameter(&parameters.values[i].0, rate);
                }
            }
            for (i, r) in q_rates.iter().enumerate() {
                if let Some(rate) = r[a] {
                    seed = seed.with_position(i, rate);
                }
            }
            for (i, r) in qd_rates.iter().enumerate() {
                if let Some(rate) = r[a] {
                    seed = seed.with_velocity(i, rate);
                }
            }
            let rates = seed
                .positions
                .iter()
                .chain(&seed.velocities)
                .map(|(_, r)| *r)
                .chain(seed.parameters.iter().map(|(_, r)| *r));
            if let Some(r) = rates.clone().find(|r| !r.is_finite()) {
                return Err(self.err(
                    self.inside(&raw.parameters.get_ref()[a]),
                    format!(
                        "an initial value's derivative with respect to '{name}' is {r} at the \
                         values given (a square root or logarithm at 0?), so sensitivities with \
                         respect to '{name}' do not exist here"
                    ),
                ));
            }
            if seed.parameters.is_empty() && seed.positions.is_empty() && seed.velocities.is_empty()
            {
                return Err(self.err(
                    self.inside(&raw.parameters.get_ref()[a]),
                    format!(
                        "the motion does not depend on '{name}': neither the model, the events nor \
                         the initial state use it (or a parameter computed from it), so every \
                         derivative with respect to it is 0; remove it from [sensitivities] \
                         parameters"
                    ),
                ));
            }
            seeds.push(seed);
        }
        Ok(SensitivitySpec {
            parameters: parameters
                .asked
                .iter()
                .map(|&p| parameters.values[p].0.clone())
                .collect(),
            control: raw.control.as_ref().is_some_and(|c| *c.get_ref()),
            seeds,
        })
    }
}

impl Builder {
    /// Refuses a seed that moves a holonomic constraint `h(t, q) = 0` off zero at the start to
    /// first order: `δh = ∂h/∂q δq0 + ∂h/∂p δp`, where the initial position is not written with a
    /// parameter the constraint reads (`q = [2.0, 0.0]` for `x^2 + y^2 - l^2` moving `l`). The
    /// library checks the velocity constraints, not this.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn check_holonomic(
        &self,
        holonomic: &[Expr],
        t0: f64,
        q0: &[f64],
        q_rates: &InitialRates,
        parameters: &Parameters,
        span: std::ops::Range<usize>,
    ) -> Result<(), Error> {
        let fixed: Vec<Dual64> = parameters
            .values
            .iter()
            .map(|(_, v)| Dual64::from(*v))
            .collect();
        let zero = vec![Dual64::from(0.0); q0.len()];
        for (a, &p) in parameters.asked.iter().enumerate() {
            let moved = parameters.duals(a);
            let q_moved: Vec<Dual64> = q0
                .iter()
                .zip(q_rates)
                .map(|(x, r)| Dual64::new(*x, r[a].unwrap_or(0.0)))
                .collect();
            let q_fixed: Vec<Dual64> = q0.iter().map(|x| Dual64::from(*x)).collect();
            let delta = |q: &[Dual64], params: &[Dual64], h: &Expr| {
                let env = Env {
                    t: Dual64::from(t0),
                    q,
                    qd: &zero,
                };
                h.eval_with_parameters(&env, params).eps
            };
            for (b, h) in holonomic.iter().enumerate() {
                let by_q = delta(&q_moved, &fixed, h);
                let by_p = delta(&q_fixed, &moved, h);
                let residual = by_q + by_p;
                if residual.abs() > 1e-8 * by_q.abs().max(by_p.abs()) {
                    let name = &parameters.values[p].0;
                    return Err(self.err(
                        span,
                        format!(
                            "moving '{name}' moves the initial position off the holonomic \
                             constraint {} ({}) to first order (∂h/∂q δq0 + ∂h/∂p δp = {residual:e}): \
                             write the initial coordinates that the constraint ties to '{name}' as \
                             expressions of it (for x^2 + y^2 - l^2, q = [\"l*sin(theta0)\", \
                             \"-l*cos(theta0)\"])",
                            b + 1,
                            h.source()
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}

/// The indices of the parameters that `exprs` read as parameter nodes, each once, increasing.
pub(super) fn reads<'a>(exprs: impl IntoIterator<Item = &'a Expr>) -> Vec<usize> {
    let mut all: Vec<usize> = exprs
        .into_iter()
        .flat_map(Expr::varying_parameters)
        .collect();
    all.sort_unstable();
    all.dedup();
    all
}
