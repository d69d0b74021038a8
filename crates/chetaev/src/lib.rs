//! chetaev
pub mod equations;
pub mod backend;
pub mod error;
pub mod integrate;
pub mod model;
pub mod problem;
pub mod solution;

pub use error::Error;
pub use integrate::driver::solve;
pub use problem::Problem;
pub use solution::{Solution, Status};

/// Common imports.
pub mod prelude {
    pub use crate::integrate::events::{Direction, Event};
    pub use crate::integrate::options::{Atol, Options, Output, Record};
    pub use crate::integrate::projection::Projection;
    pub use crate::integrate::{Dop853, Dopri5, Method, Rk4};
    pub use crate::model::{Constraints, Lagrangian, Model, Real, Unconstrained};
    pub use crate::{solve, Error, Problem, Solution, Status};
    pub use nalgebra::{SMatrix, SVector};
}
