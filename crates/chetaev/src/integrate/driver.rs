//! The driver: step-size control, output, events and projection, the same for every method.

use super::events::{locate_root, EventHit};
use super::options::{Atol, Options, Output, Record};
use super::projection::project_velocity;
use super::system::{split, ChetaevOde, OdeSystem};
use super::{ErrorNorm, Method, Stepper};
use crate::error::Error;
use crate::model::Model;
use crate::problem::{check_finite, Problem};
use crate::solution::{Solution, Status};

/// Step-size controller: safety factor and bounds on the change of `h` per step.
const SAFETY: f64 = 0.9;
const FAC_MIN: f64 = 0.2;
const FAC_MAX: f64 = 10.0;

/// Integrates `problem` with `method` as `options` ask.
///
/// Bad options are an `Err`. A failure during the integration (a singular block system, a model
/// evaluating to NaN, a step size too small, the step limit, stiffness detected by an explicit
/// method) is the [`Status::Failed`] of the returned solution, which keeps everything computed
/// up to that point.
///
/// ```
/// use chetaev::prelude::*;
///
/// struct Uniform { g: f64, v0: f64 }
/// impl Lagrangian<2> for Uniform {
///     fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
///         qd.dot(qd) * 0.5 - q[1] * self.g
///     }
/// }
/// impl Constraints<2, 1> for Uniform {
///     fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
///         SVector::from([qd.dot(qd) - self.v0 * self.v0])
///     }
/// }
///
/// let model = Uniform { g: 10.0, v0: 10.0 };
/// let problem = Problem::new(model, 0.0, SVector::from([0.0, 5.0]), SVector::from([10.0, 0.0]))?;
/// let ground = Event::new("ground", |_t, q, _qd| q[1]).falling().terminal();
/// let sol = solve(&problem, Dopri5::default(), &Options::until(10.0).tolerances(1e-10, 1e-12).event(ground))?;
/// let t_impact = sol.events[0].t;
/// // (42.38): T = (v0/g) arccosh(exp(g h0 / v0²))
/// assert!((t_impact - (0.5f64.exp()).acosh()).abs() < 1e-8);
/// # Ok::<(), chetaev::Error>(())
/// ```
pub fn solve<M, Me, const N: usize, const K: usize>(
    problem: &Problem<M, N, K>,
    method: Me,
    options: &Options<N>,
) -> Result<Solution<N, K>, Error>
where
    M: Model<N, K>,
    Me: Method,
{
    validate(options)?;
    method.validate()?;
    let t0 = problem.t0();
    let t_end = options.t_end;
    let mut sys = ChetaevOde::new(problem.model(), options.record >= Record::Energy);
    let dim = sys.dim();
    let mut y = vec![0.0; dim];
    y[..N].copy_from_slice(problem.q0().as_slice());
    y[N..2 * N].copy_from_slice(problem.qd0().as_slice());
    let norm = error_norm(options, N);

    let mut sol = Solution::new(method.name(), options.record);
    let mut run = Run {
        sys: &mut sys,
        sol: &mut sol,
        options,
    };
    let outcome = run.integrate(method, t0, t_end, &mut y, &norm);
    if let Err(e) = outcome {
        run.sol.status = Status::Failed(e);
    }
    let stats = sys.stats;
    sol.stats = Stats { ..stats };
    Ok(sol)
}

use super::system::Stats;

fn validate<const N: usize>(o: &Options<N>) -> Result<(), Error> {
    check_finite("t_end", std::slice::from_ref(&o.t_end))?;
    let positive = |name: &'static str, v: f64, hint: &'static str| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(Error::InvalidOption {
                name,
                value: v,
                hint,
            })
        }
    };
    if !(o.rtol.is_finite() && o.rtol >= 0.0) {
        return Err(Error::InvalidOption {
            name: "rtol",
            value: o.rtol,
            hint:
                "the relative tolerance must be finite and non-negative; 1e-6 to 1e-13 are typical",
        });
    }
    let atols: Vec<f64> = match &o.atol {
        Atol::Scalar(a) => vec![*a],
        Atol::PerComponent(v) => {
            if v.len() != 2 * N {
                return Err(Error::InvalidOption {
                    name: "atol (length)",
                    value: v.len() as f64,
                    hint: "give one absolute tolerance per component of (q, q̇), 2N in all",
                });
            }
            v.clone()
        }
    };
    for a in atols {
        if !(a.is_finite() && a >= 0.0) || (a == 0.0 && o.rtol == 0.0) {
            return Err(Error::InvalidOption {
                name: "atol",
                value: a,
                hint: "absolute tolerances must be finite and non-negative, and not zero together with rtol",
            });
        }
    }
    if o.rtol < 100.0 * f64::EPSILON && o.rtol != 0.0 {
        return Err(Error::InvalidOption {
            name: "rtol",
            value: o.rtol,
            hint: "below 100 ulps (2.2e-14) no step size can meet the tolerance in f64; use 1e-13 or more",
        });
    }
    if let Some(h) = o.initial_step {
        positive("initial_step", h.abs(), "a finite non-zero first step")?;
    }
    if let Some(h) = o.max_step {
        positive("max_step", h, "a finite positive bound")?;
    }
    if o.max_steps == 0 {
        return Err(Error::InvalidOption {
            name: "max_steps",
            value: 0.0,
            hint: "allow at least one step",
        });
    }
    if let Output::Times(ts) = &o.output {
        check_finite("output time", ts)?;
    }
    if let Some(p) = &o.projection {
        positive(
            "projection tol",
            p.tol,
            "a small positive relative residual such as 1e-14",
        )?;
    }
    Ok(())
}

fn error_norm<const N: usize>(o: &Options<N>, n: usize) -> ErrorNorm {
    let atol = match &o.atol {
        Atol::Scalar(a) => vec![*a; 2 * n],
        Atol::PerComponent(v) => v.clone(),
    };
    ErrorNorm::new(o.rtol, atol)
}

struct Run<'s, 'a, M, const N: usize, const K: usize> {
    sys: &'s mut ChetaevOde<'a, M, N, K>,
    sol: &'s mut Solution<N, K>,
    options: &'s Options<N>,
}

impl<M: Model<N, K>, const N: usize, const K: usize> Run<'_, '_, M, N, K> {
    /// Records `(t, y)` with what the record level asks for.
    fn record(&mut self, t: f64, y: &[f64]) -> Result<(), Error> {
        let (q, qd) = split::<N>(y);
        // Evaluate before pushing anything, so a failure leaves every recorded vector the same length.
        let d = if self.options.record >= Record::Dynamics {
            Some(self.sys.evaluate(t, &q, &qd)?)
        } else {
            None
        };
        let sol = &mut *self.sol;
        sol.t.push(t);
        sol.q.push(q);
        sol.qd.push(qd);
        if let Some(d) = d {
            sol.qdd.push(d.qdd);
            sol.mu.push(d.mu);
            sol.phi.push(d.phi);
            sol.residual.push(d.f);
            sol.energy.push(d.energy);
        }
        if self.options.record >= Record::Energy {
            sol.work.push(y[2 * N]);
            sol.dl_dt_integral.push(y[2 * N + 1]);
        }
        Ok(())
    }

    fn events_at(&mut self, t: f64, y: &[f64], out: &mut [f64]) -> Result<(), Error> {
        let (q, qd) = split::<N>(y);
        for (i, e) in self.options.events.iter().enumerate() {
            self.sys.stats.event_evaluations += 1;
            let v = (e.g)(t, &q, &qd);
            if !v.is_finite() {
                return Err(Error::NonFiniteEvent {
                    index: i,
                    t,
                    value: v,
                });
            }
            out[i] = v;
        }
        Ok(())
    }

    fn project(&mut self, t: f64, y: &mut [f64]) -> Result<bool, Error> {
        let Some(p) = self.options.projection else {
            return Ok(false);
        };
        if K == 0 {
            return Ok(false);
        }
        let (q, qd) = split::<N>(y);
        let r = project_velocity(
            self.sys.model,
            &mut self.sys.ws,
            t,
            &q,
            &qd,
            p.tol,
            p.max_iterations,
        )?;
        self.sys.stats.projections += 1;
        self.sys.stats.projection_iterations += r.iterations;
        y[N..2 * N].copy_from_slice(r.qd.as_slice());
        Ok(r.iterations > 0)
    }

    fn integrate<Me: Method>(
        &mut self,
        method: Me,
        t0: f64,
        t_end: f64,
        y: &mut [f64],
        norm: &ErrorNorm,
    ) -> Result<(), Error> {
        let options = self.options;
        self.record(t0, y)?;
        if t_end == t0 {
            return Ok(());
        }
        let dir = (t_end - t0).signum();
        let dim = y.len();
        let mut stepper = method.stepper(dim);
        stepper.reset(self.sys, t0, y)?;

        let n_events = options.events.len();
        let mut g_old = vec![0.0; n_events];
        let mut g_new = vec![0.0; n_events];
        self.events_at(t0, y, &mut g_old)?;
        let mut pending_times: Vec<f64> = match &options.output {
            Output::Times(ts) => {
                let mut v: Vec<f64> = ts
                    .iter()
                    .copied()
                    .filter(|&s| dir * (s - t0) > 0.0 && dir * (s - t_end) <= 0.0)
                    .collect();
                v.sort_by(|a, b| (dir * a).total_cmp(&(dir * b)));
                v
            }
            _ => Vec::new(),
        };
        pending_times.reverse(); // pop from the back in time order
        let h_max = options
            .max_step
            .unwrap_or(f64::INFINITY)
            .min((t_end - t0).abs());

        let mut h = match stepper.fixed_step() {
            Some(h) => h,
            None => match options.initial_step {
                Some(h) => h.abs(),
                None => self.initial_step(&mut stepper, t0, y, t_end, norm, dir)?,
            },
        }
        .min(h_max)
            * dir;

        let mut t = t0;
        let mut y_new = vec![0.0; dim];
        let mut buf = vec![0.0; dim];
        let mut steps = 0usize;
        let mut rejected_last = false;
        let order = stepper.control_order();
        loop {
            if steps >= options.max_steps {
                return Err(Error::MaxSteps {
                    t,
                    max_steps: options.max_steps,
                });
            }
            steps += 1;
            let remaining = t_end - t;
            // Land exactly on t_end; avoid a sliver of a last step by stretching within 1%.
            let last = (h * 1.01).abs() >= remaining.abs();
            if last {
                h = remaining;
            }
            if h.abs() <= 4.0 * f64::EPSILON * t.abs() && !last {
                return Err(Error::StepSizeTooSmall { t, h });
            }
            let trial = stepper.try_step(self.sys, t, h, y, &mut y_new, norm);
            let err = match trial {
                Ok(e) if e.is_finite() => e,
                Ok(_) | Err(Error::NonFiniteEvaluation { .. }) if order.is_some() => {
                    // A trial stage left the model's domain: retry with a smaller step.
                    self.sys.stats.rejected_steps += 1;
                    h *= 0.25;
                    rejected_last = true;
                    if h.abs() <= 4.0 * f64::EPSILON * t.abs().max(f64::MIN_POSITIVE) {
                        return Err(trial.err().unwrap_or(Error::StepSizeTooSmall { t, h }));
                    }
                    continue;
                }
                Ok(_) => {
                    let (q, qd) = split::<N>(&y_new);
                    return Err(super::system::locate(
                        crate::equations::saddle::SaddleFailure::NonFinite,
                        t + h,
                        &q,
                        &qd,
                    ));
                }
                Err(e) => return Err(e),
            };
            if err > 1.0 && order.is_some() {
                self.sys.stats.rejected_steps += 1;
                let p = order.unwrap_or(1) as f64;
                h *= (SAFETY * err.powf(-1.0 / p)).clamp(FAC_MIN, 1.0);
                rejected_last = true;
                continue;
            }

            // Accepted.
            self.sys.stats.accepted_steps += 1;
            stepper.accept(self.sys, t, h, y, &y_new)?;
            let t_new = if last { t_end } else { t + h };
            if let Some(h_lambda) = stepper.stiffness() {
                self.record(t_new, &y_new)?;
                return Err(Error::Stiff {
                    t: t_new,
                    h_lambda,
                    suggestion: stepper.stiff_alternative(),
                });
            }

            // Events on the dense output of [t, t_new].
            let mut terminal: Option<(usize, f64)> = None;
            if n_events > 0 {
                self.events_at(t_new, &y_new, &mut g_new)?;
                let mut hits: Vec<(usize, f64)> = Vec::new();
                for (i, e) in options.events.iter().enumerate() {
                    if !e.crosses(g_old[i], g_new[i]) {
                        continue;
                    }
                    let g = e.g.clone();
                    let mut evals = 0usize;
                    let mut at = |s: f64| {
                        evals += 1;
                        stepper.interpolate((s - t) / h, &mut buf);
                        let (q, qd) = split::<N>(&buf);
                        g(s, &q, &qd)
                    };
                    let (ts, _) = locate_root(&mut at, t, g_old[i], t_new, g_new[i]);
                    self.sys.stats.event_evaluations += evals;
                    hits.push((i, ts));
                }
                hits.sort_by(|a, b| (dir * a.1).total_cmp(&(dir * b.1)));
                for &(i, ts) in &hits {
                    if terminal.is_some() {
                        break;
                    }
                    if options.events[i].terminal {
                        terminal = Some((i, ts));
                    } else {
                        stepper.interpolate((ts - t) / h, &mut buf);
                        let (q, qd) = split::<N>(&buf);
                        self.sol.events.push(EventHit {
                            index: i,
                            t: ts,
                            q,
                            qd,
                        });
                    }
                }
            }
            let t_stop = terminal.map_or(t_new, |(_, ts)| ts);

            // Dense output at requested times up to the stop (an event point and the final point are
            // recorded from the method's own step below).
            while let Some(&s) = pending_times.last() {
                if dir * (s - t_stop) > 0.0 || (terminal.is_some() && s == t_stop) {
                    break;
                }
                pending_times.pop();
                if last && s == t_end {
                    break;
                }
                stepper.interpolate((s - t) / h, &mut buf);
                self.record(s, &buf)?;
            }

            if let Some((i, ts)) = terminal {
                // Land on the event with one step of the method itself, more accurate than the
                // interpolant, then stop.
                stepper.reset(self.sys, t, y)?;
                let h_event = ts - t;
                if h_event != 0.0 {
                    stepper.try_step(self.sys, t, h_event, y, &mut y_new, norm)?;
                } else {
                    y_new.copy_from_slice(y);
                }
                self.project(ts, &mut y_new)?;
                let (q, qd) = split::<N>(&y_new);
                self.sol.events.push(EventHit {
                    index: i,
                    t: ts,
                    q,
                    qd,
                });
                self.record(ts, &y_new)?;
                self.sol.status = Status::Terminated { event: i };
                return Ok(());
            }

            if self.project(t_new, &mut y_new)? {
                stepper.reset(self.sys, t_new, &y_new)?;
            }
            if last || matches!(options.output, Output::Steps) {
                self.record(t_new, &y_new)?;
            }
            std::mem::swap(&mut g_old, &mut g_new);
            y.copy_from_slice(&y_new);
            t = t_new;
            if last {
                return Ok(());
            }
            if let Some(p) = order {
                let fac_max = if rejected_last { 1.0 } else { FAC_MAX };
                let fac = if err > 0.0 {
                    SAFETY * err.powf(-1.0 / p as f64)
                } else {
                    FAC_MAX
                };
                h *= fac.clamp(FAC_MIN, fac_max);
                if h.abs() > h_max {
                    h = h_max * dir;
                }
            }
            rejected_last = false;
        }
    }

    /// Hairer's starting step (Solving ODEs I, II.4): balances `h·|F|` against the tolerance and
    /// the second derivative estimated from one Euler step.
    fn initial_step<S: Stepper>(
        &mut self,
        _stepper: &mut S,
        t0: f64,
        y0: &[f64],
        t_end: f64,
        norm: &ErrorNorm,
        dir: f64,
    ) -> Result<f64, Error> {
        let dim = y0.len();
        let p = 5.0f64;
        let mut f0 = vec![0.0; dim];
        self.sys.rhs(t0, y0, &mut f0)?;
        let zeros = vec![0.0; dim];
        let d0 = norm.norm(y0, y0, &zeros);
        let d1 = norm.norm(&f0, y0, &zeros);
        let mut h0 = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        };
        h0 = h0.min((t_end - t0).abs());
        let y1: Vec<f64> = (0..dim).map(|i| y0[i] + dir * h0 * f0[i]).collect();
        let mut f1 = vec![0.0; dim];
        self.sys.rhs(t0 + dir * h0, &y1, &mut f1)?;
        let diff: Vec<f64> = (0..dim).map(|i| f1[i] - f0[i]).collect();
        let d2 = norm.norm(&diff, y0, &zeros) / h0;
        let h1 = if d1.max(d2) <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / d1.max(d2)).powf(1.0 / p)
        };
        Ok((100.0 * h0).min(h1))
    }
}
