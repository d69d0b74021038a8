//! `n` solves of one problem at one tolerance by one code, nothing else: a target for an
//! instruction counter such as `valgrind --tool=callgrind`, which counts reproducibly where
//! timings are noisy (instructions are not time, so claims still come from the timed benchmark).
//!
//! ```sh
//! cargo build --release --manifest-path bench/hairer/Cargo.toml --example solves
//! valgrind --tool=callgrind bench/hairer/target/release/examples/solves particle dop853 1e-10 1000
//! ```
//!
//! Arguments: `arenstorf|particle`, `dop853|dopri5` (chetaev) or `DOP853|DOPRI5` (Hairer), the
//! tolerance (`rtol = atol`), the number of solves. Prints the work of the last solve.

use chetaev::integrate::{Dop853, Dopri5, Method};
use chetaev_hairer_bench::chetaev_side::{self, Counted};
use chetaev_hairer_bench::hairer::{self, Code};
use chetaev_hairer_bench::problems::{self, ArenstorfRhs, ParticleRhs, Problem};

fn run<S: Counted, M: Method + Copy>(
    make: impl Fn() -> S,
    method: M,
    problem: &Problem,
    tol: f64,
    n: usize,
) -> Result<(), String> {
    let options = chetaev_side::options(problem, tol, tol);
    let mut last = None;
    for _ in 0..n {
        last = Some(chetaev_side::solve(make(), method, problem, &options)?);
    }
    if let Some((y, c)) = last {
        println!("y = {y:?}, error {:.3e}, {c:?}", problem.error(&y));
    }
    Ok(())
}

fn run_hairer(code: Code, problem: &Problem, tol: f64, n: usize) -> Result<(), String> {
    let mut last = None;
    for _ in 0..n {
        last = Some(hairer::solve(code, problem, tol, tol).map_err(|idid| format!("IDID {idid}"))?);
    }
    if let Some((y, c)) = last {
        println!("y = {y:?}, error {:.3e}, {c:?}", problem.error(&y));
    }
    Ok(())
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [problem, method, tol, n] = args.as_slice() else {
        return Err("usage: solves arenstorf|particle dop853|dopri5|DOP853|DOPRI5 TOL N".into());
    };
    let tol: f64 = tol.parse().map_err(|e| format!("tolerance: {e}"))?;
    let n: usize = n.parse().map_err(|e| format!("count: {e}"))?;
    let p = match problem.as_str() {
        "arenstorf" => problems::arenstorf(),
        "particle" => problems::particle(),
        other => return Err(format!("unknown problem {other}")),
    };
    match (problem.as_str(), method.as_str()) {
        ("arenstorf", "dop853") => run(|| ArenstorfRhs::new(&p), Dop853::default(), &p, tol, n),
        ("arenstorf", "dopri5") => run(|| ArenstorfRhs::new(&p), Dopri5::default(), &p, tol, n),
        ("particle", "dop853") => run(|| ParticleRhs::new(&p), Dop853::default(), &p, tol, n),
        ("particle", "dopri5") => run(|| ParticleRhs::new(&p), Dopri5::default(), &p, tol, n),
        (_, "DOP853") => run_hairer(Code::Dop853, &p, tol, n),
        (_, "DOPRI5") => run_hairer(Code::Dopri5, &p, tol, n),
        (_, other) => Err(format!("unknown method {other}")),
    }
}
