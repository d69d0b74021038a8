//! The Chetaev equations in the form `ode_solvers` integrates, and the solution being recorded.
//!
//! State `z = [y, s]` with `y = [q (n), q̇ (n)]`, followed with the energy balance by
//! `[W_Φ, ∫∂L/∂t dt]` (the state of [`ReducedOde`]), and the time `s`: `t = t0 + dir·s`, and
//! `dz/dτ = [dir·F(t, y), 1]` for `τ ∈ [0, |t_end − t0|]`.

use std::cell::{Cell, RefCell};

use chetaev::integrate::system::{OdeSystem, ReducedOde};
use chetaev::model::Model;
use chetaev::{Error, Solution, Status};
use ode_solvers::{DVector, System};

/// The first model failure inside the right-hand side or at a recorded step.
pub(crate) struct Failure {
    /// The error.
    pub error: Error,
    /// Right-hand sides requested by `ode_solvers` up to and including the failing one.
    pub callbacks: usize,
}

/// The reduced equations, the solution being recorded and the last accepted state.
pub(crate) struct Adapter<'a, M> {
    ode: RefCell<ReducedOde<'a, M>>,
    failure: RefCell<Option<Failure>>,
    callbacks: Cell<usize>,
    sol: Solution,
    t0: f64,
    t_end: f64,
    dir: f64,
    tau_end: f64,
    /// Index of `s` in `z` (the dimension of [`ReducedOde`]).
    m: usize,
    /// Whether every accepted step is recorded ([`Output::Steps`](chetaev::prelude::Output::Steps)).
    pub record_steps: bool,
    /// Accepted steps delivered by `ode_solvers` before any failure.
    pub accepted_steps: usize,
    /// `τ` and `z` of the last accepted step (the start before the first).
    last_tau: f64,
    last: Vec<f64>,
}

impl<'a, M: Model> Adapter<'a, M> {
    /// An adapter starting from `z0` at `t0`.
    pub fn new(
        ode: ReducedOde<'a, M>,
        sol: Solution,
        t0: f64,
        t_end: f64,
        dir: f64,
        tau_end: f64,
        z0: &[f64],
    ) -> Self {
        let m = ode.dim();
        Self {
            ode: RefCell::new(ode),
            failure: RefCell::new(None),
            callbacks: Cell::new(0),
            sol,
            t0,
            t_end,
            dir,
            tau_end,
            m,
            record_steps: true,
            accepted_steps: 0,
            last_tau: 0.0,
            last: z0.to_vec(),
        }
    }

    /// Right-hand sides requested by `ode_solvers` so far.
    pub fn callbacks(&self) -> usize {
        self.callbacks.get()
    }

    /// `τ` of the last accepted step (0 before the first).
    pub fn last_tau(&self) -> f64 {
        self.last_tau
    }

    /// The failure, if the model failed.
    pub fn take_failure(&mut self) -> Option<Failure> {
        self.failure.get_mut().take()
    }

    /// The real time of `τ`; the end is hit exactly.
    fn time(&self, tau: f64) -> f64 {
        if (self.tau_end - tau).abs() <= 4.0 * f64::EPSILON * self.tau_end {
            self.t_end
        } else {
            self.t0 + self.dir * tau
        }
    }

    /// `dz/dτ`. The time is read from `s = z[m]`, never from `ode_solvers`. After a model failure
    /// every component is NaN, which makes `ode_solvers` reject each further step until it stops.
    fn derivative(&self, z: &[f64], dz: &mut [f64]) {
        self.callbacks.set(self.callbacks.get() + 1);
        if self.failure.borrow().is_some() {
            dz.fill(f64::NAN);
            return;
        }
        let m = self.m;
        let t = self.t0 + self.dir * z[m];
        let result = self.ode.borrow_mut().rhs(t, &z[..m], &mut dz[..m]);
        match result {
            Ok(()) => {
                for v in &mut dz[..m] {
                    *v *= self.dir;
                }
                dz[m] = 1.0;
            }
            Err(error) => {
                *self.failure.borrow_mut() = Some(Failure {
                    error,
                    callbacks: self.callbacks.get(),
                });
                dz.fill(f64::NAN);
            }
        }
    }

    /// Records `z` at `t` with what the solution's record level asks for; nothing is recorded if
    /// that fails.
    pub fn record(&mut self, t: f64, z: &[f64]) -> Result<(), Error> {
        self.sol.record(self.ode.get_mut(), t, &z[..self.m])
    }

    /// Records the last accepted state, unless it is the last point recorded.
    pub fn record_last(&mut self) -> Result<(), Error> {
        let t = self.time(self.last_tau);
        if self.sol.t.last() == Some(&t) {
            return Ok(());
        }
        self.sol.record(self.ode.get_mut(), t, &self.last[..self.m])
    }

    /// The solution with its status and statistics.
    pub fn finish(self, status: Status, accepted_steps: usize, rejected_steps: usize) -> Solution {
        let stats = self.ode.into_inner().stats;
        let mut sol = self.sol;
        sol.stats = chetaev::integrate::system::Stats {
            accepted_steps,
            rejected_steps,
            ..stats
        };
        sol.status = status;
        sol
    }
}

/// What `ode_solvers` holds: it keeps the system it is given, so the adapter is lent.
pub(crate) struct Callback<'r, 'a, M>(pub &'r mut Adapter<'a, M>);

impl<M: Model> System<f64, DVector<f64>> for Callback<'_, '_, M> {
    /// The time `ode_solvers` passes is not read: it is wrong at two stages of its `Dop853`.
    fn system(&self, _tau: f64, z: &DVector<f64>, dz: &mut DVector<f64>) {
        self.0.derivative(z.as_slice(), dz.as_mut_slice());
    }

    /// Takes each accepted step: the system's check of it (the singular-point check of
    /// `Options::rank_tolerance`, on the step's last evaluation, which both methods make at the
    /// new point before calling this), then its record for `Output::Steps`. Stops `ode_solvers`
    /// once the model has failed.
    fn solout(&mut self, tau: f64, z: &DVector<f64>, _dz: &DVector<f64>) -> bool {
        let adapter = &mut *self.0;
        if adapter.failure.get_mut().is_some() {
            return true;
        }
        let t = adapter.time(tau);
        let m = adapter.m;
        let mut result = adapter.ode.get_mut().accepted(t, &z.as_slice()[..m]);
        if result.is_ok() {
            adapter.accepted_steps += 1;
            adapter.last_tau = tau;
            adapter.last.copy_from_slice(z.as_slice());
            if adapter.record_steps {
                result = adapter.record(t, z.as_slice());
            }
        }
        match result {
            Ok(()) => false,
            Err(error) => {
                let callbacks = adapter.callbacks.get();
                *adapter.failure.get_mut() = Some(Failure { error, callbacks });
                true
            }
        }
    }
}
