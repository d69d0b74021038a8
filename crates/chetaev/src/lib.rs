//! # chetaev
//!
//! Mechanics under nonholonomic constraints, including constraints nonlinear in the velocities.
//! A user writes a Lagrangian `L(t, q, q̇)` and `K` velocity constraints `f(t, q, q̇) = 0` as generic
//! methods ([`model`]); everything else is derived.
//!
//! ## The pipeline
//!
//! | step | where | what |
//! |---|---|---|
//! | model | [`model`] | [`Lagrangian`](model::Lagrangian) and [`Constraints`](model::Constraints) on `SVector` (sizes known when compiling), or [`DynModel`](model::DynModel) on slices (sizes known at run time): written once over `R: Real` |
//! | problem | [`Problem`] | the model with a consistent initial state, validated; [`Problem::new`] or [`Problem::dynamic`], one type |
//! | derivatives | [`equations::derivatives`] | `∂L/∂q`, `W = ∂²L/∂q̇²`, `(∂²L/∂q̇∂q) q̇ + ∂²L/∂q̇∂t`, `J = ∂f/∂q̇`, `(∂f/∂q) q̇ + ∂f/∂t` by num-dual, in the way that suits the model's flavour |
//! | block solve | [`equations::saddle`] | `[W −Jᵀ; J 0][q̈; μ] = [∂L/∂q − g; −c]`, complete pivoting, conditioning reported; one engine for every model ([`equations::evaluate`]) |
//! | structure | [`equations::compiled`] | the model recorded once as an expression graph: zero and constant blocks proved, a constant `W` factorised once, only what varies evaluated; once a problem has run `10⁴` right-hand sides, its right-hand side with the block solve written out for its structure, as machine code |
//! | method | [`integrate`] | [`Dopri5`](integrate::Dopri5), [`Dop853`](integrate::Dop853), [`Tsit5`](integrate::Tsit5), [`Rk4`](integrate::Rk4), [`Rodas4`](integrate::Rodas4), [`Rodas5P`](integrate::Rodas5P): a recipe of facts ([`MethodInfo`](integrate::MethodInfo)), a trial step, its error, dense output |
//! | driver | [`solve`] | step control, output, events, projection, statistics |
//! | manifold | [`manifold`] | dependent coordinates and speeds completed from the independent ones; the reduced equations linearised on the constraints ([`Problem::linearize`]) |
//! | solution | [`Solution`] | `t, q, q̇, q̈, μ, Φ, f, E, W_Φ`, events, [`Stats`](integrate::system::Stats), [`Status`] |
//!
//! Conventions (Newton form, `d/dt ∂L/∂q̇ − ∂L/∂q = Jᵀμ = Φ`) are in `docs/conventions.md`. The
//! guides: `docs/adding-a-constraint.md` (a new constraint in Rust), `docs/scenes.md` (the same in
//! a scene file), `docs/adding-a-method.md` (a new integrator), `docs/formulation.md` (the maths).
//!
//! ## Example
//!
//! A particle in gravity held at constant speed (Swaczyna and Volný, *Uniform horizontal projectile
//! motion*), and the classical projectile for comparison:
//!
//! ```
//! use chetaev::prelude::*;
//!
//! struct Particle { g: f64 }
//! impl Lagrangian<2> for Particle {
//!     fn lagrangian<R: Real>(&self, _t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
//!         qd.dot(qd) * 0.5 - q[1] * self.g
//!     }
//! }
//! struct ConstantSpeed { particle: Particle, v0: f64 }
//! impl Lagrangian<2> for ConstantSpeed {
//!     fn lagrangian<R: Real>(&self, t: R, q: &SVector<R, 2>, qd: &SVector<R, 2>) -> R {
//!         self.particle.lagrangian(t, q, qd)
//!     }
//! }
//! impl Constraints<2, 1> for ConstantSpeed {
//!     fn constraints<R: Real>(&self, _t: R, _q: &SVector<R, 2>, qd: &SVector<R, 2>) -> SVector<R, 1> {
//!         SVector::from([qd.dot(qd) - self.v0 * self.v0])
//!     }
//! }
//!
//! let (q0, qd0) = (SVector::from([0.0, 5.0]), SVector::from([10.0, 0.0]));
//! let ground = || Event::new("ground", |_t, q: &[f64], _qd: &[f64]| q[1]).falling().terminal();
//! let options = Options::until(10.0).tolerances(1e-10, 1e-10).event(ground());
//!
//! let uniform = Problem::new(ConstantSpeed { particle: Particle { g: 10.0 }, v0: 10.0 }, 0.0, q0, qd0)?;
//! let classical = Problem::unconstrained(Particle { g: 10.0 }, 0.0, q0, qd0)?;
//! let u = solve(&uniform, Dopri5::default(), &options)?;
//! let c = solve(&classical, Dopri5::default(), &options)?;
//!
//! // The uniform motion lands closer and later (Table 42.1).
//! assert!(u.events[0].q[0] < c.events[0].q[0] && u.events[0].t > c.events[0].t);
//! // μ < 0 while falling (42.40); the work of Φ equals the change of potential energy.
//! assert!(u.mu.iter().skip(1).all(|mu| mu[0] < 0.0));
//! let last = u.len() - 1;
//! assert!((u.work[last] - 10.0 * (u.q[last][1] - 5.0)).abs() < 1e-8);
//! # Ok::<(), chetaev::Error>(())
//! ```
pub mod equations;
pub mod error;
pub mod integrate;
pub mod loads;
pub mod manifold;
pub mod model;
pub mod problem;
pub mod sensitivity;
pub mod solution;

pub use error::{Error, SeedPart, Singularity};
pub use integrate::driver::solve;
/// The linear algebra the model traits are written in, re-exported so a user's version cannot clash.
pub use nalgebra;
/// The dual numbers behind [`Real`](model::Real), re-exported so a user's version cannot clash.
pub use num_dual;
pub use problem::{MachineCode, Problem, Route};
pub use sensitivity::{EventSensitivity, Seed, Sensitivities};
pub use solution::{Solution, Status, Warning};

/// Common imports.
pub mod prelude {
    pub use crate::integrate::events::{Direction, Event, EventFunction};
    pub use crate::integrate::options::{Atol, Options, Output, Record};
    pub use crate::integrate::projection::Projection;
    pub use crate::integrate::{
        AnyMethod, Controller, Dop853, Dopri5, Method, Rk4, Rodas4, Rodas5P, StiffnessDetection,
        Tsit5,
    };
    pub use crate::model::{Constraints, DynModel, Lagrangian, Model, Real, Unconstrained};
    pub use crate::solution::Series;
    pub use crate::{
        solve, Error, MachineCode, Problem, Route, Seed, Singularity, Solution, Status, Warning,
    };
    pub use nalgebra::{SMatrix, SVector};
}

/// The guides of `docs/`, rendered here so that `cargo doc` shows them; the Rust code in them is
/// compiled and run as doctests of this crate.
///
/// Scene files (the `chetaev` command, in the crate `chetaev-scene`) are described in
/// `docs/scenes.md`; performance in `docs/performance.md`; sweeps on a cluster in `docs/sweeps.md`.
/// Links from one guide to another are relative to `docs/` in the repository.
pub mod guides {
    #[doc = include_str!("../../../docs/adding-a-constraint.md")]
    pub mod adding_a_constraint {}
    #[doc = include_str!("../../../docs/conventions.md")]
    pub mod conventions {}
    #[doc = include_str!("../../../docs/formulation.md")]
    pub mod formulation {}
    #[doc = include_str!("../../../docs/holonomic.md")]
    pub mod holonomic {}
    #[doc = include_str!("../../../docs/forces.md")]
    pub mod forces {}
    #[doc = include_str!("../../../docs/sensitivities.md")]
    pub mod sensitivities {}
    #[doc = include_str!("../../../docs/adding-a-method.md")]
    pub mod adding_a_method {}
    #[doc = include_str!("../../../docs/where-it-breaks.md")]
    pub mod where_it_breaks {}
}
