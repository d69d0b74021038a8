//! The Chaplygin sleigh against its hand-written limit: `chetaev` (automatic differentiation and a
//! block solve at every evaluation) and the same equations written out by hand, both integrated by
//! the same methods and driver ([`solve_ode`]), timed interleaved in one process.
//!
//! The hand-written right-hand side, on the same state `y = (x, y, θ, ẋ, ẏ, θ̇)`, is the Newton form
//! `d/dt ∂L/∂q̇ − ∂L/∂q = μ (−sin θ, cos θ, 0)` with `μ` eliminated through `ḟ = 0`
//! (`u = ẋ cos θ + ẏ sin θ`, `s = sin θ`, `c = cos θ`):
//!
//! ```text
//! μ = m I u θ̇ / (I + m a²),   θ̈ = −a μ / I,
//! ẍ = −μ s / m + a c θ̇² + a s θ̈,   ÿ = μ c / m + a s θ̇² − a c θ̈.
//! ```
//!
//! It is checked against `Problem::equations_at` at a few states before anything is timed.
//!
//! ```sh
//! cargo run --release -p chetaev-bench --example sleigh_limit
//! ```

use std::hint::black_box;
use std::time::Instant;

use chetaev::integrate::driver::solve_ode;
use chetaev::integrate::system::{Jacobian, OdeSystem};
use chetaev::model::Fixed;
use chetaev::prelude::*;
use chetaev_bench::measure::interleaved_batches;
use chetaev_catalogue::chaplygin_sleigh::{problem, ChaplyginSleigh, ClosedForm, Params};

/// End time: `c V t_end ≈ 7.6`, the turning rate has fallen to about `1e-3` of its start.
const T_END: f64 = 3.0;
const TOLERANCES: [f64; 4] = [1e-6, 1e-8, 1e-10, 1e-12];
const ROUNDS: usize = 31;
/// Each timed sample is a batch of solves lasting at least this long.
const MIN_BATCH_SECONDS: f64 = 5e-3;

/// The sleigh's equations written by hand.
#[derive(Clone, Copy)]
struct Hand {
    m: f64,
    inertia: f64,
    a: f64,
    /// Right-hand sides evaluated (the driver leaves counting to the system).
    rhs: usize,
}

impl Hand {
    fn accelerations(&self, y: &[f64]) -> ([f64; 3], f64) {
        let (s, c) = y[2].sin_cos();
        let w = y[5];
        let u = y[3] * c + y[4] * s;
        let mu = self.m * self.inertia * u * w / (self.inertia + self.m * self.a * self.a);
        let tdd = -self.a * mu / self.inertia;
        let aw2 = self.a * w * w;
        let xdd = -mu * s / self.m + aw2 * c + self.a * s * tdd;
        let ydd = mu * c / self.m + aw2 * s - self.a * c * tdd;
        ([xdd, ydd, tdd], mu)
    }
}

impl OdeSystem for Hand {
    fn dim(&self) -> usize {
        6
    }
    fn controlled_dim(&self) -> usize {
        6
    }
    #[inline]
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), Error> {
        self.rhs += 1;
        let (qdd, _) = self.accelerations(y);
        dy[..3].copy_from_slice(&y[3..]);
        dy[3..].copy_from_slice(&qdd);
        Ok(())
    }
    /// By central differences: only implicit methods call it, and none is measured here.
    fn jacobian(&mut self, t: f64, y: &[f64], out: &mut Jacobian) -> Result<(), Error> {
        let Jacobian { dy: jac, dt: dfdt } = out;
        let (mut yp, mut ym) = (y.to_vec(), y.to_vec());
        let (mut fp, mut fm) = ([0.0; 6], [0.0; 6]);
        for j in 0..6 {
            let h = 1e-7 * (1.0 + y[j].abs());
            yp[j] = y[j] + h;
            ym[j] = y[j] - h;
            self.rhs(t, &yp, &mut fp)?;
            self.rhs(t, &ym, &mut fm)?;
            for i in 0..6 {
                jac[i * 6 + j] = (fp[i] - fm[i]) / (2.0 * h);
            }
            yp[j] = y[j];
            ym[j] = y[j];
        }
        dfdt.fill(0.0);
        Ok(())
    }
}

/// The exact end state: `θ`, `θ̇`, `u` from the closed form, `(ẋ, ẏ) = u (cos θ, sin θ)`, and
/// `(x, y)` by composite 5-point Gauss–Legendre quadrature of `u (cos θ, sin θ)` (2000 panels).
fn exact_state(cf: &ClosedForm, p: &Params, t: f64) -> [f64; 6] {
    let r = (10.0f64 / 7.0).sqrt();
    let (n1, n2) = ((5.0 - 2.0 * r).sqrt() / 3.0, (5.0 + 2.0 * r).sqrt() / 3.0);
    let s70 = 70.0f64.sqrt();
    let (w0, w1, w2) = (
        128.0 / 225.0,
        (322.0 + 13.0 * s70) / 900.0,
        (322.0 - 13.0 * s70) / 900.0,
    );
    let nodes = [(0.0, w0), (n1, w1), (-n1, w1), (n2, w2), (-n2, w2)];
    let panels = 2000;
    let h = t / panels as f64;
    let (mut x, mut y) = (p.position[0], p.position[1]);
    for k in 0..panels {
        let mid = (k as f64 + 0.5) * h;
        for &(xi, wi) in &nodes {
            let s = mid + 0.5 * h * xi;
            let (u, th) = (cf.forward_speed(s), cf.heading(s));
            x += 0.5 * h * wi * u * th.cos();
            y += 0.5 * h * wi * u * th.sin();
        }
    }
    let (u, th) = (cf.forward_speed(t), cf.heading(t));
    [x, y, th, u * th.cos(), u * th.sin(), cf.turning_rate(t)]
}

/// The largest absolute difference; NaN if any difference is NaN.
fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, |m, d| {
            if m.is_nan() || d.is_nan() {
                f64::NAN
            } else {
                m.max(d)
            }
        })
}

/// A batch of `f`: `n` solves, in seconds per solve.
fn batch(f: &mut dyn FnMut() -> Vec<f64>) -> impl FnMut(usize) -> f64 + '_ {
    move |n| {
        let start = Instant::now();
        for _ in 0..n {
            black_box(f());
        }
        start.elapsed().as_secs_f64() / n as f64
    }
}

/// `log t` at error `e`, interpolated linearly in `log e` between the points `(error, time)`;
/// outside their range, extrapolated along the nearest segment (the flag says so).
fn time_at_error(points: &[(f64, f64)], e: f64) -> (f64, bool) {
    let mut pts: Vec<(f64, f64)> = points.iter().map(|&(err, t)| (err.ln(), t.ln())).collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let le = e.ln();
    let k = pts.len();
    let (i, outside) = if le < pts[0].0 {
        (0, true)
    } else if le > pts[k - 1].0 {
        (k - 2, true)
    } else {
        (
            (0..k - 1).find(|&i| le <= pts[i + 1].0).unwrap_or(k - 2),
            false,
        )
    };
    let ((e0, t0), (e1, t1)) = (pts[i], pts[i + 1]);
    ((t0 + (t1 - t0) * (le - e0) / (e1 - e0)).exp(), outside)
}

/// Errors and median times of `method` over [`TOLERANCES`], chetaev and hand-written interleaved.
fn measure<Me: Method + Copy>(
    pb: &Problem<Fixed<ChaplyginSleigh, 3, 1>>,
    hand: Hand,
    y0: &[f64],
    exact: &[f64; 6],
    method: Me,
) -> Vec<Row> {
    let mut rows = Vec::new();
    for &tol in &TOLERANCES {
        let o = Options::until(T_END)
            .tolerances(tol, tol)
            .record(Record::State)
            .output_final();
        let mut run_c = || -> Vec<f64> {
            let sol = solve(pb, method, &o).expect("valid options");
            assert!(sol.is_success(), "chetaev failed at tol {tol}");
            let (_, q, qd) = sol.last().expect("recorded");
            q.iter().chain(qd).copied().collect()
        };
        let mut run_h = || -> Vec<f64> {
            let mut sys = hand;
            let sol = solve_ode(&mut sys, method, 0.0, y0, &o).expect("valid options");
            assert!(sol.error.is_none(), "hand-written failed at tol {tol}");
            sol.y.last().expect("recorded").clone()
        };
        let err_c = max_diff(&run_c(), exact);
        let err_h = max_diff(&run_h(), exact);
        let sc = solve(pb, method, &o).expect("valid options").stats;
        let mut sys = hand;
        let sh = solve_ode(&mut sys, method, 0.0, y0, &o)
            .expect("valid options")
            .stats;
        let (mut bc, mut bh) = (batch(&mut run_c), batch(&mut run_h));
        let t = interleaved_batches(ROUNDS, MIN_BATCH_SECONDS, &mut [&mut bc, &mut bh]);
        rows.push(Row {
            tol,
            err_c,
            err_h,
            t_c: t[0],
            t_h: t[1],
            steps_c: (sc.accepted_steps, sc.rejected_steps),
            steps_h: (sh.accepted_steps, sh.rejected_steps),
            rhs: (sc.rhs_evaluations, sys.rhs),
        });
    }
    rows
}

struct Row {
    tol: f64,
    err_c: f64,
    err_h: f64,
    t_c: f64,
    t_h: f64,
    /// Accepted and rejected steps.
    steps_c: (usize, usize),
    steps_h: (usize, usize),
    /// Right-hand sides evaluated: chetaev, hand-written.
    rhs: (usize, usize),
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let p = Params::default();
    let pb = problem(&p)?;
    let cf = ClosedForm::new(&p)?;
    let hand = Hand {
        m: p.m,
        inertia: p.inertia,
        a: p.a,
        rhs: 0,
    };

    // What chetaev derived: which blocks vary.
    let (q0, qd0) = (pb.q0().to_vec(), pb.qd0().to_vec());
    let d = pb.describe(0.0, &q0, &qd0)?;
    let s = &d.structure;
    println!(
        "structure (proved from compiled expressions: {}): W depends on t {} q {} q̇ {} (constant: {}); \
         J depends on t {} q {} q̇ {} (constant: {})",
        d.proved,
        s.w.t,
        s.w.q,
        s.w.qd,
        s.w.is_constant(),
        s.j.t,
        s.j.q,
        s.j.qd,
        s.j.is_constant()
    );

    // The hand-written right-hand side against chetaev's at a few states on the constraint.
    let mut worst: f64 = 0.0;
    let states: [(f64, f64, f64, f64, f64); 5] = [
        (0.0, 0.0, 0.0, 0.2, 3.0),
        (0.3, -1.2, 0.7, -0.9, 1.1),
        (2.0, 1.0, 2.9, 1.5, -0.4),
        (-1.0, 0.5, -1.3, 0.01, 5.0),
        (0.0, 0.0, 4.0, -2.0, -2.5),
    ];
    for &(x, y, th, u, w) in &states {
        let q = [x, y, th];
        let qd = [u * th.cos(), u * th.sin(), w];
        let eq = pb.equations_at(0.0, &q, &qd)?;
        let yv = [x, y, th, qd[0], qd[1], qd[2]];
        let (qdd, mu) = hand.accelerations(&yv);
        let scale = 1.0 + eq.qdd.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let diff = max_diff(&qdd, &eq.qdd).max((mu - eq.mu[0]).abs()) / scale;
        worst = worst.max(diff);
        if diff.is_nan() || diff > 1e-12 {
            return Err(format!(
                "hand-written right-hand side disagrees with chetaev at q = {q:?}, q̇ = {qd:?}: \
                 q̈ {qdd:?} vs {:?}, μ {mu} vs {} (relative {diff:e})",
                eq.qdd, eq.mu[0]
            )
            .into());
        }
    }
    println!("hand-written q̈, μ agree with Problem::equations_at to {worst:.1e} (relative)");

    let exact = exact_state(&cf, &p, T_END);
    let y0: Vec<f64> = q0.iter().chain(&qd0).copied().collect();

    // Cross-check of the reference: chetaev at 1e-13.
    let o = Options::until(T_END)
        .tolerances(1e-13, 1e-13)
        .record(Record::State)
        .output_final();
    let sol = solve(&pb, Dop853::default(), &o)?;
    let (_, q, qd) = sol.last().ok_or("no output")?;
    let r13: Vec<f64> = q.iter().chain(qd).copied().collect();
    println!(
        "reference: closed form (θ, u, ω) + quadrature (x, y); chetaev Dop853 at 1e-13 differs by {:.1e}",
        max_diff(&r13, &exact)
    );
    println!(
        "t_end = {T_END}, {ROUNDS} interleaved rounds, batches >= {} ms",
        MIN_BATCH_SECONDS * 1e3
    );

    for (name, rows) in [
        ("Dop853", measure(&pb, hand, &y0, &exact, Dop853::default())),
        ("Dopri5", measure(&pb, hand, &y0, &exact, Dopri5::default())),
    ] {
        let hand_pts: Vec<(f64, f64)> = rows.iter().map(|r| (r.err_h, r.t_h)).collect();
        println!("\n{name}");
        println!(
            "| tol | error chetaev | error hand | steps chetaev | steps hand | time chetaev (µs) | time hand (µs) | ratio at tol | ratio at equal error |"
        );
        println!("|---|---|---|---|---|---|---|---|---|");
        for r in &rows {
            let (t, outside) = time_at_error(&hand_pts, r.err_c);
            let eq = format!(
                "{:.2}{}",
                r.t_c / t,
                if outside { " (extrapolated)" } else { "" }
            );
            println!(
                "| {:.0e} | {:.2e} | {:.2e} | {}+{} | {}+{} | {:.1} | {:.1} | {:.2} | {} |",
                r.tol,
                r.err_c,
                r.err_h,
                r.steps_c.0,
                r.steps_c.1,
                r.steps_h.0,
                r.steps_h.1,
                r.t_c * 1e6,
                r.t_h * 1e6,
                r.t_c / r.t_h,
                eq
            );
        }
        println!("\ntime per right-hand side (time / RHS evaluations):");
        for r in &rows {
            println!(
                "  {:.0e}: chetaev {:.0} ns ({} RHS), hand {:.0} ns ({} RHS)",
                r.tol,
                r.t_c / r.rhs.0 as f64 * 1e9,
                r.rhs.0,
                r.t_h / r.rhs.1 as f64 * 1e9,
                r.rhs.1
            );
        }
    }
    Ok(())
}
