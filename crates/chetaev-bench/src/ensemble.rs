//! A parameter sweep: the ratio of the uniform to the classical range over a grid of `(v0, h0)`,
//! each point solved by `chetaev` to the impact and compared with the closed forms.
//!
//! The ratio depends on `z = g h0 / v0²` alone: `R_u / R_c = arccos(e^(−z)) / √(2z)`.

use std::time::Instant;

use chetaev::prelude::*;
use rayon::prelude::*;
use uniform_projectile::closed_form::{table, Params};
use uniform_projectile::model::{classical_problem, impact, scaled_atol, uniform_problem};

/// `n` values from `lo` to `hi`, equally spaced in `log`.
pub fn log_space(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    match n {
        0 => Vec::new(),
        1 => vec![lo],
        _ => (0..n)
            .map(|i| (lo.ln() + (hi.ln() - lo.ln()) * i as f64 / (n - 1) as f64).exp())
            .collect(),
    }
}

/// The grid `(v0, h0)` of `n × n` points, each axis log-spaced over `[lo, hi]`.
pub fn grid(lo: f64, hi: f64, n: usize) -> Vec<(f64, f64)> {
    let axis = log_space(lo, hi, n);
    axis.iter()
        .flat_map(|&v0| axis.iter().map(move |&h0| (v0, h0)))
        .collect()
}

/// One solved point of the sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepPoint {
    /// Initial speed.
    pub v0: f64,
    /// Initial height.
    pub h0: f64,
    /// `z = g h0 / v0²`.
    pub z: f64,
    /// `R_u / R_c` from the two integrations (NaN when one failed).
    pub ratio: f64,
    /// `R_u / R_c` from the closed forms.
    pub closed_ratio: f64,
    /// `|R_u − R_u,closed| / R_u,closed`.
    pub uniform_error: f64,
    /// `|R_c − R_c,closed| / R_c,closed`.
    pub classical_error: f64,
    /// The method that solved the uniform motion: `Dop853`, or `Rodas4` where `Dop853` reported
    /// stiffness.
    pub method: &'static str,
    /// Accepted plus rejected steps of the uniform motion (all attempts).
    pub steps: usize,
    /// The failure, if a point could not be solved.
    pub failure: Option<String>,
}

impl SweepPoint {
    /// `|ratio − closed_ratio| / closed_ratio`.
    pub fn ratio_error(&self) -> f64 {
        ((self.ratio - self.closed_ratio) / self.closed_ratio).abs()
    }
}

fn options(p: &Params, tol: f64, t_max: f64) -> Options {
    let (atol_q, atol_qd) = scaled_atol(p, tol);
    let mut o = Options::until(t_max)
        .atol_per_component(&atol_q, &atol_qd)
        .output_final()
        .record(Record::State)
        .event(impact());
    o.rtol = tol;
    o
}

fn range(sol: &Solution) -> Result<f64, String> {
    if let Some(e) = sol.error() {
        return Err(e.to_string());
    }
    sol.events
        .first()
        .map(|hit| hit.q[0])
        .ok_or_else(|| "no impact before t_max".to_string())
}

/// Solves the uniform and the classical motion of `(v0, h0)` in gravity `g` to the impact at
/// tolerance `tol` (per-component absolute tolerances from [`scaled_atol`]). The uniform motion is
/// tried with `Dop853`; where it reports stiffness, it is solved again with `Rodas4`.
pub fn solve_point(v0: f64, h0: f64, g: f64, tol: f64) -> SweepPoint {
    let p = Params { v0, g, h0, m: 1.0 };
    let closed = table(&p);
    let t_max = 2.0 * closed.uniform.t_impact.max(closed.classical.t_impact);
    let o = options(&p, tol, t_max);
    let mut point = SweepPoint {
        v0,
        h0,
        z: p.z(),
        ratio: f64::NAN,
        closed_ratio: closed.uniform.range / closed.classical.range,
        uniform_error: f64::NAN,
        classical_error: f64::NAN,
        method: "Dop853",
        steps: 0,
        failure: None,
    };
    let outcome = (|| -> Result<(f64, f64), String> {
        let up = uniform_problem(&p).map_err(|e| e.to_string())?;
        let cp = classical_problem(&p).map_err(|e| e.to_string())?;
        let mut u = solve(&up, Dop853::default(), &o).map_err(|e| e.to_string())?;
        point.steps = u.stats.accepted_steps + u.stats.rejected_steps;
        if matches!(u.status, Status::Failed(chetaev::Error::Stiff { .. })) {
            u = solve(&up, Rodas4, &o).map_err(|e| e.to_string())?;
            point.method = "Rodas4";
            point.steps += u.stats.accepted_steps + u.stats.rejected_steps;
        }
        let c = solve(&cp, Dop853::default(), &o).map_err(|e| e.to_string())?;
        Ok((range(&u)?, range(&c)?))
    })();
    match outcome {
        Ok((ru, rc)) => {
            point.ratio = ru / rc;
            point.uniform_error = ((ru - closed.uniform.range) / closed.uniform.range).abs();
            point.classical_error = ((rc - closed.classical.range) / closed.classical.range).abs();
        }
        Err(e) => point.failure = Some(e),
    }
    point
}

/// Solves every point of `grid` on a pool of `threads` threads, calling `progress` after each
/// point. Returns the points in grid order and the wall time in seconds.
pub fn sweep(
    grid: &[(f64, f64)],
    g: f64,
    tol: f64,
    threads: usize,
    progress: &(dyn Fn() + Sync),
) -> Result<(Vec<SweepPoint>, f64), rayon::ThreadPoolBuildError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let start = Instant::now();
    // One point per job: the points differ in cost by orders of magnitude (Rodas4 in the stiff
    // corner of the grid, a few steps of Dop853 elsewhere) and neighbours cost alike, so rayon's
    // default splitting into long runs of neighbours leaves a thread idle for much of the sweep.
    let points = pool.install(|| {
        grid.par_iter()
            .with_max_len(1)
            .map(|&(v0, h0)| {
                let p = solve_point(v0, h0, g, tol);
                progress();
                p
            })
            .collect()
    });
    Ok((points, start.elapsed().as_secs_f64()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_is_log_spaced_and_complete() {
        let axis = log_space(0.1, 100.0, 4);
        assert_eq!(axis.len(), 4);
        assert!((axis[0] - 0.1).abs() < 1e-15 && (axis[3] - 100.0).abs() < 1e-12);
        assert!((axis[1] - 1.0).abs() < 1e-14 && (axis[2] - 10.0).abs() < 1e-13);
        assert_eq!(grid(0.1, 100.0, 3).len(), 9);
    }

    #[test]
    fn a_point_matches_the_closed_form_ratio() {
        let p = solve_point(10.0, 5.0, 10.0, 1e-10);
        assert!(p.failure.is_none(), "{:?}", p.failure);
        assert!(p.ratio_error() < 1e-8, "{p:?}");
        assert!((p.closed_ratio - 0.9191066572936).abs() < 1e-12);
    }
}
