//! Times chetaev's explicit Runge–Kutta methods against E. Hairer's Fortran codes at equal error.
//!
//! * [`problems`]: the Arenstorf orbit and the constant-speed particle, with references and
//!   right-hand sides written by hand (in Rust here, in Fortran in `fortran/rhs.f`).
//! * [`chetaev_side`]: one solve with `chetaev::integrate::driver::solve_ode`.
//! * [`hairer`]: one solve with DOP853 or DOPRI5 (Fortran, through `fortran/driver.f90`).
//! * [`timing`]: interleaved batches, medians.
//! * [`equal_error`]: the time one code needs for the error the other reached.
//! * [`compare`]: one comparison over the tolerances.

pub mod chetaev_side;
pub mod compare;
pub mod equal_error;
pub mod hairer;
pub mod problems;
pub mod timing;
