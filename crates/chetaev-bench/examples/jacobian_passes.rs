//! The integrator's Jacobian by dual numbers (the route a problem takes before its equations run as
//! machine code), one forward pass per column against one pass per group of columns that share no
//! row of the recorded structure's pattern, timed interleaved.
//!
//! The model: `n` masses on a line, neighbours tied by springs with a quartic term, the last one
//! driven by `cos t`, the speeds of the first two held (`q̇_0² + q̇_1² = 1`). Each `q̈_i` reaches
//! only `q_{i−1}`, `q_i`, `q_{i+1}` (and the constraint's coordinates), so its Jacobian is sparse:
//! `2n + 1` columns in a handful of groups.
//!
//! - **one pass per column**: fresh problems whose equations were recorded before the clock, each
//!   evaluating as many Jacobians as stay below `COLOUR_AFTER` passes (the groups are not made
//!   yet); the first one, which makes the scratch space, untimed;
//! - **grouped**: one problem whose groups were made (`Compiled::jacobian_passes`), evaluated again
//!   and again.
//!
//! Both are checked to give the same Jacobian first.
//!
//! ```sh
//! cargo run --release -p chetaev-bench --example jacobian_passes
//! ```

use chetaev::equations::compiled::COLOUR_AFTER;
use chetaev::integrate::system::{OdeSystem, ReducedOde};
use chetaev::prelude::*;
use chetaev_bench::measure::interleaved_batches;

/// The chain of `n` masses.
#[derive(Clone)]
struct Chain(usize);

impl DynModel for Chain {
    fn sizes(&self) -> (usize, usize) {
        (self.0, 1)
    }
    fn lagrangian<R: Real>(&self, t: R, q: &[R], qd: &[R]) -> R {
        let n = self.0;
        let mut l = R::zero();
        for v in qd {
            l += *v * *v * 0.5;
        }
        for i in 1..n {
            let d = q[i] - q[i - 1] - 1.0;
            l -= d * d * 0.5 + d.powi(4) * 0.25;
        }
        l + q[n - 1] * t.cos()
    }
    fn constraints<R: Real>(&self, _t: R, _q: &[R], qd: &[R], f: &mut [R]) {
        f[0] = qd[0] * qd[0] + qd[1] * qd[1] - 1.0;
    }
}

fn chain(n: usize) -> Result<Problem<Chain>, Error> {
    let q0: Vec<f64> = (0..n).map(|i| i as f64 * 1.1).collect();
    let mut qd0 = vec![0.0; n];
    qd0[0] = 0.6;
    qd0[1] = 0.8;
    Problem::dynamic(Chain(n), 0.0, q0, qd0)
}

/// A state near the initial one.
fn state(n: usize) -> Vec<f64> {
    let mut y: Vec<f64> = (0..n).map(|i| i as f64 * 1.1 + 0.05 * i as f64).collect();
    y.extend((0..n).map(|i| match i {
        0 => 0.6,
        1 => 0.8,
        _ => 0.1 * i as f64,
    }));
    y
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    println!("| n | columns | passes grouped | one pass per column (ns) | grouped (ns) | ratio |");
    println!("|---|---|---|---|---|---|");
    for n in [4, 8, 16, 32] {
        let y = state(n);
        let dim = 2 * n;
        let grouped = chain(n)?;
        let passes = grouped
            .compiled()
            .and_then(|c| c.jacobian_passes())
            .ok_or("the chain's Jacobian should be grouped")?;
        let mut sys = ReducedOde::for_problem(&grouped, false);
        let (mut jac, mut dfdt) = (vec![0.0; dim * dim], vec![0.0; dim]);
        sys.jacobian(0.7, &y, &mut jac, &mut dfdt)?;
        // The same Jacobian from a problem that has not made its groups.
        let fresh = chain(n)?;
        let mut dense = ReducedOde::for_problem(&fresh, false);
        let (mut jac_d, mut dfdt_d) = (vec![0.0; dim * dim], vec![0.0; dim]);
        dense.jacobian(0.7, &y, &mut jac_d, &mut dfdt_d)?;
        let worst = jac
            .iter()
            .chain(&dfdt)
            .zip(jac_d.iter().chain(&dfdt_d))
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs() / b.abs().max(1.0)));
        if worst.is_nan() || worst > 1e-12 {
            return Err(format!("n = {n}: the Jacobians differ by {worst:e}").into());
        }
        // Dense Jacobians per fresh problem: the untimed first one and the timed ones stay below
        // COLOUR_AFTER passes (2n + 1 each; the drive depends on t).
        let per_problem = (COLOUR_AFTER - 1) / (2 * n + 1) - 1;
        let mut one_per_column = |items: usize| {
            let problems = items.div_ceil(per_problem);
            let pbs: Vec<Problem<Chain>> = (0..problems)
                .map(|_| {
                    let p = chain(n).expect("consistent");
                    p.compiled();
                    p
                })
                .collect();
            let mut systems: Vec<_> = pbs
                .iter()
                .map(|p| ReducedOde::for_problem(p, false))
                .collect();
            let (mut j, mut d) = (vec![0.0; dim * dim], vec![0.0; dim]);
            for s in &mut systems {
                s.jacobian(0.7, &y, &mut j, &mut d).expect("regular");
            }
            let start = std::time::Instant::now();
            for s in &mut systems {
                for _ in 0..per_problem {
                    s.jacobian(0.7, std::hint::black_box(&y), &mut j, &mut d)
                        .expect("regular");
                    std::hint::black_box(&mut j);
                }
            }
            start.elapsed().as_secs_f64() / (problems * per_problem) as f64
        };
        let mut in_groups = |items: usize| {
            let start = std::time::Instant::now();
            for _ in 0..items {
                sys.jacobian(0.7, std::hint::black_box(&y), &mut jac, &mut dfdt)
                    .expect("regular");
                std::hint::black_box(&mut jac);
            }
            start.elapsed().as_secs_f64() / items as f64
        };
        let times = interleaved_batches(21, 0.005, &mut [&mut one_per_column, &mut in_groups]);
        println!(
            "| {n} | {} | {passes} | {:.0} | {:.0} | {:.2} |",
            2 * n + 1,
            times[0] * 1e9,
            times[1] * 1e9,
            times[0] / times[1]
        );
    }
    Ok(())
}
