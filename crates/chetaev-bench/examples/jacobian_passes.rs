//! The integrator's Jacobian by dual numbers (the route a problem takes before its equations run as
//! machine code), one forward pass per column against one pass per group of columns that share no
//! row of the recorded structure's pattern, timed interleaved, with what making the groups costs.
//!
//! The models: the paper's particle in the stiff scene; `n` masses on a line, neighbours tied by
//! springs with a quartic term, the last one driven by `cos t`, the speeds of the first two held
//! (`q̇_0² + q̇_1² = 1`), whose `q̈_i` reaches only `q_{i−1}`, `q_i`, `q_{i+1}` (and the
//! constraint's coordinates), so that its `2n + 1` columns fall into a handful of groups; and the
//! isokinetic gas, whose constraint couples every velocity, for which only the time to find that
//! its columns are not grouped is printed.
//!
//! - **one pass per column**: fresh problems whose equations were recorded before the clock, each
//!   evaluating as many Jacobians as stay below `COLOUR_AFTER` passes (the groups are not made
//!   yet); the first one, which makes the scratch space, untimed;
//! - **grouped**: one problem whose groups were made (`Compiled::jacobian_passes`), evaluated again
//!   and again;
//! - **making the groups**: `Compiled::jacobian_passes` on fresh recorded problems (both sets of
//!   groups, with and without the rows of the energy balance).
//!
//! Both Jacobians are checked to be the same first.
//!
//! ```sh
//! cargo run --release -p chetaev-bench --example jacobian_passes      # about 10 s
//! ```

use std::hint::black_box;
use std::time::Instant;

use chetaev::equations::compiled::COLOUR_AFTER;
use chetaev::integrate::system::{Jacobian, OdeSystem, ReducedOde};
use chetaev::model::Model;
use chetaev::prelude::*;
use chetaev_bench::measure::interleaved_batches;
use chetaev_bench::scenes::STIFF;
use chetaev_catalogue::benchmarks::Gas;
use uniform_projectile::model::uniform_problem;

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

/// One row of the table: the grouped Jacobian against one pass per column for problems made by
/// `make`, at `(t, y)`, and what making the groups costs (both sets, with and without the energy
/// balance's rows, as `Compiled::jacobian_passes` makes them).
fn row<M: Model + Clone>(
    name: &str,
    make: &dyn Fn() -> Result<Problem<M>, Error>,
    t: f64,
    y: &[f64],
) -> Result<(), Box<dyn std::error::Error>> {
    let dim = y.len();
    let columns = dim + 1;
    let grouped = make()?;
    let passes = grouped
        .compiled()
        .and_then(|c| c.jacobian_passes())
        .ok_or("this model's Jacobian should be grouped")?;
    let mut sys = ReducedOde::for_problem(&grouped, false);
    let mut jac = Jacobian::new(dim);
    sys.jacobian(t, y, &mut jac)?;
    // The same Jacobian from a problem that has not made its groups.
    let fresh = make()?;
    let mut dense = ReducedOde::for_problem(&fresh, false);
    let mut jac_d = Jacobian::new(dim);
    dense.jacobian(t, y, &mut jac_d)?;
    let worst = jac
        .dy
        .iter()
        .chain(&jac.dt)
        .zip(jac_d.dy.iter().chain(&jac_d.dt))
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs() / b.abs().max(1.0)));
    if worst.is_nan() || worst > 1e-12 {
        return Err(format!("{name}: the Jacobians differ by {worst:e}").into());
    }
    // Fresh problems, recorded before the clock.
    let recorded = |count: usize| -> Vec<Problem<M>> {
        (0..count)
            .map(|_| {
                let p = make().expect("consistent");
                p.compiled();
                p
            })
            .collect()
    };
    // Dense Jacobians per fresh problem: the untimed first one and the timed ones stay below
    // COLOUR_AFTER passes (at most one per column each).
    let per_problem = ((COLOUR_AFTER - 1) / columns).saturating_sub(1).max(1);
    let mut one_per_column = |items: usize| {
        let problems = items.div_ceil(per_problem);
        let pbs = recorded(problems);
        let mut systems: Vec<_> = pbs
            .iter()
            .map(|p| ReducedOde::for_problem(p, false))
            .collect();
        let mut j = Jacobian::new(dim);
        for s in &mut systems {
            s.jacobian(t, y, &mut j).expect("regular");
        }
        let start = Instant::now();
        for s in &mut systems {
            for _ in 0..per_problem {
                s.jacobian(t, black_box(y), &mut j).expect("regular");
                black_box(&mut j);
            }
        }
        start.elapsed().as_secs_f64() / (problems * per_problem) as f64
    };
    let mut in_groups = |items: usize| {
        let start = Instant::now();
        for _ in 0..items {
            sys.jacobian(t, black_box(y), &mut jac).expect("regular");
            black_box(&mut jac);
        }
        start.elapsed().as_secs_f64() / items as f64
    };
    let mut making = |items: usize| {
        let pbs = recorded(items);
        let start = Instant::now();
        for p in &pbs {
            black_box(p.compiled().and_then(|c| c.jacobian_passes()));
        }
        start.elapsed().as_secs_f64() / items as f64
    };
    let times = interleaved_batches(
        21,
        0.005,
        &mut [&mut one_per_column, &mut in_groups, &mut making],
    );
    println!(
        "| {name} | {columns} | {passes} | {:.0} | {:.0} | {:.2} | {:.1} |",
        times[0] * 1e9,
        times[1] * 1e9,
        times[0] / times[1],
        times[2] * 1e6
    );
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    println!(
        "| model | columns | passes grouped | one pass per column (ns) | grouped (ns) | ratio | \
         making the groups (µs) |"
    );
    println!("|---|---|---|---|---|---|---|");
    // The paper's particle in the stiff scene, at a state on the constraint.
    let v = STIFF.v0;
    let y = [0.1, 0.9, 0.6 * v, -0.8 * v];
    row("paper's particle", &|| uniform_problem(&STIFF), 0.0, &y)?;
    for n in [4, 8, 16, 32] {
        row(&format!("chain, n = {n}"), &|| chain(n), 0.7, &state(n))?;
    }
    // The isokinetic gas: every velocity reaches every row of q̈, so its columns are not grouped
    // beyond 64 of them; the time to find that out, once per problem.
    for n in [30, 300, 3000] {
        let gas = Gas::problem(n)?;
        let compiled = gas.compiled().ok_or("the gas records")?;
        let start = Instant::now();
        let passes = compiled.jacobian_passes();
        let found = start.elapsed().as_secs_f64() * 1e3;
        let passes = match passes {
            Some(p) => format!("{p} grouped passes"),
            None => "not grouped (a pass per column)".to_string(),
        };
        println!(
            "isokinetic gas, n = {n}: {} columns, {passes}, found in {found:.1} ms",
            2 * n + 1
        );
    }
    Ok(())
}
