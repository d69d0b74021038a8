//! # chetaev-catalogue
//!
//! Classic constrained systems for [`chetaev`], each written once as a model (a generic
//! [`Lagrangian`](chetaev::model::Lagrangian) and [`Constraints`](chetaev::model::Constraints)),
//! with a constructor of a ready [`Problem`](chetaev::Problem) from documented parameters, and its
//! **reference**: a closed form where one exists, otherwise an invariant, with the source it comes
//! from. Tests, examples and the pages in `docs/catalogue/` all use these.
//!
//! | module | system | `N` | `K` | constraint | reference |
//! |---|---|---|---|---|---|
//! | [`knife_edge`] | skate on an inclined plane | 3 | 1 | linear | closed form `x, y, φ, μ` (Neimark–Fufaev; Bloch §1.6) |
//! | [`rolling_disk`] | vertical rolling disk | 4 | 2 | linear | closed form, circle (Bloch §1.4) |
//! | [`chaplygin_sleigh`] | Chaplygin sleigh | 3 | 1 | linear | closed form `u, ω, θ, μ`, energy (Bloch §1.7) |
//! | [`isokinetic_thermostat`] | Gaussian isokinetic thermostat, particles in a field | any (`12` for four particles in 3D) | 1 | quadratic | closed form `q, q̇, μ = −α` (Evans & Morriss; Tuckerman §4.12) |
//! | [`kepler_constant_speed`] | constant speed in a Kepler field | 3 | 1 | quadratic | invariant `(q × q̇) e^(k/v0² r)`, orbit by quadrature (derived) |
//!
//! Every module has a `Params` type (with a `Default`), `problem(&Params)` and `entry(&Params)`,
//! which returns the problem together with its reference. A reference implements [`Reference`]:
//! the quantities it predicts at a recorded point, each with a natural scale, so that
//! [`compare`] gives the largest scaled error of every quantity over a [`Solution`](chetaev::Solution)
//! (and [`Reference::checks_at`] the checks at one recorded point).
//!
//! ```
//! use chetaev::prelude::*;
//! use chetaev_catalogue::{absolute_work, compare, knife_edge, max_energy_balance, Kind, Reference};
//!
//! let entry = knife_edge::entry(&knife_edge::Params::default())?;
//! let tol = 1e-10;
//! let sol = solve(&entry.problem, Dop853::default(), &Options::until(10.0).tolerances(tol, tol))?;
//! assert!(sol.is_success());
//!
//! let errors = compare(&sol, &entry.reference)?;
//! assert!(errors.max_of(Kind::Position) < 50.0 * tol);
//! assert!(errors.max_of(Kind::Multiplier) < 50.0 * tol);
//! assert!(sol.max_residual().is_some_and(|r| r < 50.0 * tol));
//! // The work of Φ is a quadrature: its error is relative to the power it integrates.
//! assert!(max_energy_balance(&sol) < 5.0 * tol * absolute_work(&sol));
//! println!("{}", entry.reference.sources()[0]);
//! # Ok::<(), chetaev_catalogue::Error>(())
//! ```

pub mod benchmarks;
pub mod chaplygin_sleigh;
pub mod error;
pub mod isokinetic_thermostat;
pub mod kepler_constant_speed;
pub mod knife_edge;
pub mod reference;
pub mod rolling_disk;
mod special;

pub use error::Error;
pub use reference::{
    absolute_work, compare, max_energy_balance, Check, Comparison, Entry, Kind, QuantityError,
    Reference, Source,
};

/// The catalogue pages, compiled and run as doctests.
#[cfg(doctest)]
pub mod pages {
    #[doc = include_str!("../../../docs/catalogue/README.md")]
    pub struct Index;
    #[doc = include_str!("../../../docs/catalogue/knife_edge.md")]
    pub struct KnifeEdge;
    #[doc = include_str!("../../../docs/catalogue/rolling_disk.md")]
    pub struct RollingDisk;
    #[doc = include_str!("../../../docs/catalogue/chaplygin_sleigh.md")]
    pub struct ChaplyginSleigh;
    #[doc = include_str!("../../../docs/catalogue/isokinetic_thermostat.md")]
    pub struct IsokineticThermostat;
    #[doc = include_str!("../../../docs/catalogue/kepler_constant_speed.md")]
    pub struct KeplerConstantSpeed;
}
