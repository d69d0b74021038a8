//! Every derivative of `L` and `f` the Chetaev equations need, by forward-mode automatic
//! differentiation. This is the one place where num-dual's types appear.
//!
//! Each model flavour takes its derivatives in its own way and writes them into the same blocks,
//! which are all the engine sees:
//!
//! - [`fixed`]: static sizes, vector dual numbers on the stack (three passes over `L`, two over `f`);
//! - [`scalar`]: run-time sizes, scalar dual numbers (one direction, or pair of directions, per pass).
//!
//! All functions are generic over the outer scalar `T`: `f64` for values, and a dual number when
//! the caller differentiates the reduced equations once more (the Jacobian of the implicit methods).

pub mod fixed;
pub mod scalar;

pub use fixed::{
    constraint_derivatives, lagrangian_derivatives, velocity_hessian, ConstraintDerivatives,
    LagrangianDerivatives, DENSE_HESSIAN_MAX_N,
};

use crate::model::Real;

/// The Lagrangian and its derivatives at one point `(t, q, q̇)`, for `n` coordinates.
#[derive(Clone, Debug)]
pub struct LagrangianBlocks<T> {
    /// `L`.
    pub l: T,
    /// `p = ∂L/∂q̇`, length `n`.
    pub p: Vec<T>,
    /// `W = ∂²L/∂q̇²`, row-major `n × n`.
    pub w: Vec<T>,
    /// `∂L/∂q`, length `n`.
    pub dl_dq: Vec<T>,
    /// `g = (∂²L/∂q̇∂q) q̇ + ∂²L/∂q̇∂t`, length `n`: the part of `d/dt ∂L/∂q̇` without `q̈`.
    pub g: Vec<T>,
    /// `∂L/∂t`.
    pub dl_dt: T,
}

impl<T: Real> LagrangianBlocks<T> {
    /// Zeroed blocks for `n` coordinates.
    pub fn new(n: usize) -> Self {
        Self {
            l: T::zero(),
            p: vec![T::zero(); n],
            w: vec![T::zero(); n * n],
            dl_dq: vec![T::zero(); n],
            g: vec![T::zero(); n],
            dl_dt: T::zero(),
        }
    }
}

/// The constraints and their derivatives at one point `(t, q, q̇)`, for `k` constraints on `n`
/// coordinates.
#[derive(Clone, Debug)]
pub struct ConstraintBlocks<T> {
    /// `f`, length `k`.
    pub f: Vec<T>,
    /// `J = ∂f/∂q̇`, row-major `k × n`.
    pub j: Vec<T>,
    /// `c = (∂f/∂q) q̇ + ∂f/∂t`, length `k`: the part of `df/dt` without `q̈`.
    pub c: Vec<T>,
}

impl<T: Real> ConstraintBlocks<T> {
    /// Zeroed blocks for `k` constraints on `n` coordinates.
    pub fn new(n: usize, k: usize) -> Self {
        Self {
            f: vec![T::zero(); k],
            j: vec![T::zero(); k * n],
            c: vec![T::zero(); k],
        }
    }
}
