//! The one error type of the crate: chetaev's own errors, and the options `ode_solvers` cannot
//! honour.
//!
//! Bad input (a non-finite end time, tolerances out of range, ...) is the [`chetaev::Error`] that
//! [`chetaev::solve`] would return, wrapped in [`BackendError::Chetaev`]. Options that are valid for
//! [`chetaev::solve`] but that `ode_solvers` cannot carry out are refused with their own variant,
//! never ignored: each names the option and what to do instead. Failures during an integration
//! are not errors: they are the [`Status`](chetaev::Status) of the returned solution.

/// Everything [`solve_with_ode_solvers`](crate::solve_with_ode_solvers) can refuse.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BackendError {
    /// An error of chetaev's: bad input, the same as [`chetaev::solve`] returns for it.
    #[error(transparent)]
    Chetaev(#[from] chetaev::Error),

    /// `Options::events` is not empty.
    #[error(
        "ode_solvers has no root finding, so the {count} event function(s) of Options::events cannot be \
         located; remove them, or use chetaev::solve, which locates events"
    )]
    Events {
        /// The number of event functions given.
        count: usize,
    },

    /// `Options::projection` is set.
    #[error(
        "ode_solvers lets its step callback read the state but not change it, so the projection onto the \
         constraints (Options::projection) cannot be applied; remove it, or use chetaev::solve, which projects"
    )]
    Projection,

    /// `Options::sensitivities` is not empty.
    #[error(
        "{count} sensitivity seed(s) given, but this backend integrates the motion only, not its \
         variational equations; remove them, or use chetaev::solve, which carries them"
    )]
    Sensitivities {
        /// How many seeds were given.
        count: usize,
    },

    /// `Options::atol` is [`Atol::PerComponent`](chetaev::prelude::Atol::PerComponent).
    #[error(
        "ode_solvers applies one scalar absolute tolerance to every component, so per-component tolerances \
         (Atol::PerComponent) cannot be honoured; give one with Options::tolerances(rtol, atol), or use \
         chetaev::solve"
    )]
    PerComponentAtol,

    /// The scalar absolute tolerance is zero.
    #[error(
        "ode_solvers needs a positive absolute tolerance (atol = 0 given): its state carries the time and, \
         with Record::Energy, two quadratures that start at zero, where rtol alone leaves no error scale; give \
         atol > 0 (such as 1e-12), or use chetaev::solve, which keeps those components outside error control"
    )]
    ZeroAtol,

    /// `Options::output` is [`Output::Times`](chetaev::prelude::Output::Times) with
    /// [`OdeSolversMethod::Dop853`](crate::OdeSolversMethod::Dop853).
    #[error(
        "the Dop853 of ode_solvers interpolates only on an equally spaced grid built by repeated addition, so \
         output at given times (Output::Times) cannot be met exactly; use OdeSolversMethod::Dopri5 (whose \
         continuous output is evaluated at any time), Output::Steps or Output::Final, or chetaev::solve"
    )]
    OutputTimes,

    /// A user step-size controller that the chosen `ode_solvers` method cannot reproduce.
    #[error(
        "the Dop853 of ode_solvers uses the step exponent α = 1/8 − 0.2 β where chetaev's controllers use \
         α = 1/8 − 0.75 β, so the PI controller with β = {beta} cannot be reproduced; give β = 0 \
         (Controller::i), or use chetaev::solve"
    )]
    Controller {
        /// The controller's `β`.
        beta: f64,
    },

    /// `Options::max_steps` exceeds what `ode_solvers` can count.
    #[error(
        "ode_solvers counts steps in a u32, so the step limit Options::max_steps = {max_steps} exceeds its \
         largest, 4294967295; give at most that, or use chetaev::solve"
    )]
    MaxSteps {
        /// The limit asked for.
        max_steps: usize,
    },
}
