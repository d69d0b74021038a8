//! Scene files: a constrained Lagrangian system written as a TOML file, solved by `chetaev`.
//!
//! A scene states the coordinates, the parameters, the Lagrangian and the constraints as
//! mathematical expressions, the initial state, the method and tolerances, the events, and the
//! tables and pictures wanted. The `chetaev` command (`chetaev run scene.toml`) solves it and writes
//! them; the schema and the expression language are described in `docs/scenes.md`.
//!
//! | step | where | what |
//! |---|---|---|
//! | parse | [`Scene::load`], [`scene`] | TOML with spans; every mistake located at a line and column |
//! | expressions | [`expr`] | our parser; parameters folded (except those sensitivities are asked for); evaluated generically over `R: Real` |
//! | graph | [`graph`] | a model as a straight-line program of operations with shared nodes ([`graph::GraphModel`]): the door for front ends with their own expression trees (the Python package's sympy models) |
//! | model | `model.rs` | `L` and `f` as expressions implement [`chetaev::model::DynModel`]: any `N ≥ 1`, `0 ≤ K ≤ N` |
//! | solve | [`Scene::solve`], [`run`] | [`chetaev::solve`] on [`chetaev::Problem::dynamic`]; records only what the tables and pictures need |
//! | sensitivities | `[sensitivities]`, [`scene::SensitivitySpec`] | derivatives of the motion and the events with respect to parameters, by `chetaev`'s seeds |
//! | output | [`output`] | CSV tables, SVG pictures (`chetaev-plot`), the summary |
//! | sweeps | [`sweep`] | the scene over a grid or a random sample of its parameters and initial values, in parallel, sharded (`chetaev sweep`) |
//!
//! Because the expressions are evaluated generically over `chetaev`'s scalar type, `chetaev`
//! differentiates them with dual numbers, exactly as it does a model written in Rust: no symbolic
//! algebra and no finite differences. The sizes `N` and `K` are read from the file, so a scene may
//! have any number of coordinates.
//!
//! ```
//! use chetaev_scene::Scene;
//!
//! let scene = Scene::parse(r#"
//!     [parameters]
//!     g = 10.0
//!     v0 = 10.0
//!     [model]
//!     coordinates = ["x", "y"]
//!     lagrangian = "0.5*(x_dot^2 + y_dot^2) - g*y"
//!     constraints = ["x_dot^2 + y_dot^2 - v0^2"]
//!     [initial]
//!     q = [0.0, 5.0]
//!     q_dot = ["v0", 0.0]
//!     [solve]
//!     t_end = 10.0
//!     rtol = 1e-10
//!     atol = 1e-10
//!     [[events]]
//!     name = "impact"
//!     expression = "y"
//!     direction = "falling"
//!     terminal = true
//! "#, "projectile.toml")?;
//! let outcome = scene.solve()?;
//! let impact = &outcome.events[0];
//! assert!((impact.t - 0.5f64.exp().acosh()).abs() < 1e-9); // T = (v0/g) arccosh e^(g h0/v0²)
//! # Ok::<(), chetaev_scene::Error>(())
//! ```

mod domain;
pub mod error;
pub mod expr;
pub mod graph;
mod model;
pub mod output;
pub mod run;
pub mod scene;
pub mod source;
pub mod sweep;

pub use error::{Error, Warning};
pub use model::ExprModel;
pub use run::Outcome;
pub use scene::Scene;
