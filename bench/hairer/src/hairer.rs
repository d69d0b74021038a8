//! E. Hairer's Fortran codes DOP853 (version of October 11, 2009) and DOPRI5 (version of April 25,
//! 1996, corrected August 8, 2005), called through the driver `fortran/driver.f90`.
//!
//! One call is one solve: the driver calls DOP853 or DOPRI5 with the Fortran right-hand side of
//! `fortran/rhs.f`, so the language boundary is crossed once per solve and never per evaluation.

use std::ffi::c_int;

use crate::problems::{Problem, ProblemId};

/// The compiler and flags the Fortran was built with (written by `build.rs`).
pub mod build_info {
    include!(concat!(env!("OUT_DIR"), "/fortran_info.rs"));
}

#[allow(unsafe_code)]
mod ffi {
    use std::ffi::c_int;

    extern "C" {
        /// `fortran/driver.f90`: one solve; `y` (length `n`) in and out, `counts` = NFCN, NSTEP,
        /// NACCPT, NREJCT, `idid` as in Hairer's codes (1 = success).
        #[allow(clippy::too_many_arguments)]
        pub fn hairer_solve(
            method: c_int,
            problem: c_int,
            n: c_int,
            t0: f64,
            t1: f64,
            y: *mut f64,
            rpar: *const f64,
            rtol: f64,
            atol: f64,
            counts: *mut c_int,
            idid: *mut c_int,
        );

        /// `fortran/driver.f90`: the right-hand side `f = F(t, y)` of `fortran/rhs.f`.
        pub fn hairer_rhs(
            problem: c_int,
            n: c_int,
            t: f64,
            y: *const f64,
            rpar: *const f64,
            f: *mut f64,
        );
    }

    /// Safe wrapper: checks the lengths the Fortran relies on (`idid = -10` otherwise).
    #[allow(clippy::too_many_arguments)]
    pub fn solve(
        method: c_int,
        problem: c_int,
        t0: f64,
        t1: f64,
        y: &mut [f64],
        rpar: &[f64],
        rtol: f64,
        atol: f64,
        counts: &mut [c_int; 4],
        idid: &mut c_int,
    ) {
        if rpar.is_empty() || y.is_empty() || y.len() > 16 {
            *idid = -10;
            return;
        }
        // SAFETY: `y` has `n` elements, `rpar` at least the one the right-hand sides read, `counts`
        // four; the Fortran keeps no pointer after returning and has no global state that another
        // thread could share (the benchmark is single-threaded).
        unsafe {
            hairer_solve(
                method,
                problem,
                y.len() as c_int,
                t0,
                t1,
                y.as_mut_ptr(),
                rpar.as_ptr(),
                rtol,
                atol,
                counts.as_mut_ptr(),
                idid,
            );
        }
    }

    /// Safe wrapper of [`hairer_rhs`]; leaves `f` alone if the lengths do not fit.
    pub fn rhs(problem: c_int, t: f64, y: &[f64], rpar: &[f64], f: &mut [f64]) {
        if rpar.is_empty() || y.is_empty() || y.len() != f.len() {
            return;
        }
        // SAFETY: `y` and `f` have `n` elements, `rpar` at least one.
        unsafe {
            hairer_rhs(
                problem,
                y.len() as c_int,
                t,
                y.as_ptr(),
                rpar.as_ptr(),
                f.as_mut_ptr(),
            );
        }
    }
}

/// Which of Hairer's codes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Code {
    /// DOP853, Dormand–Prince 8(5,3).
    Dop853,
    /// DOPRI5, Dormand–Prince 5(4).
    Dopri5,
}

impl Code {
    fn id(self) -> c_int {
        match self {
            Code::Dop853 => 1,
            Code::Dopri5 => 2,
        }
    }

    /// The code's name as Hairer spells it.
    pub fn name(self) -> &'static str {
        match self {
            Code::Dop853 => "DOP853",
            Code::Dopri5 => "DOPRI5",
        }
    }
}

fn problem_id(p: ProblemId) -> c_int {
    match p {
        ProblemId::Arenstorf => 1,
        ProblemId::Particle => 2,
    }
}

/// The work counters Hairer's codes return in `IWORK(17..20)`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// NFCN: right-hand side evaluations (including the two of the initial step guess).
    pub nfcn: usize,
    /// NSTEP: computed steps.
    pub nstep: usize,
    /// NACCPT: accepted steps.
    pub naccpt: usize,
    /// NREJCT: rejected steps (rejections in the first step are not counted).
    pub nrejct: usize,
}

/// One solve of `problem` by Hairer's code, from `y0` at `t0` to `t1`, with scalar tolerances
/// `rtol`, `atol`: the final state and the work counters, or IDID when the code did not succeed
/// (−10: a problem the driver does not know).
pub fn solve(
    code: Code,
    problem: &Problem,
    rtol: f64,
    atol: f64,
) -> Result<([f64; 4], Counts), i32> {
    let mut y = problem.y0;
    let mut counts = [0 as c_int; 4];
    let mut idid: c_int = 0;
    ffi::solve(
        code.id(),
        problem_id(problem.id),
        problem.t0,
        problem.t1,
        &mut y,
        &problem.params,
        rtol,
        atol,
        &mut counts,
        &mut idid,
    );
    if idid != 1 {
        return Err(idid);
    }
    let c = |i: usize| counts[i].max(0) as usize;
    Ok((
        y,
        Counts {
            nfcn: c(0),
            nstep: c(1),
            naccpt: c(2),
            nrejct: c(3),
        },
    ))
}

/// The Fortran right-hand side `F(t, y)` of `problem` (for checking the Rust one against it).
pub fn rhs(problem: ProblemId, params: &[f64], t: f64, y: &[f64], f: &mut [f64]) {
    ffi::rhs(problem_id(problem), t, y, params, f);
}
